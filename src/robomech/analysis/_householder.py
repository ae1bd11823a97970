"""Compiled batched Householder least squares (numba), for stacks of small systems.

LAPACK's per-call overhead dominates 30x11 systems: a loop of ``numpy.linalg.lstsq`` and numpy's
batched ``qr`` (one LAPACK call per matrix) both cost tens of microseconds per system, while the
arithmetic is ~10k flops.  This kernel runs the unblocked Householder algorithm of LAPACK's ``dgeqr2``
on the augmented matrix ``[A | b]``, so the ``n + 1``-th column becomes ``Q^T b`` and its part below
row n has the residual norm.  Systems are processed in blocks of :data:`BLOCK` with the system index
innermost (``W[column, row, system]``): every loop of the algorithm then runs over contiguous systems
and vectorises (SIMD), and blocks run in parallel.  The arithmetic of each system is exactly that of
the one-system algorithm.  ``benchmarks/bench_core.py`` keeps the evidence (docs/performance.md).
Compilation is cached on disk (``cache=True``, in ``robomech._numba.cache_dir()``, not in the
installed package); numba is imported on first use only, never at
``import robomech``.
"""

from __future__ import annotations

import functools

import numpy as np

__all__ = ["BLOCK", "householder_lstsq"]

# Systems per block: a multiple of the SIMD width (4-8 doubles) whose work array (n+1) * m * BLOCK
# doubles stays in L1/L2 for paper 4's 30x11 systems (12 * 30 * 16 * 8 B = 46 KB); 8 and 32 measured
# slower on this machine (benchmarks/bench_core.py).
BLOCK = 16

# Blocks per parallel work item: the work buffers are allocated once per item (allocation per block of
# 16 systems cost ~0.5 us per system).
CHUNK_BLOCKS = 32

# Reassociation and FMA contraction let LLVM vectorise (LAPACK's BLAS reorders sums too; Householder
# QR stays backward stable). No 'nnan'/'ninf': the kernel relies on exact zero tests.
_FASTMATH = {"reassoc", "contract", "nsz"}


