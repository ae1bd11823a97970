"""Bad-input specs of the spanning tree's dynamics quantities of robomech.multibody (multibody/_rnea.py).

Kept beside specs/multibody.py and specs/multibody_dynamics.py so the helpers' files do not collide.
"""

import numpy as np
from contract_spec import BAD_BOOL, Spec

from robomech import multibody as mb

P = "robomech.multibody."
MECH = mb.gallery.load("four_bar")
Q = mb.forward_kinematics(MECH, np.array([[0.2], [-0.4], [0.6]])).q  # (3, 3)
QD = np.array([[1.0, -0.5, 0.3], [0.2, 0.1, -1.0], [0.0, 0.4, 0.2]])
QDD = np.array([[0.2, 0.1, -1.0], [1.0, 0.0, 0.5], [-0.3, 0.2, 0.1]])

SPECS = {
    P + "generalized_forces": Spec(
        args={"mech": MECH, "q": Q, "qd": QD, "qdd": QDD, "gravity": True},
        arrays={"q": 1, "qd": 1, "qdd": 1},
        masked=("q", "qd", "qdd"),  # a non-finite sample gives a NaN row, alone
        mask=lambda r: np.all(np.isfinite(r), axis=-1),
        params=("mech",),
        options={"gravity": BAD_BOOL},
    ),
    P + "mass_matrix": Spec(
        args={"mech": MECH, "q": Q},
        arrays={"q": 1},
        masked=("q",),
        mask=lambda r: np.all(np.isfinite(r), axis=(-1, -2)),
        params=("mech",),
    ),
}
