"""Paper 5: the RRR-RR vectored-thrust spherical mechanism (kinematics, mobility, workspace, singularity)."""

from ._kinematics import (
    SINGULAR_TOL,
    AccelerationResult,
    FKResult,
    IKResult,
    JacobianResult,
    JointAxes,
    PassiveResult,
    angular_acceleration,
    angular_velocity,
    arc_clearance,
    forward_kinematics,
    inverse_kinematics,
    jacobian,
    joint_axes,
    link_clearance,
    passive_angles,
    passive_rates,
)
from ._mobility import MechanismMobility, chain_screws, mechanism_mobility, platform_mobility
from ._params import VectoredThruster

__all__ = [
    "SINGULAR_TOL",
    "AccelerationResult",
    "FKResult",
    "IKResult",
    "JacobianResult",
    "JointAxes",
    "MechanismMobility",
    "PassiveResult",
    "VectoredThruster",
    "angular_acceleration",
    "angular_velocity",
    "arc_clearance",
    "chain_screws",
    "forward_kinematics",
    "inverse_kinematics",
    "jacobian",
    "joint_axes",
    "link_clearance",
    "mechanism_mobility",
    "passive_angles",
    "passive_rates",
    "platform_mobility",
]