@functools.cache
def _kernel():
    from robomech._numba import import_numba

    numba = import_numba()  # deferred: ~0.3 s import, paid only by users of the batched solver

    @numba.njit(parallel=True, cache=True, fastmath=_FASTMATH)
    def kernel(A, b, x, resid, cond1, ok, R_out, want_R):  # pragma: no cover - compiled
        batch, m, n = A.shape
        nblocks = (batch + BLOCK - 1) // BLOCK
        nchunks = (nblocks + CHUNK_BLOCKS - 1) // CHUNK_BLOCKS
        for chunk in numba.prange(nchunks):
            # work buffers, allocated once per chunk of blocks and reused
            W = np.empty((n + 1, m, BLOCK))
            v = np.empty((m, BLOCK))
            norm2 = np.empty(BLOCK)
            scale = np.empty(BLOCK)
            dot = np.empty(BLOCK)
            r2 = np.empty(BLOCK)
            inv_piv = np.empty((n, BLOCK))
            singular = np.empty(BLOCK, dtype=np.bool_)
            X = np.empty((n, BLOCK))
            rnorm = np.empty(BLOCK)
            inv_norm = np.empty(BLOCK)
            Y = np.empty((n, BLOCK))
            for blk in range(chunk * CHUNK_BLOCKS, min(nblocks, (chunk + 1) * CHUNK_BLOCKS)):
                s0 = blk * BLOCK
                cnt = min(BLOCK, batch - s0)
                # Load [A | b] with the system index innermost (contiguous writes into W).
                for i in range(m):
                    for j in range(n):
                        for s in range(cnt):
                            W[j, i, s] = A[s0 + s, i, j]
                    for s in range(cnt):
                        W[n, i, s] = b[s0 + s, i]
                # A system is finite iff 0 * (every entry) sums to 0 (NaN and inf give NaN).
                for s in range(BLOCK):
                    norm2[s] = 0.0
                for j in range(n + 1):
                    for i in range(m):
                        for s in range(cnt):
                            norm2[s] += W[j, i, s] * 0.0
                for s in range(BLOCK):
                    good = s < cnt and norm2[s] == 0.0
                    if s < cnt:
                        ok[s0 + s] = good
                    if not good:  # padding or a non-finite system: a harmless identity system, discarded
                        for j in range(n + 1):
                            for i in range(m):
                                W[j, i, s] = 1.0 if i == j else 0.0
                for k in range(n):
                    # Householder vector of column k below the diagonal (dgeqr2/dlarfg; the sign of alpha
                    # is opposite to the pivot's to avoid cancellation).
                    for s in range(BLOCK):
                        norm2[s] = 0.0
                    for i in range(k, m):
                        for s in range(BLOCK):
                            norm2[s] += W[k, i, s] * W[k, i, s]
                    for s in range(BLOCK):
                        alpha = -np.copysign(np.sqrt(norm2[s]), W[k, k, s])
                        vnorm2 = norm2[s] - 2.0 * alpha * W[k, k, s] + alpha * alpha  # |x - alpha e1|^2
                        scale[s] = 2.0 / vnorm2 if vnorm2 > 0.0 else 0.0  # zero column: no reflection
                        v[k, s] = W[k, k, s] - alpha
                        W[k, k, s] = alpha
                    for i in range(k + 1, m):
                        for s in range(BLOCK):
                            v[i, s] = W[k, i, s]
                            W[k, i, s] = 0.0
                    for j in range(k + 1, n + 1):
                        for s in range(BLOCK):
                            dot[s] = 0.0
                        for i in range(k, m):
                            for s in range(BLOCK):
                                dot[s] += v[i, s] * W[j, i, s]
                        for s in range(BLOCK):
                            dot[s] *= scale[s]
                        for i in range(k, m):
                            for s in range(BLOCK):
                                W[j, i, s] -= dot[s] * v[i, s]
                # Residual norm: the part of Q^T b below row n.  Then x = R^-1 (Q^T b)[:n] and the exact
                # 1-norm condition number ||R||_1 ||R^-1||_1 (inf for an exact zero pivot); all across the
                # block.  R[i, j] is W[j, i, :].
                r2[:] = 0.0
                for i in range(n, m):
                    for s in range(BLOCK):
                        r2[s] += W[n, i, s] * W[n, i, s]
                singular[:] = False
                for i in range(n):
                    for s in range(BLOCK):
                        piv = W[i, i, s]
                        singular[s] |= piv == 0.0
                        inv_piv[i, s] = 1.0 / piv if piv != 0.0 else 0.0
                X[:] = 0.0
                for i in range(n - 1, -1, -1):
                    for s in range(BLOCK):
                        dot[s] = W[n, i, s]
                    for j in range(i + 1, n):
                        for s in range(BLOCK):
                            dot[s] -= W[j, i, s] * X[j, s]
                    for s in range(BLOCK):
                        X[i, s] = dot[s] * inv_piv[i, s]
                rnorm[:] = 0.0
                for j in range(n):
                    for s in range(BLOCK):
                        dot[s] = 0.0
                    for i in range(j + 1):
                        for s in range(BLOCK):
                            dot[s] += abs(W[j, i, s])
                    for s in range(BLOCK):
                        rnorm[s] = max(rnorm[s], dot[s])
                inv_norm[:] = 0.0
                Y[:] = 0.0
                for col in range(n):  # column `col` of R^-1 is zero below row `col`
                    for s in range(BLOCK):
                        Y[col, s] = inv_piv[col, s]
                        dot[s] = abs(Y[col, s])
                    for i in range(col - 1, -1, -1):
                        for s in range(BLOCK):
                            scale[s] = 0.0
                        for j in range(i + 1, col + 1):
                            for s in range(BLOCK):
                                scale[s] -= W[j, i, s] * Y[j, s]
                        for s in range(BLOCK):
                            Y[i, s] = scale[s] * inv_piv[i, s]
                            dot[s] += abs(Y[i, s])
                    for s in range(BLOCK):
                        inv_norm[s] = max(inv_norm[s], dot[s])
                for s in range(cnt):
                    resid[s0 + s] = np.sqrt(r2[s])
                    cond1[s0 + s] = np.inf if singular[s] else rnorm[s] * inv_norm[s]
                    for i in range(n):
                        x[s0 + s, i] = X[i, s]
                    if want_R:
                        for i in range(n):
                            for j in range(n):
                                R_out[s0 + s, i, j] = W[j, i, s]

    return kernel


def householder_lstsq(
    A: np.ndarray, b: np.ndarray, want_R: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """Solve each system of ``A (B, m, n)``, ``b (B, m)`` by Householder QR.

    Returns ``x (B, n)``, ``residual (B,)``, ``cond1 (B,)`` (1-norm condition number of R, inf when R
    has an exact zero pivot), ``ok (B,)`` (false for a system with a non-finite entry: its results are
    those of an identity system, for the caller to mask) and ``R (B, n, n)`` when requested.
    """
    batch, _, n = A.shape
    x = np.zeros((batch, n))
    resid = np.zeros(batch)
    cond1 = np.zeros(batch)
    ok = np.zeros(batch, dtype=bool)
    R = np.zeros((batch, n, n)) if want_R else np.zeros((1, 1, 1))
    _kernel()(np.ascontiguousarray(A), np.ascontiguousarray(b), x, resid, cond1, ok, R, want_R)
    return x, resid, cond1, ok, (R if want_R else None)
