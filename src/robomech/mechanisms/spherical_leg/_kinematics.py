"""Position, velocity and acceleration kinematics of the spherical parallel leg (paper 1, Sections 3-4).

The platform rotates about O by ``T = Rx(alpha) Ry(beta)`` (paper 1, eq. (1)); leg i joins
``A_i`` (base) to ``B_i = T b_i`` (``b_i`` = B_i at the home pose). Squared leg lengths in closed form,
with ``K = R^2 + r^2 + h^2``:

    l1^2 = K - 2R (r cos b + h sin b)
    l2^2 = K - 2R (r cos b - h sin b)
    l3^2 = K - 2R (r cos a - h cos b sin a)

so l1, l2 fix beta alone and l3 then fixes alpha: the three lengths over-determine the two angles.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._validation import as_array

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

# Forward kinematics fits beta to (l1, l2) by Newton's method started at the exact closed form.  For
# consistent lengths the start is already the answer; for noisy lengths the 1-D least-squares problem
# is smooth and convex near the start, and Newton converges quadratically in about 3-5 steps.  40 is a
# generous cap that only sub-millimetre-inconsistent inputs far from any pose could approach.
FK_MAX_ITER = 40
# Newton stops when the beta step falls below this (rad): 100x the rounding of an O(1) angle, far
# below the 1e-10 rad accuracy the tests require.
FK_STEP_TOL = 1e-14
# |sin(alpha - phi)| may exceed 1 by rounding when l3 sits exactly on the branch boundary (the
# l3-singularity); up to this excess the value is clipped, beyond it the lengths have no assembly.
ASSEMBLY_TOL = 1e-12
# Derivatives divide by the leg length; B_i can only reach A_i in a collided pose far outside any
# stroke (length_min > 0). The length is floored here so such a pose gives a huge finite derivative
# (flagged by within_limits) rather than a division-by-zero warning.
LENGTH_FLOOR = 1e-12


def _angles(alpha: object, beta: object) -> tuple[np.ndarray, np.ndarray]:
    a = as_array(alpha, "alpha")
    b = as_array(beta, "beta")
    try:
        a, b = np.broadcast_arrays(a, b)
    except ValueError as exc:
        raise ValueError(
            f"Expected alpha and beta to broadcast, got shapes {a.shape} and {b.shape}."
        ) from exc
    return a, b


def platform_rotation(alpha: object, beta: object) -> np.ndarray:
    """``T = Rx(alpha) Ry(beta)`` (paper 1, eq. (1)) -> (..., 3, 3)."""
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


def _squared_lengths(leg: SphericalLeg, sa, ca, sb, cb) -> np.ndarray:
    R, r, h = leg.R, leg.r, leg.h
    K = R * R + r * r + h * h
    q1 = K - 2 * R * (r * cb + h * sb)
    q2 = K - 2 * R * (r * cb - h * sb)
    q3 = K - 2 * R * (r * ca - h * cb * sa)
    return np.stack([q1, q2, q3], -1)


@dataclass(frozen=True)
class InverseKinematicsResult:
    """Leg lengths and geometry for platform angles (alpha, beta).

    lengths (..., 3) m; unit_vectors (..., 3, 3) rows s_i = (B_i - A_i)/l_i; platform_points
    (..., 3, 3) rows B_i in the base frame; base_points (3, 3) rows A_i; within_limits (..., 3) bool:
    length_min <= l_i <= length_max.
    """

    lengths: np.ndarray
    unit_vectors: np.ndarray
    platform_points: np.ndarray
    base_points: np.ndarray
    within_limits: np.ndarray


def inverse_kinematics(leg: SphericalLeg, alpha: object, beta: object) -> InverseKinematicsResult:
    """Leg lengths (paper 1, eq. (4)) for platform angles ``alpha``, ``beta`` (rad, broadcast).

    Every finite (alpha, beta) has a solution; non-finite angles raise ``ValueError``.
    """
    a, b = _angles(alpha, beta)
    sa, ca, sb, cb = np.sin(a), np.cos(a), np.sin(b), np.cos(b)
    T = _rotation(sa, ca, sb, cb)
    B = np.einsum("...ij,kj->...ki", T, leg.platform_points_home)
    A = leg.base_points
    u = B - A
    # the closed form keeps full relative accuracy where |B - A| is small
    lengths = np.sqrt(np.maximum(_squared_lengths(leg, sa, ca, sb, cb), 0.0))
    safe = np.where(lengths > 0, lengths, 1.0)
    s = u / safe[..., None]
    within = (lengths >= leg.length_min) & (lengths <= leg.length_max)
    return InverseKinematicsResult(lengths, s, B, A, within)


@dataclass(frozen=True)
class ForwardKinematicsResult:
    """Platform angles from leg lengths.

    alpha, beta (...) rad; residual (...) m: norm of (l(alpha, beta) - lengths), i.e. how inconsistent
    the three lengths are (rounding level for exact lengths); valid (...) bool: finite positive lengths
    that assemble (NaN angles only where valid is false); converged (...) bool: the beta fit converged.
    """

    alpha: np.ndarray
    beta: np.ndarray
    residual: np.ndarray
    valid: np.ndarray
    converged: np.ndarray


def forward_kinematics(leg: SphericalLeg, lengths: object, branch: int = 0) -> ForwardKinematicsResult:
    """Platform angles from leg lengths ``(..., 3)`` (m): exact closed form, least squares if noisy.

    beta is the least-squares fit of (l1, l2) (which depend on beta only), started from the exact
    ``atan2`` form built from l2^2 - l1^2 and l1^2 + l2^2; alpha then matches l3 exactly:
    ``h cos b sin a - r cos a = (l3^2 - K) / (2R)``, i.e. ``sin(a - phi) = s`` with
    ``phi = atan2(r, h cos b)``. ``branch=0`` is the assembly ``a = phi + asin(s)`` that contains
    alpha = 0; ``branch=1`` is ``a = phi + pi - asin(s)``. Bad samples (non-finite, non-positive, no
    assembly) are flagged in ``.valid``; a wrong shape raises ``ValueError``.
    """
    if branch not in (0, 1):
        raise ValueError(f"Expected branch to be 0 or 1, got {branch!r}.")
    L = as_array(lengths, "lengths", (3,), finite=False)
    ok_in = np.all(np.isfinite(L) & (L > 0), axis=-1)
    Lw = np.where(ok_in[..., None], L, 1.0)
    R, r, h = leg.R, leg.r, leg.h
    K = R * R + r * r + h * h
    q = Lw * Lw
    # paper 1, eq. (6) uses arcsin((l2^2 - l1^2)/(4Rh)); atan2 with the cosine from l1^2 + l2^2 is exact
    # for consistent lengths, covers |beta| > pi/2 and never leaves the domain for noisy ones.
    beta = np.arctan2((q[..., 1] - q[..., 0]) / (4 * R * h), (2 * K - q[..., 0] - q[..., 1]) / (4 * R * r))
    beta, converged = _fit_beta(leg, beta, Lw[..., 0], Lw[..., 1])
    cb = np.cos(beta)
    rho = np.hypot(h * cb, r)
    phi = np.arctan2(r, h * cb)
    # paper 1, eqs. (7): the printed Ferrari quartic (with a dropped square in k2, 9k2k3k4 for 9k1k2k3
    # and arctan(2a) for 2 arctan(a)) is replaced by this exact closed form of the l3 equation.
    s = (q[..., 2] - K) / (2 * R * rho)
    assembles = np.abs(s) <= 1.0 + ASSEMBLY_TOL
    asn = np.arcsin(np.clip(s, -1.0, 1.0))
    alpha = phi + asn if branch == 0 else phi + np.pi - asn
    alpha = np.mod(alpha + np.pi, 2 * np.pi) - np.pi
    valid = ok_in & assembles
    sa, ca, sb = np.sin(alpha), np.cos(alpha), np.sin(beta)
    fitted = np.sqrt(np.maximum(_squared_lengths(leg, sa, ca, sb, cb), 0.0))
    residual = np.linalg.norm(fitted - Lw, axis=-1)
    nan = np.nan
    return ForwardKinematicsResult(
        alpha=np.where(valid, alpha, nan),
        beta=np.where(valid, beta, nan),
        residual=np.where(valid, residual, nan),
        valid=valid,
        converged=converged & valid,
    )


def _fit_beta(
    leg: SphericalLeg, beta: np.ndarray, m1: np.ndarray, m2: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Newton's method on f(b) = 1/2 sum_{i=1,2} (l_i(b) - m_i)^2, batched; returns (beta, converged)."""
    R, r, h = leg.R, leg.r, leg.h
    K = R * R + r * r + h * h
    beta = np.array(beta, dtype=float, copy=True)
    done = np.zeros(beta.shape, dtype=bool)
    for _ in range(FK_MAX_ITER):
        sb, cb = np.sin(beta), np.cos(beta)
        # q_i = l_i^2 and its beta-derivatives (closed forms of the module docstring)
        q = np.stack([K - 2 * R * (r * cb + h * sb), K - 2 * R * (r * cb - h * sb)], -1)
        dq = np.stack([2 * R * (r * sb - h * cb), 2 * R * (r * sb + h * cb)], -1)
        ddq = np.stack([2 * R * (r * cb + h * sb), 2 * R * (r * cb - h * sb)], -1)
        lq = np.sqrt(np.maximum(q, 1e-300))
        dl = dq / (2 * lq)
        ddl = ddq / (2 * lq) - dq * dq / (4 * lq**3)
        res = lq - np.stack([m1, m2], -1)
        g = np.sum(res * dl, -1)
        hn = np.sum(dl * dl + res * ddl, -1)
        hgn = np.sum(dl * dl, -1)  # > 0: dl1 and dl2 never vanish together (R > 0, h > 0, r > 0)
        hess = np.where(hn > 0.5 * hgn, hn, hgn)  # Gauss-Newton curvature where Newton's is unsafe
        step = np.where(done, 0.0, g / hess)
        beta = beta - step
        done = done | (np.abs(step) <= FK_STEP_TOL)
        if np.all(done):
            break
    return beta, done


