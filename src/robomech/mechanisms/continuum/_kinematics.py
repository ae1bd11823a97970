"""Constant-curvature kinematics: segment transforms, forward kinematics, cable lengths, Jacobians, IK.

Coordinates: every segment i has psi_i = (theta_i, beta_i) (bend angle, bending-plane angle), stacked
as ``psi (..., 2 n) = [theta_1, beta_1, theta_2, beta_2, ...]`` (paper 3, Section 1).  Cables are indexed
``3 i + j`` (segment i, cable j); the drive length of a cable is its geometric length from the base
plate to its termination disk.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from robomech._validation import as_array
from robomech.spatial import SMALL_ANGLE

from ._params import ContinuumRobot

__all__ = [
    "IK_MAX_ITERATIONS",
    "IK_TOLERANCE",
    "IKResult",
    "cable_jacobian",
    "cable_lengths",
    "disk_transforms",
    "forward_kinematics",
    "inverse_kinematics",
    "segment_transform",
    "span_jacobian",
    "span_lengths",
    "tip_jacobian",
    "tip_position",
]

CableModel = Literal["arc", "chord"]

# IK: a tip position is reached when the residual is below 1e-10 m (0.1 nm: far below any physical
# tolerance, above the ~1e-16 * 0.1 m rounding of the forward kinematics).
IK_TOLERANCE = 1e-10
# Gauss-Newton from the exact single-arc guess converges quadratically; 30 iterations leave a wide margin.
IK_MAX_ITERATIONS = 30
# Levenberg damping (m^2): regularises the redundant (n >= 2) and the straight (theta = 0) cases;
# 1e-14 m^2 is ~1e-10 of J^T J ~ l^2 ~ 1e-2 m^2, so it does not slow convergence.
IK_DAMPING = 1e-14


# ---- scalar functions of the bend angle, exact and finite at theta = 0 --------------------------
def _small_fix(t: np.ndarray, closed, series) -> np.ndarray:
    """``closed(t)`` with the entries below SMALL_ANGLE replaced by ``series(t)`` (no 0/0 evaluated)."""
    t = np.asarray(t, dtype=float)
    small = np.abs(t) < SMALL_ANGLE
    if not np.any(small):
        return closed(t)
    out = np.array(closed(np.where(small, 1.0, t)), dtype=float)
    out[small] = series(t[small])
    return out


def _f_cos(t: np.ndarray) -> np.ndarray:
    """(1 - cos t) / t."""
    return _small_fix(t, lambda x: (1.0 - np.cos(x)) / x, lambda x: x / 2.0 - x**3 / 24.0 + x**5 / 720.0)


def _f_sin(t: np.ndarray) -> np.ndarray:
    """sin t / t."""
    return _small_fix(t, lambda x: np.sin(x) / x, lambda x: 1.0 - x**2 / 6.0 + x**4 / 120.0)


def _df_cos(t: np.ndarray) -> np.ndarray:
    """d/dt (1 - cos t)/t = (t sin t + cos t - 1) / t^2 (paper 3, eq. (6))."""
    return _small_fix(
        t, lambda x: (x * np.sin(x) + np.cos(x) - 1.0) / (x * x), lambda x: 0.5 - x**2 / 8.0 + x**4 / 144.0
    )


def _df_sin(t: np.ndarray) -> np.ndarray:
    """d/dt sin t / t = (t cos t - sin t) / t^2 (paper 3, eq. (6))."""
    return _small_fix(t, lambda x: (x * np.cos(x) - np.sin(x)) / (x * x), lambda x: -x / 3.0 + x**3 / 30.0)


def _split(robot: ContinuumRobot, psi: object, name: str = "psi") -> tuple[np.ndarray, np.ndarray]:
    p = as_array(psi, name, (2 * robot.n_segments,))
    # contiguous copies: numpy's vectorised trigonometry is ~2x faster on contiguous input
    return np.ascontiguousarray(p[..., 0::2]), np.ascontiguousarray(p[..., 1::2])


# ---- one segment --------------------------------------------------------------------------------
def _segment_T(theta: np.ndarray, beta: np.ndarray, length: np.ndarray | float) -> np.ndarray:
    """Segment poses (..., 4, 4), computed as 16 contiguous planes (4, 4, ...) and returned as a view
    with the matrix axes last: writing planes is several times faster than 16 strided writes."""
    ct, st, cb, sb = np.cos(theta), np.sin(theta), np.cos(beta), np.sin(beta)
    shape = np.broadcast_shapes(np.shape(theta), np.shape(beta), np.shape(length))
    P = np.empty((4, 4, *shape))
    cb2, sb2 = cb * cb, sb * sb
    # R = Rz(beta) Ry(theta) Rz(-beta).  paper 3, eq. (1): printed element (2,1) c(beta)s(beta)c(theta);
    # the product gives c(beta)s(beta)(c(theta) - 1) (symmetric with element (1,2)).
    P[0, 0] = ct * cb2 + sb2
    np.multiply(cb * sb, ct - 1.0, out=P[0, 1, ...])
    P[1, 0] = P[0, 1]
    np.multiply(cb, st, out=P[0, 2, ...])
    P[1, 1] = sb2 * ct + cb2
    np.multiply(sb, st, out=P[1, 2, ...])
    np.negative(P[0, 2], out=P[2, 0, ...])
    np.negative(P[1, 2], out=P[2, 1, ...])
    P[2, 2] = ct
    # paper 3, eq. (2), written with (1 - cos t)/t and sin t / t so that it is finite at theta = 0
    # (closed forms from the cosines above; Taylor series on the rare entries below SMALL_ANGLE).
    if np.any(np.abs(theta) < SMALL_ANGLE):
        fc, fs = _f_cos(theta), _f_sin(theta)
    else:
        inv = 1.0 / theta
        fc, fs = (1.0 - ct) * inv, st * inv
    fc = length * fc
    np.multiply(fc, cb, out=P[0, 3, ...])
    np.multiply(fc, sb, out=P[1, 3, ...])
    np.multiply(length, fs, out=P[2, 3, ...])
    P[3, :3] = 0.0
    P[3, 3] = 1.0
    return np.moveaxis(P, (0, 1), (-2, -1))


def segment_transform(theta: object, beta: object, length: object) -> np.ndarray:
    """Pose ``T (..., 4, 4)`` of a constant-curvature segment's end frame in its base frame.

    ``theta`` bend angle (rad), ``beta`` bending-plane angle (rad), ``length`` arc length (m); all
    broadcast.  Rotation ``Rz(beta) Ry(theta) Rz(-beta)``; exact and finite at ``theta = 0`` (series).
    """
    t = as_array(theta, "theta")
    b = as_array(beta, "beta")
    ln = as_array(length, "length")
    if np.any(ln < 0.0):
        raise ValueError("Expected length >= 0, got a negative value.")
    return _segment_T(t, b, ln)


# ---- the whole robot ----------------------------------------------------------------------------
def _fk(robot: ContinuumRobot, theta: np.ndarray, beta: np.ndarray) -> np.ndarray:
    T = _segment_T(theta, beta, robot.segment_length)  # (..., n, 4, 4), composed in place
    for i in range(1, robot.n_segments):  # loop over the fixed, small number of segments
        T[..., i, :, :] = T[..., i - 1, :, :] @ T[..., i, :, :]
    return T


def forward_kinematics(robot: ContinuumRobot, psi: object) -> np.ndarray:
    """Poses ``T_0i (..., n, 4, 4)`` of every segment's end frame in the base frame (paper 3, eq. (3)).

    The array may be a non-contiguous view (the matrix entries are computed as contiguous planes).
    """
    theta, beta = _split(robot, psi)
    return _fk(robot, theta, beta)


def tip_position(robot: ContinuumRobot, psi: object) -> np.ndarray:
    """Tip position ``(..., 3)`` in the base frame (m)."""
    return forward_kinematics(robot, psi)[..., -1, :3, 3]


def _tip_jacobian(robot: ContinuumRobot, theta: np.ndarray, beta: np.ndarray) -> np.ndarray:
    n, L = robot.n_segments, robot.segment_length
    ct, st, cb, sb = np.cos(theta), np.sin(theta), np.cos(beta), np.sin(beta)
    # Columns as contiguous planes (6, 2, ..., n), returned as a (..., 6, 2n) view (see _segment_T).
    P = np.empty((6, 2, *theta.shape))
    # paper 3, eq. (6): local angular and linear velocity columns of one segment (verified correct).
    if np.any(np.abs(theta) < SMALL_ANGLE):
        g1, g2, fc = L * _df_cos(theta), L * _df_sin(theta), L * _f_cos(theta)
    else:  # the same closed forms, reusing the cosines
        inv = 1.0 / theta
        fc = L * (1.0 - ct) * inv
        g1 = (L * st - fc) * inv
        g2 = L * (ct - st * inv) * inv
    np.negative(sb, out=P[0, 0, ...])
    P[1, 0] = cb
    P[2, 0] = 0.0
    np.multiply(-cb, st, out=P[0, 1, ...])
    np.multiply(-sb, st, out=P[1, 1, ...])
    np.subtract(1.0, ct, out=P[2, 1, ...])
    np.multiply(cb, g1, out=P[3, 0, ...])
    np.multiply(sb, g1, out=P[4, 0, ...])
    P[5, 0] = g2
    np.multiply(-sb, fc, out=P[3, 1, ...])
    np.multiply(cb, fc, out=P[4, 1, ...])
    P[5, 1] = 0.0
    # (6, 2, ..., n) -> (..., 6, n, 2) -> (..., 6, 2n) with columns [theta_1, beta_1, theta_2, ...]
    J = np.moveaxis(P, (0, 1), (-3, -1))
    J = J.reshape(*theta.shape[:-1], 6, 2 * n)
    if n == 1:  # the local columns are the tip Jacobian: base frame = segment base, tip = segment end
        return J
    T = _fk(robot, theta, beta)
    p_tip = T[..., -1, :3, 3]
    for i in range(n):  # loop over the fixed, small number of segments
        cols = slice(2 * i, 2 * i + 2)
        if i > 0:  # rotate the local columns into the base frame
            R_prev = T[..., i - 1, :3, :3]
            J[..., :3, cols] = R_prev @ J[..., :3, cols]
            J[..., 3:, cols] = R_prev @ J[..., 3:, cols]
        if i < n - 1:  # the distal segments ride on segment i's end frame: v_tip += omega x r
            r = p_tip - T[..., i, :3, 3]
            J[..., 3:, cols] += np.cross(J[..., :3, cols], r[..., :, None], axis=-2)
    return J


def tip_jacobian(robot: ContinuumRobot, psi: object) -> np.ndarray:
    """Tip Jacobian ``J_x (..., 6, 2 n)``: ``[omega; v_tip] = J_x psi_dot`` in the base frame.

    ``omega`` is the tip frame's angular velocity and ``v_tip`` the velocity of the tip point (paper 3,
    eq. (6): J_xomega stacked on J_xv, angular first as in robomech's twists).
    """
    theta, beta = _split(robot, psi)
    return _tip_jacobian(robot, theta, beta)


def disk_transforms(robot: ContinuumRobot, psi: object) -> np.ndarray:
    """Poses of the base plate and of every disk, ``(..., 1 + n N, 4, 4)``, in the base frame."""
    theta, beta = _split(robot, psi)
    return _disk_T(robot, theta, beta)


def _disk_T(robot: ContinuumRobot, theta: np.ndarray, beta: np.ndarray) -> np.ndarray:
    n, N, L = robot.n_segments, robot.disks_per_segment, robot.segment_length
    frac = np.arange(1, N + 1) / N
    T_end = _fk(robot, theta, beta)
    out = np.empty((*theta.shape[:-1], 1 + n * N, 4, 4))
    out[..., 0, :, :] = np.eye(4)
    for i in range(n):
        T_loc = _segment_T(theta[..., i, None] * frac, beta[..., i, None], L * frac)  # (..., N, 4, 4)
        T_base = out[..., 0, :, :] if i == 0 else T_end[..., i - 1, :, :]
        out[..., 1 + i * N : 1 + (i + 1) * N, :, :] = T_base[..., None, :, :] @ T_loc
    return out


# ---- cable lengths --------------------------------------------------------------------------------
def _sinc(x: np.ndarray) -> np.ndarray:
    return _f_sin(x)


def _dsinc_over_x(x: np.ndarray) -> np.ndarray:
    """(d/dx sin x / x) / x = (x cos x - sin x) / x^3, finite at 0."""
    return _small_fix(x, lambda v: (v * np.cos(v) - np.sin(v)) / v**3, lambda v: -1.0 / 3.0 + v**2 / 30.0)


def _segment_spans(
    robot: ContinuumRobot, theta: np.ndarray, beta: np.ndarray, model: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Span length of every cable in every segment, d/dtheta and (d/dbeta)/theta: (..., 3n, n) each.

    d/dbeta is proportional to theta; returning it divided by theta keeps it finite in coordinates
    (theta cos beta, theta sin beta) that are smooth through the straight pose.

    Arc model (paper 3, eq. (4)): the cable is parallel to the core, span = (l - r theta cos(beta -
    sigma)) / N.  Chord model: the cable is straight between consecutive holes (paper 3, eq. (21)); both
    holes lie at distance 1/kappa - d from the centre of curvature, d = r cos(beta - sigma), so the
    span is 2 (1/kappa - d) sin(theta / 2N) = (l - d theta)/N * sinc(theta / 2N).
    """
    N, L, r = robot.disks_per_segment, robot.segment_length, robot.hole_radius
    sig = robot.hole_angles  # (3n,)
    th = theta[..., None, :]  # (..., 1, n)
    be = beta[..., None, :] - sig[:, None]  # (..., 3n, n)
    d = r * np.cos(be)
    d_dbeta = -r * np.sin(be)
    a = (L - d * th) / N  # arc span
    if model == "arc":
        return a, np.broadcast_to(-d / N, a.shape), np.broadcast_to(-d_dbeta / N, a.shape)
    if model != "chord":
        raise ValueError(f"Expected model 'arc' or 'chord', got {model!r}.")
    x = th / (2 * N)
    s = _sinc(x)
    ds = _dsinc_over_x(x) * x  # d sinc / dx
    ell = a * s
    dth = (-d / N) * s + a * ds / (2 * N)
    dbe_over_theta = (-d_dbeta / N) * s
    return ell, dth, dbe_over_theta


