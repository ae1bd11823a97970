"""Bad-input specs of robomech.mechanisms.skid_steer (paper 4)."""

import numpy as np
from contract_spec import BAD_BOOL, BAD_POSITIVE, CONSTANT, RESULT_TYPE, Spec, exempt

from robomech.mechanisms import skid_steer as ss

P = "robomech.mechanisms.skid_steer."
ROBOT = ss.ExplorationRobot.paper()
_rng = np.random.default_rng(0)
CFG = _rng.normal(scale=0.05, size=(3, 8))
TWIST = _rng.normal(scale=0.1, size=(3, 6))
QD = _rng.normal(scale=0.1, size=(3, 8))
MEAS = ss.wheel_measurements(ROBOT, CFG, TWIST, QD)
_FIELDS = {f: getattr(ROBOT, f) for f in ROBOT.__dataclass_fields__}


def _cfg():
    return Spec(
        args={"robot": ROBOT, "config": CFG}, arrays={"config": 1}, nan_rows=("config",), params=("robot",)
    )


SPECS = {
    **exempt(
        "CONFIG_SIZE I_ROCKER1 I_ROCKER2 I_ROLL I_YAW MEASURED_SIZE N_ROWS N_WHEELS SIDE_JOINTS STRAIGHT_RTOL"
        " UNKNOWN_SIZE WHEELS WHEEL_SIDE",
        CONSTANT,
        P,
    ),
    **exempt("BodyVelocity SkidSteerTurn", RESULT_TYPE, P),
    P + "ExplorationRobot": Spec(
        args=_FIELDS,
        options={
            "road_wheel_radius": BAD_POSITIVE,
            "rear_arm_length": BAD_POSITIVE,
            "side_link_rake": (*BAD_POSITIVE, 2.0),
        },
    ),
    P + "assemble": _cfg(),
    P + "contact_frames": _cfg(),
    P + "wheel_jacobians": _cfg(),
    P + "wheel_measurements": Spec(
        args={"robot": ROBOT, "config": CFG, "twist": TWIST, "config_rate": QD},
        arrays={"config": 1, "twist": 1, "config_rate": 1},
        nan_rows=("config", "twist", "config_rate"),
        params=("robot",),
    ),
    P + "body_velocity": Spec(
        args={
            "robot": ROBOT,
            "state": CFG,
            "measured": MEAS,
            "solver": "qr",
            "exact_cond": False,
            "measurement_sigma": np.full(MEAS.shape, 0.01),
        },
        arrays={"state": 1, "measured": 1, "measurement_sigma": 1},
        masked=("state", "measured"),
        mask="valid",
        params=("robot",),
        options={"solver": ("QR", None, 1), "exact_cond": BAD_BOOL},
    ),
    P + "dead_reckoning": Spec(
        # twists (..., N, 6): a batch of 2 histories of N = 3 twists, each from its own start pose
        args={"twists": np.stack([TWIST, -TWIST]), "dt": 0.01, "T0": np.stack([np.eye(4), np.eye(4)])},
        arrays={"twists": 2, "T0": 2},
        wrong_shapes={"T0": ((3, 4),), "twists": ((2, 0, 6),)},
        # a start pose that is no rigid transform: scaled, sheared, or with a projective last row
        options={
            "dt": BAD_POSITIVE,
            "T0": (
                2.0 * np.eye(4),
                np.eye(4) + np.triu(np.ones((4, 4)), 1) * 0.1,
                np.diag([1.0, 1.0, -1.0, 1.0]),
            ),
        },
    ),
    P + "skid_steer_turn": Spec(
        args={"v_right": np.array([1.0, 2.0]), "v_left": np.array([0.5, 1.5]), "track_width": 0.5},
        arrays={"v_right": 0, "v_left": 0},
        nan_rows=("v_right", "v_left"),
        wrong_shapes={"v_left": ((3,),)},
        options={"track_width": BAD_POSITIVE},
        mask="turning",
    ),
    P + "wheel_lateral_velocity": Spec(
        args={
            "yaw_rate": np.array([0.1, -0.2]),
            "wheel_x": np.array([0.3, 0.1]),
            "icr_x": np.array([0.05, 0.0]),
        },
        arrays={"yaw_rate": 0, "wheel_x": 0, "icr_x": 0},
        nan_rows=("yaw_rate",),
        wrong_shapes={"wheel_x": ((3,),)},
    ),
    P + "paper_lateral_slip": Spec(
        args={
            "v_outer": np.array([1.0, 2.0]),
            "wheelbase": 0.5,
            "radius": np.array([1.0, 3.0]),
            "track_width": 0.4,
        },
        arrays={"v_outer": 0, "radius": 0},
        nan_rows=("v_outer", "radius"),
        wrong_shapes={"radius": ((3,),)},
        options={"wheelbase": BAD_POSITIVE, "track_width": BAD_POSITIVE},
    ),
}
