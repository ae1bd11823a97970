"""Bad-input specs of robomech.mechanisms.spherical_leg (paper 1)."""

import numpy as np
from contract_spec import (
    BAD_BOOL,
    BAD_NONNEGATIVE,
    BAD_POSITIVE,
    BAD_REAL,
    BAD_STR,
    CONSTANT,
    RESULT_TYPE,
    Spec,
    exempt,
)

from robomech.mechanisms import spherical_leg as sl

P = "robomech.mechanisms.spherical_leg."
LEG = sl.SphericalLeg.paper()
A = np.array([0.1, -0.2, 0.3])
B = np.array([0.0, 0.2, -0.1])
Q = np.stack([A, B], -1)  # (3, 2)
# four samples where a result also holds an unbatched (3, 3) array (base_points): the nan_rows check
# tells result arrays of the batch by their leading axis
A4, B4 = np.append(A, 0.05), np.append(B, 0.15)
QD = np.array([[0.1, 0.2], [-0.3, 0.0], [0.5, -0.1]])
QDD = QD[::-1].copy()
LENGTHS = sl.inverse_kinematics(LEG, A, B).lengths  # (3, 3)
J = sl.jacobian(LEG, A, B)  # (3, 3, 2)
BAD_LEGS = ((0, 0), (0, 3), (0,), "ab", 1, (0.5, 1.0), (True, False))

SPECS = {
    P + "PAPER_DRIVEN_LEGS": CONSTANT,
    **exempt(
        "ForceDistribution ForwardKinematicsResult InverseDynamicsResult InverseKinematicsResult"
        " WorkspaceMap",
        RESULT_TYPE,
        P,
    ),
    P + "LegBody": Spec(
        args={"name": "screw", "length": 0.11, "width": 0.03, "wall": 0.015, "mass": 2.0, "shape": "round"},
        options={
            "name": (None, 1),
            "length": BAD_POSITIVE,
            "width": BAD_POSITIVE,
            "wall": BAD_POSITIVE,
            "mass": BAD_NONNEGATIVE,
            "shape": ("oval", None, 1),
        },
    ),
    P + "SphericalLeg": Spec(
        args={
            "R": 0.075,
            "r": 0.03,
            "h": 0.1,
            "platform_mass": 5.0,
            "screw_spin": True,
            "gravity": (0.0, 0.0, -10.0),
        },
        options={
            "R": BAD_POSITIVE,
            "r": BAD_POSITIVE,
            "h": BAD_POSITIVE,
            "platform_mass": BAD_NONNEGATIVE,
            "screw_spin": BAD_BOOL,
            "gravity": (None, "abc", (0.0, 0.0), (0.0, 0.0, np.nan), (0.0, 0.0, 1j), (True, 0.0, 0.0)),
        },
    ),
    P + "inverse_kinematics": Spec(
        args={"leg": LEG, "alpha": A4, "beta": B4},
        arrays={"alpha": 0, "beta": 0},
        nan_rows=("alpha", "beta"),
        params=("leg",),
    ),
    P + "forward_kinematics": Spec(
        args={"leg": LEG, "lengths": LENGTHS, "branch": 0, "paper_as_printed": False},
        arrays={"lengths": 1},
        masked=("lengths",),
        mask="valid",
        params=("leg",),
        options={"branch": (2, -1, 0.5, None, "0", True), "paper_as_printed": BAD_BOOL},
    ),
    P + "platform_rotation": Spec(
        args={"alpha": A, "beta": B}, arrays={"alpha": 0, "beta": 0}, nan_rows=("alpha", "beta")
    ),
    P + "jacobian": Spec(
        args={"leg": LEG, "alpha": A, "beta": B},
        arrays={"alpha": 0, "beta": 0},
        nan_rows=("alpha", "beta"),
        params=("leg",),
    ),
    P + "hessian": Spec(
        args={"leg": LEG, "alpha": A, "beta": B},
        arrays={"alpha": 0, "beta": 0},
        nan_rows=("alpha", "beta"),
        params=("leg",),
    ),
    P + "influence_coefficients": Spec(
        args={"leg": LEG, "alpha": A, "beta": B},
        arrays={"alpha": 0, "beta": 0},
        nan_rows=("alpha", "beta"),
        params=("leg",),
    ),
    P + "angular_velocity_jacobian": Spec(args={"alpha": A}, arrays={"alpha": 0}, nan_rows=("alpha",)),
    P + "leg_rates": Spec(
        args={"leg": LEG, "q": Q, "qd": QD, "qdd": QDD},
        arrays={"q": 1, "qd": 1, "qdd": 1},
        nan_rows=("q", "qd", "qdd"),
        params=("leg",),
    ),
    P + "workspace_map": Spec(
        args={"leg": LEG, "alpha": A, "beta": B},
        arrays={"alpha": 0, "beta": 0},
        nan_rows=("alpha", "beta"),
        params=("leg",),
        mask="reachable",
    ),
    P + "generalized_forces": Spec(
        args={
            "leg": LEG,
            "q": Q,
            "qd": QD,
            "qdd": QDD,
            "platform_wrench": np.zeros((3, 6)),
            "paper_as_printed": False,
        },
        arrays={"q": 1, "qd": 1, "qdd": 1, "platform_wrench": 1},
        nan_rows=("q", "qd", "qdd"),
        params=("leg",),
        options={"paper_as_printed": BAD_BOOL},
    ),
    P + "mass_matrix": Spec(
        args={"leg": LEG, "q": Q, "paper_as_printed": False},
        arrays={"q": 1},
        nan_rows=("q",),
        params=("leg",),
        options={"paper_as_printed": BAD_BOOL},
    ),
    P + "mechanical_energy": Spec(
        args={"leg": LEG, "q": Q, "qd": QD, "paper_as_printed": False},
        arrays={"q": 1, "qd": 1},
        nan_rows=("q", "qd"),
        params=("leg",),
        options={"paper_as_printed": BAD_BOOL},
    ),
    P + "distribute_forces": Spec(
        args={"J": J, "tau": QD, "driven_legs": None, "sigma_min_bound": sl.ACTUATION_SIGMA_MIN},
        arrays={"J": 2, "tau": 1},
        masked=("J", "tau"),
        mask="valid",
        options={"driven_legs": BAD_LEGS, "sigma_min_bound": BAD_NONNEGATIVE},
    ),
    P + "inverse_dynamics": Spec(
        args={
            "leg": LEG,
            "q": Q,
            "qd": QD,
            "qdd": QDD,
            "platform_wrench": np.zeros((3, 6)),
            "driven_legs": (0, 2),
            "paper_as_printed": False,
        },
        arrays={"q": 1, "qd": 1, "qdd": 1, "platform_wrench": 1},
        nan_rows=("q", "qd", "qdd"),
        params=("leg",),
        mask="valid",
        options={"driven_legs": BAD_LEGS, "paper_as_printed": BAD_BOOL},
    ),
    P + "sway": Spec(
        args={"t": np.array([0.0, 1.0, 2.0]), "about": "x", "beta0": 0.1},
        arrays={"t": 0},
        options={"about": ("z", *BAD_STR), "beta0": BAD_REAL},
    ),
    P + "fig5_motion": Spec(
        args={"case": "b", "t": np.array([0.0, 4.0, 9.0])}, arrays={"t": 0}, options={"case": ("d", *BAD_STR)}
    ),
}
