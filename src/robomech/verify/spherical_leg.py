"""Paper 1 verification: the spherical parallel leg's analytic model against MuJoCo.

The engine model is the generic export of the mechanism's description,
``mb.to_mjcf(sl.to_multibody(leg))`` (no hand-written MJCF): the platform on two hinges at O
(``alpha`` about X, then ``beta`` about the turned Y: ``T = Rx(alpha) Ry(beta)``); per leg a universal
joint at A_i (``u{k}a`` about the base-fixed axis ``leg.cardan_axes``, ``u{k}b`` across the leg), the
lower body (for legs 1 and 3 the lead screw on ``spin{k}``, coupled to the slide by a joint equality:
the helical joint), the upper body on the slide ``l{k}``, and a ``connect`` equality at B_i (the loop
closure).  The central chain and the cardans are massless in the description; the engine needs a
positive mass to compile, so their inferred inertias are zeroed in the compiled model (``mj_setConst``).

The analytic side is ``robomech.mechanisms.spherical_leg`` only: its platform motion, leg kinematics
and, for the engine's joint values, the universal-joint angles of each leg computed from the analytic
leg axis (``_joint_state``: ``u_a = atan2(-s_z, s_x)``, ``u_b = asin(s_y)`` in the cardan frame).
Checks (the role ADAMS plays in the paper):

* kinematics: the analytic joint values satisfy the engine's closures (``efc_pos``); the engine's
  B_i, from the platform and from each leg's tip, match the analytic platform points; ``efc_J qvel = 0``
  for the analytic rates; engine velocities of B_i (``mj_jac``, platform and leg side) match; the
  engine's leg-length Jacobian (``s . dB/dq`` from ``mj_jac``) matches ``sl.jacobian``; the analytic
  forward kinematics of the engine's leg lengths returns the engine's angles; leg accelerations from
  fourth-order differences of the engine's lengths match ``l = J q + qd^T H qd``;
* dynamics: the engine's mass matrix projected on (alpha, beta), ``G^T M G`` (``mj_fullM``), matches
  ``sl.mass_matrix``; kinetic and potential energy (``mj_energyVel``, ``mj_energyPos``) match
  ``sl.mechanical_energy``; the engine's tree inverse dynamics ``M qacc + c`` (``mj_rne``) along four
  trajectories, projected through the null space of its own constraint Jacobian onto the actuators,
  matches ``sl.inverse_dynamics`` under the paper's driving rule (legs 1, 3) and the minimum-norm rule;
* forward simulation: the engine, driven by the analytic feed-forward leg forces plus a weak PD on
  the leg lengths (the platform is an inverted pendulum: open-loop force control is unstable), follows
  the trajectory; the bound is on the tracking error and on the feedback share of the force.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from robomech._validation import as_array, check_bool, check_int, check_params, check_positive
from robomech.mechanisms import spherical_leg as sl

from ._core import Check, Tolerance, Verification, optional_module
from ._mujoco import Engine, engine_options

if TYPE_CHECKING:
    import mujoco
else:  # imported on first use: discovering this module must not need the optional engine
    mujoco = optional_module("mujoco")

__all__ = ["VERIFICATION", "build_model", "inverse_dynamics_engine", "run_checks", "study_overlays"]

Array = NDArray[np.float64]

# Closure of the analytic joint values in the engine: both sides compute the same points in float64
# (the U-joint angles through atan2/asin of the analytic leg axis), so the violation is rounding
# (~1e-17 m); 1e-12 m leaves room for the transform chains.
CLOSURE_TOL = Tolerance(1e-12, "rounding of float64 positions through the joint chains (m)")
VELOCITY_TOL = Tolerance(
    1e-12, "rounding: efc_J qvel and point velocities are linear maps of exact rates (m/s)"
)
# Exact first-order kinematics both sides (leg-length Jacobian ~0.1 m/rad): rounding only.
JACOBIAN_TOL = Tolerance(1e-10, "exact first-order kinematics both sides; rounding", relative=True)
# FK from exact lengths: the analytic closed form plus its Newton refinement (FK_STEP_TOL ~1e-14 rad).
FK_TOL = Tolerance(1e-10, "closed-form FK of exact engine lengths; Newton refinement to 1e-14 rad")
# l from 4th-order central differences of engine lengths with dt = 0.01 s: truncation dt^4 w^6 l ~ 1e-13,
# rounding eps l / dt^2 ~ 1e-13 m/s^2, against accelerations of ~1e-2 m/s^2.
ACCEL_TOL = Tolerance(1e-7, "4th-order differences of engine leg lengths, dt = 0.01 s", relative=True)
# The engine's rigid-body tree dynamics are exact up to rounding; the null-space projection of the
# closed loops is well conditioned away from the actuation singularity (cond < 1e4 on these paths).
FORCE_TOL = Tolerance(1e-8, "exact rigid-body dynamics both sides; projection cond < 1e4", relative=True)
MASS_TOL = Tolerance(1e-10, "exact mass matrices both sides (engine M through exact G)", relative=True)
ENERGY_TOL = Tolerance(1e-10, "exact energies both sides; rounding", relative=True)
# Forward simulation with stiff soft equality constraints (solref 2 ms) and a 0.2 ms Euler step: the
# tracking error is the integrator's first-order error (measured 1.6e-4 rad with a ball-jointed
# hand-written model, halving with the step); the PD (30 rad/s) keeps it from accumulating.
SIM_TRACKING_TOL = Tolerance(3e-4, "Euler O(dt) error at 0.2 ms, measured ~1.6e-4 rad (halves with dt)")
SIM_FEEDBACK_TOL = Tolerance(
    1e-2, "feedback share of the leg forces: the analytic feed-forward must do the work", relative=True
)

SIM_TIMESTEP = 2e-4
SIM_DURATION = 4.0
SIM_PD_BANDWIDTH = 30.0  # rad/s, well below 1/SIM_TIMESTEP, above the 0.05 Hz motion
SIM_PD_MASS = 5.0  # kg, the order of the platform's effective mass at the legs (screw spin off)
# Stiff equality constraints for the forward simulation (time constant 10 x the step, as MuJoCo advises).
_SOLREF = "0.002 1"
_SOLIMP = "0.9999 0.9999 0.001 0.5 2"


def build_model(leg: sl.SphericalLeg, timestep: float = SIM_TIMESTEP) -> mujoco.MjModel:
    """The engine model of ``leg``: ``mb.to_mjcf(sl.to_multibody(leg))`` with the simulation options
    (``timestep``, Euler, dense Jacobian, stiff equality constraints) and the description's massless
    bodies (central chain, cardans) made massless in the compiled model."""
    check_params(leg, sl.SphericalLeg, "leg")
    timestep = check_positive(timestep, "timestep")
    from robomech import multibody as mb

    mech = sl.to_multibody(leg)
    root = engine_options(
        mb.to_mjcf(mech),
        timestep=timestep,
        integrator="Euler",
        jacobian="dense",
        solref=_SOLREF,
        solimp=_SOLIMP,
    )
    m = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
    for b in mech.bodies:
        if b.inertial is None:  # MuJoCo inferred an inertia from the visual geoms: the description has none
            bid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, b.name)
            m.body_mass[bid] = 0.0
            m.body_inertia[bid] = 0.0
    mujoco.mj_setConst(m, mujoco.MjData(m))
    return m


class _Layout:
    """Addresses of the engine model's joints and bodies (names from ``sl.to_multibody``)."""

    def __init__(self, m: mujoco.MjModel, leg: sl.SphericalLeg) -> None:
        def jnt(n: str) -> tuple[int, int]:
            qadr, dadr = Engine(m).joint_addresses([n])
            return int(qadr[0]), int(dadr[0])

        def body(n: str) -> int:
            return int(mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n))

        self.alpha, self.beta = jnt("alpha"), jnt("beta")
        self.ua = [jnt(f"u{k}a") for k in (1, 2, 3)]
        self.ub = [jnt(f"u{k}b") for k in (1, 2, 3)]
        self.slide = [jnt(f"l{k}") for k in (1, 2, 3)]
        k = leg.spin_ratio
        self.spin = {i: jnt(f"spin{i + 1}") for i in range(3) if k[i] != 0.0}
        self.platform = body("platform")
        self.cardan = [body(f"cardan{k}") for k in (1, 2, 3)]
        self.upper = [body(f"upper{k}") for k in (1, 2, 3)]
        self.l0 = sl.inverse_kinematics(leg, 0.0, 0.0).lengths
        self.B_home = leg.platform_points_home


