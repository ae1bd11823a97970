"""Issue 13 workloads: generic closed-chain inverse dynamics (robomech.multibody.inverse_dynamics).

* Delta and Stewart platform (gallery), 10^5 samples, against a per-sample loop of MuJoCo's inverse
  dynamics on the model exported from the same description (``mj_forward`` + ``mj_rne`` + the
  projection through the engine's ``efc_J``, robomech.verify._generic.engine_inverse_dynamics — the
  work a user would do per sample).  Target (issue 13): >= 5x.
* Spherical leg (paper 1), generic description vs the analytic Kane model, both batched over 10^5
  samples (the issue's "generic OmniLeg within 3x of the analytic model" cannot be measured: the OmniLeg
  description carries no inertias yet).  Target: the generic model within 3x (speed-up >= 1/3).

The 10^5 configurations are 10^3 assembled ones repeated 100 times (assembling 10^5 Delta
configurations takes minutes and is not the workload; each sample costs the same).
"""

from __future__ import annotations

import numpy as np

from robomech import multibody as mb
from robomech.mechanisms import spherical_leg as sl
from robomech.verify import _generic as g

from _harness import Workload

N = 100_000
N_DISTINCT = 1000
N_ALT_ENGINE = 300


def _states(mech):
    t, at = g.trajectory(mech, n=N_DISTINCT, t_end=N_DISTINCT * 0.01)
    qa, qd, qdd = at(t)
    q, conv = g._assemble_along(mech, qa)  # continuation along the trajectory keeps the branch
    assert conv.all()
    reps = N // N_DISTINCT
    return np.tile(q, (reps, 1)), np.tile(qd, (reps, 1)), np.tile(qdd, (reps, 1))


def _gallery(name: str) -> list[Workload]:
    mech = mb.gallery.load(name)
    q, qd, qdd = _states(mech)
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

    per = 8 * (mech.nq + 2 * 3 + len(mech.actuated))
    return [
        Workload(
            name=f"multibody: {name} inverse dynamics (generic)",
            group="13",
            run=run,
            n=N,
            bytes_moved=N * per,
            alternative=alt,
            n_alt=N_ALT_ENGINE,
            alternative_name="MuJoCo per sample (rne+efc_J)",
            target_speedup=5.0,
            repeats=1,
        )
    ]


def _spherical_leg() -> list[Workload]:
    leg = sl.SphericalLeg.paper()
    by_angles = sl.to_multibody(leg, actuate="platform")
    rng = np.random.default_rng(2)
    ab = rng.uniform(-0.5, 0.5, (N_DISTINCT, 2))
    q = mb.forward_kinematics(by_angles, ab).q
    reps = N // N_DISTINCT
    Q, AB = np.tile(q, (reps, 1)), np.tile(ab, (reps, 1))
    QD, QDD = rng.normal(size=(N, 2)), rng.normal(size=(N, 2))

    def run():
        return mb.inverse_dynamics(by_angles, Q, QD, QDD).tau

    def alt():
        return sl.inverse_dynamics(leg, AB, QD, QDD).generalized_forces

    return [
        Workload(
            name="multibody: spherical_leg inverse dynamics (generic)",
            group="13",
            run=run,
            n=N,
            bytes_moved=N * 8 * (by_angles.nq + 6),
            alternative=alt,
            n_alt=N,
            alternative_name="analytic Kane model (batched)",
            target_speedup=1 / 3,
            repeats=1,
        )
    ]


def workloads() -> list[Workload]:
    return [*_gallery("delta"), *_gallery("stewart"), *_spherical_leg()]
