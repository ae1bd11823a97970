"""Parameters of the RRR-RR vectored-thrust spherical mechanism (paper 5, Table 1)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from robomech._validation import check_real

__all__ = ["VectoredThruster"]


def _check_range(name: str, lim: tuple[float, float], bound: float) -> tuple[float, float]:
    if not isinstance(lim, tuple | list) or len(lim) != 2:
        raise ValueError(f"Expected {name} to be a (lo, hi) pair of radians, got {lim!r}.")
    lo, hi = (check_real(v, name, finite=False) for v in lim)
    if not (math.isfinite(lo) and math.isfinite(hi) and -bound <= lo < hi <= bound):
        raise ValueError(f"Expected {name} to satisfy -{bound:.4g} <= lo < hi <= {bound:.4g}, got {lim!r}.")
    return lo, hi


def _check_pos(name: str, value: float, upper: float = math.inf) -> float:
    v = check_real(value, name, finite=False)
    if not (math.isfinite(v) and 0.0 < v < upper):
        raise ValueError(f"Expected {name} in (0, {upper:.4g}), got {value!r}.")
    return v


@dataclass(frozen=True)
class VectoredThruster:
    """Geometry of the vectored thruster, SI units (metres, radians).

    Every joint axis passes through O, so the kinematics depend only on ``arc_angle``; the radii and
    the propeller arm give points, the limits the workspace (chains: docs/mechanisms/vectored_thrust.md).

    Parameters
    ----------
    arc_angle : float, optional
        Angle between X and the passive axis s12, the RRR chain's first arc (rad), in (0, π/2).
    platform_radius, rr_arc_radius, rrr_arc1_radius, rrr_arc2_radius : float, optional
        Radii (m) of the arc-link fixing device, the RR chain's 90° arc, the RRR chain's 45° and 90° arcs.
    propeller_arm : float, optional
        Distance of the propeller from O along s0 (m), larger than every radius.
    q1_limits, q2_limits : tuple of float, optional
        ``(lo, hi)`` ranges of q1 (within [-π, π]) and q2 (within [-π/2, π/2]) (rad).
    tilt_limit : float, optional
        Largest tilt of s0 from +Z allowed by the universal joint (rad), in (0, π/2).
    interference_clearance : float, optional
        Smallest angle between the 45° arc and the fixing device on the platform sphere (rad), in [0, π/2).
    """

    arc_angle: float = math.pi / 4  # paper 5, eq. (7): angle between X and s12 (the 45 deg arc)
    platform_radius: float = 0.020  # Table 1: arc-link fixing device, 20 mm
    rr_arc_radius: float = 0.0225  # Table 1: "chain 1" (the RR chain) 90 deg arc, 22.5 mm
    rrr_arc1_radius: float = 0.025  # Table 1: "chain 2" (the RRR chain) 45 deg arc, 25 mm
    rrr_arc2_radius: float = 0.0225  # Table 1: "chain 2" (the RRR chain) 90 deg arc, 22.5 mm
    propeller_arm: float = 0.080  # Table 1: propeller shaft, 80 mm from the rotation centre
    q1_limits: tuple[float, float] = (-math.pi / 4, math.pi / 4)  # Table 1: q1 range +-pi/4
    q2_limits: tuple[float, float] = (-math.pi / 6, math.pi / 6)  # Table 1: q2 range +-pi/6
    tilt_limit: float = math.pi / 4  # Table 1 / Section 4.1: universal joint delta_max = pi/4
    # Section 4.1 (2): the 45 deg arc and the fixing device must not touch.  The paper gives no
    # clearance; assumed: both members 6 mm wide, so their centre lines must stay one width
    # (6 mm) apart measured on the 20 mm platform sphere: 0.006 / 0.020 = 0.3 rad (17.2 deg).
    interference_clearance: float = 0.3

    def __post_init__(self) -> None:
        object.__setattr__(self, "arc_angle", _check_pos("arc_angle", self.arc_angle, math.pi / 2))
        radius_names = (
            "platform_radius",
            "rr_arc_radius",
            "rrr_arc1_radius",
            "rrr_arc2_radius",
            "propeller_arm",
        )
        for name in radius_names:
            object.__setattr__(self, name, _check_pos(name, getattr(self, name)))
        object.__setattr__(self, "q1_limits", _check_range("q1_limits", self.q1_limits, math.pi))
        object.__setattr__(self, "q2_limits", _check_range("q2_limits", self.q2_limits, math.pi / 2))
        object.__setattr__(self, "tilt_limit", _check_pos("tilt_limit", self.tilt_limit, math.pi / 2))
        v = check_real(self.interference_clearance, "interference_clearance", finite=False)
        if not (math.isfinite(v) and 0.0 <= v < math.pi / 2):
            raise ValueError(
                f"Expected interference_clearance in [0, pi/2) rad, got {self.interference_clearance!r}."
            )
        object.__setattr__(self, "interference_clearance", v)
        radii = (self.platform_radius, self.rr_arc_radius, self.rrr_arc2_radius, self.rrr_arc1_radius)
        if self.propeller_arm <= max(radii):
            raise ValueError(
                f"Expected propeller_arm > every arc radius ({max(radii):.4g} m) so the tip clears the "
                f"links, got {self.propeller_arm!r}."
            )

    @classmethod
    def paper(cls) -> VectoredThruster:
        """Table 1 of paper 5 (radii in mm converted to metres; ranges in radians)."""
        return cls()
