"""Automatic verification of any described mechanism against MuJoCo built from the same description.

For a :class:`~robomech.multibody.Mechanism` (from an MJCF file or the Builder) the engine model is
``mb.to_mjcf(mech)`` — the same bodies, joints, inertias and closures — and every check compares the
multibody layer with the engine's *own* computations along a smooth trajectory of the actuated joints
(each moves by ``q_act0 + a_i sin(w_i t + phi_i)``):

* closure: the engine's equality violation ``efc_pos`` at the assembled configurations;
* velocities: ``efc_J qd = 0`` for the rates ``qd = G qd_act``, and every site's ``[w; v]``
  (``mj_objectVelocity``) against ``site_jacobian @ qd_act``;
* accelerations: every site's acceleration (``mj_rnePostConstraint`` + ``mj_objectAcceleration`` with
  the engine's ``qacc`` set to the multibody ``qdd``) against ``J qdd_act + H qd_act qd_act``;
* inverse dynamics: the engine's tree dynamics ``M qdd + c + g`` (``mj_rne``) projected through the
  engine's constraint Jacobian ``efc_J`` (actuator forces ``tau`` with ``N^T (E tau - f) = 0``,
  ``N = null(efc_J)``, least squares, minimum norm) against :func:`~robomech.multibody.inverse_dynamics`;
* power balance: ``tau . qd_act`` against ``dE/dt`` of the engine's own energy (``mj_energyPos`` +
  ``mj_energyVel``), differentiated along the trajectory by a five-point stencil;
* forward simulation: :func:`~robomech.multibody.simulate` from the trajectory's first state, passive
  (gravity only), against MuJoCo's RK4 integration with stiff equality constraints; and the energy
  drift of the multibody simulation.  A fall that reaches a constraint singularity (where the
  motion is not determined) stops there and both are judged up to CROSSING_MARGIN before it, the
  crossing named in their note (:func:`_fall`).

An open chain's closure and admissible-velocity rows are 0 by construction: they are reported
``n/a`` (``Check.verdict``), neither passed nor failed.

A floating base (no hinge/slide joints determine its state) gets, at random states, its generalized
forces (``mj_rne``), mass matrix (``mj_fullM``) and, for a tree, forward dynamics under actuator forces
(the engine's ``qacc``), then a free flight against MuJoCo's RK4 with its momentum and energy.

MuJoCo is imported inside the functions (the engine is the optional ``verify`` extra).  Joint damping,
armature, springs, limits and contacts are not part of a multibody description and are absent from
the exported engine model too, so both sides model the same rigid mechanism.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from robomech._progress import stages

from . import _mujoco
from ._core import Check, Tolerance, VerificationReport

__all__ = [
    "DrivenMotion",
    "check_mechanism",
    "describe",
    "driven_motion",
    "engine_inverse_dynamics",
    "engine_model",
    "floating_states",
    "run_generic",
    "split_targets",
    "trajectory",
    "verify_file",
]

# Geometry evaluated by two codes from the same numbers: agreement to rounding of O(L) positions through
# a few dozen transforms, relative to the characteristic length (closure: FK converges to 1e-10 L, and
# in practice to ~1e-15 L).
TOL_CLOSURE = Tolerance(1e-9, "closure solved to 1e-10 L (CONVERGED_RTOL); engine rounding", relative=True)
TOL_VELOCITY = Tolerance(1e-9, "exact first-order influence coefficients; rounding only", relative=True)
TOL_ACCELERATION = Tolerance(1e-8, "exact second-order influence coefficients; rounding only", relative=True)
# Both inverse dynamics are exact rigid-body models of the same bodies (acceptance: 1e-8 relative).
TOL_TORQUE = Tolerance(1e-8, "exact tree dynamics + the engine's own constraint projection", relative=True)
# Five-point stencil with step H_POWER: truncation h^4 w^5 E / 30 ~ 1e-11 (w <= 10 rad/s on the test
# trajectory), rounding of E (~1e-15 through the assembly) / h ~ 1e-11.
TOL_POWER = Tolerance(1e-8, "dE/dt by a 5-point stencil (h = 0.2 ms): ~1e-11 relative error", relative=True)
H_POWER = 2e-4
# Forward simulation: the engine's equality constraints are soft; with a stiff setting (time constant
# 0.5 ms, impedance 0.9999) and RK4 steps of 0.1 ms the engine tracks the exact constrained motion to
# ~3e-5 over T_SIM (measured on the gallery); the multibody integration (DOP853, rtol 1e-10) to ~1e-9.
SIM_TIMESTEP = 1e-4
SIM_SOLREF = "0.0005 1"
SIM_SOLIMP = "0.9999 0.9999 0.001 0.5 2"
T_SIM = 0.3
# Longest passive fall a user may ask for: the engine steps at 0.1 ms, 10 s is 1e5 steps (~10 s CPU).
MAX_SIM_DURATION = 10.0
# Samples compared along the simulation.
SIM_SAMPLES = 31
# A constraint Jacobian whose rank-th singular value (m, _closure_sigma) is below this fraction of L is
# at a constraint singularity.
SINGULAR_SIGMA_RTOL = 1e-6
# A passive motion that reaches a constraint singularity (K loses rank: a change point, where branches
# meet) is not determined there (both codes' motions diverge after it; a type II singularity alone,
# where only the passive block of K loses rank, leaves a passive fall determined): the fall is walked
# sample by sample with K's sigma at each state, and while sigma falls each step covers at most
# APPROACH_FRACTION of the time it takes, at its current rate, to reach 0 (the steps shrink
# geometrically: ~25 reach SINGULAR_SIGMA_RTOL L from a sample 10 ms away, each a short integration,
# so the motion stops at the crossing instead of being integrated slowly through it).
# MAX_APPROACH_STEPS bounds the extra steps of one fall.
APPROACH_FRACTION = 0.5
MAX_APPROACH_STEPS = 200
# The comparison with the engine ends CROSSING_MARGIN before a crossing: four time constants of the
# engine's soft equality constraints (SIM_SOLREF, 0.5 ms), whose lag grows as sigma falls.  On the
# Agile-Eye-type wrist (crossing at 0.2852 s) the engine agrees to 3.8e-7 relative 2 ms before it,
# 5e-6 at 0.2 ms.
CROSSING_MARGIN = 2e-3
# A comparison cut to less than this fraction of the asked duration is inconclusive (the fall has
# barely started: it moves ~ (fraction)^2 of the asked fall's distance).
MIN_COMPARED_FRACTION = 0.1
TOL_SIM = Tolerance(1e-3, "soft engine constraints (0.5 ms, 0.9999) and 0.1 ms RK4 steps", relative=True)
TOL_DRIFT = Tolerance(
    1e-7,
    "DOP853 at rtol 1e-10 with projection onto the manifold; relative to the energy exchanged",
    relative=True,
)
# Floating bases: the tree quantities of two exact rigid-body codes of the same bodies (RNEA, CRBA,
# tree forward dynamics) agree to rounding (acceptance: 1e-9 relative), at N_FLOAT random states
# moved FLOAT_AMP (rad, or L) from the reference.
TOL_TREE = Tolerance(1e-9, "exact tree dynamics both sides (RNEA, CRBA); rounding only", relative=True)
N_FLOAT = 12
FLOAT_AMP = 0.5
# A free flight of a tree has no soft constraint: the engine's RK4 (0.1 ms) error is ~h^4 and the
# multibody DOP853 (rtol 1e-10) ~1e-10 relative; measured 3e-13 relative on the test quadruped (0.3 s).
TOL_FLIGHT = Tolerance(1e-7, "engine RK4 at 0.1 ms vs DOP853 at rtol 1e-10 (no constraints)", relative=True)
# Momentum along the multibody flight: the integration error of DOP853 at rtol 1e-10 (~1e-10 relative).
TOL_MOMENTUM = Tolerance(
    1e-7, "DOP853 at rtol 1e-10 with projection; relative to the momentum", relative=True
)
# Every test configuration must assemble: the error is the fraction that failed (any failure >= 1/N_TRAJ).
TOL_ASSEMBLY = Tolerance(1e-12, "every sample must assemble (FK converged); error = fraction failed")
# Trajectory: N_TRAJ samples over T_TRAJ seconds, amplitudes AMP rad (AMP L for slides).
N_TRAJ = 12
T_TRAJ = 1.0
AMP = 0.15


def engine_model(mech, *, simulation: bool = False):
    """MuJoCo model of ``mech`` from ``mb.to_mjcf``; ``simulation=True`` sets the stiff equality
    constraints and the RK4 step used by the forward-simulation check."""
    if simulation:
        return _mujoco.engine_model(
            mech, timestep=SIM_TIMESTEP, integrator="RK4", solref=SIM_SOLREF, solimp=SIM_SOLIMP
        )
    return _mujoco.engine_model(mech)


def trajectory(mech, n: int = N_TRAJ, t_end: float = T_TRAJ, seed: int = 0):
    """``t, q_act, qd_act, qdd_act`` of the smooth test motion around the reference configuration."""
    rng = np.random.default_rng(seed)
    tree = mech.tree
    na = len(mech.actuated)
    scale = np.where(tree.dof_translational[tree.act_dof], tree.length, 1.0)
    a = AMP * scale * rng.uniform(0.5, 1.0, na)
    w = 2 * np.pi * rng.uniform(0.5, 1.5, na)
    ph = rng.uniform(0, 2 * np.pi, na)
    t = np.linspace(0.0, t_end, n)

    def at(tt):
        tt = np.asarray(tt, float)[..., None]
        s = np.sin(w * tt + ph) - np.sin(ph)
        return tree.q0[tree.act_qadr] + a * s, a * w * np.cos(w * tt + ph), -a * w * w * np.sin(w * tt + ph)

    return t, at


def engine_inverse_dynamics(m, d, mech, q, qd, qdd) -> np.ndarray:
    """Actuator forces from the engine: ``mj_rne`` tree dynamics projected through its ``efc_J``
    (:meth:`Engine.inverse_dynamics <robomech.verify._mujoco.Engine.inverse_dynamics>` on ``m, d``)."""
    return _mujoco.Engine(m, d).inverse_dynamics(q, qd, qdd, mech.tree.act_dof)


def _sample_times(duration: float) -> np.ndarray:
    """SIM_SAMPLES output times over ``duration``, on the engine's step grid (SIM_TIMESTEP): the engine
    is read at exactly the times the multibody simulation reports."""
    steps = max(1, round(duration / SIM_TIMESTEP))
    return np.unique(np.round(np.linspace(0.0, steps, SIM_SAMPLES))) * SIM_TIMESTEP


def _rel(err: float, scale: float) -> float:
    return float(err / scale) if scale > 0 else float(err)


def _rel_diff(mine: np.ndarray, engine: np.ndarray) -> float:
    """Largest difference relative to the engine's largest value."""
    return _rel(float(np.max(np.abs(mine - engine))), float(np.max(np.abs(engine))))


