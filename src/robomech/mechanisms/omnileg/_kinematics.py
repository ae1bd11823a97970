"""Foot kinematics of the OmniLeg: eq. (11) forward, the corrected eq. (13) inverse, Jacobian, Hessian.

The thigh's knee point O0' lies on a sphere of radius L1 about O0: ``p_knee = L1 u`` with
``u = (tan β, -tan α, 1) / sqrt(1 + tan²α + tan²β)``, the same vector as eq. (9)/(11) written with
``cos β`` factored out.  The shank adds ``(0, 0, L5 + 2 L4 cos γ)`` (crank-slider, eq. (10)).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._validation import as_array

from ._params import OmniLeg

__all__ = [
    "IKResult",
    "foot_acceleration",
    "foot_velocity",
    "forward_kinematics",
    "hessian",
    "inverse_kinematics",
    "jacobian",
    "passive_angles",
    "thigh_direction",
    "within_limits",
]

# A foot whose horizontal distance from Z0 reaches L1 (1 - IK_HORIZONTAL_MARGIN) would need the thigh
# horizontal (|α| or |β| -> 90°), outside every joint range; the margin only keeps sqrt() real.
IK_HORIZONTAL_MARGIN = 1e-12
# cos γ computed from a reachable foot depth can exceed 1 by rounding (a few ulps of P_z / 2 L4 near the
# fully extended shank); values within this are clamped to 1, beyond it the depth is unreachable.
COS_GAMMA_ROUNDING = 1e-12
# Joint limits are inclusive up to rounding of degree-to-radian conversions.
LIMIT_SLACK = 1e-12


def _q(q: object) -> np.ndarray:
    return as_array(q, "q", (3,))


def thigh_direction(alpha: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Unit vector from O0 to the knee O0' (..., 3), paper 2, eq. (9) divided by L1."""
    a, b = np.tan(alpha), np.tan(beta)
    inv = 1.0 / np.sqrt(1.0 + a * a + b * b)
    return np.stack([b * inv, -a * inv, inv], axis=-1)


def forward_kinematics(leg: OmniLeg, q: object) -> np.ndarray:
    """Foot position ``p_F`` in the hip frame (..., 3), metres, from ``q = (α, β, γ)`` (..., 3), rad.

    Exactly paper 2, eq. (11) (Z0 toward the foot).
    """
    q = _q(q)
    alpha, beta, gamma = q[..., 0], q[..., 1], q[..., 2]
    cb = np.cos(beta)
    ta = np.tan(alpha)
    den = np.sqrt(1.0 + cb * cb * ta * ta)
    return np.stack(
        [
            leg.L1 * np.sin(beta) / den,  # paper 2, eq. (11)
            -leg.L1 * cb * ta / den,
            leg.L1 * cb / den + 2.0 * leg.L4 * np.cos(gamma) + leg.L5,
        ],
        axis=-1,
    )


def passive_angles(leg: OmniLeg, alpha: object, beta: object) -> tuple[np.ndarray, np.ndarray]:
    """Passive U-joint angles θ12 (chain 1, about x at A1) and θ22 (chain 2, about -y at A2), rad.

    paper 2, eq. (12): θ12 = arctan(tan α cos β) as printed; θ22 printed as +arctan(tan β cos α) but
    with chain 2's second axis ω22 = Rz(-π/2)[1 0 0] = [0 -1 0] (eqs. (1), (5), (6)) the closure gives
    θ22 = -arctan(tan β cos α).
    """
    a = as_array(alpha, "alpha")
    b = as_array(beta, "beta")
    theta12 = np.arctan(np.tan(a) * np.cos(b))
    theta22 = -np.arctan(np.tan(b) * np.cos(a))  # paper 2, eq. (12): printed +; the closure gives -
    return theta12, theta22


