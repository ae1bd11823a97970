"""Bad-input specs of robomech.verify and its per-mechanism modules."""

import numpy as np
from contract_spec import BAD_BOOL, BAD_POSITIVE, BAD_REAL, CONSTANT, Exempt, Spec, exempt

from robomech.mechanisms import omnileg as ol
from robomech.mechanisms import skid_steer as ss
from robomech.mechanisms import spherical_leg as sl
from robomech.mechanisms import vectored_thrust as vt
from robomech.verify import omnileg as v_ol
from robomech.verify import vectored_thrust as v_vt

P = "robomech.verify."
RECORD = Exempt(
    "record type of the verification layer: built by the library (or a fixture), no input to check"
)
LEG_OL = ol.OmniLeg.paper()
LEG_SL = sl.SphericalLeg.paper()
TH = vt.VectoredThruster()
ROBOT = ss.ExplorationRobot.paper()
_Q3 = np.array([[0.1, 0.2, 0.5], [-0.2, 0.1, 0.7]])
JM = ol.joint_motion(LEG_OL, _Q3, 0.1 * _Q3, 0.2 * _Q3)
EM = v_ol.build_model(LEG_OL)
_Q2 = np.array([[0.1, 0.2], [0.0, -0.1]])
_T = np.array([0.0, 0.5, 1.0])
_TRAJ = v_vt.table1_trajectory(_T)
_OMEGA_DOT = vt.angular_acceleration(TH, *_TRAJ).omega_dot  # (3, 3), the analytic model's

SPECS = {
    **exempt("Check VerificationReport Verification", RECORD, P),
    P + "Tolerance": Spec(
        args={"value": 1e-6, "reason": "engine constraint stiffness", "relative": False},
        options={"value": BAD_POSITIVE, "reason": (None, "", " ", 1), "relative": BAD_BOOL},
    ),
    P + "available_verifications": Spec(args={}),
    P + "run_verifications": Spec(
        args={"names": ["omnileg"]},
        options={"names": (["no-such-mechanism"], "omnileg", 1)},
        good_elsewhere="tests/verify/test_verify_omnileg.py",
    ),
    **exempt("VERIFICATION", CONSTANT, P + "continuum."),
    # omnileg
    P + "omnileg.VERIFICATION": CONSTANT,
    P + "omnileg.EngineModel": RECORD,
    P + "omnileg.build_mjcf": Spec(args={"leg": LEG_OL}, params=("leg",)),
    P + "omnileg.build_model": Spec(args={"leg": LEG_OL}, params=("leg",)),
    P + "omnileg.engine_inverse_dynamics": Spec(
        args={"em": EM, "jm": JM, "foot_force": np.array([0.0, 0.0, 1.0])},
        arrays={"foot_force": 1},
        params=("em", "jm"),
    ),
    P + "omnileg.run": Spec(args={}, good_elsewhere="tests/verify/test_verify_omnileg.py"),
    # skid_steer
    P + "skid_steer.VERIFICATION": CONSTANT,
    **exempt("GroundTruth Terrain", RECORD, P + "skid_steer."),
    P + "skid_steer.simulate": Spec(
        args={
            "robot": ROBOT,
            "duration": 0.05,
            "rate": 100.0,
            "terrain": None,
            "v_left": 0.1,
            "speed_ratio": 2.0,
            "icr_x": 0.05,
        },
        params=("robot",),
        options={
            "duration": BAD_POSITIVE,
            "rate": BAD_POSITIVE,
            "v_left": BAD_REAL,
            "speed_ratio": BAD_REAL,
            "icr_x": BAD_REAL,
            "terrain": ("uneven", 1.0),
        },
    ),
    P + "skid_steer.run_checks": Spec(
        args={"robot": ROBOT, "estimator_robot": ROBOT},
        params=("robot", "estimator_robot"),
        good_elsewhere="tests/verify/test_verify_skid_steer.py",
    ),
    # spherical_leg
    P + "spherical_leg.VERIFICATION": CONSTANT,
    P + "spherical_leg.build_model": Spec(
        args={"leg": LEG_SL, "timestep": 2e-4}, params=("leg",), options={"timestep": BAD_POSITIVE}
    ),
    P + "spherical_leg.inverse_dynamics_engine": Spec(
        args={"leg": LEG_SL, "q": _Q2, "qd": 0.1 * _Q2, "qdd": 0.2 * _Q2, "driven_legs": (0, 2)},
        arrays={"q": 1, "qd": 1, "qdd": 1},
        wrong_shapes={"q": ((2, 3), (2,)), "qd": ((3, 2),), "qdd": ((2, 3),)},
        params=("leg",),
        options={"driven_legs": ((0, 0), (0, 3), (0,), "ab", 1, (0.5, 1.0), (True, False))},
    ),
    P + "spherical_leg.run_checks": Spec(
        args={"analytic": LEG_SL, "paper_as_printed": False},
        params=("analytic",),
        options={"paper_as_printed": BAD_BOOL},
        good_elsewhere="tests/verify/test_verify_spherical_leg.py",
    ),
    P + "spherical_leg.study_overlays": Spec(
        args={"leg": LEG_SL}, params=("leg",), good_elsewhere="tests/verify/test_verify_spherical_leg.py"
    ),
    # vectored_thrust
    P + "vectored_thrust.VERIFICATION": CONSTANT,
    P + "vectored_thrust.EngineTrace": RECORD,
    P + "vectored_thrust.table1_trajectory": Spec(
        args={"t": _T, "amplitude": 0.5, "omega": 1.0},
        arrays={"t": 0},
        options={"amplitude": BAD_REAL, "omega": BAD_REAL},
    ),
    P + "vectored_thrust.build_mjcf": Spec(
        args={"th": TH, "actuated": False}, params=("th",), options={"actuated": BAD_BOOL}
    ),
    P + "vectored_thrust.engine_trace": Spec(
        args={
            "th": TH,
            "t": _T,
            "q": _TRAJ[0],
            "qd": _TRAJ[1],
            "qdd": _TRAJ[2],
            "omega_dot_model": _OMEGA_DOT,
            "analytic": TH,
        },
        arrays={"t": 0, "q": 1, "qd": 1, "qdd": 1, "omega_dot_model": 1},
        wrong_shapes={"t": ((2,),), "q": ((3, 3), (2, 2)), "omega_dot_model": ((3, 4), (2, 3))},
        params=("th", "analytic"),
    ),
    P + "vectored_thrust.run": Spec(
        args={"th": TH, "omega_dot_model": None, "analytic": TH},
        params=("th", "analytic"),
        options={"omega_dot_model": ("model", 1.0)},
        good_elsewhere="tests/verify/test_verify_vectored_thrust.py",
    ),
}
