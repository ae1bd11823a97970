"""Constant-curvature kinematics (paper 3, Sec. 1, eqs. (1)-(6)): segment poses, cable lengths,
Jacobians, IK.  Coordinates ``psi``, frames and cable indexing: ``docs/mechanisms/continuum.md``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from robomech._batching import carries_failed_rows, slices
from robomech._validation import as_array, broadcast_batch, check_params
from robomech.spatial import SMALL_ANGLE

# the unvalidated kernel: inputs are validated once at this module's public boundary
from robomech.spatial._so3 import _sincos as sincos

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

# Samples per chunk of the segment kernels: the ~20 temporaries of a chunk stay in cache and are recycled
# (whole-batch ones are fresh pages, ~1 ms of page faults each).  Measured on 10^6 one-segment poses
# (FK / Jacobian / IK, ms): 2048: 46/44/45, 8192: 34/30/36, 16384: 32/28/32, 32768: 31/29/37.
CHUNK = 16384

# IK: a tip position is reached when the residual is below 1e-10 m (0.1 nm: far below any physical
# tolerance, above the ~1e-16 * 0.1 m rounding of the forward kinematics).
IK_TOLERANCE = 1e-10
# Levenberg-Marquardt iterations per start: over 10^5 random 2- and 3-segment targets, 99.9 % of those
# reached need <= 17 (theta_i <= pi) or <= 22 (<= 6 rad) from the single arc, <= 48 from the others; 40
# keeps all but a handful (another start reaches them) and bounds the cost of unreachable targets.
IK_MAX_ITERATIONS = 40
# Damping lam = mu l^2 (J J^T ~ l^2): mu starts at 1e-3, a mild trust region (nearly a Gauss-Newton step).
IK_DAMPING_INITIAL = 1e-3
# After an accepted step mu /= 3, after a rejected one mu *= 4: the usual asymmetric Levenberg factors
# (damping grows faster than it shrinks, so a run of rejections quickly reaches a gradient step).
IK_DAMPING_DECREASE = 1.0 / 3.0
IK_DAMPING_INCREASE = 4.0
# mu in [1e-12, 1e12]: the lower bound keeps J J^T + lam I positive definite at the singular straight pose
# (condition <= ~1e12, solved to ~1e-4 relative: enough for a damped step) without slowing convergence;
# the upper bound keeps lam finite (a 1e-12 gradient step already ends the iteration).
IK_DAMPING_MIN = 1e-12
IK_DAMPING_MAX = 1e12
# The Jacobian in u needs (d p / d beta) / theta, 0/0 at theta = 0; it is continuous in u, so it is taken
# at theta = max(theta, 1e-12 rad): this moves it by ~1e-12 * n l m/rad (the residual stays exact), and
# (d p / d beta) / theta stays accurate to ~1e-16 (series below SMALL_ANGLE; no underflow at 1e-12).
IK_THETA_FLOOR = 1e-12
# Alternative starts for n >= 2, in the target's azimuthal frame: (theta, plane angle) of the proximal
# segments, then of the distal one (rad), chosen greedily on the single arc's failures over 2 x 10^5
# random 2- and 3-segment targets (curled in the target's plane, S-shapes, curled out of it), in order.
IK_STARTS = (
    ((3.0, 0.0), (3.0, 0.0)),
    ((2.0, -np.pi / 2), (2.0, np.pi)),
    ((1.0, 0.0), (1.0, np.pi)),
    ((2.0, -np.pi / 2), (3.0, -np.pi / 2)),
)


# ---- scalar functions of the bend angle, exact and finite at theta = 0 --------------------------
# Taylor series used below SMALL_ANGLE (error O(t^6) < 1e-24 there).
def _series_f_cos(x: np.ndarray) -> np.ndarray:
    return x / 2.0 - x**3 / 24.0 + x**5 / 720.0


def _series_f_sin(x: np.ndarray) -> np.ndarray:
    return 1.0 - x**2 / 6.0 + x**4 / 120.0


def _series_df_cos(x: np.ndarray) -> np.ndarray:
    return 0.5 - x**2 / 8.0 + x**4 / 144.0


def _series_df_sin(x: np.ndarray) -> np.ndarray:
    return -x / 3.0 + x**3 / 30.0


def _small_fix(t: np.ndarray, closed, series) -> np.ndarray:
    """``closed(t)`` with the entries below SMALL_ANGLE replaced by ``series(t)`` (no 0/0 evaluated)."""
    t = np.asarray(t, dtype=float)
    small = np.abs(t) < SMALL_ANGLE
    if not np.any(small):
        return closed(t)
    out = np.array(closed(np.where(small, 1.0, t)), dtype=float)
    out[small] = series(t[small])
    return out


def _half_angle(angle: np.ndarray) -> tuple[np.ndarray, ...]:
    """``(sin, cos, 1 - cos)`` of ``angle``: ``robomech.spatial.sincos``'s half-angle formulas, with
    ``1 - cos = 2 t^2 / (1 + t^2)`` (no cancellation at small angles) from the same ``t``."""
    t = np.tan(0.5 * angle)
    t2 = t * t
    d = 1.0 / (1.0 + t2)
    s = 2.0 * t * d
    c = (1.0 - t2) * d
    t2 *= 2.0
    t2 *= d
    return s, c, t2


def _bend_scalars(
    theta: np.ndarray, st: np.ndarray, ct: np.ndarray, omc: np.ndarray, derivatives: bool
) -> tuple[np.ndarray, ...]:
    """``(1 - cos t)/t, sin t / t`` and, with ``derivatives``, their derivatives (paper 3, eq. (6)),
    from the trigonometry of ``theta``; Taylor series on the entries below SMALL_ANGLE."""
    small = np.abs(theta) < SMALL_ANGLE
    any_small = bool(small.any())
    inv = 1.0 / (np.where(small, 1.0, theta) if any_small else theta)
    fc, fs = omc * inv, st * inv
    out = (fc, fs, (st - fc) * inv, (ct - fs) * inv) if derivatives else (fc, fs)
    if any_small:
        ts = theta[small]
        series = (_series_f_cos, _series_f_sin, _series_df_cos, _series_df_sin)
        for o, f in zip(out, series, strict=False):
            o[small] = f(ts)
    return out


def _flat(a: np.ndarray, shape: tuple) -> np.ndarray:
    """``a`` broadcast to ``shape`` and flattened (a view where the strides allow)."""
    return np.broadcast_to(a, shape).reshape(-1)


def _split(
    robot: ContinuumRobot, psi: object, name: str = "psi", views: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """``(theta, beta)`` of ``psi``: contiguous copies (numpy's vectorised trigonometry is ~2x faster on
    contiguous input), or strided ``views`` for the chunked kernels (which copy chunk by chunk)."""
    p = as_array(psi, name, (2 * robot.n_segments,))
    if views:
        return p[..., 0::2], p[..., 1::2]
    return np.ascontiguousarray(p[..., 0::2]), np.ascontiguousarray(p[..., 1::2])


# ---- one segment --------------------------------------------------------------------------------
def _segment_T(theta: np.ndarray, beta: np.ndarray, length: np.ndarray | float) -> np.ndarray:
    """Segment poses (..., 4, 4): a view of ``_segment_planes`` with the matrix axes last."""
    return np.moveaxis(_segment_planes(theta, beta, length), (0, 1), (-2, -1))


def _segment_planes(theta: np.ndarray, beta: np.ndarray, length: np.ndarray | float) -> np.ndarray:
    """Segment poses as 16 contiguous planes (4, 4, ...): writing planes is several times faster than
    16 strided writes.  Chunks of CHUNK samples keep the temporaries in cache; inputs of any strides."""
    shape = np.broadcast_shapes(np.shape(theta), np.shape(beta), np.shape(length))
    P = np.empty((4, 4, *shape))
    Pf = P.reshape(16, -1)
    th, be = _flat(theta, shape), _flat(beta, shape)
    scalar_length = np.ndim(length) == 0
    ln_arr = None if scalar_length else _flat(np.asarray(length, dtype=float), shape)
    ln = float(length) if scalar_length else 0.0
    for c in slices(th.size, CHUNK):
        t = np.ascontiguousarray(th[c])
        st, ct, omc = _half_angle(t)
        sb, cb = sincos(be[c])
        fc, fs = _bend_scalars(t, st, ct, omc, derivatives=False)
        # R = Rz(beta) Ry(theta) Rz(-beta) = I - (1 - cos theta) [cb^2, cb sb, .; cb sb, sb^2, .; ...] + ...
        # paper 3, eq. (1): printed element (2,1) c(beta)s(beta)c(theta); the product gives
        # c(beta)s(beta)(c(theta) - 1) (symmetric with element (1,2)).
        w = cb * omc
        np.multiply(w, cb, out=Pf[0, c])
        np.subtract(1.0, Pf[0, c], out=Pf[0, c])  # ct cb^2 + sb^2 = 1 - (1 - ct) cb^2
        np.multiply(w, sb, out=Pf[1, c])
        np.negative(Pf[1, c], out=Pf[1, c])
        Pf[4, c] = Pf[1, c]
        np.multiply(cb, st, out=Pf[2, c])
        np.multiply(sb * omc, sb, out=Pf[5, c])
        np.subtract(1.0, Pf[5, c], out=Pf[5, c])  # sb^2 ct + cb^2
        np.multiply(sb, st, out=Pf[6, c])
        np.negative(Pf[2, c], out=Pf[8, c])
        np.negative(Pf[6, c], out=Pf[9, c])
        Pf[10, c] = ct
        # paper 3, eq. (2), written with (1 - cos t)/t and sin t / t so that it is finite at theta = 0
        # (Taylor series on the rare entries below SMALL_ANGLE).
        lc = ln if ln_arr is None else ln_arr[c]
        fc *= lc
        np.multiply(fc, cb, out=Pf[3, c])
        np.multiply(fc, sb, out=Pf[7, c])
        np.multiply(fs, lc, out=Pf[11, c])
    Pf[12:15] = 0.0
    Pf[15] = 1.0
    return P


@carries_failed_rows({"theta": 0, "beta": 0}, {"length": 0})
def segment_transform(theta: object, beta: object, length: object) -> np.ndarray:
    """Pose ``T (..., 4, 4)`` of a constant-curvature segment's end frame in its base frame.

    Rotation ``Rz(beta) Ry(theta) Rz(-beta)``; exact and finite at ``theta = 0`` (series).

    Parameters
    ----------
    theta, beta : array_like, shape (...)
        Bend angle and bending-plane angle about the base z axis (rad).
    length : array_like, shape (...)
        Arc length of the segment (m).  The three arguments broadcast.
    """
    t = as_array(theta, "theta")
    b = as_array(beta, "beta")
    ln = as_array(length, "length")
    broadcast_batch((t, 0, "theta"), (b, 0, "beta"), (ln, 0, "length"))
    if np.any(ln < 0.0):
        raise ValueError("Expected length >= 0, got a negative value.")
    return _segment_T(t, b, ln)


# ---- the whole robot ----------------------------------------------------------------------------
def _fk(robot: ContinuumRobot, theta: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Poses ``T_0i (..., n, 4, 4)``: a view of ``_fk_planes`` with the matrix axes last."""
    return np.moveaxis(_fk_planes(robot, theta, beta), (0, 1), (-2, -1))


