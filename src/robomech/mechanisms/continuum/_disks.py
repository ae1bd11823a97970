"""Disk-wise constant curvature (not in paper 3): every disk interval its own arc, so that the curvature
can fall from disk to disk under friction; equilibrium by virtual work per interval, Newton in the
bending vectors.  Model and measurements: ``docs/mechanisms/continuum.md``, "Disk-wise constant curvature".
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from ._friction import _factors, _hole_residual, _wrap_from_disks
from ._kinematics import _dsinc_over_x, _segment_T, _sinc, _span_active
from ._params import ContinuumRobot

__all__ = ["DISK_MAX_ITERATIONS", "DISK_TOLERANCE", "MEMORY_MAX_ITERATIONS", "DiskEquilibrium"]

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
MEMORY_MAX_ITERATIONS = 40
"""Semi-smooth Newton iterations of one stick-slip history step (measured 5-8 per step on the study's
load-unload cycle, 13 at most)."""
MEMORY_FD_FLUX = 1e-8
"""Central-difference step (m) of the hole fluxes in the Newton matrix (tensions are linear in the
flux up to the column shortening, so any small step works; 1e-8 m is ~1e-3 N of tension)."""


@dataclass(frozen=True)
class DiskEquilibrium:
    """Equilibrium of the disk-wise constant-curvature robot (from :func:`disk_equilibrium`).

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
    taut, converged : ndarray of bool, shape (...)
        No cable slack; ``residual`` below ``DISK_TOLERANCE``.
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
    act = _span_active(robot)
    L0 = act.sum(axis=-1) * (robot.segment_length / robot.disks_per_segment)
    ea, T0, Lf = robot.cable_axial_stiffness, robot.pretension, robot.free_length
    return (ea * (ell.sum(axis=-1) - L0 + q) + T0 * (Lf + L0)) / (Lf + np.sum(P * ell, axis=-1))


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


def _geometry(robot: ContinuumRobot, k: Array) -> tuple[Array, Array, Array, Array, Array, Array]:
    """Interval bends, chord lengths (0 beyond a cable's termination) and their derivatives, disk poses."""
    th, be = _k_split(k)
    ell, dth, dbe = _interval_spans(robot, th, be)
    ell = np.where(_span_active(robot), ell, 0.0)
    return th, be, ell, dth, dbe, _chain(robot, th, be)


def _path(robot: ContinuumRobot, th: Array, ell: Array, w: Array) -> Array:
    """Cable paths: chords minus the column shape's extra shortening under span tensions ``w``."""
    h = robot.segment_length / robot.disks_per_segment
    u_path = 0.5 * h * np.sqrt(np.sum(np.maximum(w, 0.0), axis=-2) / robot.bending_stiffness)
    return ell - np.where(_span_active(robot), _column_shortening(th, u_path, h)[..., None, :], 0.0)


def _forces(robot: ContinuumRobot, k: Array, th: Array, be: Array, w: Array, dth: Array, dbe: Array) -> Array:
    """Generalized force (..., 2 J) of the intervals under the span tensions ``w (..., 3 n, n N)``."""
    h = robot.segment_length / robot.disks_per_segment
    ei = robot.bending_stiffness
    # Beam-column correction: the cables compress the core between two disks by ~sum of the span
    # tensions; the arc's chord shortening in ell already softens the interval to EI (1 - u^2/3),
    # u = (h/2) sqrt(P/EI); the exact column under end moments has EI u / tan(u).  The difference is
    # added (measured on the disk reference: without it the intervals bend ~3-4 % less than the rod).
    u = 0.5 * h * np.sqrt(np.sum(w, axis=-2) / ei)
    stiff = ei * (1.0 + _column_correction(u))
    f_th = -np.sum(w * dth, axis=-2) - stiff / h * th
    return _to_bending_vector(k, f_th, -np.sum(w * dbe, axis=-2), be)


def _to_bending_vector(k: Array, f_th: Array, f_bt: Array, be: Array) -> Array:
    """Generalized forces in ``(theta, beta / theta)`` rotated to the bending vectors ``k (..., 2 J)``:
    d/dk = d/dtheta (cos b, sin b) + (d/dbeta)/theta (-sin b, cos b)."""
    cb, sb = np.cos(be), np.sin(be)
    F = np.empty_like(k)
    F[..., 0::2] = f_th * cb - f_bt * sb
    F[..., 1::2] = f_th * sb + f_bt * cb
    return F