def _cardan_frames(leg: sl.SphericalLeg) -> Array:
    """Home frames of the universal joints (3, 3, 3): columns leg axis at home, first axis, their cross."""
    s0 = sl.inverse_kinematics(leg, 0.0, 0.0).unit_vectors
    a = leg.cardan_axes
    return np.stack([s0, a, np.cross(s0, a)], axis=-1)


def _joint_state(
    leg: sl.SphericalLeg, q: Array, qd: Array, qdd: Array
) -> tuple[Array, Array, Array, Array, Array, Array]:
    """Analytic U-joint angles, rates and accelerations (n, 3, 2) [u_a, u_b] and the leg lengths,
    rates, accelerations (n, 3), from the analytic leg axis s and its derivatives."""
    ik = sl.inverse_kinematics(leg, q[:, 0], q[:, 1])
    l, ld, ldd = sl.leg_rates(leg, q, qd, qdd)
    E = sl.angular_velocity_jacobian(q[:, 0])
    w = np.einsum("nij,nj->ni", E, qd)
    dw = (
        np.einsum("nij,nj->ni", E, qdd)
        + np.stack([np.zeros(len(q)), -np.sin(q[:, 0]), np.cos(q[:, 0])], -1) * (qd[:, 0] * qd[:, 1])[:, None]
    )
    B = ik.platform_points
    s = ik.unit_vectors
    ud = np.cross(w[:, None], B)
    udd = np.cross(dw[:, None], B) + np.cross(w[:, None], ud)
    sd = (ud - s * ld[..., None]) / l[..., None]
    sdd = (udd - s * ldd[..., None] - 2 * sd * ld[..., None]) / l[..., None]
    R = _cardan_frames(leg)  # s' = R^T s: s' = Ry(u_a) (cos u_b, sin u_b, 0)
    x, y, z = (np.einsum("lj,nlj->nl", R[:, :, c], s) for c in range(3))
    xd, yd, zd = (np.einsum("lj,nlj->nl", R[:, :, c], sd) for c in range(3))
    xdd, ydd, zdd = (np.einsum("lj,nlj->nl", R[:, :, c], sdd) for c in range(3))
    rho2 = x * x + z * z
    rho = np.sqrt(rho2)
    ua, ub = np.arctan2(-z, x), np.arctan2(y, rho)
    num = z * xd - x * zd
    uad = num / rho2
    uadd = ((z * xdd - x * zdd) * rho2 - num * 2 * (x * xd + z * zd)) / (rho2 * rho2)
    rhod = (x * xd + z * zd) / rho
    ubd = yd / rho
    ubdd = (ydd * rho - yd * rhod) / rho2
    return (
        np.stack([ua, ub], -1),
        np.stack([uad, ubd], -1),
        np.stack([uadd, ubdd], -1),
        l,
        ld,
        ldd,
    )


