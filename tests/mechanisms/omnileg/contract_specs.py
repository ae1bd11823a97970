"""Bad-input specs of robomech.mechanisms.omnileg (paper 2)."""

import numpy as np
from contract_spec import BAD_BOOL, BAD_INT, BAD_POSITIVE, BAD_REAL, CONSTANT, RESULT_TYPE, Spec, exempt

from robomech.mechanisms import omnileg as ol

P = "robomech.mechanisms.omnileg."
LEG = ol.OmniLeg.paper()
Q = np.array([[0.1, 0.2, 0.5], [-0.2, 0.1, 0.7], [0.0, 0.0, 0.3]])
QD = np.array([[0.1, -0.2, 0.3], [0.0, 0.5, -0.1], [0.2, 0.2, 0.2]])
QDD = QD[::-1].copy()
P_FOOT = ol.forward_kinematics(LEG, Q)
T = np.array([0.0, 1.0, 2.5])
L = {"L1": LEG.L1, "L3": LEG.L3, "L4": LEG.L4, "L5": LEG.L5}


def _leg(**kw):
    return Spec(
        args={"leg": LEG, **kw},
        arrays={k: 1 for k in kw},
        nan_rows=tuple(k for k in kw if k in ("q", "qd", "qdd")),
        params=("leg",),
    )


SPECS = {
    # the generic description (issue 13): takes only the parameter object
    P + "to_multibody": Spec(args={"leg": LEG}, params=("leg",)),
    P + "BODY_NAMES": CONSTANT,
    P + "TREE_JOINTS": CONSTANT,
    **exempt(
        "DynamicsResult FootForceResult GaitProfile IKResult JointMotion ShankResult ThighClosure",
        RESULT_TYPE,
        P,
    ),
    P + "RigidBody": Spec(
        args={"mass": 1.0, "com": (0.0, 0.0, 0.1), "inertia": np.eye(3) * 1e-3},
        options={
            "mass": BAD_POSITIVE,
            "com": (None, "abc", (0.0, 0.0), (0.0, 0.0, np.nan), (0.0, 0.0, 1j)),
            "inertia": (None, np.eye(2), np.full((3, 3), np.nan), -np.eye(3), np.eye(3) * 1j),
        },
    ),
    P + "OmniLeg": Spec(
        args={**L, "alpha_max": 1.0, "gravity": (0.0, 0.0, 9.8)},
        options={
            "L1": BAD_POSITIVE,
            "L3": BAD_POSITIVE,
            "alpha_max": (*BAD_POSITIVE, 2.0),
            "gravity": (None, "abc", (0.0, 0.0), (0.0, 0.0, np.inf), (0.0, 1j, 0.0)),
        },
    ),
    P + "default_bodies": Spec(
        args={**L, "knee_to_crank": 0.03},
        # a negative depth, and one that leaves the foot rod no length (>= L5), are refused by name
        options={"L1": BAD_POSITIVE, "L5": BAD_POSITIVE, "knee_to_crank": (*BAD_REAL, -0.01, 1.0)},
    ),
    P + "forward_kinematics": _leg(q=Q),
    P + "jacobian": _leg(q=Q),
    P + "hessian": _leg(q=Q),
    P + "foot_velocity": _leg(q=Q, qd=QD),
    P + "foot_acceleration": _leg(q=Q, qd=QD, qdd=QDD),
    P + "body_poses": _leg(q=Q),
    P + "mass_matrix": _leg(q=Q),
    P + "gravity_torques": _leg(q=Q),
    P + "energy": _leg(q=Q, qd=QD),
    P + "static_torques": _leg(q=Q, force=QD),
    P + "joint_motion": _leg(q=Q, qd=QD, qdd=QDD),
    P + "inverse_dynamics": Spec(
        args={"leg": LEG, "q": Q, "qd": QD, "qdd": QDD, "foot_force": QD, "paper_as_printed": False},
        arrays={"q": 1, "qd": 1, "qdd": 1, "foot_force": 1},
        nan_rows=("q", "qd", "qdd"),
        params=("leg",),
        options={"paper_as_printed": BAD_BOOL},
    ),
    P + "foot_force_from_torques": Spec(
        args={"leg": LEG, "q": Q, "tau": QD},
        arrays={"q": 1, "tau": 1},
        nan_rows=("q",),
        params=("leg",),
        mask=lambda r: ~r.singular,
    ),
    P + "within_limits": Spec(
        args={"leg": LEG, "q": Q}, arrays={"q": 1}, masked=("q",), mask=lambda r: r, params=("leg",)
    ),
    P + "inverse_kinematics": Spec(
        args={"leg": LEG, "p_foot": P_FOOT},
        arrays={"p_foot": 1},
        masked=("p_foot",),
        mask="exists",
        params=("leg",),
    ),
    P + "thigh_direction": Spec(
        args={"alpha": Q[:, 0], "beta": Q[:, 1]}, arrays={"alpha": 0, "beta": 0}, nan_rows=("alpha", "beta")
    ),
    P + "passive_angles": Spec(
        args={"leg": LEG, "alpha": Q[:, 0], "beta": Q[:, 1]},
        arrays={"alpha": 0, "beta": 0},
        nan_rows=("alpha", "beta"),
        params=("leg",),
    ),
    P + "thigh_closure": Spec(
        args={"leg": LEG, "alpha": Q[:, 0], "beta": Q[:, 1]},
        arrays={"alpha": 0, "beta": 0},
        nan_rows=("alpha", "beta"),
        params=("leg",),
        mask="converged",
    ),
    P + "shank_crank_slider": Spec(
        args={"leg": LEG, "gamma": Q[:, 2]},
        arrays={"gamma": 0},
        nan_rows=("gamma",),
        params=("leg",),
        mask="valid",
    ),
    P + "chain_screws": Spec(args={"leg": LEG}, params=("leg",)),
    P + "shank_frames": Spec(args={"leg": LEG}, params=("leg",)),
    P + "start_point": Spec(args={"leg": LEG}, params=("leg",)),
    P + "foot_trajectory_eq51": Spec(args={"leg": LEG, "t": T}, arrays={"t": 0}, params=("leg",)),
    P + "joint_trajectory_eq52": Spec(args={"t": T}, arrays={"t": 0}),
    P + "gait_eq53": Spec(
        args={"leg": LEG, "t": T, "periods": 2},
        arrays={"t": 0},
        params=("leg",),
        options={"periods": (*BAD_INT, 0)},
    ),
}
