"""Statics by virtual work (paper 3, eqs. (7)-(15)): core elastic energy, cable tensions with pretension,
coupling moments."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._batching import carries_failed_rows
from robomech._validation import as_array, broadcast_batch, check_params, check_positive

from ._friction import _as_direction, _factors, _wrap
from ._kinematics import CableModel, _span_jac, _split, _tip_jacobian
from ._params import ContinuumRobot

__all__ = [
    "TENSION_FLOOR",
    "TensionResult",
    "cable_tensions",
    "coupling_moments",
    "elastic_energy",
    "elastic_gradient",
]

# A cable counts as taut at >= 0 N: it cannot push; any tension keeps it straight (massless cable model).
TENSION_FLOOR = 0.0


@carries_failed_rows({"psi": 1})
def elastic_energy(robot: ContinuumRobot, psi: object) -> np.ndarray:
    """Bending energy ``(...)`` (J) of the cores, U = sum EI theta_i^2 / (2 l) (paper 3, eq. (8)).

    Returns
    -------
    ndarray, shape (...)
    """
    check_params(robot, ContinuumRobot, "robot")
    theta, _ = _split(robot, psi)
    return 0.5 * robot.bending_stiffness / robot.segment_length * np.sum(theta**2, axis=-1)


def _grad_u(robot: ContinuumRobot, theta: np.ndarray) -> np.ndarray:
    g = np.zeros((*theta.shape[:-1], 2 * robot.n_segments))
    g[..., 0::2] = robot.bending_stiffness / robot.segment_length * theta
    return g


@carries_failed_rows({"psi": 1})
def elastic_gradient(robot: ContinuumRobot, psi: object) -> np.ndarray:
    """dU/dpsi ``(..., 2 n)`` (N m/rad): (EI theta_i / l, 0) per segment (gradient of paper 3, eq. (8)).

    Returns
    -------
    ndarray, shape (..., 2 n)
    """
    check_params(robot, ContinuumRobot, "robot")
    theta, _ = _split(robot, psi)
    return _grad_u(robot, theta)


@carries_failed_rows({"psi": 1})
def coupling_moments(robot: ContinuumRobot, psi: object) -> np.ndarray:
    """Paper 3, eq. (12): moment (N m) of segment i+1 on segment i, ``(..., n, 2)`` = (-EI theta_i+1 / l, 0)
    (zero for the last segment): the paper's one-neighbour form, for comparison (the virtual work of
    :func:`cable_tensions` contains this coupling exactly).

    Returns
    -------
    ndarray, shape (..., n, 2)
    """
    check_params(robot, ContinuumRobot, "robot")
    theta, _ = _split(robot, psi)
    M = np.zeros((*theta.shape, 2))
    M[..., :-1, 0] = -robot.bending_stiffness / robot.segment_length * theta[..., 1:]
    return M


@dataclass(frozen=True)
class TensionResult:
    """Cable tensions in equilibrium (from :func:`cable_tensions`).

    Attributes
    ----------
    tension : ndarray, shape (..., 3 n)
        Tension of every cable where it enters the base plate (N, positive = pull).
    minimum_norm : ndarray, shape (..., 3 n)
        The minimum-norm part that balances the core and the load (N), without pretension.
    taut : ndarray of bool, shape (...)
        All cables at or above ``TENSION_FLOOR``.
    min_tension : ndarray, shape (...)
        The smallest cable tension (N).
    residual : ndarray, shape (...)
        Norm of the virtual-work balance (N m), ~1e-15 when the balance holds.
    """

    tension: np.ndarray
    minimum_norm: np.ndarray
    taut: np.ndarray
    min_tension: np.ndarray
    residual: np.ndarray


def _effective_jacobian(robot, theta, beta, direction, model):
    """G = sum_k P_k d span_k / d psi ``(..., 3 n, 2 n)``: virtual work of unit base tensions."""
    J = _span_jac(robot, theta, beta, model)  # (..., 3n, nN, 2n)
    P = _factors(robot, _wrap(robot, theta, beta), direction)
    return np.einsum("...ck,...ckj->...cj", P, J)


@carries_failed_rows({"psi": 1}, {"wrench": 1, "direction": 1})
def cable_tensions(
    robot: ContinuumRobot,
    psi: object,
    *,
    wrench: object | None = None,
    direction: object | None = None,
    pretension: float | None = None,
    model: CableModel = "chord",
) -> TensionResult:
    """Cable tensions holding the robot at ``psi (..., 2 n)`` (paper 3, eqs. (7)-(10), (23)-(24)):
    :class:`TensionResult`.

    ``-G^T tau + J_x^T W = grad U`` (tension positive), ``G`` the span Jacobians weighted by the friction
    factors in ``direction``, ``W = [m; f] (..., 6)`` (N m, N) a ``wrench`` at the tip (base frame);
    ``tau = -(G^T)^+ (grad U - J_x^T W) + (I - (G^T)^+ G^T) pretension * 1`` (``pretension`` N,
    default ``robot.pretension``).

    Returns
    -------
    TensionResult

    Examples
    --------
    >>> res = cable_tensions(ContinuumRobot.paper(), np.array([0.5, 0.0]))
    >>> res.tension.round(4), bool(res.taut), bool(res.residual < 1e-9)
    (array([12.0483,  9.087 ,  9.087 ]), True, True)
    """
    check_params(robot, ContinuumRobot, "robot")
    theta, beta = _split(robot, psi)
    batch = theta.shape[:-1]
    d = _as_direction(robot, direction, batch)
    W = None if wrench is None else as_array(wrench, "wrench", (6,))
    broadcast_batch((theta, 1, "psi"), (d, 1, "direction"), *([] if W is None else [(W, 1, "wrench")]))
    T0 = robot.pretension if pretension is None else check_positive(pretension, "pretension", allow_zero=True)
    G = _effective_jacobian(robot, theta, beta, d, model)
    rhs = _grad_u(robot, theta)
    if W is not None:
        Jx = _tip_jacobian(robot, theta, beta)
        rhs = rhs - np.einsum("...ij,...i->...j", Jx, W)
    Gt = np.swapaxes(G, -1, -2)  # (..., 2n, 3n)
    Gt_pinv = np.linalg.pinv(Gt)  # (..., 3n, 2n)
    t_min = -np.einsum("...ij,...j->...i", Gt_pinv, rhs)
    # paper 3, eq. (10): printed projector I - (J_qpsi^T)^+ J_x^T; the null-space projector of J_qpsi^T is
    # I - (J_qpsi^T)^+ J_qpsi^T.  Printed eta = (1, 1, 1) N; here eta = pretension * (1, ..., 1).
    proj = np.eye(robot.n_cables) - Gt_pinv @ Gt
    tau = t_min + T0 * proj.sum(axis=-1)
    residual = np.linalg.norm(-np.einsum("...ij,...j->...i", Gt, tau) - rhs, axis=-1)
    tmin = tau.min(axis=-1)
    return TensionResult(
        tension=tau, minimum_norm=t_min, taut=tmin >= TENSION_FLOOR, min_tension=tmin, residual=residual
    )