def _fk_planes(robot: ContinuumRobot, theta: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Poses ``T_0i`` as planes (4, 4, ..., n), composed in place plane by plane:
    T_0i = T_0,i-1 T_i-1,i as 12 entries of three products each plus the translation (the bottom rows
    are (0, 0, 0, 1)); a batched 4x4 ``@`` on these strided matrices is several times slower."""
    P = _segment_planes(theta, beta, robot.segment_length)  # (4, 4, ..., n)
    for i in range(1, robot.n_segments):  # loop over the fixed, small number of segments
        A, B = P[:3, ..., i - 1], P[..., i]
        C = A[:, 0, None] * B[0]  # (3, 4, ...): C[r, c] = sum_k A[r, k] B[k, c], k in the order 0, 1, 2
        C += A[:, 1, None] * B[1]
        C += A[:, 2, None] * B[2]
        C[:, 3] += A[:, 3]
        P[:3, ..., i] = C
    return P


@carries_failed_rows({"psi": 1})
def forward_kinematics(robot: ContinuumRobot, psi: object) -> np.ndarray:
    """Poses ``T_0i (..., n, 4, 4)`` of every segment's end frame in the base frame (paper 3, eq. (3)).

    The array may be a non-contiguous view (the matrix entries are computed as contiguous planes).

    Parameters
    ----------
    robot : ContinuumRobot
    psi : array_like, shape (..., 2 n)
        ``[theta_1, beta_1, ...]``: bend and bending-plane angle of each of the n segments (rad); the
        same argument in every function of the package.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.mechanisms import continuum as cr
    >>> robot = cr.ContinuumRobot.paper()                       # one 0.09 m segment
    >>> T = cr.forward_kinematics(robot, np.array([np.pi / 2, 0.0]))   # bent 90 deg in the x-z plane
    >>> T.shape, T[0, :3, 3].round(6)                          # on an arc of radius 0.09 / (pi/2)
    ((1, 4, 4), array([0.057296, 0.      , 0.057296]))
    """
    check_params(robot, ContinuumRobot, "robot")
    theta, beta = _split(robot, psi, views=True)
    return _fk(robot, theta, beta)


@carries_failed_rows({"psi": 1})
def tip_position(robot: ContinuumRobot, psi: object) -> np.ndarray:
    """Tip position ``(..., 3)`` in the base frame (m) at ``psi (..., 2 n)``.

    Returns
    -------
    ndarray, shape (..., 3)
    """
    check_params(robot, ContinuumRobot, "robot")
    return forward_kinematics(robot, psi)[..., -1, :3, 3]


def _local_columns(theta: np.ndarray, beta: np.ndarray, length: float) -> np.ndarray:
    """Every segment's local Jacobian columns (paper 3, eq. (6), in the segment's base frame) as
    contiguous planes ``(6, 2, ...)``, in chunks of CHUNK samples; inputs of any strides."""
    shape = np.broadcast_shapes(np.shape(theta), np.shape(beta))
    P = np.empty((6, 2, *shape))
    Pf = P.reshape(12, -1)
    th, be = _flat(theta, shape), _flat(beta, shape)
    for c in slices(th.size, CHUNK):
        t = np.ascontiguousarray(th[c])
        st, ct, omc = _half_angle(t)
        sb, cb = sincos(be[c])
        fc, _, g1, g2 = _bend_scalars(t, st, ct, omc, derivatives=True)
        np.negative(sb, out=Pf[0, c])  # row 0: omega_x, columns (theta, beta)
        np.multiply(cb, st, out=Pf[1, c])
        np.negative(Pf[1, c], out=Pf[1, c])
        Pf[2, c] = cb
        np.multiply(sb, st, out=Pf[3, c])
        np.negative(Pf[3, c], out=Pf[3, c])
        Pf[5, c] = omc  # 1 - cos theta
        fc *= length
        g1 *= length
        np.multiply(cb, g1, out=Pf[6, c])
        np.multiply(sb, fc, out=Pf[7, c])
        np.negative(Pf[7, c], out=Pf[7, c])
        np.multiply(sb, g1, out=Pf[8, c])
        np.multiply(cb, fc, out=Pf[9, c])
        np.multiply(g2, length, out=Pf[10, c])
    Pf[4] = 0.0
    Pf[11] = 0.0
    return P


def _tip_jacobian(robot: ContinuumRobot, theta: np.ndarray, beta: np.ndarray) -> np.ndarray:
    n = robot.n_segments
    # Columns as contiguous planes (6, 2, ..., n), returned as a (..., 6, 2n) view (see _segment_T).
    P = _local_columns(theta, beta, robot.segment_length)
    if n > 1:  # plane arithmetic (a batched @ and np.cross on these strided blocks are several times slower)
        T = _fk_planes(robot, theta, beta)  # (4, 4, ..., n)
        p_tip = T[:3, 3, ..., n - 1]  # (3, ...)
        for i in range(n):  # loop over the fixed, small number of segments
            W, V = P[:3, :, ..., i], P[3:, :, ..., i]  # (3, 2, ...): angular and linear rows
            if i > 0:  # rotate the local columns into the base frame: R_0,i-1 W, R_0,i-1 V
                R = T[:3, :3, None, ..., i - 1]  # (3, 3, 1, ...), broadcast over the two columns
                W = R[:, 0] * W[0] + R[:, 1] * W[1] + R[:, 2] * W[2]
                V = R[:, 0] * V[0] + R[:, 1] * V[1] + R[:, 2] * V[2]
            if i < n - 1:  # the distal segments ride on segment i's end frame: v_tip += omega x r
                r = (p_tip - T[:3, 3, ..., i])[:, None]  # (3, 1, ...)
                V = V + np.stack(
                    [W[1] * r[2] - W[2] * r[1], W[2] * r[0] - W[0] * r[2], W[0] * r[1] - W[1] * r[0]]
                )
            P[:3, :, ..., i] = W
            P[3:, :, ..., i] = V
    # (6, 2, ..., n) -> (..., 6, n, 2) -> (..., 6, 2n) with columns [theta_1, beta_1, theta_2, ...]
    J = np.moveaxis(P, (0, 1), (-3, -1))
    return J.reshape(*theta.shape[:-1], 6, 2 * n)


@carries_failed_rows({"psi": 1})
def tip_jacobian(robot: ContinuumRobot, psi: object) -> np.ndarray:
    """Tip Jacobian ``J_x (..., 6, 2 n)``: ``[omega; v_tip] = J_x psi_dot`` in the base frame.

    ``omega`` is the tip frame's angular velocity and ``v_tip`` the velocity of the tip point (paper 3,
    eq. (6): J_xomega stacked on J_xv, angular first as in robomech's twists).

    Returns
    -------
    ndarray, shape (..., 6, 2 n)
    """
    check_params(robot, ContinuumRobot, "robot")
    theta, beta = _split(robot, psi, views=True)
    return _tip_jacobian(robot, theta, beta)


@carries_failed_rows({"psi": 1})
def disk_transforms(robot: ContinuumRobot, psi: object) -> np.ndarray:
    """Poses ``(..., 1 + n N, 4, 4)`` of the base plate, then the N disks of each segment, in the base
    frame (m).

    Returns
    -------
    ndarray, shape (..., 1 + n N, 4, 4)
    """
    check_params(robot, ContinuumRobot, "robot")
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
    """sin x / x, finite at 0."""
    return _small_fix(x, lambda v: np.sin(v) / v, _series_f_sin)


def _dsinc_over_x(x: np.ndarray) -> np.ndarray:
    """(d/dx sin x / x) / x = (x cos x - sin x) / x^3, finite at 0."""
    return _small_fix(x, lambda v: (v * np.cos(v) - np.sin(v)) / v**3, lambda v: -1.0 / 3.0 + v**2 / 30.0)


def _segment_spans(
    robot: ContinuumRobot, theta: np.ndarray, beta: np.ndarray, model: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Span length of every cable in every segment, d/dtheta and (d/dbeta)/theta (finite through the
    straight pose): (..., 3n, n) each.  Arc (paper 3, eq. (4)) and chord spans
    ``(l - d theta)/N * sinc(theta / 2N)``, ``d = r cos(beta - sigma)`` (docs/mechanisms/continuum.md)."""
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