# The stages of check_mechanism, reported as progress (robomech._progress).
_STAGES = ("assembly along the test trajectory", "inverse dynamics", "engine comparison", "power balance",
           "forward simulation")  # fmt: skip


def check_mechanism(
    mech,
    name: str | None = None,
    *,
    simulate: bool = True,
    duration: float = T_SIM,
    q0: object = None,
    qd_act0: object = None,
    qd0: object = None,
) -> list[Check]:
    """Every check of this module for ``mech`` (the rows of the ``robomech verify`` table).

    ``duration`` (s, ``0 < duration <= MAX_SIM_DURATION``) is the length of the passive forward
    simulation; ``q0`` (nq,) its start configuration (assembled) and its start rates either
    ``qd_act0`` (n_act,: the actuated rates, where the actuators determine the state) or ``qd0`` (nv,:
    every coordinate's rate, MuJoCo ``qvel``, any mechanism: passive, underactuated, floating);
    zero rates when only ``q0`` is given; default: the test trajectory's first state (for a floating
    base a tumbling start, see :func:`_floating_checks`).
    """
    from robomech._validation import as_array, check_bool, check_real

    simulate = check_bool(simulate, "simulate")
    duration = check_real(duration, "duration", low=0.0, high=MAX_SIM_DURATION, low_open=True)
    start = None
    if q0 is not None or qd_act0 is not None or qd0 is not None:
        from robomech import multibody as mb

        if q0 is None:
            raise ValueError("Expected q0 with the start rates (the start configuration), got None.")
        if qd_act0 is not None and qd0 is not None:
            raise ValueError("Expected one of qd_act0 (actuated rates) and qd0 (every rate), got both.")
        q0 = as_array(q0, "q0", (mech.nq,))
        if q0.ndim != 1:
            raise ValueError(f"Expected q0 to have shape ({mech.nq},), got {q0.shape}.")
        na = len(mech.actuated)
        if qd_act0 is not None:
            if _virtually_actuated(mech)[1] != ():
                raise ValueError(
                    f"Expected qd0 (every coordinate's rate, {mech.nv} numbers; CLI --qvel0) for a "
                    f"mechanism whose actuators do not determine its state, got qd_act0 (actuated rates)."
                )
            qd = as_array(qd_act0, "qd_act0", (na,))
            if qd.ndim != 1:
                raise ValueError(f"Expected qd_act0 to have shape ({na},), got {qd.shape}.")
        full = np.zeros(mech.nv) if qd0 is None else as_array(qd0, "qd0", (mech.nv,))
        if full.ndim != 1:
            raise ValueError(f"Expected qd0 to have shape ({mech.nv},), got {full.shape}.")
        r = mb.constraint_residual(mech, q0)
        miss = float(np.max(np.abs(r))) if r.size else 0.0
        if not miss <= mb.CONVERGED_RTOL * mech.tree.length:
            raise ValueError(
                f"Expected q0 to be an assembled configuration (e.g. forward_kinematics(mech, q_act).q), "
                f"got closure residual {miss:.3g} m."
            )
        start = {"q0": q0, **({"qd_act0": qd} if qd_act0 is not None else {"qd0": full})}
    with stages(f"verify {name or getattr(mech, 'name', 'mechanism')}", _STAGES[: 4 + simulate]) as st:
        return _checks(mech, name, simulate, st, duration, start)


