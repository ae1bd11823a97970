"""Paper 1 verification: the spherical parallel leg against a MuJoCo model of the same mechanism.

The MJCF is generated from :class:`~robomech.mechanisms.spherical_leg.SphericalLeg`: the platform hangs
on two hinges at O (X, then the rotated Y: ``T = Rx(alpha) Ry(beta)``); each leg is a lower body on a
ball joint at A_i and an upper body on a slide (plus, for the lead-screw legs 1 and 3, a hinge about the
leg axis coupled to the slide by a joint equality, the helical joint); each leg's tip B_i is joined to
the platform by a ``connect`` equality (the loop closure). Inertias are the same documented bodies.

Checks (the role ADAMS plays in the paper):

* kinematics: the analytic joint values put into ``qpos`` satisfy the engine's loop closures; engine
  sites B_i match the analytic platform points; ``efc_J @ qvel = 0`` for the analytic rates; engine
  B_i velocities (``mj_objectVelocity``) match; leg accelerations from fourth-order differences of the
  engine's leg lengths match ``l = J q + qd^T H qd``;
* forces: the engine's tree inverse dynamics ``M qacc + c`` (``mj_rne``) along the Fig. 5(b)
  trajectory and the two Section 6.1 sway modes is resolved into actuator forces and constraint forces
  by least squares (``tau_tree = S^T f + J_c^T lambda + axial reaction on the non-spinning sleeves``)
  and compared with the analytic inverse dynamics under the paper's driving rule (legs 1 and 3);
* forward simulation: the engine, driven by the analytic feed-forward leg forces plus a weak PD on
  the leg lengths (the platform is an inverted pendulum: open-loop force control is unstable), follows
  the trajectory; the bound is on the tracking error and on the feedback share of the force.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from robomech._validation import as_array, check_params, check_positive
from robomech.mechanisms import spherical_leg as sl
from robomech.spatial import exp_so3

from ._core import Check, Tolerance, Verification, optional_module

if TYPE_CHECKING:
    import mujoco
else:  # imported on first use: discovering this module must not need the optional engine
    mujoco = optional_module("mujoco")

__all__ = ["VERIFICATION", "build_model", "inverse_dynamics_engine", "run_checks", "study_overlays"]

# Closure of the analytic joint values in the engine: both sides compute the same points in float64,
# so the violation is rounding (~1e-17 m); 1e-12 m leaves room for the quaternion round trip.
CLOSURE_TOL = Tolerance(1e-12, "rounding of float64 positions and of the ball-joint quaternions (m)")
VELOCITY_TOL = Tolerance(
    1e-12, "rounding: efc_J qvel and site velocities are linear maps of exact rates (m/s)"
)
# l from 4th-order central differences of engine lengths with dt = 0.01 s: truncation dt^4 w^6 l ~ 1e-13,
# rounding eps l / dt^2 ~ 1e-13 m/s^2, against accelerations of ~1e-2 m/s^2.
ACCEL_TOL = Tolerance(1e-7, "4th-order differences of engine leg lengths, dt = 0.01 s", relative=True)
# The engine's rigid-body tree dynamics are exact up to rounding; the least-squares resolution of the
# closed loops is well conditioned away from the actuation singularity (cond < 1e4 on these paths).
FORCE_TOL = Tolerance(1e-8, "exact rigid-body dynamics both sides; lstsq conditioning < 1e4", relative=True)
LSQ_RESIDUAL_TOL = Tolerance(1e-9, "engine tree forces are balanced by actuators + constraints (N, N m)")
# Forward simulation with stiff soft equality constraints (solref 2 ms) and a 0.2 ms Euler step: the
# tracking error is the integrator's first-order error (measured 1.6e-4 rad, halving with the step:
# 7.7e-5 rad at 0.1 ms); the PD (30 rad/s) keeps it from accumulating.
SIM_TRACKING_TOL = Tolerance(3e-4, "Euler O(dt) error at 0.2 ms, measured 1.6e-4 rad (halves with dt)")
SIM_FEEDBACK_TOL = Tolerance(
    1e-2, "feedback share of the leg forces: the analytic feed-forward must do the work", relative=True
)

SIM_TIMESTEP = 2e-4
SIM_DURATION = 4.0
SIM_PD_BANDWIDTH = 30.0  # rad/s, well below 1/SIM_TIMESTEP, above the 0.05 Hz motion
SIM_PD_MASS = 5.0  # kg, the order of the platform's effective mass at the legs (screw spin off)


# Stiff equality constraints for the forward simulation (time constant 10 x the step, as MuJoCo advises).
_SOLVER = 'solref="0.002 1" solimp="0.9999 0.9999 0.001 0.5 2"'


def _rot_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Minimal rotation taking unit vector a to unit vector b (never called with b = -a here: a leg
    cannot turn half a revolution from its home direction)."""
    axis = np.cross(a, b)
    n = np.linalg.norm(axis)
    ang = np.arctan2(n, float(a @ b))
    return exp_so3(axis / n * ang) if n > 0 else np.eye(3)


