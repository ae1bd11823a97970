"""Position, velocity and acceleration kinematics of the spherical parallel leg (paper 1, Sections 3-4):
l1, l2 fix beta alone and l3 then fixes alpha (docs/mechanisms/spherical_leg.md, "Frames, signs, units"
and "Departures")."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from robomech._batching import carries_failed_rows, chunked, slices
from robomech._validation import as_array, broadcast_to_batch, check_bool, check_int, check_params

# the unvalidated kernel: inputs are validated once at this module's public boundary
from robomech.spatial._so3 import _sincos as sincos

from ._params import SphericalLeg

__all__ = [
    "ForwardKinematicsResult",
    "InverseKinematicsResult",
    "angular_velocity_jacobian",
    "forward_kinematics",
    "hessian",
    "influence_coefficients",
    "inverse_kinematics",
    "jacobian",
    "leg_rates",
    "platform_rotation",
]

# FK fits beta to (l1, l2) by Newton's method from the exact closed form: no step for consistent
# lengths, 3-5 (quadratic) for noisy ones; 40 is a cap only far-inconsistent inputs could approach.
FK_MAX_ITER = 40
# Newton stops when the beta step falls below this (rad): 100x the rounding of an O(1) angle, far
# below the 1e-10 rad accuracy the tests require (used where the Gauss-Newton fallback is active).
FK_STEP_TOL = 1e-14
# Newton converges quadratically (dl1/db and dl2/db never vanish together), so after a step below 1e-8
# rad the remaining error is ~step^2 ~ 1e-16 rad: the step is applied and the iteration stops.
FK_NEWTON_STEP_TOL = 1e-8
# |sin(alpha - phi)| may exceed 1 by rounding when l3 sits exactly on the branch boundary (the
# l3-singularity); up to this excess the value is clipped, beyond it the lengths have no assembly.
ASSEMBLY_TOL = 1e-12
# Derivatives divide by the leg length, zero only in a collided pose far outside any stroke: floored so
# such a pose gives a huge finite derivative (flagged by within_limits), not a division by zero.
LENGTH_FLOOR = 1e-12
# Large batches are evaluated in chunks of this many samples so that a kernel's temporaries (about
# twenty arrays of 16384 float64 = 128 KiB each) stay in the L2 cache instead of streaming through
# memory; on 10^6 poses this roughly halves the time (benchmarks/bench_spherical_leg.py). Every
# operation is elementwise per sample, so chunking does not change any result bit.
CHUNK = 16384
# Samples per block of the compiled Newton fit: a few SIMD widths, so the masked passes vectorise and
# a block stops as soon as its slowest sample has converged (3 passes for typical noisy lengths).
FK_BLOCK = 64


def _angles(alpha: object, beta: object) -> tuple[np.ndarray, np.ndarray]:
    a = as_array(alpha, "alpha")
    b = as_array(beta, "beta")
    a, b = broadcast_to_batch((a, 0, "alpha"), (b, 0, "beta"))
    return a, b


_NO_QDD = object()


def _check_state(q: object, qd: object, qdd: object = _NO_QDD) -> tuple[np.ndarray, ...]:
    """``q``, ``qd`` (and ``qdd`` if given) (..., 2) validated and broadcast to their common batch."""
    items = [(as_array(q, "q", (2,)), 1, "q"), (as_array(qd, "qd", (2,)), 1, "qd")]
    if qdd is not _NO_QDD:
        items.append((as_array(qdd, "qdd", (2,)), 1, "qdd"))
    return broadcast_to_batch(*items)


@carries_failed_rows({"alpha": 0, "beta": 0})
def platform_rotation(alpha: object, beta: object) -> np.ndarray:
    """Platform rotation ``R_base_platform = Rx(alpha) Ry(beta)`` (paper 1, eq. (1)).

    Parameters
    ----------
    alpha, beta : array_like, shape (...)
        Platform angles (rad) about the base X axis and the turned Y axis; broadcast together.

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    a, b = _angles(alpha, beta)
    return _rotation(np.sin(a), np.cos(a), np.sin(b), np.cos(b))