@dataclasses.dataclass(frozen=True)
class DrivenMotion:
    """The test motion of a mechanism whose actuators (real or virtual) determine its state, at the
    samples that assembled: times ``t``, configurations ``q``, every actuator's ``qa, qda, qdda``, the
    multibody ``inv = inverse_dynamics(mech, q, qda, qdda)``; ``drv`` the mechanism driven (``mech`` or,
    for redundant actuation, a determining subset, :func:`_driver`) and ``at(t)`` its inputs."""

    mech: Any
    drv: Any
    at: Callable
    t: np.ndarray
    q: np.ndarray
    qa: np.ndarray
    qda: np.ndarray
    qdda: np.ndarray
    inv: Any  # multibody.InverseDynamicsResult


def driven_motion(mech, name: str, note: str = "") -> tuple[Check, DrivenMotion | None]:
    """The assembly row of ``mech``'s test trajectory (``note`` appended to its detail) and the motion
    along it (None where no sample assembled); the engine checks (MuJoCo, Pinocchio) compare along it."""
    from robomech import multibody as mb

    tree = mech.tree
    drv = _driver(mech)  # redundant actuation: a consistent motion is driven through `dof` actuators
    t, at = trajectory(drv)
    qa, qda, qdda = at(t)
    fk = _mujoco.assemble_along(drv, qa)
    conv = fk.converged
    row = Check(
        name,
        "assembly along the test trajectory",
        float(np.mean(~conv)),  # the fraction that failed (finite: --json stays strict JSON)
        TOL_ASSEMBLY,
        f"{int(conv.sum())}/{len(conv)} converged{note}",
    )
    if not conv.any():
        return row, None
    q, qa, qda, qdda = fk.q[conv], qa[conv], qda[conv], qdda[conv]
    if drv is not mech:  # every actuator's rates along the driven (consistent) motion
        rd = mb.inverse_dynamics(drv, q, qda, qdda)
        qa, qda, qdda = q[:, tree.act_qadr], rd.qd[:, tree.act_dof], rd.qdd[:, tree.act_dof]
    inv = mb.inverse_dynamics(mech, q, qda, qdda)
    return row, DrivenMotion(mech, drv, at, t[conv], q, qa, qda, qdda, inv)