def _rot_z_to(s: np.ndarray) -> np.ndarray:
    """A rotation matrix whose z axis is the unit vector ``s`` (minimal rotation from z)."""
    return _rot_between(np.array([0.0, 0.0, 1.0]), s)


def _quat(R: np.ndarray) -> np.ndarray:
    q = np.empty(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(R).reshape(9))
    return q


def build_model(leg: sl.SphericalLeg, timestep: float = SIM_TIMESTEP) -> mujoco.MjModel:
    """The MJCF of the mechanism, built from ``leg`` (SI units)."""
    check_params(leg, sl.SphericalLeg, "leg")
    timestep = check_positive(timestep, "timestep")
    home = sl.inverse_kinematics(leg, 0.0, 0.0)
    Ip = np.diag(leg.platform_inertia)
    k = leg.spin_ratio
    f = lambda v: " ".join(f"{x:.17g}" for x in np.ravel(v))  # noqa: E731
    legs, eqs, acts = [], [], []
    for i in range(3):
        lo, up = leg.lower[i], leg.upper[i]
        l0 = float(home.lengths[i])
        q_ref = _quat(_rot_z_to(home.unit_vectors[i]))
        spin = f'<joint name="spin{i}" type="hinge" axis="0 0 1"/>' if k[i] > 0 else ""
        legs.append(f"""
    <body name="lower{i}" pos="{f(leg.base_points[i])}" quat="{f(q_ref)}">
      <joint name="ball{i}" type="ball"/>
      <inertial pos="0 0 {0.5 * lo.length:.17g}" mass="{lo.mass:.17g}"
                diaginertia="{f([lo.transverse_inertia, lo.transverse_inertia, lo.axial_inertia])}"/>
      <body name="upper{i}">
        <joint name="slide{i}" type="slide" axis="0 0 1"/>
        {spin}
        <inertial pos="0 0 {l0 - 0.5 * up.length:.17g}" mass="{up.mass:.17g}"
                  diaginertia="{f([up.transverse_inertia, up.transverse_inertia, up.axial_inertia])}"/>
        <site name="tip{i}" pos="0 0 {l0:.17g}"/>
      </body>
    </body>""")
        eqs.append(f'<connect body1="upper{i}" body2="platform" anchor="0 0 {l0:.17g}" {_SOLVER}/>')
        if k[i] > 0:
            eqs.append(
                f'<joint joint1="spin{i}" joint2="slide{i}" polycoef="0 {-k[i]:.17g} 0 0 0" {_SOLVER}/>'
            )
        acts.append(f'<motor name="f{i}" joint="slide{i}"/>')
    sites = "".join(f'<site name="B{i}" pos="{f(leg.platform_points_home[i])}"/>' for i in range(3))
    xml = f"""<mujoco model="spherical_leg">
  <option timestep="{timestep:.17g}" gravity="{f(leg.gravity)}" jacobian="dense" integrator="Euler"/>
  <worldbody>
    <site name="O" pos="0 0 0"/>
    {"".join(f'<site name="A{i}" pos="{f(leg.base_points[i])}"/>' for i in range(3))}
    <body name="gimbal">
      <joint name="alpha" type="hinge" axis="1 0 0"/>
      <inertial pos="0 0 0" mass="1e-9" diaginertia="1e-12 1e-12 1e-12"/>
      <body name="platform">
        <joint name="beta" type="hinge" axis="0 1 0"/>
        <inertial pos="0 0 {leg.h:.17g}" mass="{leg.platform_mass:.17g}" diaginertia="{f(Ip)}"/>
        {sites}
      </body>
    </body>
    {"".join(legs)}
  </worldbody>
  <equality>
    {"".join(eqs)}
  </equality>
  <actuator>
    {"".join(acts)}
  </actuator>
</mujoco>"""
    return mujoco.MjModel.from_xml_string(xml)