def _span_active(robot: ContinuumRobot) -> np.ndarray:
    """(3 n, n N) mask: cable c runs over span (disk interval) j."""
    N = robot.disks_per_segment
    return np.arange(robot.n_segments * N)[None, :] < (N * (robot.cable_segment + 1))[:, None]


@carries_failed_rows({"psi": 1})
def span_lengths(robot: ContinuumRobot, psi: object, model: CableModel = "chord") -> np.ndarray:
    """Length (m) of every cable span between consecutive disks, ``(..., 3 n, n N)`` (zero beyond the
    cable's termination disk); ``model`` the cable path, as in :func:`cable_lengths`.

    Returns
    -------
    ndarray, shape (..., 3 n, n N)
    """
    check_params(robot, ContinuumRobot, "robot")
    theta, beta = _split(robot, psi)
    ell, _, _ = _segment_spans(robot, theta, beta, model)
    return np.repeat(np.where(_active(robot), ell, 0.0), robot.disks_per_segment, axis=-1)


@carries_failed_rows({"psi": 1})
def span_jacobian(robot: ContinuumRobot, psi: object, model: CableModel = "chord") -> np.ndarray:
    """``d span_lengths / d psi`` (m/rad): ``(..., 3 n, n N, 2 n)``.

    Returns
    -------
    ndarray, shape (..., 3 n, n N, 2 n)
    """
    check_params(robot, ContinuumRobot, "robot")
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


