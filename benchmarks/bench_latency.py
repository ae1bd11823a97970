"""Per-call latency and parallel scaling of the generic layer's compiled kernels (Delta).

* batch 1: ``mb.inverse_dynamics`` of one Delta sample (validation + one kernel call + result
  assembly), against the lean MuJoCo loop on the exported model (``mj_kinematics``, ``mj_comPos``,
  ``mj_makeConstraint``, ``mj_comVel``, ``mj_rne``, then the projection onto the actuators through
  the equality rows of ``efc_J``), per sample;
* 10^5 samples: the same call over the batch on all cores (numba ``prange`` over blocks), against
  one thread (``numba.set_num_threads(1)``) and against the lean MuJoCo loop per sample.

* a 6-DOF serial arm (a Builder description, exported to MJCF and read by Pinocchio's own MJCF parser):
  batch-1 ``mb.inverse_dynamics``, ``mb.generalized_forces``, ``mb.mass_matrix`` and the full-rate
  ``mb.forward_dynamics`` against ``pinocchio.rnea`` / ``pinocchio.crba`` (same answer checked to
  1e-10); at 10^5 samples ``mb.generalized_forces`` against ``pinocchio.rneaInParallel`` with the same
  thread counts (1 and all), and against a Python loop of ``pinocchio.rnea``;
* the Delta at batch 1 also against a Pinocchio-written closed-loop inverse dynamics
  (:func:`pinocchio_closed_loop`: the Pinocchio model of ``mb.to_pinocchio``, ``pin.rnea``,
  the closure rows from ``getFrameJacobian``, the lean MuJoCo loop's projection; same answer to 1e-8).

* the Delta's closed-chain ``mb.forward_dynamics`` (actuated-rates form) at batch 1 and 10^4 samples.

* ``--moved`` (:func:`moved_rows`): the Delta's ``mb.influence``, ``mb.site_hessian``,
  ``mb.site_wrench``, full-rate ``mb.inverse_dynamics``, a short ``mb.simulate``, the closure functions
  (``constraint_residual``, ``constraint_jacobian``, ``constraint_jacobian_rate``), ``singularities``,
  ``site_pose`` and ``energy`` at batch 1 and 10^4 samples (run on two source trees in turn for a
  before / after comparison).

* ``--compile`` (:func:`compile_rows`): the compile step (``_compile._compile``: tree, closure rows,
  tables, reference assembly and reference rank) and ``mb.mobility`` of the Delta and the 6-DOF arm,
  and the first load or build of each (its compile step included) in a fresh process (warm kernel
  cache).

The compared measurements are taken in interleaved rounds (:func:`_interleaved`: in each round
robomech and every alternative in turn) and reported as the minimum and the median over the rounds,
so that the shared machine's background load hits both sides alike; the load average is printed.

``python benchmarks/bench_latency.py`` prints the table recorded in docs/performance.md (per-call
latencies are not batched workloads: :func:`workloads` gives ``make bench`` none).
"""

from __future__ import annotations

import time

import numpy as np

from robomech import multibody as mb
from robomech.verify import _generic as g
from robomech.verify._mujoco import Engine, assemble_along

N_BATCH1 = 2000  # batch-1 calls timed
N_LARGE = 100_000
N_MJ = 2000  # lean MuJoCo loop samples timed (linear in the count)
N_FD = 10_000  # closed-chain forward-dynamics samples of the large-batch row
REPEATS = 3  # batch-1 runs of the arm rows (best kept)
ROUNDS = 15  # interleaved rounds of the compared measurements (min and median of each reported)