class _Layout:
    """Indices of the model's joints in qpos / qvel."""

    def __init__(self, m: mujoco.MjModel, leg: sl.SphericalLeg) -> None:
        jid = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n)  # noqa: E731
        self.qa, self.va = m.jnt_qposadr[jid("alpha")], m.jnt_dofadr[jid("alpha")]
        self.qb, self.vb = m.jnt_qposadr[jid("beta")], m.jnt_dofadr[jid("beta")]
        self.ball_q = [m.jnt_qposadr[jid(f"ball{i}")] for i in range(3)]
        self.ball_v = [m.jnt_dofadr[jid(f"ball{i}")] for i in range(3)]
        self.slide_q = [m.jnt_qposadr[jid(f"slide{i}")] for i in range(3)]
        self.slide_v = [m.jnt_dofadr[jid(f"slide{i}")] for i in range(3)]
        k = leg.spin_ratio
        self.spin = {
            i: (m.jnt_qposadr[jid(f"spin{i}")], m.jnt_dofadr[jid(f"spin{i}")]) for i in range(3) if k[i] > 0
        }
        self.body_upper = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"upper{i}") for i in range(3)]
        self.site_B = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"B{i}") for i in range(3)]
        self.site_tip = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"tip{i}") for i in range(3)]
        self.site_A = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"A{i}") for i in range(3)]


def _set_state(m, d, lay: _Layout, leg: sl.SphericalLeg, q, qd, qdd) -> None:
    """Write the analytic configuration, rates and accelerations of every engine joint (one sample)."""
    home = sl.inverse_kinematics(leg, 0.0, 0.0)
    ik = sl.inverse_kinematics(leg, q[0], q[1])
    l, ld, ldd = sl.leg_rates(leg, q, qd, qdd)
    E = sl.angular_velocity_jacobian(q[0])
    w = E @ qd
    dw = E @ qdd + np.array([0.0, -np.sin(q[0]), np.cos(q[0])]) * qd[0] * qd[1]
    B = ik.platform_points
    k = leg.spin_ratio
    d.qpos[:] = 0.0
    d.qvel[:] = 0.0
    d.qpos[lay.qa], d.qpos[lay.qb] = q
    d.qvel[lay.va], d.qvel[lay.vb] = qd
    qacc = np.zeros(m.nv)
    qacc[lay.va], qacc[lay.vb] = qdd
    for i in range(3):
        s = ik.unit_vectors[i]
        R_ref = _rot_z_to(home.unit_vectors[i])  # the body's reference orientation in the MJCF
        R = _rot_between(home.unit_vectors[i], s) @ R_ref  # its orientation now (zero spin: minimal turn)
        d.qpos[lay.ball_q[i] : lay.ball_q[i] + 4] = _quat(R_ref.T @ R)
        ud = np.cross(w, B[i])
        udd = np.cross(dw, B[i]) + np.cross(w, ud)
        sd = (ud - s * ld[i]) / l[i]
        sdd = (udd - s * ldd[i] - 2 * sd * ld[i]) / l[i]
        sig, sigd = k[i] * ld[i], k[i] * ldd[i]
        om = np.cross(s, sd) + sig * s
        dom = np.cross(s, sdd) + sigd * s + sig * sd
        d.qvel[lay.ball_v[i] : lay.ball_v[i] + 3] = R.T @ om  # ball-joint rates are local angular velocity
        qacc[lay.ball_v[i] : lay.ball_v[i] + 3] = R.T @ dom
        d.qpos[lay.slide_q[i]] = l[i] - home.lengths[i]
        d.qvel[lay.slide_v[i]] = ld[i]
        qacc[lay.slide_v[i]] = ldd[i]
        if i in lay.spin:
            qa, va = lay.spin[i]
            d.qpos[qa] = -k[i] * (l[i] - home.lengths[i])
            d.qvel[va] = -sig
            qacc[va] = -sigd
    d.qacc[:] = qacc


