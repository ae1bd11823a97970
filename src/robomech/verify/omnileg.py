"""Paper 2 (OmniLeg) against MuJoCo: the engine plays the role of the paper's ADAMS prototype.

The MJCF is generated from the same :class:`OmniLeg` parameters: a spanning tree of 22 hinges
(``TREE_JOINTS``: chain 1 carrying the knee plate, chains 2 and 3 without their last joint, the double-Cardan
drive, the shank cranks and couplers, the foot on coupler 1) and the loop closures as MuJoCo equality
constraints: each cut hinge is two ``connect`` constraints at two points of its axis; the 1:1 bevel gears
are ``joint`` equalities crank_i = drive_out.  The thigh is over-constrained (the engine's solver handles
the redundant rows).

Checks (each a :class:`Check` with a named tolerance):

* kinematics: analytic joint angles in ``qpos`` -> equality-constraint violation ``efc_pos`` and the foot
  site against eq. (11); analytic joint rates in ``qvel`` -> ``efc_J qvel`` and the foot site velocity
  against ``J q̇``;
* inverse dynamics: the engine's tree inverse dynamics (``M q̈ + c`` from ``mj_inverse``/``mj_mulM``,
  constraint forces left out) along eq. (52) with Fig. 11's foot force, projected through the
  constraint Jacobian
  (``τ_tree = Sᵀ τ + J_cᵀ λ``, least squares) -> motor torques, against the analytic model;
* forward simulation: the engine driven only by the analytic torques follows eq. (52).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

import robomech.mechanisms.omnileg as ol
from robomech._validation import as_array, broadcast_batch, check_params

from ._core import Check, Tolerance, Verification, optional_module

if TYPE_CHECKING:
    import mujoco
else:  # imported on first use: discovering this module must not need the optional engine
    mujoco = optional_module("mujoco")

__all__ = ["VERIFICATION", "EngineModel", "build_mjcf", "build_model", "engine_inverse_dynamics", "run"]

MECHANISM = "omnileg"
# Tree joints driven by the motors, in q = (α, β, γ) order.
ACTUATED_JOINTS = ("theta21", "theta11", "drive_in")
# Distance between the two connect anchors that replace a cut hinge (m): any non-zero length on the
# axis works; 20 mm keeps the rows well conditioned against the 0.1 m link scale.
CONNECT_SPAN = 0.02
# Kinematic agreement: analytic joint values satisfy the engine's closure and foot site to rounding.
TOL_KINEMATICS = Tolerance(1e-12, "pure geometry: rounding of O(0.5 m) positions through 8 joint transforms")
TOL_VELOCITY = Tolerance(
    1e-12, "pure geometry: rounding of O(1 m/s) velocities through the constraint Jacobian"
)
# Inverse dynamics: both sides are exact rigid-body models of the same bodies; only rounding differs.
TOL_TORQUE = Tolerance(
    1e-6, "exact tree inverse dynamics + least-squares projection; rounding only", relative=True
)
# Forward simulation: MuJoCo's equality constraints are soft.  A stiff setting (time constant 0.5 ms =
# 5 steps, impedance 0.9999; with the default 2 ms / 0.9-0.95 the gears lag by ~1e-2 rad) and the Euler
# step of 0.1 ms leave a slow open-loop drift from the commanded trajectory (measured 5.5e-5 rad over 2 s).
SIM_TIMESTEP = 1e-4
SIM_SOLREF = (0.0005, 1.0)
SIM_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
TOL_SIM_DRIFT = Tolerance(
    1e-3, "open-loop drift over 2 s: soft constraints (0.5 ms, 0.9999) and 0.1 ms Euler steps"
)
TOL_SIM_CLOSURE = Tolerance(1e-5, "violation of the stiff soft equality constraints under load (m, rad)")
# Samples of the eq. (52) trajectory used by the kinematic and torque checks (0-2 s, Fig. 11's window).
N_CHECK = 120
FIG11_FORCE = np.array([0.0, -20.0, 20.0])


def _quat(R: np.ndarray) -> str:
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(R, dtype=float).ravel())
    return " ".join(f"{v:.17g}" for v in q)


def _vec(v) -> str:
    return " ".join(f"{float(x):.17g}" for x in v)


def _inertial(body: ol.RigidBody) -> str:
    I = body.inertia_matrix
    full = [I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]
    return f'<inertial pos="{_vec(body.com)}" mass="{body.mass:.17g}" fullinertia="{_vec(full)}"/>'


def _kR(k: int) -> np.ndarray:
    d = 0.5 * np.pi * k
    c, s = np.cos(d), np.sin(d)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])  # paper 2, eq. (5) as printed (Rz(-δ))


def build_mjcf(leg: ol.OmniLeg) -> str:
    """MJCF of the whole leg at its home pose (q = 0), from the parameter dataclass."""
    check_params(leg, ol.OmniLeg, "leg")
    b = leg.bodies
    S = ol.shank_frames(leg)
    r, h = leg.shank_radius, leg.knee_to_crank
    hinge = 'limited="false" damping="0" armature="0"'
    parts = []

    def chain(k: int, with_plate: bool) -> str:
        A = _kR(k) @ np.array([0.0, leg.L3, 0.0])
        j = [f"theta{k + 1}{i}" for i in range(1, 5)]
        inner = ""
        if with_plate:
            shank = ""
            for i in range(3):
                foot = ""
                if i == 0:
                    foot = (
                        f'<body name="foot" pos="{_vec([-r, 0.0, leg.L4])}" quat="{_quat(S[0].T)}">'
                        f'<joint name="foot" type="hinge" pos="{_vec(S[0] @ [r, 0, 0])}" '
                        f'axis="{_vec(S[0][:, 0])}" {hinge}/>'
                        f"{_inertial(b['foot'])}"
                        f'<site name="foot_point" pos="0 0 {leg.foot_drop:.17g}" size="0.005"/></body>'
                    )
                shank += (
                    f'<body name="crank_{i + 1}" pos="{_vec(S[i] @ [r, 0.0, h])}" quat="{_quat(S[i])}">'
                    f'<joint name="crank_{i + 1}" type="hinge" axis="1 0 0" {hinge}/>{_inertial(b["crank"])}'
                    f'<body name="coupler_{i + 1}" pos="0 0 {leg.L4:.17g}">'
                    f'<joint name="coupler_{i + 1}" type="hinge" axis="1 0 0" {hinge}/>'
                    f"{_inertial(b['coupler'])}"
                    f"{foot}</body></body>"
                )
            inner = (
                f'<body name="knee_plate" pos="0 {-leg.L3:.17g} 0">'
                f'<joint name="theta14" type="hinge" pos="0 {leg.L3:.17g} 0" axis="0 1 0" {hinge}/>'
                f"{_inertial(b['knee_plate'])}"
                f'<body name="drive_shaft_out"><joint name="drive_out" type="hinge" axis="0 0 1" {hinge}/>'
                f"{_inertial(b['drive_shaft_out'])}</body>{shank}</body>"
            )
        return (
            f'<body name="hip_cross_{k + 1}" pos="{_vec(A)}" quat="{_quat(_kR(k))}">'
            f'<joint name="{j[0]}" type="hinge" axis="0 1 0" {hinge}/>{_inertial(b["hip_cross"])}'
            f'<body name="thigh_rod_{k + 1}"><joint name="{j[1]}" type="hinge" axis="1 0 0" {hinge}/>'
            f"{_inertial(b['thigh_rod'])}"
            f'<body name="knee_cross_{k + 1}" pos="0 0 {leg.L1:.17g}">'
            f'<joint name="{j[2]}" type="hinge" axis="1 0 0" {hinge}/>{_inertial(b["knee_cross"])}'
            f"{inner}</body></body></body>"
        )

    parts.append(chain(0, True))
    parts.append(chain(1, False))
    parts.append(chain(2, False))
    parts.append(
        '<body name="drive_shaft_in"><joint name="drive_in" type="hinge" axis="0 0 1" ' + hinge + "/>"
        f"{_inertial(b['drive_shaft_in'])}"
        f'<body name="drive_cross_a"><joint name="drive_phi1" type="hinge" axis="0 1 0" {hinge}/>'
        f"{_inertial(b['drive_cross'])}"
        f'<body name="drive_rod"><joint name="drive_phi2" type="hinge" axis="1 0 0" {hinge}/>'
        f"{_inertial(b['drive_rod'])}"
        f'<body name="drive_cross_b" pos="0 0 {leg.L1:.17g}">'
        f'<joint name="drive_phi3" type="hinge" axis="1 0 0" {hinge}/>{_inertial(b["drive_cross"])}'
        "</body></body></body></body>"
    )
    d = CONNECT_SPAN
    eq = []
    for k in (2, 3):  # chains 2, 3: cut hinge theta_k4 about the cross's local y
        for a in ((0, 0, 0), (0, d, 0)):
            eq.append(f'<connect body1="knee_cross_{k}" body2="knee_plate" anchor="{_vec(a)}"/>')
    for a in ((0, 0, 0), (0, d, 0)):  # drive: cut hinge of cross B4 about its local y (a1)
        eq.append(f'<connect body1="drive_cross_b" body2="drive_shaft_out" anchor="{_vec(a)}"/>')
    for i in (2, 3):  # shank: couplers 2, 3 close on the foot at E_i (hinge about local x)
        for a in ((0, 0, leg.L4), (d, 0, leg.L4)):
            eq.append(f'<connect body1="coupler_{i}" body2="foot" anchor="{_vec(a)}"/>')
    for i in (1, 2, 3):  # 1:1 bevel gears
        eq.append(f'<joint joint1="crank_{i}" joint2="drive_out" polycoef="0 1 0 0 0"/>')
    return (
        '<mujoco model="omnileg"><compiler angle="radian" autolimits="false"/>'
        f'<option gravity="{_vec(leg.gravity)}" timestep="{SIM_TIMESTEP}" jacobian="dense">'
        '<flag contact="disable"/></option>'
        f'<default><equality solref="{_vec(SIM_SOLREF)}" solimp="{_vec(SIM_SOLIMP)}"/></default>'
        f"<worldbody>{''.join(parts)}</worldbody><equality>{''.join(eq)}</equality></mujoco>"
    )


@dataclass
class EngineModel:
    model: mujoco.MjModel
    data: mujoco.MjData
    qpos_index: np.ndarray  # tree joint i (TREE_JOINTS order) -> qpos address
    dof_index: np.ndarray  # tree joint i -> dof address (qvel, qacc, forces)
    actuated: np.ndarray  # dof addresses of (α, β, γ) = (theta21, theta11, drive_in)
    foot_site: int


def build_model(leg: ol.OmniLeg) -> EngineModel:
    check_params(leg, ol.OmniLeg, "leg")
    m = mujoco.MjModel.from_xml_string(build_mjcf(leg))
    d = mujoco.MjData(m)
    jid = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n) for n in ol.TREE_JOINTS]
    qadr = np.array([m.jnt_qposadr[j] for j in jid])
    dadr = np.array([m.jnt_dofadr[j] for j in jid])
    act = dadr[[ol.TREE_JOINTS.index(n) for n in ACTUATED_JOINTS]]
    site = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "foot_point")
    return EngineModel(m, d, qadr, dadr, act, site)


def _set_state(em: EngineModel, qpos: np.ndarray, qvel: np.ndarray, qacc: np.ndarray | None = None) -> None:
    em.data.qpos[em.qpos_index] = qpos
    em.data.qvel[em.dof_index] = qvel
    if qacc is not None:
        em.data.qacc[em.dof_index] = qacc


def _eq_rows(em: EngineModel) -> np.ndarray:
    return np.flatnonzero(em.data.efc_type[: em.data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)


def engine_inverse_dynamics(
    em: EngineModel, jm: ol.JointMotion, foot_force: np.ndarray | None = None
) -> np.ndarray:
    """Motor torques (N, 3) from the engine, one sample at a time (the per-sample alternative).

    Per sample: ``mj_inverse`` (which also builds the constraint Jacobian ``efc_J``), the tree forces
    ``τ_tree = M q̈ + c(q, q̇) - J_footᵀ F`` (``mj_mulM`` + ``qfrc_bias``: the constraint forces are left
    out), then least squares on ``[Sᵀ J_cᵀ] [τ; λ] = τ_tree`` (minimum norm: the thigh's redundant
    closure rows leave λ, not τ, undetermined).
    """
    check_params(em, EngineModel, "em")
    check_params(jm, ol.JointMotion, "jm")
    m, d = em.model, em.data
    N = jm.q.shape[0]
    if foot_force is not None:
        foot_force = as_array(foot_force, "foot_force", (3,))
        broadcast_batch((foot_force, 1, "foot_force"), (jm.q, 1, "jm.q"))
        foot_force = np.broadcast_to(foot_force, (N, 3))
    out = np.empty((N, 3))
    nv = m.nv
    S = np.zeros((3, nv))
    S[[0, 1, 2], em.actuated] = 1.0
    jacp = np.zeros((3, nv))
    Mqacc = np.zeros(nv)
    for n in range(N):  # the per-sample engine loop (this is what the analytic model is compared with)
        _set_state(em, jm.q[n], jm.qd[n], jm.qdd[n])
        mujoco.mj_inverse(m, d)
        rows = _eq_rows(em)
        Jc = d.efc_J.reshape(-1, nv)[rows]
        mujoco.mj_mulM(m, d, Mqacc, d.qacc)
        tau_tree = Mqacc + d.qfrc_bias
        if foot_force is not None:
            mujoco.mj_jacSite(m, d, jacp, None, em.foot_site)
            tau_tree = tau_tree - jacp.T @ foot_force[n]
        sol = np.linalg.lstsq(np.vstack([S, Jc]).T, tau_tree, rcond=None)[0]
        out[n] = sol[:3]
    return out


def _trajectory(n: int, duration: float = 2.0) -> tuple[np.ndarray, object]:
    t = np.linspace(0.0, duration, n)
    return t, ol.joint_trajectory_eq52(t)


def kinematic_checks(leg: ol.OmniLeg, em: EngineModel) -> list[Check]:
    rng = np.random.default_rng(7)
    _, prof = _trajectory(N_CHECK, 6.0)
    qr = np.stack(
        [
            rng.uniform(-1, 1, 60) * leg.alpha_max,
            rng.uniform(-1, 1, 60) * leg.beta_max,
            rng.uniform(leg.gamma_min, leg.gamma_max, 60),
        ],
        -1,
    )
    q = np.concatenate([prof.q, qr])
    qd = np.concatenate([prof.qd, rng.normal(size=qr.shape)])
    jm = ol.joint_motion(leg, q, qd, np.zeros_like(q))
    m, d = em.model, em.data
    closure, foot, cvel, fvel = 0.0, 0.0, 0.0, 0.0
    jacp = np.zeros((3, m.nv))
    p_an = ol.forward_kinematics(leg, q)
    v_an = ol.foot_velocity(leg, q, qd)
    for n in range(q.shape[0]):
        _set_state(em, jm.q[n], jm.qd[n])
        mujoco.mj_forward(m, d)
        rows = _eq_rows(em)
        closure = max(closure, float(np.abs(d.efc_pos[rows]).max()))
        foot = max(foot, float(np.abs(d.site_xpos[em.foot_site] - p_an[n]).max()))
        J = d.efc_J.reshape(-1, m.nv)[rows]
        cvel = max(cvel, float(np.abs(J @ d.qvel).max()))
        mujoco.mj_jacSite(m, d, jacp, None, em.foot_site)
        fvel = max(fvel, float(np.abs(jacp @ d.qvel - v_an[n]).max()))
    return [
        Check(
            MECHANISM,
            "loop closure |efc_pos| at analytic joints",
            closure,
            TOL_KINEMATICS,
            "eq. (52) + 60 random poses; thigh PoE closure, Cardan drive, gears, shank",
        ),
        Check(MECHANISM, "foot site vs eq. (11) (m)", foot, TOL_KINEMATICS),
        Check(MECHANISM, "closure velocity |J_c qvel| (analytic q̇)", cvel, TOL_VELOCITY),
        Check(MECHANISM, "foot site velocity vs J q̇ (m/s)", fvel, TOL_VELOCITY),
    ]


def torque_error(
    leg_analytic: ol.OmniLeg, em: EngineModel, n: int = N_CHECK
) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """Relative max torque difference analytic vs engine along eq. (52), 0-2 s, Fig. 11's force in 0-1 s."""
    t, prof = _trajectory(n)
    F = np.where((t <= 1.0)[:, None], FIG11_FORCE, 0.0)
    tau_an = ol.inverse_dynamics(leg_analytic, prof.q, prof.qd, prof.qdd, foot_force=F).tau
    jm = ol.joint_motion(leg_analytic, prof.q, prof.qd, prof.qdd)
    tau_en = engine_inverse_dynamics(em, jm, F)
    err = float(np.abs(tau_an - tau_en).max() / np.abs(tau_en).max())
    return err, t, tau_an, tau_en