def _states(mech, n):
    t, at = g.trajectory(mech, n=200, t_end=2.0)
    qa, qd, qdd = at(t)
    fk = assemble_along(mech, qa)
    assert fk.converged.all()
    q = fk.q
    reps = -(-n // q.shape[0])
    return tuple(np.tile(x, (reps, 1))[:n] for x in (q, qd, qdd))


def lean_mujoco(mech):
    """The lean per-sample MuJoCo inverse dynamics: tree kinematics, constraint rows, RNE, projection."""
    import mujoco

    m = g.engine_model(mech)
    d = mujoco.MjData(m)
    eng = Engine(m, d)
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
        Jc = eng.equality()[0]
        _, s, Vt = np.linalg.svd(Jc)
        Nn = Vt[int(np.sum(s > 1e-9 * s[0])) :].T
        return np.linalg.lstsq(Nn.T @ E, Nn.T @ f, rcond=None)[0]

    return one


def pinocchio_closed_loop(mech):
    """A Pinocchio-written closed-loop inverse dynamics of ``mech`` (point closures): the model of
    ``mb.to_pinocchio``, then per sample ``pin.rnea``, the closure rows from ``getFrameJacobian`` at the
    closure frames, and the same projection as :func:`lean_mujoco`.  Returns (one(q, v, a) in
    Pinocchio's coordinates, to_pin: MuJoCo (qpos, qvel, qacc) -> Pinocchio (q, v, a))."""
    import pinocchio as pin

    P = mb.to_pinocchio(mech)
    model = P.model
    frames = []
    for i, cm in enumerate(P.constraints):
        assert cm.type == pin.ContactType.CONTACT_3D
        op = pin.FrameType.OP_FRAME
        frames.append(
            (
                model.addFrame(pin.Frame(f"c{i}_0", cm.joint1_id, cm.joint1_placement, op)),
                model.addFrame(pin.Frame(f"c{i}_1", cm.joint2_id, cm.joint2_placement, op)),
            )
        )
    data = model.createData()
    E = np.zeros((model.nv, len(mech.actuated)))
    for col, name in enumerate(mech.actuated):  # hinge / slide actuators: one column each
        E[model.joints[model.getJointId(name)].idx_v, col] = 1.0
    K = np.zeros((3 * len(frames), model.nv))
    LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED

    def one(q, v, a):
        f = pin.rnea(model, data, q, v, a)
        pin.computeJointJacobians(model, data, q)
        for i, (f1, f2) in enumerate(frames):
            K[3 * i : 3 * i + 3] = (
                pin.getFrameJacobian(model, data, f1, LWA)[:3]
                - pin.getFrameJacobian(model, data, f2, LWA)[:3]
            )
        _, s, Vt = np.linalg.svd(K)
        Nn = Vt[int(np.sum(s > 1e-9 * s[0])) :].T
        return np.linalg.lstsq(Nn.T @ E, Nn.T @ f, rcond=None)[0]

    return one, P.state


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

    import numba
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
    assert np.max(np.abs(mb.mass_matrix(mech, q) - pin.crba(pm, pd, q))) <= 1e-10  # (pin fills both halves)
    tp = min(_per(lambda i: pin.rnea(pm, pd, q, qd, qdd), N_BATCH1) for _ in range(REPEATS))
    tpm = min(_per(lambda i: pin.crba(pm, pd, q), N_BATCH1) for _ in range(REPEATS))
    rows = []
    for label, fn, alt, ta in (
        ("inverse_dynamics", lambda i: mb.inverse_dynamics(mech, q, qd, qdd), "pinocchio.rnea", tp),
        ("generalized_forces", lambda i: mb.generalized_forces(mech, q, qd, qdd), "pinocchio.rnea", tp),
        ("mass_matrix", lambda i: mb.mass_matrix(mech, q), "pinocchio.crba", tpm),
        ("forward_dynamics (full qd)", lambda i: mb.forward_dynamics(mech, q, tau=ref, qd=qd), "—", np.nan),
    ):
        t = min(_per(fn, N_BATCH1) for _ in range(REPEATS))
        rows.append(
            f"| 6-DOF arm {label}, batch 1 (per call) | {t * 1e6:.1f} us | "
            + (f"{alt} {ta * 1e6:.1f} us | {ta / t:.2f}x |" if np.isfinite(ta) else "— | — |")
        )
    # 10^5 samples: generalized_forces on all cores and on one, against pinocchio.rneaInParallel
    # (its own thread pool over a ModelPool, column-major (nv, N) arrays) with the same thread counts
    Q = rng.uniform(-np.pi, np.pi, (N_LARGE, 6))
    QD, QDD = rng.normal(size=(N_LARGE, 6)), rng.normal(size=(N_LARGE, 6))
    threads = numba.get_num_threads()
    pool = pin.ModelPool(pm, threads)
    QF, QDF, QDDF = (np.asfortranarray(x.T) for x in (Q, QD, QDD))
    TF = np.zeros((6, N_LARGE), order="F")
    pin.rneaInParallel(threads, pool, QF, QDF, QDDF, TF)
    ours = mb.generalized_forces(mech, Q, QD, QDD)
    assert np.max(np.abs(ours - TF.T)) <= 1e-10 * np.max(np.abs(TF))  # the same answer
    fns = {}
    for nt in (threads, 1):  # interleaved: robomech and rneaInParallel in turn, both thread counts
        fns[("rm", nt)] = _large(lambda: mb.generalized_forces(mech, Q, QD, QDD), N_LARGE, nt)
        fns[("pin", nt)] = _large(lambda nt=nt: pin.rneaInParallel(nt, pool, QF, QDF, QDDF, TF), N_LARGE, nt)
    res = _interleaved(fns)
    numba.set_num_threads(threads)
    tl = min(_per(lambda i: pin.rnea(pm, pd, Q[i], QD[i], QDD[i]), N_MJ) for _ in range(REPEATS))
    for nt in (1, threads):
        a, b = res[("rm", nt)], res[("pin", nt)]
        rows.append(
            f"| 6-DOF arm generalized_forces, 10^5 samples, {nt} thread(s) (per sample, min / median) | "
            f"{_mm(a)} | pinocchio.rneaInParallel({nt}) {_mm(b)} | "
            f"{b[0] / a[0]:.2f}x / {b[1] / a[1]:.2f}x |"
        )
    rows.append(
        f"| 6-DOF arm generalized_forces, 10^5 samples: parallel speed-up (min / median) | "
        f"{res[('rm', 1)][0] / res[('rm', threads)][0]:.2f}x / "
        f"{res[('rm', 1)][1] / res[('rm', threads)][1]:.2f}x | "
        f"rneaInParallel {res[('pin', 1)][0] / res[('pin', threads)][0]:.2f}x / "
        f"{res[('pin', 1)][1] / res[('pin', threads)][1]:.2f}x | — |"
    )
    rows.append(
        f"| 6-DOF arm, 10^5 samples, {threads} threads (per sample, min) | "
        f"{res[('rm', threads)][0] * 1e6:.2f} us | "
        f"Python loop of pinocchio.rnea {tl * 1e6:.2f} us | {tl / res[('rm', threads)][0]:.1f}x |"
    )
    return rows


def _interleaved(fns: dict, rounds: int = ROUNDS) -> dict:
    """``{name: (min, median)}`` of per-sample seconds, the measurements taken in turn in every round
    (``fns[name]()`` returns one measurement), so that background load hits every one alike."""
    t: dict = {k: [] for k in fns}
    for _ in range(rounds):
        for k, fn in fns.items():
            t[k].append(fn())
    return {k: (float(np.min(v)), float(np.median(v))) for k, v in t.items()}


def _large(fn, n, threads):
    """A per-sample timer of one call of ``fn()`` over ``n`` samples on ``threads`` numba threads."""
    import numba

    def run():
        numba.set_num_threads(threads)
        t0 = time.perf_counter()
        fn()
        return (time.perf_counter() - t0) / n

    return run


def _mm(x: tuple) -> str:
    """``min / median`` in microseconds."""
    return f"{x[0] * 1e6:.2f} / {x[1] * 1e6:.2f} us"


def _per(fn, n):
    fn(0)
    t0 = time.perf_counter()
    for i in range(n):
        fn(i)
    return (time.perf_counter() - t0) / n


def main() -> None:
    import os

    import numba

    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())

    mech = mb.gallery.load("delta")
    q, qd, qdd = _states(mech, N_LARGE)
    r = mb.inverse_dynamics(mech, q[:200], qd[:200], qdd[:200])
    assert r.valid.all()
    one = lean_mujoco(mech)
    tau_mj = np.array([one(q[i], r.qd[i], r.qdd[i]) for i in range(200)])
    assert np.max(np.abs(tau_mj - r.tau)) <= 1e-8 * np.max(np.abs(tau_mj))  # the same answer
    pone, to_pin = pinocchio_closed_loop(mech)
    pin_args = [to_pin(q[i], r.qd[i], r.qdd[i]) for i in range(200)]  # converted outside the timing
    tau_pin = np.array([pone(*a) for a in pin_args])
    assert np.max(np.abs(tau_pin - r.tau)) <= 1e-8 * np.max(np.abs(r.tau))  # the same answer
    mb.inverse_dynamics(mech, q[:1000], qd[:1000], qdd[:1000])
    tau = mb.inverse_dynamics(mech, q[:N_FD], qd[:N_FD], qdd[:N_FD]).tau
    fd = mb.forward_dynamics(mech, q[:N_FD], qd[:N_FD], tau)
    assert fd.valid.all() and np.max(np.abs(fd.qdd_act - qdd[:N_FD])) <= 1e-4  # the round trip (~1e-5)
    threads = numba.get_num_threads()
    n1, nmj = N_BATCH1 // 4, N_MJ // 4  # per round: the rounds are interleaved
    res = _interleaved(
        {
            "id1": lambda: _per(lambda i: mb.inverse_dynamics(mech, q[i], qd[i], qdd[i]), n1),
            "mj": lambda: _per(lambda i: one(q[i], r.qd[i % 200], r.qdd[i % 200]), nmj),
            "pin": lambda: _per(lambda i: pone(*pin_args[i % 200]), nmj),
            "fd1": lambda: _per(lambda i: mb.forward_dynamics(mech, q[i], qd[i], tau[i]), n1),
            "idN": _large(lambda: mb.inverse_dynamics(mech, q, qd, qdd), N_LARGE, threads),
            "id1t": _large(lambda: mb.inverse_dynamics(mech, q, qd, qdd), N_LARGE, 1),
            "fdN": _large(lambda: mb.forward_dynamics(mech, q[:N_FD], qd[:N_FD], tau), N_FD, threads),
        }
    )
    numba.set_num_threads(threads)
    t1, tmj, tpin = res["id1"], res["mj"], res["pin"]
    tp, ts = res["idN"], res["id1t"]
    print(f"load average (1, 5, 15 min) before the run: {load}")
    print("| workload | robomech (min / median) | alternative (min / median) | alternative / robomech |")
    print("|---|---|---|---|")
    print(
        f"| Delta inverse dynamics, batch 1 (per call) | {_mm(t1)} | lean MuJoCo loop {_mm(tmj)} | "
        f"{tmj[0] / t1[0]:.2f}x |"
    )
    print(
        f"| Delta inverse dynamics, batch 1 (per call) | {_mm(t1)} | Pinocchio-written loop {_mm(tpin)} | "
        f"{tpin[0] / t1[0]:.2f}x |"
    )
    print(
        f"| Delta inverse dynamics, 10^5 samples, {threads} threads (per sample) | {_mm(tp)} | "
        f"lean MuJoCo loop {_mm(tmj)} | {tmj[0] / tp[0]:.1f}x |"
    )
    print(
        f"| Delta inverse dynamics, 10^5 samples, 1 thread (per sample) | {_mm(ts)} | — | "
        f"parallel speed-up {ts[0] / tp[0]:.2f}x |"
    )
    print(f"| Delta forward dynamics (closed chain), batch 1 (per call) | {_mm(res['fd1'])} | — | — |")
    print(
        f"| Delta forward dynamics (closed chain), 10^4 samples, {threads} threads (per sample) | "
        f"{_mm(res['fdN'])} | — | — |"
    )
    for row in _arm_rows():
        print(row)


