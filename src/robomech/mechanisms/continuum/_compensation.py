"""Cable elongation, the compensated drive q~ = q + delta, and a quasi-static simulated robot.

Drive convention: ``q (..., 3 n)`` is the length of cable each actuator has pulled in since the straight,
pretensioned pose (m); the theoretical drive is ``q = -(L(psi) - L(0))`` (paper 3, eq. (37) adds the
elongation delta to it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._validation import as_array, check_params

from ._friction import _as_direction, _factors, _wrap
from ._kinematics import CableModel, _segment_spans, _split, span_lengths
from ._params import ContinuumRobot
from ._statics import TensionResult, cable_tensions

__all__ = [
    "SIM_BACKTRACKS",
    "SIM_FD_STEP",
    "SIM_MAX_ITERATIONS",
    "SIM_TOLERANCE",
    "DriveResult",
    "SimulationResult",
    "cable_elongation",
    "compensated_drive",
    "simulate",
    "theoretical_drive",
]

# Newton on the equilibrium of the simulated robot: converged when the generalized force residual is
# below 1e-10 N m (1e-9 of the ~0.03 N m bending moments) ...
SIM_TOLERANCE = 1e-10
# ... within 40 iterations (quadratic convergence needs ~5 from a nearby start; the margin covers starts
# far from the solution and the Coulomb kink of the wrap angles at theta = 0).
SIM_MAX_ITERATIONS = 40
# Step halvings of the backtracking line search (2^-12 ~ 2e-4 of a Newton step is the smallest tried).
SIM_BACKTRACKS = 12
# Central-difference step (rad) for the 2n x 2n Newton matrix: eps^(1/3) for O(1) curvature.
SIM_FD_STEP = 6e-6


def _lengths_and_factors(robot, theta, beta, direction, model):
    psi = np.stack([theta, beta], -1).reshape(*theta.shape[:-1], 2 * theta.shape[-1])
    ell = span_lengths(robot, psi, model)  # (..., 3n, nN)
    P = _factors(robot, _wrap(robot, theta, beta), direction)
    return ell, P


def _l0(robot: ContinuumRobot, model: str) -> np.ndarray:
    return span_lengths(robot, np.zeros(2 * robot.n_segments), model).sum(axis=-1)


def _elongation(robot, ell, P, t_base, model):
    ea, T0, Lf = robot.cable_axial_stiffness, robot.pretension, robot.free_length
    integral = t_base * (Lf + np.sum(P * ell, axis=-1))
    return (integral - T0 * (Lf + _l0(robot, model))) / ea


def cable_elongation(
    robot: ContinuumRobot,
    psi: object,
    tension: object,
    direction: object | None = None,
    model: CableModel = "chord",
) -> np.ndarray:
    """Stretch of every cable relative to the straight pose at pretension, ``(..., 3 n)`` (m).

    Hooke's law along the cable (paper 3, eq. (33)): delta = (int T ds - T0 (L_free + L(0))) / (E A), with
    ``tension (..., 3 n)`` the tension at the base plate, constant over the free length between the
    actuator and the base and reduced span by span by the disk friction (``direction``).  This is the
    discrete form of eq. (36) (which integrates an exponential tension profile).
    """
    check_params(robot, ContinuumRobot, "robot")
    theta, beta = _split(robot, psi)
    t = as_array(tension, "tension", (robot.n_cables,))
    d = _as_direction(robot, direction, theta.shape[:-1])
    ell, P = _lengths_and_factors(robot, theta, beta, d, model)
    return _elongation(robot, ell, P, t, model)


def theoretical_drive(robot: ContinuumRobot, psi: object, model: CableModel = "arc") -> np.ndarray:
    """Cable pulled in by each actuator for a rigid, frictionless robot: q = -(L(psi) - L(0))."""
    check_params(robot, ContinuumRobot, "robot")
    theta, beta = _split(robot, psi)
    psi_a = np.stack([theta, beta], -1).reshape(*theta.shape[:-1], 2 * theta.shape[-1])
    return -(span_lengths(robot, psi_a, model).sum(axis=-1) - _l0(robot, model))


@dataclass(frozen=True)
class DriveResult:
    """Compensated drive (batch shape ``...``): ``q`` theoretical, ``delta`` elongation, ``q_compensated``
    = q + delta (paper 3, eq. (37)), the model ``tension`` behind delta, and ``taut`` (all cables in
    tension; where false the compensation is not meaningful)."""

    q: np.ndarray
    delta: np.ndarray
    q_compensated: np.ndarray
    tension: np.ndarray
    taut: np.ndarray


def compensated_drive(
    robot: ContinuumRobot,
    psi: object,
    direction: object | None = None,
    *,
    model: CableModel = "chord",
    wrench: object | None = None,
) -> DriveResult:
    """Feed-forward drive for pose ``psi (..., 2 n)``: q~ = q + delta (paper 3, eq. (37), Fig. 10).

    The tensions come from :func:`cable_tensions` (virtual work, friction along the disks in the sliding
    ``direction``, pretension in the null space), the elongation from :func:`cable_elongation`.
    """
    check_params(robot, ContinuumRobot, "robot")
    theta, beta = _split(robot, psi)
    psi_a = np.stack([theta, beta], -1).reshape(*theta.shape[:-1], 2 * theta.shape[-1])
    tr: TensionResult = cable_tensions(robot, psi_a, wrench=wrench, direction=direction, model=model)
    q = theoretical_drive(robot, psi_a, model)
    delta = cable_elongation(robot, psi_a, tr.tension, direction, model)
    return DriveResult(q=q, delta=delta, q_compensated=q + delta, tension=tr.tension, taut=tr.taut)


# ---- the simulated robot --------------------------------------------------------------------------
@dataclass(frozen=True)
class SimulationResult:
    """Quasi-static equilibrium of the simulated robot under a drive (batch shape ``...``).

    ``psi (..., 2 n)`` pose, ``tension (..., 3 n)`` at the base plate, ``taut`` no cable went slack,
    ``converged`` Newton met ``SIM_TOLERANCE``, ``residual`` generalized-force residual (N m).
    """

    psi: np.ndarray
    tension: np.ndarray
    taut: np.ndarray
    converged: np.ndarray
    residual: np.ndarray
    iterations: np.ndarray


def _k_to_psi(k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    kx, ky = k[..., 0::2], k[..., 1::2]
    return np.hypot(kx, ky), np.arctan2(ky, kx)


def _sim_residual(robot, k, q, d, model):
    """Generalized force in bending-vector coordinates k_i = theta_i (cos beta_i, sin beta_i)."""
    theta, beta = _k_to_psi(k)
    ell, P = _lengths_and_factors(robot, theta, beta, d, model)
    L, L0 = ell.sum(axis=-1), _l0(robot, model)
    ea, T0, Lf = robot.cable_axial_stiffness, robot.pretension, robot.free_length
    # Compatibility: the cable's geometric path equals its unstretched length (pulled in by q) plus its
    # stretch; solved for the base tension, linear in it.  A cable cannot push: tension clipped at 0.
    t_raw = (ea * (L - L0 + q) + T0 * (Lf + L0)) / (Lf + np.sum(P * ell, axis=-1))
    t = np.maximum(t_raw, 0.0)
    # Virtual work of the span tensions, with d/dbeta divided by theta (finite at the straight pose):
    # d/dk = d/dtheta (cos b, sin b) + (d/dbeta)/theta (-sin b, cos b).
    _, dth, dbe_t = _segment_spans(robot, theta, beta, model)
    act = robot.cable_segment[:, None] >= np.arange(robot.n_segments)[None, :]
    N = robot.disks_per_segment
    Pseg = P.reshape(*P.shape[:-1], robot.n_segments, N).sum(axis=-1)  # (..., 3n, n)
    w = np.where(act, Pseg, 0.0) * t[..., :, None]
    f_th = -np.sum(w * dth, axis=-2) - robot.bending_stiffness / robot.segment_length * theta
    f_bt = -np.sum(w * dbe_t, axis=-2)
    cb, sb = np.cos(beta), np.sin(beta)
    F = np.empty_like(k)
    F[..., 0::2] = f_th * cb - f_bt * sb
    F[..., 1::2] = f_th * sb + f_bt * cb
    return F, t_raw


def simulate(
    robot: ContinuumRobot,
    q: object,
    direction: object | None = None,
    *,
    model: CableModel = "chord",
    initial: object | None = None,
) -> SimulationResult:
    """Equilibrium pose of a robot whose actuators have pulled in ``q (..., 3 n)`` (m): a simulated robot.

    Model: constant-curvature segments with the core energy of eq. (8); elastic cables (E A) over the
    free length and the spans; Coulomb friction at every hole in the sliding ``direction``; cables that
    would push go slack (tension 0, ``taut`` false).  Solved by Newton in bending-vector coordinates
    (smooth through the straight pose), starting from ``initial`` psi or the rigid-cable arc solution.
    """
    check_params(robot, ContinuumRobot, "robot")
    qa = as_array(q, "q", (robot.n_cables,))
    batch = qa.shape[:-1]
    d = _as_direction(robot, direction, batch)
    n = robot.n_segments
    if initial is None:
        # Rigid arc cables: q_c = r sum_{m <= seg(c)} k_m . (cos s_c, sin s_c); least squares for k.
        sig, act = robot.hole_angles, robot.cable_segment[:, None] >= np.arange(n)[None, :]
        A = np.zeros((robot.n_cables, 2 * n))
        A[:, 0::2] = robot.hole_radius * np.cos(sig)[:, None] * act
        A[:, 1::2] = robot.hole_radius * np.sin(sig)[:, None] * act
        k = np.einsum("ij,...j->...i", np.linalg.pinv(A), qa)
    else:
        th0, be0 = _split(robot, initial, "initial")
        k = np.stack([th0 * np.cos(be0), th0 * np.sin(be0)], -1).reshape(*th0.shape[:-1], 2 * n)
    k = np.broadcast_to(k, (*batch, 2 * n)).copy()
    converged = np.zeros(batch, dtype=bool)
    iterations = np.zeros(batch, dtype=int)
    eye = np.eye(2 * n)
    for _ in range(SIM_MAX_ITERATIONS):  # Newton iterations over the whole batch
        F, _ = _sim_residual(robot, k, qa, d, model)
        converged = np.linalg.norm(F, axis=-1) < SIM_TOLERANCE
        if np.all(converged):
            break
        cols = []
        for j in range(2 * n):
            e = SIM_FD_STEP * eye[j]
            cols.append(
                (_sim_residual(robot, k + e, qa, d, model)[0] - _sim_residual(robot, k - e, qa, d, model)[0])
                / (2 * SIM_FD_STEP)
            )
        Jm = np.stack(cols, -1)
        # pinv, not solve: a singular Newton matrix in one sample must not abort the batch
        step = np.einsum("...ij,...j->...i", np.linalg.pinv(Jm), F)
        # Backtracking: halve the step where it does not reduce |F| (the slack clip and the Coulomb
        # kink at theta = 0 make F only piecewise smooth).
        f0 = np.linalg.norm(F, axis=-1)
        scale = np.ones(batch)
        for _ in range(SIM_BACKTRACKS):
            F_try, _ = _sim_residual(robot, k - scale[..., None] * step, qa, d, model)
            trial = np.linalg.norm(F_try, axis=-1)
            worse = (trial >= f0) & ~converged
            if not np.any(worse):
                break
            scale = np.where(worse, 0.5 * scale, scale)
        k = np.where(converged[..., None], k, k - scale[..., None] * step)
        iterations = iterations + ~converged
    F, t_raw = _sim_residual(robot, k, qa, d, model)
    res = np.linalg.norm(F, axis=-1)
    theta, beta = _k_to_psi(k)
    psi = np.stack([theta, beta], -1).reshape(*batch, 2 * n)
    return SimulationResult(
        psi=psi,
        tension=np.maximum(t_raw, 0.0),
        taut=np.all(t_raw >= 0.0, axis=-1),
        converged=res < SIM_TOLERANCE,
        residual=res,
        iterations=iterations,
    )
