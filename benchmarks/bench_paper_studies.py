"""robomech.explore: the paper studies' chunks, design-batched kernels against an earlier revision.

``python benchmarks/bench_paper_studies.py [--before REV]`` (standalone; ~2 min on a loaded machine)
evaluates one default-size chunk of each built-in paper study (its default sampler, chunk 0's designs)
in-process on one core as a sweep's worker runs it (``WORKER_ENV``: one BLAS/OpenMP/numba thread;
``WORKER_MALLOC``: glibc's malloc as Dask's nanny sets it) and reports designs/s and design-poses/s
(designs x ``poses_per_design`` / s) from the wall time, and designs per CPU-second
(``time.process_time``, less sensitive to the machine's other load), best of ``--repeats``.  Each
measurement runs in a fresh process; with ``--before REV`` the same measurement also runs on
``git archive REV src`` (e.g. the revision before the paper studies' kernels took per-design arrays:
one mechanism call per design), the two trees alternating so that both see the same load, and the
table gives the speed-ups.

``make bench`` times one chunk of each study through ``bench_explore.workloads()``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
STUDIES = ("spherical-leg-synthesis", "omnileg-synthesis", "vectored-thrust-tolerance")
REPEATS = 3
# glibc's malloc as Dask's nanny starts a worker (distributed's default ``pre-spawn-environ``): above
# this trim threshold glibc no longer adapts its mmap threshold, so every temporary above 128 kB is
# mapped and unmapped (page faults on each use): the setting the chunks of a sweep run under.
WORKER_MALLOC = {"MALLOC_TRIM_THRESHOLD_": "65536"}
# Rounds of (before, after) measurements, alternating; the median of the rounds' best times is reported.
ROUNDS = 3


def _chunk(name: str):
    from robomech.explore import design_matrix, get_study

    st = get_study(name)
    return st, design_matrix(st.variables, st.default_chunk, st.default_sampler, 0, st.default_chunk)


def workloads() -> list:
    """None for ``run.py``: its in-process chunk of each study is ``bench_explore.workloads()``."""
    return []


def _measure(name: str, repeats: int) -> dict:
    """Best wall and CPU time of one default chunk of ``name`` in this process (after a warm-up chunk)."""
    from bench_explore import _one_chunk as _evaluate

    st, X = _chunk(name)
    _evaluate(st, X[:4])
    best, cpu = float("inf"), float("inf")
    for _ in range(repeats):
        c0, t0 = time.process_time(), time.perf_counter()
        _evaluate(st, X)
        best, cpu = min(best, time.perf_counter() - t0), min(cpu, time.process_time() - c0)
    return {
        "designs": int(X.shape[0]),
        "poses_per_design": int(st.poses_per_design),
        "seconds": best,
        "cpu": cpu,
    }


def _in_fresh_process(src: Path, name: str, repeats: int) -> dict:
    from robomech.explore._runner import WORKER_ENV

    env = {**os.environ, **WORKER_ENV, **WORKER_MALLOC, "PYTHONPATH": str(src)}
    code = (
        f"import sys, json; sys.path.insert(0, {str(ROOT / 'benchmarks')!r}); "
        "import bench_paper_studies as b; "
        f"print(json.dumps(b._measure({name!r}, {repeats})))"
    )
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True, env=env)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _archive(rev: str, into: Path) -> Path:
    """``git archive REV src`` unpacked under ``into``; returns its ``src``."""
    tar = into / "src.tar"
    subprocess.run(["git", "-C", str(ROOT), "archive", "-o", str(tar), rev, "src"], check=True)
    with tarfile.open(tar) as t:
        t.extractall(into, filter="data")
    return into / "src"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--before", default=None, help="a git revision to compare with (its src/ tree)")
    p.add_argument("--only", default=None, help="only the studies whose name contains this")
    p.add_argument("--repeats", type=int, default=REPEATS, help=f"chunks per measurement (default {REPEATS})")
    p.add_argument("--rounds", type=int, default=ROUNDS, help=f"alternating rounds (default {ROUNDS})")
    p.add_argument("--json", default=None, help="also write the rows as JSON to this file")
    a = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        trees = {"after": ROOT / "src"}
        if a.before:
            trees = {"before": _archive(a.before, Path(tmp)), **trees}
        rows = []
        for name in (s for s in STUDIES if a.only is None or a.only in s):
            runs: dict[str, list[dict]] = {k: [] for k in trees}
            for _ in range(a.rounds):
                for k, src in trees.items():
                    runs[k].append(_in_fresh_process(src, name, a.repeats))
            row = {"study": name, "load_1min": os.getloadavg()[0]}
            for k, rs in runs.items():
                r = rs[0]
                t = statistics.median(x["seconds"] for x in rs)
                c = statistics.median(x["cpu"] for x in rs)
                row[k] = {
                    "designs": r["designs"],
                    "seconds": t,
                    "cpu_seconds": c,
                    "designs_per_s": r["designs"] / t,
                    "designs_per_cpu_s": r["designs"] / c,
                    "poses_per_s": r["designs"] * r["poses_per_design"] / t,
                    "all_seconds": [x["seconds"] for x in rs],
                    "all_cpu_seconds": [x["cpu"] for x in rs],
                }
            if "before" in row:
                row["speedup"] = row["before"]["seconds"] / row["after"]["seconds"]
                row["cpu_speedup"] = row["before"]["cpu_seconds"] / row["after"]["cpu_seconds"]
            rows.append(row)
            print(_line(row), flush=True)
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1))


def _line(row: dict) -> str:
    parts = [f"{row['study']:28s} ({row['after']['designs']} designs, load {row['load_1min']:.1f})"]
    for k in ("before", "after"):
        if k in row:
            r = row[k]
            parts.append(
                f"{k}: {r['designs_per_s']:7.1f} designs/s {r['poses_per_s']:9.3g} poses/s "
                f"{r['designs_per_cpu_s']:7.1f} designs/CPU-s"
            )
    if "speedup" in row:
        parts.append(f"x{row['speedup']:.2f} (CPU x{row['cpu_speedup']:.2f})")
    return " | ".join(parts)


if __name__ == "__main__":
    main()