def _equality_rows(d) -> np.ndarray:
    return np.nonzero(d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY)[0]


def inverse_dynamics_engine(
    leg: sl.SphericalLeg, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, driven_legs=sl.PAPER_DRIVEN_LEGS
) -> tuple[np.ndarray, np.ndarray]:
    """Engine actuator forces (n, 3) along a trajectory (n, 2) and the least-squares residual (n,).

    ``tau_tree = M qacc + c`` from ``mj_rne`` is balanced by the driven legs' slide forces, the
    equality-constraint forces ``J_c^T lambda`` and, on the lead-screw legs, an axial torque on the
    sleeve (the reaction that keeps it from spinning, which the analytic model assumes).
    """
    check_params(leg, sl.SphericalLeg, "leg")
    q, qd, qdd = (as_array(v, k, (2,), min_ndim=2) for v, k in ((q, "q"), (qd, "qd"), (qdd, "qdd")))
    if not (q.ndim == 2 and q.shape == qd.shape == qdd.shape):
        raise ValueError(f"Expected q, qd, qdd of one shape (n, 2), got {q.shape}, {qd.shape}, {qdd.shape}.")
    m = build_model(leg)
    d = mujoco.MjData(m)
    lay = _Layout(m, leg)
    n = len(q)
    forces = np.zeros((n, 3))
    resid = np.zeros(n)
    jacp, jacr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
    tau_tree = np.zeros(m.nv)
    for t in range(n):
        _set_state(m, d, lay, leg, q[t], qd[t], qdd[t])
        qacc = d.qacc.copy()
        mujoco.mj_forward(m, d)
        d.qacc[:] = qacc
        mujoco.mj_rne(m, d, 1, tau_tree)
        rows = _equality_rows(d)
        Jc = d.efc_J.reshape(-1, m.nv)[rows]
        cols = []
        for i in driven_legs:
            e = np.zeros(m.nv)
            e[lay.slide_v[i]] = 1.0
            cols.append(e)
        s = sl.inverse_kinematics(leg, q[t, 0], q[t, 1]).unit_vectors
        for i in lay.spin:
            mujoco.mj_jacBody(m, d, jacp, jacr, lay.body_upper[i])
            cols.append(jacr.T @ s[i])
        A = np.column_stack([*cols, Jc.T])
        x, *_ = np.linalg.lstsq(A, tau_tree, rcond=None)
        resid[t] = np.linalg.norm(A @ x - tau_tree)
        for j, i in enumerate(driven_legs):
            forces[t, i] = x[j]
    return forces, resid


def _fast_motion(t: np.ndarray):
    """A brisk test motion (about 100x the paper's accelerations) so that inertia, not gravity, dominates."""
    a, wa, b, wb = 0.5, 2 * np.pi * 0.5, 0.3, 2 * np.pi * 0.35
    q = np.stack([a * np.sin(wa * t), b * np.sin(wb * t) + 0.1], -1)
    qd = np.stack([a * wa * np.cos(wa * t), b * wb * np.cos(wb * t)], -1)
    qdd = np.stack([-a * wa * wa * np.sin(wa * t), -b * wb * wb * np.sin(wb * t)], -1)
    return q, qd, qdd


