"""Paper 5 (vectored thruster) against MuJoCo: closure, propeller pose, angular velocity and acceleration.

The engine model is built from :class:`VectoredThruster`: two open trees from the base -- the RR chain
(hinge Y, hinge s22(0)) ending in the platform, and the RRR chain (hinge X, hinge s12(0), hinge s13(0))
ending in a copy of the platform frame -- closed by a ``weld`` equality between the two ends (the
platform's rigid connection).  Along the Table 1 trajectory the analytic joint positions, rates and
accelerations (inputs and passive joints) are written into ``qpos``/``qvel``/``qacc`` and the engine
computes, by its own tree kinematics:

* the weld violation (``efc_pos`` of the equality rows) -- the loop closure;
* the propeller tip site and the platform orientation -- vs the analytic forward kinematics;
* ``efc_J @ qvel`` of the equality rows and the platform's angular velocity (``mj_objectVelocity``);
* the platform's angular acceleration (``mj_rnePostConstraint`` + ``mj_objectAcceleration``) on *both*
  trees, vs the analytic Lie-bracket model.

A forward simulation (constraints active, inputs driven by stiff position servos along the trajectory)
checks that the engine's propeller axis equals the analytic FK of the engine's own inputs.

MuJoCo is float64 throughout; with exact joint data its tree kinematics agree with the closed forms to
rounding, so the kinematic tolerances are set far below the issue's 1e-6 relative requirement.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from robomech._validation import as_array, check_bool, check_params, check_real
from robomech.mechanisms import vectored_thrust as vt

from ._core import Check, Tolerance, Verification, optional_module

if TYPE_CHECKING:
    import mujoco
else:  # imported on first use: discovering this module must not need the optional engine
    mujoco = optional_module("mujoco")

__all__ = ["VERIFICATION", "EngineTrace", "build_mjcf", "engine_trace", "run", "table1_trajectory"]

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
# Forward simulation: soft weld (solref 2 ms) under servo forces and timestep 0.2 ms leave a constraint
# violation of order 5e-4 rad; the axis must match FK(engine inputs) to 1e-3 (0.06 deg).
SIMULATION_TOL = Tolerance(1e-3, "soft equality constraint (solref 2 ms), dt 0.2 ms, servo-driven inputs")

N_SAMPLES = 241  # trajectory samples for the kinematic checks (one period of Table 1's sinusoids)
SIM_DURATION = 2.0  # seconds of forward simulation (a slowed Table 1 trajectory: period 4 s)
SIM_TIMESTEP = 2e-4


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


def _vec(v: np.ndarray) -> str:
    return " ".join(f"{x:.17g}" for x in v)


def build_mjcf(th: vt.VectoredThruster, *, actuated: bool = False) -> str:
    """MJCF of the mechanism (home pose q = 0: every body frame at O, identity orientation)."""
    check_params(th, vt.VectoredThruster, "th")
    actuated = check_bool(actuated, "actuated")
    ca, sa = np.cos(th.arc_angle), np.sin(th.arc_angle)
    a12 = np.array([ca, 0.0, -sa])
    a13 = np.array([0.0, -1.0, 0.0])
    inert = '<inertial pos="0 0 0" mass="0.02" diaginertia="1e-5 1e-5 1e-5"/>'
    rr_mid = th.rr_arc_radius * np.array([-1.0, 1.0, 0.0]) / np.sqrt(2)
    r1 = th.rrr_arc1_radius * (np.array([1.0, 0, 0]) + a12) / np.linalg.norm(np.array([1.0, 0, 0]) + a12)
    r2 = th.rrr_arc2_radius * (a12 + a13) / np.linalg.norm(a12 + a13)
    act = ""
    if actuated:
        act = """
  <actuator>
    <position name="m1" joint="q1" kp="0.5" kv="0.005"/>
    <position name="m2" joint="q2" kp="0.5" kv="0.005"/>
  </actuator>"""
    return f"""<mujoco model="vectored_thruster">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{SIM_TIMESTEP}" gravity="0 0 0" integrator="implicitfast"/>
  <worldbody>
    <body name="rr_arc" pos="0 0 0">
      <joint name="q2" type="hinge" axis="0 1 0" damping="0.001"/>
      {inert}
      <geom type="sphere" size="0.003" pos="{_vec(rr_mid)}" contype="0" conaffinity="0"/>
      <body name="platform" pos="0 0 0">
        <joint name="theta" type="hinge" axis="-1 0 0"/>
        {inert}
        <geom type="capsule" fromto="0 0 0 0 0 {th.propeller_arm}" size="0.002" contype="0" conaffinity="0"/>
        <site name="tip" pos="0 0 {th.propeller_arm}"/>
      </body>
    </body>
    <body name="rrr_arc1" pos="0 0 0">
      <joint name="q1" type="hinge" axis="1 0 0" damping="0.001"/>
      {inert}
      <geom type="sphere" size="0.003" pos="{_vec(r1)}" contype="0" conaffinity="0"/>
      <body name="rrr_arc2" pos="0 0 0">
        <joint name="rho2" type="hinge" axis="{_vec(a12)}"/>
        {inert}
        <geom type="sphere" size="0.003" pos="{_vec(r2)}" contype="0" conaffinity="0"/>
        <body name="rrr_end" pos="0 0 0">
          <joint name="rho3" type="hinge" axis="{_vec(a13)}"/>
          {inert}
          <site name="rrr_tip" pos="0 0 {th.propeller_arm}"/>
        </body>
      </body>
    </body>
  </worldbody>
  <equality>
    <weld name="closure" body1="rrr_end" body2="platform" solref="0.002 1"/>
  </equality>{act}
