"""Bad-input specs of robomech.mechanisms.continuum (paper 3)."""

import numpy as np
from contract_spec import (
    BAD_BOOL,
    BAD_INT,
    BAD_NONNEGATIVE,
    BAD_POSITIVE,
    CONSTANT,
    RESULT_TYPE,
    Spec,
    exempt,
)

from robomech.mechanisms import continuum as c

P = "robomech.mechanisms.continuum."
ROBOT = c.ContinuumRobot.paper()
PSI = np.array([[0.3, 0.1], [0.5, -1.0], [0.1, 2.0]])
TIP = c.tip_position(ROBOT, PSI)
TENSION = c.cable_tensions(ROBOT, PSI).tension
DIRECTION = np.ones((3, 3))
Q = c.compensated_drive(ROBOT, PSI).q
BAD_MODEL = ("helix", None, 1)
PULLEY = c.Pulley(radius=0.005, wrap=1.5, alpha=0.15, n=1.0)
BAD_PULLEY = ("pulley", 1, ROBOT)
_W = np.abs(np.random.default_rng(0).normal(size=(3, 8)))
_T3 = np.array([[8.0, 4.0, 4.0], [9.0, 3.0, 3.0], [4.0, 7.0, 4.0]])
_D3 = np.array([[1.0, -1.0, -1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0]])


def _psi(**extra):
    return Spec(
        args={"robot": ROBOT, "psi": PSI, **extra}, arrays={"psi": 1}, nan_rows=("psi",), params=("robot",)
    )


def _psi_model(default):
    return Spec(
        args={"robot": ROBOT, "psi": PSI, "model": default},
        arrays={"psi": 1},
        nan_rows=("psi",),
        params=("robot",),
        options={"model": BAD_MODEL},
    )


# a history of 3 steps (leading time axis) for a batch of 2 poses, started from the span tensions a
# previous history left (> 0 on the active spans, 0 on the others)
_SS_PSI = np.stack(
    [np.array([[0.8, 0.0], [1.2, 0.0], [1.0, 0.0]]), np.array([[0.4, 0.3], [0.6, 0.3], [0.5, 0.3]])], 1
)
_SS_T = np.stack([np.array([[5.0, 5.0, 5.0], [9.0, 4.0, 4.0], [7.0, 5.0, 5.0]])] * 2, 1)
_SS_INITIAL = c.stick_slip_tensions(ROBOT, _SS_PSI, _SS_T[::-1]).span_tension[-1]  # (2, 3, 5)