def _checks(mech, name: str | None, simulate: bool, st, duration: float = T_SIM, start=None) -> list[Check]:
    import mujoco

    from robomech import multibody as mb

    name = name or mech.name
    inferred = [b.name for b in mech.bodies if b.inertial is None]
    if inferred:
        # to_mjcf lets MuJoCo derive these bodies' inertia from their visual geoms; verify the mechanism
        # as exported, with those inertias on both sides (read back from the engine's compiled model)
        mech = mb.from_mjcf(mb.to_mjcf(mech))
    mech, virtual = _virtually_actuated(mech)
    if virtual is None:  # a floating base: no joints drive a test motion; its tree dynamics are checked
        return _floating_checks(mech, name, simulate, st, duration, start)
    tree = mech.tree
    L = tree.length
    st.next()
    note = (f"; inertia of {len(inferred)} bodies from the exported geoms" if inferred else "") + (
        f"; driven through virtual actuators on {', '.join(virtual)}" if virtual else ""
    )
    row, mo = driven_motion(mech, name, note)
    checks = [row]
    if mo is None:
        return checks
    q, qda, qdda, inv = mo.q, mo.qda, mo.qdda, mo.inv
    st.next()
    eng = _mujoco.Engine(engine_model(mech))
    m, d = eng.model, eng.data
    closure = vel = acc = 0.0
    vscale = ascale = 0.0
    tau_e = np.zeros_like(inv.tau)
    g = np.asarray(mech.gravity)
    sites = [s.name for s in mech.sites]
    J = {s: mb.site_jacobian(mech, q, s) for s in sites}
    H = {s: mb.site_hessian(mech, q, s) for s in sites}
    wv = np.array([L, L, L, 1, 1, 1])
    adm = 0.0
    for i in range(len(q)):
        eng.set_state(q[i], inv.qd[i], inv.qdd[i])
        Jc, pos = eng.equality()
        if len(pos):
            closure = max(closure, float(np.max(np.abs(pos))))
            adm = max(adm, float(np.max(np.abs(Jc @ inv.qd[i]))))
        mujoco.mj_rnePostConstraint(m, d)
        for s in sites:
            sid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, s)
            v6 = np.zeros(6)
            mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_SITE, sid, v6, 0)
            a6 = np.zeros(6)
            mujoco.mj_objectAcceleration(m, d, mujoco.mjtObj.mjOBJ_SITE, sid, a6, 0)
            a6[3:] += g  # the engine's accelerations include -g (an accelerometer's reading)
            mine_v = J[s][i] @ qda[i]
            mine_a = J[s][i] @ qdda[i] + np.einsum("ijk,j,k->i", H[s][i], qda[i], qda[i])
            vel = max(vel, float(np.max(np.abs((mine_v - v6) * wv))))
            acc = max(acc, float(np.max(np.abs((mine_a - a6) * wv))))
            vscale = max(vscale, float(np.max(np.abs(mine_v * wv))))
            ascale = max(ascale, float(np.max(np.abs(mine_a * wv))))
        tau_e[i] = eng.inverse_dynamics(q[i], inv.qd[i], inv.qdd[i], tree.act_dof)
    qdscale = L * max(float(np.max(np.abs(inv.qd))), 1e-300)
    na, why_na = _open_chain(m.neq)
    checks += [
        Check(name, "closure (engine efc_pos)", closure / L, TOL_CLOSURE, "max |efc_pos| / L", na, why_na),
        Check(name, "admissible velocity (engine efc_J qd)", adm / qdscale, TOL_VELOCITY, "/ (L max|qd|)",
              na, why_na),
    ]  # fmt: skip
    if sites:
        checks += [
            Check(name, "site velocities", _rel(vel, vscale), TOL_VELOCITY, "J qd_act vs mj_objectVelocity"),
            Check(
                name, "site accelerations", _rel(acc, ascale), TOL_ACCELERATION, "J qdd + H qd qd vs engine"
            ),
        ]
    tscale = float(np.max(np.abs(tau_e)))
    checks.append(
        Check(
            name,
            "inverse dynamics (mj_rne through efc_J)",
            _rel(float(np.nanmax(np.abs(inv.tau - tau_e))), tscale) if inv.valid.all() else 1.0,
            TOL_TORQUE,
            f"max |tau| {tscale:.3g}; {int(inv.valid.sum())}/{len(inv.valid)} valid",
        )
    )
    st.next()
    checks.append(_power_check(mo.drv, name, eng, mo.at, mo.t, q, inv.tau, inv.qd[:, tree.act_dof]))
    if simulate:
        st.next()
        start = {"q0": q[0], "qd_act0": qda[0]} if start is None else start
        checks += _simulation_checks(mech, name, duration=duration, **start)
    return checks


def _open_chain(n_equality: int) -> tuple[str, str]:
    """``(verdict, note)`` of the closure and admissible-velocity rows: ``("n/a", why)`` for a model
    without equality constraints, where both are 0 by construction; ``("", "")`` otherwise."""
    if n_equality:
        return "", ""
    return "n/a", "no closure or coupling: 0 by construction (the model has no constraint rows)"


def floating_states(mech, n: int, rng) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``n`` random states ``q (n, nq), qd, qdd (n, nv)`` around the reference (engine-free: the MuJoCo
    and Pinocchio checks share them): coordinates moved by FLOAT_AMP (rad; FLOAT_AMP L along
    translations), each quaternion turned by a random rotation of that order (kept unit), rates and
    accelerations of order 1 rad/s (L/s) and 10 rad/s^2 (10 L/s^2)."""
    from robomech.multibody._tree import _TYPES

    tree = mech.tree
    L = tree.length
    dof_scale = np.where(tree.dof_translational, L, 1.0)
    q_scale = np.zeros(mech.nq)  # quaternions are turned below
    moved = {
        _TYPES["hinge"]: (1, FLOAT_AMP),
        _TYPES["slide"]: (1, FLOAT_AMP * L),
        _TYPES["free"]: (3, FLOAT_AMP * L),
    }
    for typ, a in zip(tree.jnt_type, tree.jnt_qadr, strict=True):
        width, scale = moved.get(typ, (0, 0.0))
        q_scale[a : a + width] = scale
    q = np.asarray(tree.q0, float) + q_scale * rng.standard_normal((n, mech.nq))
    for a in np.atleast_1d(tree.quat_adr).astype(int):  # q0's orientation turned by exp(FLOAT_AMP w / 2)
        w = FLOAT_AMP * rng.standard_normal((n, 3))
        angle = np.linalg.norm(w, axis=-1, keepdims=True)
        dq = np.concatenate([np.cos(angle / 2), np.sin(angle / 2) * w / np.maximum(angle, 1e-300)], -1)
        q[:, a : a + 4] = _quat_mul(dq, np.asarray(tree.q0[a : a + 4], float))
    qd = dof_scale * rng.standard_normal((n, mech.nv))
    return q, qd, 10 * dof_scale * rng.standard_normal((n, mech.nv))


def _quat_mul(p: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Hamilton product of ``(w, x, y, z)`` quaternions (broadcast)."""
    pw, pv = p[..., :1], p[..., 1:]
    rw, rv = r[..., :1], r[..., 1:]
    return np.concatenate(
        [pw * rw - np.sum(pv * rv, -1, keepdims=True), pw * rv + rw * pv + np.cross(pv, rv)], -1
    )


def _free_system(m) -> bool:
    """Every body hangs from a free joint on the world and no closure ties a body to the world (closures
    and couplings inside the system are internal forces): the system's linear momentum changes by its
    weight only and its angular momentum about its centre of mass is conserved."""
    import mujoco

    top = [b for b in range(1, m.nbody) if m.body_parentid[b] == 0]
    free = int(mujoco.mjtJoint.mjJNT_FREE)
    if not all(m.body_jntnum[b] > 0 and m.jnt_type[m.body_jntadr[b]] == free for b in top):
        return False
    site = int(mujoco.mjtObj.mjOBJ_SITE)
    for e in range(m.neq):
        if m.eq_type[e] in (mujoco.mjtEq.mjEQ_CONNECT, mujoco.mjtEq.mjEQ_WELD):
            ids = (m.eq_obj1id[e], m.eq_obj2id[e])
            bodies = [m.site_bodyid[i] if m.eq_objtype[e] == site else i for i in ids]
            if 0 in bodies:
                return False
    return True