def _engine_states(
    m: mujoco.MjModel, lay: _Layout, leg: sl.SphericalLeg, q: Array, qd: Array, qdd: Array
) -> tuple[Array, Array, Array]:
    """The engine's qpos, qvel, qacc (n, nq), (n, nv) from the analytic motion."""
    u, ud, udd, l, ld, ldd = _joint_state(leg, q, qd, qdd)
    n = len(q)
    qpos, qvel, qacc = np.zeros((n, m.nq)), np.zeros((n, m.nv)), np.zeros((n, m.nv))
    for (qa, va), j in ((lay.alpha, 0), (lay.beta, 1)):
        qpos[:, qa], qvel[:, va], qacc[:, va] = q[:, j], qd[:, j], qdd[:, j]
    k = leg.spin_ratio
    for i in range(3):
        for (qa, va), j in ((lay.ua[i], 0), (lay.ub[i], 1)):
            qpos[:, qa], qvel[:, va], qacc[:, va] = u[:, i, j], ud[:, i, j], udd[:, i, j]
        qa, va = lay.slide[i]
        qpos[:, qa], qvel[:, va], qacc[:, va] = l[:, i] - lay.l0[i], ld[:, i], ldd[:, i]
        if i in lay.spin:  # the helical joint: spin = 2 pi / lead per metre of stroke (joint equality)
            qa, va = lay.spin[i]
            qpos[:, qa], qvel[:, va], qacc[:, va] = (
                k[i] * (l[:, i] - lay.l0[i]),
                k[i] * ld[:, i],
                k[i] * ldd[:, i],
            )
    return qpos, qvel, qacc


