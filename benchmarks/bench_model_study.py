"""Throughput of model studies (explore.model_study): designs x poses per second, batched vs per design.

A user's planar five-bar on a 32 x 32 task grid (workspace area, dexterity, type II distance) and a
user's Delta along a 21-sample pick-and-place path (peak and RMS actuator torque).  A chunk of designs
is evaluated with the geometry batched in the kernels (every design's ``build`` call, then one
design-batched kernel call per step for all designs of the chunk: IK of every task point of every
design, the neighbour retries, the site Jacobians and singular values); the alternative is the same
evaluation one design at a time (chunks of one design: a kernel call per design and step).  Warm
(numba compiled) timings.

    PYTHONPATH=src python benchmarks/bench_model_study.py [--designs N] [--chunk C] [--workers K]

``--workers K``: the batched study through ``run_sweep`` on a K-worker loopback LocalCluster (chunks
of ``--chunk`` designs, a warm-up sweep first so that every worker has compiled the kernels), and the
time this rate gives for the issue's 10^5 five-bar designs and 10^4 Delta designs.
"""

import argparse
import functools
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from robomech.explore import Variable, design_matrix, load_model, model_study

from _harness import Workload

MODELS = Path(__file__).resolve().parents[1] / "examples" / "models"
# The targets: designs of each study, and the five-bar's wall-clock limit on two workers (s).
TARGET_DESIGNS = {"five-bar 32x32": 100_000, "delta pick-and-place": 10_000}
FIVE_BAR_TARGET_SECONDS = 600.0
# Designs per chunk of the batched evaluation (and of the harness workload).
CHUNK = 32


def studies():
    fb = model_study(
        load_model(f"{MODELS / 'five_bar.py'}:build"),
        [Variable("L1", 0.15, 0.25, "m"), Variable("L2", 0.15, 0.25, "m"), Variable("B", 0.05, 0.15, "m")],
        site="tip",
        metrics=("workspace_measure", "dexterity_min", "dexterity_mean", "type2_distance"),
        task_box=[[-0.5, 0.5], [-0.5, 0.5]],
        task_grid_size=32,
    )
    sys.path.insert(0, str(MODELS))
    import delta

    dl = delta.study()
    return {"five-bar 32x32": fb, "delta pick-and-place": dl}


def _batched(st, X: np.ndarray, chunk: int) -> dict:
    """``X`` in chunks of ``chunk`` designs, each chunk one batched evaluation."""
    res = [st.evaluate_rows(X[i : i + chunk], None) for i in range(0, len(X), chunk)]
    return {k: np.concatenate([r[k] for r in res]) for k in res[0]}


def _per_design(st, X: np.ndarray) -> dict:
    """The per-design loop: each design alone (a chunk of one design)."""
    return _batched(st, X, 1)


def workloads() -> list[Workload]:
    out = []
    for name, st in studies().items():
        X = design_matrix(st.variables, CHUNK, "sobol", 0, CHUNK)
        st.evaluate_rows(X[:2], None)  # compile
        out.append(
            Workload(
                name=f"model_study: {name}, {CHUNK} designs in one batched chunk",
                group="x",
                run=functools.partial(st.evaluate_rows, X, None),
                n=CHUNK * st.poses_per_design,
                bytes_moved=0,
                alternative=functools.partial(_per_design, st, X[:4]),
                n_alt=4 * st.poses_per_design,
                alternative_name="per-design loop (chunks of one design)",
                repeats=2,
            )
        )
    return out


def _rate(label: str, n: int, poses: int, dt: float) -> float:
    print(
        f"  {label}: {n} designs x {poses} poses in {dt:.2f} s -> {n / dt:.2f} designs/s, "
        f"{n * poses / dt:,.0f} design-poses/s"
    )
    return n / dt


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--designs", type=int, default=64)
    ap.add_argument("--chunk", type=int, default=CHUNK)
    ap.add_argument("--workers", type=int, default=0)
    ap.add_argument("--only", default=None)
    args = ap.parse_args()
    import os

    print(f"load average at start: {os.getloadavg()}")
    n = args.designs
    for name, st in studies().items():
        if args.only and args.only not in name:
            continue
        poses = st.poses_per_design
        X = design_matrix(st.variables, n, "sobol", 0, n)
        st.evaluate_rows(X[:2], None)  # compile
        print(f"{name}:")
        if args.workers:
            from distributed import Client

            from robomech.explore import local_cluster, run_sweep

            with local_cluster(args.workers) as cl, Client(cl) as c, tempfile.TemporaryDirectory() as d:
                run_sweep(st, d + "/warm", designs=2 * args.workers, chunk_size=1, client=c, progress=False)
                r = run_sweep(st, d + "/s", designs=n, chunk_size=args.chunk, client=c, progress=False)
            rate = _rate(f"{args.workers} workers, run_sweep, chunks of {args.chunk}", n, poses, r.seconds)
        else:
            t0 = time.perf_counter()
            res = _batched(st, X, args.chunk)
            rate = _rate(f"batched (chunks of {args.chunk})", n, poses, time.perf_counter() - t0)
            m = min(n, 8)
            t0 = time.perf_counter()
            one = _per_design(st, X[:m])
            rate1 = _rate("per-design loop (chunks of one)", m, poses, time.perf_counter() - t0)
            print(f"  batched / per-design: {rate / rate1:.2f}x; ok {int(res['design_ok'].sum())}/{n}")
            for k in one:
                a, b = np.asarray(res[k][:m], float), np.asarray(one[k], float)
                assert np.array_equal(np.isnan(a), np.isnan(b)) and np.allclose(
                    a, b, rtol=1e-12, atol=0, equal_nan=True
                ), k
        total = TARGET_DESIGNS[name]
        print(f"  -> {total:,} designs at this rate: {total / rate / 60:.1f} min")
    print(f"load average at end: {os.getloadavg()}")


if __name__ == "__main__":
    main()
