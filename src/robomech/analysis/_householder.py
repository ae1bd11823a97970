"""Compiled batched Householder least squares (numba), for stacks of small systems.

LAPACK's per-call overhead dominates 30x11 systems: a loop of ``numpy.linalg.lstsq`` and numpy's
batched ``qr`` (one LAPACK call per matrix) both cost tens of microseconds per system, while the
arithmetic is ~8k flops.  This kernel runs the same unblocked Householder algorithm as LAPACK's
``dgeqr2`` on the augmented matrix ``[A | b]``, one system per iteration of a parallel loop, so the
``n + 1``-th column becomes ``Q^T b`` and its last entry the residual norm.  ``benchmarks/bench_core.py``
keeps the evidence (docs/performance.md).  Compilation is cached on disk (``cache=True``); numba is
imported on first use only, never at ``import robomech``.
"""

from __future__ import annotations

import functools

import numpy as np

__all__ = ["householder_lstsq"]

_FASTMATH = {"reassoc", "contract", "nsz"}


@functools.cache
def _kernel():
    import numba  # deferred: ~0.3 s import, paid only by users of the batched solver

    # Reassociation and FMA contraction let LLVM vectorise the dot products (LAPACK's BLAS reorders
    # them too; Householder QR stays backward stable). No 'nnan'/'ninf': the kernel tests for zeros.
    @numba.njit(parallel=True, cache=True, fastmath=_FASTMATH)
    def kernel(A, b, skip, x, resid, cond1, R_out, want_R):  # pragma: no cover - compiled
        batch, m, n = A.shape
        for s in numba.prange(batch):
            if skip[s]:
                continue
            # W[j, i] holds column j of [A | b] (transposed so that every column is contiguous).
            W = np.empty((n + 1, m))
            for i in range(m):
                for j in range(n):
                    W[j, i] = A[s, i, j]
                W[n, i] = b[s, i]
            v = np.empty(m)
            for k in range(n):
                # Householder vector for column k below the diagonal (dgeqr2/dlarfg, sign chosen
                # to avoid cancellation).
                norm2 = 0.0
                for i in range(k, m):
                    norm2 += W[k, i] * W[k, i]
                alpha = np.sqrt(norm2)
                if alpha == 0.0:
                    continue
                if W[k, k] > 0.0:
                    alpha = -alpha
                for i in range(k, m):
                    v[i] = W[k, i]
                v[k] -= alpha
                vnorm2 = norm2 - 2.0 * alpha * W[k, k] + alpha * alpha  # |x - alpha e1|^2
                if vnorm2 == 0.0:
                    continue
                scale = 2.0 / vnorm2
                W[k, k] = alpha
                for i in range(k + 1, m):
                    W[k, i] = 0.0
                for j in range(k + 1, n + 1):
                    dot = 0.0
                    for i in range(k, m):
                        dot += v[i] * W[j, i]
                    dot *= scale
                    for i in range(k, m):
                        W[j, i] -= dot * v[i]
            # Residual norm: the part of Q^T b below row n.
            r2 = 0.0
            for i in range(n, m):
                r2 += W[n, i] * W[n, i]
            resid[s] = np.sqrt(r2)
            # Back substitution R x = (Q^T b)[:n]; R[i, j] is W[j, i].
            singular = False
            for i in range(n - 1, -1, -1):
                acc = W[n, i]
                for j in range(i + 1, n):
                    acc -= W[j, i] * x[s, j]
                if W[i, i] == 0.0:
                    singular = True
                    x[s, i] = 0.0
                else:
                    x[s, i] = acc / W[i, i]
            # Exact 1-norm condition of R: ||R||_1 ||R^-1||_1, R^-1 column by column.
            if singular:
                cond1[s] = np.inf
            else:
                rnorm = 0.0
                for j in range(n):
                    c = 0.0
                    for i in range(j + 1):
                        c += abs(W[j, i])
                    rnorm = max(rnorm, c)
                inv_norm = 0.0
                y = np.empty(n)
                dinv = np.empty(n)
                for i in range(n):
                    dinv[i] = 1.0 / W[i, i]
                for col in range(n):
                    # column `col` of R^-1 is zero below row `col`
                    c = 0.0
                    for i in range(col, -1, -1):
                        acc = 1.0 if i == col else 0.0
                        for j in range(i + 1, col + 1):
                            acc -= W[j, i] * y[j]
                        y[i] = acc * dinv[i]
                        c += abs(y[i])
                    inv_norm = max(inv_norm, c)
                cond1[s] = rnorm * inv_norm
            if want_R:
                for i in range(n):
                    for j in range(n):
                        R_out[s, i, j] = W[j, i]

    return kernel


def householder_lstsq(
    A: np.ndarray, b: np.ndarray, skip: np.ndarray, want_R: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """Solve each system of ``A (B, m, n)``, ``b (B, m)`` not marked in ``skip (B,)``.

    Returns ``x (B, n)``, ``residual (B,)``, ``cond1 (B,)`` (1-norm condition number of R, inf when R
    has an exact zero pivot) and ``R (B, n, n)`` when requested.
    """
    batch, _, n = A.shape
    x = np.zeros((batch, n))
    resid = np.zeros(batch)
    cond1 = np.zeros(batch)
    R = np.zeros((batch, n, n)) if want_R else np.zeros((1, 1, 1))
    _kernel()(np.ascontiguousarray(A), np.ascontiguousarray(b), skip, x, resid, cond1, R, want_R)
    return x, resid, cond1, (R if want_R else None)
