"""Bad-input specs of robomech.mechanisms.vectored_thrust (paper 5)."""

import numpy as np
from contract_spec import BAD_INT, BAD_POSITIVE, BAD_REAL, CONSTANT, RESULT_TYPE, Spec, exempt

from robomech.mechanisms import vectored_thrust as vt

P = "robomech.mechanisms.vectored_thrust."
TH = vt.VectoredThruster()
Q = np.array([[0.3, -0.2], [0.1, 0.2], [-0.5, 0.0]])
QD = np.array([[0.1, 0.2], [-0.3, 0.4], [0.0, 0.5]])
S = vt.forward_kinematics(TH, Q).axis
BAD_RANGE = (None, "ab", (0.1,), (0.2, 0.1), (np.nan, 0.1), (0.0, 1j), (-4.0, 0.0))


def _q(mask, **extra):
    return Spec(
        args={"th": TH, "q": Q, **extra},
        arrays={"q": 1, **{k: 1 for k in extra}},
        nan_rows=("q", *extra),
        params=("th",),
        mask=mask,
    )


SPECS = {
    P + "DEXTERITY_TOL": CONSTANT,
    P + "SINGULAR_TOL": CONSTANT,
    **exempt(
        "AccelerationResult FKResult IKResult JacobianResult JointAxes LinkClearanceResult MechanismMobility"
        " PassiveResult RotationResult VelocityResult WorkspaceMap",
        RESULT_TYPE,
        P,
    ),
    P + "VectoredThruster": Spec(
        args={
            "arc_angle": np.pi / 4,
            "platform_radius": 0.02,
            "q1_limits": (-0.7, 0.7),
            "interference_clearance": 0.3,
        },
        options={
            "arc_angle": (*BAD_POSITIVE, 2.0),
            "platform_radius": BAD_POSITIVE,
            "q1_limits": BAD_RANGE,
            "interference_clearance": (*BAD_REAL, -0.1, 2.0),
        },
    ),
    P + "forward_kinematics": _q("valid"),
    P + "platform_rotation": _q("valid"),
    P + "joint_axes": _q("valid"),
    P + "passive_angles": _q("valid"),
    P + "jacobian": _q("valid"),
    P + "workspace_map": _q("reachable"),
    P + "link_clearance": _q("valid"),
    P + "dexterity": _q(None),
    P + "passive_rates": _q("valid", qd=QD),
    P + "angular_velocity": _q("valid", qd=QD),
    P + "angular_acceleration": _q("valid", qd=QD, qdd=QD[::-1].copy()),
    P + "inverse_kinematics": Spec(
        args={"th": TH, "s": S}, arrays={"s": 1}, nan_rows=("s",), params=("th",), mask="valid"
    ),
    P + "arc_clearance": Spec(
        args={"a1": S, "b1": S[::-1].copy(), "a2": np.eye(3), "b2": np.eye(3)[::-1].copy()},
        arrays={"a1": 1, "b1": 1, "a2": 1, "b2": 1},
        nan_rows=("a1", "b1", "a2", "b2"),
    ),
    P + "idle_input_curve": Spec(
        args={"th": TH, "q1": Q[:, 0]}, arrays={"q1": 0}, nan_rows=("q1",), params=("th",)
    ),
    P + "singular_points": Spec(args={"th": TH}, params=("th",)),
    P + "input_grid": Spec(
        args={"th": TH, "n": 3, "limits": np.array([[-0.5, 0.5], [-0.3, 0.3]])},
        arrays={"limits": 2},
        wrong_shapes={"limits": ((3, 2), (2, 3))},
        params=("th",),
        options={"n": (*BAD_INT, 1, (3,), (3, 1)), "limits": (np.array([[0.5, -0.5], [-0.3, 0.3]]),)},
    ),
    P + "chain_screws": Spec(
        args={"th": TH, "q": Q[0], "offsets": {"s22": [0.0, 0.0, 0.001]}},
        arrays={"q": 1},
        params=("th",),
        options={"offsets": ({"s99": [0, 0, 0]}, {"s22": [0.0, np.nan, 0.0]}, {"s22": [0.0, 0.0]}, "abc")},
    ),
    P + "platform_mobility": Spec(
        args={"th": TH, "q": Q[0], "offsets": None},
        arrays={"q": 1},
        params=("th",),
        options={"offsets": ({"s99": [0, 0, 0]}, {"s22": [0.0, np.nan, 0.0]}), "q": ((0.0, np.pi / 4),)},
    ),
    P + "mechanism_mobility": Spec(
        args={"th": TH, "q": Q[0], "offsets": None, "ujoint_centre": (0.0, 0.0, 0.0)},
        arrays={"q": 1, "ujoint_centre": 1},
        unbatched=("q", "ujoint_centre"),  # the mobility at one configuration
        params=("th",),
        options={"offsets": ({"s99": [0, 0, 0]},)},
    ),
}
