"""Throughput of model studies (explore.model_study): designs x poses per second, one process.

A user's planar five-bar on a 32 x 32 task grid (workspace area, dexterity, type II distance) and a
user's Delta along a 21-sample pick-and-place path (peak and RMS actuator torque), each design one
``build`` call and one batched engine call per metric family (IK with neighbour retries, Jacobians,
singularities; or IK along the path and inverse dynamics).  Warm (numba compiled) timings.

    PYTHONPATH=src python benchmarks/bench_model_study.py [--designs N] [--workers K]

``--workers K``: the same studies through ``run_sweep`` on a K-worker loopback LocalCluster (chunks of
4 designs, a warm-up sweep first so that every worker has compiled the kernels).
"""

import argparse
import sys
import tempfile
import time
from pathlib import Path

from robomech.explore import Variable, design_matrix, load_model, model_study

MODELS = Path(__file__).resolve().parents[1] / "examples" / "models"


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

    dl = model_study(
        load_model(f"{MODELS / 'delta.py'}:build"),
        [
            Variable("arm", 0.2, 0.3, "m"),
            Variable("forearm", 0.5, 0.7, "m"),
            Variable("R", 0.15, 0.25, "m"),
            Variable("r", 0.04, 0.06, "m"),
        ],
        site="tcp",
        outputs="xyz",
        metrics=("peak_force", "rms_force"),
        trajectory=delta.pick_and_place(),
    )
    return {"five-bar 32x32": fb, "delta pick-and-place": dl}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--designs", type=int, default=8)
    ap.add_argument("--workers", type=int, default=0)
    args = ap.parse_args()
    n = args.designs
    if args.workers:
        from distributed import Client

        from robomech.explore import local_cluster, run_sweep

        with local_cluster(args.workers) as cl, Client(cl) as c:
            for name, st in studies().items():
                with tempfile.TemporaryDirectory() as d:
                    run_sweep(
                        st, d + "/warm", designs=2 * args.workers, chunk_size=1, client=c, progress=False
                    )
                    r = run_sweep(st, d + "/s", designs=n, chunk_size=4, client=c, progress=False)
                poses = st.poses_per_design
                print(
                    f"{name}: {args.workers} workers, {n} designs x {poses} poses in {r.seconds:.2f} s -> "
                    f"{n / r.seconds:.2f} designs/s, {n * poses / r.seconds:.0f} design-poses/s"
                )
        return
    for name, st in studies().items():
        X = design_matrix(st.variables, n, "sobol", 0, n)
        st.evaluate_rows(X[:1], None)  # compile
        t0 = time.perf_counter()
        res = st.evaluate_rows(X, None)
        dt = time.perf_counter() - t0
        poses = st.poses_per_design
        print(
            f"{name}: {n} designs x {poses} poses in {dt:.2f} s -> {n / dt:.2f} designs/s, "
            f"{n * poses / dt:.0f} design-poses/s; ok {int(res['design_ok'].sum())}/{n}"
        )


if __name__ == "__main__":
    main()
