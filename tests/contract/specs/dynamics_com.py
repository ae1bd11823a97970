"""Bad-input specs of robomech.dynamics' centre-of-mass kernel (issue 13); the older names are pending."""

import numpy as np
from contract_spec import Spec

P = "robomech.dynamics."
B, N = 2, 3
R = np.stack([np.eye(3), np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])])
I3 = np.stack([np.diag([1.0, 2.0, 3.0]), np.diag([0.5, 0.5, 0.1])])
MASS = np.array([1.0, 2.0])
J = np.arange(B * 6 * N, dtype=float).reshape(B, 6, N) / 10.0
A0 = np.ones((B, 6))
QD = np.array([0.1, -0.2, 0.3])

SPECS = {
    P + "world_inertia": Spec(args={"R": R, "inertia": I3}, arrays={"R": 2, "inertia": 2}),
    P + "com_inverse_dynamics": Spec(
        args={
            "mass": MASS,
            "inertia": I3,
            "J": J,
            "Jdot_qd": A0,
            "qd": QD,
            "qdd": QD,
            "gravity": np.zeros(3),
        },
        arrays={"mass": 1, "inertia": 3, "J": 3, "Jdot_qd": 2, "qd": 1, "qdd": 1, "gravity": 1},
    ),
    P + "com_kinetic_energy": Spec(
        args={"mass": MASS, "inertia": I3, "J": J, "qd": QD},
        arrays={"mass": 1, "inertia": 3, "J": 3, "qd": 1},
    ),
}
