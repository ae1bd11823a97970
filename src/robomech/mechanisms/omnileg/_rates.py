"""Inverse differential kinematics of the OmniLeg: ``q̇ = J⁻¹ ṗ``, ``q̈ = J⁻¹ (p̈ - q̇ᵀ H q̇)`` by the SVD of
the foot Jacobian, the weak directions damped where J is near singular (γ ≈ 0)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._batching import carries_failed_rows
from robomech._validation import as_array, broadcast_batch, check_params, check_real
from robomech.analysis.lstsq import _damped_inverse

from ._dynamics import DAMPING_RELATIVE, SINGULAR_RCOND
from ._kinematics import hessian, jacobian
from ._params import OmniLeg

__all__ = ["JointRatesResult", "joint_rates"]

# Default damping of the weak directions: foot_force_from_torques' (no direction amplified by more than
# 1 / (2 SINGULAR_RCOND) = 500: a rate of 1 m/s maps to at most ~500 / sigma_max rad/s).
DEFAULT_DAMPING = DAMPING_RELATIVE


@dataclass(frozen=True)
class JointRatesResult:
    """Joint rates and accelerations per sample for a foot motion (the result of :func:`joint_rates`).

    Attributes
    ----------
    qd, qdd : ndarray, shape (..., 3)
        Joint rates (rad/s) and accelerations (rad/s²; NaN if no foot acceleration was given).
    rcond : ndarray, shape (...)
        ``sigma_min / sigma_max`` of the foot Jacobian (dimensionless).
    singular : ndarray of bool, shape (...)
        ``rcond < SINGULAR_RCOND`` (γ ≈ 0): the weak direction is damped, so the solution is the damped
        least-squares one and the residuals are no longer zero.
    velocity_residual, acceleration_residual : ndarray, shape (...)
        ``|J q̇ - ṗ|`` (m/s) and ``|J q̈ + q̇ᵀ H q̇ - p̈|`` (m/s²; NaN if no foot acceleration was given).
    valid : ndarray of bool, shape (...)
        Not singular and every value finite.
    """

    qd: np.ndarray
    qdd: np.ndarray
    rcond: np.ndarray
    singular: np.ndarray
    velocity_residual: np.ndarray
    acceleration_residual: np.ndarray
    valid: np.ndarray


@carries_failed_rows({"q": 1, "foot_velocity": 1, "foot_acceleration": 1})
def joint_rates(
    leg: OmniLeg,
    q: object,
    foot_velocity: object,
    foot_acceleration: object | None = None,
    *,
    damping: float = DEFAULT_DAMPING,
) -> JointRatesResult:
    """Joint rates ``q̇`` (and accelerations ``q̈``) realising the foot velocity ``ṗ`` (and acceleration ``p̈``).

    Paper 2, eq. (47)'s inverse of the foot Jacobian, regularised at γ = 0: the directions with
    ``σ < SINGULAR_RCOND σ_max`` get ``c = σ / (σ² + λ²)``, ``λ = damping σ_max`` (>= 0; 0: exact, unbounded).

    Parameters
    ----------
    leg : OmniLeg
    q : array_like, shape (..., 3)
    foot_velocity, foot_acceleration : array_like, shape (..., 3)
        ``ṗ`` (m/s) and, optionally, ``p̈`` (m/s²; without it ``qdd`` is NaN), hip frame.
    damping : float, optional

    Returns
    -------
    :class:`JointRatesResult`

    Examples
    --------
    >>> leg = OmniLeg.paper()
    >>> q = np.array([0.1, 0.2, 0.8])
    >>> r = joint_rates(leg, q, jacobian(leg, q) @ [0.3, -0.2, 0.5])   # ṗ of a known q̇
    >>> r.qd.round(12), bool(r.valid)
    (array([ 0.3, -0.2,  0.5]), True)
    """
    check_params(leg, OmniLeg, "leg")
    q = as_array(q, "q", (3,))
    pd = as_array(foot_velocity, "foot_velocity", (3,))
    pdd = None if foot_acceleration is None else as_array(foot_acceleration, "foot_acceleration", (3,))
    damping = check_real(damping, "damping", low=0.0)
    with_pdd = [] if pdd is None else [(pdd, 1, "foot_acceleration")]
    batch = broadcast_batch((q, 1, "q"), (pd, 1, "foot_velocity"), *with_pdd)
    q = np.broadcast_to(q, (*batch, 3))
    pd = np.broadcast_to(pd, (*batch, 3))
    # an overflowing sample (|ṗ| ~ 1e300) becomes non-finite and is flagged below, not warned about
    with np.errstate(over="ignore", invalid="ignore"):
        return _joint_rates(leg, q, pd, pdd, damping, batch)


def _joint_rates(leg, q, pd, pdd, damping, batch) -> JointRatesResult:
    J = jacobian(leg, q)
    s, solve = _damped_inverse(J, rtol=SINGULAR_RCOND, damping=damping)
    rcond = s[..., -1] / s[..., 0]
    qd, v_res = solve(pd)
    if pdd is None:
        qdd = np.full((*batch, 3), np.nan)
        a_res = np.full(batch, np.nan)
    else:
        pdd = np.broadcast_to(pdd, (*batch, 3))
        bias = np.einsum("...ijk,...j,...k->...i", hessian(leg, q), qd, qd)  # q̇ᵀ H q̇
        qdd, a_res = solve(pdd - bias)  # |J q̈ + q̇ᵀ H q̇ - p̈|
    singular = rcond < SINGULAR_RCOND
    finite = np.all(np.isfinite(qd), -1) & (pdd is None or np.all(np.isfinite(qdd), -1))
    return JointRatesResult(
        qd=qd,
        qdd=qdd,
        rcond=rcond,
        singular=singular,
        velocity_residual=v_res,
        acceleration_residual=a_res,
        valid=~singular & finite,
    )
