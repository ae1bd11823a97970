"""ICR kinematics of a skid-steered vehicle (Martínez et al. 2005; Mandow et al. 2007), its identification
from encoders and a measured planar body twist ``(v_x, v_y, r)`` by least squares, and per-wheel slip.
The model: ``docs/mechanisms/skid_steer.md``, "ICR kinematics, identification and slip"."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from robomech._batching import carries_failed_rows
from robomech._validation import (
    as_array,
    broadcast_batch,
    broadcast_to_batch,
    check_params,
    check_positive,
    coerce_float_fields,
)
from robomech.analysis import lstsq

from ._chains import N_WHEELS, WHEEL_SIDE, WHEELS, contact_frames
from ._params import ExplorationRobot

__all__ = [
    "SLIP_SPEED_FLOOR",
    "ICRIdentification",
    "ICRModel",
    "PlanarVelocity",
    "TrackSpeeds",
    "WheelSlip",
    "encoder_track_speeds",
    "icr_velocity",
    "identify_icr",
    "wheel_radii",
    "wheel_slip",
]

# Below this speed (m/s) of both the wheel rim and the ground under it a slip ratio is 0/0: flagged.
# 1 µm/s is far below any encoder's resolution at 100 Hz (~1 mm/s for 2048 counts per revolution).
SLIP_SPEED_FLOOR = 1e-6


@dataclass(frozen=True)
class ICRModel:
    """Lateral ICR positions of the left and right tracks and the longitudinal ICR position of the body.

    Parameters
    ----------
    y_left, y_right : float
        Lateral positions of the left and right tracks' ICRs (m, body y, to the left), ``y_left > y_right``.
    x_icr : float, optional
        Longitudinal position of the body's ICR (m, body x).

    Raises
    ------
    ValueError
        ``y_left <= y_right`` (the yaw rate would have the wrong sign or be undefined).
    """

    y_left: float
    y_right: float
    x_icr: float = 0.0

    def __post_init__(self) -> None:
        coerce_float_fields(self, ("y_left", "y_right", "x_icr"))
        if not self.y_left > self.y_right:
            raise ValueError(
                f"Expected y_left > y_right, got y_left={self.y_left!r}, y_right={self.y_right!r}."
            )

    @classmethod
    def no_slip(cls, track_width: float) -> ICRModel:
        """Ideal differential drive: the track ICRs on the wheel planes, ``x_icr = 0``."""
        S = check_positive(track_width, "track_width")
        return cls(0.5 * S, -0.5 * S, 0.0)

    def track_width_factor(self, track_width: float) -> float:
        """``χ = (y_left - y_right) / S``: the effective track width in units of the real one."""
        return (self.y_left - self.y_right) / check_positive(track_width, "track_width")


@dataclass(frozen=True)
class PlanarVelocity:
    """Planar body velocity (from :func:`icr_velocity`).

    Attributes
    ----------
    v_x, v_y, yaw_rate : ndarray, shape (...)
        Body velocity (m/s, body axes) and yaw rate (rad/s, about z); NaN where not ``valid``.
    valid : ndarray of bool, shape (...)
        False where an input track speed was not finite.
    """

    v_x: np.ndarray
    v_y: np.ndarray
    yaw_rate: np.ndarray
    valid: np.ndarray


def icr_velocity(model: ICRModel, v_right: ArrayLike, v_left: ArrayLike) -> PlanarVelocity:
    """Body velocity predicted by the ICR model from the right and left track (encoder) speeds ``(...)``
    (m/s, broadcast): :class:`PlanarVelocity`; non-finite speeds (drop-outs) are flagged per sample.

    Returns
    -------
    PlanarVelocity

    Examples
    --------
    >>> icr = ICRModel.no_slip(0.5)                  # ICRs on the track lines, 0.5 m apart
    >>> v = icr_velocity(icr, 1.0, 0.5)
    >>> float(v.yaw_rate), float(v.v_x), abs(float(v.v_y))   # (v_r - v_l) / S, mean speed, no side slip
    (1.0, 0.75, 0.0)
    """
    check_params(model, ICRModel, "model")
    vr = as_array(v_right, "v_right", finite="mask")
    vl = as_array(v_left, "v_left", finite="mask")
    vr, vl = broadcast_to_batch((vr, 0, "v_right"), (vl, 0, "v_left"))
    valid = np.isfinite(vr) & np.isfinite(vl)
    vr, vl = np.where(valid, vr, 0.0), np.where(valid, vl, 0.0)
    d = model.y_left - model.y_right
    r = (vr - vl) / d
    vx = (vr * model.y_left - vl * model.y_right) / d
    vy = -r * model.x_icr
    nan = np.nan
    return PlanarVelocity(
        v_x=np.where(valid, vx, nan),
        v_y=np.where(valid, vy, nan),
        yaw_rate=np.where(valid, r, nan),
        valid=valid,
    )


def wheel_radii(robot: ExplorationRobot) -> np.ndarray:
    """Rolling radius ``(6,)`` of each wheel in ``WHEELS`` order (m).

    Returns
    -------
    ndarray, shape (6,)
    """
    check_params(robot, ExplorationRobot, "robot")
    return np.array([robot.road_wheel_radius if "road" in w else robot.rear_wheel_radius for w in WHEELS])


@dataclass(frozen=True)
class TrackSpeeds:
    """No-slip track speeds from wheel rates (from :func:`encoder_track_speeds`).

    Attributes
    ----------
    right, left : ndarray, shape (...)
        Track speeds (m/s); NaN where not ``valid``.
    valid : ndarray of bool, shape (...)
        False where a wheel rate of the sample was not finite (an encoder drop-out).
    """

    right: np.ndarray
    left: np.ndarray
    valid: np.ndarray


def encoder_track_speeds(robot: ExplorationRobot, wheel_rate: ArrayLike) -> TrackSpeeds:
    """No-slip track speeds from the wheel spin rates ``(..., 6)`` (rad/s, ``WHEELS`` order): the mean rim
    speed ``r_w φ̇_w`` of each side's three wheels, :class:`TrackSpeeds` (non-finite rates flagged).

    Returns
    -------
    TrackSpeeds
    """
    radii = wheel_radii(robot)
    w = as_array(wheel_rate, "wheel_rate", (N_WHEELS,), finite=False)
    valid = np.all(np.isfinite(w), axis=-1)
    rim = np.where(valid[..., None], w, 0.0) * radii
    side = np.asarray(WHEEL_SIDE)
    right = rim[..., side == 0].mean(axis=-1)
    left = rim[..., side == 1].mean(axis=-1)
    return TrackSpeeds(right=np.where(valid, right, np.nan), left=np.where(valid, left, np.nan), valid=valid)


@dataclass(frozen=True)
class ICRIdentification:
    """Least-squares ICR parameters and their quality (from :func:`identify_icr`).

    Attributes
    ----------
    model : ICRModel or None
        The identified model; ``None`` when not identifiable.
    residual_rms : ndarray, shape (3,)
        RMS misfit of the three equation groups (right track, left track, lateral; m/s).
    used : ndarray of bool, shape (N,)
        Samples that entered the fit (finite, weight > 0).
    n_used : int
        Number of samples used.
    cond : float
        Condition number of the least-squares system.
    identifiable : bool
        Enough turning in the used samples for a full-rank system with ``y_left > y_right``.
    """

    model: ICRModel | None
    residual_rms: np.ndarray
    used: np.ndarray
    n_used: int
    cond: float
    identifiable: bool


def identify_icr(
    v_right: ArrayLike, v_left: ArrayLike, body_velocity: ArrayLike, *, weights: ArrayLike | None = None
) -> ICRIdentification:
    """Identify ``(y_right, y_left, x_icr)`` from track speeds ``v_right, v_left (N,)`` (m/s) and measured
    planar body velocities ``(N, 3)`` = ``(v_x, v_y, r)`` by linear least squares (``analysis.lstsq``).

    ``weights (N,)`` (``>= 0``) weight each sample's three equations.  Samples with a non-finite value
    (or beyond ``_validation.MAX_MAGNITUDE``) or of weight 0 are left out and reported in ``used``; data
    without turning are reported ``identifiable = False``.

    Returns
    -------
    ICRIdentification

    Examples
    --------
    >>> true = ICRModel(y_left=0.3, y_right=-0.32, x_icr=0.02)
    >>> r = np.array([0.2, -0.4, 0.5, 0.1])                          # yaw rates (rad/s)
    >>> vx = np.array([0.5, 0.3, 0.2, 0.4])
    >>> V = np.stack([vx, -r * true.x_icr, r], axis=-1)
    >>> ident = identify_icr(vx - r * true.y_right, vx - r * true.y_left, V)
    >>> ident.identifiable, np.round([ident.model.y_left, ident.model.y_right, ident.model.x_icr], 12)
    (True, array([ 0.3 , -0.32,  0.02]))
    """
    vr = as_array(v_right, "v_right", finite="mask")
    vl = as_array(v_left, "v_left", finite="mask")
    V = as_array(body_velocity, "body_velocity", (3,), finite="mask")
    if vr.ndim != 1:
        raise ValueError(f"Expected v_right to have shape (N,), got {vr.shape}.")
    if vl.shape != vr.shape:
        raise ValueError(
            f"Expected v_left to have shape {vr.shape} like v_right (one N: one sample rate), got {vl.shape}."
        )
    if V.shape != (*vr.shape, 3):
        raise ValueError(
            f"Expected body_velocity to have shape {(*vr.shape, 3)} like v_right {vr.shape} (one N: one "
            f"sample rate), got {V.shape}."
        )
    w = np.ones(vr.shape) if weights is None else as_array(weights, "weights")
    if w.shape != vr.shape:
        raise ValueError(f"Expected weights to have shape {vr.shape} like v_right, got {w.shape}.")
    if np.any(w < 0):
        raise ValueError(f"Expected weights >= 0, got {int(np.sum(w < 0))} negative value(s).")
    # a zero weight removes a sample from the fit: it is not used (nor counted in n_used, nor in the rms)
    used = np.isfinite(vr) & np.isfinite(vl) & np.all(np.isfinite(V), axis=-1) & (w > 0.0)
    n = int(used.sum())
    # The three groups decouple (each unknown has its own column): three (N, 1) systems, one batched call.
    r = V[used, 2]
    A = np.broadcast_to(-r[None, :, None], (3, n, 1))
    b = np.stack([vr[used] - V[used, 0], vl[used] - V[used, 0], V[used, 1]])  # (3, n)
    if n == 0 or not np.any(r != 0.0):
        # no used sample, or no turning at all: every row is zero, nothing to identify
        rms = np.sqrt(np.mean(b**2, axis=1)) if n else np.full(3, np.nan)
        return ICRIdentification(None, rms, used, n, math.inf, False)
    res = lstsq.solve(A, b, weights=w[used])
    x = res.x[:, 0]
    rms = np.sqrt(np.mean((A[..., 0] * np.nan_to_num(x)[:, None] - b) ** 2, axis=1))
    y_right, y_left, x_icr = (float(v) for v in x)
    ok = bool(np.all(res.ok & res.full_rank) and np.all(np.isfinite(x)) and y_left > y_right)
    model = ICRModel(y_left, y_right, x_icr) if ok else None
    return ICRIdentification(model, rms, used, n, float(np.max(res.cond)), ok)


@dataclass(frozen=True)
class WheelSlip:
    """Per-wheel slip (batch shape ``...``, last axis the six wheels in ``WHEELS`` order).

    Attributes
    ----------
    ratio : ndarray, shape (..., 6)
        Longitudinal slip ``(r φ̇ - v) / max(|r φ̇|, |v|)`` in [-1, 1], ``v`` the contact's ground speed
        along the wheel's heading (positive: traction slip; negative: skidding); NaN where not ``valid``.
    lateral_velocity : ndarray, shape (..., 6)
        Sideways sliding speed of each contact (m/s); NaN where not ``valid``.
    valid : ndarray of bool, shape (..., 6)
        A finite wheel rate (a drop-out flags that wheel) and not both speeds below ``SLIP_SPEED_FLOOR``.
    """

    ratio: np.ndarray
    lateral_velocity: np.ndarray
    valid: np.ndarray


@carries_failed_rows({"body_velocity": 1, "config": 1}, {"wheel_rate": 1}, masked=("wheel_rate",))
def wheel_slip(
    robot: ExplorationRobot, wheel_rate: ArrayLike, body_velocity: ArrayLike, config: ArrayLike | None = None
) -> WheelSlip:
    """Slip of each wheel from its spin rate ``(..., 6)`` (rad/s) and the planar body velocity ``(..., 3)``
    = ``(v_x, v_y, r)``, contacts at ``config (..., 8)`` (default: zero joint angles, nominal slides):
    :class:`WheelSlip`.  Planar rigid motion: contact ``(x, y)`` moves at ``(v_x - r y, v_y + r x)``.

    Returns
    -------
    WheelSlip
    """
    radii = wheel_radii(robot)
    w = as_array(wheel_rate, "wheel_rate", (N_WHEELS,), finite=False)
    V = as_array(body_velocity, "body_velocity", (3,))
    if config is None:
        q = np.zeros(8)
        q[[3, 7]] = robot.rear_wheel_drop
    else:
        q = as_array(config, "config", (8,))
    broadcast_batch((w, 1, "wheel_rate"), (V, 1, "body_velocity"), (q, 1, "config"))
    p = contact_frames(robot, q)[..., :3, 3]  # (..., 6, 3)
    vx, vy, r = V[..., 0:1], V[..., 1:2], V[..., 2:3]
    ground = vx - r * p[..., 1]
    lateral = vy + r * p[..., 0]
    finite = np.isfinite(w)
    rim = np.where(finite, w, 0.0) * radii
    valid, ground, lateral, rim = np.broadcast_arrays(finite, ground, lateral, rim)
    den = np.maximum(np.abs(rim), np.abs(ground))
    valid = valid & (den > SLIP_SPEED_FLOOR)
    ratio = np.where(valid, (rim - ground) / np.where(valid, den, 1.0), np.nan)
    return WheelSlip(ratio=ratio, lateral_velocity=np.where(valid, lateral, np.nan), valid=valid)