N_MOVED = 10_000  # samples of the large-batch rows of :func:`moved_rows`
N_SIM = 20  # simulate: initial conditions of the batch row (each integrated on its own)


def moved_rows() -> list[str]:
    """The Delta's ``influence``, ``site_hessian``, ``site_wrench``, full-rate ``inverse_dynamics``
    (``qd=``, ``qdd=``), a short ``simulate`` (0.05 s, 6 output times), the closure functions,
    ``singularities``, ``site_pose`` and ``energy``: per call at batch 1 and per
    sample at 10^4 (``simulate``: ``N_SIM`` initial conditions), min / median over interleaved rounds."""
    mech = mb.gallery.load("delta")
    q, qd, qdd = _states(mech, N_MOVED)
    r = mb.inverse_dynamics(mech, q, qd, qdd)
    tau, fq, fqd = r.tau, r.qd, r.qdd
    t = np.linspace(0.0, 0.05, 6)
    calls = {
        "influence": lambda s: mb.influence(mech, q[s]),
        "site_hessian": lambda s: mb.site_hessian(mech, q[s], "tcp"),
        "site_wrench": lambda s: mb.site_wrench(mech, q[s], "tcp", tau[s]),
        "inverse_dynamics (qd=, qdd=)": lambda s: mb.inverse_dynamics(mech, q[s], qd=fq[s], qdd=fqd[s]),
        "simulate (0.05 s)": lambda s: mb.simulate(mech, q[s], qd[s], t),
        "constraint_residual": lambda s: mb.constraint_residual(mech, q[s]),
        "constraint_jacobian": lambda s: mb.constraint_jacobian(mech, q[s]),
        "constraint_jacobian_rate": lambda s: mb.constraint_jacobian_rate(mech, q[s], fq[s]),
        "singularities": lambda s: mb.singularities(mech, q[s], "tcp"),
        "site_pose": lambda s: mb.site_pose(mech, q[s], "tcp"),
        "energy": lambda s: mb.energy(mech, q[s], fq[s]),
    }
    for fn in calls.values():  # compile / load every kernel outside the timing
        fn(0), fn(slice(0, 100))
    fns = {}
    for name, fn in calls.items():
        n1 = 20 if name.startswith("simulate") else 200
        nN = N_SIM if name.startswith("simulate") else N_MOVED
        fns[name + " 1"] = lambda fn=fn, n1=n1: _per(fn, n1)
        fns[name + " N"] = _large(lambda fn=fn, nN=nN: fn(slice(0, nN)), nN, 2)
    res = _interleaved(fns, rounds=3)
    rows = [
        "| Delta function | batch 1 (per call, min / median) | 10^4 (per sample, min / median) |",
        "|---|---|---|",
    ]
    for name in calls:
        big = f"{N_SIM} samples" if name.startswith("simulate") else "10^4"
        rows.append(f"| {name} | {_mm(res[name + ' 1'])} | {big}: {_mm(res[name + ' N'])} |")
    return rows


