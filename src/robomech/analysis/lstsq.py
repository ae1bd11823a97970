"""Batched linear least squares by Householder QR (LAPACK), with per-system diagnostics.

``solve(A, b)`` handles stacks ``A (..., m, n)``, ``b (..., m)`` with ``m >= n``.  Every system is
solved independently; a rank-deficient or non-finite system is flagged in the result and never
aborts the batch.  ``solve_normal_equations`` is the textbook alternative kept for comparison: it
squares the condition number (``cond(A^T A) = cond(A)^2``), which is what paper 4 means by choosing
QR.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from robomech._validation import as_array

__all__ = ["RANK_RTOL_FACTOR", "LstsqResult", "solve", "solve_normal_equations"]

# A system is rank deficient when a singular value of R is below RANK_RTOL_FACTOR * max(m, n) * eps
# times the largest: max(m, n) * eps is numpy's matrix_rank default, the bound on the rounding that
# Householder QR leaves in R; the factor 10 keeps systems with condition up to ~1e14 full rank.
RANK_RTOL_FACTOR = 10.0


@dataclass(frozen=True)
class LstsqResult:
    """Per-system solution and diagnostics (batch shape ``...``).

    ``x (..., n)`` is NaN exactly where ``ok`` is false (non-finite input); for rank-deficient
    systems it is the minimum-norm solution and ``full_rank`` is false.
    """

    x: np.ndarray
    residual_norm: np.ndarray
    rank: np.ndarray
    cond: np.ndarray
    full_rank: np.ndarray
    ok: np.ndarray


def _validate(A: object, b: object) -> tuple[np.ndarray, np.ndarray]:
    A = as_array(A, "A", (None, None), finite=False)
    m, n = A.shape[-2:]
    if m < n:
        raise ValueError(f"Expected A to have at least as many rows as columns (m >= n), got {A.shape}.")
    b = as_array(b, "b", (m,), finite=False)
    return A, b


def solve(A: object, b: object, *, diagnostics: bool = True) -> LstsqResult:
    """Least-squares solution of every system in the stack by Householder QR.

    With ``diagnostics=False`` the singular values of R are not computed (``cond`` and ``rank`` come
    from the diagonal of R, a cheaper but only indicative estimate).
    """
    A, b = _validate(A, b)
    m, n = A.shape[-2:]
    batch = np.broadcast_shapes(A.shape[:-2], b.shape[:-1])
    A = np.broadcast_to(A, (*batch, m, n))
    b = np.broadcast_to(b, (*batch, m))
    finite = np.all(np.isfinite(A), axis=(-1, -2)) & np.all(np.isfinite(b), axis=-1)
    # Non-finite systems are replaced by a harmless identity-like system and reported as not ok.
    safe_A = np.where(finite[..., None, None], A, np.eye(m, n))
    safe_b = np.where(finite[..., None], b, 0.0)

    Q, R = np.linalg.qr(safe_A, mode="reduced")  # Householder (LAPACK dgeqrf + dorgqr), batched
    Qtb = np.einsum("...mi,...m->...i", Q, safe_b)
    if diagnostics:
        sv = np.linalg.svd(R, compute_uv=False)
        smax, smin = sv[..., 0], sv[..., -1]
        tol = RANK_RTOL_FACTOR * max(m, n) * np.finfo(float).eps * smax
        rank = np.sum(sv > tol[..., None], axis=-1)
    else:
        d = np.abs(np.diagonal(R, axis1=-2, axis2=-1))
        smax, smin = d.max(axis=-1), d.min(axis=-1)
        tol = RANK_RTOL_FACTOR * max(m, n) * np.finfo(float).eps * smax
        rank = np.sum(d > tol[..., None], axis=-1)
    full = rank == n
    cond = np.where(smin > 0, smax / np.where(smin > 0, smin, 1.0), np.inf)

    # Full-rank systems: back substitution on R (LAPACK dtrtrs, batched by SciPy).
    R_safe = np.where(full[..., None, None], R, np.eye(n))
    x = scipy.linalg.solve_triangular(R_safe, Qtb[..., None], lower=False)[..., 0]
    if not np.all(full):
        # Rank-deficient systems only: minimum-norm solution by SVD (LAPACK dgelsd via pinv).
        idx = ~full
        x[idx] = np.einsum("...ij,...j->...i", np.linalg.pinv(safe_A[idx]), safe_b[idx])
    resid = np.linalg.norm(np.einsum("...ij,...j->...i", safe_A, x) - safe_b, axis=-1)
    nan = np.nan
    return LstsqResult(
        x=np.where(finite[..., None], x, nan),
        residual_norm=np.where(finite, resid, nan),
        rank=np.where(finite, rank, 0),
        cond=np.where(finite, cond, nan),
        full_rank=full & finite,
        ok=finite,
    )


def solve_normal_equations(A: object, b: object) -> LstsqResult:
    """Least squares through ``A^T A x = A^T b`` (LU, batched), for comparison with :func:`solve`.

    Accuracy degrades like ``cond(A)^2 eps``; a numerically singular ``A^T A`` is flagged as not
    full rank (x is then the minimum-norm solution of the normal equations).
    """
    A, b = _validate(A, b)
    m, n = A.shape[-2:]
    batch = np.broadcast_shapes(A.shape[:-2], b.shape[:-1])
    A = np.broadcast_to(A, (*batch, m, n))
    b = np.broadcast_to(b, (*batch, m))
    finite = np.all(np.isfinite(A), axis=(-1, -2)) & np.all(np.isfinite(b), axis=-1)
    safe_A = np.where(finite[..., None, None], A, np.eye(m, n))
    safe_b = np.where(finite[..., None], b, 0.0)
    AtA = np.einsum("...mi,...mj->...ij", safe_A, safe_A)
    Atb = np.einsum("...mi,...m->...i", safe_A, safe_b)
    sv = np.linalg.svd(AtA, compute_uv=False)
    tol = RANK_RTOL_FACTOR * n * np.finfo(float).eps * sv[..., 0]
    rank = np.sum(sv > tol[..., None], axis=-1)
    full = rank == n
    x = np.empty((*batch, n))
    if np.any(full):
        x[full] = np.linalg.solve(AtA[full], Atb[full][..., None])[..., 0]
    if not np.all(full):
        x[~full] = np.einsum("...ij,...j->...i", np.linalg.pinv(AtA[~full]), Atb[~full])
    resid = np.linalg.norm(np.einsum("...ij,...j->...i", safe_A, x) - safe_b, axis=-1)
    cond = np.sqrt(
        np.where(sv[..., -1] > 0, sv[..., 0] / np.where(sv[..., -1] > 0, sv[..., -1], 1.0), np.inf)
    )
    return LstsqResult(
        x=np.where(finite[..., None], x, np.nan),
        residual_norm=np.where(finite, resid, np.nan),
        rank=np.where(finite, rank, 0),
        cond=np.where(finite, cond, np.nan),
        full_rank=full & finite,
        ok=finite,
    )
