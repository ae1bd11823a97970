"""Bad-input specs of robomech.trajectory."""

import numpy as np
from contract_spec import BAD_POSITIVE, RESULT_TYPE, Spec

P = "robomech.trajectory."
T = np.array([0.0, 0.4, 1.1])

SPECS = {
    P + "Profile": RESULT_TYPE,
    P + "polynomial": Spec(
        args={"t": T, "coeffs": np.array([[1.0, -2.0, 0.5], [0.0, 1.0, 0.0], [2.0, 0.0, -1.0]])},
        arrays={"t": 0, "coeffs": 1},
        wrong_shapes={"coeffs": ((2, 3), (3, 0))},
    ),
    P + "quintic": Spec(
        args={"t": T, "duration": 1.0, "start": np.array([0.2, 0.0, -0.1]), "end": np.array([1.0, 2.0, 3.0])},
        arrays={"t": 0, "start": 0, "end": 0},
        wrong_shapes={"end": ((2,),)},
        options={"duration": BAD_POSITIVE},
    ),
    P + "swing_sextic": Spec(
        args={"t": T, "duration": 1.0, "height": np.array([0.1, 0.05, 0.2])},
        arrays={"t": 0, "height": 0},
        wrong_shapes={"height": ((2,),)},
        options={"duration": BAD_POSITIVE},
    ),
    P + "sinusoid": Spec(
        args={
            "t": T,
            "amplitude": np.array([0.5, 1.0, 0.2]),
            "frequency": np.array([1.0, 2.0, 0.5]),
            "phase": np.array([0.1, 0.0, -0.3]),
            "offset": np.array([0.0, 1.0, 0.5]),
        },
        arrays={"t": 0, "amplitude": 0, "frequency": 0, "phase": 0, "offset": 0},
        wrong_shapes={"frequency": ((2,),)},
    ),
}