def _fresh_compile(name: str) -> float:
    """Seconds of the first ``gallery.load("delta")`` or ``arm6()`` (``name``: ``delta`` or ``arm6``) in a
    fresh process: reading or building the description and its compile step (both compile it)."""
    import subprocess
    import sys
    from pathlib import Path

    code = (
        "import time, sys; sys.path.insert(0, sys.argv[1]); import bench_latency as b\n"
        "from robomech import multibody as mb\n"
        "import mujoco\n"  # the MJCF reader's import, outside the timing
        "t0 = time.perf_counter()\n"
        "m = mb.gallery.load('delta') if sys.argv[2] == 'delta' else b.arm6()\n"
        "print(time.perf_counter() - t0)\n"
    )
    here = str(Path(__file__).resolve().parent)
    out = subprocess.run([sys.executable, "-c", code, here, name], capture_output=True, text=True, check=True)
    return float(out.stdout.split()[-1])


def compile_rows() -> list[str]:
    """The compile step and ``mobility`` of the Delta and the 6-DOF arm, per call (min / median over
    interleaved rounds), and the first compile in a fresh process (3 processes: min / median)."""
    from robomech.multibody import _compile

    mechs = {"Delta": mb.gallery.load("delta"), "6-DOF arm": arm6()}
    fns = {}
    for name, mech in mechs.items():
        mb.mobility(mech)  # load every kernel outside the timing
        fns[name + " compile"] = lambda mech=mech: _per(lambda i: _compile._compile(mech), 20)
        fns[name + " mobility"] = lambda mech=mech: _per(lambda i: mb.mobility(mech), 20)
    res = _interleaved(fns, rounds=5)
    rows = [
        "| | compile step (per call, min / median) | mobility (per call) | first load, fresh process |",
        "|---|---|---|---|",
    ]
    for name, key in (("Delta", "delta"), ("6-DOF arm", "arm6")):
        first = [_fresh_compile(key) for _ in range(3)]
        rows.append(
            f"| {name} | {_mm(res[name + ' compile'])} | {_mm(res[name + ' mobility'])} | "
            f"{min(first) * 1e3:.0f} / {np.median(first) * 1e3:.0f} ms |"
        )
    return rows


