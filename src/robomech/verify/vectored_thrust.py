"""Paper 5 (vectored thruster) against MuJoCo: closure, propeller pose, angular velocity and acceleration.

The engine model is the generic export of the mechanism's description,
``mb.to_mjcf(vt.to_multibody(th))`` (no hand-written MJCF): two open trees from the base -- the RR
chain (hinge ``q2`` about Y, hinge ``theta`` about s22(0)) ending in the platform, and the RRR chain
(hinge ``q1`` about X, hinge ``rho2`` about s12(0)) ending in the second arc -- closed by the revolute
joint s13 of the RRR chain, which MJCF writes as two ``connect`` equalities along its axis.  Along the
Table 1 trajectory the analytic joint positions, rates and accelerations (inputs and passive joints,
``vt.passive_angles`` / ``passive_rates`` / ``angular_acceleration``) are written into
``qpos``/``qvel``/``qacc`` and the engine computes, by its own tree kinematics:

* the closure violation (``efc_pos`` of the equality rows) and its rate ``efc_J @ qvel``;
* the propeller site's position and orientation -- vs the analytic forward kinematics;
* the platform orientation reached through the RRR tree, ``R_arc2 exp(s13(0) rho3)``;
* the platform's angular velocity (``mj_objectVelocity``) on the RR tree, and through the RRR tree
  (the second arc's engine angular velocity plus the closure hinge's rate about its engine axis);
* the same for the angular acceleration (``mj_rnePostConstraint`` + ``mj_objectAcceleration``; on
  the RRR side plus ``rho3'' s13 + w_arc2 x rho3' s13``), vs the analytic Lie-bracket model.

A forward simulation (constraints active, inputs driven by stiff position servos along the trajectory)
checks that the engine's propeller axis equals the analytic FK of the engine's own inputs.  The
description has no inertias (the paper gives none): MuJoCo derives them from the exported visual
geoms, and the servo gains follow from the engine's own inertia (bandwidth ``SIM_SERVO_BANDWIDTH``).

MuJoCo is float64 throughout; with exact joint data its tree kinematics agree with the closed forms to
rounding, so the kinematic tolerances are set far below the issue's 1e-6 relative requirement.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from robomech._validation import as_array, check_bool, check_params, check_real
from robomech.mechanisms import vectored_thrust as vt
from robomech.spatial import exp_so3

from ._core import Check, Tolerance, Verification, optional_module
from ._mujoco import Engine, engine_options
from ._store import checks_from_arrays, checks_to_arrays, computed_once

if TYPE_CHECKING:
    import mujoco
else:  # imported on first use: discovering this module must not need the optional engine
    mujoco = optional_module("mujoco")

__all__ = ["VERIFICATION", "EngineTrace", "build_mjcf", "engine_trace", "run", "table1_trajectory"]

Array = NDArray[np.float64]

# Exact joint data, float64 tree kinematics on both sides: differences are rounding (~1e-15); 1e-9
# relative leaves room for MuJoCo's quaternion/rotation-matrix conversions.
KINEMATIC_TOL = Tolerance(
    1e-9, "float64 tree kinematics with exact joint data (rounding only)", relative=True
)
# Accelerations go through the passive-acceleration solve near the closest approach to the singularity
# (1/|s22 x s12|^2 <= 7 on the trajectory): 1e-8 relative.
ACCELERATION_TOL = Tolerance(
    1e-8, "float64 engine RNE vs Lie-bracket model, conditioning <= 10", relative=True
)
CLOSURE_TOL = Tolerance(1e-12, "exact analytic joint positions; rounding only")
CLOSURE_RATE_TOL = Tolerance(1e-12, "exact analytic joint rates; rounding only")
# Forward simulation: soft connects (solref 2 ms) under servo forces and timestep 0.2 ms leave a
# constraint violation of order 1e-4 rad; the axis must match FK(engine inputs) to 1e-3 (0.06 deg).
SIMULATION_TOL = Tolerance(1e-3, "soft equality constraints (solref 2 ms), dt 0.2 ms, servo-driven inputs")

N_SAMPLES = 241  # trajectory samples for the kinematic checks (one period of Table 1's sinusoids)
SIM_DURATION = 2.0  # seconds of forward simulation (a slowed Table 1 trajectory: period 4 s)
SIM_TIMESTEP = 2e-4
# Position servos on q1, q2: kp = I w^2, kv = 2 I w (critically damped) with I the engine's own joint
# inertia at q = 0; w = 200 rad/s is well below 1/SIM_TIMESTEP and far above the 1.6 rad/s motion.
SIM_SERVO_BANDWIDTH = 200.0
_SOLREF = "0.002 1"


def table1_trajectory(
    t: np.ndarray, amplitude: float = np.pi / 4, omega: float = 1.0
) -> tuple[np.ndarray, ...]:
    """Table 1: q1 = (pi/4) sin(w t), q2 = -(pi/4) sin(w t); returns q, qd, qdd (..., 2)."""
    t = as_array(t, "t")
    amplitude = check_real(amplitude, "amplitude")
    omega = check_real(omega, "omega")
    s, c = np.sin(omega * t), np.cos(omega * t)
    sign = np.array([1.0, -1.0])
    q = amplitude * s[..., None] * sign
    qd = amplitude * omega * c[..., None] * sign
    qdd = -amplitude * omega**2 * s[..., None] * sign
    return q, qd, qdd


def build_mjcf(th: vt.VectoredThruster, *, actuated: bool = False) -> str:
    """MJCF of the mechanism: ``mb.to_mjcf(vt.to_multibody(th))`` (home pose q = 0: every body frame
    at O, identity orientation) with the simulation options; ``actuated=False`` drops the actuators
    (the kinematic checks), ``True`` keeps the exported ones on q1, q2 (made position servos by
    :func:`_servo_model`)."""
    check_params(th, vt.VectoredThruster, "th")
    actuated = check_bool(actuated, "actuated")
    from robomech import multibody as mb

    root = engine_options(
        mb.to_mjcf(vt.to_multibody(th)), timestep=SIM_TIMESTEP, integrator="implicitfast", solref=_SOLREF
    )
    act = root.find("actuator")
    if act is not None and not actuated:
        root.remove(act)
    return ET.tostring(root, encoding="unicode")


def _servo_model(th: vt.VectoredThruster) -> mujoco.MjModel:
    """The actuated engine model with its q1, q2 actuators made position servos (MuJoCo's
    ``<position>``: gain kp, bias ``-kp q - kv qd``), gains from the engine's own inertia."""
    eng = Engine(mujoco.MjModel.from_xml_string(build_mjcf(th, actuated=True)))
    m = eng.model
    eng.set_state(np.zeros(m.nq))
    M = eng.mass_matrix()
    w = SIM_SERVO_BANDWIDTH
    for a in range(m.nu):
        dof = int(m.jnt_dofadr[m.actuator_trnid[a, 0]])
        inertia = float(M[dof, dof])
        kp, kv = inertia * w * w, 2.0 * inertia * w
        m.actuator_gainprm[a, 0] = kp
        m.actuator_biastype[a] = mujoco.mjtBias.mjBIAS_AFFINE
        m.actuator_biasprm[a, :3] = (0.0, -kp, -kv)
    return m


