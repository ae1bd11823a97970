"""Model your own mechanism: a generic, batched closed-chain layer.

Describe a mechanism (MJCF through :func:`from_mjcf`, or the Python :class:`Builder`), then get its
exact, batched kinematics with nothing derived by hand::

    from robomech import multibody as mb
    mech = mb.from_mjcf("four_bar.xml")                  # or mb.Builder(...).build(); mb.to_mjcf(mech) -> str
    mech.actuated                                        # actuated joint names, in actuator order
    fk = mb.forward_kinematics(mech, q_act)              # .q (..., nq) MuJoCo qpos, .residual, .converged
    ik = mb.inverse_kinematics(mech, "tip", T_target)    # .q, .q_act, .residual, .converged
    T = mb.site_pose(mech, fk.q, "tip")                  # (..., 4, 4)
    J = mb.site_jacobian(mech, fk.q, "tip")              # (..., 6, n_act), rows [ω; ṗ] (mj_jacSite)
    H = mb.site_hessian(mech, fk.q, "tip")               # (..., 6, n_act, n_act), H[i, j, k] = ∂J_ij/∂q_act,k
    m = mb.mobility(mech)                                # .dof, .redundant_constraints, .gruebler_kutzbach
    s = mb.singularities(mech, fk.q, "tip")              # type I / II / constraint, measures in metres
    mb.draw(mech, fk.q[0])                               # matplotlib wireframe
    mb.animate(mech, fk.q, "motion.gif")                 # a GIF (or .mp4 with ffmpeg) along q (nt, nq)
    mb.view(mech)                                        # live 3-D in the browser (robomech.viewer)

Coordinates: ``q`` is MuJoCo's ``qpos`` (nq; ``[w, x, y, z]`` quaternions for ball/free joints) and
every matrix "over all coordinates" has one column per *velocity* coordinate (MuJoCo's ``qvel``, nv:
local angular velocity for ball joints).  ``q_act`` are the actuated joints' ``qpos`` entries in
actuator order.

Beyond kinematics, the same description gives:

* the loop-closure constraints, batched over any shape: :func:`constraint_residual`,
  :func:`constraint_jacobian` and its time derivative :func:`constraint_jacobian_rate`;
* the influence coefficients ``G = ∂qd/∂qd_act (..., nv, n_act)`` and ``∂G/∂q_act``: :func:`influence`;
* dynamics of the closed chain: :func:`inverse_dynamics`, :func:`statics`, :func:`site_wrench`,
  :func:`forward_dynamics`, :func:`simulate`, :func:`energy` (the dynamics page of the documentation);
  for open chains, trees, underactuated and passive mechanisms and floating bases the same functions,
  with every coordinate's rate ``qd (..., nv)`` where the actuated rates do not give the state;
* the spanning tree's :func:`generalized_forces` (RNEA, MuJoCo ``mj_rne``) and :func:`mass_matrix`
  (CRBA, ``mj_fullM``).
"""

from __future__ import annotations

from . import gallery
from ._animate import animate
from ._assembly import CONVERGED_RTOL, FKResult, IKResult, forward_kinematics, inverse_kinematics
from ._draw import body_segments, draw, view
from ._dynamics import (
    ForwardDynamicsResult,
    InverseDynamicsResult,
    SimulationResult,
    SiteWrenchResult,
    StaticsResult,
    energy,
    forward_dynamics,
    inverse_dynamics,
    simulate,
    site_wrench,
    statics,
)
from ._influence import (
    Influence,
    constraint_jacobian,
    constraint_jacobian_rate,
    constraint_residual,
    influence,
    site_hessian,
    site_jacobian,
    site_pose,
)
from ._mjcf import from_mjcf, to_mjcf
from ._mobility import MobilityReport, mobility
from ._model import Body, Builder, Closure, Coupling, Inertial, Joint, Mechanism, Site
from ._pinocchio import PinocchioModel, to_pinocchio
from ._repr import install_compact_repr
from ._rnea import generalized_forces, mass_matrix
from ._singularity import SingularityMapResult, SingularityResult, singularities, singularity_map
from ._urdf import from_urdf

# Results print their fields' shapes, masks as counts and ranges, not their arrays (notebooks).
install_compact_repr(
    FKResult,
    IKResult,
    Influence,
    MobilityReport,
    SingularityResult,
    SingularityMapResult,
    InverseDynamicsResult,
    StaticsResult,
    SiteWrenchResult,
    ForwardDynamicsResult,
    SimulationResult,
)

__all__ = [
    "CONVERGED_RTOL",
    "Body",
    "Builder",
    "Closure",
    "Coupling",
    "FKResult",
    "ForwardDynamicsResult",
    "IKResult",
    "Inertial",
    "Influence",
    "InverseDynamicsResult",
    "Joint",
    "Mechanism",
    "MobilityReport",
    "PinocchioModel",
    "SimulationResult",
    "SingularityMapResult",
    "SingularityResult",
    "Site",
    "SiteWrenchResult",
    "StaticsResult",
    "animate",
    "body_segments",
    "constraint_jacobian",
    "constraint_jacobian_rate",
    "constraint_residual",
    "draw",
    "energy",
    "forward_dynamics",
    "forward_kinematics",
    "from_mjcf",
    "from_urdf",
    "gallery",
    "generalized_forces",
    "influence",
    "inverse_dynamics",
    "inverse_kinematics",
    "mass_matrix",
    "mobility",
    "simulate",
    "singularities",
    "singularity_map",
    "site_hessian",
    "site_jacobian",
    "site_pose",
    "site_wrench",
    "statics",
    "to_mjcf",
    "to_pinocchio",
    "view",
]
