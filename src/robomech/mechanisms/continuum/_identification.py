"""Friction identification as paper 3 does it (eq. (38), Table 1): from actuator-side tensions and the
measured pose, nonlinear least squares for the friction coefficients."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from robomech._validation import as_array, check_bool, check_choice, check_params, check_positive

from ._kinematics import CableModel
from ._params import ContinuumRobot
from ._statics import cable_tensions

__all__ = [
    "IDENTIFY_MU_MAX",
    "IDENTIFY_STIFFNESS_BOUNDS",
    "PoseFrictionEstimate",
    "TipFrictionEstimate",
    "identify_friction_from_pose",
    "identify_friction_from_tip",
]

IDENTIFY_MU_MAX = 2.0
"""Upper bound of the fitted μ (Coulomb coefficients of polymer cable on aluminium are 0.1-0.6; the bound
only keeps the trust region away from exp overflow)."""
_Z95 = 1.959963984540054  # two-sided 95 % quantile of the standard normal


@dataclass(frozen=True)
class PoseFrictionEstimate:
    """Friction coefficients fitted to tensions at measured poses (:func:`identify_friction_from_pose`);
    linearised uncertainties (``docs/mechanisms/continuum.md``, Identification).

    Attributes
    ----------
    mu : ndarray, shape (3 n,)
        Estimated Coulomb friction coefficient per cable (unit-free).
    std, ci_low, ci_high : ndarray, shape (3 n,)
        Its standard deviation (inf where not identifiable) and 95 % confidence bounds.
    residual_rms : float
        RMS of the tension fit residual (N).
    identifiable : ndarray of bool, shape (3 n,)
        The data constrain the cable's μ (its Jacobian column is not zero).
    success : bool
        The solver reported success.
    """

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
    """Paper 3, eq. (38): μ minimising ||τ̃ − τ(μ)||, τ(μ) :func:`cable_tensions` at the measured poses
    ``psi (m, 2 n)``, τ̃ the actuator-side tensions ``t_act (m, 3 n)`` (N) under the sliding ``direction
    (m, 3 n)`` (±1): :class:`PoseFrictionEstimate`.  ``sigma_t`` (N): load-cell noise (``None``: from the
    residuals); ``model`` the cable path of :func:`cable_tensions`.  The paper fits the factors
    exp(−μη) linearly; μ is fitted here (bounded, nonlinear; ``docs/mechanisms/continuum.md``).

    Returns
    -------
    PoseFrictionEstimate
    """
    check_params(robot, ContinuumRobot, "robot")
    n_c = robot.n_cables
    p, t, d = _measurements(psi, "psi", 2 * robot.n_segments, t_act, direction, n_c)
    if sigma_t is not None:
        sigma_t = check_positive(sigma_t, "sigma_t")
    check_choice(model, "model", ("arc", "chord"))

    # paper 3, eq. (38): printed as a linear least-squares fit of the factors eps; eps = exp(-mu eta) of
    # the measured geometry, so mu is fitted here (nonlinear), per cable, with bounds.
    def residual(mu: np.ndarray) -> np.ndarray:
        r = dataclasses.replace(robot, friction=tuple(float(m) for m in mu))
        return (cable_tensions(r, p, direction=d, model=model).tension - t).ravel()

    mu0 = np.clip(robot.friction_array, 0.0, IDENTIFY_MU_MAX)
    sol = least_squares(residual, mu0, bounds=(0.0, IDENTIFY_MU_MAX), x_scale=0.1)
    std, identifiable = _linearised_std(sol.jac, sol.fun, sigma_t**2 if sigma_t is not None else None)
    return PoseFrictionEstimate(
        mu=sol.x,
        std=std,
        ci_low=sol.x - _Z95 * std,
        ci_high=sol.x + _Z95 * std,
        residual_rms=float(np.sqrt(np.mean(sol.fun**2))),
        identifiable=identifiable,
        success=bool(sol.success),
    )


IDENTIFY_STIFFNESS_BOUNDS = (0.25, 4.0)
"""Bounds of the fitted core-stiffness factor EI / EI_robot (the modulus of NiTi spans 40-75 GPa and the
core diameter is not printed: a factor 4 either way covers any plausible core)."""


@dataclass(frozen=True)
class TipFrictionEstimate:
    """Output-error fit of the disk-wise model to tracked tips (:func:`identify_friction_from_tip`);
    linearised uncertainties, s² the tip fit's residual variance (model error included) or 1 (EIV).

    Attributes
    ----------
    mu : ndarray, shape (3 n,)
        Estimated Coulomb friction coefficient per cable (unit-free).
    stiffness_scale : float
        Fitted core-stiffness factor EI / EI_robot (1.0 if not fitted).
    std, ci_low, ci_high : ndarray, shape (3 n,) or (3 n + 1,)
        Standard deviation and 95 % confidence bounds of ``[*mu, stiffness_scale]`` (the last entry
        only if the stiffness was fitted).
    residual_rms : float
        RMS of the tip residual (m).
    identifiable : ndarray of bool, shape (3 n,) or (3 n + 1,)
        Per parameter: the data constrain it (its Jacobian column is not zero).
    success : bool
        The solver reported success and every disk-wise equilibrium converged.
    """

    mu: np.ndarray
    stiffness_scale: float
    std: np.ndarray
    ci_low: np.ndarray
    ci_high: np.ndarray
    residual_rms: float
    identifiable: np.ndarray
    success: bool


def identify_friction_from_tip(
    robot: ContinuumRobot,
    tip: object,
    t_act: object,
    direction: object,
    *,
    fit_stiffness: bool = False,
    initial: object | None = None,
    sigma_t: float | None = None,
    sigma_tip: float | None = None,
) -> TipFrictionEstimate:
    """Friction coefficients (and, with ``fit_stiffness``, the core-stiffness factor EI / EI_robot) from
    tracked tips ``tip (m, 3)`` (m) under measured tensions ``t_act (m, 3 n)`` (N) and ``direction (m, 3 n)``
    (±1): :class:`TipFrictionEstimate`.

    Output error of :func:`disk_equilibrium` started from ``initial (m, 2 n)`` (default straight); with
    ``sigma_t`` (N) and ``sigma_tip`` (m) errors in variables (the measured tensions are noisy inputs:
    taking them as exact biases EI by +5 % and μ by −15 % on reference data).  Departure from paper 3,
    eq. (38) (which fits the tensions at the measured pose): ``docs/mechanisms/continuum.md``, item 13.

    Returns
    -------
    TipFrictionEstimate

    Raises
    ------
    ValueError
        Only one of ``sigma_t``, ``sigma_tip`` given.
    """
    from ._compensation import disk_equilibrium

    check_params(robot, ContinuumRobot, "robot")
    n_c = robot.n_cables
    p, t, d = _measurements(tip, "tip", 3, t_act, direction, n_c)
    fit = check_bool(fit_stiffness, "fit_stiffness")
    init = None if initial is None else as_array(initial, "initial", (2 * robot.n_segments,))
    if init is not None and init.shape != (p.shape[0], 2 * robot.n_segments):
        raise ValueError(f"Expected initial ({p.shape[0]}, {2 * robot.n_segments}), got {init.shape}.")
    if (sigma_t is None) != (sigma_tip is None):
        raise ValueError("Expected both sigma_t and sigma_tip (errors in variables) or neither, got one.")
    eiv = sigma_t is not None
    if eiv:
        sig_t = check_positive(sigma_t, "sigma_t")
        sig_p = check_positive(sigma_tip, "sigma_tip")
    state = {"ok": True}

    def robot_of(x: np.ndarray) -> ContinuumRobot:
        mod = robot.core_modulus * (float(x[n_c]) if fit else 1.0)
        return dataclasses.replace(robot, friction=tuple(float(m) for m in x[:n_c]), core_modulus=mod)

    k_par = n_c + int(fit)
    m = p.shape[0]

    def residual(x: np.ndarray) -> np.ndarray:
        tt = x[k_par:].reshape(m, n_c) if eiv else t
        eq = disk_equilibrium(robot_of(x), tension=np.maximum(tt, 0.0), direction=d, initial=init)
        state["ok"] = bool(np.all(eq.converged))
        r = np.nan_to_num((eq.tip - p).ravel(), nan=1.0)
        if not eiv:
            return r
        return np.concatenate([r / sig_p, (tt - t).ravel() / sig_t])

    x0 = np.clip(robot.friction_array, 0.0, IDENTIFY_MU_MAX)
    lo, hi = np.zeros(n_c), np.full(n_c, IDENTIFY_MU_MAX)
    if fit:
        x0 = np.append(x0, 1.0)
        lo, hi = np.append(lo, IDENTIFY_STIFFNESS_BOUNDS[0]), np.append(hi, IDENTIFY_STIFFNESS_BOUNDS[1])
    x0 = np.clip(x0, lo + 1e-9, hi - 1e-9)
    sparsity = None
    if eiv:
        # the tip of measurement i depends on the parameters and on its own tensions only
        x0 = np.concatenate([x0, t.ravel()])
        lo, hi = np.concatenate([lo, np.zeros(t.size)]), np.concatenate([hi, np.full(t.size, np.inf)])
        sparsity = np.zeros((3 * m + t.size, k_par + t.size), dtype=bool)
        sparsity[: 3 * m, :k_par] = True
        for i in range(m):
            sparsity[3 * i : 3 * i + 3, k_par + n_c * i : k_par + n_c * (i + 1)] = True
        sparsity[3 * m :, k_par:] = np.eye(t.size, dtype=bool)
    sol = least_squares(
        residual,
        x0,
        bounds=(lo, hi),
        x_scale=np.concatenate([np.full(k_par, 0.1), np.full(x0.size - k_par, 0.1)]),
        diff_step=1e-6,
        jac_sparsity=sparsity,
        method="trf",
    )
    residual(sol.x)  # the final state's convergence
    J = sol.jac.toarray() if hasattr(sol.jac, "toarray") else np.asarray(sol.jac)
    std, identifiable = _linearised_std(J, sol.fun, 1.0 if eiv else None)
    std = std[:k_par]
    xp = sol.x[:k_par]
    tip_res = sol.fun[: 3 * m] * (sig_p if eiv else 1.0)
    return TipFrictionEstimate(
        mu=sol.x[:n_c],
        stiffness_scale=float(sol.x[n_c]) if fit else 1.0,
        std=std,
        ci_low=xp - _Z95 * std,
        ci_high=xp + _Z95 * std,
        residual_rms=float(np.sqrt(np.mean(tip_res**2))),
        identifiable=identifiable[:k_par],
        success=bool(sol.success) and state["ok"],
    )


def _linearised_std(J: np.ndarray, fun: np.ndarray, s2: float | None) -> tuple[np.ndarray, np.ndarray]:
    """Standard deviations from the covariance s² (JᵀJ)⁻¹ over the identifiable parameters (inf for the
    others) and the identifiable mask; ``s2`` ``None``: the residual variance."""
    if s2 is None:
        s2 = float(np.sum(fun**2)) / max(J.shape[0] - J.shape[1], 1)
    identifiable = np.linalg.norm(J, axis=0) > 0.0
    cov = np.full((J.shape[1], J.shape[1]), np.inf)
    idx = np.flatnonzero(identifiable)
    if idx.size:
        Ji = J[:, idx]
        cov[np.ix_(idx, idx)] = s2 * np.linalg.pinv(Ji.T @ Ji)
    return np.sqrt(np.diag(cov)), identifiable


def _measurements(
    pose: object, pose_name: str, pose_size: int, t_act: object, direction: object, n_c: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The measured poses ``(m, pose_size)``, actuator-side tensions and sliding directions ``(m, n_c)``
    of an identification data set, validated together (one m >= 1, directions +-1, tensions > 0)."""
    p = as_array(pose, pose_name, (pose_size,))
    t = as_array(t_act, "t_act", (n_c,))
    d = as_array(direction, "direction", (n_c,))
    if p.ndim != 2 or p.shape[0] < 1 or t.shape != (p.shape[0], n_c) or d.shape != t.shape:
        raise ValueError(
            f"Expected {pose_name} (m, {pose_size}), t_act and direction (m, {n_c}) with one m >= 1, got "
            f"{p.shape}, {t.shape}, {d.shape}."
        )
    if np.any((d != 1.0) & (d != -1.0)):
        raise ValueError("Expected direction entries +1 or -1 (a sliding cable), got others.")
    if np.any(t <= 0.0):
        raise ValueError("Expected t_act > 0 (a slack cable carries no friction information).")
    return p, t, d
