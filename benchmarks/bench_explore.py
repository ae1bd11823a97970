"""robomech.explore: throughput of the built-in design studies, Dask scaling and per-chunk overhead.

``workloads()`` (for ``run.py``): one default-size chunk of each study evaluated in-process (pose
evaluations per second on one core, no Dask).

``python benchmarks/bench_explore.py`` (standalone, ~1-2 min on 2 cores): for each study, the same sweep
on a LocalCluster of 1 and of 2 worker processes (cluster start-up excluded): pose evaluations per second
and the scaling efficiency ``rate(2) / (2 rate(1))``; the Dask overhead per chunk at the default chunk
size, ``(wall time x workers - sum of worker chunk times) / chunks`` against the mean chunk work; and the
extrapolated time of a 10^6-design spherical-leg synthesis per worker.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from robomech.explore import design_matrix, get_study, open_results, run_sweep
from robomech.explore._sampling import chunk_seed

from _harness import Workload

STUDIES = ("spherical-leg-synthesis", "vectored-thrust-tolerance", "omnileg-synthesis")
# Chunks per worker in the scaling runs: enough for the load to balance, small enough to stay quick.
CHUNKS_PER_WORKER = 4
SYNTHESIS_DESIGNS = 1_000_000


def workloads() -> list[Workload]:
    out = []
    for name in STUDIES:
        st = get_study(name)
        X = design_matrix(st.variables, st.default_chunk, st.default_sampler, 0, st.default_chunk)
        out.append(
            Workload(
                name=f"explore: {name}, one chunk ({st.default_chunk} designs)",
                group="x",
                run=lambda st=st, X=X: st.evaluate_rows(X, chunk_seed(0, 0)),
                n=st.default_chunk * st.poses_per_design,
                bytes_moved=0,
                repeats=2,
            )
        )
    return out


def _sweep(name: str, workers: int, chunks: int) -> dict:
    from distributed import Client, LocalCluster

    st = get_study(name)
    n = chunks * st.default_chunk
    with (
        LocalCluster(
            n_workers=workers, threads_per_worker=1, host="127.0.0.1", dashboard_address="127.0.0.1:0",
            silence_logs=40,
        ) as cluster,
        Client(cluster) as client,
        tempfile.TemporaryDirectory() as d,
    ):  # fmt: skip
        client.run(lambda: __import__("robomech.explore"))  # imports on the workers: not part of the sweep
        # warm-up chunk (first-call costs on each worker), then the timed sweep
        run_sweep(st, Path(d) / "warm", designs=st.default_chunk * workers, client=client, progress=False)
        t0 = time.perf_counter()
        s = run_sweep(st, Path(d) / "s", designs=n, client=client, progress=False)
        wall = time.perf_counter() - t0
        stored = open_results(Path(d) / "s")
        work = float(np.sum(stored["chunk_seconds"]))
        cpu = float(np.sum(stored["chunk_cpu_seconds"]))
    return {
        "study": name,
        "workers": workers,
        "designs": n,
        "chunks": s.n_chunks,
        "chunk_size": st.default_chunk,
        "wall_s": wall,
        "work_s": work,
        "poses_per_s": n * st.poses_per_design / wall,
        "designs_per_s": n / wall,
        "overhead_per_chunk_s": (wall * workers - work) / s.n_chunks,
        "work_per_chunk_s": work / s.n_chunks,
        "utilisation": work / (wall * workers),  # fraction of worker time spent in chunk work
        "cpu_per_design_s": cpu / n,  # CPU time of the study's own computation per design
        "cpu_share": cpu / work,  # CPU time / wall time of the chunks: < 1 when the cores are contended
    }


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--json", default=None)
    p.add_argument("--only", default=None)
    args = p.parse_args()
    rows = []
    print(
        f"{'study':<28} {'workers':>7} {'designs':>7} {'wall s':>7} {'poses/s':>10} {'efficiency':>10} "
        f"{'chunk work s':>12} {'overhead/chunk s':>16} {'overhead %':>10} {'utilisation':>11} "
        f"{'cpu share':>9} {'cpu µs/pose':>11} {'free-core eff.':>14}"
    )
    for name in STUDIES:
        if args.only and args.only not in name:
            continue
        one = _sweep(name, 1, CHUNKS_PER_WORKER)
        two = _sweep(name, 2, 2 * CHUNKS_PER_WORKER)
        for r in (one, two):
            r["efficiency"] = r["poses_per_s"] / (r["workers"] * one["poses_per_s"])
            # free-core estimate: the same CPU per design and the measured Dask utilisation
            r["cpu_efficiency"] = (
                one["cpu_per_design_s"] / r["cpu_per_design_s"] * r["utilisation"] / one["utilisation"]
            )
            pct = 100 * r["overhead_per_chunk_s"] / r["work_per_chunk_s"]
            print(
                f"{name:<28} {r['workers']:>7} {r['designs']:>7} {r['wall_s']:>7.2f} "
                f"{r['poses_per_s']:>10.3g} {r['efficiency']:>10.2f} {r['work_per_chunk_s']:>12.3f} "
                f"{r['overhead_per_chunk_s']:>16.4f} "
                f"{pct:>10.1f} {r['utilisation']:>11.2f} {r['cpu_share']:>9.2f} "
                f"{r['cpu_per_design_s'] / get_study(name).poses_per_design * 1e6:>11.3f} "
                f"{r['cpu_efficiency']:>14.2f}",
                flush=True,
            )
            rows.append(r)
        if name == "spherical-leg-synthesis":
            per_worker = SYNTHESIS_DESIGNS / one["designs_per_s"]
            two_h = per_worker / 3600 / (2 * two["efficiency"])
            print(
                f"  10^6-design spherical-leg synthesis: {per_worker / 3600:.2f} h on 1 worker, "
                f"{two_h:.2f} h on 2 workers (measured efficiency), {per_worker / 3600 / 64:.3f} h on 64 "
                "(ideal scaling)",
                flush=True,
            )
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2))
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    raise SystemExit(main())
