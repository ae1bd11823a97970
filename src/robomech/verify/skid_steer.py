"""Paper 4: an independent ground truth for the skid-steer velocity estimator.

A kinematic rigid-body simulation of the robot on uneven ground, written apart from the estimator (it
shares only the parameter dataclass and the core ``spatial`` module): 4×4 transform chains for the
wheel contact frames, a terrain height field, Newton's method (with its own finite-difference
Jacobian) to keep all six wheels on the ground, and velocities by 5-point central differences in
time of the poses and contact positions.  It plays the part of the paper's RecurDyn run.

Motion: the body's ground track is that of an ideal skid-steered vehicle with the right tracks at
``speed_ratio`` times the left (a circle, with the centre of rotation ``icr_x`` ahead of the body
centre, which makes the body slide sideways); height, roll and pitch follow planes fitted to the
terrain under the wheels; the differential makes the body pitch the mean of the two rocker pitches;
the bogie, side links and rear slides take whatever values put the wheels on the ground.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from robomech._validation import check_params, check_positive, check_real
from robomech.mechanisms.skid_steer import (
    ExplorationRobot,
    ICRModel,
    body_velocity,
    dead_reckoning,
    encoder_track_speeds,
    icr_velocity,
    identify_icr,
)
from robomech.spatial import rot_x, rot_y, rot_z, transform, vee

from ._core import Check, Tolerance, Verification
from ._skid_steer_engine import EngineParams, EngineRun, Terrain, simulate_engine

__all__ = [
    "VERIFICATION",
    "EngineParams",
    "EngineRun",
    "GroundTruth",
    "Terrain",
    "engine_checks",
    "engine_runs",
    "run_checks",
    "simulate",
    "simulate_engine",
]

# Newton on the contact conditions stops when every residual is below this (m): a few hundred eps of
# the 0.3 m geometry, the level below which the residual is rounding.
CONTACT_TOL = 1e-13
# Iteration cap for Newton; from the nominal guess it converges in about 6 iterations.
NEWTON_MAX_ITER = 30
# Forward-difference step (rad or m) of Newton's Jacobian: sqrt(eps) scale for O(0.1) quantities.
NEWTON_FD_STEP = 1e-7
# Time step (s) of the 5-point central differences that give all velocities: truncation h^4 f^(5)/30
# ~ 1e-13 for the terrain frequencies used (~4 rad/s), rounding eps |x| / h ~ 1e-13.
TIME_FD_STEP = 1e-3

_SIGN = (-1.0, 1.0)  # side 1 right at y = -b, side 2 left at y = +b


@dataclass(frozen=True)
class GroundTruth:
    """Simulated run, ``N`` samples.

    ``T_GB (N, 4, 4)`` body poses; ``twist (N, 6)`` body twists ``[ω_B; v_B]`` in body axes;
    ``config``/``config_rate (N, 8)``; ``measured (N, 22)`` exact measurements in the estimator's
    layout; ``contact_world (N, 6, 3)``; ``contact_residual (N, 6)`` height above the terrain of each
    contact (m); ``converged (N,)``; ``track_speeds (2,)`` right/left commanded speeds (m/s).
    """

    t: np.ndarray
    T_GB: np.ndarray
    twist: np.ndarray
    config: np.ndarray
    config_rate: np.ndarray
    measured: np.ndarray
    contact_world: np.ndarray
    contact_residual: np.ndarray
    converged: np.ndarray
    track_speeds: np.ndarray
    icr_x: float


def _trans(x, y, z) -> np.ndarray:
    x, y, z = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float), np.asarray(z, float))
    return transform(np.broadcast_to(np.eye(3), (*x.shape, 3, 3)), np.stack([x, y, z], axis=-1))


def _contacts_in_body(robot: ExplorationRobot, q: np.ndarray) -> np.ndarray:
    """``T_BP (..., 6, 4, 4)`` by explicit transform chains (independent of the estimator's kernel)."""
    out = []
    ls, rk = robot.side_link_length, robot.side_link_rake
    link_to_contact = _trans(-ls * np.sin(rk), 0.0, -ls * np.cos(rk) - robot.road_wheel_radius)
    for side in range(2):
        th, t1, t2, s = (q[..., 4 * side + k] for k in range(4))
        zero = np.zeros_like(th)
        pivot = np.stack([zero, zero + _SIGN[side] * robot.rocker_lateral_offset, zero], -1)
        T_BR = transform(rot_y(th), pivot)
        T_RH = _trans(robot.bogie_hinge_x + zero, 0.0, -robot.bogie_hinge_drop) @ transform(
            rot_y(t1), np.zeros(3)
        )
        T_BH = T_BR @ T_RH
        link = transform(rot_y(t2), np.zeros(3))
        T_F = T_BH @ _trans(robot.side_link_hinge_offset, 0.0, 0.0) @ link @ link_to_contact
        T_H = T_BH @ _trans(-robot.side_link_hinge_offset, 0.0, 0.0) @ link @ link_to_contact
        T_P = T_BR @ _trans(-robot.rear_arm_length + zero, 0.0, -(s + robot.rear_wheel_radius))
        out += [T_F, T_H, T_P]
    return np.stack(out, axis=-3)


def _planar(t: np.ndarray, u: float, v: float, r: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Ground track of a body with constant body-frame velocity (u, v) and yaw rate r from the origin."""
    psi = r * t
    if r == 0.0:
        return u * t, v * t, psi
    x = (u * np.sin(psi) + v * np.cos(psi) - v) / r
    y = (-u * np.cos(psi) + v * np.sin(psi) + u) / r
    return x, y, psi


def _pose_and_config(
    robot: ExplorationRobot, terrain: Terrain, t: np.ndarray, u: float, v: float, r: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Body pose, configuration, contact residuals and convergence at times ``t``."""
    x, y, psi = _planar(t, u, v, r)
    zero = np.zeros_like(t)
    T0 = _contacts_in_body(robot, np.zeros(8))[:, :3, 3]  # nominal contacts (6, 3)
    cps, sps = np.cos(psi)[..., None], np.sin(psi)[..., None]
    wx = x[..., None] + cps * T0[:, 0] - sps * T0[:, 1]
    wy = y[..., None] + sps * T0[:, 0] + cps * T0[:, 1]
    h = terrain.height(wx, wy)  # (N, 6)
    # per side: least-squares line h = a_i + b_i ξ through its three nominal contacts
    side_pitch, side_height = [], []
    for side in range(2):
        xi = T0[3 * side : 3 * side + 3, 0]
        M = np.stack([np.ones(3), xi], axis=-1)
        coef = h[:, 3 * side : 3 * side + 3] @ np.linalg.pinv(M).T
        side_height.append(coef[:, 0])
        side_pitch.append(-np.arctan(coef[:, 1]))
    pitch = 0.5 * (side_pitch[0] + side_pitch[1])  # the differential: body pitch is the mean
    rocker = side_pitch[0] - pitch  # right rocker; the left one is its negative
    roll = np.arctan((side_height[1] - side_height[0]) / robot.track_width)
    z = 0.5 * (side_height[0] + side_height[1]) + robot.rear_wheel_drop + robot.rear_wheel_radius
    R = rot_z(psi) @ rot_y(pitch) @ rot_x(roll)
    T_GB = transform(R, np.stack([x, y, z], axis=-1))

    q = np.zeros((*t.shape, 8))
    q[..., 0], q[..., 4] = rocker, -rocker
    q[..., 3] = q[..., 7] = robot.rear_wheel_drop

    def residual(qq: np.ndarray) -> np.ndarray:
        P = (T_GB[..., None, :, :] @ _contacts_in_body(robot, qq))[..., :3, 3]
        return P[..., 2] - terrain.height(P[..., 0], P[..., 1])

    unknown = [1, 2, 3, 5, 6, 7]  # bogie, side link, slide of each side; each side's 3 wheels
    res = residual(q)
    for _ in range(NEWTON_MAX_ITER):
        if np.max(np.abs(res)) < CONTACT_TOL:
            break
        # The sides are independent (each side's wheels depend on its own joints only), so joint k of
        # both sides is perturbed together: 3 residual evaluations give both 3x3 Jacobians.
        Jn = np.zeros((*t.shape, 2, 3, 3))
        for k in range(3):
            qq = q.copy()
            qq[..., [unknown[k], unknown[k + 3]]] += NEWTON_FD_STEP
            col = (residual(qq) - res) / NEWTON_FD_STEP
            Jn[..., 0, :, k] = col[..., 0:3]
            Jn[..., 1, :, k] = col[..., 3:6]
        step = np.linalg.solve(Jn, res.reshape(*t.shape, 2, 3, 1))[..., 0].reshape(*t.shape, 6)
        q[..., unknown] -= step
        res = residual(q)
    return T_GB, q, res, np.all(np.abs(res) < CONTACT_TOL, axis=-1) & (zero == 0)


def simulate(
    robot: ExplorationRobot,
    duration: float = 50.0,
    rate: float = 1000.0,
    *,
    terrain: Terrain | None = None,
    v_left: float = 0.10,
    speed_ratio: float = 2.0,
    icr_x: float = 0.05,
) -> GroundTruth:
    """Simulate ``duration`` s sampled at ``rate`` Hz; the right tracks run at ``speed_ratio × v_left``."""
    check_params(robot, ExplorationRobot, "robot")
    duration, rate = check_positive(duration, "duration"), check_positive(rate, "rate")
    v_left, icr_x = check_real(v_left, "v_left"), check_real(icr_x, "icr_x")
    speed_ratio = check_real(speed_ratio, "speed_ratio")
    terrain = Terrain.uneven() if terrain is None else terrain
    check_params(terrain, Terrain, "terrain")
    n = round(duration * rate) + 1
    t = np.arange(n) / rate
    v1, v2 = speed_ratio * v_left, v_left
    r = (v1 - v2) / robot.track_width
    u = 0.5 * (v1 + v2)
    v = -r * icr_x  # lateral velocity of the body centre, centre of rotation icr_x ahead of it
    h = TIME_FD_STEP
    stencil = (-2, -1, 1, 2)
    weights = np.array([1.0, -8.0, 8.0, -1.0]) / (12.0 * h)
    T_GB, q, res, conv = _pose_and_config(robot, terrain, t, u, v, r)
    P = T_GB[..., None, :, :] @ _contacts_in_body(robot, q)
    dT = np.zeros_like(T_GB)
    dq = np.zeros_like(q)
    dP = np.zeros((n, 6, 3))
    for k, wgt in zip(stencil, weights, strict=True):
        Tk, qk, _, ck = _pose_and_config(robot, terrain, t + k * h, u, v, r)
        conv &= ck
        dT += wgt * Tk
        dq += wgt * qk
        dP += wgt * (Tk[..., None, :, :] @ _contacts_in_body(robot, qk))[..., :3, 3]
    R = T_GB[..., :3, :3]
    Rt = np.swapaxes(R, -1, -2)
    W = Rt @ dT[..., :3, :3]
    w_B = vee(0.5 * (W - np.swapaxes(W, -1, -2)))
    v_B = np.einsum("...ij,...j->...i", Rt, dT[..., :3, 3])
    twist = np.concatenate([w_B, v_B], axis=-1)
    R_GP = P[..., :3, :3]
    v_P = np.einsum("...ji,...j->...i", R_GP, dP)  # contact velocities in contact axes
    meas = np.zeros((n, 22))
    meas[:, :18] = v_P.reshape(n, 18)
    meas[:, 18] = w_B[:, 1] + dq[:, 0]
    meas[:, 19] = w_B[:, 1] + dq[:, 4]
    meas[:, 20] = w_B[:, 2]
    meas[:, 21] = w_B[:, 0]
    return GroundTruth(
        t=t,
        T_GB=T_GB,
        twist=twist,
        config=q,
        config_rate=dq,
        measured=meas,
        contact_world=P[..., :3, 3],
        contact_residual=res,
        converged=conv,
        track_speeds=np.array([v1, v2]),
        icr_x=icr_x,
    )


# --- checks -----------------------------------------------------------------------------------------

TOL_CONTACT = Tolerance(1e-12, "Newton stops at 1e-13 m; the wheels are on the terrain to rounding")
TOL_ESTIMATE = Tolerance(
    1e-9,
    "noise-free estimate vs simulated truth: 5-point time differences (~1e-12) plus QR rounding "
    "cond(A0)·eps (~1e-14); the issue's target",
)
TOL_RATES = Tolerance(1e-9, "passive joint rates: same sources, divided by lever arms of 5-30 cm")
TOL_DEAD_RECKONING = Tolerance(
    1e-6, "pose from integrating the true twists at 200 Hz with the mean-twist rule: O(dt²) drift over 10 s"
)
# --- engine checks (MuJoCo contact physics, ``_skid_steer_engine``) ---
TOL_ENGINE_TWIST = Tolerance(
    1.5e-4,
    "30x11 estimate from the engine's carrier-fixed contact velocities vs the engine's chassis twist: "
    "exact kinematics except the soft joint equalities (parallelogram, differential), measured 5e-5; "
    "a 10 % track-width error gives 4e-4",
)
TOL_ENGINE_SPEED = Tolerance(
    0.02,
    "straight run on flat ground: encoder speed r·φ̇ vs the engine's forward speed; MuJoCo's soft "
    "contact leaves ~0.4 % longitudinal creep; a 10 % radius error gives > 6 %",
    relative=True,
)
TOL_ENGINE_ICR = Tolerance(
    0.03,
    "yaw rate of the ICR model identified on five other flat manoeuvres vs the engine, RMS over "
    "validation turns (rad/s): χ varies with the turn, measured 0.011; the no-slip formula errs 0.2",
)


def run_checks(
    robot: ExplorationRobot | None = None, estimator_robot: ExplorationRobot | None = None
) -> list[Check]:
    """All checks; ``estimator_robot`` (default: ``robot``) is the geometry the estimator believes."""
    robot = ExplorationRobot.paper() if robot is None else robot
    est = robot if estimator_robot is None else estimator_robot
    check_params(robot, ExplorationRobot, "robot")
    check_params(est, ExplorationRobot, "estimator_robot")
    gt = simulate(robot, duration=10.0, rate=200.0)
    name = "skid-steer"
    contact = float(np.max(np.abs(gt.contact_residual)))
    checks = [
        Check(
            name,
            "ground truth: contact height residual (m)",
            contact,
            TOL_CONTACT,
            f"{gt.t.size} samples, converged {bool(np.all(gt.converged))}",
        )
    ]
    bv = body_velocity(est, gt.config, gt.measured)
    err = np.where(bv.valid[:, None], np.abs(bv.twist - gt.twist), np.inf)
    checks.append(
        Check(
            name,
            "noise-free body twist vs truth (m/s, rad/s)",
            float(np.max(err)),
            TOL_ESTIMATE,
            f"max cond(A0) {np.nanmax(bv.cond):.1f}",
        )
    )
    err = np.where(bv.valid[:, None], np.abs(bv.config_rate - gt.config_rate), np.inf)
    checks.append(Check(name, "noise-free joint rates vs truth (rad/s, m/s)", float(np.max(err)), TOL_RATES))
    T = dead_reckoning(gt.twist, gt.t[1] - gt.t[0], gt.T_GB[0])
    drift = float(np.max(np.linalg.norm(T[:, :3, 3] - gt.T_GB[:, :3, 3], axis=-1)))
    checks.append(Check(name, "dead reckoning of true twists: position (m)", drift, TOL_DEAD_RECKONING))
    checks += engine_checks(robot, est)
    return checks


# Engine manoeuvres (right, left track speeds, m/s): identification set and validation set (disjoint).
IDENTIFICATION_RUNS = ((0.25, 0.05), (0.05, 0.25), (0.3, 0.15), (0.2, -0.1), (0.1, 0.3))
VALIDATION_TURNS = ((0.3, 0.1), (0.15, 0.25), (0.2, 0.0))
ENGINE_RUN_S = 3.0  # s recorded per manoeuvre
ENGINE_RATE = 50.0  # Hz recorded
ENGINE_TRANSIENT_S = 1.0  # s after the start discarded (commands ramp in over 0.5 s, then settle)


@functools.lru_cache(maxsize=4)
def engine_runs(robot: ExplorationRobot) -> dict[str, tuple[EngineRun, ...]]:
    """The engine manoeuvres of the checks for the true ``robot`` (cached: the teeth tests reuse them)."""
    check_params(robot, ExplorationRobot, "robot")
    sim = functools.partial(simulate_engine, robot, duration=ENGINE_RUN_S, rate=ENGINE_RATE)
    return {
        "identification": tuple(sim(v) for v in IDENTIFICATION_RUNS),
        "validation": tuple(sim(v) for v in VALIDATION_TURNS),
        "straight": (sim((0.2, 0.2)),),
        "uneven": (sim((0.25, 0.1), terrain=Terrain.uneven()),),
    }


def planar_twist(run: EngineRun) -> np.ndarray:
    """``(v_x, v_y, r)`` of the chassis in body axes, ``(N, 3)``."""
    return np.stack([run.twist[:, 3], run.twist[:, 4], run.twist[:, 2]], axis=-1)


def steady(run: EngineRun) -> slice:
    return slice(round(ENGINE_TRANSIENT_S * run.rate), None)


def identify_from_runs(robot: ExplorationRobot, runs) -> ICRModel:
    """ICR model identified from encoder speeds (``robot``'s radii) and the engine's body twists."""
    parts = []
    for u in runs:
        sl = steady(u)
        tr = encoder_track_speeds(robot, u.wheel_rate[sl])
        vr, vl = tr.right, tr.left
        parts.append((vr, vl, planar_twist(u)[sl]))
    vr, vl, V = (np.concatenate(x) for x in zip(*parts, strict=True))
    ident = identify_icr(vr, vl, V)
    if not ident.identifiable or ident.model is None:
        raise RuntimeError("ICR identification data carry no turning (internal manoeuvre set is wrong).")
    return ident.model


def engine_checks(robot: ExplorationRobot, est: ExplorationRobot) -> list[Check]:
    """Checks of the estimators against the MuJoCo contact-physics ground truth (``robot``: the true
    geometry the engine is built from; ``est``: the geometry the estimators believe)."""
    check_params(robot, ExplorationRobot, "robot")
    check_params(est, ExplorationRobot, "est")
    runs = engine_runs(robot)
    name = "skid-steer"
    checks = []
    err = []
    for u in (*runs["validation"], *runs["uneven"]):
        sl = steady(u)
        bv = body_velocity(est, u.config[sl], u.measured[sl])
        e = np.abs(bv.twist - u.twist[sl])[:, [0, 2, 3, 4, 5]]
        err.append(np.where(bv.valid[:, None], e, np.inf).max())
    contact = min(float(u.in_contact.mean()) for u in (*runs["validation"], *runs["uneven"]))
    checks.append(
        Check(
            name,
            "engine: 30x11 body twist (ω_BX, ω_BZ, v_B) vs MuJoCo (m/s, rad/s)",
            float(max(err)),
            TOL_ENGINE_TWIST,
            f"3 flat turns + uneven ground; wheels in contact ≥ {100 * contact:.0f} % of samples",
        )
    )
    u = runs["straight"][0]
    sl = steady(u)
    tr = encoder_track_speeds(est, u.wheel_rate[sl])
    speed = 0.5 * (tr.right + tr.left)
    rel = float(np.max(np.abs(speed - u.twist[sl, 3])) / np.mean(np.abs(u.twist[sl, 3])))
    checks.append(
        Check(name, "engine: straight flat run, encoder speed vs MuJoCo (relative)", rel, TOL_ENGINE_SPEED)
    )
    model = identify_from_runs(est, runs["identification"])
    no_slip = ICRModel.no_slip(est.track_width)
    e_icr, e_ns = [], []
    for u in runs["validation"]:
        sl = steady(u)
        tr = encoder_track_speeds(est, u.wheel_rate[sl])
        vr, vl = tr.right, tr.left
        e_icr.append(icr_velocity(model, vr, vl).yaw_rate - u.twist[sl, 2])
        e_ns.append(icr_velocity(no_slip, vr, vl).yaw_rate - u.twist[sl, 2])
    rms_icr = float(np.sqrt(np.mean(np.concatenate(e_icr) ** 2)))
    rms_ns = float(np.sqrt(np.mean(np.concatenate(e_ns) ** 2)))
    checks.append(
        Check(
            name,
            "engine: flat turns, yaw rate of the identified ICR model vs MuJoCo, RMS (rad/s)",
            rms_icr,
            TOL_ENGINE_ICR,
            f"χ = {model.track_width_factor(est.track_width):.2f}; no-slip (v1−v2)/S RMS error "
            f"{rms_ns:.3f} rad/s ({rms_ns / rms_icr:.0f}× larger)",
        )
    )
    return checks


VERIFICATION = Verification(
    name="skid-steer",
    title="Skid-steer estimators vs an independent kinematic simulation and MuJoCo contact physics",
    engine="kinematic rigid-body simulation (transform chains + Newton contact) and MuJoCo (MjSpec model, "
    "wheel-ground friction, height field)",
    run=run_checks,
    requires=("mujoco",),  # the contact-physics checks; skipped without robomech[verify]
)
