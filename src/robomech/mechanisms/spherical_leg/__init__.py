"""Paper 1: the 2RUHU-RUPR-RUR spherical parallel leg of a wheel-leg robot (Chen et al., Optics and
Precision Engineering 27(8), 2019); every assumption and departure: ``docs/mechanisms/spherical_leg.md``.
"""

from ._dynamics import (
    ACTUATION_SIGMA_MIN,
    CARDAN_LOCK_TOL,
    PAPER_DRIVEN_LEGS,
    ForceDistribution,
    InverseDynamicsResult,
    distribute_forces,
    generalized_forces,
    inverse_dynamics,
    mass_matrix,
    mechanical_energy,
)
from ._kinematics import (
    ForwardKinematicsResult,
    InverseKinematicsResult,
    angular_velocity_jacobian,
    forward_kinematics,
    hessian,
    influence_coefficients,
    inverse_kinematics,
    jacobian,
    leg_rates,
    platform_rotation,
)
from ._motions import fig5_motion, sway
from ._params import LegBody, SphericalLeg
from ._tracking import BranchTrack, track_branches
from ._workspace import WorkspaceMap, workspace_map

__all__ = [
    "ACTUATION_SIGMA_MIN",
    "CARDAN_LOCK_TOL",
    "PAPER_DRIVEN_LEGS",
    "BranchTrack",
    "ForceDistribution",
    "ForwardKinematicsResult",
    "InverseDynamicsResult",
    "InverseKinematicsResult",
    "LegBody",
    "SphericalLeg",
    "WorkspaceMap",
    "angular_velocity_jacobian",
    "distribute_forces",
    "fig5_motion",
    "forward_kinematics",
    "generalized_forces",
    "hessian",
    "influence_coefficients",
    "inverse_dynamics",
    "inverse_kinematics",
    "jacobian",
    "leg_rates",
    "mass_matrix",
    "mechanical_energy",
    "platform_rotation",
    "sway",
    "track_branches",
    "workspace_map",
]
from ._multibody import to_multibody as to_multibody