def _state(
    robot: ContinuumRobot, k: Array, load: Array, d: Array, mode: Mode
) -> tuple[Array, Array, Array, Array, Array, Array]:
    """Generalized force (..., 2 J) and (t_raw, P, ell, disk poses) at bending vectors ``k``."""
    th, be, ell, dth, dbe, T = _geometry(robot, k)
    act = _span_active(robot)
    P = np.where(act, _factors(robot, _wrap_from_disks(robot, T), d), 0.0)
    # The column shape's extra shortening, in the cable paths only; in drive mode a fixed point (the
    # compression depends on the tensions): the drive-mode round trip is off by 2e-7 N at 80 deg after 5
    # passes, by 1e-9 N after COLUMN_PASSES = 8 (paper robot).
    ell_path, t_raw = ell, load
    for _ in range(1 if mode == "tension" else COLUMN_PASSES):
        t_u = load if mode == "tension" else _tension_estimate(robot, ell_path, P, load)
        ell_path = _path(robot, th, ell, np.maximum(t_u, 0.0)[..., :, None] * P)
        t_raw = load if mode == "tension" else _tension_estimate(robot, ell_path, P, load)
    w = np.maximum(t_raw, 0.0)[..., :, None] * P  # span tensions (a cable cannot push)
    return _forces(robot, k, th, be, w, dth, dbe), t_raw, P, ell_path, T, w


def _backtrack(
    norm: Callable[[Array], Array],
    x: Array,
    step: Array,
    f0: Array,
    conv: NDArray[np.bool_],
    backtracks: int = DISK_BACKTRACKS,
) -> Array:
    """``x - t step`` per sample, ``t`` halved (at most ``backtracks`` times) until the residual norm
    ``norm`` falls below ``f0``; converged samples stay at ``x``."""
    scale = np.ones(conv.shape)
    for _ in range(backtracks):
        worse = ~(norm(x - scale[..., None] * step) < f0) & ~conv
        if not np.any(worse):
            break
        scale = np.where(worse, 0.5 * scale, scale)
    return np.where(conv[..., None], x, x - scale[..., None] * step)


def _fd_jacobian(fun: Callable[[Array], Array], x: Array, step: float) -> Array:
    """Central-difference Jacobian ``(..., m, k)`` of ``fun`` at ``x (..., k)``, non-finite entries 0."""
    cols = [(fun(x + step * e) - fun(x - step * e)) / (2.0 * step) for e in np.eye(x.shape[-1])]
    return np.nan_to_num(np.stack(cols, -1))


def _gauss_newton_step(J: Array, F: Array) -> Array:
    """``J^+ F`` per sample; pinv: a singular Newton matrix in one sample must not abort the batch."""
    return np.einsum("...ij,...j->...i", np.linalg.pinv(J), np.nan_to_num(F))


def _newton(
    fun: Callable[[Array], Array],
    k0: Array,
    tol: float = DISK_TOLERANCE,
    max_iterations: int = DISK_MAX_ITERATIONS,
    fd_step: float = DISK_FD_STEP,
    backtracks: int = DISK_BACKTRACKS,
) -> tuple[Array, NDArray[np.bool_], NDArray[np.int_]]:
    """Newton with backtracking on ``fun(k) = 0`` from ``k0 (..., 2 J)``, central-difference Jacobian,
    batched; returns (k, converged, iterations).  A singular or non-finite sample does not stop the
    others."""
    k = k0.copy()
    conv = np.zeros(k.shape[:-1], dtype=bool)
    iterations = np.zeros(k.shape[:-1], dtype=int)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        for _ in range(max_iterations):
            F = fun(k)
            f0 = np.linalg.norm(F, axis=-1)
            conv = f0 < tol
            if np.all(conv | ~np.isfinite(f0)):
                break
            step = _gauss_newton_step(_fd_jacobian(fun, k, fd_step), F)
            k = _backtrack(lambda kk: np.linalg.norm(fun(kk), axis=-1), k, step, f0, conv, backtracks)
            iterations += ~conv
    return k, conv, iterations


