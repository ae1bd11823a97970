"""Paper 2: the OmniLeg serial-parallel leg (3-UU double-parallel thigh + 3-RRR crank-slider shank); joints
``q = (α, β, γ)`` (rad), hip frame with Z0 toward the foot, every assumption and departure from the printed
paper: ``docs/mechanisms/omnileg.md``."""

from ._chains import ShankResult, ThighClosure, chain_screws, shank_crank_slider, shank_frames, thigh_closure
from ._dynamics import (
    BODY_NAMES,
    FOOT_FORCE_CONVENTION,
    DynamicsResult,
    FootForceResult,
    body_poses,
    energy,
    foot_force_from_torques,
    gravity_torques,
    inverse_dynamics,
    mass_matrix,
    static_torques,
)
from ._joints import TREE_JOINTS, JointMotion, joint_motion
from ._kinematics import (
    IKResult,
    foot_acceleration,
    foot_velocity,
    forward_kinematics,
    hessian,
    inverse_kinematics,
    jacobian,
    passive_angles,
    thigh_direction,
    within_limits,
)
from ._multibody import to_multibody
from ._params import BodySet, OmniLeg, RigidBody, default_bodies
from ._rates import JointRatesResult, joint_rates
from ._trajectories import (
    GaitProfile,
    foot_trajectory_eq51,
    gait_eq53,
    joint_trajectory_eq52,
    start_point,
)
from ._workspace import (
    FootWorkspace,
    SymmetryResult,
    WorkspaceMap,
    foot_workspace,
    joint_grid,
    singular_surface,
    workspace_map,
    workspace_symmetry,
)

__all__ = [
    "BODY_NAMES",
    "FOOT_FORCE_CONVENTION",
    "TREE_JOINTS",
    "BodySet",
    "DynamicsResult",
    "FootForceResult",
    "FootWorkspace",
    "GaitProfile",
    "IKResult",
    "JointMotion",
    "JointRatesResult",
    "OmniLeg",
    "RigidBody",
    "ShankResult",
    "SymmetryResult",
    "ThighClosure",
    "WorkspaceMap",
    "body_poses",
    "chain_screws",
    "default_bodies",
    "energy",
    "foot_acceleration",
    "foot_force_from_torques",
    "foot_trajectory_eq51",
    "foot_velocity",
    "foot_workspace",
    "forward_kinematics",
    "gait_eq53",
    "gravity_torques",
    "hessian",
    "inverse_dynamics",
    "inverse_kinematics",
    "jacobian",
    "joint_grid",
    "joint_motion",
    "joint_rates",
    "joint_trajectory_eq52",
    "mass_matrix",
    "passive_angles",
    "shank_crank_slider",
    "shank_frames",
    "singular_surface",
    "start_point",
    "static_torques",
    "thigh_closure",
    "thigh_direction",
    "to_multibody",
    "within_limits",
    "workspace_map",
    "workspace_symmetry",
]