def _rotation(sa: np.ndarray, ca: np.ndarray, sb: np.ndarray, cb: np.ndarray) -> np.ndarray:
    z = np.zeros_like(sa)
    return np.stack(
        [
            np.stack([cb, z, sb], -1),
            np.stack([sa * sb, ca, -sa * cb], -1),
            np.stack([-ca * sb, sa, ca * cb], -1),
        ],
        -2,
    )


def _squared_length_columns(leg: SphericalLeg, sa, ca, sb, cb) -> tuple[np.ndarray, ...]:
    R, r, h = leg.R, leg.r, leg.h
    K = R * R + r * r + h * h
    q1 = K - 2 * R * (r * cb + h * sb)
    q2 = K - 2 * R * (r * cb - h * sb)
    q3 = K - 2 * R * (r * ca - h * cb * sa)
    return q1, q2, q3


def _squared_lengths(leg: SphericalLeg, sa, ca, sb, cb) -> np.ndarray:
    return np.stack(_squared_length_columns(leg, sa, ca, sb, cb), -1)


@dataclass(frozen=True)
class InverseKinematicsResult:
    """Leg lengths and geometry (the result of :func:`inverse_kinematics`).

    Attributes
    ----------
    lengths : ndarray, shape (..., 3)
        Leg lengths l_i (m).
    unit_vectors, platform_points : ndarray, shape (..., 3, 3)
        Rows ``s_i = (B_i - A_i) / l_i`` (leg directions) and B_i (m, relative to O), base frame.
    base_points : ndarray, shape (3, 3)
        Rows A_i (m, base frame).
    within_limits : ndarray of bool, shape (..., 3)
        ``length_min <= l_i <= length_max``.
    """

    lengths: np.ndarray
    unit_vectors: np.ndarray
    platform_points: np.ndarray
    base_points: np.ndarray
    within_limits: np.ndarray


@carries_failed_rows({"alpha": 0, "beta": 0})
def inverse_kinematics(leg: SphericalLeg, alpha: object, beta: object) -> InverseKinematicsResult:
    """Leg lengths (paper 1, eq. (4)) for platform angles ``alpha``, ``beta`` (rad, broadcast).

    Parameters
    ----------
    leg : SphericalLeg
    alpha, beta : array_like, shape (...)

    Returns
    -------
    :class:`InverseKinematicsResult`
    """
    check_params(leg, SphericalLeg, "leg")
    a, b = _angles(alpha, beta)
    shape = a.shape
    n = a.size
    L = np.empty((n, 3))
    S = np.empty((n, 3, 3))
    B = np.empty((n, 3, 3))
    a, b = a.reshape(-1), b.reshape(-1)
    chunked(lambda c: _ik_kernel(leg, a[c], b[c], L[c], S[c], B[c]), n, CHUNK)
    within = (L >= leg.length_min) & (L <= leg.length_max)
    return InverseKinematicsResult(
        L.reshape(*shape, 3),
        S.reshape(*shape, 3, 3),
        B.reshape(*shape, 3, 3),
        leg.base_points,
        within.reshape(*shape, 3),
    )


def _ik_kernel(leg: SphericalLeg, a, b, L, S, B) -> None:
    """B_i = T b_i written out (paper 1, eq. (3) and its analogues), lengths from the closed form."""
    r, h = leg.r, leg.h
    (sa, ca), (sb, cb) = sincos(a), sincos(b)
    rsb_m_hcb = r * sb - h * cb
    rsb_p_hcb = r * sb + h * cb
    B[:, 0, 0] = r * cb + h * sb
    B[:, 0, 1] = sa * rsb_m_hcb
    B[:, 0, 2] = -ca * rsb_m_hcb
    B[:, 1, 0] = h * sb - r * cb
    B[:, 1, 1] = -sa * rsb_p_hcb
    B[:, 1, 2] = ca * rsb_p_hcb
    hcb = h * cb
    B[:, 2, 0] = h * sb
    B[:, 2, 1] = r * ca - sa * hcb
    B[:, 2, 2] = r * sa + ca * hcb
    # the closed form keeps full relative accuracy where |B - A| is small
    L[:, 0], L[:, 1], L[:, 2] = _squared_length_columns(leg, sa, ca, sb, cb)
    np.sqrt(np.maximum(L, 0.0, out=L), out=L)
    np.subtract(B, leg.base_points, out=S)
    S /= np.where(L > 0, L, 1.0)[:, :, None]


