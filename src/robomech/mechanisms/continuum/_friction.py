"""Cable friction: wrap angles from the geometry, capstan transfer along the disks, the improved
capstan equation of a cable-pulley system (paper 3, eqs. (29)-(32)), and friction identification.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._batching import carries_failed_rows
from robomech._validation import as_array, broadcast_batch, check_params, check_positive

from ._kinematics import _disk_T, _span_active, _split
from ._params import ContinuumRobot

__all__ = [
    "CAPSTAN_ACCURACY",
    "CAPSTAN_FIRST_STEP",
    "CAPSTAN_H_MAX",
    "CAPSTAN_LAYER_STEPS",
    "CAPSTAN_MAX_STEPS",
    "CAPSTAN_STABILITY",
    "FrictionEstimate",
    "TensionHistory",
    "capstan_coefficient",
    "capstan_tension_ratio",
    "classical_capstan_ratio",
    "friction_factors",
    "identify_friction",
    "stick_slip_tensions",
    "wrap_angles",
]


# ---- wrap angles and the capstan transfer along the disks -----------------------------------------
def _wrap(robot: ContinuumRobot, theta: np.ndarray, beta: np.ndarray) -> np.ndarray:
    return _wrap_from_disks(robot, _disk_T(robot, theta, beta))


def _wrap_from_disks(robot: ContinuumRobot, T: np.ndarray) -> np.ndarray:
    """Wrap angles (..., 3n, nN) from the base plate and disk poses T (..., 1 + nN, 4, 4)."""
    r, sig = robot.hole_radius, robot.hole_angles
    holes_local = np.stack([r * np.cos(sig), r * np.sin(sig), np.zeros_like(sig)], -1)  # (3n, 3)
    holes = np.einsum("...kab,cb->...cka", T[..., :3, :3], holes_local) + T[..., None, :, :3, 3]
    chords = np.diff(holes, axis=-2)  # (..., 3n, nN, 3)
    # paper 3, eq. (21): printed h = h / |h| with the chord undefined; the unit chord between
    # consecutive holes is meant.
    b = chords / np.linalg.norm(chords, axis=-1, keepdims=True)
    incoming = np.concatenate([np.broadcast_to([0.0, 0.0, 1.0], (*b.shape[:-2], 1, 3)), b[..., :-1, :]], -2)
    # paper 3, eq. (22): eta = arccos(b_k . b_k+1); 2 atan2(|a - b|, |a + b|) is the same angle without
    # arccos's loss of accuracy near 0.
    eta = 2.0 * np.arctan2(np.linalg.norm(b - incoming, axis=-1), np.linalg.norm(b + incoming, axis=-1))
    return np.where(_span_active(robot), eta, 0.0)


@carries_failed_rows({"psi": 1})
def wrap_angles(robot: ContinuumRobot, psi: object) -> np.ndarray:
    """Wrap angle eta ``(..., 3 n, n N)`` (rad) of every cable at the hole where each span starts
    (paper 3, eqs. (21)-(22)).

    Span 0 starts at the base plate, where the cable arrives along the base z axis; span k at disk k.
    Zero beyond the cable's termination disk.

    Returns
    -------
    ndarray, shape (..., 3 n, n N)
    """
    check_params(robot, ContinuumRobot, "robot")
    theta, beta = _split(robot, psi)
    return _wrap(robot, theta, beta)


def _as_direction(robot: ContinuumRobot, direction: object | None, batch: tuple[int, ...]) -> np.ndarray:
    if direction is None:
        return np.zeros((*batch, robot.n_cables))
    d = as_array(direction, "direction", (robot.n_cables,))
    # paper 3, eq. (19): the stuck branch (q_dot = 0) keeps the previous tension, which needs a stick-slip
    # model with memory; it is not implemented, so a sticking cable with friction is refused instead of
    # silently getting the frictionless tension.  0 is accepted where mu = 0.
    sliding = (d == 1.0) | (d == -1.0)
    if np.any(~sliding & (robot.friction_array > 0.0)):
        raise ValueError(
            "Expected direction +1 (pulled in) or -1 (paid out) for every cable with friction, got other "
            "values (0 = sticking: a stuck cable's tension depends on its history, see simulate_history "
            "and stick_slip_tensions; pass direction=None for the frictionless model)."
        )
    return d


def _factors(robot: ContinuumRobot, eta: np.ndarray, direction: np.ndarray) -> np.ndarray:
    mu = robot.friction_array
    # paper 3, eqs. (17)-(19) and (23): friction opposes sliding, so a cable pulled in by the actuator
    # (direction +1) loses tension distally: T_k+1 = T_k exp(-mu eta).  The printed
    # exp(+sgn(q_dot) mu eta) makes the pulled cable gain tension along the disks.
    return np.exp(-np.cumsum(direction[..., :, None] * mu[:, None] * eta, axis=-1))


@carries_failed_rows({"psi": 1}, {"direction": 1})
def friction_factors(robot: ContinuumRobot, psi: object, direction: object | None = None) -> np.ndarray:
    """Tension of every span over the cable's base-plate tension, ``(..., 3 n, n N)``: the cumulative
    capstan factors ``exp(-direction mu sum eta)`` (paper 3, eqs. (17)-(19), (23), physical sign).

    ``direction (..., 3 n)``: +1 pulled in, -1 paid out, ``None`` frictionless; 0 (eq. (19)'s stuck
    branch) raises ValueError for a cable with friction (its tension needs a stick-slip memory).

    Returns
    -------
    ndarray, shape (..., 3 n, n N)
    """
    check_params(robot, ContinuumRobot, "robot")
    theta, beta = _split(robot, psi)
    d = _as_direction(robot, direction, theta.shape[:-1])
    broadcast_batch((theta, 1, "psi"), (d, 1, "direction"))
    return _factors(robot, _wrap(robot, theta, beta), d)


# ---- the improved capstan equation ----------------------------------------------------------------
# Fixed-step RK4, vectorised, every point with its own steps: (1) a geometrically graded boundary layer,
# CAPSTAN_LAYER_STEPS steps from |lambda h| = CAPSTAN_FIRST_STEP (lambda = c T^p, the stiff eigenvalue of
# eq. (31); the transient decays faster than the steps grow: local error ~ (lambda h0)^5 / 120 ~ 1e-7 of
# a transient itself ~ rho/c^2 small); (2) uniform steps with |lambda h| <= CAPSTAN_STABILITY (inside
# RK4's real stability interval [-2.78, 0]) and h <= CAPSTAN_ACCURACY c / rho (see _layer), capped at
# CAPSTAN_H_MAX.  Buckets of equal step count (factors of sqrt 2).  Measured error ~1e-9 (1e-8 tested).
CAPSTAN_LAYER_STEPS = 60
CAPSTAN_FIRST_STEP = 0.1
CAPSTAN_STABILITY = 2.0
CAPSTAN_ACCURACY = 0.005
CAPSTAN_H_MAX = 0.1
# Largest phase-2 step count accepted (~1 s per point group): beyond it the stiffness (rho large with
# n < 1) calls for the rho = inf limit, which is solved in closed form.
CAPSTAN_MAX_STEPS = 2**20
# Slack on the a-priori bound T <= t_out exp(phi rho / c) used for the stiffness estimate.
_GROWTH_MARGIN = 1.1


def capstan_coefficient(rho: np.ndarray, alpha: np.ndarray, n: np.ndarray) -> np.ndarray:
    """c = (rho / n) ((1 + rho) / (alpha rho))^(1/n) of paper 3, eq. (29) (``N^(-(1-n)/n)``), broadcast.

    ``rho`` pulley radius / cable radius (> 0), ``alpha`` (> 0) and ``n`` (in (0, 1]) of the friction law
    ``f = alpha N^n`` (eq. (25)), as in :func:`capstan_tension_ratio`.

    Returns
    -------
    ndarray
    """
    rho, alpha, n = as_array(rho, "rho"), as_array(alpha, "alpha"), as_array(n, "n")
    broadcast_batch((rho, 0, "rho"), (alpha, 0, "alpha"), (n, 0, "n"))
    if np.any(rho <= 0.0) or np.any(alpha <= 0.0) or np.any(n <= 0.0) or np.any(n > 1.0):
        bad = "rho" if np.any(rho <= 0.0) else "alpha" if np.any(alpha <= 0.0) else "n"
        raise ValueError(f"Expected rho > 0, alpha > 0 and n in (0, 1], got an invalid {bad}.")
    return (rho / n) * ((1.0 + rho) / (alpha * rho)) ** (1.0 / n)


@carries_failed_rows({"phi": 0}, {"mu": 0})
def classical_capstan_ratio(phi: object, mu: object) -> np.ndarray:
    """Euler-Eytelwein capstan law T_in / T_out = exp(mu phi): wrap angle ``phi`` (rad) and Coulomb
    coefficient ``mu`` broadcast.

    Returns
    -------
    ndarray
    """
    mu_a, phi_a = as_array(mu, "mu"), as_array(phi, "phi")
    broadcast_batch((phi_a, 0, "phi"), (mu_a, 0, "mu"))
    return np.exp(mu_a * phi_a)


def _layer(rho: np.ndarray, c: np.ndarray, lam: np.ndarray) -> tuple[np.ndarray, ...]:
    """First step h0, growth factor g and length of the boundary layer, and the phase-2 step cap.  The
    slow mode's step: RK4's error scales with (h * growth rate)^4, the growth rate of T is at most rho / c
    (slow manifold), so h = CAPSTAN_ACCURACY / rate, capped at CAPSTAN_H_MAX."""
    M1 = CAPSTAN_LAYER_STEPS
    h0 = CAPSTAN_FIRST_STEP / lam
    h_cap = np.minimum(CAPSTAN_STABILITY / lam, np.minimum(CAPSTAN_ACCURACY * c / rho, CAPSTAN_H_MAX))
    g = np.maximum((h_cap / h0) ** (1.0 / M1), 1.0)
    layer = np.where(g > 1.0, h0 * (g**M1 - 1.0) / np.where(g > 1.0, g - 1.0, 1.0), h0 * M1)
    return h0, g, layer, h_cap


def _rk4(phi, rho, c, p, lam, M2):
    """Integrate y'' + c y^p y' - rho y = 0, y(0) = 1, y'(0) = 0 over [0, phi] (1-D arrays)."""
    y = np.ones_like(phi)
    z = np.zeros_like(phi)
    w = np.ones_like(phi)  # w = y^p carried as a state (cheaper than a power per stage)

    def f(y, z, w):
        return z, rho * y - c * w * z, p * w * z / y

    def step(y, z, w, h):
        h2, h6 = 0.5 * h, h / 6.0
        a1, b1, c1 = f(y, z, w)
        a2, b2, c2 = f(y + h2 * a1, z + h2 * b1, w + h2 * c1)
        a3, b3, c3 = f(y + h2 * a2, z + h2 * b2, w + h2 * c2)
        a4, b4, c4 = f(y + h * a3, z + h * b3, w + h * c3)
        return (
            y + h6 * (a1 + 2.0 * (a2 + a3) + a4),
            z + h6 * (b1 + 2.0 * (b2 + b3) + b4),
            w + h6 * (c1 + 2.0 * (c2 + c3) + c4),
        )

    h0, g, layer, _ = _layer(rho, c, lam)
    h = h0 * np.minimum(1.0, phi / layer)  # a short wrap is covered by the layer alone
    for _ in range(CAPSTAN_LAYER_STEPS):  # time steps; every step acts on the whole bucket
        y, z, w = step(y, z, w, h)
        h = h * g
    h = np.maximum(phi - np.minimum(layer, phi), 0.0) / M2
    for _ in range(M2):
        y, z, w = step(y, z, w, h)
    return y, z


@carries_failed_rows({"phi": 0}, {"alpha": 0, "n": 0, "t_out": 0})
def capstan_tension_ratio(
    phi: object, *, rho: object, alpha: object, n: object, t_out: object = 1.0
) -> np.ndarray:
    """Input/output tension ratio kappa of a cable over a pulley, paper 3, eqs. (29)-(32).

    Solves T'' + c T^((1-n)/n) T' - rho T = 0 (c: :func:`capstan_coefficient`) from the output side,
    T(0) = t_out, T'(0) = 0 (eq. (31), theta_1 = 0): kappa = sqrt(rho^2 T(phi)^2 + T'(phi)^2) / (rho T(0)).
    Closed forms for n = 1 and rho = inf, else integrated (CAPSTAN_* constants); arguments broadcast.

    Parameters
    ----------
    phi : array_like
        Wrap angle (rad, >= 0).
    rho : array_like
        Pulley radius / cable radius (unit-free, > 0; ``np.inf`` allowed).
    alpha : array_like
        Coefficient of the friction law ``f = alpha N^n`` (> 0).
    n : array_like
        Exponent of the friction law, in (0, 1].
    t_out : array_like, optional
        Output-side tension (N, > 0); default 1 N.

    Raises
    ------
    ValueError
        ``rho`` too large for the explicit integration with n < 1 (use ``rho=np.inf``, which is allowed).

    Examples
    --------
    >>> np.round(capstan_tension_ratio(np.pi, rho=np.inf, alpha=0.1, n=1.0), 4)   # = exp(0.1 pi)
    np.float64(1.3691)
    """
    phi_a = as_array(phi, "phi")
    rho_a = as_array(rho, "rho", finite=False)
    alpha_a = as_array(alpha, "alpha")
    n_a = as_array(n, "n")
    t_a = as_array(t_out, "t_out")
    broadcast_batch(
        (phi_a, 0, "phi"), (rho_a, 0, "rho"), (alpha_a, 0, "alpha"), (n_a, 0, "n"), (t_a, 0, "t_out")
    )
    if np.any(phi_a < 0.0):
        raise ValueError("Expected phi >= 0, got a negative wrap angle.")
    if np.any(np.isnan(rho_a)) or np.any(rho_a <= 0.0):
        raise ValueError("Expected rho > 0 (np.inf allowed), got a non-positive or NaN value.")
    if np.any(alpha_a <= 0.0):
        raise ValueError("Expected alpha > 0, got a non-positive value.")
    if np.any(n_a <= 0.0) or np.any(n_a > 1.0):
        raise ValueError("Expected n in (0, 1], got a value outside.")
    if np.any(t_a <= 0.0):
        raise ValueError("Expected t_out > 0, got a non-positive value.")
    phi_b, rho_b, alpha_b, n_b, t_b = (
        np.ravel(a) for a in np.broadcast_arrays(phi_a, rho_a, alpha_a, n_a, t_a)
    )
    shape = np.broadcast_shapes(phi_a.shape, rho_a.shape, alpha_a.shape, n_a.shape, t_a.shape)
    out = np.ones(phi_b.shape)
    inf = np.isinf(rho_b)
    one = n_b == 1.0

    # rho -> inf: eq. (29) / rho -> (1/n) alpha^(-1/n) T^p T' = T, p = (1 - n)/n, whose solution is
    # T^p = t_out^p + (1 - n) alpha^(1/n) phi (exp(alpha phi) for n = 1: the classical law).
    m = inf & one
    out[m] = np.exp(alpha_b[m] * phi_b[m])
    m = inf & ~one
    p = (1.0 - n_b[m]) / n_b[m]
    out[m] = (1.0 + (1.0 - n_b[m]) * alpha_b[m] ** (1.0 / n_b[m]) * phi_b[m] / t_b[m] ** p) ** (1.0 / p)

    # n = 1, finite rho: linear ODE y'' + a y' - rho y = 0, a = (1 + rho)/alpha, y(0) = 1, y'(0) = 0.
    m = ~inf & one
    if np.any(m):
        r, ph = rho_b[m], phi_b[m]
        a = (1.0 + r) / alpha_b[m]
        disc = np.sqrt(a * a + 4.0 * r)
        lp = 2.0 * r / (a + disc)  # (-a + disc)/2 without cancellation
        lm = -0.5 * (a + disc)
        cp, cm = -lm / disc, lp / disc
        ep, em = np.exp(lp * ph), np.exp(lm * ph)
        y = cp * ep + cm * em
        z = cp * lp * ep + cm * lm * em
        out[m] = np.sqrt(y * y + (z / r) ** 2)

    # n < 1, finite rho: integrate (normalised y = T / t_out, so c_eff = c t_out^p).
    m = ~inf & ~one & (phi_b > 0.0)
    if np.any(m):
        idx = np.flatnonzero(m)
        r, ph, nn = rho_b[m], phi_b[m], n_b[m]
        p = (1.0 - nn) / nn
        c = capstan_coefficient(r, alpha_b[m], nn) * t_b[m] ** p
        # A-priori bound of y: on the slow manifold y'/y = rho / (c y^p) <= rho / c.
        lam = c * (_GROWTH_MARGIN * np.exp(ph * r / c)) ** p
        _, _, layer, h_cap = _layer(r, c, lam)
        need = np.maximum(ph - layer, 0.0) / h_cap
        if np.any(need > CAPSTAN_MAX_STEPS):
            raise ValueError(
                f"Expected rho small enough for an explicit integration (at most {CAPSTAN_MAX_STEPS} steps), "
                f"got rho up to {r[need > CAPSTAN_MAX_STEPS].max():g} with n < 1; pass rho=np.inf for the "
                "limit of vanishing bending stiffness."
            )
        bucket = np.ceil(2.0 * np.log2(np.maximum(need, 1.0))).astype(int)
        for b in np.unique(bucket):  # a handful of step-count buckets, not samples
            sel = bucket == b
            y, z = _rk4(ph[sel], r[sel], c[sel], p[sel], lam[sel], int(np.ceil(2.0 ** (b / 2.0))))
            out[idx[sel]] = np.sqrt(y * y + (z / r[sel]) ** 2)
    return out.reshape(shape)


# ---- identification -------------------------------------------------------------------------------
@dataclass(frozen=True)
class FrictionEstimate:
    """Least-squares friction coefficients with their uncertainty (from :func:`identify_friction`).

    Attributes
    ----------
    mu : ndarray, shape (...)
        Estimated Coulomb friction coefficient (unit-free).
    std : ndarray, shape (...)
        Its standard deviation (from the stated tension noise if given, else from the residual scatter).
    chi2_per_dof : ndarray, shape (...)
        Weighted residual per degree of freedom (about 1 when the noise model holds).
    n_used : ndarray of int, shape (...)
        Measurements used (those with nonzero direction).
    """

    mu: np.ndarray
    std: np.ndarray
    chi2_per_dof: np.ndarray
    n_used: np.ndarray


def identify_friction(
    wrap: object, t_in: object, t_out: object, direction: object, *, sigma_t: float | None = None
) -> FrictionEstimate:
    """Friction coefficient per cable from measured input and output tensions: :class:`FrictionEstimate`
    (weighted least squares on ln(t_in / t_out) = s mu eta, eq. (18) with the physical sign, last axis).

    Parameters
    ----------
    wrap : array_like, shape (..., m)
        Total wrap angle eta (rad) of each of the m measurements.
    t_in, t_out : array_like, shape (..., m)
        Actuator-side and distal tension (N, > 0).
    direction : array_like, shape (..., m)
        Sliding direction s of each measurement: +1 pulled in, -1 paid out, 0 ignored.
        The four arrays broadcast together.
    sigma_t : float, optional
        Standard deviation of each tension reading (N, > 0); ``None``: unweighted, the uncertainty
        taken from the residual scatter.

    Raises
    ------
    ValueError
        A batch element with no measurement of nonzero wrap and direction.
    """
    eta = as_array(wrap, "wrap", (None,))
    ti = as_array(t_in, "t_in", (None,))
    to = as_array(t_out, "t_out", (None,))
    s = as_array(direction, "direction", (None,))
    if np.any(ti <= 0.0) or np.any(to <= 0.0):
        raise ValueError("Expected t_in and t_out > 0 (a slack cable carries no friction information).")
    if sigma_t is not None:
        sigma_t = check_positive(sigma_t, "sigma_t")
    broadcast_batch((eta, 0, "wrap"), (ti, 0, "t_in"), (to, 0, "t_out"), (s, 0, "direction"))
    eta, ti, to, s = np.broadcast_arrays(eta, ti, to, s)
    y = np.log(ti / to)
    x = s * eta
    var = (sigma_t**2) * (1.0 / ti**2 + 1.0 / to**2) if sigma_t is not None else np.ones_like(y)
    w = np.where(s != 0.0, 1.0 / var, 0.0)
    sxx = np.sum(w * x * x, axis=-1)
    if np.any(sxx <= 0.0):
        raise ValueError("Expected at least one measurement with nonzero wrap and direction per cable.")
    mu = np.sum(w * x * y, axis=-1) / sxx
    n_used = np.count_nonzero(w, axis=-1)
    dof = np.maximum(n_used - 1, 1)
    chi2 = np.sum(w * (y - mu[..., None] * x) ** 2, axis=-1) / dof
    std = np.sqrt(1.0 / sxx) if sigma_t is not None else np.sqrt(chi2 / sxx)
    return FrictionEstimate(mu=mu, std=std, chi2_per_dof=chi2, n_used=n_used)


# ---- stick-slip with memory (eq. (19)) --------------------------------------------------------------
@dataclass(frozen=True)
class TensionHistory:
    """Span tensions of every cable over a history (from :func:`stick_slip_tensions`), time axis first.

    Attributes
    ----------
    span_tension : ndarray, shape (n_t, ..., 3 n, n N)
        Tension of every span (N); zero beyond a cable's termination disk.
    state : ndarray of int, shape (n_t, ..., 3 n, n N)
        Per hole (where each span starts): +1 sliding pulled in (span at its lower friction bound), -1
        paid out (upper bound), 0 stuck (tension kept from the previous step, within the bounds).
    distal : ndarray, shape (n_t, ..., 3 n)
        Tension of each cable's last span (N).
    """

    span_tension: np.ndarray
    state: np.ndarray
    distal: np.ndarray


def stick_slip_tensions(
    robot: ContinuumRobot, psi: object, t_act: object, *, initial: object | None = None
) -> TensionHistory:
    """Paper 3, eq. (19) with memory: span tensions along the disks for a history of poses ``psi
    (n_t, ..., 2 n)`` and actuator-side tensions ``t_act (n_t, ..., 3 n)`` (N, > 0): :class:`TensionHistory`.

    A span keeps its previous tension while it lies within the Coulomb-capstan bounds of its proximal
    neighbour, else it slides at the bound; the fixed-geometry limit of :func:`simulate_history`
    (``docs/mechanisms/continuum.md``, "Stick-slip with memory").  ``initial (..., 3 n, n N)``: span
    tensions before the first step (N, > 0; ``None``: every span at the first actuator tension).

    Returns
    -------
    TensionHistory

    Examples
    --------
    >>> robot = ContinuumRobot.paper()
    >>> psi = np.tile([0.5, 0.0], (3, 1))                      # 3 steps at one pose (rad)
    >>> t_act = np.array([[5.0, 5, 5], [6, 5, 5], [5, 5, 5]])  # cable 0 pulled, then released (N)
    >>> h = stick_slip_tensions(robot, psi, t_act)
    >>> h.span_tension.shape, h.distal[:, 0].round(4)          # the released cable keeps 5.34 N
    ((3, 3, 5), array([5.    , 5.3375, 5.3375]))
    """
    check_params(robot, ContinuumRobot, "robot")
    p = as_array(psi, "psi", (None, 2 * robot.n_segments))
    t = as_array(t_act, "t_act", (None, robot.n_cables))
    if p.ndim < 2 or t.ndim < 2:
        raise ValueError(
            f"Expected psi (n_t, ..., {2 * robot.n_segments}) and t_act (n_t, ..., {robot.n_cables}) with a "
            "leading time axis."
        )
    if p.shape[0] != t.shape[0] or p.shape[0] < 1:
        raise ValueError(
            f"Expected psi and t_act with one common time length >= 1, got psi {p.shape} and t_act {t.shape}."
        )
    if np.any(t <= 0.0):
        raise ValueError(
            "Expected t_act > 0 at every step (a cable at or below zero tension is slack and has no friction "
            f"state), got min {t.min()!r} N."
        )
    active = _span_active(robot)
    init = None if initial is None else as_array(initial, "initial", active.shape)
    # the batch axes follow the time axis: align them from the right (NumPy rules) after it; an
    # initial state (no time axis) may extend the history's batch
    k = max(p.ndim - 2, t.ndim - 2, 0 if init is None else init.ndim - 2)
    p = p.reshape(p.shape[0], *(1,) * (k + 2 - p.ndim), *p.shape[1:])
    t = t.reshape(t.shape[0], *(1,) * (k + 2 - t.ndim), *t.shape[1:])
    with_initial = [] if init is None else [(init, 2, "initial")]
    batch = broadcast_batch((p[0], 1, "psi"), (t[0], 1, "t_act"), *with_initial)
    theta, beta = _split(robot, p)
    eta = _wrap(robot, theta, beta)  # (n_t, ..., 3n, nN)
    n_t = p.shape[0]
    eta = np.broadcast_to(eta, (n_t, *batch, *eta.shape[-2:]))
    t = np.broadcast_to(t, (n_t, *batch, robot.n_cables))
    mu = robot.friction_array[:, None]
    if init is None:
        prev = np.where(active, t[0][..., None], 0.0)
    else:
        if np.any(init[..., active] <= 0.0):
            raise ValueError("Expected initial span tensions > 0 on every active span.")
        prev = np.where(active, np.broadcast_to(init, (*batch, *active.shape)), 0.0)
    out = np.zeros((n_t, *batch, *active.shape))
    state = np.zeros(out.shape, dtype=int)
    K = active.shape[-1]
    for i in range(n_t):  # time steps (a history is sequential), vectorised over batch and cables
        cur = np.empty_like(prev)
        proximal = t[i]
        for k in range(K):  # holes from the actuator to the tip
            lo = proximal * np.exp(-mu[:, 0] * eta[i][..., k])
            hi = proximal * np.exp(mu[:, 0] * eta[i][..., k])
            old = prev[..., k]
            # paper 3, eq. (19): stuck (q_dot = 0) keeps T(t^-1); the print gives no criterion for
            # sticking: here a span sticks while within the Coulomb-capstan bounds, else slides at them
            new = np.clip(old, lo, hi)
            state[i][..., k] = np.where(old < lo, 1, np.where(old > hi, -1, 0))
            cur[..., k] = np.where(active[:, k], new, 0.0)
            state[i][..., k] = np.where(active[:, k], state[i][..., k], 0)
            proximal = np.where(active[:, k], new, proximal)
        out[i] = cur
        prev = cur
    last = robot.disks_per_segment * (robot.cable_segment + 1) - 1
    distal = np.take_along_axis(out, np.broadcast_to(last[:, None], (*out.shape[:-1], 1)), axis=-1)[..., 0]
    return TensionHistory(span_tension=out, state=state, distal=distal)


# ---- stick-slip of an elastic cable through the holes (docs/mechanisms/continuum.md) --------------
# paper 3, eq. (19): the print keeps the stuck TENSION T(t^-1) and gives no criterion for sticking;
# here the stuck hole keeps the material on both sides (its span tensions then change elastically with
# the pose) and sticks while its tension ratio lies inside the capstan cone.
STUCK_FLUX_TOL = 1e-14
"""A hole counts as sliding in a step when more than 1e-14 m of cable crossed it (the material per span
is ~0.02 m, its rounding ~1e-18 m; the step's equilibrium leaves < 4e-14 m of flux at a stuck hole)."""


def _hole_residual(
    T: np.ndarray, s: np.ndarray, a: np.ndarray, c: float, branch: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Coulomb-capstan complementarity R = T_{h+1} - clip(T_{h+1} - c s_h, T_h e^{-a}, T_h e^{a}) of every
    hole, ``(..., C, K)`` (N), and its own branch (0 inside the cone, +1 below, -1 above), from piece
    tensions ``T (..., C, K + 1)``, fluxes ``s (..., C, K)`` (m), ``a`` mu eta and a scale ``c`` (N/m).
    With ``branch`` given, R is evaluated on it (the smooth piece for the Newton matrix)."""
    prox, dist = T[..., :-1], T[..., 1:]
    lo, hi = prox * np.exp(-a), prox * np.exp(a)
    z = dist - c * s
    own = np.where(z < lo, 1.0, np.where(z > hi, -1.0, 0.0))
    b = own if branch is None else branch
    R = np.where(b == 0.0, c * s, np.where(b > 0.0, dist - lo, dist - hi))
    return R, own
