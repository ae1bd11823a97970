"""Per-call latency and parallel scaling of the generic layer's compiled kernels (Delta).

* batch 1: ``mb.inverse_dynamics`` of one Delta sample (validation + one kernel call + result
  assembly), against the lean MuJoCo loop on the exported model (``mj_kinematics``, ``mj_comPos``,
  ``mj_makeConstraint``, ``mj_comVel``, ``mj_rne``, then the projection onto the actuators through
  the equality rows of ``efc_J``), per sample;
* 10^5 samples: the same call over the batch on all cores (numba ``prange`` over blocks), against
  one thread (``numba.set_num_threads(1)``) and against the lean MuJoCo loop per sample.

* a 6-DOF serial arm (a Builder description, exported to MJCF and read by Pinocchio's own MJCF parser):
  batch-1 ``mb.inverse_dynamics`` and ``mb.generalized_forces`` against ``pinocchio.rnea`` (same
  answer checked to 1e-10).

``python benchmarks/bench_latency.py`` prints the table recorded in docs/performance.md (per-call
latencies are not batched workloads: :func:`workloads` gives ``make bench`` none).
"""

from __future__ import annotations

import time

import numpy as np

from robomech import multibody as mb
from robomech.verify import _generic as g

N_BATCH1 = 2000  # batch-1 calls timed
N_LARGE = 100_000
N_MJ = 2000  # lean MuJoCo loop samples timed (linear in the count)
REPEATS = 3  # large-batch runs per thread count (best kept)


