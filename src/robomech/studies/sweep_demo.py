"""Design exploration demo: two small sweeps of robomech.explore on a local Dask cluster (seconds).

The full-size runs are ``robomech sweep STUDY --out DIR [--scheduler tcp://HOST:PORT]`` (docs/explore.md).
"""

from __future__ import annotations

from pathlib import Path

from robomech.explore import get_study, local_cluster, run_sweep

from ._core import Figure, Progress, Study, StudyResult, Table
from ._sweep import sweep_result

# Small enough for `make run` (seconds on 2 cores), large enough for a visible front and histogram.
DEMO = (("spherical-leg-synthesis", 128, 32), ("vectored-thrust-tolerance", 512, 128))
# Worker processes of the demo's LocalCluster (one per core of the reference machine).
DEMO_WORKERS = 2


def run(out_dir: Path, progress: Progress) -> StudyResult:
    from distributed import Client

    res = StudyResult(
        name="sweep-demo",
        title="Design exploration: dimensional synthesis and tolerances on a local Dask cluster",
        source="robomech.explore (docs/explore.md); papers 1 and 5",
        summary=(
            "Two small sweeps run as Dask tasks on a LocalCluster and stored as Zarr groups in this "
            "folder (rerunning resumes them). The same command runs on a cluster with "
            "`robomech sweep STUDY --out DIR --scheduler tcp://HOST:PORT`."
        ),
    )
    summaries = {}
    progress.plan(["LocalCluster", *(f"{name}: {what}" for name, *_ in DEMO for what in ("sweep", "chunks"))])
    progress.step(f"LocalCluster of {DEMO_WORKERS} worker processes on 127.0.0.1")
    with (
        local_cluster(DEMO_WORKERS) as cluster,  # the sweeps' own settings (explore.local_cluster)
        Client(cluster) as client,
    ):
        for name, n, chunk in DEMO:
            progress.step(f"sweep {name}: {n} designs")
            s = run_sweep(
                get_study(name), out_dir / f"{name}.zarr", designs=n, chunk_size=chunk, client=client,
                progress=False,
            )  # fmt: skip
            progress.step(
                f"{len(s.computed_chunks)} chunks computed, {s.skipped_chunks} stored, {s.seconds:.1f} s"
            )
            summaries[name] = s
    for name, s in summaries.items():
        part = sweep_result(out_dir / f"{name}.zarr", out_dir, name, prefix=f"{name}_")
        res.tables += [Table(f"{name}: {t.title}", t.columns, t.rows, t.note) for t in part.tables]
        res.figures += [Figure(f.path, f"{name}: {f.caption}") for f in part.figures]
        res.data[name] = {**part.data, "seconds": s.seconds, "computed_chunks": len(s.computed_chunks)}
    return res


STUDY = Study(
    name="sweep-demo",
    title="Design exploration: small sweeps on a local Dask cluster",
    source="robomech.explore",
    run=run,
    requires=("distributed", "zarr"),  # the explore extra; skipped without robomech[explore]
)