</mujoco>"""


@dataclass(frozen=True)
class EngineTrace:
    """Engine and analytic quantities along a trajectory (n samples)."""

    t: np.ndarray
    closure: np.ndarray  # (n,) max |efc_pos| of the weld rows (m and rad)
    closure_rate: np.ndarray  # (n,) max |efc_J qvel| of the weld rows
    tip_engine: np.ndarray  # (n, 3) m
    tip_analytic: np.ndarray
    R_engine: np.ndarray  # (n, 3, 3)
    R_analytic: np.ndarray
    omega_engine: np.ndarray  # (n, 3) rad/s, platform (RR tree)
    omega_engine_rrr: np.ndarray  # (n, 3) rad/s, RRR tree end
    omega_analytic: np.ndarray
    omega_dot_engine: np.ndarray  # (n, 3) rad/s^2, platform (RR tree)
    omega_dot_engine_rrr: np.ndarray  # (n, 3), RRR tree end
    omega_dot_analytic: np.ndarray


def _joint_data(
    th: vt.VectoredThruster, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray
) -> tuple[np.ndarray, ...]:
    """qpos, qvel, qacc (n, 5) in the engine's joint order (q2, theta, q1, rho2, rho3)."""
    p = vt.passive_angles(th, q).values
    r = vt.passive_rates(th, q, qd).values
    a = vt.angular_acceleration(th, q, qd, qdd).passive_acc
    order = lambda inp, pas: np.stack([inp[:, 1], pas[:, 0], inp[:, 0], pas[:, 1], pas[:, 2]], -1)  # noqa: E731
    return order(q, p), order(qd, r), order(qdd, a)


def engine_trace(
    th: vt.VectoredThruster,
    t: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    omega_dot_model=None,
) -> EngineTrace:
    """Evaluate engine and analytic kinematics at trajectory samples ``q, qd, qdd (n, 2)``."""
    check_params(th, vt.VectoredThruster, "th")
    t = as_array(t, "t", (None,))
    q, qd, qdd = (as_array(v, k, (2,), min_ndim=2) for v, k in ((q, "q"), (qd, "qd"), (qdd, "qdd")))
    if not (t.ndim == 1 and q.shape == qd.shape == qdd.shape == (t.shape[0], 2)):
        raise ValueError(
            f"Expected t (n,) and q, qd, qdd (n, 2), got {t.shape}, {q.shape}, {qd.shape}, {qdd.shape}."
        )
    m = mujoco.MjModel.from_xml_string(build_mjcf(th))
    d = mujoco.MjData(m)
    qpos, qvel, qacc = _joint_data(th, q, qd, qdd)
    n = t.shape[0]
    bid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "platform")
    bid_rrr = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "rrr_end")
    sid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "tip")
    out = {k: np.zeros((n, 3)) for k in ("tip", "w", "w3", "wd", "wd3")}
    R = np.zeros((n, 3, 3))
    closure, closure_rate = np.zeros(n), np.zeros(n)
    res = np.zeros(6)
    for i in range(n):  # the engine is per-sample by nature
        d.qpos[:], d.qvel[:] = qpos[i], qvel[i]
        mujoco.mj_forward(m, d)
        eq = d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        closure[i] = np.abs(d.efc_pos[eq]).max()
        Jc = d.efc_J.reshape(d.nefc, m.nv)[eq] if d.nefc else np.zeros((0, m.nv))
        closure_rate[i] = np.abs(Jc @ d.qvel).max()
        out["tip"][i] = d.site_xpos[sid]
        R[i] = d.xmat[bid].reshape(3, 3)
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, bid, res, 0)
        out["w"][i] = res[:3]
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, bid_rrr, res, 0)
        out["w3"][i] = res[:3]
        d.qacc[:] = qacc[i]
        mujoco.mj_rnePostConstraint(m, d)
        mujoco.mj_objectAcceleration(m, d, mujoco.mjtObj.mjOBJ_BODY, bid, res, 0)
        out["wd"][i] = res[:3]
        mujoco.mj_objectAcceleration(m, d, mujoco.mjtObj.mjOBJ_BODY, bid_rrr, res, 0)
        out["wd3"][i] = res[:3]
    fk = vt.forward_kinematics(th, q)
    wd_model = (
        vt.angular_acceleration(th, q, qd, qdd).omega_dot if omega_dot_model is None else omega_dot_model
    )
    return EngineTrace(
        t=t,
        closure=closure,
        closure_rate=closure_rate,
        tip_engine=out["tip"],
        tip_analytic=fk.tip,
        R_engine=R,
        R_analytic=vt.platform_rotation(th, q).R,
        omega_engine=out["w"],
        omega_engine_rrr=out["w3"],
        omega_analytic=vt.angular_velocity(th, q, qd).omega,
        omega_dot_engine=out["wd"],
        omega_dot_engine_rrr=out["wd3"],
        omega_dot_analytic=wd_model,
    )


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


