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


def _batch(a, k=3):
    """A leading batch of k samples of ``a`` (scaled copies, so the samples differ)."""
    return np.stack([a * (1.0 + 0.25 * i) for i in range(k)])


MASS3, I33, J3, A03, QD3 = _batch(MASS), _batch(I3), _batch(J), _batch(A0), _batch(QD)

SPECS = {
    P + "world_inertia": Spec(args={"R": R, "inertia": I3}, arrays={"R": 2, "inertia": 2}),
    P + "com_inverse_dynamics": Spec(
        args={
            "mass": MASS3,
            "inertia": I33,
            "J": J3,
            "Jdot_qd": A03,
            "qd": QD3,
            "qdd": QD3[::-1].copy(),
            "gravity": np.tile([0.0, 0.0, -9.81], (3, 1)),
        },
        arrays={"mass": 1, "inertia": 3, "J": 3, "Jdot_qd": 2, "qd": 1, "qdd": 1, "gravity": 1},
    ),
    P + "com_kinetic_energy": Spec(
        args={"mass": MASS3, "inertia": I33, "J": J3, "qd": QD3},
        arrays={"mass": 1, "inertia": 3, "J": 3, "qd": 1},
    ),
}
