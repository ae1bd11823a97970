"""Foot kinematics of the OmniLeg: eq. (11) forward (the knee ``L1 w/|w|``, not mirrored beyond 90°), the
corrected eq. (13) inverse, Jacobian, Hessian; ``q = (α, β, γ)`` (rad) throughout (docs/mechanisms/omnileg.md,
"Beyond 90°" and "Departures")."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from robomech._batching import carries_failed_rows, slices
from robomech._validation import as_array, broadcast_batch, check_params

# sin, cos from the half-angle tangent: numpy's tan is SIMD-vectorised, sin/cos are not (~3x faster,
# a few ulps; the unvalidated kernel, inputs are validated at this module's boundary)
from robomech.spatial._so3 import _sincos as sincos

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
# Samples per chunk of the elementwise kernels: 32768 doubles = 256 KiB per temporary, which keeps the
# kernels' dozen temporaries in L2 (measured 2-3x faster than whole 1e6-sample arrays).
KIN_CHUNK = 32768


def _q(q: object) -> np.ndarray:
    return as_array(q, "q", (3,))


@carries_failed_rows({"alpha": 0, "beta": 0})
def thigh_direction(alpha: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Unit vector ``w / |w|`` from O0 to the knee O0' (paper 2, eq. (9) divided by L1, x corrected).

    Parameters
    ----------
    alpha, beta : array_like, shape (...)
        Active thigh angles α (about X0) and β (about Y0), rad; broadcast together.

    Returns
    -------
    ndarray, shape (..., 3)
    """
    a, b = as_array(alpha, "alpha"), as_array(beta, "beta")
    broadcast_batch((a, 0, "alpha"), (b, 0, "beta"))
    ca, sa, cb, sb = np.cos(a), np.sin(a), np.cos(b), np.sin(b)
    inv = 1.0 / np.sqrt(ca * ca + (cb * sa) ** 2)
    return np.stack([sb * ca * inv, -cb * sa * inv, cb * ca * inv], axis=-1)


@carries_failed_rows({"q": 1})
def forward_kinematics(leg: OmniLeg, q: object) -> np.ndarray:
    """Foot position ``p_F`` (m) in the hip frame (paper 2, eq. (11); Z0 toward the foot).

    Parameters
    ----------
    leg : OmniLeg
    q : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3)
    """
    check_params(leg, OmniLeg, "leg")
    q = _q(q)
    qf = q.reshape(-1, 3)
    out = np.empty_like(qf)
    L1, L4, L5 = leg.L1, leg.L4, leg.L5
    for s in slices(qf.shape[0], KIN_CHUNK):
        alpha, beta, gamma = qf[s, 0], qf[s, 1], qf[s, 2]
        sa, ca = sincos(alpha)
        sb, cb = sincos(beta)
        cbsa = cb * sa
        inv = L1 / np.sqrt(ca * ca + cbsa * cbsa)
        # paper 2, eq. (11) multiplied through by cos α: identical for |α| < 90°, and not mirrored beyond
        cainv = ca * inv
        out[s, 0] = sb * cainv
        out[s, 1] = -cbsa * inv
        out[s, 2] = cb * cainv + 2.0 * L4 * sincos(gamma)[1] + L5
    return out.reshape(q.shape)


@carries_failed_rows({"alpha": 0, "beta": 0})
def passive_angles(leg: OmniLeg, alpha: object, beta: object) -> tuple[np.ndarray, np.ndarray]:
    """Passive U-joint angles θ12 (chain 1, about x at A1) and θ22 (chain 2, about -y at A2), rad.

    paper 2, eq. (12): θ22 printed as +arctan(tan β cos α); chain 2's second axis ω22 = [0 -1 0]
    (eqs. (1), (5), (6)) gives the minus.  atan2 forms: continuous beyond 90°, where arctan mirrors.

    Parameters
    ----------
    leg : OmniLeg
    alpha, beta : array_like, shape (...)

    Returns
    -------
    theta12, theta22 : ndarray, shape (...)
    """
    check_params(leg, OmniLeg, "leg")
    a = as_array(alpha, "alpha")
    b = as_array(beta, "beta")
    broadcast_batch((a, 0, "alpha"), (b, 0, "beta"))
    theta12 = np.arctan2(np.sin(a) * np.cos(b), np.cos(a))  # paper 2, eq. (12), cos α multiplied through
    theta22 = -np.arctan2(np.sin(b) * np.cos(a), np.cos(b))  # paper 2, eq. (12): printed +; closure gives -
    return theta12, theta22