def _active(robot: ContinuumRobot) -> np.ndarray:
    """(3n, n) mask: cable c runs through segment m."""
    return robot.cable_segment[:, None] >= np.arange(robot.n_segments)[None, :]


def span_lengths(robot: ContinuumRobot, psi: object, model: CableModel = "chord") -> np.ndarray:
    """Length of every cable span ``(..., 3 n, n N)`` (zero beyond the cable's termination disk)."""
    theta, beta = _split(robot, psi)
    ell, _, _ = _segment_spans(robot, theta, beta, model)
    return np.repeat(np.where(_active(robot), ell, 0.0), robot.disks_per_segment, axis=-1)


def span_jacobian(robot: ContinuumRobot, psi: object, model: CableModel = "chord") -> np.ndarray:
    """``d span / d psi``: ``(..., 3 n, n N, 2 n)``."""
    theta, beta = _split(robot, psi)
    return _span_jac(robot, theta, beta, model)


def _span_jac(robot: ContinuumRobot, theta: np.ndarray, beta: np.ndarray, model: str) -> np.ndarray:
    n, N = robot.n_segments, robot.disks_per_segment
    _, dth, dbe_t = _segment_spans(robot, theta, beta, model)
    dbe = dbe_t * theta[..., None, :]
    act = _active(robot)
    J = np.zeros((*theta.shape[:-1], robot.n_cables, n, 2 * n))
    for m in range(n):
        J[..., :, m, 2 * m] = np.where(act[:, m], dth[..., :, m], 0.0)
        J[..., :, m, 2 * m + 1] = np.where(act[:, m], dbe[..., :, m], 0.0)
    return np.repeat(J, N, axis=-2)