def _floating_checks(mech, name, simulate: bool, st, duration: float, start) -> list[Check]:
    """The checks of a mechanism whose state no set of hinge/slide joints determines (a floating base):
    at N_FLOAT random states, the tree's generalized forces (:func:`multibody.generalized_forces` vs
    ``mj_rne``), mass matrix (:func:`multibody.mass_matrix` vs ``mj_fullM``) and, for a tree, forward
    dynamics under random actuator forces (:func:`multibody.forward_dynamics` vs the engine's
    ``qacc``); then a free flight (:func:`multibody.simulate`, no actuator force) from a tumbling start
    (or ``start``) against the engine's RK4 integration (every body's position), its momentum (the
    engine's ``mj_subtreeVel`` of the multibody trajectory: linear momentum changes by the weight only,
    angular momentum about the centre of mass is constant) and its energy drift."""
    from robomech import multibody as mb

    rng = np.random.default_rng(0)
    eng = _mujoco.Engine(engine_model(mech))
    L = mech.tree.length
    st.next()
    q, qd, qdd = floating_states(mech, N_FLOAT, rng)
    st.next()
    f = mb.generalized_forces(mech, q, qd, qdd)
    M = mb.mass_matrix(mech, q)
    f_e, M_e = np.zeros_like(f), np.zeros_like(M)
    for i in range(N_FLOAT):
        eng.set_state(q[i], qd[i], qdd[i])
        f_e[i], M_e[i] = eng.tree_forces(), eng.mass_matrix()
    st.next()
    states = f"{N_FLOAT} random states of the floating tree"
    checks = [
        Check(name, "generalized forces (vs mj_rne)", _rel_diff(f, f_e), TOL_TREE, states),
        Check(name, "mass matrix (vs mj_fullM)", _rel_diff(M, M_e), TOL_TREE, states),
    ]
    if not (mech.closures or mech.couplings):  # the engine's closures are soft: compared in the flight only
        tau = float(np.max(np.abs(f_e))) * rng.standard_normal((N_FLOAT, len(mech.actuated)))
        fd = mb.forward_dynamics(mech, q, tau=tau, qd=qd)
        acc = np.zeros_like(fd.qdd)
        for i in range(N_FLOAT):
            eng.data.qfrc_applied[:] = 0.0
            eng.data.qfrc_applied[mech.tree.act_dof] = tau[i]
            acc[i] = eng.set_state(q[i], qd[i]).qacc
        eng.data.qfrc_applied[:] = 0.0
        err = _rel_diff(fd.qdd, acc)
        checks.append(
            Check(name, "forward dynamics under actuator forces (vs engine qacc)",
                  err if bool(np.all(fd.valid)) else 1.0, TOL_TREE,
                  f"{int(np.sum(fd.valid))}/{N_FLOAT} valid; random forces of the size of the tree's")
        )  # fmt: skip
    st.next()
    if simulate:
        st.next()
        if start is None:  # a tumbling start: the reference pose with random rates
            tree = mech.tree
            start = {"q0": np.asarray(tree.q0, float), "qd0": np.where(tree.dof_translational, L, 1.0)
                     * rng.standard_normal(mech.nv)}  # fmt: skip
        checks += _flight_checks(mech, name, start["q0"], start.get("qd0"), duration, eng)
    return checks


def _flight_checks(mech, name, q0, qd0, duration: float, eng) -> list[Check]:
    """Free flight from ``(q0, qd0)``: body positions against the engine's RK4 integration, momentum
    (where the system is free) and energy drift of the multibody simulation."""
    import mujoco

    from robomech import multibody as mb

    t = _sample_times(duration)
    sim = mb.simulate(mech, q0, t=t, qd0=np.zeros(mech.nv) if qd0 is None else qd0)
    if not bool(sim.success):
        return [Check(name, "free flight vs engine", 1.0, TOL_SIM, "integration failed (error: 1)")]
    engine = _mujoco.Engine(engine_model(mech, simulation=True))
    engine.set_state(sim.q[0], sim.qd[0])
    xe = np.array(engine.simulate(t, lambda d: d.xpos[1:].copy()))
    m, d = eng.model, eng.data
    xm = np.empty_like(xe)
    p, h = np.empty((len(t), 3)), np.empty((len(t), 3))
    for k in range(len(t)):
        eng.set_state(sim.q[k], sim.qd[k])
        mujoco.mj_subtreeVel(m, d)
        xm[k] = d.xpos[1:]
        p[k] = m.body_subtreemass[0] * d.subtree_linvel[0]
        h[k] = d.subtree_angmom[0]
    moved = float(np.max(np.linalg.norm(xm - xm[0], axis=-1))) / mech.tree.length
    err = float(np.max(np.linalg.norm(xm - xe, axis=-1))) / mech.tree.length
    tol = TOL_SIM if mech.closures or mech.couplings else TOL_FLIGHT
    checks = [
        Check(name, f"free flight vs engine ({duration:g} s, passive)", _rel(err, max(moved, 1e-3)), tol,
              f"max body position difference {err:.2e} L for a motion of {moved:.3g} L"),
    ]  # fmt: skip
    if _free_system(m):
        weight = m.body_subtreemass[0] * np.asarray(mech.gravity) * t[:, None]
        p_err = float(np.max(np.abs(p - p[0] - weight)))
        p_scale = max(float(np.max(np.abs(p))), float(np.max(np.abs(weight))), 1e-300)
        h_err = float(np.max(np.abs(h - h[0])))
        h_scale = max(float(np.max(np.abs(h))), 1e-300)
        checks.append(
            Check(name, "momentum of the free flight", max(p_err / p_scale, h_err / h_scale), TOL_MOMENTUM,
                  f"linear {p_err / p_scale:.1e} (less the weight's impulse), angular about the CoM "
                  f"{h_err / h_scale:.1e}; engine mj_subtreeVel of the multibody trajectory")
        )  # fmt: skip
    checks.append(
        Check(name, "energy drift of the simulation", float(sim.energy_drift_rel), TOL_DRIFT,
              f"{float(sim.energy_drift):.2e} J")
    )  # fmt: skip
    return checks


