"""Batched linear least squares by Householder QR (a compiled numba kernel), with per-system diagnostics.

``solve(A, b)`` handles stacks ``A (..., m, n)``, ``b (..., m)`` with ``m >= n``.  Every system is
solved independently; a rank-deficient or non-finite system is flagged in the result and never
aborts the batch.  The QR is robomech's own compiled kernel (``_householder.py``: LAPACK's ``dgeqr2``
algorithm, not a LAPACK call); LAPACK's SVD is used only for the rank-deficient systems.
``solve_normal_equations`` is the textbook alternative kept for comparison: it
squares the condition number (``cond(A^T A) = cond(A)^2``), which is what paper 4 means by choosing
QR.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from robomech._validation import as_array, broadcast_batch, check_bool, check_int, finite_samples

__all__ = ["RANK_RTOL_FACTOR", "LstsqResult", "rank_cond_limit", "solve", "solve_normal_equations"]

# A system is rank deficient when a singular value of R is below RANK_RTOL_FACTOR * max(m, n) * eps
# times the largest: max(m, n) * eps is numpy's matrix_rank default, the bound on the rounding that
# Householder QR leaves in R; the factor 10 keeps systems with condition up to ~1e14 full rank.
RANK_RTOL_FACTOR = 10.0


@dataclass(frozen=True)
class LstsqResult:
    """Per-system solution and diagnostics (batch shape ``...``).

    ``x (..., n)`` and ``residual_norm`` are NaN exactly where ``ok`` is false: non-finite input, or
    a finite system whose solution or residual overflows float64.  For rank-deficient systems ``x``
    is the minimum-norm solution and ``full_rank`` is false.

    ``cond`` is the condition number of the triangular factor R of ``A = QR`` in the **1-norm**,
    ``||R||_1 ||R^-1||_1`` (it equals that of A in the 2-norm within a factor n; ``solve(...,
    exact_cond=True)`` gives the 2-norm condition number instead; ``solve_normal_equations`` gives
    the 2-norm one of A from the normal matrix).

    Attributes
    ----------
    x : ndarray, shape (..., n)
        Least-squares solution of ``A x ≈ b`` (minimum norm when rank deficient), in the units of
        ``b`` over those of ``A``; NaN where not ``ok``.
    residual_norm : ndarray, shape (...)
        ``||A x - b||_2`` (units of ``b``); NaN where not ``ok``.
    rank : ndarray of int, shape (...)
        Numerical rank of ``A`` (0 where not ``ok``).
    cond : ndarray, shape (...)
        Condition number (of R in the 1-norm unless stated above); NaN where not ``ok``.
    full_rank : ndarray of bool, shape (...)
        ``ok`` and ``cond`` within :func:`rank_cond_limit` (rank n).
    ok : ndarray of bool, shape (...)
        The input was finite and ``x`` and the residual are finite.
    """

    x: np.ndarray
    residual_norm: np.ndarray
    rank: np.ndarray
    cond: np.ndarray
    full_rank: np.ndarray
    ok: np.ndarray


def _validate(A: ArrayLike, b: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    A = as_array(A, "A", (None, None), finite=False, nonempty=True)
    m, n = A.shape[-2:]
    if m < n:
        raise ValueError(f"Expected A to have at least as many rows as columns (m >= n), got {A.shape}.")
    b = as_array(b, "b", (m,), finite=False)
    broadcast_batch((A, 2, "A"), (b, 1, "b"))
    return A, b


def _apply_weights(A: np.ndarray, b: np.ndarray, weights: ArrayLike | None) -> tuple[np.ndarray, np.ndarray]:
    """Scale the rows of ``A`` and ``b`` by ``sqrt(weights)``: least squares then minimises
    ``Σ_i w_i r_i²`` (weighted least squares; ``w_i = 1/σ_i²`` for independent row errors)."""
    if weights is None:
        return A, b
    w = as_array(weights, "weights", (A.shape[-2],))
    broadcast_batch((A, 2, "A"), (w, 1, "weights"))
    if np.any(w < 0.0):
        raise ValueError(f"Expected weights >= 0, got {int(np.sum(w < 0.0))} negative value(s).")
    sw = np.sqrt(w)
    return A * sw[..., :, None], b * sw


def solve(
    A: ArrayLike, b: ArrayLike, *, exact_cond: bool = False, weights: ArrayLike | None = None
) -> LstsqResult:
    """Least-squares solution of every system in the stack by Householder QR.

    Each system is factorised as ``[A | b] = Q [R, c; 0, r]`` (unblocked Householder, the algorithm
    of LAPACK's ``dgeqr2``, compiled and run in parallel over the batch: see ``_householder.py``), so
    ``x = R^-1 c`` and the residual norm is ``|r|``.  The first call in a process compiles the kernel
    (several seconds; cached on disk afterwards).

    ``cond`` is the exact 1-norm condition number ``||R||_1 ||R^-1||_1`` of R (within a factor n of
    the 2-norm condition number of A) unless ``exact_cond=True``, which computes the 2-norm one from
    the singular values of R.  A system whose condition exceeds :func:`rank_cond_limit` is rank
    deficient: its rank comes from the SVD and ``x`` is the minimum-norm solution.

    ``weights (..., m)`` (finite, ``>= 0``, broadcasting with the stack) makes it weighted least squares,
    ``min Σ_i w_i (A x - b)_i²``, solved as the ordinary problem on rows scaled by ``sqrt(w_i)``;
    ``residual_norm`` and ``cond`` are then those of the weighted system.

    Parameters
    ----------
    A : array_like, shape (..., m, n)
        Coefficient matrices, ``m >= n`` (any consistent units).
    b : array_like, shape (..., m)
        Right-hand sides; batch dimensions broadcast with those of ``A``.
    exact_cond : bool, optional
        Report the 2-norm condition number (from the SVD of R) instead of the 1-norm one of R.
    weights : array_like, shape (..., m), optional
        Row weights ``w_i >= 0`` (finite) for weighted least squares; default unweighted.

    Returns
    -------
    LstsqResult
        ``x (..., n)``, ``residual_norm (...)``, ``rank (...)``, ``cond (...)``, ``full_rank (...)``,
        ``ok (...)``: per system; a non-finite system gives ``ok`` False and NaN in ``x`` without
        affecting the others.

    Examples
    --------
    >>> import numpy as np
    >>> A = np.array([[[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]], [[1.0, 2.0], [2.0, 4.0], [3.0, 6.0]]])
    >>> r = solve(A, np.array([[1.0, 2.0, 3.0], [1.0, 2.0, 3.0]]))
    >>> r.x[0].round(12), bool(r.full_rank[0])          # a consistent full-rank system
    (array([1., 2.]), True)
    >>> int(r.rank[1]), bool(r.full_rank[1]), bool(r.ok[1])   # rank 1: minimum-norm solution, flagged
    (1, False, True)
    """
    from ._householder import householder_lstsq

    # A bool check, not truthiness: any other object would also compile a new kernel specialisation.
    exact_cond = check_bool(exact_cond, "exact_cond")
    A, b = _validate(A, b)
    A, b = _apply_weights(A, b, weights)
    m, n = A.shape[-2:]
    batch = np.broadcast_shapes(A.shape[:-2], b.shape[:-1])
    Af = np.broadcast_to(A, (*batch, m, n)).reshape(-1, m, n)
    bf = np.broadcast_to(b, (*batch, m)).reshape(-1, m)
    x, resid, cond, finite, R = householder_lstsq(Af, bf, exact_cond)
    # A finite system can still overflow (entries ~1e200): its solution is then not a number either.
    finite = finite & finite_samples(x, 1) & np.isfinite(resid)
    if exact_cond:
        assert R is not None  # householder_lstsq returns R when asked (want_R)
        R = np.where(finite[:, None, None], R, np.eye(n))
        sv = np.linalg.svd(R, compute_uv=False)
        cond = np.where(sv[:, -1] > 0, sv[:, 0] / np.where(sv[:, -1] > 0, sv[:, -1], 1.0), np.inf)
    full = finite & (cond <= rank_cond_limit(m, n))
    rank = np.where(full, n, 0)
    deficient = finite & ~full
    if np.any(deficient):
        # Rank-deficient systems only: numerical rank and minimum-norm solution by SVD (LAPACK).
        Ad, bd = Af[deficient], bf[deficient]
        sv = np.linalg.svd(Ad, compute_uv=False)
        tol = RANK_RTOL_FACTOR * max(m, n) * np.finfo(float).eps * sv[:, :1]
        rank[deficient] = np.sum(sv > tol, axis=-1)
        xd = np.einsum("kij,kj->ki", np.linalg.pinv(Ad, rcond=tol[:, 0] / sv[:, 0]), bd)
        x[deficient] = xd
        resid[deficient] = np.linalg.norm(np.einsum("kij,kj->ki", Ad, xd) - bd, axis=-1)
        finite = finite & finite_samples(x, 1) & np.isfinite(resid)
        full &= finite
    nan = np.nan
    return LstsqResult(
        x=np.where(finite[:, None], x, nan).reshape(*batch, n),
        residual_norm=np.where(finite, resid, nan).reshape(batch),
        rank=np.where(finite, rank, 0).reshape(batch),
        cond=np.where(finite, cond, nan).reshape(batch),
        full_rank=full.reshape(batch),
        ok=finite.reshape(batch),
    )


def _damped_svd_solve(
    U: np.ndarray, s: np.ndarray, Vt: np.ndarray, b: np.ndarray, lam: np.ndarray, weak: np.ndarray
) -> np.ndarray:
    """``V diag(c) Uᵀ b`` for ``A = U diag(s) Vt`` (full or thin SVD), batched: ``c = 1/σ`` on the regular
    directions and ``σ/(σ² + λ²)`` on the ``weak`` ones (selectively damped least squares; 0 where
    σ = λ = 0).  The mechanisms' damped rate and force inversions near a singularity."""
    den = s * s + lam * lam
    coef = np.where(weak, s / np.where(den > 0, den, 1.0), 1.0 / np.where(weak, 1.0, s))
    return np.einsum("...ji,...j->...i", Vt, coef * np.einsum("...ji,...j->...i", U, b))


def _damped_inverse(
    A: np.ndarray, *, rtol: float = 0.0, atol: float = 0.0, damping: float
) -> tuple[np.ndarray, Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]]:
    """The mechanisms' damped rate and force inversion: the SVD of each ``A (..., m, n)`` once, and
    ``solve(b) -> (x, |A x - b|)`` by :func:`_damped_svd_solve` on it, the directions with
    ``σ < rtol σ_max + atol`` damped by ``λ = damping σ_max``.  Also returns the singular values
    (descending)."""
    U, s, Vt = np.linalg.svd(A, full_matrices=False)
    smax = s[..., :1]
    weak = s < rtol * smax + atol
    lam = damping * smax

    def solve(b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x = _damped_svd_solve(U, s, Vt, b, lam, weak)
        return x, np.linalg.norm(np.einsum("...ij,...j->...i", A, x) - b, axis=-1)

    return s, solve


def rank_cond_limit(m: int, n: int) -> float:
    """Condition number above which a system counts as rank deficient: ``1 / (10 max(m, n) eps)``.

    Parameters
    ----------
    m, n : int
        Rows and columns of the systems.

    Returns
    -------
    float

    Examples
    --------
    >>> f"{rank_cond_limit(30, 11):.3e}"
    '1.501e+13'
    """
    m = check_int(m, "m", low=1)
    n = check_int(n, "n", low=1)
    return 1.0 / (RANK_RTOL_FACTOR * max(m, n) * np.finfo(float).eps)


def solve_normal_equations(A: ArrayLike, b: ArrayLike) -> LstsqResult:
    """Least squares through ``A^T A x = A^T b`` (LU, batched), for comparison with :func:`solve`.

    Accuracy degrades like ``cond(A)^2 eps``; a numerically singular ``A^T A`` is flagged as not
    full rank (x is then the minimum-norm solution of the normal equations).

    Parameters
    ----------
    A : array_like, shape (..., m, n)
        Coefficient matrices, ``m >= n``.
    b : array_like, shape (..., m)
        Right-hand sides; batch dimensions broadcast.

    Returns
    -------
    LstsqResult
        As :func:`solve`; ``cond`` is the 2-norm condition number of ``A`` from the normal matrix.

    Examples
    --------
    >>> import numpy as np
    >>> A = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    >>> solve_normal_equations(A, np.array([1.0, 2.0, 3.0])).x.round(12)
    array([1., 2.])
    """
    A, b = _validate(A, b)
    m, n = A.shape[-2:]
    batch = np.broadcast_shapes(A.shape[:-2], b.shape[:-1])
    A = np.broadcast_to(A, (*batch, m, n))
    b = np.broadcast_to(b, (*batch, m))
    finite = np.all(np.isfinite(A), axis=(-1, -2)) & np.all(np.isfinite(b), axis=-1)
    safe_A = np.where(finite[..., None, None], A, np.eye(m, n))
    safe_b = np.where(finite[..., None], b, 0.0)
    with np.errstate(over="ignore", invalid="ignore"):
        AtA = np.einsum("...mi,...mj->...ij", safe_A, safe_A)
        Atb = np.einsum("...mi,...m->...i", safe_A, safe_b)
    # Squaring overflows for entries beyond ~1e154 (the normal equations' defect): such a system is
    # flagged, never handed to LAPACK (an SVD of inf raises for the whole batch).
    finite = finite & finite_samples(AtA, 2) & finite_samples(Atb, 1)
    AtA = np.where(finite[..., None, None], AtA, np.eye(n))
    Atb = np.where(finite[..., None], Atb, 0.0)
    safe_A = np.where(finite[..., None, None], safe_A, np.eye(m, n))
    safe_b = np.where(finite[..., None], safe_b, 0.0)
    sv = np.linalg.svd(AtA, compute_uv=False)
    tol = RANK_RTOL_FACTOR * n * np.finfo(float).eps * sv[..., 0]
    rank = np.sum(sv > tol[..., None], axis=-1)
    full = rank == n
    x = np.empty((*batch, n))
    if np.any(full):
        x[full] = np.linalg.solve(AtA[full], Atb[full][..., None])[..., 0]
    if not np.all(full):
        x[~full] = np.einsum("...ij,...j->...i", np.linalg.pinv(AtA[~full]), Atb[~full])
    with np.errstate(over="ignore", invalid="ignore"):
        resid = np.linalg.norm(np.einsum("...ij,...j->...i", safe_A, x) - safe_b, axis=-1)
    finite = finite & finite_samples(x, 1) & np.isfinite(resid)
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