def cable_lengths(robot: ContinuumRobot, psi: object, model: CableModel = "arc") -> np.ndarray:
    """Geometric length of every cable from the base plate to its termination disk, ``(..., 3 n)`` (m).

    ``model="arc"`` is paper 3, eq. (4) (cable parallel to the core); ``model="chord"`` takes straight
    cable spans between the holes of consecutive disks (what a real cable does).
    """
    theta, beta = _split(robot, psi)
    ell, _, _ = _segment_spans(robot, theta, beta, model)
    return robot.disks_per_segment * np.sum(np.where(_active(robot), ell, 0.0), axis=-1)


def cable_jacobian(robot: ContinuumRobot, psi: object, model: CableModel = "arc") -> np.ndarray:
    """``J_qpsi = d cable_lengths / d psi``, ``(..., 3 n, 2 n)`` (paper 3, eq. (5) for one segment)."""
    theta, beta = _split(robot, psi)
    return _span_jac(robot, theta, beta, model).sum(axis=-2)


# ---- inverse kinematics ---------------------------------------------------------------------------
@dataclass(frozen=True)
class IKResult:
    """Inverse kinematics from a tip position (batch shape ``...``).

    ``psi (..., 2 n)`` with theta >= 0 and beta in (-pi, pi]; ``reachable`` where the tip residual
    ``residual`` (m) is below ``IK_TOLERANCE``; otherwise ``psi`` is the least-squares (closest) pose.
    ``converged`` where the iteration met its step criterion.
    """

    psi: np.ndarray
    residual: np.ndarray
    reachable: np.ndarray
    converged: np.ndarray
    iterations: np.ndarray


