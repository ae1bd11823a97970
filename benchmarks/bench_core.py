"""Core workloads: batched least squares (issue 9 workload 1) and the import time of robomech."""

from __future__ import annotations

import subprocess
import sys

import numpy as np

from robomech.analysis import lstsq

from _harness import Workload, fresh_process_seconds

N_SYSTEMS = 250_000  # paper 4's "computationally heavy" count
M, N = 30, 11  # paper 4's overdetermined system
N_ALT = 5_000


def _systems(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return rng.normal(size=(n, M, N)), rng.normal(size=(n, M))


def _numpy_batched_qr(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The obvious vectorised alternative: numpy's stacked QR (one LAPACK call per matrix)."""
    Q, R = np.linalg.qr(A, mode="reduced")
    return np.linalg.solve(R, np.einsum("...mi,...m->...i", Q, b)[..., None])[..., 0]


def _compile_seconds() -> float:
    """First-call time in a fresh process with an empty numba cache: the kernel's compile cost."""
    return fresh_process_seconds(
        "import time, numpy as np; t=time.perf_counter(); from robomech.analysis import lstsq; "
        "lstsq.solve(np.ones((1, 3, 2)) + np.eye(3, 2), np.ones((1, 3))); print(time.perf_counter() - t)"
    )


def workloads() -> list[Workload]:
    A, b = _systems(N_SYSTEMS)
    A_alt, b_alt = A[:N_ALT], b[:N_ALT]
    io_bytes = A.nbytes + b.nbytes + N_SYSTEMS * N * 8

    def loop_numpy() -> None:
        for a, y in zip(A_alt, b_alt, strict=True):
            np.linalg.lstsq(a, y, rcond=None)

    def import_time() -> None:
        subprocess.run([sys.executable, "-c", "import robomech"], check=True)

    def python_startup() -> None:
        subprocess.run([sys.executable, "-c", "pass"], check=True)

    print(f"lstsq kernel: compile on first use {_compile_seconds():.1f} s (then cached on disk)")
    return [
        Workload(
            name="lstsq.solve 30x11 (Householder, cond_1 of R)",
            group="1",
            run=lambda: lstsq.solve(A, b),
            n=N_SYSTEMS,
            bytes_moved=io_bytes,
            alternative=loop_numpy,
            n_alt=N_ALT,
            alternative_name="loop numpy.linalg.lstsq",
            target_speedup=20,
        ),
        Workload(
            name="lstsq.solve 30x11 (exact_cond: + SVD of R)",
            group="1",
            run=lambda: lstsq.solve(A, b, exact_cond=True),
            n=N_SYSTEMS,
            bytes_moved=io_bytes,
            alternative=loop_numpy,
            n_alt=N_ALT,
            alternative_name="loop numpy.linalg.lstsq",
        ),
        Workload(
            name="numpy batched qr + solve (LAPACK per matrix)",
            group="1",
            run=lambda: _numpy_batched_qr(A, b),
            n=N_SYSTEMS,
            bytes_moved=io_bytes,
            alternative=loop_numpy,
            n_alt=N_ALT,
            alternative_name="loop numpy.linalg.lstsq",
        ),
        Workload(
            name="lstsq.solve_normal_equations 30x11",
            group="1",
            run=lambda: lstsq.solve_normal_equations(A, b),
            n=N_SYSTEMS,
            bytes_moved=io_bytes,
            alternative=loop_numpy,
            n_alt=N_ALT,
            alternative_name="loop numpy.linalg.lstsq",
        ),
        Workload(
            name="import robomech (subprocess, incl. python start)",
            group="-",
            run=import_time,
            n=1,
            bytes_moved=0,
            alternative=python_startup,
            n_alt=1,
            alternative_name="bare python start",
        ),
    ]