def _states(mech, n):
    t, at = g.trajectory(mech, n=200, t_end=2.0)
    qa, qd, qdd = at(t)
    q, conv = g._assemble_along(mech, qa)
    assert conv.all()
    reps = -(-n // q.shape[0])
    return tuple(np.tile(x, (reps, 1))[:n] for x in (q, qd, qdd))


def lean_mujoco(mech):
    """The lean per-sample MuJoCo inverse dynamics: tree kinematics, constraint rows, RNE, projection."""
    import mujoco

    m = g.engine_model(mech)
    d = mujoco.MjData(m)
    E = np.zeros((m.nv, len(mech.actuated)))
    E[mech.tree.act_dof, np.arange(len(mech.actuated))] = 1.0
    f = np.zeros(m.nv)

    def one(q, qd, qdd):
        d.qpos[:] = q
        d.qvel[:] = qd
        d.qacc[:] = qdd
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        mujoco.mj_makeConstraint(m, d)
        mujoco.mj_comVel(m, d)
        mujoco.mj_rne(m, d, 1, f)
        Jc = g._efc_equality(m, d)
        _, s, Vt = np.linalg.svd(Jc)
        Nn = Vt[int(np.sum(s > 1e-9 * s[0])) :].T
        return np.linalg.lstsq(Nn.T @ E, Nn.T @ f, rcond=None)[0]

    return one


def workloads() -> list:
    """None for ``benchmarks/run.py``: this file prints its own latency table (``main``)."""
    return []


def arm6() -> mb.Mechanism:
    """A 6-DOF serial arm (alternating axes, offset links, every body massive), all joints actuated."""
    b = mb.Builder("arm6")
    axes = [(0, 0, 1), (0, 1, 0), (0, 1, 0), (1, 0, 0), (0, 1, 0), (1, 0, 0)]
    parent = "world"
    for i, ax in enumerate(axes):
        b.body(
            f"l{i}",
            parent=parent,
            pos=(0.2, 0, 0) if i % 2 else (0, 0, 0.1 if i else 0.0),
            joints=[b.hinge(f"j{i}", axis=ax)],
            inertial=mb.Inertial(1.0 + 0.1 * i, pos=(0.05, 0.01, 0.02), diaginertia=(0.01, 0.012, 0.008)),
        )
        parent = f"l{i}"
    b.site("tool", parent, pos=(0.1, 0, 0))
    b.actuate(*[f"j{i}" for i in range(6)])
    return b.build()


def _arm_rows() -> list[str]:
    import os
    import tempfile

    import pinocchio as pin

    mech = arm6()
    rng = np.random.default_rng(0)
    q, qd, qdd = rng.uniform(-1, 1, 6), rng.normal(size=6), rng.normal(size=6)
    path = os.path.join(tempfile.mkdtemp(), "arm6.xml")
    with open(path, "w") as f:
        f.write(mb.to_mjcf(mech))
    pm = pin.buildModelFromMJCF(path)
    pd = pm.createData()
    ref = pin.rnea(pm, pd, q, qd, qdd)
    tau = mb.inverse_dynamics(mech, q, qd, qdd).tau
    assert np.max(np.abs(tau - ref)) <= 1e-10 * np.max(np.abs(ref))  # the same answer
    assert np.max(np.abs(mb.generalized_forces(mech, q, qd, qdd) - ref)) <= 1e-10 * np.max(np.abs(ref))
    tp = min(_per(lambda i: pin.rnea(pm, pd, q, qd, qdd), N_BATCH1) for _ in range(REPEATS))
    rows = []
    for label, fn in (
        ("inverse_dynamics", lambda i: mb.inverse_dynamics(mech, q, qd, qdd)),
        ("generalized_forces", lambda i: mb.generalized_forces(mech, q, qd, qdd)),
    ):
        t = min(_per(fn, N_BATCH1) for _ in range(REPEATS))
        rows.append(
            f"| 6-DOF arm {label}, batch 1 (per call) | {t * 1e6:.1f} us | "
            f"pinocchio.rnea {tp * 1e6:.1f} us | {tp / t:.2f}x |"
        )
    return rows


def _per(fn, n):
    fn(0)
    t0 = time.perf_counter()
    for i in range(n):
        fn(i)
    return (time.perf_counter() - t0) / n


def main() -> None:
    import numba

    mech = mb.gallery.load("delta")
    q, qd, qdd = _states(mech, N_LARGE)
    r = mb.inverse_dynamics(mech, q[:200], qd[:200], qdd[:200])
    assert r.valid.all()
    one = lean_mujoco(mech)
    tau_mj = np.array([one(q[i], r.qd[i], r.qdd[i]) for i in range(200)])
    assert np.max(np.abs(tau_mj - r.tau)) <= 1e-8 * np.max(np.abs(tau_mj))  # the same answer
    t1 = min(_per(lambda i: mb.inverse_dynamics(mech, q[i], qd[i], qdd[i]), N_BATCH1) for _ in range(REPEATS))
    tmj = min(_per(lambda i: one(q[i], r.qd[i % 200], r.qdd[i % 200]), N_MJ) for _ in range(REPEATS))
    mb.inverse_dynamics(mech, q[:1000], qd[:1000], qdd[:1000])
    threads = numba.get_num_threads()
    tp = ts = np.inf
    for _ in range(REPEATS):  # alternated, best of each: the machine is shared
        numba.set_num_threads(threads)
        t0 = time.perf_counter()
        mb.inverse_dynamics(mech, q, qd, qdd)
        tp = min(tp, (time.perf_counter() - t0) / N_LARGE)
        numba.set_num_threads(1)
        t0 = time.perf_counter()
        mb.inverse_dynamics(mech, q, qd, qdd)
        ts = min(ts, (time.perf_counter() - t0) / N_LARGE)
    numba.set_num_threads(threads)
    print("| workload | robomech | alternative | alternative / robomech |")
    print("|---|---|---|---|")
    print(
        f"| Delta inverse dynamics, batch 1 (per call) | {t1 * 1e6:.0f} us | {tmj * 1e6:.0f} us | "
        f"{tmj / t1:.2f}x |"
    )
    print(
        f"| Delta inverse dynamics, 10^5 samples, {threads} threads (per sample) | {tp * 1e6:.2f} us | "
        f"{tmj * 1e6:.0f} us | {tmj / tp:.1f}x |"
    )
    print(
        f"| Delta inverse dynamics, 10^5 samples, 1 thread (per sample) | {ts * 1e6:.2f} us | — | "
        f"parallel speed-up {ts / tp:.2f}x |"
    )
    for row in _arm_rows():
        print(row)


if __name__ == "__main__":
    main()
