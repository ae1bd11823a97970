"""Cable elongation, the compensated drive q~ = q + delta (paper 3, eqs. (33)-(37)) and a quasi-static
simulated robot; the drive convention ``q = -(L(psi) - L(0))``: ``docs/mechanisms/continuum.md``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from robomech._batching import carries_failed_rows
from robomech._validation import as_array, broadcast_batch, check_choice, check_params

from ._disks import (
    DiskEquilibrium,
    _fd_jacobian,
    _gauss_newton_step,
    _memory_initial,
    _memory_step,
    _newton,
    _segment_psi,
    _solve,
    _to_bending_vector,
    _uniform_k,
)
from ._friction import STUCK_FLUX_TOL, _as_direction, _factors, _wrap, stick_slip_tensions
from ._kinematics import CableModel, _active, _disk_T, _fk, _segment_spans, _span_active, _split, span_lengths
from ._params import ContinuumRobot
from ._pulley import PULLEY_FIXED_POINT_ITERATIONS, Pulley, pulley_chain, pulley_stretch
from ._statics import TensionResult, cable_tensions

__all__ = [
    "COMPENSATION_ITERATIONS",
    "COMPENSATION_STEP_TOL",
    "SIM_BACKTRACKS",
    "SIM_FD_STEP",
    "SIM_MAX_ITERATIONS",
    "SIM_TOLERANCE",
    "STICK_SLIP_TENSION_FLOOR",
    "DriveResult",
    "HistoryResult",
    "SimulationResult",
    "cable_elongation",
    "compensated_drive",
    "disk_equilibrium",
    "simulate",
    "simulate_history",
    "theoretical_drive",
]

# Newton on the simulated robot: converged below 1e-10 N m (1e-9 of the ~0.03 N m bending moments) ...
SIM_TOLERANCE = 1e-10
# ... within 40 iterations (~5 from a nearby start; margin for far starts and the kink at theta = 0).
SIM_MAX_ITERATIONS = 40
# Step halvings of the backtracking line search (2^-12 ~ 2e-4 of a Newton step is the smallest tried).
SIM_BACKTRACKS = 12
# Central-difference step (rad) for the 2n x 2n Newton matrix: eps^(1/3) for O(1) curvature.
SIM_FD_STEP = 6e-6
# compensated_drive(method="disk"): Gauss-Newton on psi' stopped at a step below 1e-10 rad (the ends then
# sit at their least-squares point to ~1e-11 m; 2n parameters cannot hit 3n coordinates exactly) ...
COMPENSATION_STEP_TOL = 1e-10
# ... or after 12 iterations (3-5 are needed from psi' = psi; the Jacobian is a central difference).
COMPENSATION_ITERATIONS = 12
COMPENSATION_FD_STEP = 1e-6  # rad, central difference of the segment ends in psi'

# simulate_history: a slack cable (tension 0) has no friction state; stick_slip_tensions is fed this
# floor (N, far below any working tension) and the sample is flagged (taut false).
STICK_SLIP_TENSION_FLOOR = 1e-9

CompensationMethod = Literal["paper", "disk"]
HistoryMemory = Literal["elastic", "slip"]


def _lengths_and_factors(robot, theta, beta, direction, model):
    psi = np.stack([theta, beta], -1).reshape(*theta.shape[:-1], 2 * theta.shape[-1])
    ell = span_lengths(robot, psi, model)  # (..., 3n, nN)
    P = _factors(robot, _wrap(robot, theta, beta), direction)
    return ell, P


def _l0(robot: ContinuumRobot, model: CableModel) -> np.ndarray:
    return span_lengths(robot, np.zeros(2 * robot.n_segments), model).sum(axis=-1)


def _elongation(robot, ell, P, t_base, model):
    ea, T0, Lf = robot.cable_axial_stiffness, robot.pretension, robot.free_length
    integral = t_base * (Lf + np.sum(P * ell, axis=-1))
    return (integral - T0 * (Lf + _l0(robot, model))) / ea


@carries_failed_rows({"psi": 1, "tension": 1}, {"direction": 1})
def cable_elongation(
    robot: ContinuumRobot,
    psi: object,
    tension: object,
    direction: object | None = None,
    model: CableModel = "chord",
) -> np.ndarray:
    """Stretch ``(..., 3 n)`` (m) of every cable beyond its straight, pretensioned length (paper 3, eq. (33)).

    delta = (int T ds - T0 (L_free + L(0))) / (E A), the discrete form of eq. (36): ``tension (..., 3 n)``
    (N) at the base plate, constant over the free length and reduced span by span by the disk friction.

    Parameters
    ----------
    robot : ContinuumRobot
    psi : array_like, shape (..., 2 n)
    tension : array_like, shape (..., 3 n)
        Tension of every cable where it enters the base plate (N), e.g. ``cable_tensions(...).tension``.
    direction : array_like, shape (..., 3 n), optional
        Sliding direction of each cable (+1 pulled in, -1 paid out, see :func:`friction_factors`);
        ``None``: frictionless.  The same argument in every function of the package.
    model : {"chord", "arc"}, optional
        Cable path model of the spans (see :func:`cable_lengths`).
    """
    check_params(robot, ContinuumRobot, "robot")
    theta, beta = _split(robot, psi)
    t = as_array(tension, "tension", (robot.n_cables,))
    d = _as_direction(robot, direction, theta.shape[:-1])
    broadcast_batch((theta, 1, "psi"), (t, 1, "tension"), (d, 1, "direction"))
    ell, P = _lengths_and_factors(robot, theta, beta, d, model)
    return _elongation(robot, ell, P, t, model)


@carries_failed_rows({"psi": 1})
def theoretical_drive(robot: ContinuumRobot, psi: object, model: CableModel = "arc") -> np.ndarray:
    """Cable ``(..., 3 n)`` (m) pulled in by each actuator of a rigid, frictionless robot since the
    straight pose: q = -(L(psi) - L(0)), paper 3, eq. (37) before delta is added.

    Returns
    -------
    ndarray, shape (..., 3 n)
    """
    check_params(robot, ContinuumRobot, "robot")
    return -(span_lengths(robot, psi, model).sum(axis=-1) - _l0(robot, model))


@dataclass(frozen=True)
class DriveResult:
    """Compensated drive ``q_compensated = q + delta`` (paper 3, eq. (37)), from :func:`compensated_drive`.

    Attributes
    ----------
    q : ndarray, shape (..., 3 n)
        Theoretical drive of the rigid, frictionless robot, :func:`theoretical_drive` (m).
    delta : ndarray, shape (..., 3 n)
        Cable elongation to compensate (m), including ``delta_pulley``.
    q_compensated : ndarray, shape (..., 3 n)
        Feed-forward drive q~ = q + delta (m): cable each actuator pulls in since the straight,
        pretensioned pose.
    tension : ndarray, shape (..., 3 n)
        Model tension behind delta, where the cable enters the base plate (N).
    taut : ndarray of bool, shape (...)
        All cables in tension (and, for ``method="disk"`` or with a pulley, the model solved and the
        tensions finite and positive).
    actuator_tension : ndarray, shape (..., 3 n)
        Tension at the actuator, beyond the pulley (N); equal to ``tension`` without a pulley, NaN
        where ``taut`` is false with one.
    delta_pulley : ndarray, shape (..., 3 n)
        Part of ``delta`` stretched over the pulley wrap, eq. (34) (m); 0 without a pulley.
    """

    q: np.ndarray
    delta: np.ndarray
    q_compensated: np.ndarray
    tension: np.ndarray
    taut: np.ndarray
    actuator_tension: np.ndarray
    delta_pulley: np.ndarray


@carries_failed_rows({"psi": 1}, {"direction": 1, "wrench": 1})
def compensated_drive(
    robot: ContinuumRobot,
    psi: object,
    direction: object | None = None,
    *,
    model: CableModel = "chord",
    wrench: object | None = None,
    method: CompensationMethod = "paper",
    pulley: Pulley | None = None,
) -> DriveResult:
    """Feed-forward drive q~ = q + delta at ``psi (..., 2 n)`` (paper 3, eq. (37)): :class:`DriveResult`.

    ``method="paper"``: tensions from :func:`cable_tensions`, delta from :func:`cable_elongation`.
    ``method="disk"`` (not in the paper): the drive whose :func:`disk_equilibrium` puts the segment ends
    on the commanded ones (chord cables, no ``wrench``).  ``pulley``: the guide pulley at every actuator
    (eqs. (29)-(35)), its stretch added to delta.  Both: ``docs/mechanisms/continuum.md``.

    Parameters
    ----------
    robot : ContinuumRobot
    psi : array_like, shape (..., 2 n)
    direction : array_like, shape (..., 3 n), optional
    model : {"chord", "arc"}, optional
    wrench : array_like, shape (..., 6), optional
        External wrench ``[m; f]`` (N m, N) at the tip, base frame; ``None``: unloaded.
    method : {"paper", "disk"}, optional
    pulley : Pulley, optional
        ``None``: no pulley.

    Raises
    ------
    ValueError
        ``method="disk"`` combined with ``model="arc"`` or a ``wrench``.
    """
    check_params(robot, ContinuumRobot, "robot")
    check_choice(method, "method", ("paper", "disk"))
    if pulley is not None:
        check_params(pulley, Pulley, "pulley")
    theta, beta = _split(robot, psi)
    psi_a = np.stack([theta, beta], -1).reshape(*theta.shape[:-1], 2 * theta.shape[-1])
    broadcast_batch(
        (theta, 1, "psi"),
        *([] if direction is None else [(_as_direction(robot, direction, ()), 1, "direction")]),
        *([] if wrench is None else [(as_array(wrench, "wrench", (6,)), 1, "wrench")]),
    )
    if method == "disk":
        if model != "chord":
            raise ValueError(f"Expected model='chord' with method='disk' (chord spans), got {model!r}.")
        if wrench is not None:
            raise ValueError("Expected wrench=None with method='disk' (no tip load in the disk-wise model).")
        d = _as_direction(robot, direction, theta.shape[:-1])
        q = theoretical_drive(robot, psi_a, "chord")
        eq = _disk_compensation(robot, theta, beta, d)
        delta, tension, taut = eq.drive - q, eq.tension, eq.taut & eq.converged
    else:
        tr: TensionResult = cable_tensions(robot, psi_a, wrench=wrench, direction=direction, model=model)
        q = theoretical_drive(robot, psi_a, model)
        delta = cable_elongation(robot, psi_a, tr.tension, direction, model)
        tension, taut = tr.tension, tr.taut
    if pulley is None:
        t_act, d_c, ok = tension, np.zeros_like(delta), taut
    else:
        d = np.broadcast_to(_as_direction(robot, direction, theta.shape[:-1]), tension.shape)
        with np.errstate(invalid="ignore", over="ignore"):
            t_act, d_c = pulley_stretch(robot, pulley, np.nan_to_num(tension), d)
        ok = taut & np.all(np.isfinite(tension) & (tension > 0.0), axis=-1)
        t_act = np.where(ok[..., None], t_act, np.nan)
        d_c = np.where(ok[..., None], d_c, np.nan)
    return DriveResult(
        q=q,
        delta=delta + d_c,
        q_compensated=q + delta + d_c,
        tension=tension,
        taut=ok,
        actuator_tension=t_act,
        delta_pulley=d_c,
    )


# ---- the simulated robot --------------------------------------------------------------------------
@dataclass(frozen=True)
class SimulationResult:
    """Quasi-static equilibrium of the simulated robot under a drive (from :func:`simulate`).

    Attributes
    ----------
    psi : ndarray, shape (..., 2 n)
        Equilibrium pose ``[theta_1, beta_1, ...]`` (rad).
    tension : ndarray, shape (..., 3 n)
        Cable tension where it enters the base plate (N, >= 0; 0 for a slack cable).
    taut, converged : ndarray of bool, shape (...)
        No cable went slack; Newton met ``SIM_TOLERANCE``.
    residual : ndarray, shape (...)
        Norm of the generalized-force residual (N m).
    iterations : ndarray of int, shape (...)
        Newton iterations used.
    actuator_tension : ndarray, shape (..., 3 n)
        Tension at the actuator, beyond the pulley (N); equal to ``tension`` without a pulley.
    """

    psi: np.ndarray
    tension: np.ndarray
    taut: np.ndarray
    converged: np.ndarray
    residual: np.ndarray
    iterations: np.ndarray
    actuator_tension: np.ndarray


def _k_to_psi(k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    kx, ky = k[..., 0::2], k[..., 1::2]
    return np.hypot(kx, ky), np.arctan2(ky, kx)


def _sim_residual(robot, k, q, d, model, pulley=None):
    """Generalized force in bending-vector coordinates k_i = theta_i (cos beta_i, sin beta_i)."""
    theta, beta = _k_to_psi(k)
    ell, P = _lengths_and_factors(robot, theta, beta, d, model)
    L, L0 = ell.sum(axis=-1), _l0(robot, model)
    ea, T0, Lf = robot.cable_axial_stiffness, robot.pretension, robot.free_length
    # Compatibility: the cable's geometric path equals its unstretched length (pulled in by q) plus its
    # stretch; solved for the base tension, linear in it.  A cable cannot push: tension clipped at 0.
    t_raw = (ea * (L - L0 + q) + T0 * (Lf + L0)) / (Lf + np.sum(P * ell, axis=-1))
    if pulley is not None and pulley.wrap > 0.0:
        # The wrap adds R (int T dphi' - T0 phi) / (E A) (eq. (34)); int T dphi' = t g(t), g constant for
        # n = 1 (one pass exact), slowly varying for n < 1 (fixed point from the pulley-free tension).
        R = pulley.radius + 0.5 * robot.cable_diameter
        num = ea * (L - L0 + q) + T0 * (Lf + L0 + R * pulley.wrap)
        den = Lf + np.sum(P * ell, axis=-1)
        iters = 1 if pulley.n == 1.0 else PULLEY_FIXED_POINT_ITERATIONS
        t_lvl = np.maximum(t_raw, T0 if T0 > 0.0 else 1.0)
        for _ in range(iters):
            _, integral = pulley_chain(robot, pulley, t_lvl, d)
            t_raw = num / (den + R * integral / t_lvl)
            t_lvl = np.maximum(t_raw, np.finfo(float).tiny)
    t = np.maximum(t_raw, 0.0)
    # Virtual work of the span tensions, with d/dbeta divided by theta (finite at the straight pose).
    _, dth, dbe_t = _segment_spans(robot, theta, beta, model)
    Pseg = P.reshape(*P.shape[:-1], robot.n_segments, robot.disks_per_segment).sum(axis=-1)  # (..., 3n, n)
    w = np.where(_active(robot), Pseg, 0.0) * t[..., :, None]
    f_th = -np.sum(w * dth, axis=-2) - robot.bending_stiffness / robot.segment_length * theta
    return _to_bending_vector(k, f_th, -np.sum(w * dbe_t, axis=-2), beta), t_raw


@carries_failed_rows({"q": 1}, {"direction": 1, "initial": 1})
def simulate(
    robot: ContinuumRobot,
    q: object,
    direction: object | None = None,
    *,
    model: CableModel = "chord",
    initial: object | None = None,
    pulley: Pulley | None = None,
) -> SimulationResult:
    """Equilibrium pose of a simulated robot whose actuators have pulled in ``q (..., 3 n)`` (m):
    :class:`SimulationResult`.

    Constant-curvature segments, elastic cables, Coulomb friction at every hole in ``direction``, slack
    cables flagged; Newton in the bending vectors from ``initial`` (``None``: the rigid-arc-cable pose
    for ``q``); ``pulley`` as in :func:`compensated_drive` (``docs/mechanisms/continuum.md``).

    Returns
    -------
    SimulationResult

    Examples
    --------
    >>> robot = ContinuumRobot.paper()
    >>> q = compensated_drive(robot, np.array([0.5, 0.0])).q_compensated
    >>> res = simulate(robot, q)
    >>> bool(res.converged), bool(res.taut), round(float(res.psi[0]), 4)
    (True, True, 0.5)
    """
    check_params(robot, ContinuumRobot, "robot")
    if pulley is not None:
        check_params(pulley, Pulley, "pulley")
    qa = as_array(q, "q", (robot.n_cables,))
    batch = qa.shape[:-1]
    d = _as_direction(robot, direction, batch)
    n_init = (2 * robot.n_segments,)
    th_init = [] if initial is None else [(as_array(initial, "initial", n_init), 1, "initial")]
    if broadcast_batch((qa, 1, "q"), (d, 1, "direction"), *th_init) != batch:
        got = ", ".join(f"{nm} {a.shape[:-1]}" for a, _, nm in [(d, 1, "direction"), *th_init])
        raise ValueError(
            f"Expected direction and initial with batch shapes that broadcast to q's {batch}, got {got}."
        )
    n = robot.n_segments
    if initial is None:
        # Rigid arc cables: q_c = r sum_{m <= seg(c)} k_m . (cos s_c, sin s_c); least squares for k.
        sig, act = robot.hole_angles, _active(robot)
        A = np.zeros((robot.n_cables, 2 * n))
        A[:, 0::2] = robot.hole_radius * np.cos(sig)[:, None] * act
        A[:, 1::2] = robot.hole_radius * np.sin(sig)[:, None] * act
        k = np.einsum("ij,...j->...i", np.linalg.pinv(A), qa)
    else:
        th0, be0 = _split(robot, initial, "initial")
        k = np.stack([th0 * np.cos(be0), th0 * np.sin(be0)], -1).reshape(*th0.shape[:-1], 2 * n)
    k = np.broadcast_to(k, (*batch, 2 * n)).copy()
    # Newton with backtracking: the slack clip and the Coulomb kink at theta = 0 make F piecewise smooth
    fun = lambda kk: _sim_residual(robot, kk, qa, d, model, pulley)[0]  # noqa: E731
    k, _, iterations = _newton(fun, k, SIM_TOLERANCE, SIM_MAX_ITERATIONS, SIM_FD_STEP, SIM_BACKTRACKS)
    F, t_raw = _sim_residual(robot, k, qa, d, model, pulley)
    res = np.linalg.norm(F, axis=-1)
    psi = _psi_from_u(k)
    tension = np.maximum(t_raw, 0.0)
    if pulley is None:
        t_act = tension
    else:
        t_act = np.where(
            t_raw > 0.0, pulley_chain(robot, pulley, tension, np.broadcast_to(d, tension.shape))[0], 0.0
        )
    return SimulationResult(
        psi=psi,
        tension=tension,
        taut=np.all(t_raw >= 0.0, axis=-1),
        converged=res < SIM_TOLERANCE,
        residual=res,
        iterations=iterations,
        actuator_tension=t_act,
    )


@dataclass(frozen=True)
class HistoryResult:
    """Quasi-static response to a history of drives (from :func:`simulate_history`), time axis first.

    Attributes
    ----------
    psi : ndarray, shape (n_t, ..., 2 n)
        Pose at every step (rad); ``memory="elastic"``: the arcs with each segment's end-disk orientation.
    tension, actuator_tension : ndarray, shape (n_t, ..., 3 n)
        Cable tension between the actuator and the base plate, and at the actuator beyond the pulley (N;
        the same without a pulley).
    direction : ndarray, shape (n_t, ..., 3 n)
        Sign of every cable's last nonzero drive increment (+1 before it moved): ``memory="slip"``'s
        sliding direction; for information only with ``"elastic"`` (each hole's own is ``state``).
    span_tension : ndarray, shape (n_t, ..., 3 n, n N)
        Tension of every span (N, 0 beyond a cable's termination); ``"slip"``: from
        :func:`stick_slip_tensions`, not acting on the pose.
    state : ndarray of int, shape (n_t, ..., 3 n, n N)
        Every hole in that step (the hole where each span starts): +1 cable sliding toward the actuator,
        -1 away from it, 0 stuck.
    taut, converged : ndarray of bool, shape (n_t, ...)
        No cable (piece) went slack; the step met its tolerance (``SIM_TOLERANCE`` / ``DISK_TOLERANCE``).
    residual : ndarray, shape (n_t, ...)
        Norm of the equilibrium residual (N m; with ``"elastic"`` including the hole conditions, N
        times the disk spacing).
    valid : ndarray of bool, shape (n_t, ...)
        ``taut & converged``.
    tip : ndarray, shape (n_t, ..., 3)
        Tip position (m, base frame).
    bend : ndarray, shape (n_t, ..., n N, 2)
        ``[theta_j, beta_j]`` (rad) of every disk interval (``"slip"``: the segment arcs spread evenly).
    slip : ndarray, shape (n_t, ..., 3 n, n N)
        Cable length that crossed every hole toward the actuator during the step (m; 0 where stuck;
        ``"slip"``: implied by the sliding model, whose sign it does not enforce).
    """

    psi: np.ndarray
    tension: np.ndarray
    actuator_tension: np.ndarray
    direction: np.ndarray
    span_tension: np.ndarray
    state: np.ndarray
    taut: np.ndarray
    converged: np.ndarray
    residual: np.ndarray
    valid: np.ndarray
    tip: np.ndarray
    bend: np.ndarray
    slip: np.ndarray


def simulate_history(
    robot: ContinuumRobot,
    q: object,
    *,
    times: object | None = None,
    model: CableModel = "chord",
    pulley: Pulley | None = None,
    memory: HistoryMemory = "elastic",
) -> HistoryResult:
    """The simulated robot driven through a history ``q (n_t, ..., 3 n)`` (m, time axis first) from the
    straight pretensioned pose: :class:`HistoryResult`, path-dependent (paper 3, eq. (19) with memory).

    ``memory="elastic"`` (default; chord cables, no pulley): stick-slip of elastic cables through the
    holes, fed back into the pose of the disk-wise robot; ``"slip"``: every cable slides in the direction
    of its last drive increment, each step :func:`simulate`.  Both: ``docs/mechanisms/continuum.md``,
    "Stick-slip with memory that the pose feels" and departure 15.  ``times`` (s) are only checked.

    Returns
    -------
    HistoryResult

    Raises
    ------
    ValueError
        ``times`` not strictly increasing, or ``memory="elastic"`` combined with ``model="arc"`` or a pulley.
    """
    check_params(robot, ContinuumRobot, "robot")
    if pulley is not None:
        check_params(pulley, Pulley, "pulley")
    check_choice(model, "model", ("arc", "chord"))
    check_choice(memory, "memory", ("elastic", "slip"))
    if memory == "elastic" and model != "chord":
        raise ValueError(f"Expected model='chord' with memory='elastic' (chord spans), got {model!r}.")
    if memory == "elastic" and pulley is not None:
        raise ValueError(
            "Expected pulley=None with memory='elastic' (the pulley's stick-slip is not modelled), got a "
            "Pulley; use memory='slip'."
        )
    qa = as_array(q, "q", (None, robot.n_cables))
    if qa.ndim < 2 or qa.shape[0] < 1:
        raise ValueError(
            f"Expected q (n_t, ..., {robot.n_cables}) with a leading time axis of length >= 1, got shape "
            f"{qa.shape}."
        )
    n_t = qa.shape[0]
    if times is not None:
        ts = as_array(times, "times", (None,))
        if ts.shape != (n_t,):
            raise ValueError(
                f"Expected times of shape ({n_t},) (one per drive sample of q {qa.shape}), got {ts.shape}."
            )
        if np.any(np.diff(ts) <= 0.0):
            raise ValueError("Expected times strictly increasing, got a non-monotone history.")
    if memory == "elastic":
        return _elastic_history(robot, qa)
    return _slip_history(robot, qa, model, pulley)


def _drive_directions(qa: np.ndarray) -> np.ndarray:
    """Sign of every cable's last nonzero drive increment, +1 before it moved, ``(n_t, ..., 3 n)``."""
    d = np.ones(qa.shape[1:])
    prev = np.zeros(qa.shape[1:])
    out = np.empty_like(qa)
    for i in range(qa.shape[0]):
        dq = qa[i] - prev
        d = np.where(dq > 0.0, 1.0, np.where(dq < 0.0, -1.0, d))
        out[i] = d
        prev = qa[i]
    return out


def _elastic_history(robot: ContinuumRobot, qa: np.ndarray) -> HistoryResult:
    batch = qa.shape[1:-1]
    k, m, _ = _memory_initial(robot, batch)
    prev_q = np.zeros((*batch, robot.n_cables))
    act = _span_active(robot)
    rows = []
    for i in range(qa.shape[0]):  # a history is sequential
        st = _memory_step(robot, k, m, qa[i] - prev_q)
        rows.append(st)
        good = st.converged & np.all(np.isfinite(st.k), axis=-1)
        # a sample that failed keeps its last good state (it is flagged; the batch goes on)
        k = np.where(good[..., None], st.k, k)
        m = np.where(good[..., None, None], st.material, m)
        prev_q = np.where(good[..., None], qa[i], prev_q)
    tp = np.stack([r.piece_tension for r in rows])
    flux = np.stack([r.flux for r in rows])
    disk_T = np.stack([r.disk_T for r in rows])
    kk = np.stack([r.k for r in rows])
    th, be = _k_to_psi(kk)
    live = np.concatenate([np.ones((robot.n_cables, 1), dtype=bool), act], -1)
    taut = np.all(np.where(live, tp >= 0.0, True), axis=(-2, -1))
    conv = np.stack([r.converged for r in rows])
    tension = np.maximum(tp[..., 0], 0.0)
    # the state of a hole is the sign of the material that crossed it (0: stuck)
    state = np.where(np.abs(flux) > STUCK_FLUX_TOL, np.sign(flux), 0.0).astype(int)
    return HistoryResult(
        psi=_segment_psi(robot, disk_T),
        tension=tension,
        actuator_tension=tension.copy(),
        direction=_drive_directions(qa),
        span_tension=np.where(act, np.maximum(tp[..., 1:], 0.0), 0.0),
        state=state,
        taut=taut,
        converged=conv,
        residual=np.stack([r.residual for r in rows]),
        valid=taut & conv,
        tip=disk_T[..., -1, :3, 3],
        bend=np.stack([th, be], -1),
        slip=flux,
    )


def _slip_history(
    robot: ContinuumRobot, qa: np.ndarray, model: CableModel, pulley: Pulley | None
) -> HistoryResult:
    n_t = qa.shape[0]
    dirs = _drive_directions(qa)
    psi_prev: np.ndarray | None = None
    rows = []
    for i in range(n_t):  # a history is sequential
        r = simulate(robot, qa[i], dirs[i], model=model, initial=psi_prev, pulley=pulley)
        rows.append(r)
        # the next step starts from this pose where it is usable, else from the straight pose
        good = np.all(np.isfinite(r.psi), axis=-1, keepdims=True)
        psi_prev = np.where(good, r.psi, 0.0)
    psi = np.stack([r.psi for r in rows])
    tension = np.stack([r.tension for r in rows])
    taut = np.stack([r.taut for r in rows])
    conv = np.stack([r.converged for r in rows])
    # stick_slip_tensions needs T > 0: a slack cable gets a floor value, its sample is flagged not taut
    floor = np.maximum(tension, STICK_SLIP_TENSION_FLOOR)
    hist = stick_slip_tensions(robot, np.nan_to_num(psi), np.nan_to_num(floor, nan=STICK_SLIP_TENSION_FLOOR))
    theta, beta = psi[..., 0::2], psi[..., 1::2]
    disk = _disk_T(robot, np.nan_to_num(theta), np.nan_to_num(beta))
    N = robot.disks_per_segment
    # the cable that crossed every hole, implied by the sliding model itself: every span holds
    # ell (1 - T / EA) of cable at its fully sliding tension; s_h = -(change of the cable distal of h)
    psi0 = np.nan_to_num(psi)
    ell = span_lengths(robot, psi0, model)
    span_t = np.nan_to_num(tension)[..., None] * _factors(
        robot, _wrap(robot, psi0[..., 0::2], psi0[..., 1::2]), dirs
    )
    act = _span_active(robot)
    mat = np.where(act, ell * (1.0 - span_t / robot.cable_axial_stiffness), 0.0)
    h0 = robot.segment_length / N
    rest = np.where(act, h0 * (1.0 - robot.pretension / robot.cable_axial_stiffness), 0.0)
    dm = np.diff(np.concatenate([np.broadcast_to(rest, mat[:1].shape), mat]), axis=0)
    slip = -np.cumsum(dm[..., ::-1], axis=-1)[..., ::-1]
    return HistoryResult(
        psi=psi,
        tension=tension,
        actuator_tension=np.stack([r.actuator_tension for r in rows]),
        direction=dirs,
        span_tension=hist.span_tension,
        state=hist.state,
        taut=taut,
        converged=conv,
        residual=np.stack([r.residual for r in rows]),
        valid=taut & conv,
        tip=np.where(np.isfinite(psi).all(-1, keepdims=True), disk[..., -1, :3, 3], np.nan),
        bend=np.stack([np.repeat(theta / N, N, axis=-1), np.repeat(beta, N, axis=-1)], -1),
        slip=np.where(act, slip, 0.0),
    )


# ---- disk-wise constant curvature ---------------------------------------------------------------
def _ends_of(robot: ContinuumRobot, eq: DiskEquilibrium) -> np.ndarray:
    N = robot.disks_per_segment
    return eq.disk_T[..., N::N, :3, 3].reshape(*eq.tip.shape[:-1], 3 * robot.n_segments)


def _psi_from_u(u: np.ndarray) -> np.ndarray:
    th, be = _k_to_psi(u)
    return np.stack([th, be], -1).reshape(u.shape)


def _disk_at(robot: ContinuumRobot, u: np.ndarray, d: np.ndarray) -> DiskEquilibrium:
    """Disk-wise equilibrium under the library's tensions for the commanded pose with bending vectors u."""
    psi = _psi_from_u(u)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        t = cable_tensions(robot, np.nan_to_num(psi), direction=d).tension
    th, be = psi[..., 0::2], psi[..., 1::2]
    return _solve(robot, _uniform_k(robot, th, be), t, d, "tension")


def _disk_compensation(robot: ContinuumRobot, theta: np.ndarray, beta: np.ndarray, d: np.ndarray):
    n = robot.n_segments
    target = _fk(robot, theta, beta)[..., :3, 3].reshape(*theta.shape[:-1], 3 * n)
    u = np.stack([theta * np.cos(beta), theta * np.sin(beta)], -1).reshape(*theta.shape[:-1], 2 * n)
    done = np.zeros(theta.shape[:-1], dtype=bool)
    ends = lambda uu: _ends_of(robot, _disk_at(robot, uu, d))  # noqa: E731
    for _ in range(COMPENSATION_ITERATIONS):
        step = _gauss_newton_step(_fd_jacobian(ends, u, COMPENSATION_FD_STEP), ends(u) - target)
        u = np.where(done[..., None], u, u - step)
        done = done | (np.max(np.abs(step), axis=-1) < COMPENSATION_STEP_TOL)
        if np.all(done):
            break
    return _disk_at(robot, u, d)


@carries_failed_rows({"tension": 1}, {"direction": 1, "initial": 1})
def disk_equilibrium(
    robot: ContinuumRobot,
    *,
    tension: object | None = None,
    drive: object | None = None,
    direction: object | None = None,
    initial: object | None = None,
) -> DiskEquilibrium:
    """Equilibrium of the disk-wise constant-curvature robot, one arc per disk interval (not in paper 3;
    ``docs/mechanisms/continuum.md``): :class:`DiskEquilibrium`.

    Loaded by exactly one of ``tension`` (actuator side, N) and ``drive`` (m pulled in); ``initial``
    the segment pose ``psi`` to start from (``None``: straight).

    Returns
    -------
    DiskEquilibrium

    Raises
    ------
    ValueError
        Both or neither of ``tension`` and ``drive`` given.
    """
    check_params(robot, ContinuumRobot, "robot")
    if (tension is None) == (drive is None):
        raise ValueError("Expected exactly one of tension and drive, got both or neither.")
    if tension is not None:
        load = as_array(tension, "tension", (robot.n_cables,))
        if np.any(load < 0.0):
            raise ValueError(f"Expected tension >= 0 (a cable cannot push), got min {float(load.min())!r}.")
        mode: Literal["tension", "drive"] = "tension"
    else:
        load = as_array(drive, "drive", (robot.n_cables,))
        mode = "drive"
    batch = load.shape[:-1]
    if initial is not None:
        init = as_array(initial, "initial", (2 * robot.n_segments,))
        th0, be0 = _split(robot, init, "initial")
        batch = broadcast_batch((load, 1, mode), (init, 1, "initial"))
        with_initial = [(init, 1, "initial")]
    else:
        th0 = np.zeros((*batch, robot.n_segments))
        be0 = np.zeros_like(th0)
        with_initial = []
    d = _as_direction(robot, direction, batch)
    batch = broadcast_batch((load, 1, mode), *with_initial, (d, 1, "direction"))
    k0 = np.broadcast_to(
        _uniform_k(robot, th0, be0), (*batch, 2 * robot.n_segments * robot.disks_per_segment)
    )
    load = np.broadcast_to(load, (*batch, robot.n_cables))
    d = np.broadcast_to(d, (*batch, robot.n_cables))
    return _solve(robot, k0, load, d, mode)