def _solve(robot: ContinuumRobot, k0: Array, load: Array, d: Array, mode: Mode) -> DiskEquilibrium:
    """Newton with backtracking from ``k0 (..., 2 J)`` (all arrays already validated/broadcast)."""
    k = _newton(lambda kk: _state(robot, kk, load, d, mode)[0], k0)[0]
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        F, t_raw, P, ell, T, w = _state(robot, k, load, d, mode)
    res = np.linalg.norm(F, axis=-1)
    th, be = _k_split(k)
    t = np.maximum(t_raw, 0.0)
    act = _span_active(robot)
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


# ---- stick-slip with memory fed back into the pose -------------------------------------------------
@dataclass(frozen=True)
class MemoryStep:
    """One step of the stick-slip history of the disk-wise robot (internal; see simulate_history):
    bending vectors, unstretched ``material (..., 3 n, 1 + n N)`` of every piece (free length first), the
    branch of every hole, piece tensions (N, < 0 where slack), ``flux`` (m) and mu eta of every hole."""

    k: Array
    material: Array
    slide: Array
    piece_tension: Array
    flux: Array
    wrap_mu: Array
    disk_T: Array
    converged: NDArray[np.bool_]
    residual: Array


def _pieces(robot: ContinuumRobot, ell_path: Array) -> Array:
    """Piece lengths (..., 3 n, 1 + n N): the free length, then the spans (1 beyond the termination: a
    dummy piece of material 1 and tension 0, cut off by a stuck hole)."""
    free = np.full((*ell_path.shape[:-1], 1), robot.free_length)
    return np.concatenate([free, np.where(_span_active(robot), ell_path, 1.0)], -1)


def _memory_initial(robot: ContinuumRobot, batch: tuple[int, ...]) -> tuple[Array, Array, Array]:
    """Straight, pretensioned rest state: (k, material, slide) with every hole stuck."""
    J = robot.n_segments * robot.disks_per_segment
    h = robot.segment_length / robot.disks_per_segment
    g = _pieces(robot, np.full((robot.n_cables, J), h))
    live = np.concatenate([np.ones((robot.n_cables, 1), dtype=bool), _span_active(robot)], -1)
    m = np.where(live, g * (1.0 - robot.pretension / robot.cable_axial_stiffness), 1.0)
    k = np.zeros((*batch, 2 * J))
    return k, np.broadcast_to(m, (*batch, *m.shape)).copy(), np.zeros((*batch, robot.n_cables, J))


def _memory_eval(
    robot: ContinuumRobot,
    k: Array,
    s: Array,
    m_prev: Array,
    dq: Array,
    branch: Array | None = None,
) -> tuple[Array, Array, Array, Array, Array, Array, Array]:
    """Residual ``(..., 2 J + 3 n n N)`` of one history step at bending vectors ``k (..., 2 J)`` and hole
    fluxes ``s (..., 3 n, n N)``: the interval equilibrium (N m) and the hole complementarity (times h),
    with own branch, piece tensions, material, mu eta, disk poses and generalized force."""
    th, be, ell, dth, dbe, T = _geometry(robot, k)
    act = _span_active(robot)
    a = robot.friction_array[:, None] * np.where(act, _wrap_from_disks(robot, T), 0.0)
    ea = robot.cable_axial_stiffness
    h = robot.segment_length / robot.disks_per_segment
    s = np.where(act, s, 0.0)
    # piece p gains the flux of the hole at its distal end (s_p) and loses that at its proximal end
    # (s_{p-1}; the actuator reels in dq); the last active span ends at the anchor (s = 0 beyond it)
    inflow = np.concatenate([s, np.zeros((*s.shape[:-1], 1))], -1)
    outflow = np.concatenate([np.broadcast_to(dq[..., None], (*s.shape[:-1], 1)), s], -1)
    m = m_prev + inflow - outflow
    ell_path = ell
    for _ in range(COLUMN_PASSES):
        tp = ea * (1.0 - m / _pieces(robot, ell_path))
        ell_path = _path(robot, th, ell, np.where(act, tp[..., 1:], 0.0))
    tp = ea * (1.0 - m / _pieces(robot, ell_path))
    tp = np.concatenate([tp[..., :1], np.where(act, tp[..., 1:], 0.0)], -1)
    w = np.where(act, np.maximum(tp[..., 1:], 0.0), 0.0)  # a cable cannot push
    F = _forces(robot, k, th, be, w, dth, dbe)
    R, own = _hole_residual(tp, s, a, ea / h, None if branch is None else branch)
    R = np.where(act, R, ea / h * s)  # holes beyond the termination: no flux
    own = np.where(act, own, 0.0)
    res = np.concatenate([F, (h * R).reshape(*R.shape[:-2], -1)], -1)
    return res, own, tp, m, a, T, F