def jacobian(leg: SphericalLeg, alpha: object, beta: object) -> np.ndarray:
    """``J[..., i, j] = d l_i / d (alpha, beta)_j`` -> (..., 3, 2) in m/rad."""
    a, b = _angles(alpha, beta)
    return _jacobian(leg, np.sin(a), np.cos(a), np.sin(b), np.cos(b))


def _derivatives(leg: SphericalLeg, sa, ca, sb, cb):
    """Squared lengths q (..., 3), dq (..., 3, 2) and d2q (..., 3, 2, 2) w.r.t. (alpha, beta)."""
    R, r, h = leg.R, leg.r, leg.h
    z = np.zeros_like(sa)
    q = _squared_lengths(leg, sa, ca, sb, cb)
    dq = np.stack(
        [
            np.stack([z, 2 * R * (r * sb - h * cb)], -1),
            np.stack([z, 2 * R * (r * sb + h * cb)], -1),
            np.stack([2 * R * (r * sa + h * cb * ca), -2 * R * h * sb * sa], -1),
        ],
        -2,
    )
    d2q = np.stack(
        [
            np.stack([np.stack([z, z], -1), np.stack([z, 2 * R * (r * cb + h * sb)], -1)], -2),
            np.stack([np.stack([z, z], -1), np.stack([z, 2 * R * (r * cb - h * sb)], -1)], -2),
            np.stack(
                [
                    np.stack([2 * R * (r * ca - h * cb * sa), -2 * R * h * sb * ca], -1),
                    np.stack([-2 * R * h * sb * ca, -2 * R * h * cb * sa], -1),
                ],
                -2,
            ),
        ],
        -3,
    )
    return q, dq, d2q