@carries_failed_rows({"psi": 1})
def cable_lengths(robot: ContinuumRobot, psi: object, model: CableModel = "arc") -> np.ndarray:
    """Geometric length of every cable from the base plate to its termination disk, ``(..., 3 n)`` (m).

    ``model="arc"`` is paper 3, eq. (4) (cable parallel to the core); ``model="chord"`` takes straight
    cable spans between the holes of consecutive disks (what a real cable does).  Cable ``3 i + j``
    belongs to segment i.

    Returns
    -------
    ndarray, shape (..., 3 n)
    """
    check_params(robot, ContinuumRobot, "robot")
    theta, beta = _split(robot, psi)
    ell, _, _ = _segment_spans(robot, theta, beta, model)
    return robot.disks_per_segment * np.sum(np.where(_active(robot), ell, 0.0), axis=-1)


@carries_failed_rows({"psi": 1})
def cable_jacobian(robot: ContinuumRobot, psi: object, model: CableModel = "arc") -> np.ndarray:
    """``J_qpsi = d cable_lengths / d psi`` (m/rad), ``(..., 3 n, 2 n)`` (paper 3, eq. (5), one segment).

    Returns
    -------
    ndarray, shape (..., 3 n, 2 n)
    """
    check_params(robot, ContinuumRobot, "robot")
    theta, beta = _split(robot, psi)
    return _span_jac(robot, theta, beta, model).sum(axis=-2)