SPECS = {
    P + "IK_TOLERANCE": CONSTANT,
    P + "IDENTIFY_MU_MAX": CONSTANT,
    P + "IDENTIFY_STIFFNESS_BOUNDS": CONSTANT,
    P + "COMPENSATION_ITERATIONS": CONSTANT,
    P + "COMPENSATION_STEP_TOL": CONSTANT,
    P + "DISK_MAX_ITERATIONS": CONSTANT,
    P + "DISK_TOLERANCE": CONSTANT,
    P + "PULLEY_FIXED_POINT_ITERATIONS": CONSTANT,
    P + "PULLEY_QUAD_NODES": CONSTANT,
    P + "STICK_SLIP_TENSION_FLOOR": CONSTANT,
    P + "STUCK_FLUX_TOL": CONSTANT,
    P + "MEMORY_MAX_ITERATIONS": CONSTANT,
    **exempt(
        "DiskEquilibrium DriveResult FrictionEstimate HistoryResult IKResult PoseFrictionEstimate "
        "SimulationResult TensionHistory TensionResult TipFrictionEstimate",
        RESULT_TYPE,
        P,
    ),
    P + "ContinuumRobot": Spec(
        args={
            "n_segments": 1,
            "segment_length": 0.09,
            "friction": (0.2, 0.3, 0.25),
            "pretension": 5.0,
            "hole_radius": 0.004,
        },
        options={
            "n_segments": (*BAD_INT, 0, True),
            "segment_length": BAD_POSITIVE,
            "pretension": BAD_NONNEGATIVE,
            "hole_radius": (1e-6, 4e-4),  # inside the 1 mm core: the cable cannot run there
            "friction": (
                None,
                "abc",
                (0.1, 0.2),
                (0.1, 0.2, np.nan),
                (0.1, 0.2, -0.1),
                ((0.1, 0.2, 0.3),) * 2,
            ),
        },
    ),
    P + "forward_kinematics": _psi(),
    P + "tip_position": _psi(),
    P + "tip_jacobian": _psi(),
    P + "disk_transforms": _psi(),
    P + "elastic_energy": _psi(),
    P + "elastic_gradient": _psi(),
    P + "coupling_moments": _psi(),
    P + "wrap_angles": _psi(),
    P + "span_lengths": _psi_model("chord"),
    P + "span_jacobian": _psi_model("chord"),
    P + "cable_lengths": _psi_model("arc"),
    P + "cable_jacobian": _psi_model("arc"),
    P + "theoretical_drive": _psi_model("arc"),
    P + "friction_factors": Spec(
        args={"robot": ROBOT, "psi": PSI, "direction": DIRECTION},
        arrays={"psi": 1, "direction": 1},
        nan_rows=("psi",),
        params=("robot",),
    ),
    P + "segment_transform": Spec(
        args={"theta": PSI[:, 0], "beta": PSI[:, 1], "length": np.array([0.09, 0.08, 0.1])},
        arrays={"theta": 0, "beta": 0, "length": 0},
        nan_rows=("theta", "beta"),
        options={"length": (-0.1,)},
    ),
    P + "inverse_kinematics": Spec(
        args={"robot": ROBOT, "p_tip": TIP},
        arrays={"p_tip": 1},
        nan_rows=("p_tip",),
        params=("robot",),
        mask="reachable",
    ),
    P + "cable_tensions": Spec(
        args={
            "robot": ROBOT,
            "psi": PSI,
            "wrench": np.zeros((3, 6)),
            "direction": DIRECTION,
            "model": "chord",
            "pretension": 5.0,
        },
        arrays={"psi": 1, "wrench": 1, "direction": 1},
        nan_rows=("psi",),
        params=("robot",),
        mask="taut",
        options={"pretension": tuple(v for v in BAD_NONNEGATIVE if v is not None), "model": BAD_MODEL},
    ),
    P + "cable_elongation": Spec(
        args={"robot": ROBOT, "psi": PSI, "tension": TENSION, "direction": DIRECTION, "model": "chord"},
        arrays={"psi": 1, "tension": 1, "direction": 1},
        nan_rows=("psi", "tension"),
        params=("robot",),
        options={"model": BAD_MODEL},
    ),
    P + "compensated_drive": Spec(
        args={
            "robot": ROBOT,
            "psi": PSI,
            "direction": DIRECTION,
            "wrench": np.zeros((3, 6)),
            "model": "chord",
            "method": "paper",
            "pulley": PULLEY,
        },
        arrays={"psi": 1, "direction": 1, "wrench": 1},
        nan_rows=("psi",),
        params=("robot",),
        mask="taut",
        options={"model": BAD_MODEL, "method": ("segment", None, 1), "pulley": BAD_PULLEY},
    ),
    P + "simulate": Spec(
        args={
            "robot": ROBOT,
            "q": Q,
            "direction": DIRECTION,
            "model": "chord",
            "pulley": PULLEY,
            "initial": PSI,
        },
        arrays={"q": 1, "direction": 1, "initial": 1},
        nan_rows=("q",),
        params=("robot",),
        mask="converged",
        options={"model": BAD_MODEL, "pulley": BAD_PULLEY},
    ),
    # memory="elastic" (the default) needs chord cables and no pulley: the good call has none; the
    # pulley and the arc model are exercised with memory="slip" in test_continuum_drive_chain.py
    P + "simulate_history": Spec(
        args={
            "robot": ROBOT,
            "q": Q,
            "times": np.array([0.0, 0.5, 1.0]),
            "model": "chord",
            "pulley": None,
            "memory": "elastic",
        },
        arrays={"q": 1, "times": 0},
        wrong_shapes={"q": ((3, 4),), "times": ((2,), (3, 1))},
        params=("robot",),
        options={
            "model": (*BAD_MODEL, "arc"),
            "pulley": (*BAD_PULLEY, PULLEY),
            "memory": ("rigid", None, 1),
            "times": (np.array([0.0, 1.0, 0.5]),),
        },
        empty_batch=False,  # the leading axis is time: a history needs a first step
    ),
    P + "Pulley": Spec(
        args={"radius": 0.005, "wrap": 1.5, "alpha": 0.15, "n": 1.0},
        options={
            "radius": BAD_POSITIVE,
            "wrap": BAD_NONNEGATIVE,
            "alpha": BAD_NONNEGATIVE,
            "n": (*BAD_POSITIVE, 1.5),
        },
    ),
    P + "capstan_coefficient": Spec(
        args={"rho": np.array([2.0, 3.0]), "alpha": np.array([1.0, 0.8]), "n": np.array([0.5, 1.0])},
        arrays={"rho": 0, "alpha": 0, "n": 0},
        options={"n": (0.0, -0.5, 1.5), "rho": (0.0,), "alpha": (-1.0,)},
    ),
    P + "capstan_tension_ratio": Spec(
        args={
            "phi": np.array([0.5, 1.0]),
            "rho": 2.5,  # an option (np.inf allowed): not cut to the empty batch
            "alpha": np.array([1.0, 0.8]),
            "n": np.array([0.5, 1.0]),
            "t_out": np.array([1.0, 2.0]),
        },
        arrays={"phi": 0, "alpha": 0, "n": 0, "t_out": 0},
        nan_rows=("phi",),  # rho: an option (np.inf is allowed)
        options={"n": (0.0, 1.5), "rho": (0.0, np.nan, None, "2"), "phi": (-1.0,), "t_out": (0.0,)},
    ),
    P + "classical_capstan_ratio": Spec(
        args={"phi": np.array([0.5, 1.0]), "mu": np.array([0.3, 0.1])},
        arrays={"phi": 0, "mu": 0},
        nan_rows=("phi",),
    ),
    P + "identify_friction": Spec(
        args={
            "wrap": _W,
            "t_in": 5 * np.exp(0.3 * _W),
            "t_out": np.full((3, 8), 5.0),
            "direction": np.ones((3, 8)),
            "sigma_t": 0.1,
        },
        arrays={"wrap": 1, "t_in": 1, "t_out": 1, "direction": 1},
        wrong_shapes={"wrap": ((3, 9),), "t_in": ((3, 9),), "t_out": ((3, 9),), "direction": ((3, 9),)},
        options={"sigma_t": tuple(v for v in BAD_POSITIVE if v is not None)},
    ),
    P + "stick_slip_tensions": Spec(
        args={"robot": ROBOT, "psi": _SS_PSI, "t_act": _SS_T, "initial": _SS_INITIAL},
        arrays={"psi": 1, "t_act": 1, "initial": 2},
        params=("robot",),
        empty_batch=False,  # the leading axis is time: a history needs a first step
    ),
    P + "disk_equilibrium": Spec(
        args={"robot": ROBOT, "tension": TENSION, "direction": DIRECTION, "initial": PSI},
        arrays={"tension": 1, "direction": 1, "initial": 1},
        nan_rows=("tension",),
        params=("robot",),
        mask="converged",
        options={"tension": (-np.ones(3),)},
    ),
    P + "identify_friction_from_tip": Spec(
        args={
            "robot": ROBOT,
            "tip": c.disk_equilibrium(ROBOT, tension=_T3, direction=_D3).tip,
            "t_act": _T3,
            "direction": _D3,
            "fit_stiffness": False,
            "sigma_t": 0.05,
            "sigma_tip": 2e-5,
        },
        arrays={"tip": 1, "t_act": 1, "direction": 1},
        params=("robot",),
        options={"fit_stiffness": BAD_BOOL, "sigma_t": (0.0, -1.0, "a"), "sigma_tip": (0.0, -1.0, "a")},
        empty_batch=False,  # the leading axis lists measurements of one fit (m >= 1 required)
    ),
    P + "identify_friction_from_pose": Spec(
        args={
            "robot": ROBOT,
            "psi": np.array([[0.8, 0.0], [1.2, 0.0], [1.0, 2.1]]),
            "t_act": np.array([[8.0, 4.0, 4.0], [9.0, 3.0, 3.0], [4.0, 7.0, 4.0]]),
            "direction": np.array([[1.0, -1.0, -1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0]]),
            "sigma_t": 0.05,
            "model": "chord",
        },
        arrays={"psi": 1, "t_act": 1, "direction": 1},
        params=("robot",),
        options={"sigma_t": tuple(v for v in BAD_POSITIVE if v is not None), "model": BAD_MODEL},
        empty_batch=False,  # the leading axis lists measurements of one fit (m >= 1 required)
    ),
}
