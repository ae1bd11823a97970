"""Geometry of the six-wheel wheel-track exploration robot (paper 4), in SI units; frames:
``docs/mechanisms/skid_steer.md``."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from robomech._validation import check_positive, check_real

__all__ = ["ExplorationRobot"]

# paper 4, Sec. 2.2: the six lengths it prints, in millimetres.
_PAPER_MM = {
    "rocker_lateral_offset": 225.0,  # L^D_{R1Y}: differential (body centre) to rocker pivot, along y
    "spring_mount_offset": 28.0,  # L^R_{Q1Z}: rocker pivot to spring-damper mount, along rocker z
    "side_link_hinge_offset": 68.0,  # L^H_{LF1}: bogie hinge to front side-link hinge, along bogie x
    "road_wheel_radius": 50.0,  # L^K_{AF1Z}: road-wheel hub to its contact point
    "rear_wheel_drop": 190.0,  # L^R_{W1Z}: rocker pivot to rear-wheel hub along rocker z (nominal)
    "rear_wheel_radius": 100.0,  # L^W_{P1Z}: rear-wheel hub to its contact point
}


@dataclass(frozen=True)
class ExplorationRobot:
    """Kinematic geometry of the robot (metres, radians): the paper prints six lengths (``paper()``), the
    others are documented choices (``docs/mechanisms/skid_steer.md``, "Parameters").

    Attributes
    ----------
    rocker_lateral_offset, spring_mount_offset, side_link_hinge_offset : float
        ``b``, body centre to each rocker pivot and wheel plane (track width ``S = 2 b``); rocker pivot to
        the spring-damper mount (no kinematics); bogie hinge to each side-link hinge (front +x, rear -x).
    road_wheel_radius, rear_wheel_radius, rear_wheel_drop : float
        Hub-to-contact distances (track neglected); nominal rear-wheel slide ``s`` along the rocker's -z.
    rear_arm_length, bogie_hinge_x, bogie_hinge_drop, side_link_length, side_link_rake : float
        Not printed: rocker pivot to the rear slide (along -x); bogie hinge at ``(+x, 0, -drop)`` in the
        rocker frame; each road wheel ``side_link_length`` from its hinge, raked back by ``side_link_rake``.
    """

    rocker_lateral_offset: float
    spring_mount_offset: float
    side_link_hinge_offset: float
    road_wheel_radius: float
    rear_wheel_drop: float
    rear_wheel_radius: float
    rear_arm_length: float
    bogie_hinge_x: float
    bogie_hinge_drop: float
    side_link_length: float
    side_link_rake: float

    def __post_init__(self) -> None:
        for f in fields(self):
            if f.name == "side_link_rake":
                continue
            object.__setattr__(self, f.name, check_positive(getattr(self, f.name), f.name))
        rake = check_real(self.side_link_rake, "side_link_rake", finite=False)
        if not (math.isfinite(rake) and 0.0 < rake < 0.5 * math.pi):
            # A vertical side link (rake 0) makes the two road-wheel rates indistinguishable from the
            # bogie rate at first order; a horizontal one (pi/2) cannot lift the wheels.
            raise ValueError(f"Expected side_link_rake in (0, pi/2) rad, got {self.side_link_rake!r}.")
        object.__setattr__(self, "side_link_rake", rake)

    @classmethod
    def paper(cls) -> ExplorationRobot:
        """The paper's six lengths (Sec. 2.2) with the documented values for what it omits."""
        mm = {k: v * 1e-3 for k, v in _PAPER_MM.items()}
        side_link_length = 0.080
        side_link_rake = math.radians(40.0)
        # All six contacts level at zero joint angles: rear contact depth (drop + rear radius) equals
        # the road-wheel contact depth (hinge drop + link height + road radius).
        depth = mm["rear_wheel_drop"] + mm["rear_wheel_radius"]
        hinge_drop = depth - mm["road_wheel_radius"] - side_link_length * math.cos(side_link_rake)
        return cls(
            **mm,
            rear_arm_length=0.300,
            bogie_hinge_x=0.250,
            bogie_hinge_drop=hinge_drop,
            side_link_length=side_link_length,
            side_link_rake=side_link_rake,
        )

    @property
    def track_width(self) -> float:
        """``S``: distance between the left and right wheel planes (m)."""
        return 2.0 * self.rocker_lateral_offset

    @property
    def ground_clearance_depth(self) -> float:
        """Depth of the rear contact points below the body centre at zero joint angles (m)."""
        return self.rear_wheel_drop + self.rear_wheel_radius

    @property
    def wheelbase(self) -> float:
        """``L``: rear-wheel contact to the midpoint of the road-wheel contacts, at zero joint angles (m)."""
        road_mid = self.bogie_hinge_x - self.side_link_length * math.sin(self.side_link_rake)
        return road_mid + self.rear_arm_length
