"""Mobility of a described mechanism from its constraint Jacobian, with screw theory where it fits.

At an assembled ``q`` the admissible velocities are ``null(K)`` (``K (m, nv)`` the velocity constraint
matrix).  With all rotation rows and translational columns scaled to metres by the characteristic
length ``L`` (so that ranks are unit-consistent):

* ``total_dof = nv - rank K``: every instantaneous motion, idle ones included;
* ``idle_dof``: motions with every actuated joint locked that move nothing that matters: no output
  body (the whole twists of the bodies that carry sites; all bodies if there is none), no body a weld
  holds in orientation, and none of the points that connect or carry mass (every tree joint's anchor,
  as a point of its body and of its parent; both anchors of every point closure; the centre of mass of
  every body with mass) — e.g. a massless S–S link, or one with its centre of mass on its axis,
  spinning about the line through its two ball centres.  Those points are fixed in their bodies, so
  the count does not hinge on the outputs' twists: a passive chain hanging straight, where its tip
  loses a rank, or a chain of more links than its tip has twist directions, counts a DOF per link;
* ``dof = total_dof - idle_dof``: the mechanism's degrees of freedom (the Delta's 3, Bennett's 1);
* ``gruebler_kutzbach = nv - sum c_i`` (the spatial count ``6(n - 1) - sum (6 - f)`` for the tree plus
  a cut joint of ``c`` equations per closure: 3 point, 5 revolute (or two point closures between the
  same two bodies), 6 rigid, 1 coupling);
* ``redundant_constraints = sum c_i - rank K``, so that ``total_dof = gruebler_kutzbach +
  redundant_constraints`` (a planar four-bar cut by a hinge: -2 + 3 = 1; Bennett's linkage the same);
* ``singular``: the rank of K is not locally constant — it differs at configurations assembled a
  small step away along the admissible motions.

For a platform carried by serial legs (every closure joins the platform to a leg), the same
configuration is also passed to :func:`robomech.analysis.mobility.analyze` (reciprocal screws),
which gives the platform's twist system, common and redundant constraints and the modified
Grübler–Kutzbach count; ``platform_dof`` from the constraint Jacobian must agree with it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from robomech.analysis import mobility as screw_mobility

from ._assembly import check_mechanism, check_q
from ._compile import _rank, compile_model, instantaneous_mobility
from ._model import Mechanism
from ._options import MOBILITY_RTOL, NEIGHBOUR_STEP

# The rank is checked at neighbours along at most this many admissible directions (both signs): a
# rank that is not locally constant drops on a set of measure zero, so generic (random orthonormal)
# combinations of the directions see it as the directions themselves do; a chain of 1000 hinges
# then costs 2 x 6 neighbour solves, not 2 x 1000.
NEIGHBOUR_DIRECTIONS = 6

__all__ = ["MOBILITY_RTOL", "NEIGHBOUR_STEP", "MobilityReport", "mobility"]

_C = {"point": 3, "revolute": 5, "rigid": 6}


@dataclass(frozen=True)
class MobilityReport:
    """Mobility of a mechanism at one configuration: the result of :func:`mobility`.

    Attributes
    ----------
    dof : int
        Degrees of freedom: ``total_dof - idle_dof``, the admissible motions without the idle ones.
    total_dof : int
        ``nv - rank``: every instantaneous admissible motion, idle motions included.
    idle_dof : int
        Motions with every actuated joint locked that move no output, turn no welded body and move no
        joint anchor, closure point or centre of mass (an S–S leg spinning about its axis).
    locked_dof : int
        Motions left with every actuated joint locked (idle plus uncontrolled).
    redundant_constraints : int
        ``n_equations - rank``: dependent closure equations (a planar loop in space has 3).
    n_equations : int
        Sum of the cut joints' constraint counts (point 3, revolute 5, rigid 6, coupling 1).
    rank : int
        Rank of the (unit-scaled) constraint Jacobian K.
    gruebler_kutzbach : int
        The spatial count ``nv - n_equations``.
    singular : bool
        The rank of K changes within ``NEIGHBOUR_STEP`` along some admissible direction.
    rank_nearby : tuple of int
        The ranks of K at those neighbouring, re-assembled configurations.
    n_actuated : int
        Number of actuated joints.
    actuation : str
        ``"exact"`` (n_act = dof), ``"redundant"`` (n_act > dof) or ``"under"`` (n_act < dof).
    platform : str or None
        The body whose twist system is analysed (default the body of the first site).
    platform_dof : int or None
        Rank of the platform twists over the admissible motions.
    platform_rotational_dof : int or None
        Rank of their angular parts.
    platform_twists : ndarray, shape (platform_dof, 6), or None
        Orthonormal basis of the platform twists, rows ``[ω; v / L]``.
    screw_theory : MobilityResult or None
        :func:`robomech.analysis.mobility.analyze` on the platform's serial legs, if it has them.
    length : float
        The characteristic length L (m).
    """

    dof: int
    total_dof: int
    idle_dof: int
    locked_dof: int  # motions left with every actuated joint locked (idle + uncontrolled)
    redundant_constraints: int
    n_equations: int  # sum of the cut joints' constraint counts c_i
    rank: int  # rank of the constraint Jacobian
    gruebler_kutzbach: int
    singular: bool
    rank_nearby: tuple[int, ...]
    n_actuated: int
    actuation: str  # "exact", "redundant" (n_act > dof) or "under" (n_act < dof)
    platform: str | None
    platform_dof: int | None  # rank of the platform twists over the admissible motions
    platform_rotational_dof: int | None
    platform_twists: np.ndarray | None  # (platform_dof, 6) orthonormal basis (angular, linear/L)
    screw_theory: screw_mobility.MobilityResult | None  # analysis.mobility on the serial legs, if it fits
    length: float

    def summary(self) -> str:
        """One line: DOF, idle motions, closure equations, rank, redundancy, actuation, platform."""
        s = (
            f"DOF {self.dof} (+{self.idle_dof} idle); {self.n_equations} closure equations, "
            f"rank {self.rank}, "
            f"{self.redundant_constraints} redundant; Gruebler-Kutzbach {self.gruebler_kutzbach}; "
            f"{self.n_actuated} actuated ({self.actuation}){'; SINGULAR' if self.singular else ''}"
        )
        if self.platform is not None:
            s += f"; platform {self.platform}: {self.platform_dof} DOF ({self.platform_rotational_dof}R)"
        return s


def _scaled_K(mech: Mechanism, q: np.ndarray) -> np.ndarray:
    """``K (N, m, nv)`` at ``q (N, nq)`` (the compiled kernel), translational columns times L."""
    from ._compiled import compiled_resjac  # numba loads on the first kernel call, not at import

    tree = mech.tree
    K = compiled_resjac(compile_model(mech), q, True)[1]
    col = np.where(tree.dof_translational, tree.length, 1.0)
    return K * col


def _serial_legs(mech: Mechanism, T: np.ndarray, S: np.ndarray, platform: int) -> list[np.ndarray] | None:
    """Joint screws (world, at q: body poses ``T (nb, 4, 4)``, coordinate screws ``S (nv, 6)``) of each
    serial leg to ``platform``; None if not of that form."""
    tree = mech.tree
    if mech.couplings:
        return None
    chains = [S[tree.A[platform] > 0]]
    used = tree.A[platform].copy()
    for c in mech.closures:
        b1, b2 = tree.body_index(c.body1), tree.body_index(c.body2)
        if platform not in (b1, b2):
            return None
        other, anchor = (b2, c.anchor2) if b1 == platform else (b1, c.anchor1)
        if (
            tree.A[other] * used
        ).any():  # shares joints with another leg: not serial legs (e.g. a parallelogram)
            return None
        used = np.maximum(used, tree.A[other])
        Tb = T[other]
        p = Tb[:3, :3] @ np.asarray(anchor) + Tb[:3, 3]
        leg = list(S[tree.A[other] > 0])
        if c.kind == "point":
            leg += [np.concatenate([e, np.cross(p, e)]) for e in np.eye(3)]
        elif c.kind == "revolute":
            a = Tb[:3, :3] @ np.asarray(c.axis2 if b1 == platform else c.axis)
            leg.append(np.concatenate([a, np.cross(p, a)]))
        if not leg:
            return None
        chains.append(np.array(leg))
    return chains


def _cut_constraints(mech: Mechanism) -> int:
    """Constraints of the cut joints: point 3, revolute 5, rigid 6, coupling 1.

    Two point closures between the same two bodies are one hinge cut (how MJCF writes a revolute
    closure: their six equations always have one dependence), 5; three or more are a rigid cut, 6.
    """
    pairs: dict[frozenset, int] = {}
    n = len(mech.couplings)
    for c in mech.closures:
        if c.kind == "point":
            key = frozenset((c.body1, c.body2))
            pairs[key] = pairs.get(key, 0) + 1
        else:
            n += _C[c.kind]
    return n + sum({1: 3, 2: 5}.get(k, 6) for k in pairs.values())


def mobility(mech: Mechanism, q: ArrayLike | None = None, *, platform: str | None = None) -> MobilityReport:
    """Mobility at one assembled configuration ``q (nq,)`` (default the reference configuration).

    ``platform`` (a body name; default the body of the first site not on the world, if any) adds the
    platform's twist system, and the screw-theory analysis of :mod:`robomech.analysis.mobility` when the
    platform is carried by serial legs.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (nq,), optional
        An assembled configuration (default ``mech.q0``).
    platform : str, optional
        A body name whose twist system is analysed.

    Returns
    -------
    MobilityReport
        ``dof`` (without idle motions), ``redundant_constraints``, ``gruebler_kutzbach``, ``singular``,
        the actuation and the platform's twists; ``summary()`` gives one line.

    Examples
    --------
    >>> from robomech import multibody as mb
    >>> m = mb.mobility(mb.gallery.load("four_bar"))
    >>> m.dof, m.gruebler_kutzbach, m.redundant_constraints      # planar: 1 DOF, spatial count 0
    (1, 0, 1)
    """
    mech = check_mechanism(mech)
    tree = mech.tree
    if platform is not None and (not isinstance(platform, str) or platform not in tree.body_names[1:]):
        raise ValueError(
            f"Expected platform to be None or a body name among {list(tree.body_names[1:])}, "
            f"got {platform!r}."
        )
    q = mech.q0 if q is None else check_q(mech, q)  # the assembled reference
    if q.ndim != 1:
        raise ValueError(f"Expected q to have shape ({mech.nq},) (one configuration), got {q.shape}.")
    q = q[None]
    model = compile_model(mech)
    inst = instantaneous_mobility(tree, model, q, model.bodies)
    K, kmax, rank, N = inst.K, inst.kmax, inst.rank, inst.N
    locked, idle = inst.locked, inst.idle
    nv = K.shape[1]
    total = nv - rank
    col = np.where(tree.dof_translational, tree.length, 1.0)
    na = len(tree.act_dof)
    dof = total - idle
    n_c = _cut_constraints(mech)
    gk = nv - n_c
    # locally constant rank: re-assemble a small step along each admissible direction
    nearby = []
    if N.shape[1]:
        D = N
        if N.shape[1] > NEIGHBOUR_DIRECTIONS:  # a long chain: generic combinations of the directions
            rng = np.random.default_rng(0)  # fixed: the report is deterministic
            D = N @ np.linalg.qr(rng.standard_normal((N.shape[1], NEIGHBOUR_DIRECTIONS)))[0]
        steps = np.concatenate([D.T, -D.T]) * NEIGHBOUR_STEP / col  # back to unscaled coordinates
        from ._compiled import compiled_fk, compiled_integrate  # numba loads on the first kernel call

        qn = compiled_integrate(model, np.repeat(q, steps.shape[0], axis=0), steps)
        qn, _rc, _, _ = compiled_fk(mech, qn, np.arange(nv))
        Kn = _scaled_K(mech, qn)  # one batched evaluation for every neighbour
        nearby = [_rank(Kn[k], kmax) for k in range(Kn.shape[0])]
    singular = any(r != rank for r in nearby)
    moving_sites = [int(b) for b in tree.site_body if b != 0]  # a site on the world is no platform
    if platform is None and moving_sites:
        platform = tree.body_names[moving_sites[0]]
    p_dof = p_rot = p_tw = sm = None
    if platform is not None:
        pb = tree.body_index(platform)
        from ._compiled import space_jacobians

        Jp = space_jacobians(tree.A, inst.S[None], [pb])[0, 0] / col
        Tw = Jp @ N
        Tw[3:] /= tree.length
        U, s, _ = np.linalg.svd(Tw) if Tw.size else (np.zeros((6, 0)), np.zeros(0), None)
        p_dof = int(np.sum(s > MOBILITY_RTOL))  # N orthonormal, Tw entries O(1)
        p_tw = U[:, :p_dof].T
        p_rot = _rank(p_tw[:, :3], 1.0) if p_dof else 0
        legs = _serial_legs(mech, inst.T, inst.S, pb)
        if legs is not None and all(len(c) for c in legs):  # a platform welded to the world has no legs
            # analysis.mobility divides moments by length_scale and wants unit screws after that:
            # prismatic screws [0; d] are passed as [0; L d]
            legs = [
                np.where(np.linalg.norm(c[:, :3], axis=1, keepdims=True) < 1e-12, tree.length * c, c)
                for c in legs
            ]
            sm = screw_mobility.analyze(legs, length_scale=tree.length)
    act = "exact" if na == dof else ("redundant" if na > dof else "under")
    return MobilityReport(
        dof=dof,
        total_dof=total,
        idle_dof=idle,
        locked_dof=int(locked.shape[1]),
        redundant_constraints=n_c - rank,
        n_equations=n_c,
        rank=rank,
        gruebler_kutzbach=gk,
        singular=singular,
        rank_nearby=tuple(nearby),
        n_actuated=na,
        actuation=act,
        platform=platform,
        platform_dof=p_dof,
        platform_rotational_dof=p_rot,
        platform_twists=p_tw,
        screw_theory=sm,
        length=tree.length,
    )