def _dw(q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """w = (tan β, -tan α, 1), its q-Jacobian (..., 3, 3), u = w/|w| and N = |w|."""
    a, b = np.tan(q[..., 0]), np.tan(q[..., 1])
    N = np.sqrt(1.0 + a * a + b * b)
    u = np.stack([b, -a, np.ones_like(a)], axis=-1) / N[..., None]
    W = np.zeros((*q.shape[:-1], 3, 3))
    W[..., 1, 0] = -(1.0 + a * a)
    W[..., 0, 1] = 1.0 + b * b
    return u, N, W, np.stack([a, b], axis=-1)


def jacobian(leg: OmniLeg, q: object) -> np.ndarray:
    """Foot Jacobian ``J[..., i, j] = ∂p_F,i/∂q_j`` (..., 3, 3), eq. (14).  Singular whenever γ = 0."""
    q = _q(q)
    u, N, W, _ = _dw(q)
    D1 = (np.eye(3) - u[..., :, None] * u[..., None, :]) / N[..., None, None]
    J = leg.L1 * D1 @ W
    J[..., 2, 2] = -2.0 * leg.L4 * np.sin(q[..., 2])
    return J


def hessian(leg: OmniLeg, q: object) -> np.ndarray:
    """Second-order influence coefficients ``H[..., i, j, k] = ∂²p_F,i/∂q_j∂q_k`` (..., 3, 3, 3)."""
    q = _q(q)
    u, N, W, ab = _dw(q)
    eye = np.eye(3)
    # ∂²(w/|w|)_i/∂w_a∂w_b = -(δ_ia u_b + δ_ib u_a + δ_ab u_i - 3 u_i u_a u_b) / |w|²
    D2 = (
        -(
            eye[:, :, None] * u[..., None, None, :]
            + eye[:, None, :] * u[..., None, :, None]
            + eye[None, :, :] * u[..., :, None, None]
            - 3.0 * u[..., :, None, None] * u[..., None, :, None] * u[..., None, None, :]
        )
        / (N * N)[..., None, None, None]
    )
    D1 = (eye - u[..., :, None] * u[..., None, :]) / N[..., None, None]
    a, b = ab[..., 0], ab[..., 1]
    W2 = np.zeros((*q.shape[:-1], 3, 3, 3))
    W2[..., 1, 0, 0] = -2.0 * a * (1.0 + a * a)
    W2[..., 0, 1, 1] = 2.0 * b * (1.0 + b * b)
    H = leg.L1 * (
        np.einsum("...iab,...aj,...bk->...ijk", D2, W, W) + np.einsum("...ia,...ajk->...ijk", D1, W2)
    )
    H[..., 2, 2, 2] = -2.0 * leg.L4 * np.cos(q[..., 2])
    return H


def foot_velocity(leg: OmniLeg, q: object, qd: object) -> np.ndarray:
    """``v_F = J q̇`` (..., 3), m/s."""
    qd = as_array(qd, "qd", (3,))
    return np.einsum("...ij,...j->...i", jacobian(leg, q), qd)


def foot_acceleration(leg: OmniLeg, q: object, qd: object, qdd: object) -> np.ndarray:
    """``a_F = J q̈ + q̇ᵀ H q̇`` (..., 3), m/s² (the foot does not rotate, Section 2)."""
    qd = as_array(qd, "qd", (3,))
    qdd = as_array(qdd, "qdd", (3,))
    return np.einsum("...ij,...j->...i", jacobian(leg, q), qdd) + np.einsum(
        "...ijk,...j,...k->...i", hessian(leg, q), qd, qd
    )


def within_limits(leg: OmniLeg, q: object) -> np.ndarray:
    """Per-sample mask: |α| ≤ α_max, |β| ≤ β_max, γ_min ≤ γ ≤ γ_max (Table 2 as magnitudes)."""
    q = as_array(q, "q", (3,), finite=False)
    with np.errstate(invalid="ignore"):
        return (
            (np.abs(q[..., 0]) <= leg.alpha_max + LIMIT_SLACK)
            & (np.abs(q[..., 1]) <= leg.beta_max + LIMIT_SLACK)
            & (q[..., 2] >= leg.gamma_min - LIMIT_SLACK)
            & (q[..., 2] <= leg.gamma_max + LIMIT_SLACK)
        )


@dataclass(frozen=True)
class IKResult:
    """Inverse kinematics per sample.

    ``q (..., 3)`` is NaN exactly where ``exists`` is false (no real solution: the foot is farther than
    L1 from Z0 horizontally, or deeper/shallower than the shank can reach).  ``within_limits`` checks the
    joint ranges; ``reachable = exists & within_limits``.  ``residual`` is ``|FK(q) - p|`` (m).
    """

    q: np.ndarray
    exists: np.ndarray
    within_limits: np.ndarray
    reachable: np.ndarray
    residual: np.ndarray


def inverse_kinematics(leg: OmniLeg, p_foot: object) -> IKResult:
    """Joint angles ``(α, β, γ)`` for foot positions ``p_foot (..., 3)`` (m), branch γ ≥ 0.

    paper 2, eq. (13) corrected: α = arctan(-P_y / s) (printed without the minus, inconsistent with
    eq. (11)); γ = arccos((P_z - L5 - s) / (2 L4)) (printed with only s divided by 2 L4), where
    ``s = sqrt(L1² - P_x² - P_y²)`` is the depth of the knee below O0.  Non-finite input samples are
    flagged (``exists`` false), not raised.
    """
    p = as_array(p_foot, "p_foot", (3,), finite=False)
    finite = np.all(np.isfinite(p), axis=-1)
    px = np.where(finite, p[..., 0], 0.0)
    py = np.where(finite, p[..., 1], 0.0)
    pz = np.where(finite, p[..., 2], 0.0)
    rho2 = px * px + py * py
    s2 = leg.L1 * leg.L1 - rho2
    thigh_ok = s2 > (leg.L1 * leg.L1) * IK_HORIZONTAL_MARGIN
    s = np.sqrt(np.where(thigh_ok, s2, 1.0))
    alpha = np.arctan2(-py, s)  # paper 2, eq. (13): printed arctan(P_y / s); eq. (11) needs the minus
    beta = np.arctan2(px, s)
    c = (pz - leg.L5 - s) / (2.0 * leg.L4)  # paper 2, eq. (13): the whole numerator is over 2 L4
    shank_ok = (c <= 1.0 + COS_GAMMA_ROUNDING) & (c > 0.0)
    gamma = np.arccos(np.clip(c, -1.0, 1.0))
    exists = finite & thigh_ok & shank_ok
    q = np.where(exists[..., None], np.stack([alpha, beta, gamma], axis=-1), np.nan)
    q_safe = np.where(exists[..., None], q, 0.0)
    resid = np.where(
        exists,
        np.linalg.norm(forward_kinematics(leg, q_safe) - np.where(finite[..., None], p, 0), axis=-1),
        np.nan,
    )
    lim = within_limits(leg, q_safe) & exists
    return IKResult(q=q, exists=exists, within_limits=lim, reachable=exists & lim, residual=resid)