def _virtually_actuated(mech):
    """``(mech, ())`` where the actuated rates determine the state; otherwise the same mechanism with
    actuators added on hinge/slide joints, in file order, each one that the actuators so far leave free
    (it lowers the passive rates' nullity at the reference), until the actuators determine the driven
    mechanism's motion (as many as its own DOF): ``(mech', added names)``.  The added actuators only
    give the checks a motion to follow and forces to compare (the passive simulation applies none), so
    a passive or underactuated description is verified as it is.
    ``(mech, None)`` where no such set exists (a floating base)."""
    from robomech import multibody as mb

    def nullity(m) -> int:
        inf = mb.influence(m, m.q0, second_order=False)
        return int(m.tree.nv - len(m.actuated) - int(inf.passive_rank))

    dof = mb.mobility(mech).dof
    if len(mech.actuated) >= dof:  # idle motions (a Delta's forearm spins) need no actuator
        return mech, ()
    free = nullity(mech)
    added: list[str] = []
    for body in mech.bodies:
        for j in body.joints:
            if j.type not in ("hinge", "slide") or j.name in mech.actuated:
                continue
            trial = dataclasses.replace(mech, actuated=(*mech.actuated, *added, j.name))
            n = nullity(trial)
            if n < free:
                added.append(j.name)
                free = n
                # determined as the dynamics judge it: the driven mechanism's own DOF (a chain straight
                # at its reference counts a locked motion as idle until enough joints are actuated)
                if len(trial.actuated) >= mb.mobility(trial).dof:
                    return trial, tuple(added)
    return mech, None


def _driver(mech):
    """``mech``, or for redundant actuation the same mechanism driven by the first subset of ``dof``
    actuators that determines its motion (to generate consistent test motions)."""
    from itertools import combinations

    from robomech import multibody as mb

    dof = mb.mobility(mech).dof
    if len(mech.actuated) <= dof:
        return mech
    for sub in combinations(mech.actuated, dof):
        drv = dataclasses.replace(mech, actuated=sub)
        if mb.mobility(drv).dof == dof and mb.influence(drv, drv.q0, second_order=False).consistency < 1e-9:
            return drv
    return mech


def _power_check(mech, name, eng, at, t, q, tau, qd_act) -> Check:
    """``tau . qd_act`` (every actuator's force and rate) against dE/dt of the engine's energy along the
    motion driven through ``mech``'s actuators (``at``)."""
    from robomech import multibody as mb

    h = H_POWER
    err = 0.0
    scale = 0.0
    for i, ti in enumerate(t):
        qa, qda, qdda = at(ti + h * np.arange(-2, 3))
        fk = mb.forward_kinematics(mech, qa, guess=q[i])
        r = mb.inverse_dynamics(mech, fk.q, qda, qdda)
        E = np.array([sum(eng.energies(fk.q[k], r.qd[k])) for k in range(5)])
        dE = (E[0] - 8 * E[1] + 8 * E[3] - E[4]) / (12 * h)
        P = float(tau[i] @ qd_act[i])
        err = max(err, abs(P - dE))
        scale = max(scale, abs(P), abs(dE))
    return Check(name, "power balance tau.qd = dE/dt (engine energy)", _rel(err, scale), TOL_POWER, "")


def _closure_sigma(mech, q: np.ndarray, rank: int) -> np.ndarray:
    """The ``rank``-th singular value (m) of the constraint Jacobian K at each ``q (n, nq)`` (slide
    columns times L, so that every entry is a length), ``rank`` its rank at a regular configuration:
    0 at a constraint singularity, where K loses rank and a passive motion (no actuator holding any
    joint) is not determined.  (A type II singularity alone, the passive block of K losing rank with K
    keeping its own, leaves a passive fall determined: MuJoCo and robomech follow it through.)"""
    from robomech import multibody as mb

    tree = mech.tree
    K = mb.constraint_jacobian(mech, q) * np.where(tree.dof_translational, tree.length, 1.0)
    return np.linalg.svd(K, compute_uv=False)[..., rank - 1]


