"""Paper 2 (OmniLeg) against MuJoCo: the engine plays the role of the paper's ADAMS prototype.

The engine model is the generic export of the leg's description,
``robomech.multibody.to_mjcf(omnileg.to_multibody(leg))`` (no hand-written MJCF): the 22 bodies with the
analytic model's inertias, the spanning tree of 22 hinges (``TREE_JOINTS``: chain 1 carrying the knee
plate, chains 2 and 3 without their last joint, the double-Cardan drive, the shank cranks and couplers,
the foot on coupler 1), each cut hinge as two ``connect`` constraints on its axis and the 1:1 bevel gears
as ``joint`` equalities crank_i = drive_out.  :func:`build_mjcf` adds only the engine options of the
forward simulation (time step, stiff equality constraints).  The thigh is over-constrained (the engine's
solver handles the redundant rows).

Checks of the *analytic* model (``mechanisms/omnileg``, Lagrange) against the engine, each a
:class:`Check` with a named tolerance:

* kinematics: analytic joint angles (``joint_motion``) in ``qpos`` -> equality-constraint violation
  ``efc_pos`` and the foot site against eq. (11); analytic joint rates in ``qvel`` -> ``efc_J qvel`` and
  the foot site velocity against ``J q̇``;
* energy: analytic kinetic and potential energy against the engine's ``mj_energyPos``/``mj_energyVel``;
* inverse dynamics: the engine's tree inverse dynamics (``M q̈ + c`` from ``mj_rne``, constraint
  forces left out) along eq. (52) with Fig. 11's foot force, projected on the null space of the
  constraint Jacobian (``Nᵀ (Sᵀ τ - τ_tree) = 0``, least squares) -> motor torques, against the
  analytic model;
* forward simulation: the engine driven only by the analytic torques follows eq. (52).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

import robomech.mechanisms.omnileg as ol
from robomech import multibody as mb
from robomech._validation import as_array, broadcast_batch, check_params, check_positive
from robomech.trajectory import Profile

from ._core import Check, Tolerance, Verification, optional_module
from ._mujoco import Engine, engine_options, model_digest
from ._store import computed_once

if TYPE_CHECKING:
    import mujoco
else:  # imported on first use: discovering this module must not need the optional engine
    mujoco = optional_module("mujoco")

__all__ = ["VERIFICATION", "EngineModel", "build_mjcf", "build_model", "engine_inverse_dynamics", "run"]

Array = NDArray[np.float64]

MECHANISM = "omnileg"
# Tree joints driven by the motors, in q = (α, β, γ) order (the description's actuators).
ACTUATED_JOINTS = ("theta21", "theta11", "drive_in")
# The foot point (eq. (11)) in the description.
FOOT_SITE = "foot"
# Kinematic agreement: analytic joint values satisfy the engine's closure and foot site to rounding.
TOL_KINEMATICS = Tolerance(1e-12, "pure geometry: rounding of O(0.5 m) positions through 8 joint transforms")
TOL_VELOCITY = Tolerance(
    1e-12, "pure geometry: rounding of O(1 m/s) velocities through the constraint Jacobian"
)
# Energy: the same bodies summed by two codes (MuJoCo from its compiled principal inertias).
TOL_ENERGY = Tolerance(1e-10, "the same 22 rigid bodies; rounding of principal-axis inertias", relative=True)
# Inverse dynamics: both sides are exact rigid-body models of the same bodies; only rounding differs
# (measured 6e-15; the bar is 1e-8 relative).
TOL_TORQUE = Tolerance(
    1e-8, "exact tree inverse dynamics + least-squares projection; rounding only", relative=True
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


def _vec(v: ArrayLike) -> str:
    return " ".join(f"{float(x):.17g}" for x in np.ravel(v))


def build_mjcf(leg: ol.OmniLeg) -> str:
    """MJCF of the whole leg: ``mb.to_mjcf(omnileg.to_multibody(leg))`` plus the simulation options.

    The options (not part of a mechanism description): time step ``SIM_TIMESTEP``, stiff equality
    constraints ``SIM_SOLREF``/``SIM_SOLIMP``, dense constraint Jacobian, contacts off.
    """
    check_params(leg, ol.OmniLeg, "leg")
    root = engine_options(
        mb.to_mjcf(ol.to_multibody(leg), comment="robomech verify omnileg"),
        timestep=SIM_TIMESTEP,
        jacobian="dense",
        solref=_vec(SIM_SOLREF),
        solimp=_vec(SIM_SOLIMP),
        contact=False,
    )
    return ET.tostring(root, encoding="unicode")


@dataclass
class EngineModel:
    model: mujoco.MjModel
    data: mujoco.MjData
    qpos_index: NDArray[np.intp]  # tree joint i (TREE_JOINTS order) -> qpos address
    dof_index: NDArray[np.intp]  # tree joint i -> dof address (qvel, qacc, forces)
    actuated: NDArray[np.intp]  # dof addresses of (α, β, γ) = (theta21, theta11, drive_in)
    foot_site: int

    @property
    def engine(self) -> Engine:
        """The shared harness on this model and data."""
        return Engine(self.model, self.data)

    def set_state(self, qpos: Array, qvel: Array, qacc: Array | None = None) -> mujoco.MjData:
        """Write tree-joint values (``TREE_JOINTS`` order) and run ``mj_forward``."""
        return self.engine.set_state(qpos, qvel, qacc, qpos_index=self.qpos_index, dof_index=self.dof_index)


def build_model(leg: ol.OmniLeg) -> EngineModel:
    """The engine model of :func:`build_mjcf` with the address maps of ``TREE_JOINTS`` and the foot site."""
    check_params(leg, ol.OmniLeg, "leg")
    eng = Engine(mujoco.MjModel.from_xml_string(build_mjcf(leg)))
    m = eng.model
    qadr, dadr = eng.joint_addresses(ol.TREE_JOINTS)
    act = dadr[[ol.TREE_JOINTS.index(n) for n in ACTUATED_JOINTS]]
    site = int(mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, FOOT_SITE))
    return EngineModel(m, eng.data, qadr, dadr, act, site)


def engine_inverse_dynamics(
    em: EngineModel, jm: ol.JointMotion, foot_force: ArrayLike | None = None
) -> Array:
    """Motor torques (N, 3) from the engine, one sample at a time (the per-sample alternative).

    Per sample (:meth:`Engine.inverse_dynamics <robomech.verify._mujoco.Engine.inverse_dynamics>`): the
    tree forces ``τ_tree = M q̈ + c(q, q̇) - J_footᵀ F`` (``mj_rne``: the constraint forces are left out),
    balanced by the motors in the null space ``N`` of the equality-constraint Jacobian,
    ``Nᵀ (Sᵀ τ - τ_tree) = 0`` (least squares; the thigh's redundant closure rows drop out of ``N``).
    """
    check_params(em, EngineModel, "em")
    check_params(jm, ol.JointMotion, "jm")
    m = em.model
    N = jm.q.shape[0]
    F: Array | None = None
    if foot_force is not None:
        F = as_array(foot_force, "foot_force", (3,))
        broadcast_batch((F, 1, "foot_force"), (jm.q, 1, "jm.q"))
        F = np.broadcast_to(F, (N, 3))
    out = np.empty((N, 3))
    jacp = np.zeros((3, m.nv))
    eng = em.engine

    def foot(n: int) -> Callable[[mujoco.MjData], Array] | None:  # J_footᵀ F at the state written
        if F is None:
            return None
        Fn = F[n]

        def applied(d: mujoco.MjData) -> Array:
            mujoco.mj_jacSite(m, d, jacp, None, em.foot_site)
            return np.asarray(jacp.T @ Fn)

        return applied

    for n in range(N):  # the per-sample engine loop (this is what the analytic model is compared with)
        idx = {"qpos_index": em.qpos_index, "dof_index": em.dof_index}
        out[n] = eng.inverse_dynamics(jm.q[n], jm.qd[n], jm.qdd[n], em.actuated, applied=foot(n), **idx)
    return out


def _trajectory(n: int, duration: float = 2.0) -> tuple[Array, Profile]:
    t = np.linspace(0.0, duration, n)
    return t, ol.joint_trajectory_eq52(t)


def _random_states(leg: ol.OmniLeg, n: int, seed: int) -> tuple[Array, Array]:
    """``n`` random poses inside Table 2's ranges and random rates (rad, rad/s)."""
    rng = np.random.default_rng(seed)
    q = np.stack(
        [
            rng.uniform(-1, 1, n) * leg.alpha_max,
            rng.uniform(-1, 1, n) * leg.beta_max,
            rng.uniform(leg.gamma_min, leg.gamma_max, n),
        ],
        -1,
    )
    return q, rng.normal(size=q.shape)


def kinematic_checks(leg: ol.OmniLeg, em: EngineModel) -> list[Check]:
    _, prof = _trajectory(N_CHECK, 6.0)
    qr, qdr = _random_states(leg, 60, 7)
    q = np.concatenate([prof.q, qr])
    qd = np.concatenate([prof.qd, qdr])
    jm = ol.joint_motion(leg, q, qd, np.zeros_like(q))
    m = em.model
    closure, foot, cvel, fvel = 0.0, 0.0, 0.0, 0.0
    jacp = np.zeros((3, m.nv))
    p_an = ol.forward_kinematics(leg, q)
    v_an = ol.foot_velocity(leg, q, qd)
    for n in range(q.shape[0]):
        d = em.set_state(jm.q[n], jm.qd[n])
        J, pos = em.engine.equality()
        closure = max(closure, float(np.abs(pos).max()))
        foot = max(foot, float(np.abs(d.site_xpos[em.foot_site] - p_an[n]).max()))
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


def energy_error(leg_analytic: ol.OmniLeg, em: EngineModel, n: int = 60) -> float:
    """Relative max difference of the analytic kinetic + potential energy from the engine's.

    Random poses and rates (``n`` samples); the engine's energy (``mj_energyPos`` + ``mj_energyVel``,
    potential ``-Σ m gᵀ p``, the analytic model's reference too) at the analytic joint state.  Kinetic
    and potential energy are compared separately, each relative to its own scale.
    """
    check_params(leg_analytic, ol.OmniLeg, "leg_analytic")
    check_params(em, EngineModel, "em")
    q, qd = _random_states(leg_analytic, n, 11)
    T_an, U_an = ol.energy(leg_analytic, q, qd)
    jm = ol.joint_motion(leg_analytic, q, qd, np.zeros_like(q))
    T_en, U_en = np.empty(n), np.empty(n)
    idx = {"qpos_index": em.qpos_index, "dof_index": em.dof_index}
    for k in range(n):
        U_en[k], T_en[k] = em.engine.energies(jm.q[k], jm.qd[k], **idx)
    eT = float(np.abs(T_an - T_en).max() / np.abs(T_en).max())
    eU = float(np.abs(U_an - U_en).max() / np.abs(U_en).max())
    return max(eT, eU)


def torque_error(
    leg_analytic: ol.OmniLeg, em: EngineModel, n: int = N_CHECK
) -> tuple[float, Array, Array, Array]:
    """Relative max torque difference analytic vs engine along eq. (52), 0-2 s, Fig. 11's force in 0-1 s."""
    t, prof = _trajectory(n)
    F = np.where((t <= 1.0)[:, None], FIG11_FORCE, 0.0)
    tau_an = ol.inverse_dynamics(leg_analytic, prof.q, prof.qd, prof.qdd, foot_force=F).tau
    jm = ol.joint_motion(leg_analytic, prof.q, prof.qd, prof.qdd)
    tau_en = engine_inverse_dynamics(em, jm, F)
    err = float(np.abs(tau_an - tau_en).max() / np.abs(tau_en).max())
    return err, t, tau_an, tau_en


def forward_simulation(leg: ol.OmniLeg, em: EngineModel, duration: float = 2.0) -> dict[str, Array | float]:
    """Drive the engine with the analytic torques of eq. (52) (no foot force) and record the drift.

    Returns ``t (n,)`` s, the actuated joints ``q_sim`` and ``q_ref (n, 3)`` rad, ``drift`` (rad) and
    ``closure`` (the largest equality violation).  The study draws it too: computed once per output
    folder (:mod:`robomech.verify._store`; the key holds ``leg``, ``duration`` and the engine model's
    bytes).
    """
    check_params(leg, ol.OmniLeg, "leg")
    check_params(em, EngineModel, "em")
    duration = check_positive(duration, "duration")
    params = (leg, duration, model_digest(em.model))
    return computed_once("omnileg.forward_simulation", params, lambda: _simulate(leg, em, duration))


def _simulate(leg: ol.OmniLeg, em: EngineModel, duration: float) -> dict[str, Array | float]:
    """:func:`forward_simulation`, computed."""
    m, d = em.model, em.data
    n_steps = round(duration / m.opt.timestep)
    t = np.arange(n_steps + 1) * m.opt.timestep
    prof = ol.joint_trajectory_eq52(t)
    tau = ol.inverse_dynamics(leg, prof.q, prof.qd, prof.qdd).tau
    jm0 = ol.joint_motion(leg, prof.q[0], prof.qd[0], prof.qdd[0])
    mujoco.mj_resetData(m, d)
    em.set_state(jm0.q, jm0.qd)
    rows = np.flatnonzero(d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)  # fixed: no contacts
    act_q = em.qpos_index[[ol.TREE_JOINTS.index(n) for n in ACTUATED_JOINTS]]

    def drive(d: mujoco.MjData) -> None:  # the analytic torques, averaged over the step
        k = round(d.time / m.opt.timestep)
        d.qfrc_applied[:] = 0.0
        d.qfrc_applied[em.actuated] = 0.5 * (tau[k] + tau[k + 1])

    rec = em.engine.simulate(t, lambda d: (d.qpos[act_q].copy(), float(np.abs(d.efc_pos[rows]).max())), drive)
    q_sim = np.array([r[0] for r in rec])
    closure = max(r[1] for r in rec)
    drift = float(np.abs(q_sim - prof.q).max())
    return {"t": t, "q_sim": q_sim, "q_ref": prof.q, "drift": drift, "closure": closure}


def run() -> list[Check]:
    leg = ol.OmniLeg.paper()
    em = build_model(leg)
    checks = kinematic_checks(leg, em)
    checks.append(
        Check(
            MECHANISM,
            "kinetic and potential energy vs engine (mj_energy)",
            energy_error(leg, em),
            TOL_ENERGY,
            "60 random states; each energy relative to its scale",
        )
    )
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
    title="Paper 2: OmniLeg vs MuJoCo (closure, foot kinematics, energy, torques, forward simulation)",
    engine="MuJoCo",
    requires=("mujoco",),
    run=run,
)