def _jacobian(leg: SphericalLeg, sa, ca, sb, cb) -> np.ndarray:
    R, r, h = leg.R, leg.r, leg.h
    q = _squared_lengths(leg, sa, ca, sb, cb)
    two_l = 2 * np.sqrt(np.maximum(q, LENGTH_FLOOR**2))
    z = np.zeros_like(sa)
    J = np.empty((*sa.shape, 3, 2))
    J[..., 0, 0] = z
    J[..., 1, 0] = z
    J[..., 0, 1] = 2 * R * (r * sb - h * cb) / two_l[..., 0]
    J[..., 1, 1] = 2 * R * (r * sb + h * cb) / two_l[..., 1]
    J[..., 2, 0] = 2 * R * (r * sa + h * cb * ca) / two_l[..., 2]
    J[..., 2, 1] = -2 * R * h * sb * sa / two_l[..., 2]
    return J


def hessian(leg: SphericalLeg, alpha: object, beta: object) -> np.ndarray:
    """``H[..., i, j, k] = d^2 l_i / dq_j dq_k`` with q = (alpha, beta) -> (..., 3, 2, 2) in m/rad^2."""
    a, b = _angles(alpha, beta)
    q, dq, d2q = _derivatives(leg, np.sin(a), np.cos(a), np.sin(b), np.cos(b))
    l = np.sqrt(np.maximum(q, LENGTH_FLOOR**2))[..., None, None]
    # l = sqrt(q): l'' = q''/(2l) - q' q'^T / (4 l^3)
    return d2q / (2 * l) - np.einsum("...ij,...ik->...ijk", dq, dq) / (4 * l**3)