@dataclasses.dataclass(frozen=True)
class _Fall:
    """A passive fall walked by :func:`_fall`: the states ``q, qd`` and energies ``kinetic, potential``
    at the output times ``t`` reached; every state visited (output times and the steps approaching a
    singularity) as ``seen_t`` with the constraint Jacobian's ``seen_sigma`` (m, :func:`_closure_sigma`;
    empty without constraints); ``crossing`` the time a constraint singularity was reached (None:
    none) and ``success``
    False where the integration failed after the last time in ``t``."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    seen_t: np.ndarray
    seen_sigma: np.ndarray
    crossing: float | None
    success: bool

    def drift(self) -> tuple[float, float]:
        """Energy drift (J) and relative to the energy exchanged, as :class:`multibody.SimulationResult`
        states them for a passive motion (no actuator work)."""
        E = self.kinetic + self.potential
        drift = float(np.max(np.abs(E - E[0])))
        scale = max(float(np.max(self.kinetic)), float(np.max(np.abs(self.potential - self.potential[0]))))
        return drift, drift / max(scale, 1e-300)


def _fall(mech, q0, t: np.ndarray, qd_act0=None, qd0=None) -> _Fall:
    """The passive motion from ``q0`` with the actuated rates ``qd_act0`` or every rate ``qd0`` to the
    output times ``t``, walked one sample interval at a time (:func:`multibody.simulate` from the state
    reached, which it projects onto the manifold at each output time anyway), with the constraint
    Jacobian's sigma (:func:`_closure_sigma`) at every state (the first step is one engine step long,
    for sigma's first rate).  While sigma falls, a step covers at most APPROACH_FRACTION of the time it
    takes to reach 0 at its current rate; the walk stops at a constraint singularity (sigma below
    SINGULAR_SIGMA_RTOL L), where the passive motion is not determined."""
    from robomech import multibody as mb

    full = int(mb.mobility(mech, np.asarray(q0, float)).rank)  # K's rank at the (regular) start
    watch = full > 0
    floor = SINGULAR_SIGMA_RTOL * mech.tree.length
    kw = {"qd0": qd0} if qd_act0 is None else {"qd_act0": qd_act0}
    out: list[tuple[np.ndarray, ...]] = []  # (q, qd, T, U) at each output time reached
    seen_t: list[float] = []
    seen_s: list[float] = []
    q, now, k, extra, crossing, ok = np.asarray(q0, float), float(t[0]), 1, 0, None, True
    if watch and float(_closure_sigma(mech, q[None], full)[0]) < floor:  # starts at the singularity
        nan = np.full(1, np.nan)
        return _Fall(t[:1], q[None], np.zeros((1, mech.nv)), nan, nan, t[:1], np.zeros(1), float(t[0]), True)
    while k < len(t):
        end = float(t[k])
        if watch and len(seen_s) < 2:  # a first step of one engine step gives sigma's first rate
            end = min(end, now + SIM_TIMESTEP)
        elif watch and seen_s[-1] < seen_s[-2] and extra < MAX_APPROACH_STEPS:
            rate = (seen_s[-1] - seen_s[-2]) / (seen_t[-1] - seen_t[-2])
            end = min(end, now + APPROACH_FRACTION * seen_s[-1] / -rate)
        if not end > now:  # closer than the clock resolves: at the singularity
            crossing = now
            break
        sim = mb.simulate(mech, q, t=[now, end], **kw)
        if not out:
            out.append((sim.q[0], sim.qd[0], sim.kinetic[0], sim.potential[0]))
            if watch:
                seen_t.append(now)
                seen_s.append(float(_closure_sigma(mech, sim.q[:1], full)[0]))
        if not bool(sim.success):
            ok = False
            break
        q, now, kw = sim.q[-1], end, {"qd0": sim.qd[-1]}
        if end == float(t[k]):
            out.append((sim.q[-1], sim.qd[-1], sim.kinetic[-1], sim.potential[-1]))
            k += 1
        else:
            extra += 1
        if watch:
            seen_t.append(now)
            seen_s.append(float(_closure_sigma(mech, sim.q[-1:], full)[0]))
            if seen_s[-1] < floor:
                crossing = now
                break
    Q, QD, T, U = (np.array(c) for c in zip(*out, strict=True))
    return _Fall(t[: len(out)], Q, QD, T, U, np.array(seen_t), np.array(seen_s), crossing, ok)


def _cut(mech, fall: _Fall, t_end: float, kw: dict) -> _Fall:
    """``fall`` up to ``t_end`` (on the engine's step grid, before its crossing): its output times before
    ``t_end`` and the state at ``t_end`` itself, simulated from the last of them (before the crossing's
    margin: a short, regular integration)."""
    from robomech import multibody as mb

    n = int(np.searchsorted(fall.t, t_end - 0.5 * SIM_TIMESTEP))  # output times before t_end
    if n == 0:
        sim = mb.simulate(mech, fall.q[0], t=[fall.t[0], t_end], **kw)
        n, extra = 1, (sim.q[-1:], sim.qd[-1:], sim.kinetic[-1:], sim.potential[-1:])
    else:
        sim = mb.simulate(mech, fall.q[n - 1], t=[fall.t[n - 1], t_end], qd0=fall.qd[n - 1])
        extra = (sim.q[-1:], sim.qd[-1:], sim.kinetic[-1:], sim.potential[-1:])
    head = (fall.q[:n], fall.qd[:n], fall.kinetic[:n], fall.potential[:n])
    Q, QD, T, U = (np.concatenate([h, e]) for h, e in zip(head, extra, strict=True))
    t = np.append(fall.t[:n], t_end)
    return dataclasses.replace(fall, t=t, q=Q, qd=QD, kinetic=T, potential=U, success=bool(sim.success))


def _why(mech, t: np.ndarray, q: np.ndarray, off: np.ndarray, seen=None) -> str:
    """Why a simulation disagrees: when it first left the engine, and the constraint singularity it
    crossed or came closest to before (:func:`_closure_sigma`, m) among the states the simulation
    visited: ``seen = (times, sigma)`` (the walk of :func:`_fall`, nothing simulated again), or the
    samples ``t, q`` themselves."""
    from robomech import multibody as mb

    words = []
    end = float(t[-1])
    if off.any():
        end = float(t[int(np.argmax(off))])
        words.append(f"diverged from the engine after t = {end:.3g} s")
    if seen is None:
        rank = int(mb.mobility(mech, q[0]).rank)
        if not rank:
            return "; ".join(words)
        seen = (np.asarray(t), _closure_sigma(mech, q, rank))
    times, sigma = (np.asarray(a, float) for a in seen)
    before = times <= end + 0.5 * SIM_TIMESTEP
    if not before.any():
        return "; ".join(words)
    times, sigma = times[before], sigma[before]
    j = int(np.argmin(sigma))
    kind = (
        "crossed a constraint singularity near"
        if sigma[j] < SINGULAR_SIGMA_RTOL * mech.tree.length
        else ("closest to a constraint singularity at")
    )
    words.append(f"{kind} t = {times[j]:.4g} s (sigma {sigma[j]:.1e} m)")
    return "; ".join(words)


def _simulation_checks(mech, name, q0, qd_act0=None, duration: float = T_SIM, *, qd0=None) -> list[Check]:
    """The passive simulation from ``q0`` with the actuated rates ``qd_act0`` or every rate ``qd0``
    against the engine's, and the energy drift of the multibody simulation; where the motion reaches a
    constraint singularity (:func:`_fall`), both on the interval ending CROSSING_MARGIN before it, the
    crossing named in the checks' note (inconclusive when that interval is shorter than
    MIN_COMPARED_FRACTION of ``duration``)."""
    from robomech import multibody as mb

    t = _sample_times(duration)
    fall = _fall(mech, q0, t, qd_act0, qd0)
    sim_q, tree = "forward simulation vs engine", mech.tree
    note, verdict = "", ""
    if fall.crossing is not None:
        t_end = np.floor((fall.crossing - CROSSING_MARGIN) / SIM_TIMESTEP) * SIM_TIMESTEP
        where = f"[0, {t_end:.4g}] s" if t_end > t[0] else "nothing"
        note = (
            f"the motion reaches a constraint singularity (its closure's Jacobian loses rank) at t = "
            f"{fall.crossing:.4g} s, where it is not determined: compared on {where}, "
            f"{CROSSING_MARGIN * 1e3:g} ms before it"
        )
        if t_end < MIN_COMPARED_FRACTION * duration:
            verdict = "inconclusive"
            note += f" (less than {MIN_COMPARED_FRACTION:.0%} of the {duration:g} s asked: inconclusive)"
        if t_end > t[0]:
            kw = {"qd0": qd0} if qd_act0 is None else {"qd_act0": qd_act0}
            fall = _cut(mech, fall, float(t_end), kw)
        else:
            fall = dataclasses.replace(fall, t=fall.t[:1], q=fall.q[:1], qd=fall.qd[:1],
                                       kinetic=fall.kinetic[:1], potential=fall.potential[:1])  # fmt: skip
    seen = (fall.seen_t, fall.seen_sigma)
    label = f"{sim_q} ({duration:g} s, passive)"
    if not fall.success:
        ok = np.all(np.isfinite(fall.q), axis=-1)
        why = _why(mech, fall.t[ok], fall.q[ok], np.zeros(int(ok.sum()), bool), seen) if ok.any() else ""
        return [
            Check(name, sim_q, 1.0, TOL_SIM, "integration failed (error: 1)" + (f": {why}" if why else ""))
        ]
    if len(fall.t) < 2:  # nothing left to compare
        return [
            Check(name, label, float("nan"), TOL_SIM, "", verdict, note),
            Check(name, "energy drift of the simulation", float("nan"), TOL_DRIFT, "", verdict, note),
        ]
    qvel = mb.influence(mech, q0, second_order=False).G @ qd_act0 if qd0 is None else fall.qd[0]
    engine = _mujoco.Engine(engine_model(mech, simulation=True))
    engine.set_state(q0, qvel)  # the multibody side projects qd0 onto the admissible rates: so does this
    eng = np.array(engine.simulate(fall.t, lambda d: d.qpos[tree.act_qadr].copy()))
    q_act = fall.q[:, tree.act_qadr]
    scale = np.where(tree.dof_translational[tree.act_dof], 1.0 / tree.length, 1.0)
    dev = np.max(np.abs((q_act - eng) * scale), axis=-1)
    err = float(np.max(dev))
    moved = float(np.max(np.abs((q_act - q_act[0]) * scale)))
    rel = _rel(err, max(moved, 1e-3))
    detail = f"max |q_act - engine| {err:.2e} (rad, slides / L) for a motion of {moved:.3g}"
    off = dev > TOL_SIM.value * max(moved, 1e-3)  # where the motion left the engine's
    explained: list[str] = []  # computed once for both checks

    def explain() -> str:
        if not explained:
            explained.append(_why(mech, fall.t, fall.q, off, seen))
        return explained[0]

    if not rel <= TOL_SIM.value and not verdict:
        detail += "; " + explain()
    energy_drift, energy_drift_rel = fall.drift()
    drift = f"{energy_drift:.2e} J"
    if not energy_drift_rel <= TOL_DRIFT.value and not verdict:
        drift += "; " + explain()
    return [
        Check(name, label, rel, TOL_SIM, detail, verdict, note),
        Check(name, "energy drift of the simulation", energy_drift_rel, TOL_DRIFT, drift, verdict, note),
    ]


def verify_file(path: str | Path) -> VerificationReport:
    """``robomech verify path/to/model.xml`` (or ``.urdf``): every check of :func:`check_mechanism` on a
    user's MJCF or URDF."""
    mech = _load_file(Path(path))
    report = VerificationReport()
    report.checks.extend(check_mechanism(mech, Path(path).stem))
    return report