KERNEL_MECHS = ("delta", "stewart")  # a 3-DOF and a 6-DOF parallel mechanism of the gallery
KERNEL_SIZES = (1, 1_000, 10_000)  # batch sizes of :func:`kernel_rows`


def kernel_rows() -> list[str]:
    """``singularities`` (site Jacobian, scaled K, K_p and J and their singular values) and
    ``constraint_jacobian_rate`` of the Delta and the Stewart platform at batch sizes ``KERNEL_SIZES``:
    per call at batch 1, per sample above (the largest batch on every numba thread and on one), min /
    median over interleaved rounds (run on two source trees in turn for a before / after comparison)."""
    import os

    import numba

    threads = numba.get_num_threads()
    fns = {}
    for name in KERNEL_MECHS:
        mech = mb.gallery.load(name)
        q, qd_act, qdd_act = _states(mech, max(KERNEL_SIZES))
        qd = mb.inverse_dynamics(mech, q, qd_act, qdd_act).qd  # the full admissible rates
        site = mech.sites[0].name
        calls = {
            "singularities": lambda s, mech=mech, q=q, site=site: mb.singularities(mech, q[s], site),
            "constraint_jacobian_rate": lambda s, mech=mech, q=q, qd=qd: mb.constraint_jacobian_rate(
                mech, q[s], qd[s]
            ),
        }
        for fn in calls.values():  # compile / load every kernel outside the timing
            fn(0), fn(slice(0, 100))
        for call, fn in calls.items():
            for n in KERNEL_SIZES:
                fns[(name, call, n)] = (
                    (lambda fn=fn: _per(fn, 200))
                    if n == 1
                    else _large(lambda fn=fn, n=n: fn(slice(0, n)), n, threads)
                )
            n = KERNEL_SIZES[-1]  # the largest batch on one thread too: the work, not the cores
            fns[(name, call, "1 thread")] = _large(lambda fn=fn, n=n: fn(slice(0, n)), n, 1)
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    res = _interleaved(fns, rounds=3)
    numba.set_num_threads(threads)
    rows = [
        f"load average (1, 5, 15 min) before the run: {load}",
        "| mechanism | function | batch 1 (per call) | 10^3 (per sample) | "
        f"10^4 (per sample, {threads} threads) | 10^4 (per sample, 1 thread) |",
        "|---|---|---|---|---|---|",
    ]
    for name in KERNEL_MECHS:
        for call in ("singularities", "constraint_jacobian_rate"):
            cells = " | ".join(_mm(res[(name, call, n)]) for n in (*KERNEL_SIZES, "1 thread"))
            rows.append(f"| {name} | {call} | {cells} |")
    return rows


if __name__ == "__main__":
    import sys

    if sys.argv[1:] == ["--moved"]:
        for row in moved_rows():
            print(row)
    elif sys.argv[1:] == ["--compile"]:
        for row in compile_rows():
            print(row)
    elif sys.argv[1:] == ["--kernels"]:
        for row in kernel_rows():
            print(row)
    else:
        main()