@dataclass(frozen=True)
class EngineTrace:
    """Engine and analytic quantities along a trajectory (n samples).

    ``*_rrr``: the platform reached through the RRR tree (the second arc's engine pose, velocity and
    acceleration composed with the closure hinge s13 at its analytic angle, rate and acceleration)."""

    t: np.ndarray
    closure: np.ndarray  # (n,) max |efc_pos| of the equality rows (m)
    closure_rate: np.ndarray  # (n,) max |efc_J qvel| of the equality rows
    tip_engine: np.ndarray  # (n, 3) m
    tip_analytic: np.ndarray
    R_engine: np.ndarray  # (n, 3, 3) propeller site (RR tree)
    R_engine_rrr: np.ndarray  # (n, 3, 3) second arc x exp(s13(0) rho3)
    R_analytic: np.ndarray
    omega_engine: np.ndarray  # (n, 3) rad/s, platform (RR tree)
    omega_engine_rrr: np.ndarray  # (n, 3) rad/s, through the RRR tree
    omega_analytic: np.ndarray
    omega_dot_engine: np.ndarray  # (n, 3) rad/s^2, platform (RR tree)
    omega_dot_engine_rrr: np.ndarray  # (n, 3), through the RRR tree
    omega_dot_analytic: np.ndarray


