"""Position, velocity and acceleration kinematics of the RRR-RR vectored thruster (paper 5, Section 3):
``q = (q1, q2)`` (rad), inputs about X (RRR) and Y (RR); axes, closure, ``R = Ry(q2) Rx(-theta)`` and the
singularity (s22 parallel to s12): docs/mechanisms/vectored_thrust.md."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from robomech._batching import R, carries_failed_rows, chunked_rows
from robomech._validation import as_array, broadcast_batch, check_params
from robomech.spatial import lie_bracket, rot_x

# the unvalidated kernel: inputs are validated once at this module's public boundary
from robomech.spatial._so3 import _sincos as sincos

from ._params import VectoredThruster

__all__ = [
    "SINGULAR_TOL",
    "AccelerationResult",
    "FKResult",
    "IKResult",
    "JacobianResult",
    "JointAxes",
    "LinkClearanceResult",
    "PassiveResult",
    "RotationResult",
    "VelocityResult",
    "angular_acceleration",
    "angular_velocity",
    "arc_clearance",
    "forward_kinematics",
    "inverse_kinematics",
    "jacobian",
    "joint_axes",
    "link_clearance",
    "passive_angles",
    "passive_rates",
    "platform_rotation",
]

# |s22 x s12| (the sine of the angle between the two passive axes, in [0, 1]) below which a
# configuration counts as singular: the platform's rotation about s22 is then undetermined, rates
# grow like 1/|s22 x s12|^2, and at 1e-6 a unit input rate already maps to ~1e12 rad/s.
SINGULAR_TOL = 1e-6
# A propeller direction shorter than this (in the caller's units) has no direction to invert.
MIN_DIRECTION_NORM = 1e-12
# Inputs within this of a range limit count as in range: an IK solution on the boundary carries a few
# ulps of rounding (1e-16 rad), and a limit is never meaningful to better than a micro-radian.
RANGE_TOL = 1e-12
# Samples per block in the batched kernels: their ~20 temporaries stay in cache (1.3-2x faster at 10^6
# samples); not 16384, whose 128 KiB temporaries reach glibc's default mmap threshold (every temporary a
# fresh mmap in a fresh process: docs/mechanisms/vectored_thrust.md, "Numerical constants").
CHUNK = 1 << 13


def _chunked(kernel: Callable[[VectoredThruster, np.ndarray], R], th: VectoredThruster, x: np.ndarray) -> R:
    return chunked_rows(lambda rows: kernel(th, rows), x, CHUNK)


_X = np.array([1.0, 0.0, 0.0])
_Y = np.array([0.0, 1.0, 0.0])


@dataclass(frozen=True)
class JointAxes:
    """Unit joint axes (..., 3) in the base frame; all pass through O.

    Attributes
    ----------
    s11, s12, s13, s21, s22, s0 : ndarray, shape (..., 3)
        RRR input axis X, passive axes between the arcs (eq. (7)) and on the platform (eq. (8)); RR input
        axis Y, passive axis on the platform (eq. (5)); propeller shaft ``s22 x s13`` (eq. (11)).  s13 and
        s0 are NaN where singular.
    distance : ndarray, shape (...)
        ``|s22 x s12|``, the distance to the singularity, in [0, 1].
    valid : ndarray of bool, shape (...)
        ``distance > SINGULAR_TOL``.
    """

    s11: np.ndarray
    s12: np.ndarray
    s13: np.ndarray
    s21: np.ndarray
    s22: np.ndarray
    s0: np.ndarray
    distance: np.ndarray
    valid: np.ndarray


@dataclass(frozen=True)
class LinkClearanceResult:
    """The interference clearance of :func:`link_clearance` per sample.

    Attributes
    ----------
    clearance : ndarray, shape (...)
        Angular clearance (rad) between the 45 deg arc and the fixing device; NaN where not ``valid``.
    valid : ndarray of bool, shape (...)
        Not singular (the fixing device's arc exists).
    """

    clearance: np.ndarray
    valid: np.ndarray


@dataclass(frozen=True)
class FKResult:
    """Forward kinematics per sample (:func:`forward_kinematics`).

    Attributes
    ----------
    axis : ndarray, shape (..., 3)
        Unit propeller axis s0 (base frame); NaN where not valid.
    tip : ndarray, shape (..., 3)
        Propeller position ``propeller_arm * s0`` (m, base frame).
    tilt : ndarray, shape (...)
        Angle between s0 and Z, the universal joint's deflection (rad).
    valid, in_range, tilt_ok, within_limits : ndarray of bool, shape (...)
        Not singular; inputs within ``q1_limits``, ``q2_limits``; valid and ``tilt <= tilt_limit``;
        ``in_range & tilt_ok`` (link interference: :func:`link_clearance`).
    """

    axis: np.ndarray
    tip: np.ndarray
    tilt: np.ndarray
    valid: np.ndarray
    in_range: np.ndarray
    tilt_ok: np.ndarray
    within_limits: np.ndarray


@dataclass(frozen=True)
class IKResult:
    """Inverse kinematics per sample (:func:`inverse_kinematics`).

    Attributes
    ----------
    q : ndarray, shape (..., 2)
        Inputs ``(q1, q2)`` (rad); NaN where not solved.
    solved, in_range, tilt_ok, valid : ndarray of bool, shape (...)
        An assembly with this direction exists (limits ignored); solved and ``q`` within ``q1_limits``,
        ``q2_limits``; solved and the direction within ``tilt_limit`` of Z; ``solved & in_range & tilt_ok``.
    """

    q: np.ndarray
    solved: np.ndarray
    in_range: np.ndarray
    tilt_ok: np.ndarray
    valid: np.ndarray


@dataclass(frozen=True)
class RotationResult:
    """Platform rotation per sample (:func:`platform_rotation`).

    Attributes
    ----------
    R : ndarray, shape (..., 3, 3)
        Platform rotation ``R_OP``, columns ``(-s22, -s13, s0)``; NaN where not valid.
    valid : ndarray of bool, shape (...)
        Not singular.
    """

    R: np.ndarray
    valid: np.ndarray


@dataclass(frozen=True)
class PassiveResult:
    """Passive joint quantities ordered (RR s22, RRR s12, RRR s13), shape (..., 3).

    Attributes
    ----------
    values : ndarray, shape (..., 3)
        Passive angles (rad) or rates (rad/s); NaN where not valid.
    valid : ndarray of bool, shape (...)
        Not singular.
    """

    values: np.ndarray
    valid: np.ndarray


@dataclass(frozen=True)
class JacobianResult:
    """Platform Jacobian per sample (:func:`jacobian`).

    Attributes
    ----------
    J : ndarray, shape (..., 3, 2)
        ``omega = J qd``, omega the platform's angular velocity (base frame); NaN where not valid.
    valid : ndarray of bool, shape (...)
        Not singular.
    distance : ndarray, shape (...)
        ``|s22 x s12|``, in [0, 1].
    """

    J: np.ndarray
    valid: np.ndarray
    distance: np.ndarray


@dataclass(frozen=True)
class AccelerationResult:
    """Platform angular motion per sample (:func:`angular_acceleration`); NaN where not valid.

    Attributes
    ----------
    omega, omega_dot : ndarray, shape (..., 3)
        Platform angular velocity (rad/s) and acceleration (rad/s²), base frame.
    passive_acc, velocity_product : ndarray, shape (..., 3)
        Passive accelerations (RR s22, RRR s12, RRR s13; rad/s²); the Lie-bracket part ``J̇ q̇`` of
        ``omega_dot`` (rad/s²).
    valid : ndarray of bool, shape (...)
        Not singular.
    """

    omega: np.ndarray
    omega_dot: np.ndarray
    passive_acc: np.ndarray
    velocity_product: np.ndarray
    valid: np.ndarray


def _q(q: object) -> np.ndarray:
    return as_array(q, "q", (2,))


def _closure(th: VectoredThruster, q: np.ndarray) -> tuple[np.ndarray, ...]:
    """Kernel: sin, cos of q1 and q2 and ``(x, y) = |s22 x s12| (cos theta, sin theta)``."""
    ca, sa = np.cos(th.arc_angle), np.sin(th.arc_angle)
    s1, c1 = sincos(q[..., 0])  # see _theta_cs: one tangent instead of np.sin + np.cos
    s2, c2 = sincos(q[..., 1])
    return s1, c1, s2, c2, sa * c1 * c2 - ca * s2, -sa * s1


def _axes(th: VectoredThruster, q: np.ndarray) -> JointAxes:
    """Kernel: joint axes at inputs ``q (..., 2)`` (trusted)."""
    ca, sa = np.cos(th.arc_angle), np.sin(th.arc_angle)
    # theta: RR passive angle, R = Ry(q2) Rx(-theta); (cos, sin)(theta) ~ (x, y), D = |s22 x s12|.
    s1, c1, s2, c2, x, y = _closure(th, q)
    zero, one = np.zeros_like(c1), np.ones_like(c1)
    s12 = np.stack([ca * one, sa * s1, -sa * c1], axis=-1)  # paper 5, eq. (7), with a = pi/4
    s22 = np.stack([-c2, zero, s2], axis=-1)  # paper 5, eq. (5)
    d = np.sqrt(x * x + y * y)  # x, y are O(1): no overflow, so no need for (slow) np.hypot
    valid = d > SINGULAR_TOL
    dd = np.where(valid, d, 1.0)
    ct, st = np.where(valid, x / dd, np.nan), np.where(valid, y / dd, np.nan)
    s13 = np.stack([s2 * st, -ct, c2 * st], axis=-1)  # = s22 x s12 / D, paper 5, eq. (8)
    s0 = np.stack([s2 * ct, st, c2 * ct], axis=-1)  # = s22 x s13, paper 5, eqs. (11)-(12) corrected
    return JointAxes(
        s11=np.broadcast_to(_X, s12.shape),
        s12=s12,
        s13=s13,
        s21=np.broadcast_to(_Y, s12.shape),
        s22=s22,
        s0=s0,
        distance=d,
        valid=valid,
    )


@carries_failed_rows({"q": 1})
def joint_axes(th: VectoredThruster, q: object) -> JointAxes:
    """Unit joint axes at inputs ``q`` (paper 5, eqs. (5), (7), (8), (11)).

    Parameters
    ----------
    th : VectoredThruster
    q : array_like, shape (..., 2)

    Returns
    -------
    JointAxes
    """
    check_params(th, VectoredThruster, "th")
    return _axes(th, _q(q))


def _in_range2(th: VectoredThruster, q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """q1, q2 within their limits (+- RANGE_TOL); False where NaN."""
    (a1, b1), (a2, b2) = th.q1_limits, th.q2_limits
    a1, a2, b1, b2 = a1 - RANGE_TOL, a2 - RANGE_TOL, b1 + RANGE_TOL, b2 + RANGE_TOL
    with np.errstate(invalid="ignore"):
        r = q1 >= a1
        r &= q1 <= b1
        r &= q2 >= a2
        r &= q2 <= b2
        return r


# Component-wise 3-vector helpers (tuples of arrays): np.cross / np.linalg.norm on (..., 3) arrays cost
# several times more than these fused element-wise expressions.
_V = tuple[np.ndarray, np.ndarray, np.ndarray]


def _cross(u: _V, v: _V) -> _V:
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


def _dot(u: _V, v: _V) -> np.ndarray:
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


def _unit(u: _V) -> _V:
    n = np.sqrt(_dot(u, u))
    inv = np.divide(1.0, n, out=np.zeros_like(n), where=n > 0)
    return (u[0] * inv, u[1] * inv, u[2] * inv)


def _angle(u: _V, v: _V) -> np.ndarray:
    """Angle between vectors, accurate at 0 and pi."""
    c = _cross(u, v)
    return np.arctan2(np.sqrt(_dot(c, c)), _dot(u, v))


def _arc_clearance(a1: _V, b1: _V, a2: _V, b2: _V) -> np.ndarray:
    n1, n2 = _unit(_cross(a1, b1)), _unit(_cross(a2, b2))
    # p lies within the minor arc a -> b of unit normal n iff p.(n x a) >= 0 and p.(b x n) >= 0
    e1a, e1b = _cross(n1, a1), _cross(b1, n1)
    e2a, e2b = _cross(n2, a2), _cross(b2, n2)
    m = _cross(n1, n2)
    has_m = _dot(m, m) > 0  # the signs below do not depend on |m|: no normalisation needed
    # the great circles meet at +-m; the arcs cross if one of those lies within both arcs
    on1 = (_dot(m, e1a), _dot(m, e1b))
    on2 = (_dot(m, e2a), _dot(m, e2b))
    plus = (on1[0] >= 0) & (on1[1] >= 0) & (on2[0] >= 0) & (on2[1] >= 0)
    minus = (on1[0] <= 0) & (on1[1] <= 0) & (on2[0] <= 0) & (on2[1] <= 0)
    crosses = has_m & (plus | minus)
    # Otherwise the closest point is an end of one arc: its distance to the other arc is the distance to
    # that arc's great circle where its foot lies within the arc (never more than the distance to the
    # arc's ends), else the nearer end.  So the clearance is the smallest of the four end-to-end angles
    # and of the perpendicular distances of the ends whose foot lies within the other arc.
    ends = np.minimum(np.minimum(_angle(a1, a2), _angle(a1, b2)), np.minimum(_angle(b1, a2), _angle(b1, b2)))
    for p, n, ea, eb in ((a1, n2, e2a, e2b), (b1, n2, e2a, e2b), (a2, n1, e1a, e1b), (b2, n1, e1a, e1b)):
        inside = (_dot(p, ea) >= 0) & (_dot(p, eb) >= 0)
        perp = np.arcsin(np.minimum(np.abs(_dot(p, n)), 1.0))
        ends = np.where(inside, np.minimum(ends, perp), ends)
    return np.where(crosses, 0.0, ends)


@carries_failed_rows({"a1": 1, "b1": 1, "a2": 1, "b2": 1})
def arc_clearance(a1: object, b1: object, a2: object, b2: object) -> np.ndarray:
    """Angular distance (rad, in [0, π]) between the minor great-circle arcs (a1 -> b1) and (a2 -> b2).

    Parameters
    ----------
    a1, b1, a2, b2 : array_like, shape (..., 3)
        Unit start and end points of the two arcs; broadcast together.

    Returns
    -------
    ndarray, shape (...)
    """
    arrs = [as_array(v, name, (3,)) for v, name in ((a1, "a1"), (b1, "b1"), (a2, "a2"), (b2, "b2"))]
    broadcast_batch(*((v, 1, name) for v, name in zip(arrs, ("a1", "b1", "a2", "b2"), strict=True)))
    return _arc_clearance(*((v[..., 0], v[..., 1], v[..., 2]) for v in arrs))


def _interference(th: VectoredThruster, q: np.ndarray) -> np.ndarray:
    """Clearance (rad) of the 45 deg arc (s11 -> s12) from the fixing device (s22 -> s13); NaN if singular:
    :func:`_arc_clearance` specialised to these arcs (tested against it): normals ``(0, c1, s1)`` and
    ``s0``, side vectors ``(0, s1, -c1)``, ``(sin a, -cos a s1, cos a c1)``, ``s13``, ``s22``; about 70
    element-wise passes instead of ~250 for the generic 3-vector form.
    """
    with np.errstate(invalid="ignore"):  # NaN (singular samples) is masked at the end
        return _interference_unmasked(th, q)


def _interference_unmasked(th: VectoredThruster, q: np.ndarray) -> np.ndarray:
    ca, sa = np.cos(th.arc_angle), np.sin(th.arc_angle)
    s1, c1, s2, c2, x, y = _closure(th, q)
    d = np.sqrt(x * x + y * y)  # |s12 x s22|
    valid = d > SINGULAR_TOL
    inv = 1.0 / np.where(valid, d, np.nan)
    ct, st = x * inv, y * inv
    s12: _V = (np.full_like(s1, ca), -y, -sa * c1)
    s22: _V = (-c2, np.zeros_like(c2), s2)
    s13: _V = (s2 * st, -ct, c2 * st)
    c2ct, s2ct = c2 * ct, s2 * ct
    # the circles meet at +-m, m = n1 x s0; the arcs cross if one of those lies within both arcs
    m: _V = (c1 * c2ct - s1 * st, s1 * s2ct, -c1 * s2ct)
    has_m = _dot(m, m) > 0
    on1 = (m[1] * s1 - m[2] * c1, sa * m[0] - ca * (m[1] * s1 - m[2] * c1))
    on2 = (_dot(m, s13), _dot(m, s22))
    plus = (on1[0] >= 0) & (on1[1] >= 0) & (on2[0] >= 0) & (on2[1] >= 0)
    minus = (on1[0] <= 0) & (on1[1] <= 0) & (on2[0] <= 0) & (on2[1] <= 0)
    crosses = has_m & (plus | minus)
    # end-to-end angles: X-s22, X-s13, s12-s22 (|s12 x s22| = d), s12-s13
    d12_22 = _dot(s12, s22)
    c2st = c2 * st
    ends = np.minimum(np.arctan2(np.abs(s2), -c2), np.arctan2(np.sqrt(c2st * c2st + ct * ct), s2 * st))
    ends = np.minimum(ends, np.arctan2(d, d12_22))
    ends = np.minimum(ends, _angle(s12, s13))
    d12_13 = _dot(s12, s13)
    # ends whose foot on the other arc's great circle lies within that arc: perpendicular distances
    perps = (
        ((s2 * st >= 0) & (c2 <= 0), np.abs(s2ct)),  # X to arc 2 (normal s0)
        ((d12_13 >= 0) & (d12_22 >= 0), np.abs(ca * s2ct + sa * s1 * st - sa * c1 * c2ct)),  # s12 to arc 2
        ((c1 * s2 <= 0) & (ca * c1 * s2 - sa * c2 >= 0), np.abs(s1 * s2)),  # s22 to arc 1 (normal n1)
        ((-ct * s1 - c1 * c2 * st >= 0) & (sa * s2 * st + ca * (s1 * ct + c1 * c2 * st) >= 0),
         np.abs(s1 * c2 * st - c1 * ct)),  # s13 to arc 1
    )  # fmt: skip
    for inside, pn in perps:
        ends = np.where(inside, np.minimum(ends, np.arcsin(np.minimum(pn, 1.0))), ends)
    return np.where(valid, np.where(crosses, 0.0, ends), np.nan)


@carries_failed_rows({"q": 1})
def link_clearance(th: VectoredThruster, q: object) -> LinkClearanceResult:
    """Angular clearance (rad) between the RRR chain's 45 deg arc and the fixing device (Section 4.1 (2)).

    Parameters
    ----------
    th : VectoredThruster
    q : array_like, shape (..., 2)

    Returns
    -------
    LinkClearanceResult
    """
    check_params(th, VectoredThruster, "th")
    c = _interference(th, _q(q))
    return LinkClearanceResult(clearance=c, valid=np.isfinite(c))


def _theta_cs(th: VectoredThruster, q: np.ndarray) -> tuple[np.ndarray, ...]:
    """Kernel: cos q2, sin q2, cos theta, sin theta (NaN where singular), |s22 x s12|, valid."""
    ca, sa = np.cos(th.arc_angle), np.sin(th.arc_angle)
    # one half-angle tangent per input instead of np.sin + np.cos (numpy's float64 sin/cos are not
    # vectorised: ~9-15 ns per call and sample here, 3.5x the cost of sincos; docs/performance.md)
    s1, c1 = sincos(q[..., 0])
    s2, c2 = sincos(q[..., 1])
    x = c1
    x *= c2
    x *= sa
    x -= ca * s2  # sa c1 c2 - ca s2
    y = s1
    y *= -sa  # -sa s1
    d = x * x
    d += y * y
    d = np.sqrt(d)  # x, y are O(1): no overflow, so no need for hypot
    valid = d > SINGULAR_TOL
    inv = 1.0 / np.where(valid, d, np.nan)  # a select and a divide: cheaper than a masked divide
    x *= inv
    y *= inv
    return c2, s2, x, y, d, valid


def _fk(th: VectoredThruster, q: np.ndarray) -> FKResult:
    c2, s2, ct, st, _, valid = _theta_cs(th, q)
    # s0 = s22 x s13 = Ry(q2) (0, sin th, cos th): paper 5, eq. (12) with sin(phi1) -> sin(phi2)
    az = c2 * ct
    axis = np.stack([s2 * ct, st, az], axis=-1)
    tilt = np.arccos(np.clip(az, -1.0, 1.0))
    with np.errstate(invalid="ignore"):  # NaN where singular, covered by valid
        tilt_ok = tilt <= th.tilt_limit
    tilt_ok &= valid
    in_range = _in_range2(th, q[..., 0], q[..., 1])
    return FKResult(
        axis=axis,
        tip=np.multiply(axis, th.propeller_arm),
        tilt=tilt,
        valid=valid,
        in_range=in_range,
        tilt_ok=tilt_ok,
        within_limits=in_range & tilt_ok,
    )


@carries_failed_rows({"q": 1})
def forward_kinematics(th: VectoredThruster, q: object) -> FKResult:
    """Propeller axis and tip from the inputs ``q`` (paper 5, eqs. (11)-(12), eq. (12)'s sin(phi1) corrected
    to sin(phi2)); the link-interference limit is :func:`link_clearance`'s.

    Parameters
    ----------
    th : VectoredThruster
    q : array_like, shape (..., 2)

    Returns
    -------
    FKResult
    """
    check_params(th, VectoredThruster, "th")
    return _chunked(_fk, th, _q(q))


@carries_failed_rows({"q": 1})
def platform_rotation(th: VectoredThruster, q: object) -> RotationResult:
    """Platform rotation ``R_OP (..., 3, 3)`` = Ry(q2) Rx(-theta), columns (-s22, -s13, s0).

    Parameters
    ----------
    th : VectoredThruster
    q : array_like, shape (..., 2)

    Returns
    -------
    RotationResult
    """
    check_params(th, VectoredThruster, "th")
    ax = _axes(th, _q(q))
    return RotationResult(R=np.stack([-ax.s22, -ax.s13, ax.s0], axis=-1), valid=ax.valid)


def _ik(th: VectoredThruster, s: np.ndarray) -> IKResult:
    # Unmasked element-wise passes (warnings off; every non-finite intermediate is selected away by the
    # masks below), in-place where possible: on CHUNK-sized blocks each avoided temporary or masked
    # ufunc (``where=``, not vectorised) saves a pass.  The arithmetic is that of the closed form.
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return _ik_unmasked(th, s)


def _ik_unmasked(th: VectoredThruster, s: np.ndarray) -> IKResult:
    sx, sy, sz = s[..., 0], s[..., 1], s[..., 2]
    norm = sx * sx
    norm += sy * sy
    norm += sz * sz
    norm = np.sqrt(norm)  # (np.einsum over the last axis measured 3x slower here)
    has_dir = norm > MIN_DIRECTION_NORM
    inv = 1.0 / np.where(has_dir, norm, 1.0)
    ux, uy, uz = sx * inv, sy * inv, sz * inv
    # s0 = (sin q2 cos th, sin th, cos q2 cos th).  |q2| < pi/2 (enforced by the parameters) needs
    # cos q2 > 0, so cos(theta) takes the sign of u_z: the branch through q = 0 for a propeller above the
    # horizontal, and theta beyond 90 deg (the propeller past the horizontal, as the FK allows) below it.
    # Taking cos(theta) > 0 there gives |q2| > pi/2 and a wrong root below, i.e. a
    # "solved" q whose FK is another direction.  paper 5, eq. (13): phi2 = arctan(L*/N*) is right for
    # u_z > 0 only.
    ct2 = ux * ux
    ct2 += uz * uz
    sgn = np.where(uz < 0.0, -1.0, 1.0)
    ct = np.sqrt(ct2)  # unit components: no overflow
    ct *= sgn
    st = uy
    q2 = np.arctan2(sgn * ux, sgn * uz)
    ca, sa = np.cos(th.arc_angle), np.sin(th.arc_angle)
    pos = ct2 > 0
    ict = np.where(pos, 1.0 / ct, 0.0)
    c2 = np.where(pos, uz * ict, 1.0)  # >= 0
    s2 = ux * ict  # 0 where ct = 0
    # paper 5, eq. (13): printed phi1 = -arctan(M* N* / L*^2) does not invert eq. (12).  Correct: find
    # t > 0 with t (cos th, sin th) = (sa c1 c2 - ca s2, -sa s1) (the FK closure and its branch), i.e.
    # A t^2 + B t + C = 0 from s1^2 + c1^2 = 1; take the larger root (the only positive one for |q2| < a).
    ncst = c2 * st
    np.negative(ncst, out=ncst)  # -c2 st
    A = ncst * ncst
    A += ct2  # ct^2 + (c2 st)^2
    hb = ux * ca  # B / 2 = ct ca s2, with ct s2 = ux (halving B scales the discriminant by 4: exact)
    cas2 = s2 * ca
    C = sa * c2
    C *= C
    np.subtract(cas2 * cas2, C, out=C)  # (ca s2)^2 - (sa c2)^2
    disc = hb * hb
    disc -= A * C  # (B^2 - 4 A C) / 4
    ok = disc >= 0
    ok &= A > 0
    ok &= has_dir
    sq = np.sqrt(np.maximum(disc, 0.0))
    # qq = -(B + sign(B) sqrt(B^2 - 4AC)) / 2: the stable pair of roots qq / A and C / qq (where
    # B = -0.0, copysign takes the other sign, which gives the same pair)
    qq = np.copysign(sq, hb, out=sq)
    qq += hb
    np.negative(qq, out=qq)
    r1 = qq / A
    r2 = np.where(qq != 0, C / qq, r1)
    t = np.maximum(r1, r2, out=r2)
    ok &= t > SINGULAR_TOL
    # (sin q1, cos q1) = (-t st / sa, (t ct + ca s2) / (sa c2)); sa, c2 > 0
    ycomp = t * ncst
    xcomp = t * ct
    xcomp += cas2
    q1 = np.where(ok, np.arctan2(ycomp, xcomp), np.nan)
    q2 = np.where(ok, q2, np.nan)
    in_range = _in_range2(th, q1, q2)
    in_range &= ok
    tilt_ok = uz >= np.cos(th.tilt_limit)  # arccos(uz) <= limit, without the arccos
    tilt_ok &= ok
    q = np.stack([q1, q2], axis=-1)
    return IKResult(q=q, solved=ok, in_range=in_range, tilt_ok=tilt_ok, valid=in_range & tilt_ok)


@carries_failed_rows({"s": 1})
def inverse_kinematics(th: VectoredThruster, s: object) -> IKResult:
    """Inputs ``q`` pointing the propeller along ``s`` (paper 5, eq. (13), corrected: see the code).

    Parameters
    ----------
    th : VectoredThruster
    s : array_like, shape (..., 3)
        Propeller direction (base frame; any positive multiple: the axis or the tip).

    Returns
    -------
    IKResult

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.mechanisms import vectored_thrust as vt
    >>> th = vt.VectoredThruster.paper()
    >>> ik = vt.inverse_kinematics(th, vt.forward_kinematics(th, np.array([0.3, 0.2])).axis)
    >>> ik.q.round(12), bool(ik.valid)                         # the round trip
    (array([0.3, 0.2]), True)
    """
    check_params(th, VectoredThruster, "th")
    return _chunked(_ik, th, as_array(s, "s", (3,)))


def _solve3(c0: np.ndarray, c1: np.ndarray, c2: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cramer's rule for ``[c0 c1 c2] x = b`` batched over (..., 3) columns."""
    det = np.sum(c0 * np.cross(c1, c2), axis=-1)
    safe = np.where(det != 0, det, 1.0)
    x = np.stack(
        [
            np.sum(b * np.cross(c1, c2), -1),
            np.sum(c0 * np.cross(b, c2), -1),
            np.sum(c0 * np.cross(c1, b), -1),
        ],
        axis=-1,
    )
    return x / safe[..., None]


def _rates(ax: JointAxes, qd: np.ndarray) -> np.ndarray:
    """:func:`passive_rates`' kernel: ``q1' X + rho2' s12 + rho3' s13 = q2' Y + theta' s22`` (eq. (16)),
    i.e. ``[s22, -s12, -s13] x = q1' X - q2' Y``; paper 5, eq. (17)'s printed rates violate it."""
    b = qd[..., 0:1] * ax.s11 - qd[..., 1:2] * ax.s21
    return _solve3(ax.s22, -ax.s12, -ax.s13, b)


@carries_failed_rows({"q": 1})
def passive_angles(th: VectoredThruster, q: object) -> PassiveResult:
    """Passive joint angles (rad, zero at q = 0) by products of exponentials from the home axes.

    Parameters
    ----------
    th : VectoredThruster
    q : array_like, shape (..., 2)

    Returns
    -------
    PassiveResult
    """
    check_params(th, VectoredThruster, "th")
    q = _q(q)
    ax = _axes(th, q)
    ca, sa = np.cos(th.arc_angle), np.sin(th.arc_angle)
    _, _, ct, st, _, _ = _theta_cs(th, q)
    theta = np.arctan2(st, ct)  # full circle: the propeller may pass beyond the horizontal
    R = np.stack([-ax.s22, -ax.s13, ax.s0], axis=-1)
    # R_rel = Rx(-q1) R, expressed in the basis P = [s12(0), s13(0), s12(0) x s13(0)] = Rx'(rho2) Ry'(rho3).
    P = np.array([[ca, 0.0, -sa], [0.0, -1.0, 0.0], [-sa, 0.0, -ca]])
    M = np.einsum("ji,...jk,...kl,lm->...im", P, rot_x(-q[..., 0]), R, P)
    rho3 = np.arctan2(M[..., 0, 2], M[..., 0, 0])
    rho2 = np.arctan2(M[..., 2, 1], M[..., 1, 1])
    vals = np.stack([theta, rho2, rho3], axis=-1)
    return PassiveResult(values=np.where(ax.valid[..., None], vals, np.nan), valid=ax.valid)


@carries_failed_rows({"q": 1, "qd": 1})
def passive_rates(th: VectoredThruster, q: object, qd: object) -> PassiveResult:
    """Passive joint rates (rad/s): the velocity closure (paper 5, eq. (16)) solved.

    Parameters
    ----------
    th : VectoredThruster
    q, qd : array_like, shape (..., 2)

    Returns
    -------
    PassiveResult
    """
    check_params(th, VectoredThruster, "th")
    q, qd = _q(q), as_array(qd, "qd", (2,))
    batch = broadcast_batch((q, 1, "q"), (qd, 1, "qd"))
    ax = _axes(th, q)
    x = _rates(ax, qd)
    valid = np.broadcast_to(ax.valid, batch)  # the mask has the batch of every argument
    return PassiveResult(values=np.where(valid[..., None], x, np.nan), valid=valid)


def _jacobian(th: VectoredThruster, q: np.ndarray) -> JacobianResult:
    ca, sa = np.cos(th.arc_angle), np.sin(th.arc_angle)
    s1, c1, s2, c2, x, y = _closure(th, q)
    d2 = x * x + y * y
    valid = d2 > SINGULAR_TOL**2
    inv = sa / np.where(valid, d2, np.nan)  # NaN where singular; a select is cheaper than a masked divide
    # d theta / d q from theta = atan2(y, x):  omega = q2' Y + theta' s22.
    # paper 5, eq. (21): the printed J = (J_o)^-1 J_i maps inputs to passive rates, not to omega.
    # th1 = sa (ca c1 s2 - sa c2) / d2,  th2 = -sa s1 (sa c1 s2 + ca c2) / d2
    c1s2 = c1 * s2
    th1 = ca * c1s2
    th1 -= sa * c2
    th1 *= inv
    th2 = c1s2
    th2 *= sa
    th2 += ca * c2
    th2 *= s1
    th2 *= -inv
    J = np.empty((*q.shape[:-1], 3, 2))
    np.multiply(c2, th1, out=J[..., 0, 0])
    np.negative(J[..., 0, 0], out=J[..., 0, 0])
    np.multiply(0.0, th1, out=J[..., 1, 0])  # 0, or NaN where singular
    np.multiply(s2, th1, out=J[..., 2, 0])
    np.multiply(c2, th2, out=J[..., 0, 1])
    np.negative(J[..., 0, 1], out=J[..., 0, 1])
    np.add(1.0, J[..., 1, 0], out=J[..., 1, 1])
    np.multiply(s2, th2, out=J[..., 2, 1])
    return JacobianResult(J=J, valid=valid, distance=np.sqrt(d2))


@carries_failed_rows({"q": 1})
def jacobian(th: VectoredThruster, q: object) -> JacobianResult:
    """Platform Jacobian ``omega = J qd`` (``omega`` base frame, the propeller's own spin excluded).

    Parameters
    ----------
    th : VectoredThruster
    q : array_like, shape (..., 2)

    Returns
    -------
    JacobianResult
    """
    check_params(th, VectoredThruster, "th")
    return _chunked(_jacobian, th, _q(q))


@dataclass(frozen=True)
class VelocityResult:
    """Platform angular velocity per sample (:func:`angular_velocity`).

    Attributes
    ----------
    omega : ndarray, shape (..., 3)
        Platform angular velocity (rad/s, base frame); NaN where not valid.
    valid : ndarray of bool, shape (...)
        Not singular.
    """

    omega: np.ndarray
    valid: np.ndarray


@carries_failed_rows({"q": 1, "qd": 1})
def angular_velocity(th: VectoredThruster, q: object, qd: object) -> VelocityResult:
    """Platform angular velocity ``omega = J qd`` (rad/s).

    Parameters
    ----------
    th : VectoredThruster
    q, qd : array_like, shape (..., 2)

    Returns
    -------
    VelocityResult
    """
    check_params(th, VectoredThruster, "th")
    q, qd = _q(q), as_array(qd, "qd", (2,))
    batch = broadcast_batch((q, 1, "q"), (qd, 1, "qd"))
    jr = _jacobian(th, q)
    valid = np.broadcast_to(jr.valid, batch)  # the mask has the batch of every argument
    return VelocityResult(omega=np.einsum("...ij,...j->...i", jr.J, qd), valid=valid)


def _screw(s: np.ndarray) -> np.ndarray:
    """Unit joint screw [s; 0] of an axis through O."""
    return np.concatenate([s, np.zeros_like(s)], axis=-1)


@carries_failed_rows({"q": 1, "qd": 1, "qdd": 1})
def angular_acceleration(th: VectoredThruster, q: object, qd: object, qdd: object) -> AccelerationResult:
    """Platform angular acceleration by screw theory: each chain's acceleration twist is
    ``sum_i S_i x_i'' + sum_{i<j} [S_i x_i', S_j x_j']``; equating the chains gives the passive accelerations.

    paper 5, eq. (24): printed with the Klein form (a scalar, zero for axes through O) where the Lie
    bracket is needed; eq. (32) therefore lacks the velocity-product terms included here.

    Parameters
    ----------
    th : VectoredThruster
    q, qd, qdd : array_like, shape (..., 2)

    Returns
    -------
    AccelerationResult
    """
    check_params(th, VectoredThruster, "th")
    q, qd, qdd = _q(q), as_array(qd, "qd", (2,)), as_array(qdd, "qdd", (2,))
    batch = broadcast_batch((q, 1, "q"), (qd, 1, "qd"), (qdd, 1, "qdd"))
    ax = _axes(th, q)
    s13 = np.where(ax.valid[..., None], ax.s13, 0.0)
    axv = JointAxes(ax.s11, ax.s12, s13, ax.s21, ax.s22, ax.s0, ax.distance, ax.valid)
    r = _rates(axv, qd)
    V11 = qd[..., 0:1] * _screw(ax.s11)
    V12 = r[..., 1:2] * _screw(ax.s12)
    V13 = r[..., 2:3] * _screw(s13)
    V21 = qd[..., 1:2] * _screw(ax.s21)
    V22 = r[..., 0:1] * _screw(ax.s22)
    lie_rrr = lie_bracket(V11, V12) + lie_bracket(V11 + V12, V13)
    lie_rr = lie_bracket(V21, V22)
    b = qdd[..., 0:1] * ax.s11 - qdd[..., 1:2] * ax.s21 + lie_rrr[..., :3] - lie_rr[..., :3]
    acc = _solve3(ax.s22, -ax.s12, -s13, b)
    omega = qd[..., 1:2] * ax.s21 + r[..., 0:1] * ax.s22
    omega_dot = qdd[..., 1:2] * ax.s21 + acc[..., 0:1] * ax.s22 + lie_rr[..., :3]
    # velocity-product part: omega' with qdd = 0
    b0 = lie_rrr[..., :3] - lie_rr[..., :3]
    acc0 = _solve3(ax.s22, -ax.s12, -s13, b0)
    vp = acc0[..., 0:1] * ax.s22 + lie_rr[..., :3]
    valid = np.broadcast_to(ax.valid, batch)  # the mask has the batch of every argument
    m = valid[..., None]
    nan = np.nan
    return AccelerationResult(
        omega=np.where(m, omega, nan),
        omega_dot=np.where(m, omega_dot, nan),
        passive_acc=np.where(m, acc, nan),
        velocity_product=np.where(m, vp, nan),
        valid=valid,
    )