def _memory_step(
    robot: ContinuumRobot, k0: Array, m_prev: Array, dq: Array, *, fixed_pose: bool = False
) -> MemoryStep:
    """One quasi-static step of the history, the drive moved by ``dq (..., 3 n)`` from (k0, m_prev): pose
    and hole fluxes by semi-smooth Newton from the elastic predictor (docs/mechanisms/continuum.md).
    ``fixed_pose``: the pose is held (the rigid-geometry case of :func:`stick_slip_tensions`)."""
    C, K = robot.n_cables, robot.n_segments * robot.disks_per_segment
    J2 = k0.shape[-1]
    batch = k0.shape[:-1]
    n_s = C * K
    x = np.concatenate([k0, np.zeros((*batch, n_s))], -1)
    lo_idx = J2 if fixed_pose else 0
    steps = np.concatenate([np.full(J2, DISK_FD_STEP), np.full(n_s, MEMORY_FD_FLUX)])

    def fun(xx: Array, branch: Array | None = None, extra: int = 0) -> tuple[Array, Array]:
        mp = m_prev.reshape(*batch, *(1,) * extra, C, K + 1)
        d = dq.reshape(*batch, *(1,) * extra, C)
        ss = xx[..., J2:].reshape(*xx.shape[:-1], C, K)
        r, own = _memory_eval(robot, xx[..., :J2], ss, mp, d, branch)[:2]
        return r[..., lo_idx:], own

    conv = np.zeros(batch, dtype=bool)
    n_x = J2 + n_s
    E = np.eye(n_x)[lo_idx:] * steps[None, :]  # (n_free, n_x) perturbations
    n_free = E.shape[0]
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        for _ in range(MEMORY_MAX_ITERATIONS):
            r, own = fun(x)
            f0 = np.linalg.norm(r, axis=-1)
            conv = f0 < DISK_TOLERANCE
            if np.all(conv | ~np.isfinite(f0)):
                break
            # all central differences in one batched evaluation (the perturbations as an extra axis)
            X = np.concatenate([x[..., None, :] + E, x[..., None, :] - E], -2)
            RR = fun(X, own[..., None, :, :], extra=1)[0]
            diff = (RR[..., :n_free, :] - RR[..., n_free:, :]) / (2.0 * steps[lo_idx:, None])
            Jm = np.nan_to_num(np.swapaxes(diff, -1, -2))
            step = np.zeros_like(x)
            step[..., lo_idx:] = _gauss_newton_step(Jm, r)
            x = _backtrack(lambda xx: np.linalg.norm(fun(xx)[0], axis=-1), x, step, f0, conv)
        k, s = x[..., :J2], x[..., J2:].reshape(*batch, C, K)
        r, own, tp, m, a, T, _ = _memory_eval(robot, k, s, m_prev, dq)
    res = np.linalg.norm(r[..., lo_idx:], axis=-1)
    finite = np.isfinite(res) & np.all(np.isfinite(x), axis=-1)
    act = _span_active(robot)
    return MemoryStep(
        k=k,
        material=m,
        slide=own,
        piece_tension=tp,
        flux=np.where(act, s, 0.0),
        wrap_mu=a,
        disk_T=T,
        converged=finite & (res < DISK_TOLERANCE),
        residual=res,
    )


def _segment_psi(robot: ContinuumRobot, disk_T: Array) -> Array:
    """``[theta_i, beta_i, ...]`` of the constant-curvature arc with each segment's end tangent: theta the
    angle between the segment's base and end disk normals, beta the plane of that rotation."""
    N = robot.disks_per_segment
    R = disk_T[..., :3, :3]
    base, end = R[..., 0:-1:N, :, :], R[..., N::N, :, :]
    z = np.einsum("...ba,...b->...a", base, end[..., :, 2])  # end normal in the segment base frame
    th = np.arctan2(np.sqrt(z[..., 0] ** 2 + z[..., 1] ** 2), z[..., 2])
    be = np.arctan2(z[..., 1], z[..., 0])
    return np.stack([th, be], -1).reshape(*th.shape[:-1], 2 * robot.n_segments)
