"""Bad-input specs of robomech.kinematics."""

import numpy as np
from contract_spec import Spec

from robomech.spatial import screw_from_axis

P = "robomech.kinematics."
S3 = screw_from_axis(np.eye(3), np.array([[0.0, 0.0, 0.0], [0.3, 0.0, 0.0], [0.3, 0.2, 0.0]]))  # (3, 6)
Q2 = np.array([[0.1, -0.4, 0.7], [1.0, 0.2, -0.3]])
S3B = np.stack([S3, S3[::-1].copy()])  # (2, 3, 6): screws broadcast with q's batch
M = np.eye(4)
MB = np.stack([M, np.diag([1.0, -1.0, -1.0, 1.0])])  # (2, 4, 4)
H = np.random.default_rng(0).normal(size=(2, 6, 3, 3))

SPECS = {
    P + "poe_fk": Spec(
        args={"M": MB, "screws": S3B, "q": Q2},
        arrays={"M": 2, "screws": 2, "q": 1},
        wrong_shapes={"M": ((3, 4),)},
    ),
    P + "jacobian_space": Spec(args={"screws": S3B, "q": Q2}, arrays={"screws": 2, "q": 1}),
    P + "jacobian_body": Spec(args={"body_screws": S3B, "q": Q2}, arrays={"body_screws": 2, "q": 1}),
    P + "hessian_space": Spec(args={"screws": S3B, "q": Q2}, arrays={"screws": 2, "q": 1}),
    P + "hessian_body": Spec(args={"body_screws": S3B, "q": Q2}, arrays={"body_screws": 2, "q": 1}),
    P + "jacobian_derivative": Spec(
        args={"H": H, "qd": Q2},
        arrays={"H": 3, "qd": 1},
        wrong_shapes={"H": ((2, 6, 3, 4),), "qd": ((3, 3),)},
    ),
}