def forward_simulation(th: vt.VectoredThruster, duration: float = SIM_DURATION) -> dict[str, np.ndarray]:
    """Simulate with constraints active, inputs servoed along a slowed Table 1 trajectory (period 4 s).

    Returns time, engine inputs (n, 2), engine propeller axis (n, 3) and the analytic FK of those inputs.
    """
    m = mujoco.MjModel.from_xml_string(build_mjcf(th, actuated=True))
    d = mujoco.MjData(m)
    sid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "tip")
    jq1 = m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "q1")]
    jq2 = m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "q2")]
    w = 2 * np.pi / 4.0
    steps = round(duration / m.opt.timestep)
    every = 50
    ts, qs, axes = [], [], []
    mujoco.mj_forward(m, d)
    for k in range(steps):
        q_ref, _, _ = table1_trajectory(np.array(d.time), omega=w)
        d.ctrl[:] = [q_ref[0], q_ref[1]]
        mujoco.mj_step(m, d)
        if k % every == 0:
            ts.append(d.time)
            qs.append([d.qpos[jq1], d.qpos[jq2]])
            axes.append(d.site_xpos[sid] / th.propeller_arm)
    q = np.array(qs)
    return {
        "t": np.array(ts),
        "q": q,
        "axis_engine": np.array(axes),
        "axis_fk": vt.forward_kinematics(th, q).axis,
    }


def run(th: vt.VectoredThruster | None = None, omega_dot_model=None) -> list[Check]:
    """All checks along one period of the Table 1 trajectory (``omega_dot_model`` replaces the analytic ω̇)."""
    th = vt.VectoredThruster.paper() if th is None else th
    check_params(th, vt.VectoredThruster, "th")
    if omega_dot_model is not None and not callable(omega_dot_model):
        raise ValueError(f"Expected omega_dot_model to be a callable, got {type(omega_dot_model).__name__}.")
    t = np.linspace(0.0, 2 * np.pi, N_SAMPLES)
    q, qd, qdd = table1_trajectory(t)
    if omega_dot_model is not None:
        omega_dot_model = omega_dot_model(th, q, qd, qdd)
    tr = engine_trace(th, t, q, qd, qdd, omega_dot_model)
    mech = "vectored-thrust"
    sim = forward_simulation(th)
    return [
        Check(
            mech,
            "loop closure |efc_pos| (weld), m/rad",
            float(tr.closure.max()),
            Tolerance(1e-12, "exact analytic joint positions; rounding only"),
        ),
        Check(
            mech,
            "closure rate |efc_J qvel|",
            float(tr.closure_rate.max()),
            Tolerance(1e-12, "exact analytic joint rates; rounding only"),
        ),
        Check(mech, "propeller tip position (rel)", _rel(tr.tip_engine, tr.tip_analytic), KINEMATIC_TOL),
        Check(mech, "platform orientation (rel)", _rel(tr.R_engine, tr.R_analytic), KINEMATIC_TOL),
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
    title="Paper 5 vectored thruster vs MuJoCo (closure, pose, angular velocity and acceleration)",
    engine="MuJoCo",
    requires=("mujoco",),
    run=run,
)