def _joint_data(
    th: vt.VectoredThruster, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray
) -> tuple[dict[str, Array], ...]:
    """Analytic joint positions, rates, accelerations by engine joint name (and the closure's rho3)."""
    p = vt.passive_angles(th, q).values
    r = vt.passive_rates(th, q, qd).values
    a = vt.angular_acceleration(th, q, qd, qdd).passive_acc

    def by_name(inp: Array, pas: Array) -> dict[str, Array]:
        return {"q1": inp[:, 0], "q2": inp[:, 1], "theta": pas[:, 0], "rho2": pas[:, 1], "rho3": pas[:, 2]}

    return by_name(q, p), by_name(qd, r), by_name(qdd, a)


def engine_trace(
    th: vt.VectoredThruster,
    t: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    omega_dot_model: np.ndarray | None = None,
    *,
    analytic: vt.VectoredThruster | None = None,
) -> EngineTrace:
    """Evaluate engine and analytic kinematics at trajectory samples ``q, qd, qdd (n, 2)``.

    The engine is built from ``th``; the analytic side (joint data, FK, rates, accelerations) from
    ``analytic`` (default ``th``): pass a perturbed one to see the comparison fail."""
    check_params(th, vt.VectoredThruster, "th")
    if analytic is not None:
        check_params(analytic, vt.VectoredThruster, "analytic")
    an = th if analytic is None else analytic
    t = as_array(t, "t", (None,))
    q, qd, qdd = (as_array(v, k, (2,), min_ndim=2) for v, k in ((q, "q"), (qd, "qd"), (qdd, "qdd")))
    if not (t.ndim == 1 and q.shape == qd.shape == qdd.shape == (t.shape[0], 2)):
        raise ValueError(
            f"Expected t (n,) and q, qd, qdd (n, 2), got {t.shape}, {q.shape}, {qd.shape}, {qdd.shape}."
        )
    if omega_dot_model is not None:
        omega_dot_model = as_array(omega_dot_model, "omega_dot_model", (3,))
        if omega_dot_model.shape != (t.shape[0], 3):
            raise ValueError(
                f"Expected omega_dot_model (n, 3) at the n = {t.shape[0]} samples of t, q, qd, qdd, "
                f"got {omega_dot_model.shape}."
            )
    mech = vt.to_multibody(th)
    hinge = mech.closures[0]  # the RRR chain's s13 joint, a revolute closure rrr_arc2 -> platform
    s13_local = np.asarray(hinge.axis, dtype=float)
    eng = Engine(mujoco.MjModel.from_xml_string(build_mjcf(th)))
    m, d = eng.model, eng.data
    pos, vel, acc = _joint_data(an, q, qd, qdd)
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(m.njnt)]
    qadr, dadr = eng.joint_addresses(names)
    bid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "platform")
    bid_rrr = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, hinge.body1)
    sid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "propeller")
    n = t.shape[0]
    out = {k: np.zeros((n, 3)) for k in ("tip", "w", "w3", "wd", "wd3")}
    R, R3 = np.zeros((n, 3, 3)), np.zeros((n, 3, 3))
    closure, closure_rate = np.zeros(n), np.zeros(n)
    res = np.zeros(6)
    E3 = exp_so3(s13_local * pos["rho3"][:, None])  # (n, 3, 3) the closure hinge at its analytic angle
    for i in range(n):  # the engine is per-sample by nature
        eng.set_state(
            [pos[k][i] for k in names],
            [vel[k][i] for k in names],
            [acc[k][i] for k in names],
            qpos_index=qadr,
            dof_index=dadr,
        )
        Jc, efc_pos = eng.equality()
        closure[i] = np.abs(efc_pos).max()
        closure_rate[i] = np.abs(Jc @ d.qvel).max()
        out["tip"][i] = d.site_xpos[sid]
        R[i] = d.site_xmat[sid].reshape(3, 3)
        R_arc2 = d.xmat[bid_rrr].reshape(3, 3)
        R3[i] = R_arc2 @ E3[i]
        s13 = R_arc2 @ s13_local  # the hinge axis in the world, as the engine places the arc
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, bid, res, 0)
        out["w"][i] = res[:3]
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, bid_rrr, res, 0)
        w_arc2 = res[:3].copy()
        out["w3"][i] = w_arc2 + vel["rho3"][i] * s13
        mujoco.mj_rnePostConstraint(m, d)
        mujoco.mj_objectAcceleration(m, d, mujoco.mjtObj.mjOBJ_BODY, bid, res, 0)
        out["wd"][i] = res[:3]
        mujoco.mj_objectAcceleration(m, d, mujoco.mjtObj.mjOBJ_BODY, bid_rrr, res, 0)
        # a serial hinge on the arc: w' = w'_arc2 + rho3'' s13 + w_arc2 x (rho3' s13)
        out["wd3"][i] = res[:3] + acc["rho3"][i] * s13 + np.cross(w_arc2, vel["rho3"][i] * s13)
    fk = vt.forward_kinematics(an, q)
    wd_model = (
        vt.angular_acceleration(an, q, qd, qdd).omega_dot if omega_dot_model is None else omega_dot_model
    )
    return EngineTrace(
        t=t,
        closure=closure,
        closure_rate=closure_rate,
        tip_engine=out["tip"],
        tip_analytic=fk.tip,
        R_engine=R,
        R_engine_rrr=R3,
        R_analytic=vt.platform_rotation(an, q).R,
        omega_engine=out["w"],
        omega_engine_rrr=out["w3"],
        omega_analytic=vt.angular_velocity(an, q, qd).omega,
        omega_dot_engine=out["wd"],
        omega_dot_engine_rrr=out["wd3"],
        omega_dot_analytic=wd_model,
    )


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