def inverse_dynamics_engine(
    leg: sl.SphericalLeg,
    q: object,
    qd: object,
    qdd: object,
    driven_legs: tuple[int, int] | None = sl.PAPER_DRIVEN_LEGS,
) -> tuple[Array, Array]:
    """Engine actuator forces (n, 3) along a trajectory (n, 2) and the closure error of the state (n,).

    ``tau_tree = M qacc + c`` from ``mj_rne`` is projected on the null space of the engine's equality
    Jacobian (the admissible motions) and balanced by the driven legs' slide forces (``driven_legs``,
    default paper 1's legs 1 and 3; ``None``: all three, minimum norm).  The second array is
    ``max |efc_pos|`` of the analytic state in the engine (m): the forces mean something only there.
    """
    check_params(leg, sl.SphericalLeg, "leg")
    qa, qda, qdda = (as_array(v, k, (2,), min_ndim=2) for v, k in ((q, "q"), (qd, "qd"), (qdd, "qdd")))
    if not (qa.ndim == 2 and qa.shape == qda.shape == qdda.shape):
        raise ValueError(
            f"Expected q, qd, qdd of one shape (n, 2), got {qa.shape}, {qda.shape}, {qdda.shape}."
        )
    if driven_legs is None:
        legs: tuple[int, ...] = (0, 1, 2)
    else:
        pair = tuple(driven_legs) if isinstance(driven_legs, tuple | list) else ()
        legs = tuple(check_int(i, "driven_legs", low=0, high=2) for i in pair)
        if len(legs) != 2 or legs[0] == legs[1]:
            raise ValueError(
                f"Expected driven_legs to be None or two different leg indices in 0..2, got {driven_legs!r}."
            )
    eng = Engine(build_model(leg))
    lay = _Layout(eng.model, leg)
    qpos, qvel, qacc = _engine_states(eng.model, lay, leg, qa, qda, qdda)
    forces = np.zeros((len(qa), 3))
    closure = np.zeros(len(qa))
    slides = [lay.slide[i][1] for i in legs]
    for t in range(len(qa)):  # the slide forces of the driven legs; the others carry none
        forces[t, list(legs)] = eng.inverse_dynamics(qpos[t], qvel[t], qacc[t], slides)
        closure[t] = float(np.max(np.abs(eng.equality()[1])))
    return forces, closure


def _fast_motion(t: Array) -> tuple[Array, Array, Array]:
    """A brisk test motion (about 100x the paper's accelerations) so that inertia, not gravity, dominates."""
    a, wa, b, wb = 0.5, 2 * np.pi * 0.5, 0.3, 2 * np.pi * 0.35
    q = np.stack([a * np.sin(wa * t), b * np.sin(wb * t) + 0.1], -1)
    qd = np.stack([a * wa * np.cos(wa * t), b * wb * np.cos(wb * t)], -1)
    qdd = np.stack([-a * wa * wa * np.sin(wa * t), -b * wb * wb * np.sin(wb * t)], -1)
    return q, qd, qdd


def _trajectories() -> dict[str, tuple[Array, Array, Array]]:
    """The checked motions: the two Section 6.1 sway modes, Fig. 5(b), and a brisk test motion."""
    t = np.arange(0.0, 20.0, 0.5)
    return {
        "sway about X": sl.sway(t, "x"),
        "sway about Y": sl.sway(t, "y"),
        "Fig. 5(b)": sl.fig5_motion("b", np.arange(0.0, 25.0, 0.5)),
        "brisk test motion": _fast_motion(np.arange(0.0, 4.0, 0.05)),
    }


def _point_velocity(m: mujoco.MjModel, d: mujoco.MjData, body: int, p: Array) -> Array:
    jacp = np.zeros((3, m.nv))
    mujoco.mj_jac(m, d, jacp, None, p, body)
    return np.asarray(jacp @ d.qvel)


