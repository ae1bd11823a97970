"""Issue 13 workloads: generic closed-chain inverse dynamics (robomech.multibody.inverse_dynamics).

Batches of 10^5 samples run the compiled per-sample kernel (``multibody/_compiled.py``, ``inv_dyn``,
single-threaded); the numpy path is the reference it is tested against.

* Every gallery mechanism (four-bar, Bennett, 3-RRR, Delta, 3-RPS, Stewart), the spherical leg (paper 1,
  actuated by its platform angles) and the OmniLeg (paper 2), 10^5 samples, against a per-sample loop
  of MuJoCo's inverse dynamics on the model exported from the same description (``mj_forward`` +
  ``mj_rne`` + the projection through the engine's ``efc_J``,
  robomech.verify._generic.engine_inverse_dynamics — the work a user would do per sample; its answer is
  checked equal to 1e-8 on every run).  Target (issue 13): >= 5x.
* Spherical leg and OmniLeg, generic description vs the analytic model (Kane, Lagrange), both batched
  over 10^5 samples.  Target: the generic model within 3x (speed-up >= 1/3).

The OmniLeg description carries the analytic model's inertias; should a body lack one, it gets the
inertia MuJoCo derives from the exported visual geometry (``mb.from_mjcf(mb.to_mjcf(mech))``, as
``robomech verify`` does), which costs the same per sample (every body massive).

The 10^5 configurations are 10^3 assembled ones repeated 100 times (assembling 10^5 Delta
configurations is not the workload; each sample costs the same).
"""

from __future__ import annotations

import numpy as np

from robomech import multibody as mb
from robomech.mechanisms import omnileg as ol
from robomech.mechanisms import spherical_leg as sl
from robomech.verify import _generic as g
from robomech.verify._mujoco import assemble_along

from _harness import Workload

N = 100_000
N_DISTINCT = 1000
N_ALT_ENGINE = 300
GALLERY = ("four_bar", "bennett", "planar_3rrr", "delta", "rps_3", "stewart")


def _tile(*xs: np.ndarray) -> tuple[np.ndarray, ...]:
    reps = N // xs[0].shape[0]
    return tuple(np.tile(x, (reps, 1)) for x in xs)


def _gallery_states(mech):
    t, at = g.trajectory(mech, n=N_DISTINCT, t_end=N_DISTINCT * 0.01)
    qa, qd, qdd = at(t)
    fk = assemble_along(mech, qa)  # continuation along the trajectory keeps the branch
    q, conv = fk.q, fk.converged
    assert conv.all()
    return _tile(q, qd, qdd)


def _vs_engine(label: str, mech, q, qd, qdd) -> Workload:
    r = mb.inverse_dynamics(mech, q[:N_ALT_ENGINE], qd[:N_ALT_ENGINE], qdd[:N_ALT_ENGINE])
    assert r.valid.all()

    def run():
        return mb.inverse_dynamics(mech, q, qd, qdd).tau

    import mujoco

    m = g.engine_model(mech)
    d = mujoco.MjData(m)

    def alt():
        tau = np.array(
            [g.engine_inverse_dynamics(m, d, mech, q[i], r.qd[i], r.qdd[i]) for i in range(N_ALT_ENGINE)]
        )
        assert np.max(np.abs(tau - r.tau)) <= 1e-8 * np.max(np.abs(tau))  # same answer
        return tau

    return Workload(
        name=f"multibody: {label} inverse dynamics (generic)",
        group="13",
        run=run,
        n=N,
        bytes_moved=N * 8 * (mech.nq + 3 * len(mech.actuated)),
        alternative=alt,
        n_alt=N_ALT_ENGINE,
        alternative_name="MuJoCo per sample (rne+efc_J)",
        target_speedup=5.0,
        repeats=1,
    )


def _vs_analytic(label: str, mech, q, qd, qdd, analytic, name: str) -> Workload:
    def run():
        return mb.inverse_dynamics(mech, q, qd, qdd).tau

    return Workload(
        name=f"multibody: {label} generic vs analytic",
        group="13",
        run=run,
        n=N,
        bytes_moved=N * 8 * (mech.nq + 3 * len(mech.actuated)),
        alternative=analytic,
        n_alt=N,
        alternative_name=name,
        target_speedup=1 / 3,
        repeats=1,
    )


def _spherical_leg() -> list[Workload]:
    leg = sl.SphericalLeg.paper()
    by_angles = sl.to_multibody(leg, actuate="platform")
    rng = np.random.default_rng(2)
    ab = rng.uniform(-0.5, 0.5, (N_DISTINCT, 2))
    q = mb.forward_kinematics(by_angles, ab).q
    Q, AB = _tile(q, ab)
    QD, QDD = rng.normal(size=(N, 2)), rng.normal(size=(N, 2))

    def analytic():
        return sl.inverse_dynamics(leg, AB, QD, QDD).generalized_forces

    return [
        _vs_engine("spherical_leg", by_angles, Q, QD, QDD),
        _vs_analytic("spherical_leg", by_angles, Q, QD, QDD, analytic, "analytic Kane model (batched)"),
    ]


def _omnileg() -> list[Workload]:
    leg = ol.OmniLeg.paper()
    mech = ol.to_multibody(leg)
    if any(b.inertial is None for b in mech.bodies):  # the inertias of the exported geometry (docstring)
        mech = mb.from_mjcf(mb.to_mjcf(mech))
    t = np.linspace(0.0, 6.0, N_DISTINCT)
    prof = ol.joint_trajectory_eq52(t)  # the gait of paper 2, (alpha, beta, gamma) = q_act order
    fk = assemble_along(mech, prof.q)
    assert fk.converged.all()
    q = fk.q
    Q, QA, QD, QDD = _tile(q, prof.q, prof.qd, prof.qdd)

    def analytic():
        return ol.inverse_dynamics(leg, QA, QD, QDD).tau

    return [
        _vs_engine("omnileg", mech, Q, QD, QDD),
        _vs_analytic("omnileg", mech, Q, QD, QDD, analytic, "analytic Lagrange model (batched)"),
    ]


def workloads() -> list[Workload]:
    out = [
        _vs_engine(name, mb.gallery.load(name), *_gallery_states(mb.gallery.load(name))) for name in GALLERY
    ]
    return [*out, *_spherical_leg(), *_omnileg()]