def _normalise(theta: np.ndarray, beta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    neg = theta < 0.0
    theta = np.abs(theta)
    beta = np.where(neg, beta + np.pi, beta)
    beta = np.arctan2(np.sin(beta), np.cos(beta))
    return theta, beta


def inverse_kinematics(robot: ContinuumRobot, p_tip: object) -> IKResult:
    """Bend parameters ``psi`` that put the tip at ``p_tip (..., 3)`` (m).

    Start: the single constant-curvature arc through all segments (exact for every reachable tip of a
    one-segment robot: beta = atan2(y, x), theta = 2 atan2(sqrt(x^2 + y^2), z)), refined by damped
    Gauss-Newton on the tip position (minimum-norm steps for the redundant n >= 2 robot).
    """
    p = as_array(p_tip, "p_tip", (3,))
    n, L = robot.n_segments, robot.segment_length
    batch = p.shape[:-1]
    pf = p.reshape(-1, 3)
    rh = np.hypot(pf[:, 0], pf[:, 1])
    theta = np.repeat((2.0 * np.arctan2(rh, pf[:, 2]) / n)[:, None], n, axis=-1)
    beta = np.repeat(np.arctan2(pf[:, 1], pf[:, 0])[:, None], n, axis=-1)
    res = np.linalg.norm(pf - _fk(robot, theta, beta)[:, -1, :3, 3], axis=-1)
    converged = res < IK_TOLERANCE  # the single-arc start is exact for every reachable one-segment tip
    iterations = np.zeros(pf.shape[0], dtype=int)
    idx = np.flatnonzero(~converged)
    eye = np.eye(2 * n)
    for _ in range(IK_MAX_ITERATIONS):  # iterations, not samples: every step acts on the unconverged set
        if idx.size == 0:
            break
        th, be, pp = theta[idx], beta[idx], pf[idx]
        e = pp - _fk(robot, th, be)[:, -1, :3, 3]
        Jv = _tip_jacobian(robot, th, be)[:, 3:, :]
        JtJ = np.swapaxes(Jv, -1, -2) @ Jv + IK_DAMPING * eye
        step = np.linalg.solve(JtJ, np.einsum("...ji,...j->...i", Jv, e)[..., None])[..., 0]
        theta[idx] = th + step[:, 0::2]
        beta[idx] = be + step[:, 1::2]
        iterations[idx] += 1
        done = np.linalg.norm(step, axis=-1) * L < IK_TOLERANCE
        converged[idx[done]] = True
        res[idx] = np.linalg.norm(pp - _fk(robot, theta[idx], beta[idx])[:, -1, :3, 3], axis=-1)
        idx = idx[~done]
    theta, beta = _normalise(theta, beta)
    psi = np.stack([theta, beta], -1).reshape(*batch, 2 * n)
    res, converged, iterations = res.reshape(batch), converged.reshape(batch), iterations.reshape(batch)
    return IKResult(
        psi=psi, residual=res, reachable=res < IK_TOLERANCE, converged=converged, iterations=iterations
    )
