"""Benchmark harness: a workload is timed beside its obvious alternative and the machine's floors.

Each ``benchmarks/bench_*.py`` module defines ``workloads() -> list[Workload]``.  ``run.py`` measures the
machine's floors (memory bandwidth from a large array copy; float64 matmul rate) in the same run, then
times every workload (best of several repeats) and its alternative (a per-sample Python loop, a peer
library), and prints one table.  Alternatives are timed on a subset (``n_alt`` samples) and scaled:
they are per-sample loops, linear in the sample count.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = ["Floors", "Workload", "best_time", "fresh_process_seconds", "measure_floors"]


@dataclass(frozen=True)
class Workload:
    name: str  # e.g. "spherical_leg: inverse kinematics"
    group: str  # issue 9 workload number ("1" .. "5")
    run: Callable[[], object]  # the batched call over n samples
    n: int
    bytes_moved: int  # bytes of inputs + outputs of the batched call (memory-traffic floor)
    alternative: Callable[[], object] | None = None  # the obvious alternative over n_alt samples
    n_alt: int = 0
    alternative_name: str = ""
    target_speedup: float | None = None  # issue 9 target ratio vs the alternative
    target_floor_ratio: float | None = None  # issue 9 target: time within this factor of the floor
    flops: float | None = None  # floating-point operations of the batched call, if known
    repeats: int = 3


@dataclass(frozen=True)
class Floors:
    bandwidth: float  # bytes/s for read+write of a large copy
    matmul_flops: float  # float64 FLOP/s of a large matmul


def best_time(fn: Callable[[], object], repeats: int = 3) -> float:
    fn()  # warm-up (allocations, caches, lazy imports)
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def measure_floors() -> Floors:
    a = np.ones(2**26)  # 512 MiB
    b = np.empty_like(a)
    t = best_time(lambda: np.copyto(b, a), repeats=5)
    bandwidth = 2 * a.nbytes / t  # read + write
    n = 2048
    x = np.random.default_rng(0).normal(size=(n, n))
    tm = best_time(lambda: x @ x, repeats=3)
    return Floors(bandwidth=bandwidth, matmul_flops=2 * n**3 / tm)


def fresh_process_seconds(code: str) -> float:
    """Run ``code`` in a fresh Python process with an empty numba cache and return the float it prints.

    Used to measure a compiled kernel's one-off compile cost (the cache is then on disk for users).
    """
    with tempfile.TemporaryDirectory() as d:
        env = {**os.environ, "NUMBA_CACHE_DIR": d}
        out = subprocess.run(
            [sys.executable, "-c", code], check=True, capture_output=True, text=True, env=env
        )
    return float(out.stdout.strip())
