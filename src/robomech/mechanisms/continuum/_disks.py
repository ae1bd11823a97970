"""Disk-wise constant curvature: every disk interval its own arc (issue 16).

Paper 3 models each segment as one arc (eqs. (1)-(4)) and multiplies the tensions by one friction
factor per segment (eq. (24)).  With friction at the holes the span tensions fall (pulled cable) or
rise (paid-out cables) from disk to disk, so the bending moment and the curvature do too: measured on
the disk-resolved Cosserat reference, a 45 deg bend at beta = 0 with Table 1 mu bends the five
intervals by 13.4, 10.5, 8.2, 6.4 and 4.9 deg instead of 9 deg each.  The segment-wise model cannot
represent that shape, which puts the tip ~5 mm away from the arc's tip for the same total bend, and the
paper's compensation (adding the stretch delta, eq. (37)) makes it worse (5.3 -> 6.6 mm).

This module relaxes constant curvature to one arc per disk interval (the same cable chords, wrap angles,
capstan friction and elastic cables as the segment model, see :mod:`._compensation`); it reduces to the
segment model when all span tensions are equal (no friction).  Equilibrium of interval j by virtual
work with its own span tensions: ``EI theta_j / h = -sum_c T_cj d ell_cj / d theta_j`` (and the beta
component), the chord length ``ell_cj`` of cable c over interval j depending on that interval's
bend only.  Solved by Newton in bending-vector coordinates k_j = theta_j (cos beta_j, sin beta_j).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from ._friction import _factors, _wrap_from_disks
from ._kinematics import _dsinc_over_x, _segment_T, _sinc
from ._params import ContinuumRobot

__all__ = ["DISK_MAX_ITERATIONS", "DISK_TOLERANCE", "DiskEquilibrium"]

Array = NDArray[np.float64]

DISK_TOLERANCE = 1e-10
"""Converged when the generalized-force residual of every interval is below 1e-10 N m (1e-8 of the
~0.01 N m interval moments), like ``SIM_TOLERANCE`` of the segment model."""
DISK_MAX_ITERATIONS = 40
"""Newton iterations (from the segment arc guess ~4-8 are needed; margin for the slack clip)."""
DISK_BACKTRACKS = 12
"""Step halvings of the line search."""
COLUMN_SERIES_BELOW = 0.1
"""Below u = 0.1 the column correction uses its series (-u^4/45 - 2u^6/945; the closed form cancels to
~1e-12 relative there, the first omitted term is ~u^8/4725 ~ 2e-12)."""
COLUMN_PASSES = 8
"""Fixed-point passes of the column shortening in drive mode (see _state)."""
DISK_FD_STEP = 6e-6
"""Central-difference step (rad) of the Newton matrix: eps^(1/3) for O(0.1) interval bends."""


@dataclass(frozen=True)
class DiskEquilibrium:
    """Equilibrium of the disk-wise constant-curvature robot (batch shape ``...``), SI units.

    Attributes
    ----------
    bend : ndarray, shape (..., n N, 2)
        ``[theta_j, beta_j]`` (rad) of every disk interval, base first.
    disk_T : ndarray, shape (..., 1 + n N, 4, 4)
        Poses of the base plate and of every disk in the base frame (m).
    tip : ndarray, shape (..., 3)
        Tip position (m, base frame).
    tension : ndarray, shape (..., 3 n)
        Cable tensions on the actuator side, at the base plate (N).
    span_tension : ndarray, shape (..., 3 n, n N)
        Tension of every span (N); 0 beyond a cable's termination disk.
    elongation : ndarray, shape (..., 3 n)
        Cable stretch from the straight pose at the pretension (m).
    drive : ndarray, shape (..., 3 n)
        Cable length pulled in by each actuator that holds this equilibrium (m; the given drive in
        drive mode).
    taut : ndarray of bool, shape (...)
        No cable slack.
    converged : ndarray of bool, shape (...)
        ``residual`` below ``DISK_TOLERANCE``.
    residual : ndarray, shape (...)
        Generalized-force residual of the equilibrium (N m).
    """

    bend: Array
    disk_T: Array
    tip: Array
    tension: Array
    span_tension: Array
    elongation: Array
    drive: Array
    taut: NDArray[np.bool_]
    converged: NDArray[np.bool_]
    residual: Array


def _interval_spans(robot: ContinuumRobot, th: Array, be: Array) -> tuple[Array, Array, Array]:
    """Chord length of every cable over every interval and its derivatives d/dtheta_j, (d/dbeta_j)/theta_j,
    ``(..., 3 n, n N)`` each: the chord formula of ``_segment_spans`` for one interval of length h."""
    h = robot.segment_length / robot.disks_per_segment
    r, sig = robot.hole_radius, robot.hole_angles
    t = th[..., None, :]
    b = be[..., None, :] - sig[:, None]
    d, d_db = r * np.cos(b), -r * np.sin(b)
    a = h - d * t
    x = t / 2.0
    s = _sinc(x)
    ds = _dsinc_over_x(x) * x
    return a * s, -d * s + a * ds / 2.0, -d_db * s


def _column_correction(u: Array) -> Array:
    """u / tan(u) - (1 - u^2 / 3): exact beam-column end stiffness minus the arc's, series below 0.1."""
    small = u < COLUMN_SERIES_BELOW
    us = np.where(small, 1.0, u)
    with np.errstate(divide="ignore", invalid="ignore"):
        closed = us / np.tan(us) - 1.0 + us * us / 3.0
    series = -(u**4) / 45.0 - 2.0 * u**6 / 945.0
    return np.where(small, series, closed)


