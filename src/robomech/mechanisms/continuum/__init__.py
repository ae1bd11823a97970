"""Paper 3: the cable-driven continuum robot — kinematics, statics, cable friction, compensation,
identification.

Constant-curvature segments ``psi = [theta_1, beta_1, ...]``; cables indexed ``3 i + j``; SI units.
See ``docs/mechanisms/continuum.md`` for every assumption and every departure from the print.
"""

from ._compensation import (
    COMPENSATION_ITERATIONS,
    COMPENSATION_STEP_TOL,
    DriveResult,
    SimulationResult,
    cable_elongation,
    compensated_drive,
    disk_equilibrium,
    simulate,
    theoretical_drive,
)
from ._disks import DISK_MAX_ITERATIONS, DISK_TOLERANCE, DiskEquilibrium
from ._friction import (
    FrictionEstimate,
    TensionHistory,
    capstan_coefficient,
    capstan_tension_ratio,
    classical_capstan_ratio,
    friction_factors,
    identify_friction,
    stick_slip_tensions,
    wrap_angles,
)
from ._identification import (
    IDENTIFY_MU_MAX,
    IDENTIFY_STIFFNESS_BOUNDS,
    PoseFrictionEstimate,
    TipFrictionEstimate,
    identify_friction_from_pose,
    identify_friction_from_tip,
)
from ._kinematics import (
    IK_TOLERANCE,
    IKResult,
    cable_jacobian,
    cable_lengths,
    disk_transforms,
    forward_kinematics,
    inverse_kinematics,
    segment_transform,
    span_jacobian,
    span_lengths,
    tip_jacobian,
    tip_position,
)
from ._params import ContinuumRobot
from ._statics import (
    TensionResult,
    cable_tensions,
    coupling_moments,
    elastic_energy,
    elastic_gradient,
)

__all__ = [
    "COMPENSATION_ITERATIONS",
    "COMPENSATION_STEP_TOL",
    "DISK_MAX_ITERATIONS",
    "DISK_TOLERANCE",
    "IDENTIFY_MU_MAX",
    "IDENTIFY_STIFFNESS_BOUNDS",
    "IK_TOLERANCE",
    "ContinuumRobot",
    "DiskEquilibrium",
    "DriveResult",
    "FrictionEstimate",
    "IKResult",
    "PoseFrictionEstimate",
    "SimulationResult",
    "TensionHistory",
    "TensionResult",
    "TipFrictionEstimate",
    "cable_elongation",
    "cable_jacobian",
    "cable_lengths",
    "cable_tensions",
    "capstan_coefficient",
    "capstan_tension_ratio",
    "classical_capstan_ratio",
    "compensated_drive",
    "coupling_moments",
    "disk_equilibrium",
    "disk_transforms",
    "elastic_energy",
    "elastic_gradient",
    "forward_kinematics",
    "friction_factors",
    "identify_friction",
    "identify_friction_from_pose",
    "identify_friction_from_tip",
    "inverse_kinematics",
    "segment_transform",
    "simulate",
    "span_jacobian",
    "span_lengths",
    "stick_slip_tensions",
    "theoretical_drive",
    "tip_jacobian",
    "tip_position",
    "wrap_angles",
]