def _dw(q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """w = (sβ cα, -cβ sα, cβ cα), its q-Jacobian W (..., 3, 3), u = w/|w|, N = |w|, ∂²w (..., 3, 3, 3)."""
    ca, sa, cb, sb = np.cos(q[..., 0]), np.sin(q[..., 0]), np.cos(q[..., 1]), np.sin(q[..., 1])
    w = np.stack([sb * ca, -cb * sa, cb * ca], axis=-1)
    N = np.sqrt(np.sum(w * w, axis=-1))
    u = w / N[..., None]
    W = np.zeros((*q.shape[:-1], 3, 3))
    W[..., :, 0] = np.stack([-sb * sa, -cb * ca, -cb * sa], axis=-1)  # ∂w/∂α
    W[..., :, 1] = np.stack([cb * ca, sb * sa, -sb * ca], axis=-1)  # ∂w/∂β
    W2 = np.zeros((*q.shape[:-1], 3, 3, 3))
    W2[..., :, 0, 0] = -w  # ∂²w/∂α² = ∂²w/∂β² = -w
    W2[..., :, 1, 1] = -w
    cross = np.stack([-cb * sa, sb * ca, sb * sa], axis=-1)  # ∂²w/∂α∂β
    W2[..., :, 0, 1] = cross
    W2[..., :, 1, 0] = cross
    return u, N, W, W2


@carries_failed_rows({"q": 1})
def jacobian(leg: OmniLeg, q: object) -> np.ndarray:
    """Foot Jacobian ``J[..., i, j] = ∂p_F,i/∂q_j`` (m/rad), eq. (14); singular whenever γ = 0.

    ``∂p/∂(α, β) = L1 (I - u uᵀ) ∂w/∂(α, β) / |w|``, ``∂p/∂γ = (0, 0, -2 L4 sin γ)``.

    Parameters
    ----------
    leg : OmniLeg
    q : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    check_params(leg, OmniLeg, "leg")
    q = _q(q)
    qf = q.reshape(-1, 3)
    J = np.zeros((qf.shape[0], 3, 3))
    for s in slices(qf.shape[0], KIN_CHUNK):
        sa, ca = sincos(qf[s, 0])
        sb, cb = sincos(qf[s, 1])
        inv = 1.0 / np.sqrt(ca * ca + (cb * sa) ** 2)
        u = (sb * ca * inv, -cb * sa * inv, cb * ca * inv)
        k = leg.L1 * inv
        for j, dw in enumerate(((-sb * sa, -cb * ca, -cb * sa), (cb * ca, sb * sa, -sb * ca))):
            ud = u[0] * dw[0] + u[1] * dw[1] + u[2] * dw[2]
            for i in range(3):
                J[s, i, j] = k * (dw[i] - u[i] * ud)
        J[s, 2, 2] = -2.0 * leg.L4 * sincos(qf[s, 2])[0]
    return J.reshape(*q.shape, 3)


@carries_failed_rows({"q": 1})
def hessian(leg: OmniLeg, q: object) -> np.ndarray:
    """Second-order influence coefficients ``H[..., i, j, k] = ∂²p_F,i/∂q_j∂q_k`` (m/rad²): ∂J/∂q.

    Parameters
    ----------
    leg : OmniLeg
    q : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3, 3)
    """
    check_params(leg, OmniLeg, "leg")
    q = _q(q)
    u, N, W, W2 = _dw(q)
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
    H = leg.L1 * (
        np.einsum("...iab,...aj,...bk->...ijk", D2, W, W) + np.einsum("...ia,...ajk->...ijk", D1, W2)
    )
    H[..., 2, 2, 2] = -2.0 * leg.L4 * np.cos(q[..., 2])
    return H


@carries_failed_rows({"q": 1, "qd": 1})
def foot_velocity(leg: OmniLeg, q: object, qd: object) -> np.ndarray:
    """Foot velocity ``v_F = J q̇`` (m/s, hip frame; paper 2, eq. (14)).

    Parameters
    ----------
    leg : OmniLeg
    q, qd : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3)
    """
    check_params(leg, OmniLeg, "leg")
    qd = as_array(qd, "qd", (3,))
    broadcast_batch((_q(q), 1, "q"), (qd, 1, "qd"))
    return np.einsum("...ij,...j->...i", jacobian(leg, q), qd)


@carries_failed_rows({"q": 1, "qd": 1, "qdd": 1})
def foot_acceleration(leg: OmniLeg, q: object, qd: object, qdd: object) -> np.ndarray:
    """Foot acceleration ``a_F = J q̈ + q̇ᵀ H q̇`` (m/s², hip frame; the foot does not rotate, Section 2).

    Parameters
    ----------
    leg : OmniLeg
    q, qd, qdd : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3)
    """
    check_params(leg, OmniLeg, "leg")
    qd = as_array(qd, "qd", (3,))
    qdd = as_array(qdd, "qdd", (3,))
    broadcast_batch((_q(q), 1, "q"), (qd, 1, "qd"), (qdd, 1, "qdd"))
    return np.einsum("...ij,...j->...i", jacobian(leg, q), qdd) + np.einsum(
        "...ijk,...j,...k->...i", hessian(leg, q), qd, qd
    )


def within_limits(leg: OmniLeg, q: object) -> np.ndarray:
    """Per-sample mask: |α| ≤ α_max, |β| ≤ β_max, γ_min ≤ γ ≤ γ_max (Table 2 as magnitudes).

    Parameters
    ----------
    leg : OmniLeg
    q : array_like, shape (..., 3)

    Returns
    -------
    ndarray of bool, shape (...)
        Inclusive, up to ``LIMIT_SLACK``; False for non-finite samples.
    """
    check_params(leg, OmniLeg, "leg")
    q = as_array(q, "q", (3,), finite=False)
    with np.errstate(invalid="ignore"):
        return _within(leg, q[..., 0], q[..., 1], q[..., 2])


def _within(leg: OmniLeg, alpha: np.ndarray, beta: np.ndarray, gamma: np.ndarray) -> np.ndarray:
    return (
        (np.abs(alpha) <= leg.alpha_max + LIMIT_SLACK)
        & (np.abs(beta) <= leg.beta_max + LIMIT_SLACK)
        & (gamma >= leg.gamma_min - LIMIT_SLACK)
        & (gamma <= leg.gamma_max + LIMIT_SLACK)
    )


@dataclass(frozen=True)
class IKResult:
    """Inverse kinematics per sample (the result of :func:`inverse_kinematics`).

    Attributes
    ----------
    q : ndarray, shape (..., 3)
        Joint angles ``(α, β, γ)`` (rad), branch γ ≥ 0; NaN where no solution exists.
    exists, within_limits, reachable : ndarray of bool, shape (...)
        A real solution exists (the foot within L1 of Z0 horizontally and within the shank's depths); it is
        within the joint ranges; ``exists & within_limits``.
    leg : OmniLeg
    p_foot : ndarray, shape (..., 3)
        The requested foot positions (m, hip frame).
    residual : ndarray, shape (...)
        ``|FK(q) - p_foot|`` (m), NaN where no solution exists (computed on first access: it costs
        a forward kinematics).
    """

    q: np.ndarray
    exists: np.ndarray
    within_limits: np.ndarray
    reachable: np.ndarray
    leg: OmniLeg = field(repr=False, compare=False)
    p_foot: np.ndarray = field(repr=False, compare=False)

    @cached_property
    def residual(self) -> np.ndarray:
        q_safe = np.where(self.exists[..., None], self.q, 0.0)
        p_safe = np.where(self.exists[..., None], self.p_foot, 0.0)
        r = np.linalg.norm(forward_kinematics(self.leg, q_safe) - p_safe, axis=-1)
        return np.where(self.exists, r, np.nan)


def inverse_kinematics(leg: OmniLeg, p_foot: object) -> IKResult:
    """Joint angles ``(α, β, γ)`` for foot positions ``p_foot (..., 3)`` (m), branch γ ≥ 0.

    Paper 2, eq. (13), two misprints corrected (at the lines), with the knee's depth below O0
    ``s = sqrt(L1² - P_x² - P_y²)``.  Non-finite samples are flagged.

    Parameters
    ----------
    leg : OmniLeg
    p_foot : array_like, shape (..., 3)

    Returns
    -------
    :class:`IKResult`

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.mechanisms import omnileg as ol
    >>> leg = ol.OmniLeg.paper()
    >>> p = ol.forward_kinematics(leg, np.array([0.1, 0.2, 0.8]))
    >>> ik = ol.inverse_kinematics(leg, p)
    >>> ik.q.round(12), bool(ik.reachable)                      # the round trip
    (array([0.1, 0.2, 0.8]), True)
    """
    check_params(leg, OmniLeg, "leg")
    p = as_array(p_foot, "p_foot", (3,), finite="mask")  # NaN, inf, beyond 1e100: masked
    pf = p.reshape(-1, 3)
    n = pf.shape[0]
    q = np.empty((n, 3))
    exists = np.empty(n, dtype=bool)
    lim = np.empty(n, dtype=bool)
    L1, L4, L5 = leg.L1, leg.L4, leg.L5
    for s in slices(n, KIN_CHUNK):
        finite = np.isfinite(pf[s]).all(axis=-1)
        ps = pf[s] if finite.all() else np.where(finite[:, None], pf[s], 0.0)  # non-finite: flagged below
        px, py, pz = ps[:, 0], ps[:, 1], ps[:, 2]
        s2 = L1 * L1 - (px * px + py * py)
        thigh_ok = s2 > (L1 * L1) * IK_HORIZONTAL_MARGIN
        depth = np.sqrt(np.where(thigh_ok, s2, 1.0))
        c = (pz - L5 - depth) / (2.0 * L4)  # paper 2, eq. (13): the whole numerator is over 2 L4
        ok = finite & thigh_ok & (c <= 1.0 + COS_GAMMA_ROUNDING) & (c > 0.0)
        a, b = -py / depth, px / depth  # tan α, tan β (depth > 0)
        alpha = np.arctan(a)  # paper 2, eq. (13): printed arctan(P_y / s); eq. (11) needs the minus
        beta = np.arctan(b)
        gamma = np.arccos(np.clip(c, -1.0, 1.0))
        exists[s] = ok
        q[s, 0] = alpha
        q[s, 1] = beta
        q[s, 2] = gamma
        if not ok.all():  # NaN exactly where no solution exists
            q[s][~ok] = np.nan
        lim[s] = ok & _within(leg, alpha, beta, gamma)
    batch = p.shape[:-1]
    return IKResult(
        q=q.reshape(p.shape),
        exists=exists.reshape(batch),
        within_limits=lim.reshape(batch),
        reachable=(exists & lim).reshape(batch),
        leg=leg,
        p_foot=p,
    )
