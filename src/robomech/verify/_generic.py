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
  drift of the multibody simulation.

MuJoCo is imported inside the functions (the engine is the optional ``verify`` extra).  Joint damping,
armature, springs, limits and contacts are not part of a multibody description and are absent from
the exported engine model too, so both sides model the same rigid mechanism.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from robomech._progress import stages

from . import _mujoco
from ._core import Check, Tolerance, VerificationReport

__all__ = [
    "check_mechanism",
    "describe",
    "engine_inverse_dynamics",
    "engine_model",
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
# Samples compared along the simulation (and searched for the closest singularity when it fails).
SIM_SAMPLES = 31
# A passive block whose smallest singular value is below this fraction of L is at a type II singularity.
SINGULAR_SIGMA_RTOL = 1e-6
TOL_SIM = Tolerance(1e-3, "soft engine constraints (0.5 ms, 0.9999) and 0.1 ms RK4 steps", relative=True)
TOL_DRIFT = Tolerance(
    1e-7,
    "DOP853 at rtol 1e-10 with projection onto the manifold; relative to the energy exchanged",
    relative=True,
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


def _rel(err: float, scale: float) -> float:
    return float(err / scale) if scale > 0 else float(err)


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
) -> list[Check]:
    """Every check of this module for ``mech`` (the rows of the ``robomech verify`` table).

    ``duration`` (s, ``0 < duration <= MAX_SIM_DURATION``) is the length of the passive forward
    simulation; ``q0`` (nq,) and ``qd_act0`` (n_act,) its start (default: the test trajectory's first
    state; ``q0`` must be assembled, ``qd_act0`` defaults to zero when ``q0`` is given).
    """
    from robomech._validation import as_array, check_bool, check_real

    simulate = check_bool(simulate, "simulate")
    duration = check_real(duration, "duration", low=0.0, high=MAX_SIM_DURATION, low_open=True)
    start = None
    if q0 is not None or qd_act0 is not None:
        from robomech import multibody as mb

        if q0 is None:
            raise ValueError("Expected q0 with qd_act0 (the start configuration), got None.")
        q0 = as_array(q0, "q0", (mech.nq,))
        if q0.ndim != 1:
            raise ValueError(f"Expected q0 to have shape ({mech.nq},), got {q0.shape}.")
        na = len(mech.actuated)
        qd = np.zeros(na) if qd_act0 is None else as_array(qd_act0, "qd_act0", (na,))
        if qd.ndim != 1:
            raise ValueError(f"Expected qd_act0 to have shape ({na},), got {qd.shape}.")
        r = mb.constraint_residual(mech, q0)
        miss = float(np.max(np.abs(r))) if r.size else 0.0
        if not miss <= mb.CONVERGED_RTOL * mech.tree.length:
            raise ValueError(
                f"Expected q0 to be an assembled configuration (e.g. forward_kinematics(mech, q_act).q), "
                f"got closure residual {miss:.3g} m."
            )
        start = (q0, qd)
    with stages(f"verify {name or getattr(mech, 'name', 'mechanism')}", _STAGES[: 4 + simulate]) as st:
        return _checks(mech, name, simulate, st, duration, start)


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
    if virtual is None:
        return [
            Check(
                name,
                "actuated rates determine the state",
                1.0,
                TOL_ASSEMBLY,
                "no set of hinge/slide joints determines the state (a floating base): the engine checks "
                "need a test motion driven through joints; check generalized_forces / mass_matrix directly",
            )
        ]
    tree = mech.tree
    L = tree.length
    checks: list[Check] = []
    st.next()
    drv = _driver(mech)  # redundant actuation: a consistent motion is driven through `dof` actuators
    t, at = trajectory(drv)
    qa, qda, qdda = at(t)
    fk = _mujoco.assemble_along(drv, qa)
    q, conv = fk.q, fk.converged
    checks.append(
        Check(
            name,
            "assembly along the test trajectory",
            float(np.mean(~conv)),  # the fraction that failed (finite: --json stays strict JSON)
            TOL_ASSEMBLY,
            f"{int(conv.sum())}/{len(conv)} converged"
            + (f"; inertia of {len(inferred)} bodies from the exported geoms" if inferred else "")
            + (f"; driven through virtual actuators on {', '.join(virtual)}" if virtual else ""),
        )
    )
    q, qa, qda, qdda = q[conv], qa[conv], qda[conv], qdda[conv]
    if not len(q):
        return checks
    st.next()
    if drv is not mech:  # every actuator's rates along the driven (consistent) motion
        rd = mb.inverse_dynamics(drv, q, qda, qdda)
        qa, qda, qdda = q[:, tree.act_qadr], rd.qd[:, tree.act_dof], rd.qdd[:, tree.act_dof]
    inv = mb.inverse_dynamics(mech, q, qda, qdda)
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
    checks += [
        Check(name, "closure (engine efc_pos)", closure / L, TOL_CLOSURE, "max |efc_pos| / L"),
        Check(name, "admissible velocity (engine efc_J qd)", adm / qdscale, TOL_VELOCITY, "/ (L max|qd|)"),
    ]
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
    checks.append(_power_check(drv, name, eng, at, t[conv], q, inv.tau, inv.qd[:, tree.act_dof]))
    if simulate:
        st.next()
        q_s, qd_s = (q[0], qda[0]) if start is None else start
        checks += _simulation_checks(mech, name, q_s, qd_s, duration)
    return checks


def _virtually_actuated(mech):
    """``(mech, ())`` where the actuated rates determine the state; otherwise the same mechanism with
    actuators added on hinge/slide joints, in file order, each one that the actuators so far leave free
    (it lowers the passive rates' nullity at the reference), until none is left free: ``(mech', added
    names)``.  The added actuators only give the checks a motion to follow and forces to compare (the
    passive simulation applies none), so a passive or underactuated description is verified as it is.
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
            if len(mech.actuated) + len(added) == dof:
                return dataclasses.replace(mech, actuated=(*mech.actuated, *added)), tuple(added)
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


def _why(mech, t: np.ndarray, q: np.ndarray, off: np.ndarray) -> str:
    """Why a simulation disagrees: when it first left the engine, and the closest type II singularity
    (smallest singular value of the passive block of K, in m, from :func:`multibody.influence`)."""
    from robomech import multibody as mb

    words = []
    if off.any():
        words.append(f"diverged from the engine after t = {t[int(np.argmax(off))]:.3g} s")
    inf = mb.influence(mech, q, second_order=False)
    if inf.n_passive:
        smin = np.where(inf.passive_rank < inf.passive_rank.max(initial=0), 0.0, inf.sigma_min)
        k = int(np.nanargmin(smin))
        if smin[k] < SINGULAR_SIGMA_RTOL * mech.tree.length or inf.passive_rank[k] < inf.passive_rank.max():
            words.append(
                f"crossed a type II singularity near t = {t[k]:.3g} s (sigma_min {inf.sigma_min[k]:.1e} m)"
            )
        else:
            words.append(f"closest to a type II singularity at t = {t[k]:.3g} s (sigma_min {smin[k]:.1e} m)")
    return "; ".join(words)


def _simulation_checks(mech, name, q0, qd_act0, duration: float = T_SIM) -> list[Check]:
    from robomech import multibody as mb

    t = np.linspace(0.0, duration, SIM_SAMPLES)
    sim = mb.simulate(mech, q0, qd_act0, t)
    engine = _mujoco.Engine(engine_model(mech, simulation=True))
    G = mb.influence(mech, q0, second_order=False).G
    engine.set_state(q0, G @ qd_act0)
    eng = np.array(engine.simulate(t, lambda d: d.qpos[mech.tree.act_qadr].copy()))
    tree = mech.tree
    if not bool(sim.success):
        ok = np.all(np.isfinite(sim.q), axis=-1)
        why = _why(mech, t[ok], sim.q[ok], np.zeros(int(ok.sum()), bool)) if ok.any() else ""
        return [
            Check(
                name,
                "forward simulation vs engine",
                1.0,
                TOL_SIM,
                "integration failed (error: 1)" + (f": {why}" if why else ""),
            )
        ]
    scale = np.where(tree.dof_translational[tree.act_dof], 1.0 / tree.length, 1.0)
    dev = np.max(np.abs((sim.q_act - eng) * scale), axis=-1)
    err = float(np.max(dev))
    moved = float(np.max(np.abs((sim.q_act - sim.q_act[0]) * scale)))
    rel = _rel(err, max(moved, 1e-3))
    detail = f"max |q_act - engine| {err:.2e} (rad, slides / L) for a motion of {moved:.3g}"
    if not rel <= TOL_SIM.value:
        detail += "; " + _why(mech, t, sim.q, dev > TOL_SIM.value * max(moved, 1e-3))
    return [
        Check(name, f"forward simulation vs engine ({duration:g} s, passive)", rel, TOL_SIM, detail),
        Check(
            name,
            "energy drift of the simulation",
            float(sim.energy_drift_rel),
            TOL_DRIFT,
            f"{float(sim.energy_drift):.2e} J",
        ),
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
        checks.extend(check_mechanism(mech, label, **options))
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