def _trajectories() -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The checked motions: the two Section 6.1 sway modes, Fig. 5(b), and a brisk test motion."""
    t = np.arange(0.0, 20.0, 0.5)
    return {
        "sway about X": sl.sway(t, "x"),
        "sway about Y": sl.sway(t, "y"),
        "Fig. 5(b)": sl.fig5_motion("b", np.arange(0.0, 25.0, 0.5)),
        "brisk test motion": _fast_motion(np.arange(0.0, 4.0, 0.05)),
    }


def _kinematic_errors(engine_leg: sl.SphericalLeg, leg: sl.SphericalLeg, q, qd, qdd) -> dict[str, float]:
    """Closure, site and velocity errors of ``leg``'s analytic kinematics in the engine of ``engine_leg``."""
    m = build_model(engine_leg)
    d = mujoco.MjData(m)
    lay = _Layout(m, engine_leg)
    v6 = np.zeros(6)
    err = {"closure": 0.0, "sites": 0.0, "velocity closure": 0.0, "site velocity": 0.0}
    for t in range(len(q)):
        _set_state(m, d, lay, leg, q[t], qd[t], qdd[t])
        mujoco.mj_forward(m, d)
        rows = _equality_rows(d)
        ik = sl.inverse_kinematics(leg, q[t, 0], q[t, 1])
        w = sl.angular_velocity_jacobian(q[t, 0]) @ qd[t]
        err["closure"] = max(err["closure"], float(np.max(np.abs(d.efc_pos[rows]))))
        Jc = d.efc_J.reshape(-1, m.nv)[rows]
        err["velocity closure"] = max(err["velocity closure"], float(np.max(np.abs(Jc @ d.qvel))))
        for i in range(3):
            err["sites"] = max(
                err["sites"], float(np.max(np.abs(d.site_xpos[lay.site_B[i]] - ik.platform_points[i])))
            )
            mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_SITE, lay.site_B[i], v6, 0)
            vB = np.cross(w, ik.platform_points[i])
            err["site velocity"] = max(err["site velocity"], float(np.max(np.abs(v6[3:] - vB))))
    return err