def forward_simulation(
    leg: ol.OmniLeg, em: EngineModel, duration: float = 2.0
) -> dict[str, np.ndarray | float]:
    """Drive the engine with the analytic torques of eq. (52) (no foot force) and record the drift."""
    m, d = em.model, em.data
    n_steps = round(duration / m.opt.timestep)
    t = np.arange(n_steps + 1) * m.opt.timestep
    prof = ol.joint_trajectory_eq52(t)
    tau = ol.inverse_dynamics(leg, prof.q, prof.qd, prof.qdd).tau
    jm0 = ol.joint_motion(leg, prof.q[0], prof.qd[0], prof.qdd[0])
    mujoco.mj_resetData(m, d)
    _set_state(em, jm0.q, jm0.qd)
    mujoco.mj_forward(m, d)
    q_sim = np.empty((n_steps + 1, 3))
    closure = 0.0
    rows = _eq_rows(em)  # no contacts or limits: the equality rows are fixed
    act_q = em.qpos_index[[ol.TREE_JOINTS.index(n) for n in ACTUATED_JOINTS]]
    for k in range(n_steps + 1):  # time stepping (inherently sequential)
        q_sim[k] = d.qpos[act_q]
        closure = max(closure, float(np.abs(d.efc_pos[rows]).max()))
        if k == n_steps:
            break
        d.qfrc_applied[:] = 0.0
        d.qfrc_applied[em.actuated] = 0.5 * (tau[k] + tau[k + 1])
        mujoco.mj_step(m, d)
    drift = float(np.abs(q_sim - prof.q).max())
    return {"t": t, "q_sim": q_sim, "q_ref": prof.q, "drift": drift, "closure": closure}


def run() -> list[Check]:
    leg = ol.OmniLeg.paper()
    em = build_model(leg)
    checks = kinematic_checks(leg, em)
    err, *_ = torque_error(leg, em)
    checks.append(
        Check(
            MECHANISM,
            "motor torques vs engine ID, eq. (52)+Fig.11",
            err,
            TOL_TORQUE,
            "engine M q̈ + c, least squares through the equality-constraint Jacobian",
        )
    )
    sim = forward_simulation(leg, em)
    checks.append(
        Check(
            MECHANISM,
            "forward-sim drift from eq. (52) (rad)",
            float(sim["drift"]),
            TOL_SIM_DRIFT,
        )
    )
    checks.append(
        Check(MECHANISM, "forward-sim constraint violation", float(sim["closure"]), TOL_SIM_CLOSURE)
    )
    return checks


VERIFICATION = Verification(
    name="omnileg",
    title="Paper 2: OmniLeg vs MuJoCo (closure, foot kinematics, torques, forward simulation)",
    engine="MuJoCo",
    requires=("mujoco",),
    run=run,
)
