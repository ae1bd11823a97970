"""Bad-input specs of the skid-steer MuJoCo ground truth added by issue 17 (``robomech.verify.skid_steer``).

The names that existed before issue 17 are specified in ``verify.py`` (or still pending).
"""

import numpy as np
from contract_spec import BAD_NONNEGATIVE, BAD_POSITIVE, RESULT_TYPE, Spec, exempt

from robomech.mechanisms.skid_steer import ExplorationRobot
from robomech.verify import skid_steer as vs

P = "robomech.verify.skid_steer."
ROBOT = ExplorationRobot.paper()
BAD_OBJECT = ("terrain", 1.0, ExplorationRobot)

SPECS = {
    **exempt("EngineRun", RESULT_TYPE, P),
    P + "EngineParams": Spec(
        args={"friction": 0.6, "timestep": 1e-3, "wheel_gain": 5.0, "chassis_mass": 15.0, "joint_limit": 0.4},
        options={
            k: BAD_POSITIVE for k in ("friction", "timestep", "wheel_gain", "chassis_mass", "joint_limit")
        },
    ),
    P + "simulate_engine": Spec(
        args={
            "robot": ROBOT,
            "track_speeds": np.array([0.2, 0.1]),
            "duration": 0.05,
            "terrain": vs.Terrain.flat(),
            "rate": 100.0,
            "settle": 0.02,
            "ramp": 0.02,
            "params": vs.EngineParams(),
        },
        arrays={"track_speeds": 1},
        params=("robot",),
        options={
            "duration": BAD_POSITIVE,
            "rate": (*BAD_POSITIVE, 300.0),  # 300 Hz is no whole number of 1 ms engine steps
            "settle": BAD_NONNEGATIVE,
            "ramp": BAD_NONNEGATIVE,
            "terrain": BAD_OBJECT,
            "params": BAD_OBJECT,
        },
        wrong_shapes={"track_speeds": ((3,), (1, 3), (2, 2))},
        slow=True,
    ),
    P + "engine_runs": Spec(
        args={"robot": ROBOT}, params=("robot",), good_elsewhere="tests/verify/test_verify_skid_steer.py"
    ),
    P + "engine_checks": Spec(
        args={"robot": ROBOT, "est": ROBOT},
        params=("robot", "est"),
        good_elsewhere="tests/verify/test_verify_skid_steer.py",
    ),
}
