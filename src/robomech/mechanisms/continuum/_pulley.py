"""The actuator pulley of the drive chain: improved capstan (paper 3, eqs. (29)-(35)) and its stretch."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from robomech._validation import coerce_float_fields

from ._friction import capstan_tension_ratio
from ._params import ContinuumRobot

__all__ = ["PULLEY_FIXED_POINT_ITERATIONS", "PULLEY_QUAD_NODES", "Pulley"]

# Gauss-Legendre nodes for the wrap integral int_0^phi T dphi' of eq. (34): T(phi') is smooth (an
# exponential-like profile, exp(mu phi) <= exp(0.6 pi) ~ 6.6 over the paper's range), so 24 nodes give
# the integral to ~1e-15 relative.
PULLEY_QUAD_NODES = 24
# Fixed-point iterations for the tension-level dependence of kappa when n < 1 (eq. (29)): the ratio
# varies slowly with the tension level (d ln kappa / d ln T = O(1 - n) small), the iteration contracts
# by that factor; 30 iterations reach rounding for n >= 0.5.  n = 1 is exact after the first.
PULLEY_FIXED_POINT_ITERATIONS = 30


@dataclass(frozen=True)
class Pulley:
    """The guide pulley between an actuator and the robot's base plate (paper 3, Section 3.3, Fig. 7).

    The cable radius r_s is the robot's ``cable_diameter / 2``; rho = R_j / r_s and the contact arc radius
    R = R_j + r_s (eq. (34)).

    Parameters
    ----------
    radius : float, optional
        Pulley radius R_j (m, > 0); not printed in the paper, default 5 mm.
    wrap : float, optional
        Contact (wrap) angle phi of the cable (rad, >= 0); paper Fig. 9: 0 ... pi; default pi / 2.
    alpha : float, optional
        Friction constant of f = alpha N^n (eq. (25), >= 0); alpha = mu, n = 1 is Amontons' law;
        paper Fig. 9: 0.15 or 0.6; default 0.15.  alpha = 0 is the frictionless pulley.
    n : float, optional
        Exponent of eq. (25), in (0, 1]; paper Fig. 9: 0.67 or 1; default 1.
    """

    radius: float = 0.005
    wrap: float = math.pi / 2.0
    alpha: float = 0.15
    n: float = 1.0

    def __post_init__(self) -> None:
        coerce_float_fields(self, ("radius",), positive=True)
        coerce_float_fields(self, ("wrap", "alpha"), positive=True, allow_zero=True)
        coerce_float_fields(self, ("n",), positive=True)
        if self.n > 1.0:
            raise ValueError(f"Expected n in (0, 1] (eq. (25)), got {self.n!r}.")


def _kappa(
    robot: ContinuumRobot, pulley: Pulley, phi: NDArray[np.float64], t_out: NDArray[np.float64]
) -> NDArray[np.float64]:
    """kappa(phi; t_out) of eq. (32), 1 for a frictionless pulley."""
    if pulley.alpha == 0.0:
        return np.ones(np.broadcast_shapes(np.shape(phi), np.shape(t_out)))
    rho = pulley.radius / (0.5 * robot.cable_diameter)
    return capstan_tension_ratio(phi, rho=rho, alpha=pulley.alpha, n=pulley.n, t_out=t_out)


def _profile_integral(
    robot: ContinuumRobot, pulley: Pulley, t_out: NDArray[np.float64]
) -> NDArray[np.float64]:
    """int_0^phi kappa(phi'; t_out) dphi' (rad) by Gauss-Legendre: the wrap profile from the output side."""
    phi = pulley.wrap
    if phi == 0.0:
        return np.zeros(np.shape(t_out))
    x, w = np.polynomial.legendre.leggauss(PULLEY_QUAD_NODES)
    nodes = 0.5 * phi * (x + 1.0)
    k = _kappa(robot, pulley, nodes, np.asarray(t_out)[..., None])
    return 0.5 * phi * np.sum(w * k, axis=-1)


def pulley_chain(
    robot: ContinuumRobot, pulley: Pulley, t: NDArray[np.float64], d: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Actuator-side tension and the wrap integral int T dphi' (N rad) for base tensions ``t`` (> 0).
    The output side: the robot for d = +1, the actuator for d = -1 (fixed point for n < 1); d = 0 (only
    where mu = 0 at the disks): the pulley taken as stuck, T = t throughout."""
    t = np.maximum(np.asarray(t, dtype=float), np.finfo(float).tiny)
    d = np.broadcast_to(d, t.shape)
    phi = pulley.wrap
    # pulled in: output = robot side
    k_in = _kappa(robot, pulley, np.asarray(phi), t)
    t_act = np.where(d > 0, k_in * t, t)
    integral = np.where(d > 0, t * _profile_integral(robot, pulley, t), t * phi)
    if np.any(d < 0):
        # paid out: output = actuator side; kappa depends on the tension level only for n < 1
        ta = t / _kappa(robot, pulley, np.asarray(phi), t)
        iters = 1 if pulley.n == 1.0 else PULLEY_FIXED_POINT_ITERATIONS
        for _ in range(iters):
            ta = t / _kappa(robot, pulley, np.asarray(phi), ta)
        t_act = np.where(d < 0, ta, t_act)
        integral = np.where(d < 0, ta * _profile_integral(robot, pulley, ta), integral)
    return t_act, integral


def pulley_stretch(
    robot: ContinuumRobot, pulley: Pulley, t: NDArray[np.float64], d: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(actuator tension, stretch of the wrapped cable delta_c) of eq. (34), with R = R_j + r_s."""
    t_act, integral = pulley_chain(robot, pulley, t, d)
    # paper 3, eqs. (34)-(35): (35) is garbled (errata: k undefined); eq. (34) is used as written,
    # delta_c = (R int_0^phi T dphi' - T0 R phi) / (E A), with the profile T(phi') of eq. (29).
    R = pulley.radius + 0.5 * robot.cable_diameter
    delta = R * (integral - robot.pretension * pulley.wrap) / robot.cable_axial_stiffness
    return t_act, delta
