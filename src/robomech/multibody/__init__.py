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

Coordinates: ``q`` is MuJoCo's ``qpos`` (nq; ``[w, x, y, z]`` quaternions for ball/free joints) and
every matrix "over all coordinates" has one column per *velocity* coordinate (MuJoCo's ``qvel``, nv:
local angular velocity for ball joints).  ``q_act`` are the actuated joints' ``qpos`` entries in
actuator order.

Internals for the dynamics layer (issue 13).  All take flat batches and return world-frame
quantities; ``mech.tree`` (``_tree.Tree``) and ``mech.constraints`` (``_constraints.Constraints``)
are the compiled arrays, cached on the frozen mechanism:

* body poses: ``_tree.kinematics(tree, q (N, nq)) -> TreeState`` with ``.T (N, nb, 4, 4)`` every body's
  world pose (index 0 the world; ``tree.body_names``) and ``.S (N, nv, 6)`` every velocity
  coordinate's space screw ``[ω; v]``; ``_tree.body_poses`` for poses only;
* body twists / Jacobians: ``_tree.space_jacobian(tree, state, b) (N, 6, nv)`` (space twist of body b,
  ``V_b = J qd``), ``_tree.frame_jacobian(tree, state, b, p) (N, 6, nv)`` (``[ω; ṗ]`` of a world point
  ``p (N, 3)`` fixed in b), ``_tree.body_twists(tree, state, qd)``; their time derivatives along ``qd``:
  ``Sd = _tree.screw_rates(tree, state, qd)`` (``dS/dt``) and
  ``_tree.frame_jacobian_rate(tree, state, Sd, b, p, qd)``;  ``tree.A (nb, nv)`` the ancestor mask;
* constraint Jacobian and its derivative: ``_constraints.residual / jacobian / jacobian_rate``
  (``K (N, m, nv)``, ``dK/dt`` along ``qd``); public, batched over any shape:
  :func:`constraint_residual`, :func:`constraint_jacobian`, :func:`constraint_jacobian_rate`;
* ``G = ∂qd/∂qd_act (…, nv, n_act)`` and ``∂G/∂q_act``: :func:`influence` (``_influence._influence_flat``
  for flat batches, returning the state, K, G, dG and the screw rates together);
* dynamics (issue 13, ``_dynamics``): :func:`inverse_dynamics`, :func:`statics`, :func:`site_wrench`,
  :func:`forward_dynamics`, :func:`simulate`, :func:`energy` (docs/dynamics.md);
* ``_tree.integrate(tree, q, dv)``: ``q ⊕ dv`` on the configuration manifold (``mj_integratePos``).
"""

from __future__ import annotations

from . import gallery
from ._assembly import CONVERGED_RTOL, FKResult, IKResult, forward_kinematics, inverse_kinematics
from ._draw import body_segments, draw
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
from ._rnea import generalized_forces, mass_matrix
from ._singularity import SingularityMapResult, SingularityResult, singularities, singularity_map

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
    "SimulationResult",
    "SingularityMapResult",
    "SingularityResult",
    "Site",
    "SiteWrenchResult",
    "StaticsResult",
    "body_segments",
    "constraint_jacobian",
    "constraint_jacobian_rate",
    "constraint_residual",
    "draw",
    "energy",
    "forward_dynamics",
    "forward_kinematics",
    "from_mjcf",
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
]
