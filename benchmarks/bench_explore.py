"""robomech.explore: throughput of the built-in design studies, Dask scaling and per-chunk overhead.

``workloads()`` (for ``run.py``): one default-size chunk of each study evaluated in-process (pose
evaluations per second on one core, no Dask).

``python benchmarks/bench_explore.py`` (standalone, ~2 min on 2 idle cores): one LocalCluster of 1 and
one of 2 single-threaded worker processes (``robomech.explore``'s own ``local_cluster``: ``WORKER_ENV``
and ``LOCAL_CLUSTER_CONFIG``; ``--dask-defaults`` uses Dask's default settings instead, for an A/B of
those settings), a warm-up
sweep per study and worker count, then for each study the *same* sweep (``--chunks`` default-size chunks,
the same designs) ``--repeats`` times on each cluster, alternating the clusters, reading back per sweep:

- ``T`` the wall time of ``run_sweep`` (store creation and everything else included);
- the Dask task stream: when each task started and stopped on its worker, so ``window`` is the time
  from the first task's start to the last task's stop (the steady state, without the sweep's one-off
  set-up: connecting, creating the store, the design matrix) and ``task overhead`` the worker-side time
  of a task outside the study's code (task duration minus the in-task work timer ``chunk_seconds``);
- the client's time per chunk in ``ChunkWriter.write`` (the Zarr write of a finished chunk);
- CPU accounting (psutil, user + system CPU seconds of every process before and after the sweep): this
  process (client, both schedulers and the nannies), the cluster's worker processes and the other,
  idle cluster's workers, against the in-task CPU of the chunks (``chunk_cpu_seconds``).  Unlike wall
  time this does not depend on what else runs on the machine.

Reported per study (medians over the repeats):

- poses/s = designs x ``poses_per_design`` / T; set-up + tail = T - window (once per sweep);
- efficiency ``T1 / (2 T2)`` (the acceptance figure) and the steady-state one ``window1 / (2 window2)``;
- CPU efficiency = in-task CPU / CPU of all processes: the share of the CPU the sweep used that went
  into the study's computation (the rest is Dask's and the client's work), a load-robust companion of
  ``T1 / (2 T2)``; with the in-task CPU per chunk on 2 workers over that on 1 (the slow-down of the
  study's own code when two processes share caches and memory bandwidth) it explains the efficiency;
- overhead per chunk = (workers x window - sum of chunk work) / chunks: everything per chunk that is not
  the study's computation (scheduling, transfer, the worker's task wrapper, the client's receipt and
  Zarr write competing for the cores, and the 2-worker load imbalance), as a fraction of the mean chunk
  work; and its parts, the worker-side task overhead and the client's write time;
- the 10^6-design spherical-leg synthesis extrapolated from the 1-worker steady throughput;
- the machine's own two-process ceiling, without Dask: the same chunks evaluated by plain processes
  (``concurrent.futures``, spawned with ``WORKER_ENV``), all by one process vs half each by two at once,
  ``ceiling = T1 / (2 T2)``.  On a machine whose two cores slow each other down (shared caches, memory
  bandwidth, a hypervisor's vCPUs) the ceiling is below 1 and no scheduler can beat it, so Dask's
  efficiency is also reported relative to it (``efficiency / ceiling``: what Dask itself loses);
  ``--no-ceiling`` skips it (small A/B runs).
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from robomech.explore import DesignStudy, design_matrix, get_study, open_results, run_sweep
from robomech.explore import _runner as runner_mod
from robomech.explore._sampling import chunk_seed

from _harness import Workload

STUDIES = ("spherical-leg-synthesis", "vectored-thrust-tolerance", "omnileg-synthesis")
# Default-size chunks per timed sweep: the same designs on 1 and 2 workers (2 chunks per worker).
CHUNKS = 4
# Repeats of each timed sweep (medians reported): the machine is shared, single runs vary by +-30 %.
REPEATS = 3
SYNTHESIS_DESIGNS = 1_000_000


def _one_chunk(st: DesignStudy, X: np.ndarray) -> None:
    """One in-process chunk of ``st`` (chunk 0's seed, fresh each call)."""
    st.evaluate_rows(X, chunk_seed(0, 0))


def workloads() -> list[Workload]:
    out = []
    for name in STUDIES:
        st = get_study(name)
        X = design_matrix(st.variables, st.default_chunk, st.default_sampler, 0, st.default_chunk)
        out.append(
            Workload(
                name=f"explore: {name}, one chunk ({st.default_chunk} designs)",
                group="x",
                run=functools.partial(_one_chunk, st, X),
                n=st.default_chunk * st.poses_per_design,
                bytes_moved=0,
                repeats=2,
            )
        )
    return out


class _TimedWriter(runner_mod.ChunkWriter):
    """The runner's ChunkWriter, timing each chunk's write (client side)."""

    seconds: ClassVar[list[float]] = []

    def write(self, *args: Any, **kwargs: Any) -> None:
        t0 = time.perf_counter()
        super().write(*args, **kwargs)
        _TimedWriter.seconds.append(time.perf_counter() - t0)


def _cpu_seconds() -> dict[str, float]:
    """CPU seconds (user + system) so far of this process (the client, the schedulers and the nannies of
    both clusters) and of each of its descendants (the worker processes), keyed "client" and by pid."""
    # psutil (a dependency of dask.distributed) ships no type stubs.
    import psutil  # type: ignore[import-untyped]

    me = psutil.Process()
    out = {"client": sum(me.cpu_times()[:2])}
    for p in me.children(recursive=True):
        try:
            out[str(p.pid)] = sum(p.cpu_times()[:2])
        except psutil.NoSuchProcess:  # pragma: no cover - a process that ended meanwhile
            continue
    return out


def _one_sweep(client: Any, name: str, out: Path, n: int) -> dict[str, float]:
    from distributed import get_task_stream

    st = get_study(name)
    _TimedWriter.seconds = []
    mine = {str(pid) for pid in client.run(os.getpid).values()}  # this cluster's worker processes
    with get_task_stream(client=client) as ts:
        c0 = _cpu_seconds()
        t0 = time.perf_counter()
        s = run_sweep(st, out, designs=n, client=client, progress=False)
        wall = time.perf_counter() - t0
        c1 = _cpu_seconds()
    used = {k: c1[k] - c0.get(k, 0.0) for k in c1}
    tasks = [t for t in ts.data if str(t["key"]).startswith("_chunk_task")]
    computes = [ss for t in tasks for ss in t["startstops"] if ss["action"] == "compute"]
    durations = [ss["stop"] - ss["start"] for t in tasks for ss in t["startstops"]]
    window = max(ss["stop"] for ss in computes) - min(ss["start"] for ss in computes)
    stored = open_results(out, as_dict=True)
    work = np.asarray(stored["chunk_seconds"], dtype=float)
    chunks = s.n_chunks
    assert len(computes) == chunks and s.computed_designs == n, "a chunk ran twice or not at all"
    task_cpu = float(np.sum(stored["chunk_cpu_seconds"]))
    return {
        # CPU accounting (load-independent): the in-task CPU of the chunks over the CPU of every process
        "cpu_all_s": sum(used.values()),
        "cpu_client_s": used["client"],
        "cpu_workers_outside_tasks_s": sum(v for k, v in used.items() if k in mine) - task_cpu,
        "cpu_other_s": sum(v for k, v in used.items() if k != "client" and k not in mine),
        "cpu_efficiency": task_cpu / sum(used.values()),
        "wall_s": wall,
        "window_s": window,
        "work_s": float(work.sum()),
        "work_per_chunk_s": float(work.mean()),
        "task_overhead_s": (sum(durations) - float(work.sum())) / chunks,
        "client_write_s": float(np.mean(_TimedWriter.seconds)),
        "cpu_s": task_cpu,
    }


def _measure(names: list[str], chunks: int, repeats: int) -> dict[int, dict[str, list[dict[str, float]]]]:
    """Both clusters stay up; the repeats alternate 1 and 2 workers so that a drifting load on a shared
    machine biases neither."""
    from contextlib import ExitStack

    import dask.config
    from distributed import Client

    runner_mod.ChunkWriter = _TimedWriter  # type: ignore[misc]
    out: dict[int, dict[str, list[dict[str, float]]]] = {1: {}, 2: {}}
    with ExitStack() as stack:
        d = Path(stack.enter_context(tempfile.TemporaryDirectory()))
        clients = {}
        for w in (1, 2):
            # the sweeps' own LocalCluster (WORKER_ENV, LOCAL_CLUSTER_CONFIG), as robomech sweep starts it
            cluster = stack.enter_context(runner_mod.local_cluster(w))
            with dask.config.set(runner_mod.LOCAL_CLUSTER_CONFIG):
                clients[w] = stack.enter_context(Client(cluster))
        for name in names:
            st = get_study(name)
            for w, client in clients.items():
                # warm-up: every worker imports robomech and runs its first chunk (first-call costs)
                run_sweep(st, d / f"warm-{w}-{name}", designs=st.default_chunk * w, client=client,
                          progress=False)  # fmt: skip
                out[w][name] = []
            for r in range(repeats):
                for w, client in clients.items():
                    out[w][name].append(
                        _one_sweep(client, name, d / f"{name}-{w}-{r}", chunks * st.default_chunk)
                    )
    return out


def _ceiling_chunks(name: str, chunks: list[int]) -> float:
    """In a plain worker process: evaluate the given default-size chunks of a study; the seconds it took."""
    st = get_study(name)
    t0 = time.perf_counter()
    for k in chunks:
        X = design_matrix(st.variables, st.default_chunk, st.default_sampler, 0, st.default_chunk)
        st.evaluate_rows(X, chunk_seed(0, k))
    return time.perf_counter() - t0


def _ceiling(names: list[str], chunks: int, repeats: int) -> dict[str, float]:
    """Two-process efficiency T1 / (2 T2) of the bare chunk computation (no Dask), median of repeats."""
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    saved = {k: os.environ.get(k) for k in runner_mod.WORKER_ENV}
    os.environ.update(runner_mod.WORKER_ENV)  # inherited by the spawned processes before they import numpy
    try:
        ctx = mp.get_context("spawn")
        with ProcessPoolExecutor(1, mp_context=ctx) as one, ProcessPoolExecutor(2, mp_context=ctx) as two:
            out = {}
            for name in names:
                one.submit(_ceiling_chunks, name, [0]).result()  # warm-up: imports, first-call costs
                list(two.map(_ceiling_chunks, [name, name], [[0], [1]]))
                effs = []
                for _ in range(repeats):
                    t0 = time.perf_counter()
                    one.submit(_ceiling_chunks, name, list(range(chunks))).result()
                    t1 = time.perf_counter() - t0
                    half = chunks // 2
                    t0 = time.perf_counter()
                    halves = [list(range(half)), list(range(half, chunks))]
                    list(two.map(_ceiling_chunks, [name, name], halves))
                    t2 = time.perf_counter() - t0
                    effs.append(t1 / (2 * t2))
                out[name] = statistics.median(effs)
            return out
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def _median(runs: list[dict[str, float]], key: str) -> float:
    return statistics.median(r[key] for r in runs)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--json", default=None, help="also write the rows as JSON to this file")
    p.add_argument("--only", default=None, help="only the studies whose name contains this")
    p.add_argument("--chunks", type=int, default=CHUNKS, help=f"chunks per timed sweep (default {CHUNKS})")
    p.add_argument("--repeats", type=int, default=REPEATS, help=f"repeats per sweep (default {REPEATS})")
    p.add_argument("--no-ceiling", action="store_true", help="skip the two-process ceiling (no Dask)")
    p.add_argument(
        "--dask-defaults",
        action="store_true",
        help="clusters with Dask's default settings instead of LOCAL_CLUSTER_CONFIG (A/B of those settings)",
    )
    args = p.parse_args()
    if args.dask_defaults:
        runner_mod.LOCAL_CLUSTER_CONFIG = {}
    names = [n for n in STUDIES if not args.only or args.only in n]
    t_start = time.perf_counter()
    load = os.getloadavg()[0]
    res = _measure(names, args.chunks, args.repeats)
    nan = float("nan")
    ceiling = {n: nan for n in names} if args.no_ceiling else _ceiling(names, args.chunks, args.repeats)
    rows = []
    print(
        f"\n{args.chunks} chunks per sweep, median of {args.repeats}; load average {load:.1f} at the start, "
        f"{os.getloadavg()[0]:.1f} at the end; {os.cpu_count()} cores; Dask settings: "
        f"{runner_mod.LOCAL_CLUSTER_CONFIG or 'Dask defaults'}\n"
    )
    print(
        "| study (chunk) | workers | T (s) | poses/s | efficiency T1/(2 T2) | steady efficiency | "
        "CPU efficiency | chunk work (s) | overhead / chunk (ms) | overhead / work | task overhead (ms) | "
        "client write (ms) | set-up + tail (s) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name in names:
        st = get_study(name)
        n = args.chunks * st.default_chunk
        one, two = res[1][name], res[2][name]
        t1, t2 = _median(one, "wall_s"), _median(two, "wall_s")
        w1, w2 = _median(one, "window_s"), _median(two, "window_s")
        for workers, runs, eff, steady in ((1, one, 1.0, 1.0), (2, two, t1 / (2 * t2), w1 / (2 * w2))):
            over = statistics.median((workers * r["window_s"] - r["work_s"]) / args.chunks for r in runs)
            work = _median(runs, "work_per_chunk_s")
            row = {
                "study": name,
                "chunk_size": st.default_chunk,
                "workers": workers,
                "designs": n,
                "wall_s": _median(runs, "wall_s"),
                "window_s": _median(runs, "window_s"),
                "poses_per_s": n * st.poses_per_design / _median(runs, "wall_s"),
                "efficiency": eff,
                "steady_efficiency": steady,
                "work_per_chunk_s": work,
                "overhead_per_chunk_s": over,
                "overhead_fraction": over / work,
                "task_overhead_s": _median(runs, "task_overhead_s"),
                "client_write_s": _median(runs, "client_write_s"),
                "cpu_per_design_s": _median(runs, "cpu_s") / n,
                "cpu_efficiency": _median(runs, "cpu_efficiency"),
                "task_cpu_per_chunk_s": _median(runs, "cpu_s") / args.chunks,
                "client_cpu_per_chunk_s": _median(runs, "cpu_client_s") / args.chunks,
                "worker_cpu_outside_tasks_per_chunk_s": _median(runs, "cpu_workers_outside_tasks_s")
                / args.chunks,
                "other_cpu_per_chunk_s": _median(runs, "cpu_other_s") / args.chunks,
                "ceiling": ceiling[name],
                "efficiency_vs_ceiling": eff / ceiling[name] if workers == 2 else 1.0,
                "runs": runs,
            }
            rows.append(row)
            print(
                f"| {name} ({st.default_chunk}) | {workers} | {row['wall_s']:.2f} | "
                f"{row['poses_per_s']:.3g} | {eff:.2f} | {steady:.2f} | {row['cpu_efficiency']:.3f} | "
                f"{work:.2f} | {1e3 * over:.0f} | "
                f"{100 * over / work:.1f} % | "
                f"{1e3 * row['task_overhead_s']:.1f} | {1e3 * row['client_write_s']:.1f} | "
                f"{row['wall_s'] - row['window_s']:.2f} |",
                flush=True,
            )
    print(
        "\nThe machine's two-process ceiling without Dask (same chunks, plain processes, T1 / (2 T2)) and "
        "Dask's 2-worker efficiency relative to it:\n"
    )
    print("| study | ceiling (no Dask) | Dask T1/(2 T2) | Dask / ceiling |")
    print("|---|---|---|---|")
    for row in rows:
        if row["workers"] == 2:
            print(
                f"| {row['study']} | {row['ceiling']:.2f} | {row['efficiency']:.2f} | "
                f"{row['efficiency_vs_ceiling']:.2f} |"
            )
    print(
        "\nCPU accounting per sweep (psutil, user + system, medians): the chunks' in-task CPU, and per chunk "
        "the CPU of the client process (client, scheduler, nannies), of the workers outside their tasks "
        "(event loop, heartbeats, transfers) and of the other cluster's idle workers; CPU efficiency = "
        "in-task CPU / all of it. The in-task CPU per chunk on 2 workers over that on 1 is the slow-down of "
        "the study's own work when two processes share the machine (caches, memory bandwidth).\n"
    )
    print(
        "| study | workers | CPU efficiency | in-task CPU / chunk (s) | 2-worker / 1-worker in-task CPU | "
        "client process (ms / chunk) | workers outside tasks (ms / chunk) | other processes (ms / chunk) |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for row in rows:
        base = next(r for r in rows if r["study"] == row["study"] and r["workers"] == 1)
        print(
            f"| {row['study']} | {row['workers']} | {row['cpu_efficiency']:.3f} | "
            f"{row['task_cpu_per_chunk_s']:.3f} | "
            f"{row['task_cpu_per_chunk_s'] / base['task_cpu_per_chunk_s']:.3f} | "
            f"{1e3 * row['client_cpu_per_chunk_s']:.1f} | "
            f"{1e3 * row['worker_cpu_outside_tasks_per_chunk_s']:.1f} | "
            f"{1e3 * row['other_cpu_per_chunk_s']:.1f} |"
        )
    if "spherical-leg-synthesis" in names:
        st = get_study("spherical-leg-synthesis")
        n = args.chunks * st.default_chunk
        steady1 = n / _median(res[1][st.name], "window_s")  # designs/s of one worker, steady state
        eff2 = _median(res[1][st.name], "window_s") / (2 * _median(res[2][st.name], "window_s"))
        hours = SYNTHESIS_DESIGNS / steady1 / 3600
        print(
            f"\n10^6-design spherical-leg synthesis, from the 1-worker steady throughput ({steady1:.0f} "
            f"designs/s = {steady1 * st.poses_per_design:.3g} poses/s): {hours:.2f} h on 1 worker, "
            f"{hours / (2 * eff2):.2f} h on 2 (measured steady efficiency {eff2:.2f}), "
            f"{60 * hours / 16:.1f} min on 16 and {60 * hours / 64:.1f} min on 64 (ideal scaling)"
        )
    print(f"\nbenchmark wall time {time.perf_counter() - t_start:.0f} s")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2))
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    raise SystemExit(main())
