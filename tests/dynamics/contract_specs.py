"""Bad-input specs of robomech.dynamics."""

import numpy as np
from contract_spec import CONSTANT, RESULT_TYPE, Spec

from robomech import dynamics

P = "robomech.dynamics."
rng = np.random.default_rng(0)
G = dynamics.spatial_inertia(np.array([1.0, 2.0]), np.array([[0.1, 0, 0], [0, 0.2, 0]]), np.eye(3) * 0.01)
G2 = np.broadcast_to(G, (2, 2, 6, 6)).copy()  # (batch 2, bodies 2, 6, 6)
J = rng.normal(size=(2, 2, 6, 3))
JD = rng.normal(size=(2, 2, 6, 3))
QD = rng.normal(size=(2, 3))
JA = rng.normal(size=(3, 4, 3))  # actuator Jacobians (k = 4 actuators, n = 3)

SPECS = {
    P + "DynamicsTerms": RESULT_TYPE,
    P + "ActuatorForces": RESULT_TYPE,
    P + "ACTUATION_RESIDUAL_RTOL": CONSTANT,
    P + "INERTIA_RTOL": CONSTANT,
    P + "spatial_inertia": Spec(
        args={
            "mass": np.array([1.0, 2.0]),
            "com": np.array([[0.1, 0, 0], [0, 0.2, 0]]),
            "inertia_com": np.stack([np.eye(3), 2.0 * np.eye(3)]),
        },
        arrays={"mass": 0, "com": 1, "inertia_com": 2},
        wrong_shapes={"mass": ((3,),)},
        # an indefinite and an asymmetric inertia: no mass has them
        options={
            "mass": (-1.0,),
            "inertia_com": (np.diag([1.0, 1.0, -1.0]), np.array([[1.0, 0.5, 0], [0, 1, 0], [0, 0, 1]])),
        },
    ),
    P + "mass_matrix": Spec(
        args={"G": G2, "J": J},
        arrays={"G": 3, "J": 3},
        wrong_shapes={"G": ((2, 2, 5, 6),), "J": ((2, 2, 5, 3), (2, 3, 6, 3))},
    ),
    P + "kinetic_energy": Spec(
        args={"G": G2, "J": J, "qd": QD},
        arrays={"G": 3, "J": 3, "qd": 1},
        wrong_shapes={"J": ((2, 2, 5, 3),)},
    ),
    P + "inverse_dynamics": Spec(
        args={
            "G": G2,
            "J": J,
            "Jdot": JD,
            "qd": QD,
            "qdd": QD[::-1],
            "gravity_body": np.tile([0.0, 0.0, -9.81], (2, 2, 1)),
            "external_wrench_body": np.zeros((2, 2, 6)),
        },
        arrays={"G": 3, "J": 3, "Jdot": 3, "qd": 1, "qdd": 1, "gravity_body": 2, "external_wrench_body": 2},
        wrong_shapes={"J": ((2, 2, 5, 3),), "Jdot": ((2, 2, 6, 4),)},
    ),
    P + "static_torques": Spec(
        args={"J": J[:, 0], "wrench": rng.normal(size=(2, 6))},
        arrays={"J": 2, "wrench": 1},
        wrong_shapes={"J": ((6,),)},
    ),
    P + "actuator_forces": Spec(
        args={"J_act": JA, "tau_q": rng.normal(size=(3, 3)), "rcond": 1e-12},
        arrays={"J_act": 2, "tau_q": 1},
        wrong_shapes={"J_act": ((3, 2, 3),)},
        masked=("J_act", "tau_q"),
        mask="valid",
        options={"rcond": (np.nan, -1.0, "1e-12", True)},
    ),
}