def forward_simulation(
    th: vt.VectoredThruster, duration: float = SIM_DURATION, analytic: vt.VectoredThruster | None = None
) -> dict[str, np.ndarray]:
    """Simulate with constraints active, inputs servoed along a slowed Table 1 trajectory (period 4 s).

    Returns time, engine inputs (n, 2), engine propeller axis (n, 3) and the analytic FK of those inputs
    (``analytic``'s, default ``th``'s).
    """
    eng = Engine(_servo_model(th))
    m = eng.model
    sid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "propeller")
    jq, _ = eng.joint_addresses(["q1", "q2"])
    act = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, n) for n in ("act_q1", "act_q2")]
    w = 2 * np.pi / 4.0
    every = 50  # record every 50th step
    dt = m.opt.timestep
    times = dt * (1 + np.arange(0, round(duration / dt), every))
    eng.set_state(np.zeros(m.nq), np.zeros(m.nv))

    def servo(d: mujoco.MjData) -> None:  # position servos along the slowed Table 1 trajectory
        d.ctrl[act] = table1_trajectory(np.array(d.time), omega=w)[0]

    rec = eng.simulate(
        times, lambda d: (d.time, d.qpos[jq].copy(), d.site_xpos[sid] / th.propeller_arm), servo
    )
    ts, qs, axes = zip(*rec, strict=True)
    q = np.array(qs)
    return {
        "t": np.array(ts),
        "q": q,
        "axis_engine": np.array(axes),
        "axis_fk": vt.forward_kinematics(th if analytic is None else analytic, q).axis,
    }


