"""Bad-input specs of robomech.spatial (pure math: every bad input raises, nothing is masked)."""

import numpy as np
from contract_spec import CONSTANT, Spec

P = "robomech.spatial."
W2 = np.array([[0.1, -0.2, 0.3], [0.4, 0.5, -0.6]])  # (2, 3) rotation vectors
V2 = np.array([[0.1, -0.2, 0.3, 1.0, 2.0, -1.0], [0.0, 0.5, -0.6, 0.2, 0.0, 0.1]])  # (2, 6) twists
R2 = np.stack([np.eye(3), np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])])
T2 = np.zeros((2, 4, 4))
T2[:, :3, :3] = R2
T2[:, :3, 3] = [[1.0, 2.0, 3.0], [-1.0, 0.0, 0.5]]
T2[:, 3, 3] = 1.0
ANG = np.array([0.1, -2.0, 3.0])

SPECS = {
    P + "SMALL_ANGLE": CONSTANT,
    P + "hat": Spec(args={"w": W2}, arrays={"w": 1}),
    P + "vee": Spec(args={"W": R2}, arrays={"W": 2}, wrong_shapes={"W": ((2, 3, 4),)}),
    P + "exp_so3": Spec(args={"w": W2}, arrays={"w": 1}),
    P + "log_so3": Spec(args={"R": R2}, arrays={"R": 2}, wrong_shapes={"R": ((2, 3, 4), (3,), (2, 4, 4))}),
    P + "rot_x": Spec(args={"angle": ANG}, arrays={"angle": 0}),
    P + "rot_y": Spec(args={"angle": ANG}, arrays={"angle": 0}),
    P + "rot_z": Spec(args={"angle": ANG}, arrays={"angle": 0}),
    P + "sincos": Spec(args={"angle": ANG}, arrays={"angle": 0}),
    P + "transform": Spec(
        args={"R": R2, "p": W2}, arrays={"R": 2, "p": 1}, wrong_shapes={"p": ((3, 3), (2, 4))}
    ),
    P + "inverse_transform": Spec(args={"T": T2}, arrays={"T": 2}, wrong_shapes={"T": ((2, 3, 4),)}),
    P + "hat_se3": Spec(args={"V": V2}, arrays={"V": 1}),
    P + "vee_se3": Spec(args={"X": T2}, arrays={"X": 2}, wrong_shapes={"X": ((2, 3, 4),)}),
    P + "exp_se3": Spec(args={"V": V2}, arrays={"V": 1}),
    P + "log_se3": Spec(args={"T": T2}, arrays={"T": 2}, wrong_shapes={"T": ((2, 3, 4),)}),
    P + "adjoint": Spec(args={"T": T2}, arrays={"T": 2}, wrong_shapes={"T": ((2, 3, 4),)}),
    P + "ad": Spec(args={"V": V2}, arrays={"V": 1}),
    P + "lie_bracket": Spec(args={"V1": V2, "V2": V2[::-1]}, arrays={"V1": 1, "V2": 1}),
    P + "reciprocal_product": Spec(args={"S1": V2, "S2": V2[::-1]}, arrays={"S1": 1, "S2": 1}),
    P + "virtual_power": Spec(args={"W": V2, "V": V2[::-1]}, arrays={"W": 1, "V": 1}),
    P + "screw_from_axis": Spec(
        args={"axis": W2, "point": W2[::-1], "pitch": 0.1},
        arrays={"axis": 1, "point": 1},
        options={"pitch": (np.nan, None, "0.1", 1j)},
    ),
    P + "screw_to_axis": Spec(args={"S": V2}, arrays={"S": 1}),
    P + "wrench_at": Spec(
        args={"force": W2, "point": W2[::-1], "moment": W2 * 0.5},
        arrays={"force": 1, "point": 1, "moment": 1},
        options={"moment": (0.0, 1.0, [1.0, 2.0])},  # a moment is a vector: no scalar
    ),
}