def engine_leg_accelerations(leg: sl.SphericalLeg, t: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Leg accelerations (n - 4, 3) at t[2:-2]: 4th-order central differences of the engine's leg lengths
    |B_i - A_i| (platform sites placed by the engine's hinges; uniform t)."""
    m = build_model(leg)
    d = mujoco.MjData(m)
    lay = _Layout(m, leg)
    L = np.zeros((len(t), 3))
    for k in range(len(t)):
        d.qpos[:] = 0.0
        d.qpos[lay.qa], d.qpos[lay.qb] = q[k]
        mujoco.mj_kinematics(m, d)
        for i in range(3):
            L[k, i] = np.linalg.norm(d.site_xpos[lay.site_B[i]] - d.site_xpos[lay.site_A[i]])
    dt = t[1] - t[0]
    return (-L[:-4] + 16 * L[1:-3] - 30 * L[2:-2] + 16 * L[3:-1] - L[4:]) / (12 * dt * dt)


def forward_simulation(leg: sl.SphericalLeg, analytic: sl.SphericalLeg) -> tuple[float, float, dict]:
    """Drive the engine with ``analytic``'s feed-forward forces (legs 1, 3) plus a weak PD on the leg
    lengths along the brisk test motion; returns (max pose error rad, feedback share, traces)."""
    m = build_model(leg, SIM_TIMESTEP)
    d = mujoco.MjData(m)
    lay = _Layout(m, leg)
    t = np.arange(0.0, SIM_DURATION, SIM_TIMESTEP)
    q, qd, qdd = _fast_motion(t)
    ff = sl.inverse_dynamics(analytic, q, qd, qdd, driven_legs=sl.PAPER_DRIVEN_LEGS).leg_forces
    l_ref, ld_ref, _ = sl.leg_rates(leg, q, qd, qdd)
    l0 = sl.inverse_kinematics(leg, 0.0, 0.0).lengths
    kp = SIM_PD_MASS * SIM_PD_BANDWIDTH**2
    kd = 2.0 * SIM_PD_MASS * SIM_PD_BANDWIDTH
    _set_state(m, d, lay, leg, q[0], qd[0], qdd[0])
    mujoco.mj_forward(m, d)
    err = np.zeros(len(t))
    fb_max = 0.0
    for k in range(len(t)):
        err[k] = max(abs(d.qpos[lay.qa] - q[k, 0]), abs(d.qpos[lay.qb] - q[k, 1]))
        for i in sl.PAPER_DRIVEN_LEGS:
            li = d.qpos[lay.slide_q[i]] + l0[i]
            fb = kp * (l_ref[k, i] - li) + kd * (ld_ref[k, i] - d.qvel[lay.slide_v[i]])
            fb_max = max(fb_max, abs(fb))
            d.ctrl[i] = ff[k, i] + fb
        mujoco.mj_step(m, d)
    share = fb_max / float(np.max(np.abs(ff)))
    return float(err.max()), share, {"t": t, "error": err}


def run_checks(analytic: sl.SphericalLeg | None = None) -> list[Check]:
    """All checks of the paper-1 verification; ``analytic`` (default: the engine's own parameters) is the
    model being verified: pass a deliberately wrong one to see the checks fail."""
    if analytic is not None:
        check_params(analytic, sl.SphericalLeg, "analytic")
    leg = sl.SphericalLeg.paper()
    analytic = leg if analytic is None else analytic
    name = "spherical-leg"
    checks: list[Check] = []
    trajs = _trajectories()
    kin = {"closure": 0.0, "sites": 0.0, "velocity closure": 0.0, "site velocity": 0.0}
    for q, qd, qdd in trajs.values():
        for k, v in _kinematic_errors(leg, analytic, q, qd, qdd).items():
            kin[k] = max(kin[k], v)
    checks.append(Check(name, "loop closure of analytic joints (m)", kin["closure"], CLOSURE_TOL))
    checks.append(Check(name, "platform points B_i vs engine sites (m)", kin["sites"], CLOSURE_TOL))
    checks.append(Check(name, "velocity closure efc_J qvel (m/s)", kin["velocity closure"], VELOCITY_TOL))
    checks.append(Check(name, "B_i velocity vs mj_objectVelocity (m/s)", kin["site velocity"], VELOCITY_TOL))
    t = np.arange(0.0, 20.0, 0.01)
    acc_err = 0.0
    for about in ("x", "y"):
        q, qd, qdd = sl.sway(t, about)
        ldd_e = engine_leg_accelerations(leg, t, q)
        ldd_a = sl.leg_rates(analytic, q, qd, qdd)[2][2:-2]
        acc_err = max(acc_err, float(np.max(np.abs(ldd_e - ldd_a)) / np.max(np.abs(ldd_a))))
    checks.append(Check(name, "leg accelerations vs engine (Section 6.1 modes)", acc_err, ACCEL_TOL))
    f_err, r_max = 0.0, 0.0
    for q, qd, qdd in trajs.values():
        fe, res = inverse_dynamics_engine(leg, q, qd, qdd)
        fa = sl.inverse_dynamics(analytic, q, qd, qdd, driven_legs=sl.PAPER_DRIVEN_LEGS).leg_forces
        f_err = max(f_err, float(np.max(np.abs(fe - fa)) / np.max(np.abs(fa))))
        r_max = max(r_max, float(res.max()))
    checks.append(
        Check(
            name,
            "actuator forces vs engine inverse dynamics",
            f_err,
            FORCE_TOL,
            "legs 1, 3 driven (paper's rule); 4 trajectories incl. a brisk one",
        )
    )
    checks.append(Check(name, "engine force balance residual (lstsq)", r_max, LSQ_RESIDUAL_TOL))
    no_spin = replace(leg, screw_spin=False)
    err, share, _ = forward_simulation(no_spin, replace(analytic, screw_spin=False))
    checks.append(
        Check(
            name,
            "forward simulation: pose tracking (rad)",
            err,
            SIM_TRACKING_TOL,
            "engine driven by analytic feed-forward + weak PD; screw spin off (see module doc)",
        )
    )
    checks.append(Check(name, "forward simulation: feedback share of force", share, SIM_FEEDBACK_TOL))
    return checks


def study_overlays(leg: sl.SphericalLeg) -> dict:
    """Engine curves for the study's figures: leg accelerations of both sway modes, Fig. 5(b) forces."""
    check_params(leg, sl.SphericalLeg, "leg")
    t = np.arange(0.0, 30.0, 0.1)
    acc = {}
    for about in ("x", "y"):
        q, _, _ = sl.sway(t, about)
        acc[about] = (t[2:-2], engine_leg_accelerations(leg, t, q))
    tb = np.arange(0.0, 25.0 + 1e-9, 0.5)
    fe, _ = inverse_dynamics_engine(leg, *sl.fig5_motion("b", tb))
    return {"acc": acc, "force_b": (tb, fe)}


VERIFICATION = Verification(
    name="spherical-leg",
    title="Paper 1 spherical parallel leg vs a MuJoCo model of the same mechanism",
    engine="MuJoCo",
    requires=("mujoco",),
    run=run_checks,
)
