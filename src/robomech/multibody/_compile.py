"""The compile step: a frozen description (``Mechanism``) -> its compiled model, built once.

As MuJoCo compiles an ``MjSpec`` into an ``MjModel`` and Pinocchio builds a ``Model``, the description
stays a plain frozen value and every numerical array the algorithms run on is built here, by
:func:`compile_model` alone: the spanning tree (``_tree.Tree``), the closure rows
(``_constraints.Constraints``), the bodies' inertias, the actuated and passive coordinates, the
reference rank (passive rank, mobility and rank of the constraint Jacobian at the reference
configuration) and the packed tables the compiled kernels read (:class:`Tables`, :class:`DynTables`).
Nothing is written into the description: the compiled model is kept in a module-level table keyed by
the description's identity (released with it), and :attr:`Model.cache` holds what other modules
derive from it.

The step runs in this order: the tree (its characteristic length, when the description gives none,
from the body poses at ``qpos0``), the closure rows, the packed :class:`Tables`, then the reference
assembly and the reference rank, both on the compiled kernels of ``_compiled`` run on those tables (the
model does not exist yet): the tree kinematics, closure residual and ``K`` have one implementation, the
kernels'.

Import order inside the layer (no circle): ``_options`` and ``_model`` (the description) ->
``_tree``, ``_constraints`` (the tree and closure rows compiled to arrays) -> ``_compile`` ->
``_compiled`` (kernels) -> ``_designs`` (design-batched drivers), ``_assembly``, ``_influence`` ->
analysis and dynamics modules.  ``_compile`` calls ``_compiled`` and ``_reference`` inside its
functions only (they import ``_compile`` at module level).
"""

from __future__ import annotations

import threading
import weakref
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from robomech.spatial import hat

from . import _options as opt
from ._constraints import Constraints, compile_constraints
from ._tree import Tree, compile_tree, quat_to_matrix

if TYPE_CHECKING:  # the description; imported for the annotations only
    from ._model import Mechanism

__all__ = [
    "DynTables",
    "Model",
    "RneaTables",
    "Tables",
    "build_tree",
    "compile_model",
    "instantaneous_mobility",
]


class Tables(NamedTuple):
    """The tree and closure rows packed for the compiled kernels (numba types it as a named tuple)."""

    parent: NDArray[np.int64]
    T_off: NDArray[np.float64]
    j0: NDArray[np.int64]  # (nb + 1,) joints of body b are j0[b]:j0[b + 1]
    jtype: NDArray[np.int64]
    jqadr: NDArray[np.int64]
    jdadr: NDArray[np.int64]
    jpos: NDArray[np.float64]
    jaxis: NDArray[np.float64]
    jref: NDArray[np.float64]
    A: NDArray[np.float64]  # (nb, nv) coordinate k moves body b
    C: NDArray[np.float64]  # (nv, nv) coordinate j moves the carrier frame of coordinate k
    dof_tr: NDArray[np.bool_]
    # closure rows
    pp: NDArray[np.int64]  # (np, 3) int: b1, b2, first row
    px: NDArray[np.float64]  # (np, 2, 3) local points
    rr: NDArray[np.int64]  # (nr, 3) int: b1, b2, first row
    rR: NDArray[np.float64]  # (nr, 3, 3)
    cc: NDArray[np.int64]  # (nc, 5) int: d1, q1, d2, q2, row
    cf: NDArray[np.float64]  # (nc, 8) float: ref1, ref2, c0..c4, scale
    geom_row: NDArray[np.bool_]  # (m,) bool
    m: int
    L: float


class DynTables(NamedTuple):
    """What the inverse-dynamics kernel needs beyond :class:`Tables`."""

    bidx: NDArray[np.int64]  # (B,) bodies with mass or inertia
    mass: NDArray[np.float64]  # (B,)
    com: NDArray[np.float64]  # (B, 3) body frame
    inertia: NDArray[np.float64]  # (B, 3, 3) about the com, body axes
    act: NDArray[np.int64]  # (na,) actuated velocity coordinates
    pas: NDArray[np.int64]  # (npas,) the others
    rank0: int  # generic rank of K_p
    dof: int  # mobility
    gram_cond_max: float
    gram_refine_cond: float
    gram_refine2_cond: float
    pinv_rtol: float
    rank_rtol: float
    singular_cond: float
    admissible_rtol: float
    rate_floor: float


