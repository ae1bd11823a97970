"""Skid steering (turning from the two track speeds, lateral slip) and dead reckoning of the body pose."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from robomech._batching import carries_failed_rows
from robomech._validation import as_array, broadcast_batch, check_positive
from robomech.spatial import exp_se3
from robomech.spatial._so3 import ROTATION_ATOL

__all__ = [
    "LATERAL_SLIP_RTOL",
    "STRAIGHT_RTOL",
    "LateralSlip",
    "SkidSteerTurn",
    "dead_reckoning",
    "paper_lateral_slip",
    "skid_steer_turn",
    "wheel_lateral_velocity",
]

# Track speeds whose difference is below this fraction of their magnitude are "straight": the radius
# (S/2)(v1+v2)/(v1-v2) would then be dominated by the rounding of v1 - v2 (relative 1e-13 ~ 500 eps).
STRAIGHT_RTOL = 1e-13
# paper_lateral_slip divides by 2R + S, which vanishes when the centre of rotation lies on the inner
# track line (R = -S/2, the inner track at rest).  There the outer speed is 0 as well and v_Y = r L/2 is
# indeterminate from (v_outer, R); within this fraction of S the quotient amplifies the rounding of
# v_outer by more than 1e9 L/S, so such samples are flagged instead of returned as huge or inf values.
LATERAL_SLIP_RTOL = 1e-9


@dataclass(frozen=True)
class SkidSteerTurn:
    """Turning of a skid-steered body from its right/left track speeds (from :func:`skid_steer_turn`).

    Attributes
    ----------
    yaw_rate, forward_speed : ndarray, shape (...)
        ``(v1 - v2) / S`` (rad/s, about body z; positive: turning left), ``(v1 + v2) / 2`` (m/s).
    radius : ndarray, shape (...)
        Signed radius of the body centre's path (m, positive: centre of rotation on the left); ``inf``
        where not ``turning`` (straight or at rest).
    turning : ndarray of bool, shape (...)
        ``|v1 - v2|`` above ``STRAIGHT_RTOL`` times ``|v1| + |v2|``.
    """

    yaw_rate: np.ndarray
    forward_speed: np.ndarray
    radius: np.ndarray
    turning: np.ndarray


@carries_failed_rows({"v_right": 0, "v_left": 0})
def skid_steer_turn(v_right: ArrayLike, v_left: ArrayLike, track_width: float) -> SkidSteerTurn:
    """Yaw rate, speed and turning radius of the body centre from the right (``v1``) and left (``v2``)
    track speeds ``(...)`` (m/s, broadcast), tracks ``track_width`` (m) apart, no longitudinal slip:
    :class:`SkidSteerTurn` (paper 4, Sec. 1.2, with the departures commented at the lines below).

    Returns
    -------
    SkidSteerTurn

    Examples
    --------
    >>> t = skid_steer_turn(1.0, 0.5, 0.6)
    >>> round(float(t.yaw_rate), 12), float(t.forward_speed), round(float(t.radius), 12)  # R = v / r
    (0.833333333333, 0.75, 0.9)
    """
    v1 = as_array(v_right, "v_right")
    v2 = as_array(v_left, "v_left")
    broadcast_batch((v1, 0, "v_right"), (v2, 0, "v_left"))
    S = check_positive(track_width, "track_width")
    diff = v1 - v2
    total = v1 + v2
    turning = np.abs(diff) > STRAIGHT_RTOL * (np.abs(v1) + np.abs(v2))
    # paper 4, Sec. 1.2: printed R_s (same formula) is called the inner wheel's radius; it is the centre's.
    radius = np.where(turning, 0.5 * S * total / np.where(turning, diff, 1.0), np.inf)
    # paper 4, Sec. 1.2: printed ω = 2 v_X / L; the yaw rate consistent with the geometry is (v1 - v2)/S.
    return SkidSteerTurn(yaw_rate=diff / S, forward_speed=0.5 * total, radius=radius, turning=turning)


@carries_failed_rows({"yaw_rate": 0}, {"wheel_x": 0, "icr_x": 0})
def wheel_lateral_velocity(yaw_rate: ArrayLike, wheel_x: ArrayLike, icr_x: ArrayLike = 0.0) -> np.ndarray:
    """Lateral (body y) sliding velocity ``r (x_w - x_icr)`` (m/s) of a contact at body ``x = wheel_x`` (m)
    of a body turning at ``yaw_rate`` (rad/s) about a centre of rotation at ``x = icr_x`` (m); broadcast.

    Returns
    -------
    ndarray, shape (...)
    """
    r = as_array(yaw_rate, "yaw_rate")
    x = as_array(wheel_x, "wheel_x")
    xi = as_array(icr_x, "icr_x")
    broadcast_batch((r, 0, "yaw_rate"), (x, 0, "wheel_x"), (xi, 0, "icr_x"))
    return r * (x - xi)


@dataclass(frozen=True)
class LateralSlip:
    """Lateral slip speed of the outer wheel (from :func:`paper_lateral_slip`, paper 4, Sec. 1.2).

    Attributes
    ----------
    lateral_speed : ndarray, shape (...)
        Lateral slip speed ``v_Y`` (m/s); NaN exactly where ``valid`` is false.
    valid : ndarray of bool, shape (...)
        False within ``LATERAL_SLIP_RTOL`` S of the singularity ``2 R + S = 0`` (or on an overflow).
    """

    lateral_speed: np.ndarray
    valid: np.ndarray


@carries_failed_rows({"v_outer": 0, "radius": 0})
def paper_lateral_slip(
    v_outer: ArrayLike, wheelbase: float, radius: ArrayLike, track_width: float
) -> LateralSlip:
    """paper 4, Sec. 1.2: ``v_Y = v_X L / (2 R_s + S)`` (m/s), the lateral slip of an outer wheel ``L/2``
    from the centre of rotation, from the outer track speed ``v_outer`` (m/s), ``wheelbase`` L (m), the
    radius ``R_s`` of the body centre (m; not of the inner wheel, as printed) and ``track_width`` S (m).

    Returns
    -------
    LateralSlip
    """
    v = as_array(v_outer, "v_outer")
    R = as_array(radius, "radius")
    broadcast_batch((v, 0, "v_outer"), (R, 0, "radius"))
    L = check_positive(wheelbase, "wheelbase")
    S = check_positive(track_width, "track_width")
    den = 2.0 * R + S
    valid = np.abs(den) > LATERAL_SLIP_RTOL * S
    out = np.where(valid, v * L / np.where(valid, den, 1.0), np.nan)
    valid = valid & np.isfinite(out)
    return LateralSlip(lateral_speed=np.where(valid, out, np.nan), valid=valid)


def _check_rigid(T: np.ndarray, name: str) -> np.ndarray:
    """``T`` if every matrix is a rigid transform within ``ROTATION_ATOL``, else a ValueError naming it."""
    R = T[..., :3, :3]
    err = np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max(axis=(-2, -1), initial=0.0)
    det_err = np.abs(np.linalg.det(R) - 1.0) if R.size else np.zeros(R.shape[:-2])
    row_err = np.abs(T[..., 3, :] - [0.0, 0.0, 0.0, 1.0]).max(axis=-1, initial=0.0)
    worst = float(max(np.max(err, initial=0.0), np.max(det_err, initial=0.0), np.max(row_err, initial=0.0)))
    if worst > ROTATION_ATOL:
        raise ValueError(
            f"Expected {name} to be rigid transforms (rotation part R^T R = I, det R = 1, last row "
            f"(0, 0, 0, 1), within {ROTATION_ATOL}), got a deviation of {worst:.3g}."
        )
    return T


def dead_reckoning(twists: ArrayLike, dt: float, T0: ArrayLike | None = None) -> np.ndarray:
    """Body poses ``T_GB (..., N, 4, 4)`` (the first is ``T0``, default the identity) from body twists
    ``[ω; v]`` ``(..., N, 6)`` (rad/s, m/s) sampled every ``dt`` s: ``T_{k+1} = T_k exp(dt (V_k +
    V_{k+1})/2)`` (second order), evaluated as a parallel prefix scan (``log2 N`` batched products).

    Returns
    -------
    ndarray, shape (..., N, 4, 4)

    Examples
    --------
    >>> V = np.tile([0.0, 0.0, 0.5, 1.0, 0.0, 0.0], (3, 1))     # 1 m/s forward turning at 0.5 rad/s
    >>> T = dead_reckoning(V, 0.1)
    >>> T.shape, T[-1, :2, 3].round(4)                          # on the arc of radius 2 m after 0.2 s
    ((3, 4, 4), array([0.1997, 0.01  ]))
    """
    V = as_array(twists, "twists", (None, 6), min_ndim=2, nonempty=True)
    h = check_positive(dt, "dt")
    n = V.shape[-2]
    T0a = np.eye(4) if T0 is None else _check_rigid(as_array(T0, "T0", (4, 4)), "T0")
    out = np.empty((*broadcast_batch((V, 2, "twists"), (T0a, 2, "T0")), n, 4, 4))
    out[..., 0, :, :] = T0a
    if n == 1:
        return out
    P = exp_se3(0.5 * h * (V[..., :-1, :] + V[..., 1:, :]))  # increments D_k, (..., n-1, 4, 4)
    shift = 1
    while shift < n - 1:
        P[..., shift:, :, :] = P[..., :-shift, :, :] @ P[..., shift:, :, :]
        shift *= 2
    out[..., 1:, :, :] = T0a[..., None, :, :] @ P
    return out