@dataclass(frozen=True)
class ForwardKinematicsResult:
    """Platform angles from leg lengths (the result of :func:`forward_kinematics`).

    Attributes
    ----------
    alpha, beta : ndarray, shape (...)
        Platform angles (rad); NaN where not ``valid``.
    residual : ndarray, shape (...)
        Norm of ``l(alpha, beta) - lengths`` (m): how inconsistent the three lengths are (rounding
        level for exact lengths).
    valid, converged : ndarray of bool, shape (...)
        Finite positive lengths that assemble (NaN angles only where this is False); the beta fit converged.
    """

    alpha: np.ndarray
    beta: np.ndarray
    residual: np.ndarray
    valid: np.ndarray
    converged: np.ndarray


def forward_kinematics(
    leg: SphericalLeg, lengths: object, branch: int = 0, *, paper_as_printed: bool = False
) -> ForwardKinematicsResult:
    """Platform angles from leg lengths ``(..., 3)`` (m): exact closed form, least squares if noisy.

    beta fits (l1, l2) (Newton from the exact ``atan2`` form), then alpha matches l3 exactly on the
    assembly ``branch``: ``sin(alpha - phi) = s``, branch 0 ``alpha = phi + asin(s)`` contains alpha = 0,
    branch 1 is ``phi + pi - asin(s)`` (docs/mechanisms/spherical_leg.md, "Departures").

    Parameters
    ----------
    leg : SphericalLeg
    lengths : array_like, shape (..., 3)
    branch : {0, 1}, optional
    paper_as_printed : bool, optional
        Run paper 1's printed eqs. (6)-(7) instead (``_as_printed.py``), for comparison only:
        ``residual`` then shows how far the printed alpha is from assembling; ``branch`` is ignored.

    Returns
    -------
    :class:`ForwardKinematicsResult`

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.mechanisms import spherical_leg as sl
    >>> leg = sl.SphericalLeg.paper()
    >>> ik = sl.inverse_kinematics(leg, np.array([0.0, 0.1]), 0.05)       # two poses (rad)
    >>> fk = sl.forward_kinematics(leg, ik.lengths)                       # and back
    >>> fk.alpha.round(12) + 0.0, fk.beta.round(12), fk.valid
    (array([0. , 0.1]), array([0.05, 0.05]), array([ True,  True]))
    """
    check_params(leg, SphericalLeg, "leg")
    branch = check_int(branch, "branch", low=0, high=1)
    paper_as_printed = check_bool(paper_as_printed, "paper_as_printed")
    L = as_array(lengths, "lengths", (3,), finite=False)
    L, shape = as_array(L, "lengths", finite="mask"), L.shape[:-1]  # beyond 1e100: masked like NaN
    n = int(np.prod(shape, dtype=int))
    if paper_as_printed:
        from ._as_printed import forward_as_printed

        a, b, res, ok = (o.reshape(shape) for o in forward_as_printed(leg, L.reshape(n, 3)))
        return ForwardKinematicsResult(alpha=a, beta=b, residual=res, valid=ok, converged=ok.copy())
    outs = (np.empty(n), np.empty(n), np.empty(n), np.empty(n, dtype=bool), np.empty(n, dtype=bool))
    _fk_kernel_compiled(leg, branch, np.ascontiguousarray(L.reshape(n, 3)), *outs)
    alpha, beta, residual, valid, converged = (o.reshape(shape) for o in outs)
    return ForwardKinematicsResult(
        alpha=alpha, beta=beta, residual=residual, valid=valid, converged=converged
    )