def run(
    th: vt.VectoredThruster | None = None,
    omega_dot_model: Callable[[vt.VectoredThruster, Array, Array, Array], Array] | None = None,
    *,
    analytic: vt.VectoredThruster | None = None,
) -> list[Check]:
    """All checks along one period of the Table 1 trajectory (``omega_dot_model`` replaces the analytic
    ω̇).  The engine is built from ``th`` (default: the paper's); ``analytic`` (default ``th``) is the
    model being verified: pass a deliberately wrong one to see the checks fail."""
    th = vt.VectoredThruster.paper() if th is None else th
    check_params(th, vt.VectoredThruster, "th")
    if analytic is not None:
        check_params(analytic, vt.VectoredThruster, "analytic")
    an = th if analytic is None else analytic
    if omega_dot_model is not None and not callable(omega_dot_model):
        raise ValueError(f"Expected omega_dot_model to be a callable, got {type(omega_dot_model).__name__}.")
    if omega_dot_model is not None:  # a callable has no key: computed, never stored
        return _checks(th, omega_dot_model, an)
    # the study shows these checks: computed once per output folder (robomech.verify._store)
    return checks_from_arrays(
        computed_once("vectored-thrust.checks", (th, an), lambda: checks_to_arrays(_checks(th, None, an)))
    )


def _checks(
    th: vt.VectoredThruster,
    omega_dot_model: Callable[[vt.VectoredThruster, Array, Array, Array], Array] | None,
    an: vt.VectoredThruster,
) -> list[Check]:
    """The checks of :func:`run`, computed."""
    t = np.linspace(0.0, 2 * np.pi, N_SAMPLES)
    q, qd, qdd = table1_trajectory(t)
    wd_model = None if omega_dot_model is None else np.asarray(omega_dot_model(an, q, qd, qdd), dtype=float)
    tr = engine_trace(th, t, q, qd, qdd, wd_model, analytic=an)
    mech = "vectored-thrust"
    sim = forward_simulation(th, analytic=an)
    return [
        Check(
            mech,
            "loop closure |efc_pos| (s13 hinge as 2 connects), m",
            float(tr.closure.max()),
            CLOSURE_TOL,
        ),
        Check(mech, "closure rate |efc_J qvel|", float(tr.closure_rate.max()), CLOSURE_RATE_TOL),
        Check(mech, "propeller tip position (rel)", _rel(tr.tip_engine, tr.tip_analytic), KINEMATIC_TOL),
        Check(mech, "platform orientation (rel)", _rel(tr.R_engine, tr.R_analytic), KINEMATIC_TOL),
        Check(
            mech,
            "platform orientation, RRR tree (rel)",
            _rel(tr.R_engine_rrr, tr.R_analytic),
            KINEMATIC_TOL,
            detail="engine R_arc2 exp(s13(0) rho3)",
        ),
        Check(
            mech, "angular velocity, RR tree (rel)", _rel(tr.omega_engine, tr.omega_analytic), KINEMATIC_TOL
        ),
        Check(
            mech,
            "angular velocity, RRR tree (rel)",
            _rel(tr.omega_engine_rrr, tr.omega_analytic),
            KINEMATIC_TOL,
        ),
        Check(
            mech,
            "angular acceleration, RR tree (rel)",
            _rel(tr.omega_dot_engine, tr.omega_dot_analytic),
            ACCELERATION_TOL,
        ),
        Check(
            mech,
            "angular acceleration, RRR tree (rel)",
            _rel(tr.omega_dot_engine_rrr, tr.omega_dot_analytic),
            ACCELERATION_TOL,
        ),
        Check(
            mech,
            "forward sim: axis vs FK(engine q)",
            float(np.abs(sim["axis_engine"] - sim["axis_fk"]).max()),
            SIMULATION_TOL,
            detail=f"{sim['t'].size} samples over {SIM_DURATION} s",
        ),
    ]


VERIFICATION = Verification(
    name="vectored-thrust",
    title="Paper 5 vectored thruster vs MuJoCo (generic export of its description): closure, pose, "
    "angular velocity and acceleration",
    engine="MuJoCo",
    requires=("mujoco",),
    run=run,
)