class RneaTables(NamedTuple):
    """The tree and the massive bodies only, for the tree-dynamics kernel (fewer arrays to pass: a
    kernel call spends ~0.2 us per array unboxing its arguments)."""

    parent: NDArray[np.int64]
    T_off: NDArray[np.float64]
    j0: NDArray[np.int64]
    jtype: NDArray[np.int64]
    jqadr: NDArray[np.int64]
    jdadr: NDArray[np.int64]
    jpos: NDArray[np.float64]
    jaxis: NDArray[np.float64]
    jref: NDArray[np.float64]
    nv: int
    bidx: NDArray[np.int64]
    mass: NDArray[np.float64]
    com: NDArray[np.float64]
    inertia: NDArray[np.float64]
    dof_body: NDArray[np.int64]  # (nv,) the body each coordinate moves directly
    A: NDArray[np.float64]  # (nb, nv) coordinate k moves body b (the mass matrix's sparsity)


@dataclass(frozen=True, eq=False)
class Bodies:
    """The bodies with mass or inertia (tree indices ``idx``), body frame."""

    idx: np.ndarray  # (B,)
    mass: np.ndarray  # (B,) kg
    com: np.ndarray  # (B, 3) m
    inertia: np.ndarray  # (B, 3, 3) about the com, body axes (kg m^2)


@dataclass(frozen=True, eq=False)
class Model:
    """A compiled mechanism: everything the algorithms need, built once by :func:`compile_model`."""

    tree: Tree
    constraints: Constraints
    tables: Tables
    bodies: Bodies
    act: np.ndarray  # (na,) actuated velocity coordinates
    pas: np.ndarray  # (nv - na,) passive ones
    rank0: int  # rank of the passive block K_p at the reference configuration (idle motions excluded)
    dof: int  # degrees of freedom (idle motions excluded)
    idle_dof: int
    rank_K: int  # generic rank of the full constraint Jacobian
    locked_dof: int  # admissible motions with every actuated joint locked (idle ones included)
    dyn: DynTables
    q_ref: np.ndarray  # (nq,) the assembled reference configuration (mech.q0), _reference
    rnea: RneaTables
    # what other modules derive from the compiled model (their own keys); never the description
    cache: dict[Any, Any] = field(default_factory=dict)


# ----------------------------------------------------------------------------- the reference rank
def _rank(X: np.ndarray, scale: float | None = None) -> int:
    """Numerical rank; ``scale`` the size of a non-zero entry (default the largest singular value)."""
    if X.size == 0:
        return 0
    s = np.linalg.svd(X, compute_uv=False)
    ref = s[0] if scale is None else scale
    return int(np.sum(s > opt.MOBILITY_RTOL * max(ref, 1e-300))) if s.size else 0


def _null(X: np.ndarray, n: int) -> np.ndarray:
    if X.shape[0] == 0:
        return np.eye(n)
    _, s, Vt = np.linalg.svd(X)
    r = int(np.sum(s > opt.MOBILITY_RTOL * max(s[0] if s.size else 0.0, 1e-300)))
    return Vt[r:].T


def _output_bodies(tree: Tree) -> list[int]:
    if len(tree.site_names):
        return sorted(set(int(b) for b in tree.site_body))
    return list(range(1, len(tree.body_names)))


