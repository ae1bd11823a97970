"""Composite velocity system ``A0 ṗ = J q̇`` of the six wheels (paper 4, eq. (5)) and its batched
least-squares solution.  Unknowns ``ṗ (..., 11)`` in paper order, measurements ``q̇ (..., 22)`` (the
18 contact-frame velocities, ``ω1, ω2``, yaw and roll rate) and rows: ``docs/mechanisms/skid_steer.md``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from robomech._batching import carries_failed_rows, chunked
from robomech._validation import as_array, broadcast_batch, broadcast_to_batch, check_bool, check_params
from robomech.analysis import lstsq

from ._chains import CONFIG_SIZE, N_WHEELS, _linear_columns
from ._params import ExplorationRobot

__all__ = [
    "I_ROCKER1",
    "I_ROCKER2",
    "I_ROLL",
    "I_YAW",
    "MEASURED_SIZE",
    "N_ROWS",
    "UNKNOWN_SIZE",
    "BodyVelocity",
    "assemble",
    "body_velocity",
    "wheel_measurements",
]

N_ROWS = 5 * N_WHEELS  # 30
UNKNOWN_SIZE = 11
MEASURED_SIZE = 3 * N_WHEELS + 4  # 22
# Column indices in the measured vector.
I_ROCKER1, I_ROCKER2, I_YAW, I_ROLL = 18, 19, 20, 21
# Samples per block in body_velocity: the (block, 30, 11) and (block, 30, 22) systems (6 MB) stay in
# cache while they are assembled and solved; one 250,000-sample block ran ~2x slower (strided writes).
CHUNK = 8192
# Samples per block of a bare assembly (8 kB of output per sample stays in the 2 MB L2 cache).
ASSEMBLY_CHUNK = 256
# Unknown indices of each side's passive rates (θ̇01, θ̇02, ṡ).
_PASSIVE = ((5, 6, 9), (7, 8, 10))


@carries_failed_rows({"config": 1})
def assemble(robot: ExplorationRobot, config: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """``A0 (..., 30, 11)`` and ``J (..., 30, 22)`` of ``A0 ṗ = J q̇`` at ``config (..., 8)``: the
    coefficients of the unknowns and of the measured vector (paper order).

    Returns
    -------
    A0, J : ndarray, shape (..., 30, 11) and (..., 30, 22)
    """
    check_params(robot, ExplorationRobot, "robot")
    q = as_array(config, "config", (CONFIG_SIZE,))
    batch = q.shape[:-1]
    qf = q.reshape(-1, CONFIG_SIZE)
    A0, J = chunked(lambda sl: _assemble(robot, qf[sl]), qf.shape[0], ASSEMBLY_CHUNK)
    return A0.reshape(*batch, N_ROWS, UNKNOWN_SIZE), J.reshape(*batch, N_ROWS, MEASURED_SIZE)


def _assemble(robot: ExplorationRobot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    batch = q.shape[:-1]
    p, alpha, G = _linear_columns(robot, q)
    A0 = np.zeros((*batch, N_ROWS, UNKNOWN_SIZE))
    J = np.zeros((*batch, N_ROWS, MEASURED_SIZE))
    c, s = np.cos(alpha), np.sin(alpha)
    px, py, pz = p[..., 0], p[..., 1], p[..., 2]
    for w in range(N_WHEELS):
        side = w // 3
        r = 5 * w
        # v_B
        A0[..., r, 0] = 1.0
        A0[..., r + 1, 1] = 1.0
        A0[..., r + 2, 2] = 1.0
        # ω_BX x × p = (0, -p_z, p_y); ω_BZ z × p = (-p_y, p_x, 0)
        A0[..., r + 1, 3] = -pz[..., w]
        A0[..., r + 2, 3] = py[..., w]
        A0[..., r, 4] = -py[..., w]
        A0[..., r + 1, 4] = px[..., w]
        # passive chain rates: (θ̇01, θ̇02, ṡ) are side joints 1, 2, 3
        for j, col in zip((1, 2, 3), _PASSIVE[side], strict=True):
            A0[..., r, col] = G[..., w, 0, j]
            A0[..., r + 2, col] = G[..., w, 1, j]
        # angular rows.  paper 4, eqs. (1)-(2): printed ω_BX = sin(α) ω, ω_BZ = cos(α) ω (contact frames
        # not rolling relative to the ground); that cannot hold for all wheels once their α differ, so the
        # rows are ω_BX = measured roll rate, ω_BZ = measured yaw rate (22 measurements, not 21).
        A0[..., r + 3, 3] = 1.0
        A0[..., r + 4, 4] = 1.0
        # right-hand side: R_BP v_P with R_BP = rot_y(α)
        k = 3 * w
        J[..., r, k] = c[..., w]
        J[..., r, k + 2] = s[..., w]
        J[..., r + 1, k + 1] = 1.0
        J[..., r + 2, k] = -s[..., w]
        J[..., r + 2, k + 2] = c[..., w]
        # rocker terms: -(ω_BY y × p + θ̇_i G_θ) with ω_BY = (ω1+ω2)/2, θ̇_i = ω_i - ω_BY.  Since the
        # rocker pivot lies on the body y axis, G_θ = y × p and the sum is -ω_i (y × p): each wheel
        # sees only its own rocker's absolute pitch rate.
        # paper 4, eq. (1): printed zero columns for the rocker rate ω1 in the linear rows; the rocker
        # carries the wheel, so its rate enters.  Printed ω_BY = -(ω1+ω2)/2: here ω_i are right-handed about
        # +y, so ω_BY = +(ω1+ω2)/2.
        own = I_ROCKER1 if side == 0 else I_ROCKER2
        J[..., r, own] = -G[..., w, 0, 0]
        J[..., r + 2, own] = -G[..., w, 1, 0]
        J[..., r + 3, I_ROLL] = 1.0
        J[..., r + 4, I_YAW] = 1.0
    return A0, J


@carries_failed_rows({"config": 1, "twist": 1, "config_rate": 1})
def wheel_measurements(
    robot: ExplorationRobot, config: ArrayLike, twist: ArrayLike, config_rate: ArrayLike
) -> np.ndarray:
    """Exact measurements ``q̇ (..., 22)`` of a known motion (the forward velocity map): body ``twist
    (..., 6)`` ``[ω_B; v_B]`` relative to the ground in body axes (rad/s, m/s), joint rates ``config_rate
    (..., 8)``.  :func:`body_velocity` recovers them, with ``ω_BY = (ω1 + ω2)/2`` (exact only when the
    differential holds, ``θ̇2 = -θ̇1``).

    Returns
    -------
    ndarray, shape (..., 22)

    Examples
    --------
    >>> robot = ExplorationRobot.paper()
    >>> twist = np.array([0.0, 0.0, 0.2, 0.5, 0.0, 0.0])    # 0.5 m/s forward, turning at 0.2 rad/s
    >>> m = wheel_measurements(robot, np.zeros(8), twist, np.zeros(8))
    >>> body_velocity(robot, np.zeros(8), m).twist.round(12) + 0.0   # recovered exactly
    array([0. , 0. , 0.2, 0.5, 0. , 0. ])
    """
    check_params(robot, ExplorationRobot, "robot")
    q = as_array(config, "config", (CONFIG_SIZE,))
    V = as_array(twist, "twist", (6,))
    qd = as_array(config_rate, "config_rate", (CONFIG_SIZE,))
    # every argument to the common batch: the kernel stacks per-wheel slices of each
    q, V, qd = broadcast_to_batch((q, 1, "config"), (V, 1, "twist"), (qd, 1, "config_rate"))
    p, alpha, G = _linear_columns(robot, q)
    w_B, v_B = V[..., None, :3], V[..., None, 3:]
    v = v_B + np.cross(w_B, p)  # (..., 6, 3)
    side_rates = np.stack([qd[..., 4 * (w // 3) : 4 * (w // 3) + 4] for w in range(N_WHEELS)], -2)
    vx = v[..., 0] + np.einsum("...wj,...wj->...w", G[..., 0, :], side_rates)
    vz = v[..., 2] + np.einsum("...wj,...wj->...w", G[..., 1, :], side_rates)
    c, s = np.cos(alpha), np.sin(alpha)
    # v_P = R_PB v with R_PB = rot_y(α)^T
    vp = np.stack([c * vx - s * vz, v[..., 1], s * vx + c * vz], axis=-1)
    out = np.empty((*np.broadcast_shapes(vp.shape[:-2], V.shape[:-1]), MEASURED_SIZE))
    out[..., :18] = vp.reshape(*vp.shape[:-2], 18)
    out[..., I_ROCKER1] = V[..., 1] + qd[..., 0]
    out[..., I_ROCKER2] = V[..., 1] + qd[..., 4]
    out[..., I_YAW] = V[..., 2]
    out[..., I_ROLL] = V[..., 0]
    return out


@dataclass(frozen=True)
class BodyVelocity:
    """Estimated body motion per sample (from :func:`body_velocity`); NaN only where ``valid`` is false.

    Attributes
    ----------
    twist : ndarray, shape (..., 6)
        ``[ω_B; v_B]`` (rad/s, m/s) in body axes (ω_BY from the rockers, the rest estimated).
    config_rate : ndarray, shape (..., 8)
        All joint rates (rad/s, m/s; rockers from ω1, ω2, the rest estimated).
    unknowns : ndarray, shape (..., 11)
        The least-squares solution in paper order.
    residual_norm : ndarray, shape (...)
        ``‖A0 ṗ - J q̇‖`` (m/s and rad/s mixed, as in the paper).
    cond : ndarray, shape (...)
        Condition number of ``A0`` (NaN only for non-finite inputs).
    valid : ndarray of bool, shape (...)
        Finite inputs and full-rank ``A0``.
    """

    twist: np.ndarray
    config_rate: np.ndarray
    unknowns: np.ndarray
    residual_norm: np.ndarray
    cond: np.ndarray
    valid: np.ndarray


def body_velocity(
    robot: ExplorationRobot,
    state: ArrayLike,
    measured: ArrayLike,
    *,
    solver: Literal["qr", "normal_equations"] = "qr",
    exact_cond: bool = False,
    measurement_sigma: ArrayLike | None = None,
) -> BodyVelocity:
    """Body twist and passive joint rates from the joint configuration ``state (..., 8)`` and the measured
    vector ``measured (..., 22)``, per sample (non-finite samples flagged).

    ``solver="qr"``: Householder QR (``analysis.lstsq.solve``, paper 4, Sec. 2.1); ``"normal_equations"``
    for comparison.  ``cond``: 1-norm condition number of R (within 11x of the 2-norm one, which
    ``exact_cond=True`` gives).  ``measurement_sigma (..., 22)`` (> 0): weighted least squares with the
    rows' inverse variances ``1 / Σ_j J_ij² σ_j²`` (diagonal; ``residual_norm`` then dimensionless).

    Returns
    -------
    BodyVelocity

    Examples
    --------
    >>> robot = ExplorationRobot.paper()
    >>> m = wheel_measurements(robot, np.zeros(8), np.array([0, 0, 0, 0.5, 0, 0]), np.zeros(8))
    >>> m = np.stack([m, np.full(22, np.nan)])                # a drop-out in the second sample
    >>> bv = body_velocity(robot, np.zeros(8), m)
    >>> bv.twist[0, 3].round(12), bv.valid
    (np.float64(0.5), array([ True, False]))
    """
    check_params(robot, ExplorationRobot, "robot")
    q = as_array(state, "state", (CONFIG_SIZE,), finite="mask")  # NaN, inf, beyond 1e100: drop-outs
    m = as_array(measured, "measured", (MEASURED_SIZE,), finite="mask")
    if solver not in ("qr", "normal_equations"):
        raise ValueError(f"Expected solver 'qr' or 'normal_equations', got {solver!r}.")
    check_bool(exact_cond, "exact_cond")
    sig = None
    if measurement_sigma is not None:
        if solver != "qr":
            raise ValueError(f"Expected solver 'qr' with measurement_sigma (weighted QR), got {solver!r}.")
        sig = as_array(measurement_sigma, "measurement_sigma", (MEASURED_SIZE,))
        if np.any(sig <= 0):
            raise ValueError(f"Expected measurement_sigma > 0, got {int(np.sum(sig <= 0))} value(s) <= 0.")
    arrays = [(q, 1, "state"), (m, 1, "measured")] + ([] if sig is None else [(sig, 1, "measurement_sigma")])
    batch = broadcast_batch(*arrays)
    n = int(np.prod(batch))
    qf = np.broadcast_to(q, (*batch, CONFIG_SIZE)).reshape(n, CONFIG_SIZE)
    mf = np.broadcast_to(m, (*batch, MEASURED_SIZE)).reshape(n, MEASURED_SIZE)
    sf = None if sig is None else np.broadcast_to(sig, (*batch, MEASURED_SIZE)).reshape(n, MEASURED_SIZE)

    def solve(sl: slice) -> tuple[np.ndarray, ...]:
        qc = qf[sl]
        finite_q = np.all(np.isfinite(qc), axis=-1)
        A0, J = _assemble(robot, np.where(finite_q[:, None], qc, 0.0))
        A0[~finite_q] = np.nan  # flagged by lstsq as not ok
        b = np.einsum("nij,nj->ni", J, mf[sl])
        if sf is not None:
            w = 1.0 / np.einsum("nij,nj->ni", J * J, sf[sl] * sf[sl])  # inverse variance of each row's b_i
            res = lstsq.solve(A0, b, exact_cond=exact_cond, weights=w)
        elif solver == "qr":
            res = lstsq.solve(A0, b, exact_cond=exact_cond)
        else:
            res = lstsq.solve_normal_equations(A0, b)
        # the condition number stays reported for finite rank-deficient samples (huge or inf); a finite
        # but huge sample can overflow the residual (or x) to inf: never valid
        ok = res.ok & res.full_rank & np.isfinite(res.residual_norm) & np.all(np.isfinite(res.x), axis=-1)
        return res.x, res.residual_norm, np.where(res.ok, res.cond, np.nan), ok

    x, resid, cond, valid = chunked(solve, n, CHUNK)
    x = x.reshape(*batch, UNKNOWN_SIZE)
    # A non-finite rocker reading (inf - inf) only reaches samples that the mask below flags.
    with np.errstate(invalid="ignore", over="ignore"):
        w_by = 0.5 * (m[..., I_ROCKER1] + m[..., I_ROCKER2])
        w_by = np.broadcast_to(w_by, batch)
        valid = valid.reshape(batch) & np.isfinite(w_by)
        twist = np.stack([x[..., 3], w_by, x[..., 4], x[..., 0], x[..., 1], x[..., 2]], axis=-1)
        rate = np.empty((*batch, CONFIG_SIZE))
        rate[..., 0] = m[..., I_ROCKER1] - w_by
        rate[..., 4] = m[..., I_ROCKER2] - w_by
    for side in range(2):
        for j, col in zip((1, 2, 3), _PASSIVE[side], strict=True):
            rate[..., 4 * side + j] = x[..., col]
    nan = np.nan
    return BodyVelocity(
        twist=np.where(valid[..., None], twist, nan),
        config_rate=np.where(valid[..., None], rate, nan),
        unknowns=np.where(valid[..., None], x, nan),
        residual_norm=np.where(valid, resid.reshape(batch), nan),
        cond=cond.reshape(batch),
        valid=valid,
    )
