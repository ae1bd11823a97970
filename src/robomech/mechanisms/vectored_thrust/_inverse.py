"""Inverse rates and accelerations (paper 5, Section 3.3: ``J q̇ = ω``, ``J q̈ = ω̇ - J̇ q̇`` in least
squares, J being 3 x 2) and statics (virtual work, ``τ = -Jᵀ m_O``) of the vectored thruster."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._batching import carries_failed_rows
from robomech._validation import as_array, broadcast_batch, check_params, check_real
from robomech.analysis.lstsq import _damped_inverse

from ._kinematics import _chunked, _jacobian, _q, angular_acceleration
from ._params import VectoredThruster

__all__ = [
    "INPUT_GAIN_MAX",
    "RATE_RESIDUAL_ATOL",
    "RATE_RESIDUAL_RTOL",
    "InverseRatesResult",
    "StaticsResult",
    "inverse_rates",
    "static_torques",
]

# The input rates are q̇ = J⁺ω: an input must turn 1/sigma_min(J) times faster than the platform in
# J's weakest direction.  Beyond 100 (sigma_min < 0.01) the mechanism is flagged singular: a platform
# rate of 0.1 rad/s would already need 10 rad/s at an input (the speed class of the servo motors of
# such thrusters), and the flagged band is the neighbourhood of the idle-input curve and of the
# passive-axes-parallel points; over Table 1's input box sigma_min >= 0.47 (tests).
INPUT_GAIN_MAX = 100.0
# Default damping of the weak direction at flagged samples, relative to sigma_max: with
# lambda = sigma_min_bound = 1 / INPUT_GAIN_MAX no direction is amplified by more than INPUT_GAIN_MAX / 2.
DEFAULT_DAMPING = 1.0 / INPUT_GAIN_MAX
# A commanded ω (ω̇) is realised when the residual |J q̇ - ω| (|J q̈ + J̇q̇ - ω̇|) is at most this
# fraction of the command's size (plus RATE_RESIDUAL_ATOL): at a regular sample q̇ is the exact
# least-squares solution, whose residual for a command in J's range is rounding (~1e-16 |ω| times
# 1/sigma_min <= INPUT_GAIN_MAX); 1e-9 leaves six orders for commands built from rounded data, while a
# command with a component outside the platform's two rotational freedoms leaves a residual of that
# component's size and is not valid.
RATE_RESIDUAL_RTOL = 1e-9
# Absolute floor of that test (rad/s, rad/s²): a zero command has a zero residual to rounding.
RATE_RESIDUAL_ATOL = 1e-12


@dataclass(frozen=True)
class InverseRatesResult:
    """Input rates and accelerations per sample for a commanded platform motion.

    Attributes
    ----------
    qd, qdd : ndarray, shape (..., 2)
        Input rates (rad/s) and accelerations (rad/s²; NaN if no ω̇ was given); NaN where J does not exist.
    sigma_min : ndarray, shape (...)
        Smallest singular value of J (dimensionless; 0 where J does not exist).
    singular : ndarray of bool, shape (...)
        ``sigma_min < 1 / INPUT_GAIN_MAX`` or J does not exist (the weak direction is damped there).
    omega_residual, omega_dot_residual : ndarray, shape (...)
        ``|J q̇ - ω|`` (rad/s; the part of ω outside J's range, or damped) and ``|J q̈ + J̇ q̇ - ω̇|`` (rad/s²;
        NaN if no ω̇ was given).
    valid : ndarray of bool, shape (...)
        Not singular, every value finite and the command realised: ``omega_residual`` (and
        ``omega_dot_residual`` if given) at most ``RATE_RESIDUAL_RTOL`` times the command's norm plus
        ``RATE_RESIDUAL_ATOL`` (a command outside the platform's two rotational freedoms is not valid).
    """

    qd: np.ndarray
    qdd: np.ndarray
    sigma_min: np.ndarray
    singular: np.ndarray
    omega_residual: np.ndarray
    omega_dot_residual: np.ndarray
    valid: np.ndarray


@carries_failed_rows({"q": 1, "omega": 1, "omega_dot": 1})
def inverse_rates(
    th: VectoredThruster,
    q: object,
    omega: object,
    omega_dot: object | None = None,
    *,
    damping: float = DEFAULT_DAMPING,
) -> InverseRatesResult:
    """Input rates ``q̇`` (and accelerations ``q̈``) for the platform's ``omega`` (and ``omega_dot``).

    paper 5, eqs. (22)-(28), with the Lie-bracket velocity products the print drops.

    Parameters
    ----------
    th : VectoredThruster
    q : array_like, shape (..., 2)
    omega, omega_dot : array_like, shape (..., 3)
        Commanded platform angular velocity (rad/s) and acceleration (rad/s², optional: without it
        ``qdd`` is NaN), base frame; broadcast with ``q``.
    damping : float, optional
        Damping (>= 0, relative to sigma_max) of the directions with ``sigma < 1 / INPUT_GAIN_MAX``.

    Returns
    -------
    InverseRatesResult
    """
    check_params(th, VectoredThruster, "th")
    q = _q(q)
    w = as_array(omega, "omega", (3,))
    wd = None if omega_dot is None else as_array(omega_dot, "omega_dot", (3,))
    lam_rel = check_real(damping, "damping", low=0.0)
    with_wd = [] if wd is None else [(wd, 1, "omega_dot")]
    batch = broadcast_batch((q, 1, "q"), (w, 1, "omega"), *with_wd)
    q = np.broadcast_to(q, (*batch, 2))
    w = np.broadcast_to(w, (*batch, 3))
    # an overflowing sample (|ω| ~ 1e300) becomes non-finite and is flagged below, not warned about
    with np.errstate(over="ignore", invalid="ignore"):
        return _inverse_rates(th, q, w, wd, lam_rel, batch)


def _inverse_rates(th, q, w, wd, lam_rel, batch) -> InverseRatesResult:
    jr = _chunked(_jacobian, th, np.ascontiguousarray(q))
    exists = jr.valid
    J = np.where(exists[..., None, None], jr.J, 0.0)
    bound = 1.0 / INPUT_GAIN_MAX
    s, solve = _damped_inverse(J, atol=bound, damping=lam_rel)
    qd, w_res = solve(w)
    sigma_min = np.where(exists, s[..., -1], 0.0)
    singular = ~exists | (sigma_min < bound)
    if wd is None:
        qdd = np.full((*batch, 2), np.nan)
        wd_res = np.full(batch, np.nan)
    else:
        wd = np.broadcast_to(wd, (*batch, 3))
        q_safe = np.where(exists[..., None], q, 0.0)
        qd_safe = np.where(exists[..., None], qd, 0.0)
        vp = angular_acceleration(th, q_safe, qd_safe, np.zeros_like(qd_safe)).velocity_product
        vp = np.where(exists[..., None], vp, 0.0)
        qdd, wd_res = solve(wd - vp)  # |J q̈ + J̇ q̇ - ω̇|
        qdd = np.where(exists[..., None], qdd, np.nan)
        wd_res = np.where(exists, wd_res, np.nan)
    finite = np.all(np.isfinite(qd), -1) & (wd is None or np.all(np.isfinite(qdd), -1))
    realised = w_res <= RATE_RESIDUAL_RTOL * np.linalg.norm(w, axis=-1) + RATE_RESIDUAL_ATOL
    if wd is not None:
        realised &= wd_res <= RATE_RESIDUAL_RTOL * np.linalg.norm(wd, axis=-1) + RATE_RESIDUAL_ATOL
    return InverseRatesResult(
        qd=np.where(exists[..., None], qd, np.nan),
        qdd=qdd,
        sigma_min=sigma_min,
        singular=singular,
        omega_residual=np.where(exists, w_res, np.nan),
        omega_dot_residual=wd_res,
        # a flag never says valid where a value overflowed (e.g. |ω| ~ 1e300) or ω is not realised
        valid=~singular & finite & realised,
    )


@dataclass(frozen=True)
class StaticsResult:
    """Motor torques holding a wrench on the platform; only its moment about O loads the motors.

    Attributes
    ----------
    tau : ndarray, shape (..., 2)
        Motor torques on the inputs q1, q2 (N·m); NaN where not ``valid``.
    moment : ndarray, shape (..., 3)
        Moment of the wrench about O (N·m, base frame).
    unloaded : ndarray, shape (..., 3)
        Component of ``moment`` outside J's range (N·m), carried without motor torque.
    valid : ndarray of bool, shape (...)
        J exists (passive axes not parallel) and the torques are finite.
    """

    tau: np.ndarray
    moment: np.ndarray
    unloaded: np.ndarray
    valid: np.ndarray


@carries_failed_rows({"q": 1}, {"wrench": 1})
def static_torques(th: VectoredThruster, q: object, wrench: object) -> StaticsResult:
    """Motor torques ``τ = -Jᵀ m_O`` holding the platform against a wrench (virtual work
    ``τ·q̇ + m_O·ω = 0``: the force passes through O and needs no motor torque).

    Parameters
    ----------
    th : VectoredThruster
    q : array_like, shape (..., 2)
    wrench : array_like, shape (..., 6)
        ``[m_O; f]`` applied to the platform (N·m, N; base frame, moment about O); a propeller's
        thrust T and reaction torque Q about its shaft s0 are ``[Q s0; T s0]``.

    Returns
    -------
    StaticsResult

    Examples
    --------
    >>> th = VectoredThruster.paper()
    >>> r = static_torques(th, [0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 10.0])  # thrust along s0 = +Z
    >>> bool(np.allclose(r.tau, 0.0)), bool(r.valid)
    (True, True)
    """
    check_params(th, VectoredThruster, "th")
    q = _q(q)
    wr = as_array(wrench, "wrench", (6,))
    batch = broadcast_batch((q, 1, "q"), (wr, 1, "wrench"))
    q = np.broadcast_to(q, (*batch, 2))
    m = np.broadcast_to(wr[..., :3], (*batch, 3))
    jr = _chunked(_jacobian, th, np.ascontiguousarray(q))
    J = np.where(jr.valid[..., None, None], jr.J, 0.0)
    with np.errstate(over="ignore", invalid="ignore"):  # overflow -> non-finite -> flagged below
        return _statics(J, m, jr.valid)


def _statics(J: np.ndarray, m: np.ndarray, exists: np.ndarray) -> StaticsResult:
    tau = -np.einsum("...ij,...i->...j", J, m)
    # component of m_O orthogonal to range(J): spanned by the normal n = J1 x J2 of the two columns
    n = np.cross(J[..., :, 0], J[..., :, 1])
    nn = np.sum(n * n, -1)
    unloaded = n * (np.sum(n * m, -1) / np.where(nn > 0, nn, 1.0))[..., None]
    ok = exists & np.all(np.isfinite(tau), -1)
    return StaticsResult(
        tau=np.where(ok[..., None], tau, np.nan),
        moment=np.array(m),
        unloaded=np.where(ok[..., None], unloaded, np.nan),
        valid=ok,
    )