def angular_velocity_jacobian(alpha: object) -> np.ndarray:
    """``E`` with platform angular velocity ``omega = E (alpha_dot, beta_dot)`` (base frame), (..., 3, 2).

    For T = Rx(alpha) Ry(beta): omega = alpha_dot x + beta_dot Rx(alpha) y.
    """
    a = as_array(alpha, "alpha")
    E = np.zeros((*a.shape, 3, 2))
    E[..., 0, 0] = 1.0
    E[..., 1, 1] = np.cos(a)
    E[..., 2, 1] = np.sin(a)
    return E


def influence_coefficients(leg: SphericalLeg, alpha: object, beta: object) -> np.ndarray:
    """First-order influence coefficients: ``ldot = G [omega; v_O]`` -> G (..., 3, 6).

    Row i is the Pluecker line of leg i, ``[(B_i - O) x s_i; s_i]``, acting on the platform twist
    ``[omega; v_O]`` (base frame, reference point O; for this leg v_O = 0 since O is fixed). This is
    paper 1, eqs. (8)-(12) with the reference point moved from P to O; eq. (12)'s first row lacks a
    factor sin(alpha) on its ``R r`` term (errata). ``jacobian = G[..., :3] @ angular_velocity_jacobian``.
    """
    ik = inverse_kinematics(leg, alpha, beta)
    G = np.empty((*ik.lengths.shape[:-1], 3, 6))
    G[..., :3] = np.cross(ik.platform_points, ik.unit_vectors)
    G[..., 3:] = ik.unit_vectors
    return G


def leg_rates(
    leg: SphericalLeg, q: object, qd: object, qdd: object
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Leg lengths, rates and accelerations ``(l, ldot, lddot)`` (each (..., 3)) along q = (alpha, beta).

    ``ldot = J qd``, ``lddot = J qdd + qd^T H qd`` (conventions: H[..., i, j, k] = dJ_ij/dq_k).
    """
    qa = as_array(q, "q", (2,))
    qda = as_array(qd, "qd", (2,))
    qdda = as_array(qdd, "qdd", (2,))
    a, b = qa[..., 0], qa[..., 1]
    sa, ca, sb, cb = np.sin(a), np.cos(a), np.sin(b), np.cos(b)
    qq, dq, d2q = _derivatives(leg, sa, ca, sb, cb)
    l = np.sqrt(np.maximum(qq, LENGTH_FLOOR**2))
    J = dq / (2 * l[..., None])
    H = d2q / (2 * l[..., None, None]) - np.einsum("...ij,...ik->...ijk", dq, dq) / (
        4 * l[..., None, None] ** 3
    )
    ld = np.einsum("...ij,...j->...i", J, qda)
    ldd = np.einsum("...ij,...j->...i", J, qdda) + np.einsum("...ijk,...j,...k->...i", H, qda, qda)
    return l, ld, ldd