# ---- inverse kinematics ---------------------------------------------------------------------------
@dataclass(frozen=True)
class IKResult:
    """Inverse kinematics from a tip position (the result of :func:`inverse_kinematics`).

    Attributes
    ----------
    psi : ndarray, shape (..., 2 n)
        ``[theta_1, beta_1, ...]`` (rad), theta >= 0, beta in (-pi, pi] (0 where theta = 0); where not
        ``reachable``, the best least-squares pose found.
    residual : ndarray, shape (...)
        Distance of the pose's tip from the target (m).
    reachable, converged : ndarray of bool, shape (...)
        ``residual`` below ``IK_TOLERANCE``; the solver stopped on its own criterion (reached, or a
        stationary point), not on the iteration cap.
    iterations : ndarray of int, shape (...)
        Iterations of all starts tried for the sample.
    """

    psi: np.ndarray
    residual: np.ndarray
    reachable: np.ndarray
    converged: np.ndarray
    iterations: np.ndarray


def _normalise(theta: np.ndarray, beta: np.ndarray) -> None:
    """In place: theta >= 0 (a negative bend is the opposite plane) and beta in [-pi, pi]; entries
    already there (every pose the solver returns: theta from a norm or atan2, beta from atan2) are left
    bit for bit as they are."""
    bad = (theta < 0.0) | (np.abs(beta) > np.pi)
    if np.any(bad):
        t, b = theta[bad], beta[bad]
        b = np.where(t < 0.0, b + np.pi, b)
        theta[bad] = np.abs(t)
        beta[bad] = np.arctan2(np.sin(b), np.cos(b))