def _fk_kernel_compiled(
    leg: SphericalLeg, branch: int, L, alpha_out, beta_out, resid_out, valid_out, conv_out
) -> None:
    """FK of a flat batch: compiled ``fit`` (Newton on beta) and ``close`` (alpha, residual) over the
    whole batch (a parallel region per chunk cost ~8 ms each under load); the transcendental calls stay
    in numpy, whose SIMD atan2/tan are several times faster than numba's scalar libm calls."""
    fit, close = _fk_numba_kernels()
    R, r, h = leg.R, leg.r, leg.h
    n = L.shape[0]
    cb, sb = np.empty(n), np.empty(n)
    tols = (FK_NEWTON_STEP_TOL, FK_STEP_TOL, LENGTH_FLOOR**2)
    M = np.empty((3, n))  # lengths (1.0 for bad samples) by column: contiguous loads vectorise
    fit(L, R, r, h, FK_MAX_ITER, *tols, M, cb, sb, valid_out, conv_out)
    for c in slices(n, CHUNK):  # numpy's temporaries stay in cache
        np.arctan2(sb[c], cb[c], out=beta_out[c])
        sb[c], cb[c] = sincos(beta_out[c])
    sa, ca = np.empty(n), np.empty(n)
    sign = -1.0 if branch == 1 else 1.0
    close(M, R, r, h, sign, ASSEMBLY_TOL, sb, cb, sa, ca, beta_out, resid_out, valid_out, conv_out)
    np.arctan2(sa, ca, out=alpha_out)


