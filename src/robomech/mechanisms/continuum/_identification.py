"""Friction identification as paper 3 does it (eq. (38), Table 1): from actuator-side tensions and the
measured pose, nonlinear least squares for the friction coefficients."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from robomech._validation import as_array, check_params, check_positive

from ._kinematics import CableModel
from ._params import ContinuumRobot
from ._statics import cable_tensions

__all__ = ["IDENTIFY_MU_MAX", "PoseFrictionEstimate", "identify_friction_from_pose"]

IDENTIFY_MU_MAX = 2.0
"""Upper bound of the fitted μ (Coulomb coefficients of polymer cable on aluminium are 0.1-0.6; the bound
only keeps the trust region away from exp overflow)."""
_Z95 = 1.959963984540054  # two-sided 95 % quantile of the standard normal


@dataclass(frozen=True)
class PoseFrictionEstimate:
    """Least-squares friction coefficients per cable (3 n,) with their standard deviation and 95 %
    confidence interval (linearised: covariance s² (JᵀJ)⁻¹, s² from ``sigma_t`` if given, else from the
    residuals); ``residual_rms`` (N) of the tension fit; ``identifiable`` where the data constrain a
    cable's μ (its Jacobian column is not zero); ``success`` of the solver."""

    mu: np.ndarray
    std: np.ndarray
    ci_low: np.ndarray
    ci_high: np.ndarray
    residual_rms: float
    identifiable: np.ndarray
    success: bool


def identify_friction_from_pose(
    robot: ContinuumRobot,
    psi: object,
    t_act: object,
    direction: object,
    *,
    sigma_t: float | None = None,
    model: CableModel = "chord",
) -> PoseFrictionEstimate:
    """Paper 3, eq. (38): μ minimising ||τ̃ − τ(μ)|| over measurements ``psi (m, 2 n)`` (the pose measured
    at each sample, e.g. by IK of the tracked tip), ``t_act (m, 3 n)`` actuator-side tensions (load cells)
    and ``direction (m, 3 n)`` (±1, the sliding direction the drive imposed).  τ(μ) is
    :func:`cable_tensions` of ``robot`` with friction μ (pretension and stiffness from ``robot``).

    paper 3, eq. (38) fits the friction factors ε by "linear least squares"; the factors are exp(−μη)
    of the geometry, so μ itself is fitted here, nonlinearly (scipy.optimize.least_squares, bounds
    0 ≤ μ ≤ IDENTIFY_MU_MAX).  Table 1's λ (mm) is not defined in the paper and is not fitted.
    """
    check_params(robot, ContinuumRobot, "robot")
    n_c = robot.n_cables
    p = as_array(psi, "psi", (2 * robot.n_segments,))
    t = as_array(t_act, "t_act", (n_c,))
    d = as_array(direction, "direction", (n_c,))
    if p.ndim != 2 or p.shape[0] < 1 or t.shape != (p.shape[0], n_c) or d.shape != t.shape:
        raise ValueError(
            f"Expected psi (m, {2 * robot.n_segments}), t_act and direction (m, {n_c}) with one m >= 1, got "
            f"{p.shape}, {t.shape}, {d.shape}."
        )
    if np.any((d != 1.0) & (d != -1.0)):
        raise ValueError("Expected direction entries +1 or -1 (a sliding cable), got others.")
    if np.any(t <= 0.0):
        raise ValueError("Expected t_act > 0 (a slack cable carries no friction information).")
    if sigma_t is not None:
        sigma_t = check_positive(sigma_t, "sigma_t")
    if model not in ("arc", "chord"):
        raise ValueError(f"Expected model 'arc' or 'chord', got {model!r}.")

    # paper 3, eq. (38): printed as a linear least-squares fit of the factors eps; eps = exp(-mu eta) of
    # the measured geometry, so mu is fitted here (nonlinear), per cable, with bounds.
    def residual(mu: np.ndarray) -> np.ndarray:
        r = dataclasses.replace(robot, friction=tuple(float(m) for m in mu))
        return (cable_tensions(r, p, direction=d, model=model).tension - t).ravel()

    mu0 = np.clip(robot.friction_array, 0.0, IDENTIFY_MU_MAX)
    sol = least_squares(residual, mu0, bounds=(0.0, IDENTIFY_MU_MAX), x_scale=0.1)
    J = sol.jac
    dof = max(J.shape[0] - J.shape[1], 1)
    s2 = sigma_t**2 if sigma_t is not None else float(np.sum(sol.fun**2)) / dof
    identifiable = np.linalg.norm(J, axis=0) > 0.0
    cov = np.full((n_c, n_c), np.inf)
    idx = np.flatnonzero(identifiable)
    if idx.size:
        Ji = J[:, idx]
        cov_i = s2 * np.linalg.pinv(Ji.T @ Ji)
        cov[np.ix_(idx, idx)] = cov_i
    std = np.sqrt(np.diag(cov))
    return PoseFrictionEstimate(
        mu=sol.x,
        std=std,
        ci_low=sol.x - _Z95 * std,
        ci_high=sol.x + _Z95 * std,
        residual_rms=float(np.sqrt(np.mean(sol.fun**2))),
        identifiable=identifiable,
        success=bool(sol.success),
    )