def _state_errors(
    engine_leg: sl.SphericalLeg, leg: sl.SphericalLeg, q: Array, qd: Array, qdd: Array, paper_as_printed: bool
) -> dict[str, float]:
    """Kinematic and dynamic errors of ``leg``'s analytic model at the states of a trajectory, in the
    engine built from ``engine_leg``; relative errors as (max error, max scale) pairs folded later."""
    eng = Engine(build_model(engine_leg))
    m, d = eng.model, eng.data
    lay = _Layout(m, engine_leg)
    qpos, qvel, _ = _engine_states(m, lay, leg, q, qd, qdd)
    n = len(q)
    # unit platform rates: the engine's qvel per unit alpha_dot, beta_dot (G, from the analytic joint map)
    G = [_engine_states(m, lay, leg, q, np.broadcast_to(e, q.shape), np.zeros_like(q))[1] for e in np.eye(2)]
    ik = sl.inverse_kinematics(leg, q[:, 0], q[:, 1])
    Ja = sl.jacobian(leg, q[:, 0], q[:, 1])
    Ma = sl.mass_matrix(leg, q, paper_as_printed=paper_as_printed)
    Ta, Va = sl.mechanical_energy(leg, q, qd, paper_as_printed=paper_as_printed)
    w = np.einsum("nij,nj->ni", sl.angular_velocity_jacobian(q[:, 0]), qd)
    err: dict[str, float] = {}

    def up(key: str, e: float) -> None:
        err[key] = max(err.get(key, 0.0), float(e))

    for t in range(n):
        Ve, Te = eng.energies(qpos[t], qvel[t])
        Jc, pos = eng.equality()
        up("closure", np.max(np.abs(pos)))
        up("velocity closure", np.max(np.abs(Jc @ d.qvel)))
        Bt = ik.platform_points[t]
        Rp, pp = d.xmat[lay.platform].reshape(3, 3), d.xpos[lay.platform]
        Jeng = np.zeros((3, 2))
        for i in range(3):
            B_plat = Rp @ lay.B_home[i] + pp
            Ru, pu = d.xmat[lay.upper[i]].reshape(3, 3), d.xpos[lay.upper[i]]
            B_leg = Ru @ np.array([lay.l0[i], 0.0, 0.0]) + pu
            up("sites", max(np.max(np.abs(B_plat - Bt[i])), np.max(np.abs(B_leg - Bt[i]))))
            vB = np.cross(w[t], Bt[i])
            v1 = _point_velocity(m, d, lay.platform, B_plat)
            v2 = _point_velocity(m, d, lay.upper[i], B_leg)
            up("site velocity", max(np.max(np.abs(v1 - vB)), np.max(np.abs(v2 - vB))))
            # the engine's leg-length Jacobian: s . dB/d(alpha, beta) from the platform's point Jacobian
            jacp = np.zeros((3, m.nv))
            mujoco.mj_jac(m, d, jacp, None, B_plat, lay.platform)
            A = d.xpos[lay.cardan[i]]
            s = (B_plat - A) / np.linalg.norm(B_plat - A)
            Jeng[i] = s @ jacp[:, [lay.alpha[1], lay.beta[1]]]
        up("jacobian", np.max(np.abs(Jeng - Ja[t])) / np.max(np.abs(Ja[t])))
        Gt = np.stack([G[0][t], G[1][t]], -1)
        Me = Gt.T @ eng.mass_matrix() @ Gt
        up("mass matrix", np.max(np.abs(Me - Ma[t])) / np.max(np.abs(Ma[t])))
        up("energy", max(abs(Te - Ta[t]), abs(Ve - Va[t])) / max(abs(Ta[t]) + abs(Va[t]), 1e-300))
    # FK of the engine's own leg lengths (only alpha, beta set: the platform placed by the engine)
    L = _engine_leg_lengths(m, mujoco.MjData(m), lay, q)
    fk = sl.forward_kinematics(leg, L)
    fk_err = np.abs(np.stack([fk.alpha, fk.beta], -1) - q)
    up("fk", float(np.max(fk_err)) if bool(np.all(fk.valid)) else np.inf)
    return err