@functools.cache
def _fk_numba_kernels():
    """Compile (or load from the on-disk cache) the forward-kinematics kernels: (fit, close)."""
    from robomech._numba import import_numba

    numba = import_numba()  # deferred: ~0.3 s import and compilation, paid by large-batch FK users only

    @numba.njit(parallel=True, cache=True, error_model="numpy")
    def fit(L, R, r, h, max_iter, newton_tol, gn_tol, floor2, M, cb, sb, ok, conv):  # pragma: no cover
        # Samples go in blocks of FK_BLOCK; every Newton pass runs over a whole block with a select
        # for the converged ones (their values freeze), so the pass vectorises (SIMD) across samples
        # instead of one sample's latency-bound chain of square roots and divisions.
        K = R * R + r * r + h * h
        n = L.shape[0]
        nblocks = (n + FK_BLOCK - 1) // FK_BLOCK
        for blk in numba.prange(nblocks):
            i0 = blk * FK_BLOCK
            cnt = min(FK_BLOCK, n - i0)
            m1 = np.empty(FK_BLOCK)
            m2 = np.empty(FK_BLOCK)
            c = np.empty(FK_BLOCK)
            s = np.empty(FK_BLOCK)
            active = np.zeros(FK_BLOCK, dtype=np.bool_)
            for j in range(cnt):
                a1, a2, a3 = L[i0 + j, 0], L[i0 + j, 1], L[i0 + j, 2]
                good = a1 > 0 and a2 > 0 and a3 > 0 and max(max(a1, a2), a3) < np.inf
                ok[i0 + j] = good
                if not good:
                    a1, a2, a3 = 1.0, 1.0, 1.0
                m1[j], m2[j] = a1, a2
                M[0, i0 + j], M[1, i0 + j], M[2, i0 + j] = a1, a2, a3
                q0, q1 = a1 * a1, a2 * a2
                y = (q1 - q0) * (1.0 / (4 * R * h))
                x = (2 * K - q0 - q1) * (1.0 / (4 * R * r))
                n0 = np.sqrt(x * x + y * y)
                inv = 1.0 / n0 if n0 > 0 else 1.0
                c[j] = x * inv if n0 > 0 else 1.0
                s[j] = y * inv
                active[j] = True
            for _ in range(max_iter):
                left = 0
                for j in range(cnt):
                    cj, sj = c[j], s[j]
                    rc, hs, rs, hc = r * cj, h * sj, r * sj, h * cj
                    l1 = np.sqrt(max(K - 2 * R * (rc + hs), floor2))
                    l2 = np.sqrt(max(K - 2 * R * (rc - hs), floor2))
                    i1, i2 = 1.0 / l1, 1.0 / l2
                    d1 = R * (rs - hc) * i1
                    d2 = R * (rs + hc) * i2
                    dd1 = (R * (rc + hs) - d1 * d1) * i1
                    dd2 = (R * (rc - hs) - d2 * d2) * i2
                    e1 = -m1[j] + l1
                    e2 = -m2[j] + l2
                    hgn = d1 * d1 + d2 * d2
                    hn = hgn + e1 * dd1 + e2 * dd2
                    newton = hn > 0.5 * hgn
                    step = (e1 * d1 + e2 * d2) / (hn if newton else hgn)
                    t = 0.5 * step
                    w = 1.0 / (1.0 + t * t)
                    ct = (1.0 - t * t) * w
                    st = (2.0 * w) * t
                    act = active[j]
                    c[j] = cj * ct + sj * st if act else cj
                    s[j] = sj * ct - cj * st if act else sj
                    still = act and abs(step) > (newton_tol if newton else gn_tol)
                    active[j] = still
                    left += still
                if left == 0:
                    break
            for j in range(cnt):
                cb[i0 + j], sb[i0 + j], conv[i0 + j] = c[j], s[j], not active[j]

    @numba.njit(parallel=True, cache=True, error_model="numpy")
    def close(M, R, r, h, sign, tol, sb, cb, sa, ca, beta, resid, ok, conv):  # pragma: no cover
        K = R * R + r * r + h * h
        # branch-free (selects only) and an inner plain loop per block, so that the loop vectorises
        n = M.shape[1]
        for blk in numba.prange((n + FK_BLOCK - 1) // FK_BLOCK):
            for i in range(blk * FK_BLOCK, min(n, (blk + 1) * FK_BLOCK)):
                good = ok[i]
                m1, m2, m3 = M[0, i], M[1, i], M[2, i]
                c, sn = cb[i], sb[i]
                hcb = h * c
                rho = np.sqrt(hcb * hcb + r * r)
                inv_rho = 1.0 / rho
                s = (m3 * m3 - K) * (0.5 / R) * inv_rho
                good = good & (abs(s) <= 1.0 + tol)
                s = min(max(s, -1.0), 1.0)
                cw = sign * np.sqrt(max((1.0 - s) * (1.0 + s), 0.0))
                sphi, cphi = r * inv_rho, hcb * inv_rho
                sai = sphi * cw + cphi * s
                cai = cphi * cw - sphi * s
                e1 = np.sqrt(max(K - 2 * R * (r * c + h * sn), 0.0)) - m1
                e2 = np.sqrt(max(K - 2 * R * (r * c - h * sn), 0.0)) - m2
                e3 = np.sqrt(max(K - 2 * R * (r * cai - hcb * sai), 0.0)) - m3
                ok[i] = good
                conv[i] = conv[i] & good
                sa[i] = sai if good else np.nan
                ca[i] = cai if good else np.nan
                resid[i] = np.sqrt(e1 * e1 + e2 * e2 + e3 * e3) if good else np.nan
                beta[i] = beta[i] if good else np.nan

    return fit, close


@carries_failed_rows({"alpha": 0, "beta": 0})
def jacobian(leg: SphericalLeg, alpha: object, beta: object) -> np.ndarray:
    """Leg Jacobian ``J[..., i, j] = d l_i / d (alpha, beta)_j`` (m/rad).

    Parameters
    ----------
    leg : SphericalLeg
    alpha, beta : array_like, shape (...)

    Returns
    -------
    ndarray, shape (..., 3, 2)
    """
    check_params(leg, SphericalLeg, "leg")
    a, b = _angles(alpha, beta)
    shape, a, b = a.shape, a.reshape(-1), b.reshape(-1)
    J = np.empty((a.size, 3, 2))
    chunked(lambda c: _jacobian_kernel(leg, a[c], b[c], J[c]), a.size, CHUNK)
    return J.reshape(*shape, 3, 2)


def _jacobian_kernel(leg: SphericalLeg, a, b, J) -> None:
    (sa, ca), (sb, cb) = sincos(a), sincos(b)
    _jacobian_sincos(leg, sa, ca, sb, cb, J)


def _jacobian_sincos(leg, sa, ca, sb, cb, J) -> None:
    """J from the sines and cosines; ``leg``'s R, r, h may be per-design arrays broadcasting with them."""
    R, r, h = leg.R, leg.r, leg.h
    hsb, rsb, hcb = h * sb, r * sb, h * cb
    q1, q2, q3 = _squared_length_columns(leg, sa, ca, sb, cb)
    # dl/dq = (dq/dq) / (2 l) with q = l^2; R/l below is 2R / (2l)
    J[..., 0, 0] = 0.0
    J[..., 1, 0] = 0.0
    J[..., 0, 1] = (rsb - hcb) * R / np.sqrt(np.maximum(q1, LENGTH_FLOOR**2))
    J[..., 1, 1] = (rsb + hcb) * R / np.sqrt(np.maximum(q2, LENGTH_FLOOR**2))
    k3 = R / np.sqrt(np.maximum(q3, LENGTH_FLOOR**2))
    J[..., 2, 0] = (r * sa + hcb * ca) * k3
    J[..., 2, 1] = -(hsb * sa) * k3


def _derivatives(leg: SphericalLeg, sa, ca, sb, cb):
    """Squared lengths q (..., 3), dq (..., 3, 2) and d2q (..., 3, 2, 2) w.r.t. (alpha, beta)."""
    R, r, h = leg.R, leg.r, leg.h
    q = _squared_lengths(leg, sa, ca, sb, cb)
    dq = np.zeros((*sa.shape, 3, 2))
    dq[..., 0, 1] = 2 * R * (r * sb - h * cb)
    dq[..., 1, 1] = 2 * R * (r * sb + h * cb)
    dq[..., 2, 0] = 2 * R * (r * sa + h * cb * ca)
    dq[..., 2, 1] = -2 * R * h * sb * sa
    d2q = np.zeros((*sa.shape, 3, 2, 2))
    d2q[..., 0, 1, 1] = 2 * R * (r * cb + h * sb)
    d2q[..., 1, 1, 1] = 2 * R * (r * cb - h * sb)
    d2q[..., 2, 0, 0] = 2 * R * (r * ca - h * cb * sa)
    d2q[..., 2, 0, 1] = d2q[..., 2, 1, 0] = -2 * R * h * sb * ca
    d2q[..., 2, 1, 1] = -2 * R * h * cb * sa
    return q, dq, d2q


@carries_failed_rows({"alpha": 0, "beta": 0})
def hessian(leg: SphericalLeg, alpha: object, beta: object) -> np.ndarray:
    """``H[..., i, j, k] = d^2 l_i / dq_j dq_k`` (m/rad^2), q = (alpha, beta): d :func:`jacobian` / dq.

    Parameters
    ----------
    leg : SphericalLeg
    alpha, beta : array_like, shape (...)

    Returns
    -------
    ndarray, shape (..., 3, 2, 2)
    """
    check_params(leg, SphericalLeg, "leg")
    a, b = _angles(alpha, beta)
    return _lengths_jh(leg, a, b)[2]


def _lengths_jh(leg: SphericalLeg, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, ...]:
    """Leg lengths l, J = dl/dq and H = d2l/dq2 at q = (a, b), from the squared lengths' derivatives."""
    q, dq, d2q = _derivatives(leg, np.sin(a), np.cos(a), np.sin(b), np.cos(b))
    l = np.sqrt(np.maximum(q, LENGTH_FLOOR**2))
    ln = l[..., None, None]
    # l = sqrt(q): l' = q'/(2l), l'' = q''/(2l) - q' q'^T / (4 l^3)
    H = d2q / (2 * ln) - np.einsum("...ij,...ik->...ijk", dq, dq) / (4 * ln**3)
    return l, dq / (2 * l[..., None]), H


@carries_failed_rows({"alpha": 0})
def angular_velocity_jacobian(alpha: object) -> np.ndarray:
    """``E = [x, Rx(alpha) y]``: platform angular velocity ``omega = E (alpha_dot, beta_dot)`` (base frame).

    Parameters
    ----------
    alpha : array_like, shape (...)
        ``E`` does not depend on beta.

    Returns
    -------
    ndarray, shape (..., 3, 2)
    """
    a = as_array(alpha, "alpha")
    E = np.zeros((*a.shape, 3, 2))
    E[..., 0, 0] = 1.0
    E[..., 1, 1] = np.cos(a)
    E[..., 2, 1] = np.sin(a)
    return E


@carries_failed_rows({"alpha": 0, "beta": 0})
def influence_coefficients(leg: SphericalLeg, alpha: object, beta: object) -> np.ndarray:
    """First-order influence coefficients ``G``: ``ldot = G [omega; v_O]`` (base frame, about O).

    Row i is the Plücker line of leg i, ``[(B_i - O) x s_i; s_i]``: paper 1, eqs. (8)-(12) about O
    instead of P, eq. (12)'s first row with its missing sin(alpha) restored (errata).
    ``jacobian = G[..., :3] @ angular_velocity_jacobian``.

    Parameters
    ----------
    leg : SphericalLeg
    alpha, beta : array_like, shape (...)

    Returns
    -------
    ndarray, shape (..., 3, 6)
    """
    check_params(leg, SphericalLeg, "leg")
    ik = inverse_kinematics(leg, alpha, beta)
    G = np.empty((*ik.lengths.shape[:-1], 3, 6))
    G[..., :3] = np.cross(ik.platform_points, ik.unit_vectors)
    G[..., 3:] = ik.unit_vectors
    return G


@carries_failed_rows({"q": 1, "qd": 1, "qdd": 1})
def leg_rates(
    leg: SphericalLeg, q: object, qd: object, qdd: object
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Leg lengths (m), rates (m/s), accelerations (m/s²) ``(l, ldot, lddot)`` along q = (alpha, beta).

    ``ldot = J qd``, ``lddot = J qdd + qd^T H qd``, replacing paper 1, eqs. (13)-(17) (see the code).

    Parameters
    ----------
    leg : SphericalLeg
    q, qd, qdd : array_like, shape (..., 2)
        Platform angles ``(alpha, beta)`` (rad), their rates and accelerations; broadcast together.

    Returns
    -------
    l, ldot, lddot : ndarray, shape (..., 3)
    """
    check_params(leg, SphericalLeg, "leg")
    qa, qda, qdda = _check_state(q, qd, qdd)
    l, J, H = _lengths_jh(leg, qa[..., 0], qa[..., 1])
    ld = np.einsum("...ij,...j->...i", J, qda)
    # paper 1, eqs. (13)-(17): printed l*lddot = L.V (for l*ldot) and a scalar (1 - S^2)/l; correct is
    # lddot = s.a_B + v_B^T (I - s s^T) v_B / l = s.a_B + (|v_B|^2 - ldot^2)/l, which J qdd + qd^T H qd
    # equals (tested against the engine and against this form).
    ldd = np.einsum("...ij,...j->...i", J, qdda) + np.einsum("...ijk,...j,...k->...i", H, qda, qda)
    return l, ld, ldd