def _watched_points(
    tree: Tree, tables: Tables, bodies: Bodies, T: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The points an idle motion must leave still, at body poses ``T (nb, 4, 4)``: the body each moves
    with ``(n,)`` and its world position ``(n, 3)``.

    Every tree joint's anchor, as a point of the joint's body and of its parent (where the body attaches;
    they differ for slides), both anchors of every point closure (``connect``; a revolute closure's two
    point pairs, a weld's anchor), and the centre of mass of every body with mass.  The sites move with
    the output bodies, whose whole twists are watched (:func:`_output_bodies`).
    """
    jb = tree.jnt_body.astype(np.int64)
    heavy = bodies.mass > 0
    # (body the point moves with, body whose frame gives it, its position in that frame)
    on = np.concatenate([jb, tree.parent[jb], tables.pp[:, 0], tables.pp[:, 1], bodies.idx[heavy]])
    frame = np.concatenate([jb, jb, tables.pp[:, 0], tables.pp[:, 1], bodies.idx[heavy]])
    x = np.concatenate([tree.jnt_pos, tree.jnt_pos, tables.px[:, 0], tables.px[:, 1], bodies.com[heavy]])
    keep = on > 0  # a point of the world never moves
    on, frame, x = on[keep].astype(np.int64), frame[keep], x[keep]
    return on, np.einsum("nij,nj->ni", T[frame, :3, :3], x) + T[frame, :3, 3]


@dataclass(frozen=True, eq=False)
class Instantaneous:
    """The instantaneous mobility at one configuration (unit-scaled constraint Jacobian)."""

    K: np.ndarray  # (m, nv) scaled: translational columns times L
    kmax: float  # its largest singular value
    rank: int
    N: np.ndarray  # (nv, total_dof) orthonormal basis of the admissible motions (scaled coordinates)
    locked: np.ndarray  # admissible motions with every actuated joint locked
    idle: int  # locked motions that move no output body and none of the watched points
    T: np.ndarray  # (nb, 4, 4) the bodies' world poses at q
    S: np.ndarray  # (nv, 6) the coordinates' space screws at q


def instantaneous_mobility(
    tree: Tree, tables: Tables | Model, q: np.ndarray, bodies: Bodies
) -> Instantaneous:
    """Rank of the unit-scaled ``K`` at ``q (1, nq)``, admissible and locked motions, idle count
    (poses, screws and ``K`` from the compiled kernels on ``tables``, or on a compiled model's).

    A locked motion (every actuated joint still) is idle when it moves no output body
    (:func:`_output_bodies`: the twists of the bodies that carry sites, every body without sites),
    rotates no body held in orientation by a closure (a weld's two bodies), and moves none of the points
    of :func:`_watched_points` (joint anchors, closure points, centres of mass of bodies with mass): an
    S-S rod spinning about the line through its two ball centres, with its centre of mass on that line.
    ``bodies``: the mass tables (:class:`Bodies`) of the description."""
    from ._compiled import compiled_kinematics, compiled_resjac, space_jacobians

    tb = tables.tables if isinstance(tables, Model) else tables
    T, S = compiled_kinematics(tables, q)
    col = np.where(tree.dof_translational, tree.length, 1.0)
    K = compiled_resjac(tables, q, True)[1][0] * col
    nv = K.shape[1]
    kmax = float(np.max(np.linalg.svd(K, compute_uv=False))) if K.size else 1.0
    rank = _rank(K, kmax)
    N = _null(K, nv)
    na = len(tree.act_dof)
    locked = N @ _null(N[tree.act_dof], N.shape[1]) if na else N
    if not locked.shape[1]:
        return Instantaneous(K=K, kmax=kmax, rank=rank, N=N, locked=locked, idle=0, T=T[0], S=S[0])
    # every body's twist per scaled coordinate (nb, 6, nv), [ω; v] with v at the world origin
    J = space_jacobians(tree.A, S, range(len(tree.body_names)))[0] / col
    # whole twists of the output bodies and of the welded ones, angular rows times L: rows of order L,
    # so a motion that moves one has |J v| ~ L|v|
    whole = sorted(set(_output_bodies(tree)) | {int(b) for r in tb.rr for b in r[:2] if b > 0})
    Jw = J[whole] * np.array([tree.length] * 3 + [1.0] * 3)[:, None]
    # the watched points of the other bodies (m per scaled coordinate, of order L as well)
    on, P = _watched_points(tree, tb, bodies, T[0])
    free = ~np.isin(on, whole)  # a point of a body whose whole twist is watched adds nothing
    on, P = on[free], P[free]
    Jp = J[on, 3:] - hat(P) @ J[on, :3]  # v + ω × p = v - [p]× ω
    moved = np.concatenate([Jw.reshape(-1, nv), Jp.reshape(-1, nv)])
    idle = locked.shape[1] - _rank(moved @ locked, tree.length)
    return Instantaneous(K=K, kmax=kmax, rank=rank, N=N, locked=locked, idle=int(idle), T=T[0], S=S[0])


# ----------------------------------------------------------------------------- packing
def _bodies(mech: Mechanism) -> Bodies:
    idx, m, c, inn = [], [], [], []
    for i, b in enumerate(mech.bodies, start=1):
        if b.inertial is None:
            continue
        it = b.inertial
        if it.mass == 0 and max(it.diaginertia) == 0:
            continue
        Ri = quat_to_matrix(np.asarray(it.quat))
        idx.append(i)
        m.append(it.mass)
        c.append(it.pos)
        inn.append(Ri @ np.diag(it.diaginertia) @ Ri.T)
    return Bodies(
        np.array(idx, dtype=int),
        np.array(m, float),
        np.array(c, float).reshape(-1, 3),
        np.array(inn, float).reshape(-1, 3, 3),
    )


def _tables(tree: Tree, cs: Constraints) -> Tables:
    nb = len(tree.body_names)
    j0 = np.zeros(nb + 1, dtype=np.int64)
    for b in range(nb):
        j0[b + 1] = j0[b] + len(tree.body_jnts[b])
    pp, px, rr, rR, cc, cf = [], [], [], [], [], []
    row = 0
    for k, d in cs.blocks:
        if k == "point":
            b1, x1, b2, x2 = d
            pp.append((b1, b2, row))
            px.append((x1[:3], x2[:3]))
            row += 3
        elif k == "rot":
            b1, R, b2 = d
            rr.append((b1, b2, row))
            rR.append(R)
            row += 3
        else:
            d1, q1, ref1, d2, q2, ref2, c, s = d
            cc.append((d1, q1, d2, q2, row))
            cf.append((ref1, ref2, *c, s))
            row += 1
    return Tables(
        parent=tree.parent.astype(np.int64),
        T_off=np.ascontiguousarray(tree.T_off),
        j0=j0,
        jtype=tree.jnt_type.astype(np.int64),
        jqadr=tree.jnt_qadr.astype(np.int64),
        jdadr=tree.jnt_dadr.astype(np.int64),
        jpos=np.ascontiguousarray(tree.jnt_pos),
        jaxis=np.ascontiguousarray(tree.jnt_axis),
        jref=tree.jnt_ref.astype(float),
        A=np.ascontiguousarray(tree.A),
        C=np.ascontiguousarray(tree.C),
        dof_tr=tree.dof_translational.astype(np.bool_),
        pp=np.array(pp, dtype=np.int64).reshape(-1, 3),
        px=np.array(px, dtype=float).reshape(-1, 2, 3),
        rr=np.array(rr, dtype=np.int64).reshape(-1, 3),
        rR=np.array(rR, dtype=float).reshape(-1, 3, 3),
        cc=np.array(cc, dtype=np.int64).reshape(-1, 5),
        cf=np.array(cf, dtype=float).reshape(-1, 8),
        geom_row=np.array([k != "coupling" for k in cs.row_kind], dtype=np.bool_),
        m=cs.m,
        L=float(tree.length),
    )


_NO_ROWS = Constraints(blocks=(), m=0, row_owner=(), row_kind=())


def _default_length(tree: Tree) -> float:
    """RMS distance of the body origins, joint anchors and sites from their centroid at q0 (m).

    This is the length that makes a rotation (rad) and a translation (m) commensurate in residuals
    and conditioning; 1 m if the mechanism has no extent (a single point).
    """
    from ._compiled import compiled_body_poses  # lazily: _compiled -> _compile

    T = compiled_body_poses(_tables(tree, _NO_ROWS), tree.q0[None])[0]
    pts = [T[1:, :3, 3]]
    for k in range(len(tree.jnt_names)):
        Tb = T[tree.jnt_body[k]]
        pts.append((Tb[:3, :3] @ tree.jnt_pos[k] + Tb[:3, 3])[None])
    for s in range(len(tree.site_names)):
        pts.append((T[tree.site_body[s]] @ tree.T_site[s])[None, :3, 3])
    P = np.concatenate(pts)
    L = float(np.sqrt(np.mean(np.sum((P - P.mean(axis=0)) ** 2, axis=1)))) if len(P) > 1 else 0.0
    return L if L > 1e-9 else 1.0


def build_tree(mech: Mechanism) -> Tree:
    """The compiled tree of ``mech``, its characteristic length the description's or, when it gives
    none, :func:`_default_length`."""
    return compile_tree(mech, _default_length)


def _compile(mech: Mechanism, tree: Tree | None = None) -> Model:
    tree = build_tree(mech) if tree is None else tree
    cs = compile_constraints(mech, tree)
    tables = _tables(tree, cs)  # first: the reference assembly and rank below run on the kernels
    act = tree.act_dof.astype(np.int64)
    pas = np.setdiff1d(np.arange(tree.nv), act).astype(np.int64)
    from ._reference import assembled_reference  # lazily: _reference -> _assembly -> _compile

    # the reference configuration: qpos0, or the assembly nearest to it for a description typed
    # unassembled (a ValueError with the residual if none); the reference rank is taken there
    q_ref = assembled_reference(mech, tree, cs, tables)
    bodies = _bodies(mech)
    inst = instantaneous_mobility(tree, tables, q_ref[None], bodies)
    total = tree.nv - inst.rank
    dof = total - inst.idle
    # the passive block has full column rank but for the idle motions (computed at the reference, not
    # taken from the rank of K_p there, which may itself be singular); K's generic rank leaves the DOF
    # and the idle motions free
    rank0 = len(pas) - inst.idle
    rank_K = tree.nv - dof - inst.idle
    dyn = DynTables(
        bidx=bodies.idx.astype(np.int64),
        mass=np.ascontiguousarray(bodies.mass, dtype=float),
        com=np.ascontiguousarray(bodies.com, dtype=float),
        inertia=np.ascontiguousarray(bodies.inertia, dtype=float),
        act=act,
        pas=pas,
        rank0=int(rank0),
        dof=int(dof),
        gram_cond_max=float(opt.GRAM_COND_MAX),
        gram_refine_cond=float(opt.GRAM_REFINE_COND),
        gram_refine2_cond=float(opt.GRAM_REFINE2_COND),
        pinv_rtol=float(opt.PASSIVE_RANK_RTOL),
        rank_rtol=float(opt.RANK_RTOL),
        singular_cond=float(opt.SINGULAR_COND),
        admissible_rtol=float(opt.ADMISSIBLE_RTOL),
        rate_floor=float(opt.RATE_FLOOR),
    )
    rnea = RneaTables(
        parent=tables.parent,
        T_off=tables.T_off,
        j0=tables.j0,
        jtype=tables.jtype,
        jqadr=tables.jqadr,
        jdadr=tables.jdadr,
        jpos=tables.jpos,
        jaxis=tables.jaxis,
        jref=tables.jref,
        nv=int(tree.nv),
        bidx=dyn.bidx,
        mass=dyn.mass,
        com=dyn.com,
        inertia=dyn.inertia,
        dof_body=tree.dof_body.astype(np.int64),
        A=tables.A,
    )
    return Model(
        tree=tree,
        constraints=cs,
        tables=tables,
        bodies=bodies,
        act=act,
        pas=pas,
        rank0=int(rank0),
        dof=int(dof),
        idle_dof=int(inst.idle),
        rank_K=int(rank_K),
        locked_dof=int(inst.locked.shape[1]),
        dyn=dyn,
        q_ref=q_ref,
        rnea=rnea,
    )


# id(description) -> (weak reference to it, its model); the entry is dropped when the description is
# collected.  Keyed by identity, not by value: a lookup costs a dict access, not a hash of the whole
# description (which is what a batch-1 call would otherwise pay).
_MODELS: dict[int, tuple[weakref.ref, Model]] = {}
_LOCK = threading.Lock()


def _drop(key: int) -> None:
    _MODELS.pop(key, None)


def compile_model(mech: Mechanism, *, _tree: Tree | None = None) -> Model:
    """The compiled model of ``mech`` (built on first use, then returned from the table).  ``_tree``:
    its already compiled tree (:func:`build_tree` of a description with the same bodies, sites, actuation
    and characteristic length: the tree depends on nothing else), which the first use then reuses."""
    hit = _MODELS.get(id(mech))
    if hit is not None and hit[0]() is mech:
        return hit[1]
    with _LOCK:
        hit = _MODELS.get(id(mech))
        if hit is not None and hit[0]() is mech:
            return hit[1]
        model = _compile(mech, _tree)
        key = id(mech)
        def _release(_ref: object, key: int = key) -> None:
            _drop(key)

        _MODELS[key] = (weakref.ref(mech, _release), model)
        return model