def _engine_leg_lengths(m: mujoco.MjModel, d: mujoco.MjData, lay: _Layout, q: Array) -> Array:
    """Leg lengths |B_i - A_i| ``(n, 3)`` in the engine at the platform angles ``q (n, 2)``: only alpha,
    beta set (the platform placed by the engine's hinges), A_i the cardans' origins."""
    L = np.zeros((len(q), 3))
    for k in range(len(q)):
        d.qpos[:] = 0.0
        d.qpos[lay.alpha[0]], d.qpos[lay.beta[0]] = q[k]
        mujoco.mj_kinematics(m, d)
        Rp, pp = d.xmat[lay.platform].reshape(3, 3), d.xpos[lay.platform]
        for i in range(3):
            L[k, i] = np.linalg.norm(Rp @ lay.B_home[i] + pp - d.xpos[lay.cardan[i]])
    return L


def engine_leg_accelerations(leg: sl.SphericalLeg, t: Array, q: Array) -> Array:
    """Leg accelerations (n - 4, 3) at t[2:-2]: 4th-order central differences of the engine's leg lengths
    |B_i - A_i| (platform placed by the engine's hinges, A_i the cardans' origins; uniform t)."""
    m = build_model(leg)
    d = mujoco.MjData(m)
    lay = _Layout(m, leg)
    L = _engine_leg_lengths(m, d, lay, q)
    dt = t[1] - t[0]
    return np.asarray((-L[:-4] + 16 * L[1:-3] - 30 * L[2:-2] + 16 * L[3:-1] - L[4:]) / (12 * dt * dt))


def forward_simulation(
    leg: sl.SphericalLeg, analytic: sl.SphericalLeg, paper_as_printed: bool = False
) -> tuple[float, float, dict[str, Array]]:
    """Drive the engine with ``analytic``'s feed-forward forces (legs 1, 3) plus a weak PD on the leg
    lengths along the brisk test motion; returns (max pose error rad, feedback share, traces)."""
    eng = Engine(build_model(leg, SIM_TIMESTEP))
    m = eng.model
    lay = _Layout(m, leg)
    t = np.arange(0.0, SIM_DURATION, SIM_TIMESTEP)
    q, qd, qdd = _fast_motion(t)
    ff = sl.inverse_dynamics(
        analytic, q, qd, qdd, driven_legs=sl.PAPER_DRIVEN_LEGS, paper_as_printed=paper_as_printed
    ).leg_forces
    l_ref, ld_ref, _ = sl.leg_rates(leg, q, qd, qdd)
    kp = SIM_PD_MASS * SIM_PD_BANDWIDTH**2
    kd = 2.0 * SIM_PD_MASS * SIM_PD_BANDWIDTH
    qpos, qvel, _ = _engine_states(m, lay, leg, q[:1], qd[:1], qdd[:1])
    eng.set_state(qpos[0], qvel[0])
    act = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, f"act_l{i + 1}") for i in range(3)]
    fb_max = 0.0

    def servo(d: mujoco.MjData) -> None:  # feed-forward leg forces plus the weak PD on the lengths
        nonlocal fb_max
        k = round(d.time / SIM_TIMESTEP)
        for i in sl.PAPER_DRIVEN_LEGS:
            li = d.qpos[lay.slide[i][0]] + lay.l0[i]
            fb = kp * (l_ref[k, i] - li) + kd * (ld_ref[k, i] - d.qvel[lay.slide[i][1]])
            fb_max = max(fb_max, abs(fb))
            d.ctrl[act[i]] = ff[k, i] + fb

    def pose_error(d: mujoco.MjData) -> float:
        k = round(d.time / SIM_TIMESTEP)
        return max(abs(d.qpos[lay.alpha[0]] - q[k, 0]), abs(d.qpos[lay.beta[0]] - q[k, 1]))

    err = np.array(eng.simulate(t, pose_error, servo))
    share = fb_max / float(np.max(np.abs(ff)))
    return float(err.max()), share, {"t": t, "error": err}