def _u_to_psi(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bending vectors ``u (..., n, 2)`` -> ``(theta, beta)`` (..., n); theta >= 0, beta := 0 at theta = 0."""
    ux, uy = u[..., 0], u[..., 1]
    theta = np.sqrt(ux * ux + uy * uy)  # np.hypot is ~10x slower; only |u| < 1e-154 (straight) loses digits
    # arctan2(-0.0, -0.0) = -pi: the straight segment gets the convention beta = 0 explicitly
    beta = np.where(theta > 0.0, np.arctan2(u[..., 1], u[..., 0]), 0.0)
    return theta, beta


def _psi_to_u(theta: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """``(theta, beta)`` (..., n) -> bending vectors ``u = theta (cos beta, sin beta)`` (..., n, 2)."""
    s, c = sincos(beta)
    return np.stack([theta * c, theta * s], -1)


def _tip_u(robot: ContinuumRobot, u: np.ndarray) -> np.ndarray:
    """Tip position (..., 3) of bending vectors ``u (..., n, 2)`` (exact at u = 0: series in _segment_T)."""
    theta, beta = _u_to_psi(u)
    return _fk(robot, theta, beta)[..., -1, :3, 3]


def _tip_jacobian_u(robot: ContinuumRobot, u: np.ndarray) -> np.ndarray:
    """``d p_tip / d u`` (..., 3, 2 n), columns ``[u_1x, u_1y, u_2x, ...]``, by the chain rule from
    ``_tip_jacobian``: d/du_x = cos(b) d/dtheta - sin(b) (d/dbeta)/theta, d/du_y = sin(b) d/dtheta +
    cos(b) (d/dbeta)/theta.  Evaluated at theta = max(theta, IK_THETA_FLOOR) (see there)."""
    theta, beta = _u_to_psi(u)
    theta = np.maximum(theta, IK_THETA_FLOOR)
    J = _tip_jacobian(robot, theta, beta)[..., 3:, :]
    J_th, J_be = J[..., 0::2], J[..., 1::2] / theta[..., None, :]  # (..., 3, n) each
    s, c = sincos(beta[..., None, :])
    Ju = np.stack([c * J_th - s * J_be, s * J_th + c * J_be], -1)  # (..., 3, n, 2)
    return Ju.reshape(*Ju.shape[:-2], 2 * robot.n_segments)


def _lm_step(J: np.ndarray, e: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """Levenberg-Marquardt step ``(J^T J + lam I)^-1 J^T e`` for ``J (k, 3, m)``, ``e (k, 3)``, ``lam (k,)``.

    For m > 3 (redundant robot) the identical ``J^T (J J^T + lam I)^-1 e`` solves a 3x3 system instead.
    """
    m = J.shape[-1]
    Jt = np.swapaxes(J, -1, -2)
    if m > 3:
        A = J @ Jt + lam[:, None, None] * np.eye(3)
        return (Jt @ np.linalg.solve(A, e[..., None]))[..., 0]
    A = Jt @ J + lam[:, None, None] * np.eye(m)
    return np.linalg.solve(A, (Jt @ e[..., None]))[..., 0]


def _ik_solve(robot: ContinuumRobot, p: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, ...]:
    """Levenberg-Marquardt on the tip position in bending-vector coordinates from ``u (k, n, 2)``, with
    per-sample adaptive damping ``lam = mu l^2``, on the whole unconverged subset at every iteration
    (docs/mechanisms/continuum.md).  Returns ``u, residual, converged, iterations``."""
    L2 = robot.segment_length**2
    u = u.copy()
    e_all = p - _tip_u(robot, u)
    res = np.linalg.norm(e_all, axis=-1)
    converged = res < IK_TOLERANCE
    iterations = np.zeros(p.shape[0], dtype=int)
    mu = np.full(p.shape[0], IK_DAMPING_INITIAL)
    idx = np.flatnonzero(~converged)
    J, e = _tip_jacobian_u(robot, u[idx]), e_all[idx]
    for _ in range(IK_MAX_ITERATIONS):  # iterations, not samples: every step acts on the unconverged set
        if idx.size == 0:
            break
        step = _lm_step(J, e, mu[idx] * L2)
        trial = u[idx] + step.reshape(-1, robot.n_segments, 2)
        e_trial = p[idx] - _tip_u(robot, trial)
        r_trial = np.linalg.norm(e_trial, axis=-1)
        iterations[idx] += 1
        accept = r_trial < res[idx]
        u[idx[accept]] = trial[accept]
        res[idx[accept]] = r_trial[accept]
        mu[idx] = np.where(
            accept,
            np.maximum(mu[idx] * IK_DAMPING_DECREASE, IK_DAMPING_MIN),
            np.minimum(mu[idx] * IK_DAMPING_INCREASE, IK_DAMPING_MAX),
        )
        done = (accept & (r_trial < IK_TOLERANCE)) | (
            np.linalg.norm(step, axis=-1) * robot.segment_length < IK_TOLERANCE
        )
        converged[idx[done]] = True
        keep = ~done
        idx, J, e = idx[keep], J[keep], e[keep]
        moved = accept[keep]  # new linearisation only where the step was accepted
        if np.any(moved):
            J[moved] = _tip_jacobian_u(robot, u[idx[moved]])
            e[moved] = e_trial[keep][moved]
    return u, res, converged, iterations


def _ik_start(robot: ContinuumRobot, p: np.ndarray, shape: tuple) -> np.ndarray:
    """Start ``u (k, n, 2)`` of one IK_STARTS shape, rotated to the azimuth of every target ``p (k, 3)``."""
    n = robot.n_segments
    (th_p, be_p), (th_d, be_d) = shape
    th = np.array([th_p] * (n - 1) + [th_d])
    be = np.arctan2(p[:, 1], p[:, 0])[:, None] + np.array([be_p] * (n - 1) + [be_d])
    return _psi_to_u(np.broadcast_to(th, be.shape), be)


def _single_arc(robot: ContinuumRobot, p: np.ndarray, theta: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """The single constant-curvature arc through every tip ``p (k, 3)``: writes ``theta, beta (k, n)``
    and returns the tip residual ``(k,)`` of that pose (one segment: chunked, with the formulas of
    _segment_T; n >= 2: from the composed forward kinematics)."""
    n, L = robot.n_segments, robot.segment_length
    res = np.empty(p.shape[0])
    for c in slices(p.shape[0], CHUNK):
        x, y, z = p[c, 0], p[c, 1], p[c, 2]
        rh = x * x
        rh += y * y
        np.sqrt(rh, out=rh)  # sqrt(x^2 + y^2): np.hypot is ~10x slower here, and tips never underflow
        th = np.arctan2(rh, z)
        th *= 2.0
        if n > 1:
            th /= n
        be = np.arctan2(y, x)
        theta[c] = th[:, None]
        beta[c] = be[:, None]
        if n > 1:
            continue
        st, ct, omc = _half_angle(th)
        sb, cb = sincos(be)
        fc, fs = _bend_scalars(th, st, ct, omc, derivatives=False)
        fc *= L
        fs *= L
        ex = x - fc * cb
        ey = y - fc * sb
        ez = z - fs
        ex *= ex
        ey *= ey
        ez *= ez
        ex += ey
        ex += ez
        np.sqrt(ex, out=res[c])
    if n > 1:
        res = np.linalg.norm(p - _fk(robot, theta, beta)[:, -1, :3, 3], axis=-1)
    return res


@carries_failed_rows({"p_tip": 1})
def inverse_kinematics(robot: ContinuumRobot, p_tip: object) -> IKResult:
    """Bend parameters ``psi`` that put the tip at ``p_tip (..., 3)`` (m, base frame): :class:`IKResult`.

    The single constant-curvature arc through the tip, refined by Levenberg-Marquardt in the bending
    vectors, with restarts from ``IK_STARTS`` for n >= 2 (``docs/mechanisms/continuum.md``, Models).

    Returns
    -------
    IKResult

    Examples
    --------
    >>> ik = inverse_kinematics(ContinuumRobot.paper(), np.array([0.057296, 0.0, 0.057296]))
    >>> ik.psi.round(4), bool(ik.converged)
    (array([1.5708, 0.    ]), True)
    """
    check_params(robot, ContinuumRobot, "robot")
    p = as_array(p_tip, "p_tip", (3,))
    n = robot.n_segments
    batch = p.shape[:-1]
    pf = p.reshape(-1, 3)
    psi = np.empty((pf.shape[0], n, 2))
    theta, beta = psi[..., 0], psi[..., 1]  # views: the solution is written in place
    res = _single_arc(robot, pf, theta, beta)
    converged = res < IK_TOLERANCE  # the single-arc start is exact for every reachable one-segment tip
    iterations = np.zeros(pf.shape[0], dtype=int)
    idx = np.flatnonzero(~converged)
    if idx.size:
        u, r, c, it = _ik_solve(robot, pf[idx], _psi_to_u(theta[idx], beta[idx]))
        theta[idx], beta[idx] = _u_to_psi(u)
        res[idx], converged[idx], iterations[idx] = r, c, it
        # restart only what the robot can reach: the tip is never farther from the base than n l
        within = np.linalg.norm(pf[idx], axis=-1) <= n * robot.segment_length + IK_TOLERANCE
        idx = idx[(r >= IK_TOLERANCE) & within]
    for shape in IK_STARTS if n > 1 else ():  # a one-segment tip is reached by the single arc or not at all
        if idx.size == 0:
            break
        u, r, c, it = _ik_solve(robot, pf[idx], _ik_start(robot, pf[idx], shape))
        iterations[idx] += it
        better = r < res[idx]
        theta[idx[better]], beta[idx[better]] = _u_to_psi(u[better])
        res[idx[better]], converged[idx[better]] = r[better], c[better]
        idx = idx[r >= IK_TOLERANCE]
    _normalise(theta, beta)
    beta[theta == 0.0] = 0.0  # beta is undefined on a straight segment: 0 by convention
    psi_out: np.ndarray = psi.reshape(*batch, 2 * n)
    res_out: np.ndarray = res.reshape(batch)
    return IKResult(
        psi=psi_out,
        residual=res_out,
        reachable=res_out < IK_TOLERANCE,
        converged=converged.reshape(batch),
        iterations=iterations.reshape(batch),
    )