def _column_shortening(th: Array, u: Array, h: float) -> Array:
    """Extra chord shortening of a column-shaped interval over its arc at the same end rotation theta:
    theta² h [(u - sin u cos u) / (16 u sin² u) - 1/24] (the deflection of a column under end moments,
    w ∝ cos(k(s - h/2)) / cos u - 1), series u²/180 + u⁴/1260 + u⁶/9450 below COLUMN_SERIES_BELOW."""
    small = u < COLUMN_SERIES_BELOW
    us = np.where(small, 1.0, u)
    with np.errstate(divide="ignore", invalid="ignore"):
        closed = (us - np.sin(us) * np.cos(us)) / (16.0 * us * np.sin(us) ** 2) - 1.0 / 24.0
    series = u**2 / 180.0 + u**4 / 1260.0 + u**6 / 9450.0
    return th * th * h * np.where(small, series, closed)


def _tension_estimate(robot: ContinuumRobot, ell: Array, P: Array, q: Array) -> Array:
    """Base tension from each cable's compatibility (path = L0 - q + stretch), linear in it."""
    act = _active(robot)
    L0 = act.sum(axis=-1) * (robot.segment_length / robot.disks_per_segment)
    ea, T0, Lf = robot.cable_axial_stiffness, robot.pretension, robot.free_length
    return (ea * (ell.sum(axis=-1) - L0 + q) + T0 * (Lf + L0)) / (Lf + np.sum(P * ell, axis=-1))


def _active(robot: ContinuumRobot) -> NDArray[np.bool_]:
    """(3 n, n N): cable c runs over interval j."""
    N = robot.disks_per_segment
    return np.arange(robot.n_segments * N)[None, :] < (N * (robot.cable_segment + 1))[:, None]


def _chain(robot: ContinuumRobot, th: Array, be: Array) -> Array:
    """Base plate and disk poses (..., 1 + n N, 4, 4) of the chained interval arcs."""
    h = robot.segment_length / robot.disks_per_segment
    T_loc = _segment_T(th, be, h)  # (..., J, 4, 4)
    J = th.shape[-1]
    out = np.empty((*th.shape[:-1], J + 1, 4, 4))
    out[..., 0, :, :] = np.eye(4)
    for j in range(J):
        out[..., j + 1, :, :] = out[..., j, :, :] @ T_loc[..., j, :, :]
    return out


def _k_split(k: Array) -> tuple[Array, Array]:
    kx, ky = k[..., 0::2], k[..., 1::2]
    return np.sqrt(kx * kx + ky * ky), np.arctan2(ky, kx)


Mode = Literal["tension", "drive"]


