"""The test trajectories of paper 2, eqs. (51)-(53), built from :mod:`robomech.trajectory`: foot displacements
X, Y along X0, Y0 and a lift Z from :func:`start_point` (docs/mechanisms/omnileg.md, departures 10-12)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._validation import as_array, check_int, check_params
from robomech.trajectory import Profile, quintic, sinusoid, swing_sextic

from ._kinematics import forward_kinematics
from ._params import OmniLeg

__all__ = [
    "EQ51_PERIOD",
    "EQ52_DURATION",
    "START_GAMMA",
    "GaitProfile",
    "foot_trajectory_eq51",
    "gait_eq53",
    "joint_trajectory_eq52",
    "start_point",
]

# Start pose of the foot trajectories: the paper does not give it.  γ = 60° leaves the shank room to
# extend (the thigh's depth shrinks when it tilts) and to retract (lift), so eq. (51) stays reachable.
START_GAMMA = np.radians(60.0)
# eq. (51) is a normalised quintic/sextic written out for a period T = 5 s (errata): X rises over
# T/2 and returns, Y rises over T, Z lifts and returns over T.
EQ51_PERIOD = 5.0
EQ51_X, EQ51_Y, EQ51_Z = 0.1, 0.1, 0.05  # m, paper 2, eq. (51) coefficients
# eq. (52) is evaluated for 0 <= t <= 6 s (one period of sin(pi t / 3)).
EQ52_DURATION = 6.0
EQ52_AMPLITUDE = np.array([np.pi / 6, np.pi / 6, 25 * np.pi / 180])  # rad, paper 2, eq. (52)
EQ52_FREQUENCY = 1.0 / 6.0  # Hz: sin(pi t / 3) = sin(2 pi t / 6)
# eq. (53) parameters, paper 2, Section 4: stride L = 0.1 m, swing height H = 0.05 m, L_h = 0, T = 1 s.
GAIT_STRIDE, GAIT_HEIGHT, GAIT_LATERAL, GAIT_PERIOD = 0.1, 0.05, 0.0, 1.0


def start_point(leg: OmniLeg) -> np.ndarray:
    """Foot start point ``FK(0, 0, START_GAMMA)`` (m) of eqs. (51) and (53) (the paper gives none).

    Parameters
    ----------
    leg : OmniLeg

    Returns
    -------
    ndarray, shape (3,)
    """
    check_params(leg, OmniLeg, "leg")
    return forward_kinematics(leg, np.array([0.0, 0.0, START_GAMMA]))


def _lift(p0: np.ndarray, x: Profile, y: Profile, z: Profile) -> Profile:
    """Foot profile ``p0 + (X, Y, -Z)``: Z is a lift, against Z0 (which points toward the foot)."""
    up = np.array([1.0, 1.0, -1.0])
    return Profile(p0 + up * x.stack(y, z).q, up * x.stack(y, z).qd, up * x.stack(y, z).qdd)


def foot_trajectory_eq51(leg: OmniLeg, t: object) -> Profile:
    """Foot position, velocity, acceleration (m, hip frame) of eq. (51): X rises by 0.1 m over T/2 and
    returns, Y rises by 0.1 m over T, Z lifts 0.05 m and returns, T = ``EQ51_PERIOD``.

    Parameters
    ----------
    leg : OmniLeg
    t : array_like, shape (...)
        Times (s), in ``[0, EQ51_PERIOD]``.

    Returns
    -------
    Profile
    """
    check_params(leg, OmniLeg, "leg")
    t = as_array(t, "t")
    half = EQ51_PERIOD / 2
    rising = t <= half
    tm = np.where(rising, t, EQ51_PERIOD - t)  # eq. (51): X(t) for t > T/2 is X(T - t)
    xq = quintic(tm, half, 0.0, EQ51_X)
    sign = np.where(rising, 1.0, -1.0)
    x = Profile(xq.q, sign * xq.qd, xq.qdd)
    y = quintic(t, EQ51_PERIOD, 0.0, EQ51_Y)
    z = swing_sextic(t, EQ51_PERIOD, EQ51_Z)
    return _lift(start_point(leg), x, y, z)


def joint_trajectory_eq52(t: object) -> Profile:
    """Joint angles, rates, accelerations of eq. (52): (α, β, γ) = (π/6, π/6, 25π/180) sin(πt/3) (γ < 0
    for 3 s < t < 6 s, outside Table 2's range: the model is valid there, eq. (11) is even in γ).

    Parameters
    ----------
    t : array_like, shape (...)
        Times (s), typically in ``[0, EQ52_DURATION]``.

    Returns
    -------
    Profile
    """
    t = as_array(t, "t")
    return sinusoid(t[..., None], EQ52_AMPLITUDE, EQ52_FREQUENCY)


@dataclass(frozen=True)
class GaitProfile:
    """Foot profile and stance mask of eq. (53) (the result of :func:`gait_eq53`).

    Attributes
    ----------
    foot : Profile
        Foot position ``q`` (m), velocity ``qd`` (m/s) and acceleration ``qdd`` (m/s²), each (..., 3),
        hip frame.
    stance : ndarray of bool, shape (...)
        True during the stance periods (foot on the ground), false during swing.
    """

    foot: Profile
    stance: np.ndarray


def gait_eq53(leg: OmniLeg, t: object, periods: int = 6) -> GaitProfile:
    """Gait of the single-leg platform, eq. (53): swing (Y from -L/2 to +L/2, lifting H) and stance (back
    on the ground) periods of T = 1 s; the paper writes only the swing (docs/mechanisms/omnileg.md).

    Parameters
    ----------
    leg : OmniLeg
    t : array_like, shape (...)
        Times (s), in ``[0, periods * GAIT_PERIOD]`` (``GAIT_PERIOD`` = 1 s).
    periods : int, optional
        Number of periods (>= 1; default 6), starting with a swing.

    Returns
    -------
    :class:`GaitProfile`
    """
    check_params(leg, OmniLeg, "leg")
    t = as_array(t, "t")
    periods = check_int(periods, "periods", low=1)
    T = GAIT_PERIOD
    k = np.clip(np.floor(t / T), 0, periods - 1)
    tau = t - k * T
    stance = (k.astype(int) % 2) == 1
    s = quintic(tau, T, 0.0, 1.0)
    sign = np.where(stance, -1.0, 1.0)
    y = Profile(sign * GAIT_STRIDE * (s.q - 0.5), sign * GAIT_STRIDE * s.qd, sign * GAIT_STRIDE * s.qdd)
    x = Profile(GAIT_LATERAL * s.q, GAIT_LATERAL * s.qd, GAIT_LATERAL * s.qdd)
    zs = swing_sextic(tau, T, GAIT_HEIGHT)
    z = Profile(np.where(stance, 0.0, zs.q), np.where(stance, 0.0, zs.qd), np.where(stance, 0.0, zs.qdd))
    return GaitProfile(_lift(start_point(leg), x, y, z), stance)