def run_checks(analytic: sl.SphericalLeg | None = None, *, paper_as_printed: bool = False) -> list[Check]:
    """All checks of the paper-1 verification; ``analytic`` (default: the engine's own parameters) is the
    model being verified: pass a deliberately wrong one to see the checks fail.  ``paper_as_printed``
    verifies the analytic dynamics without the legs' spin that the base universal joints impose (paper
    1, eq. (23)): the dynamic checks then fail: the paper's energy misses that spin."""
    if analytic is not None:
        check_params(analytic, sl.SphericalLeg, "analytic")
    printed = check_bool(paper_as_printed, "paper_as_printed")
    leg = sl.SphericalLeg.paper()
    analytic = leg if analytic is None else analytic
    name = "spherical-leg"
    checks: list[Check] = []
    trajs = _trajectories()
    err: dict[str, float] = {}
    for q, qd, qdd in trajs.values():
        for k, v in _state_errors(leg, analytic, q, qd, qdd, printed).items():
            err[k] = max(err.get(k, 0.0), v)
    checks += [
        Check(name, "loop closure of analytic joints (m)", err["closure"], CLOSURE_TOL, "engine efc_pos"),
        Check(name, "platform points B_i vs engine (m)", err["sites"], CLOSURE_TOL, "platform and leg tips"),
        Check(name, "velocity closure efc_J qvel (m/s)", err["velocity closure"], VELOCITY_TOL),
        Check(name, "B_i velocity vs engine mj_jac (m/s)", err["site velocity"], VELOCITY_TOL),
        Check(name, "leg Jacobian dl/dq vs engine", err["jacobian"], JACOBIAN_TOL, "s . mj_jac(B_i)"),
        Check(name, "forward kinematics of engine lengths (rad)", err["fk"], FK_TOL),
    ]
    t = np.arange(0.0, 20.0, 0.01)
    acc_err = 0.0
    for about in ("x", "y"):
        q, qd, qdd = sl.sway(t, about)
        ldd_e = engine_leg_accelerations(leg, t, q)
        ldd_a = sl.leg_rates(analytic, q, qd, qdd)[2][2:-2]
        acc_err = max(acc_err, float(np.max(np.abs(ldd_e - ldd_a)) / np.max(np.abs(ldd_a))))
    checks.append(Check(name, "leg accelerations vs engine (Section 6.1 modes)", acc_err, ACCEL_TOL))
    checks += [
        Check(name, "mass matrix G^T M G vs engine (mj_fullM)", err["mass matrix"], MASS_TOL),
        Check(name, "kinetic and potential energy vs engine", err["energy"], ENERGY_TOL, "mj_energyVel/Pos"),
    ]
    for rule, legs in (("legs 1, 3 driven (paper's rule)", sl.PAPER_DRIVEN_LEGS), ("minimum norm", None)):
        f_err = 0.0
        for q, qd, qdd in trajs.values():
            fe, _ = inverse_dynamics_engine(leg, q, qd, qdd, driven_legs=legs)
            fa = sl.inverse_dynamics(
                analytic, q, qd, qdd, driven_legs=legs, paper_as_printed=printed
            ).leg_forces
            f_err = max(f_err, float(np.max(np.abs(fe - fa)) / np.max(np.abs(fa))))
        quantity = "actuator forces vs engine inverse dynamics"
        checks.append(
            Check(
                name,
                quantity if legs is not None else quantity + " (minimum norm)",
                f_err,
                FORCE_TOL,
                f"{rule}; 4 trajectories incl. a brisk one; mj_rne through null(efc_J)",
            )
        )
    no_spin = replace(leg, screw_spin=False)
    sim_err, share, _ = forward_simulation(no_spin, replace(analytic, screw_spin=False), printed)
    checks.append(
        Check(
            name,
            "forward simulation: pose tracking (rad)",
            sim_err,
            SIM_TRACKING_TOL,
            "engine driven by analytic feed-forward + weak PD; screw spin off (PD tuned for it)",
        )
    )
    checks.append(Check(name, "forward simulation: feedback share of force", share, SIM_FEEDBACK_TOL))
    return checks


def study_overlays(leg: sl.SphericalLeg) -> dict[str, Any]:
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
    title="Paper 1 spherical parallel leg vs MuJoCo (generic export of its description)",
    engine="MuJoCo",
    requires=("mujoco",),
    run=run_checks,
)