def _state(
    robot: ContinuumRobot, k: Array, load: Array, d: Array, mode: Mode
) -> tuple[Array, Array, Array, Array, Array, Array]:
    """Generalized force (..., 2 J) and (t_raw, P, ell, disk poses) at bending vectors ``k``."""
    th, be = _k_split(k)
    ell, dth, dbe = _interval_spans(robot, th, be)
    act = _active(robot)
    ell = np.where(act, ell, 0.0)
    T = _chain(robot, th, be)
    P = np.where(act, _factors(robot, _wrap_from_disks(robot, T), d), 0.0)
    h = robot.segment_length / robot.disks_per_segment
    ei = robot.bending_stiffness
    # The column shape shortens the interval more than its arc (see _column_shortening): in the cable
    # paths only (the virtual work has it through the stiffness correction below).  In drive mode the
    # compression depends on the tensions that depend on the paths: a fixed point (the shortening is
    # ~1e-5 m, and 1e-5 m of path is ~0.1 N of tension); measured: after 5 passes the drive-mode round
    # trip is off by 2e-5 N at 80 deg, after COLUMN_PASSES = 8 by 6e-8 N.
    ell_path, t_raw = ell, load
    for _ in range(1 if mode == "tension" else COLUMN_PASSES):
        t_u = load if mode == "tension" else _tension_estimate(robot, ell_path, P, load)
        u_path = 0.5 * h * np.sqrt(np.sum(np.maximum(t_u, 0.0)[..., :, None] * P, axis=-2) / ei)
        ell_path = ell - np.where(act, _column_shortening(th, u_path, h)[..., None, :], 0.0)
        t_raw = load if mode == "tension" else _tension_estimate(robot, ell_path, P, load)
    w = np.maximum(t_raw, 0.0)[..., :, None] * P  # span tensions (a cable cannot push)
    # Beam-column correction: the cables compress the core between two disks by ~sum of the span
    # tensions; the arc's chord shortening in ell already softens the interval to EI (1 - u^2/3),
    # u = (h/2) sqrt(P/EI); the exact column under end moments has EI u / tan(u).  The difference is
    # added (measured on the disk reference: without it the intervals bend ~3-4 % less than the rod).
    u = 0.5 * h * np.sqrt(np.sum(w, axis=-2) / ei)
    stiff = ei * (1.0 + _column_correction(u))
    f_th = -np.sum(w * dth, axis=-2) - stiff / h * th
    f_bt = -np.sum(w * dbe, axis=-2)
    cb, sb = np.cos(be), np.sin(be)
    F = np.empty_like(k)
    F[..., 0::2] = f_th * cb - f_bt * sb
    F[..., 1::2] = f_th * sb + f_bt * cb
    return F, t_raw, P, ell_path, T, w


def _solve(robot: ContinuumRobot, k0: Array, load: Array, d: Array, mode: Mode) -> DiskEquilibrium:
    """Newton with backtracking from ``k0 (..., 2 J)`` (all arrays already validated/broadcast)."""
    k = k0.copy()
    batch = k.shape[:-1]
    eye = np.eye(k.shape[-1])
    conv = np.zeros(batch, dtype=bool)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        for _ in range(DISK_MAX_ITERATIONS):
            F = _state(robot, k, load, d, mode)[0]
            f0 = np.linalg.norm(F, axis=-1)
            conv = f0 < DISK_TOLERANCE
            if np.all(conv | ~np.isfinite(f0)):
                break
            cols = [
                (
                    _state(robot, k + DISK_FD_STEP * e, load, d, mode)[0]
                    - _state(robot, k - DISK_FD_STEP * e, load, d, mode)[0]
                )
                / (2.0 * DISK_FD_STEP)
                for e in eye
            ]
            Jm = np.nan_to_num(np.stack(cols, -1))
            # pinv: a singular Newton matrix in one sample must not abort the batch
            step = np.einsum("...ij,...j->...i", np.linalg.pinv(Jm), np.nan_to_num(F))
            scale = np.ones(batch)
            for _ in range(DISK_BACKTRACKS):
                trial = np.linalg.norm(_state(robot, k - scale[..., None] * step, load, d, mode)[0], axis=-1)
                worse = ~(trial < f0) & ~conv
                if not np.any(worse):
                    break
                scale = np.where(worse, 0.5 * scale, scale)
            k = np.where(conv[..., None], k, k - scale[..., None] * step)
        F, t_raw, P, ell, T, w = _state(robot, k, load, d, mode)
    res = np.linalg.norm(F, axis=-1)
    th, be = _k_split(k)
    t = np.maximum(t_raw, 0.0)
    act = _active(robot)
    L0 = act.sum(axis=-1) * (robot.segment_length / robot.disks_per_segment)
    ea, T0, Lf = robot.cable_axial_stiffness, robot.pretension, robot.free_length
    elong = (t * (Lf + np.sum(P * ell, axis=-1)) - T0 * (Lf + L0)) / ea
    drive = L0 - ell.sum(axis=-1) + elong  # compatibility: path = L0 - q + stretch
    if mode == "drive":
        drive = np.broadcast_to(load, drive.shape).copy()
    finite = np.isfinite(res) & np.all(np.isfinite(k), axis=-1)
    return DiskEquilibrium(
        bend=np.stack([th, be], -1),
        disk_T=T,
        tip=T[..., -1, :3, 3],
        tension=t,
        span_tension=w,
        elongation=elong,
        drive=drive,
        taut=np.all(t_raw >= 0.0, axis=-1),
        converged=finite & (res < DISK_TOLERANCE),
        residual=res,
    )


def _uniform_k(robot: ContinuumRobot, theta: Array, beta: Array) -> Array:
    """Bending vectors of the segment arcs spread evenly over their disks, (..., 2 n N)."""
    N = robot.disks_per_segment
    th = np.repeat(theta / N, N, axis=-1)
    be = np.repeat(beta, N, axis=-1)
    return np.stack([th * np.cos(be), th * np.sin(be)], -1).reshape(*th.shape[:-1], 2 * th.shape[-1])