def split_targets(targets, available) -> tuple[list[str], list[str]]:
    """``robomech verify`` arguments: (registered names and unknown words, generic targets).

    Generic targets are MJCF paths and gallery / paper-description names that are not registered
    verifications; they get :func:`check_mechanism`."""
    from robomech import multibody as mb

    described = set(_paper()) | set(mb.gallery.NAMES)

    def is_generic(a: str) -> bool:
        return a not in available and (a in described or a.endswith((".xml", ".urdf")) or Path(a).is_file())

    generic = [a for a in targets if is_generic(a)]
    return [a for a in targets if a not in generic], generic


def run_generic(targets, **options) -> list[Check]:
    """The generic checks of each target (MJCF path, gallery or description name); ValueError if one
    cannot be read.  ``options`` (``duration``, ``q0``, ``qd_act0``) go to :func:`check_mechanism`."""
    checks: list[Check] = []
    for t in targets:
        try:
            mech = describe(t)
        except OSError as exc:
            raise ValueError(f"cannot read {t!r}: {exc}") from exc
        label = Path(t).stem if t.endswith((".xml", ".urdf")) else f"{t} (generic)"
        try:
            checks.extend(check_mechanism(mech, label, **options))
        except ValueError as exc:  # of several targets, say which one
            raise ValueError(f"{t}: {exc}") from exc
    return checks


def _paper() -> dict:
    from robomech.mechanisms import omnileg as ol
    from robomech.mechanisms import spherical_leg as sl
    from robomech.mechanisms import vectored_thrust as vt

    return {
        "spherical-leg": lambda: sl.to_multibody(sl.SphericalLeg.paper()),
        "omnileg": lambda: ol.to_multibody(ol.OmniLeg.paper()),
        "vectored-thrust": lambda: vt.to_multibody(vt.VectoredThruster.paper()),
    }


def describe(target: str):
    """The mechanism named by ``target`` (``robomech export``): a paper mechanism with a description
    (its ``to_multibody`` at the paper's parameters), a gallery name or an MJCF path."""
    from robomech import multibody as mb

    paper = _paper()
    if target in paper:
        return paper[target]()
    if target in mb.gallery.NAMES:
        return mb.gallery.load(target)
    if target.endswith((".xml", ".urdf")) or Path(target).is_file():
        return _load_file(Path(target))
    raise ValueError(
        f"Expected MECHANISM among {sorted(paper)} or the gallery {list(mb.gallery.NAMES)}, "
        f"or an MJCF or URDF file, got {target!r}."
    )


def _load_file(path: Path):
    """An MJCF file through ``from_mjcf``, a ``.urdf`` file through ``from_urdf``."""
    from robomech import multibody as mb

    return mb.from_urdf(path) if path.suffix.lower() == ".urdf" else mb.from_mjcf(path)
