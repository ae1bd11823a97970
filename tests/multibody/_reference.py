"""The numpy formulation of the compiled kernels, kept here as the tests' reference.

The library runs one implementation per algorithm (the compiled kernels of
``robomech/multibody/_compiled.py``, at every batch size, the compile step's reference assembly and
rank included).  The same algorithms written batched in numpy on the compiled tree and closure rows
(``_tree.Tree``, ``_constraints.Constraints``): tree kinematics, body Jacobians, integration, the
closure residual, K and dK/dt, ... are the independent formulation the kernels are checked against:
:func:`numpy_reference` swaps them in for the kernels inside a ``with`` block.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from robomech.dynamics import _com_terms
from robomech.multibody import _compiled, _dynamics, _rnea, _rnea_kernels
from robomech.multibody import _dynamics as D
from robomech.multibody._compile import Tables
from robomech.multibody._constraints import Constraints
from robomech.multibody._model import Mechanism
from robomech.multibody._options import (
    ADMISSIBLE_RTOL,
    CONVERGED_RTOL,
    GRAM_COND_MAX,
    GRAM_REFINE2_COND,
    GRAM_REFINE_COND,
    MAX_ITER,
    MAX_STEP,
    MU_MAX,
    MU_MIN,
    MU_START,
    PASSIVE_RANK_RTOL,
    RANK_RTOL,
    RATE_FLOOR,
    SINGULAR_COND,
    STOP_RTOL,
)
from robomech.multibody._tree import Tree, normalize_quaternions, quat_mul, quat_to_matrix


# ----------------------------------------------------------------------------- tree kinematics
# The numpy formulation of _compiled.kin / kin_block (compiled_kinematics, compiled_body_poses),
# batched over samples with Python loops over bodies and joints.
@dataclass(frozen=True, eq=False)
class TreeState:
    """World poses ``T (N, nb, 4, 4)`` of all bodies and space screws ``S (N, nv, 6)`` of all coordinates."""

    T: np.ndarray
    S: np.ndarray


def _cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.cross`` of ``(N, 3)`` arrays, the same products and differences in the same order (so the
    same bits) without its axis handling."""
    out = np.empty(a.shape)
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def quat_exp(w: np.ndarray) -> np.ndarray:
    """Unit quaternion of the rotation vector ``w`` (..., 3)."""
    th = np.linalg.norm(w, axis=-1)
    half = 0.5 * th
    # sin(th/2)/th, with its series below 1e-4 rad (error < th^4/3840 ~ 1e-19)
    small = th < 1e-4
    k = np.where(small, 0.5 - th * th / 48.0, np.sin(half) / np.where(small, 1.0, th))
    return np.concatenate([np.cos(half)[..., None], k[..., None] * w], axis=-1)


def axis_angle_matrix(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotation (..., 3, 3) by ``angle (...)`` about the unit ``axis (3,)`` (Rodrigues)."""
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    s, c = np.sin(angle)[..., None, None], np.cos(angle)[..., None, None]
    return np.eye(3) + s * K + (1 - c) * (K @ K)


def _kin(tree: Tree, q: np.ndarray, screws: bool) -> TreeState:
    N = q.shape[0]
    nb = len(tree.body_names)
    T = np.empty((N, nb, 4, 4))
    T[:, 0] = np.eye(4)
    # Without screws S is an empty (N, 0, 6) placeholder that is never written (only poses wanted).
    S = np.zeros((N, tree.nv if screws else 0, 6))
    for b in range(1, nb):
        Tb = T[:, tree.parent[b]] @ tree.T_off[b]
        for k in tree.body_jnts[b]:
            typ, qa, da = tree.jnt_type[k], tree.jnt_qadr[k], tree.jnt_dadr[k]
            pos, axis = tree.jnt_pos[k], tree.jnt_axis[k]
            R, p = Tb[:, :3, :3], Tb[:, :3, 3]
            if typ == 0 or typ == 2:
                anchor = p + R @ pos
                Rj = (
                    axis_angle_matrix(axis, q[:, qa] - tree.jnt_ref[k])
                    if typ == 0
                    else quat_to_matrix(q[:, qa : qa + 4])
                )
                Rn = R @ Rj
                Tb = Tb.copy()
                Tb[:, :3, :3] = Rn
                Tb[:, :3, 3] = anchor - Rn @ pos
                if screws:
                    if typ == 0:
                        w = R @ axis
                        S[:, da, :3] = w
                        S[:, da, 3:] = _cross3(anchor, w)
                    else:
                        for c in range(3):
                            w = Rn[:, :, c]
                            S[:, da + c, :3] = w
                            S[:, da + c, 3:] = _cross3(anchor, w)
            elif typ == 1:
                w = R @ axis
                Tb = Tb.copy()
                Tb[:, :3, 3] = p + w * (q[:, qa] - tree.jnt_ref[k])[:, None]
                if screws:
                    S[:, da, 3:] = w
            else:
                Tb = np.tile(np.eye(4), (N, 1, 1))
                Rn = quat_to_matrix(q[:, qa + 3 : qa + 7])
                Tb[:, :3, :3] = Rn
                Tb[:, :3, 3] = q[:, qa : qa + 3]
                if screws:
                    for c in range(3):
                        S[:, da + c, 3 + c] = 1.0
                        w = Rn[:, :, c]
                        S[:, da + 3 + c, :3] = w
                        S[:, da + 3 + c, 3:] = _cross3(q[:, qa : qa + 3], w)
        T[:, b] = Tb
    return TreeState(T=T, S=S)


def body_poses(tree: Tree, q: np.ndarray) -> np.ndarray:
    """World pose of every body, ``(N, nb, 4, 4)`` (body 0 is the world).  ``q`` normalised quaternions."""
    return _kin(tree, q, screws=False).T


def kinematics(tree: Tree, q: np.ndarray) -> TreeState:
    """Body poses and coordinate space screws at ``q (N, nq)`` (quaternions already normalised)."""
    return _kin(tree, q, screws=True)


def integrate(tree: Tree, q: np.ndarray, dv: np.ndarray) -> np.ndarray:
    """``q ⊕ dv``: the configuration reached from ``q`` by the velocity increment ``dv (N, nv)``
    (the numpy formulation of _compiled.integrate / compiled_integrate)."""
    out = np.array(q, copy=True)
    for k in range(len(tree.jnt_names)):
        typ, qa, da = tree.jnt_type[k], tree.jnt_qadr[k], tree.jnt_dadr[k]
        if typ <= 1:
            out[:, qa] += dv[:, da]
        elif typ == 2:
            out[:, qa : qa + 4] = quat_mul(q[:, qa : qa + 4], quat_exp(dv[:, da : da + 3]))
        else:
            out[:, qa : qa + 3] += dv[:, da : da + 3]
            out[:, qa + 3 : qa + 7] = quat_mul(q[:, qa + 3 : qa + 7], quat_exp(dv[:, da + 3 : da + 6]))
    return normalize_quaternions(tree, out) if tree.quat_adr else out


def space_jacobian(tree: Tree, state: TreeState, body: int) -> np.ndarray:
    """Space-twist Jacobian of ``body`` (N, 6, nv): ``V_b = J qd`` (``[ω; v]``, v at the world origin)."""
    return (state.S * tree.A[body][:, None]).swapaxes(-1, -2)


def body_twists(tree: Tree, state: TreeState, qd: np.ndarray) -> np.ndarray:
    """Space twists of all bodies (N, ..., nb, 6) for ``qd (N, ..., nv)``."""
    S = state.S.reshape(state.S.shape[0], *(1,) * (qd.ndim - 2), *state.S.shape[1:])
    return np.einsum("bk,...kx,...k->...bx", tree.A, S, qd)


def frame_jacobian(tree: Tree, state: TreeState, body: int, point: np.ndarray) -> np.ndarray:
    """``[ω; ṗ] = J qd`` for the point ``point (N, 3)`` (world) fixed in ``body``: (N, 6, nv)."""
    S = state.S
    mask = tree.A[body][None, :, None]
    w = S[..., :3] * mask
    v = (S[..., 3:] + np.cross(S[..., :3], point[:, None, :])) * mask
    return np.concatenate([w, v], axis=-1).swapaxes(-1, -2)


# ----------------------------------------------------------------------------- closure rows and K
# The numpy formulation of _compiled.resjac / resjac_block (compiled_resjac), row block by row block.
def _poly(c: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    f = c[0] + x * (c[1] + x * (c[2] + x * (c[3] + x * c[4])))
    d1 = c[1] + x * (2 * c[2] + x * (3 * c[3] + x * 4 * c[4]))
    d2 = 2 * c[2] + x * (6 * c[3] + x * 12 * c[4])
    return f, d1, d2


def _points(
    state: TreeState, b1: int, x1: np.ndarray, b2: int, x2: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    return (state.T[:, b1] @ x1)[:, :3], (state.T[:, b2] @ x2)[:, :3]


def residual(cs: Constraints, tree: Tree, state: TreeState, q: np.ndarray) -> np.ndarray:
    """Closure residual ``(N, m)`` in length units."""
    out = []
    L = tree.length
    for k, d in cs.blocks:
        if k == "point":
            p1, p2 = _points(state, *d)
            out.append(p1 - p2)
        elif k == "rot":
            b1, Rrel, b2 = d
            Rt = state.T[:, b1, :3, :3] @ Rrel
            R2 = state.T[:, b2, :3, :3]
            out.append(0.5 * L * np.sum(np.cross(Rt, R2, axis=-2), axis=-1))
        else:
            _d1, q1, ref1, _, q2, ref2, c, s = d
            x = q[:, q2] - ref2 if q2 >= 0 else np.zeros(q.shape[0])
            out.append((s * ((q[:, q1] - ref1) - _poly(c, x)[0]))[:, None])
    return np.concatenate(out, axis=-1) if out else np.zeros((q.shape[0], 0))


def jacobian(cs: Constraints, tree: Tree, state: TreeState, q: np.ndarray) -> np.ndarray:
    """Velocity constraint matrix ``K (N, m, nv)``."""
    N = state.T.shape[0]
    L = tree.length
    out = []
    for k, d in cs.blocks:
        if k == "point":
            b1, _x1, b2, _x2 = d
            p1, p2 = _points(state, *d)
            out.append(
                frame_jacobian(tree, state, b1, p1)[:, 3:] - frame_jacobian(tree, state, b2, p2)[:, 3:]
            )
        elif k == "rot":
            b1, _, b2 = d
            w = state.S[..., :3].swapaxes(-1, -2)
            out.append(L * w * (tree.A[b2] - tree.A[b1]))
        else:
            d1, _, _, d2, q2, ref2, c, s = d
            row = np.zeros((N, 1, tree.nv))
            row[:, 0, d1] = s
            if d2 >= 0:
                row[:, 0, d2] -= s * _poly(c, q[:, q2] - ref2)[1]
            out.append(row)
    return np.concatenate(out, axis=-2) if out else np.zeros((N, 0, tree.nv))


# ----------------------------------------------------------------------------- dK/dt
# The numpy formulation of _compiled.screw_rates_into, point_rate and kdot_block (batched over samples).
def screw_rates(tree: Tree, state: TreeState, qd: np.ndarray) -> np.ndarray:
    """``dS/dt (N, ..., nv, 6)`` along ``qd (N, ..., nv)``: ``[V_c, S_k]`` with V_c the carrier twist."""
    S = state.S.reshape(state.S.shape[0], *(1,) * (qd.ndim - 2), *state.S.shape[1:])
    Vc = np.einsum("kj,...jx,...j->...kx", tree.C, S, qd)
    wc, vc = Vc[..., :3], Vc[..., 3:]
    ws, vs = S[..., :3], S[..., 3:]
    return np.concatenate([np.cross(wc, ws), np.cross(wc, vs) - np.cross(ws, vc)], axis=-1)


def frame_jacobian_rate(
    tree: Tree, state: TreeState, Sd: np.ndarray, body: int, point: np.ndarray, qd: np.ndarray
) -> np.ndarray:
    """Time derivative of :func:`frame_jacobian` along ``qd (N, ..., nv)`` with ``Sd = screw_rates(...)``.

    Column k: ``[dω_k; dv_k + dω_k × p + ω_k × ṗ]`` with ``ṗ = v_b + ω_b × p``; (N, ..., 6, nv).
    """
    extra = qd.ndim - 2
    S = state.S.reshape(state.S.shape[0], *(1,) * extra, *state.S.shape[1:])
    p = point.reshape(point.shape[0], *(1,) * extra, 3)
    mask = tree.A[body][:, None]
    V = np.einsum("k,...kx,...k->...x", tree.A[body], S, qd)
    pd = V[..., 3:] + np.cross(V[..., :3], p)
    dw = Sd[..., :3] * mask
    dv = (
        Sd[..., 3:] + np.cross(Sd[..., :3], p[..., None, :]) + np.cross(S[..., :3], pd[..., None, :])
    ) * mask
    return np.concatenate([dw, dv], axis=-1).swapaxes(-1, -2)


def jacobian_rate(
    cs: Constraints, tree: Tree, state: TreeState, Sd: np.ndarray, q: np.ndarray, qd: np.ndarray
) -> np.ndarray:
    """``dK/dt (N, ..., m, nv)`` along ``qd (N, ..., nv)`` (``Sd = screw_rates(tree, state, qd)``)."""
    L = tree.length
    extra = qd.ndim - 2
    out = []
    for k, d in cs.blocks:
        if k == "point":
            b1, _x1, b2, _x2 = d
            p1, p2 = _points(state, *d)
            out.append(
                frame_jacobian_rate(tree, state, Sd, b1, p1, qd)[..., 3:, :]
                - frame_jacobian_rate(tree, state, Sd, b2, p2, qd)[..., 3:, :]
            )
        elif k == "rot":
            b1, _, b2 = d
            out.append(L * Sd[..., :3].swapaxes(-1, -2) * (tree.A[b2] - tree.A[b1]))
        else:
            _d1, _, _, d2, q2, ref2, c, s = d
            row = np.zeros((*qd.shape[:-1], 1, tree.nv))
            if d2 >= 0:
                x = (q[:, q2] - ref2).reshape(-1, *(1,) * extra)
                row[..., 0, d2] = -s * _poly(c, x)[2] * qd[..., d2]
            out.append(row)
    return np.concatenate(out, axis=-2) if out else np.zeros((*qd.shape[:-1], 0, tree.nv))


# ----------------------------------------------------------------------------- influence coefficients
# The numpy formulation of _compiled.influence_block (batched over samples): G = [I; -K_p^+ K_a] by the
# SVD pseudo-inverse, dG along the unit input motions, the site Hessian (_influence's module docstring).
# An empty passive block (an open chain or tree: no closure rows, or no passive coordinate) cannot lose
# rank: its measures are those of the best-conditioned block, cond 1 and sigma_min = the characteristic
# length (the singular value of a unit passive column at distance L), finite like every other sample's.
def _pinv(Kp: np.ndarray, length: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Batched pseudo-inverse of ``Kp (N, m, n)`` with its rank, smallest kept singular value, cond."""
    N, m, n = Kp.shape
    if m == 0 or n == 0:
        return np.zeros((N, n, m)), np.zeros(N, dtype=int), np.full(N, float(length)), np.ones(N)
    U, s, Vt = np.linalg.svd(Kp, full_matrices=False)
    cut = PASSIVE_RANK_RTOL * s[:, :1]
    keep = s > cut
    sinv = np.where(keep, 1.0 / np.where(keep, s, 1.0), 0.0)
    P = np.einsum("nji,nj,nkj->nik", Vt, sinv, U)
    rank = np.sum(keep, axis=-1)
    smin = np.min(np.where(keep, s, np.inf), axis=-1)
    cond = np.where(rank > 0, s[:, 0] / np.where(np.isfinite(smin), smin, 1.0), np.inf)
    return P, rank, smin, cond


def _influence_flat(mech: Mechanism, q: np.ndarray, second: bool):
    """``(state, K, G, dG, Sd, (rank, n_passive, consistency, sigma_min, cond))`` at ``q (N, nq)``."""
    tree, cs = mech.tree, mech.constraints
    state = kinematics(tree, q)
    K = jacobian(cs, tree, state, q)
    N = q.shape[0]
    na = len(tree.act_dof)
    act = tree.act_dof
    pas = np.setdiff1d(np.arange(tree.nv), act)
    P, rank, smin, cond = _pinv(K[..., pas], tree.length)
    G = np.zeros((N, tree.nv, na))
    G[:, act, np.arange(na)] = 1.0
    G[:, pas] = -P @ K[..., act]
    cons = np.max(np.abs(K @ G), axis=(-1, -2)) / tree.length if K.shape[1] and na else np.zeros(N)
    dG = None
    Sd = None
    if second and na:
        qd = G.swapaxes(-1, -2)  # (N, na, nv): the motion of unit rate of input k
        Sd = screw_rates(tree, state, qd)
        Kd = jacobian_rate(cs, tree, state, Sd, q, qd)  # (N, na, m, nv)
        dGk = np.zeros((N, na, tree.nv, na))
        dGk[:, :, pas] = -np.einsum("nim,nkmj->nkij", P, Kd @ G[:, None])
        dG = dGk.transpose(0, 2, 3, 1)
    return state, K, G, dG, Sd, (rank, len(pas), cons, smin, cond)


def numpy_influence(mech: Mechanism, q: np.ndarray, second: bool = True) -> tuple:
    """``(G, dG, rank, consistency, sigma_min, cond)`` of ``_compiled.compiled_influence``."""
    _, _, G, dG, _, (rank, _, cons, smin, cond) = _influence_flat(mech, q, second)
    return G, dG, rank, cons, smin, cond


def numpy_site_hessian(mech: Mechanism, q: np.ndarray, site: int) -> np.ndarray:
    """``H (N, 6, na, na)``: ``(dJ_f/dt along G e_k) G e_j + J_f dG[:, j, k]`` (``mb.site_hessian``)."""
    tree = mech.tree
    state, _, G, dG, Sd, _ = _influence_flat(mech, q, True)
    b = tree.site_body[site]
    p = (state.T[:, b] @ tree.T_site[site])[:, :3, 3]
    Jf = frame_jacobian(tree, state, b, p)
    Jfd = frame_jacobian_rate(tree, state, Sd, b, p, G.swapaxes(-1, -2))  # (N, na_k, 6, nv)
    Hk = Jfd @ G[:, None] + Jf[:, None] @ dG.transpose(0, 3, 1, 2)  # (N, k, 6, j)
    return Hk.transpose(0, 2, 3, 1)


# ----------------------------------------------------------------------------- closure rows, batched
# The numpy formulation of the kernels' closure terms (_compiled.resjac, rates_kdot, site_forces,
# pinv_rank): K with the point rows' cross products in component arithmetic, Kdot qd without forming
# Kdot, the site wrenches' generalized forces, the pseudo-inverse truncated to the generic rank.
def pinv_rank(K: np.ndarray, r: int) -> tuple[np.ndarray, np.ndarray]:
    """Pseudo-inverse of ``K (N, m, n)`` truncated to the mechanism's generic rank ``r``, and the ratio
    ``s_1 / s_r`` (N,).  A fixed rank rather than a tolerance: between two projections a simulated state
    is ~1e-12 off the manifold, which lifts the zero singular values of an over-constrained closure
    (Bennett, planar loops in 3-D) to ~1e-12 — a tolerance would then invert them."""
    N, m, n = K.shape
    if r == 0 or m == 0:
        return np.zeros((N, n, m)), np.ones(N)
    U, s, Vt = np.linalg.svd(K, full_matrices=False)
    sr = s[:, r - 1]
    ok = sr > 0
    sinv = np.zeros_like(s)
    sinv[:, :r] = 1.0 / np.where(ok[:, None], s[:, :r], 1.0)
    P = np.einsum("nji,nj,nkj->nik", Vt, sinv, U)
    return P, np.where(ok, s[:, 0] / np.where(ok, sr, 1.0), np.inf)


def screw_rates_flat(tree, state, qd: np.ndarray) -> np.ndarray:
    """``_tree.screw_rates`` for flat ``qd (N, nv)`` with the carrier twists by matmul (the 3-operand
    einsum there runs as a naive loop): ``dS_k = [w_c x w_k; w_c x v_k - w_k x v_c]``."""
    S = state.S
    Vc = tree.C @ (S * qd[..., None])
    wc, vc = Vc[..., :3], Vc[..., 3:]
    ws, vs = S[..., :3], S[..., 3:]
    return np.concatenate([np.cross(wc, ws), np.cross(wc, vs) - np.cross(ws, vc)], axis=-1)


def _path(tree, b: int) -> np.ndarray:
    """Indices of the velocity coordinates that move body ``b`` (``Tree.dof_paths``, compiled once)."""
    return tree.dof_paths[b]


def constraint_matrix(mech: Mechanism, state, q: np.ndarray) -> np.ndarray:
    """``K (N, m, nv)`` as ``_constraints.jacobian`` builds it (same rows, same order), with the point
    rows' cross products in component arithmetic (the dynamics' hot path; tested equal)."""

    tree, cs = mech.tree, mech.constraints
    N, nv = q.shape[0], tree.nv
    S = state.S
    w = S[..., :3]
    w0, w1, w2 = w[..., 0], w[..., 1], w[..., 2]
    v = S[..., 3:]
    L = tree.length
    out = []
    for kind, d in cs.blocks:
        if kind == "point":
            b1, x1, b2, x2 = d
            rows = np.zeros((N, 3, nv))
            for b, x, sign in ((b1, x1, 1.0), (b2, x2, -1.0)):
                if b == 0:
                    continue
                p = (state.T[:, b] @ x)[:, :3]
                c = _path(tree, b)  # only the coordinates that move body b (a loop touches few)
                p0, p1, p2 = p[:, 0, None], p[:, 1, None], p[:, 2, None]
                a0, a1, a2 = w0[:, c], w1[:, c], w2[:, c]
                rows[:, 0, c] += sign * (v[:, c, 0] + a1 * p2 - a2 * p1)
                rows[:, 1, c] += sign * (v[:, c, 1] + a2 * p0 - a0 * p2)
                rows[:, 2, c] += sign * (v[:, c, 2] + a0 * p1 - a1 * p0)
            out.append(rows)
        elif kind == "rot":
            b1, _, b2 = d
            out.append(L * w.swapaxes(-1, -2) * (tree.A[b2] - tree.A[b1]))
        else:
            d1, _, _, d2, q2, ref2, c, sc = d
            row = np.zeros((N, 1, nv))
            row[:, 0, d1] = sc
            if d2 >= 0:
                row[:, 0, d2] -= sc * _poly(c, q[:, q2] - ref2)[1]
            out.append(row)
    return np.concatenate(out, axis=-2) if out else np.zeros((N, 0, nv))


def kdot_qd(mech: Mechanism, state, q: np.ndarray, qd: np.ndarray, Sd: np.ndarray) -> np.ndarray:
    """``Kdot qd (N, m)`` directly (the closure rows' velocity-product accelerations), block by block as
    ``_constraints.jacobian_rate`` builds ``Kdot``, without forming the (N, m, nv) matrix: a point row is
    the difference of the two anchors' ``dVd_v + dVd_w x p + w x pdot`` (``Vd = sum_k A Sd_k qd_k``), a
    rotation row ``L (Vd_w2 - Vd_w1)``, a coupling row ``-s poly''(x) qd2^2``."""

    tree, cs = mech.tree, mech.constraints
    V = tree.A @ (state.S * qd[..., None])
    Vd = tree.A @ (Sd * qd[..., None])
    L = tree.length
    out = []
    for kind, d in cs.blocks:
        if kind == "point":
            b1, x1, b2, x2 = d
            acc = []
            for b, x in ((b1, x1), (b2, x2)):
                pt = (state.T[:, b] @ x)[:, :3]
                w = V[:, b, :3]
                pd = V[:, b, 3:] + np.cross(w, pt)
                acc.append(Vd[:, b, 3:] + np.cross(Vd[:, b, :3], pt) + np.cross(w, pd))
            out.append(acc[0] - acc[1])
        elif kind == "rot":
            b1, _, b2 = d
            out.append(L * (Vd[:, b2, :3] - Vd[:, b1, :3]))
        else:
            _d1, _, _, d2, q2, ref2, c, sc = d
            row = np.zeros((q.shape[0], 1))
            if d2 >= 0:
                row[:, 0] = -sc * _poly(c, q[:, q2] - ref2)[2] * qd[:, d2] ** 2
            out.append(row)
    return np.concatenate(out, axis=-1) if out else np.zeros((q.shape[0], 0))


def site_terms(mech: Mechanism, state, wrenches: dict[int, np.ndarray]) -> np.ndarray:
    """``-sum_s J_s^T W_s`` (N, nv) for wrenches ``W_s (N, 6)`` applied to the mechanism at sites."""
    tree = mech.tree
    out = np.zeros((state.T.shape[0], tree.nv))
    for si, W in wrenches.items():
        b = tree.site_body[si]
        p = (state.T[:, b] @ tree.T_site[si])[:, :3, 3]
        Js = frame_jacobian(tree, state, b, p)
        out -= np.einsum("nik,ni->nk", Js, W)
    return out


# ----------------------------------------------------------------------------- Levenberg–Marquardt
# The numpy formulation of _compiled.lm_solve (batched over samples): assembly and inverse kinematics.
def numpy_lm(
    mech: Mechanism,
    q: np.ndarray,
    free: np.ndarray,
    extra: Callable[[TreeState, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]] | None = None,
    max_iter: int = MAX_ITER,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """LM on the closure rows (plus ``extra(state, q, idx) -> (r, J)`` rows) over the coordinates ``free``.

    ``q (N, nq)`` start (normalised); ``free`` indices of velocity coordinates that may move.
    Returns ``q, closure residual (N,) max-abs, total residual (N,), iterations (N,)``: the numpy
    formulation, batched over samples, of ``_compiled.lm_solve`` (FK without extra rows, IK with the
    site rows of :func:`site_error`).
    """
    tree, cs = mech.tree, mech.constraints
    N = q.shape[0]
    nf = len(free)

    def fun(qs: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        st = kinematics(tree, qs)
        r = residual(cs, tree, st, qs)
        J = jacobian(cs, tree, st, qs)
        rc = np.max(np.abs(r), axis=-1) if r.shape[-1] else np.zeros(qs.shape[0])
        if extra is not None:
            r2, J2 = extra(st, qs, idx)
            r = np.concatenate([r, r2], axis=-1)
            J = np.concatenate([J, J2], axis=-2)
        return r, J[..., free], rc

    q = np.array(q, copy=True)
    all_idx = np.arange(N)
    r, J, rc = fun(q, all_idx)
    finite = np.all(np.isfinite(r), axis=-1) & np.all(np.isfinite(J), axis=(-1, -2))
    cost = np.where(finite, np.sum(np.where(finite[:, None], r, 0.0) ** 2, axis=-1), np.inf)
    mu = np.full(N, MU_START)
    iters = np.zeros(N, dtype=int)
    active = finite.copy()
    stop = (STOP_RTOL * tree.length) ** 2
    wstep = np.where(tree.dof_translational, 1.0 / tree.length, 1.0)[free]
    geom_rows = np.array([k != "coupling" for k in cs.row_kind] + [True] * (r.shape[-1] - cs.m), dtype=bool)
    if nf == 0:
        active[:] = False
    for _ in range(max_iter):
        active &= cost > stop
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        Js, rs = J[idx], r[idx]
        JtJ = np.einsum("nmi,nmj->nij", Js, Js)
        g = np.einsum("nmi,nm->ni", Js, rs)
        scale = np.trace(JtJ, axis1=-2, axis2=-1) / nf + 1e-300
        Amat = JtJ + (mu[idx] * scale)[:, None, None] * np.eye(nf)
        dx = -np.linalg.solve(Amat, g[..., None])[..., 0]
        # coordinates that move no closure point or site (e.g. a lead screw's coupled spin) are not capped
        geo = (
            np.any(Js[:, geom_rows[: Js.shape[1]]] != 0.0, axis=1)
            if geom_rows.size
            else np.ones_like(dx, bool)
        )
        big = np.max(np.abs(dx) * wstep * geo, axis=-1)
        dx *= np.where(big > MAX_STEP, MAX_STEP / np.where(big > 0, big, 1.0), 1.0)[:, None]
        dv = np.zeros((idx.size, tree.nv))
        dv[:, free] = dx
        q_try = integrate(tree, q[idx], dv)
        r_t, J_t, rc_t = fun(q_try, idx)
        ok_f = np.all(np.isfinite(r_t), axis=-1) & np.all(np.isfinite(J_t), axis=(-1, -2))
        c_t = np.where(ok_f, np.sum(np.where(ok_f[:, None], r_t, 0.0) ** 2, axis=-1), np.inf)
        acc = c_t < cost[idx]
        ia = idx[acc]
        q[ia], r[ia], J[ia], rc[ia], cost[ia] = q_try[acc], r_t[acc], J_t[acc], rc_t[acc], c_t[acc]
        mu[ia] = np.maximum(mu[ia] / 10.0, MU_MIN)
        ir = idx[~acc]
        mu[ir] *= 10.0
        iters[idx] += 1
        active[ir[mu[ir] > MU_MAX]] = False
    rc = np.where(finite, rc, np.inf)
    return q, rc, np.sqrt(cost), iters


def site_error(tree, state, site: int, T_target: np.ndarray, w: np.ndarray):
    """Pose error rows ``[L rot; pos]`` (N, 6) of a site against ``T_target`` and their matrix (N, 6, nv)."""
    b = tree.site_body[site]
    Ts = state.T[:, b] @ tree.T_site[site]
    L = tree.length
    rot = 0.5 * L * np.sum(np.cross(T_target[:, :3, :3], Ts[:, :3, :3], axis=-2), axis=-1)
    pos = Ts[:, :3, 3] - T_target[:, :3, 3]
    Jf = frame_jacobian(tree, state, b, Ts[:, :3, 3])
    Jf = np.concatenate([L * Jf[:, :3], Jf[:, 3:]], axis=-2)
    return np.concatenate([rot, pos], axis=-1) * w, Jf * w[:, None]


def numpy_fk(mech, q, free, max_iter=MAX_ITER):
    """The assembly of ``_compiled.compiled_fk`` by the numpy iteration: (q, rc, iterations, residual)."""
    q, rc, res, it = numpy_lm(mech, np.array(q, dtype=float), np.asarray(free), None, max_iter)
    return q, rc, it, res


def numpy_ik(mech, site, T_target, guess, weights, steps=1):
    """The inverse kinematics of ``mb.inverse_kinematics`` by the numpy iteration, on finite
    ``T_target (N, 4, 4)`` and ``guess (N, nq)`` (``steps`` continuation stages from the guess's site
    pose, ``_assembly._interp_pose``): (q, converged, residual, pose error, iterations)."""
    from robomech.multibody._assembly import _interp_pose

    tree = mech.tree
    si = tree.site_index(site)
    w = np.asarray(weights, dtype=float)
    q = np.array(guess, dtype=float)
    start = kinematics(tree, q).T[:, tree.site_body[si]] @ tree.T_site[si]
    iters = np.zeros(q.shape[0], dtype=int)
    for s in range(1, steps + 1):
        Ts = T_target if s == steps else _interp_pose(start, T_target, s / steps)

        def extra(state, qs, idx, Ts=Ts):
            return site_error(tree, state, si, Ts[idx], w)

        q, rc, _, it = numpy_lm(mech, q, np.arange(tree.nv), extra)
        iters += it
    e, _ = site_error(tree, kinematics(tree, q), si, T_target, w)
    pe = np.max(np.abs(e), axis=-1)
    tol = CONVERGED_RTOL * tree.length
    return q, (rc <= tol) & (pe <= tol), rc, pe, iters


def numpy_site_jacobian(mech, q, site):
    """``J = J_f G`` (``_compiled.compiled_site_jacobian``) from the numpy influence coefficients."""
    tree = mech.tree
    state, _, G, _, _, _ = _influence_flat(mech, q, False)
    b = tree.site_body[site]
    p = (state.T[:, b] @ tree.T_site[site])[:, :3, 3]
    return frame_jacobian(tree, state, b, p) @ G


def numpy_compiled_influence(model, q, second, site=-1):
    """``_compiled.compiled_influence`` by the numpy formulation (``model`` carries the tree and rows)."""
    G, dG, rank, cons, smin, cond = numpy_influence(model, q, second)
    H = numpy_site_hessian(model, q, site) if second and site >= 0 else None
    return G, dG, H, rank, cons, smin, cond


def rank_measures(Kp: np.ndarray, rank0: int, length: float) -> tuple[np.ndarray, np.ndarray]:
    """``(sigma_min, cond)`` of ``Kp (N, m, n)`` against the mechanism's generic passive rank ``rank0``:
    the ``rank0``-th singular value and ``s_1`` over it (inf where it is zero).  A truncated
    pseudo-inverse keeps only the non-zero values, so its own ratio is 1 at a rank drop (a type II
    singularity); this is the measure reported wherever a sample is not valid.  An empty block or a
    generic rank 0: ``(length, 1)`` as in ``_influence._pinv``."""
    N, m, n = Kp.shape
    if m == 0 or n == 0 or rank0 == 0:
        return np.full(N, float(length)), np.ones(N)
    s = np.linalg.svd(np.where(np.isfinite(Kp), Kp, 0.0), compute_uv=False)
    sr = s[:, rank0 - 1] if s.shape[1] >= rank0 else np.zeros(N)
    cond = np.where(sr > 0, s[:, 0] / np.where(sr > 0, sr, 1.0), np.inf)
    return sr, cond


def numpy_passive_rank_measures(model, q):
    """``_rnea_kernels.passive_rank_measures``: :func:`rank_measures` of ``K_p`` at ``q (N, nq)``."""
    K = constraint_matrix(model, kinematics(model.tree, q), q)
    return rank_measures(K[..., model.pas], model.rank0, model.tree.length)


def numpy_closure_terms(model, q, qd, W, wsb, wT):
    """The closure terms of the full-rate inverse dynamics: ``(K, Kdot qd, -sum_s J_s^T W_s, closure)``."""
    tree = model.tree
    state = kinematics(tree, q)
    K = constraint_matrix(model, state, q)
    kdq = kdot_qd(model, state, q, qd, screw_rates_flat(tree, state, qd))
    ext = np.zeros((q.shape[0], tree.nv))
    for s, b in enumerate(wsb):
        p = (state.T[:, b] @ wT[s])[:, :3, 3]
        ext -= np.einsum("nik,ni->nk", frame_jacobian(tree, state, b, p), W[:, s])
    return K, kdq, ext, _closure_error(model, state, q)


def numpy_project(model, q, qd):
    """``_compiled.compiled_project``: ``qd - K^+ K qd``, ``K^+`` truncated to the generic rank of K."""
    tree = model.tree
    K = jacobian(model.constraints, tree, kinematics(tree, q), q)
    if not K.shape[1] or not model.rank_K:
        return np.array(qd, dtype=float)
    Kp, _ = pinv_rank(K, model.rank_K)
    return qd - np.einsum("nij,njk,nk->ni", Kp, K, qd)


def _closure_error(mech, state, q: np.ndarray) -> np.ndarray:
    """Largest closure row ``max |phi(q)|`` (m) per sample; 0 for a tree."""
    if mech.constraints.m == 0:
        return np.zeros(q.shape[0])
    return np.max(np.abs(residual(mech.constraints, mech.tree, state, q)), axis=-1)


def numpy_resjac(model, q: np.ndarray, with_jac: bool) -> tuple:
    """The numpy formulation of ``_compiled.compiled_resjac``: the closure residual and K."""
    if isinstance(model, Tables):  # the compile step of a mechanism compiled inside the block
        return _KERNELS["compiled_resjac"](model, q, with_jac)
    st = kinematics(model.tree, q)
    r = residual(model.constraints, model.tree, st, q)
    return r, (jacobian(model.constraints, model.tree, st, q) if with_jac else None)


def numpy_jacobian_rate(model, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """The numpy formulation of ``_compiled.compiled_jacobian_rate``: dK/dt along ``qd``."""
    st = kinematics(model.tree, q)
    return jacobian_rate(model.constraints, model.tree, st, screw_rates(model.tree, st, qd), q, qd)


def numpy_singular_values(model, q: np.ndarray, site: int, L: float, rows: tuple[int, ...]) -> tuple:
    """The numpy formulation of ``_compiled.compiled_singular_values``: the largest closure row and the
    singular values of the scaled K, K_p and site Jacobian rows (hinge columns and rotation rows times L)."""
    tree = model.tree
    r, K = numpy_resjac(model, q, True)
    col = np.where(tree.dof_translational, 1.0, L)
    scale = np.array([L, L, L, 1.0, 1.0, 1.0])
    J = (scale[:, None] * numpy_site_jacobian(model, q, site) / col[model.act])[:, list(rows)]
    Ks = K * col

    def sv(X: np.ndarray) -> np.ndarray:
        return np.linalg.svd(X, compute_uv=False) if X.shape[1] and X.shape[2] else np.zeros((len(q), 0))

    closure = np.max(np.abs(r), axis=-1, initial=0.0)
    return closure, sv(Ks), sv(Ks[..., model.pas]), sv(J)


# ----------------------------------------------------------------------------- site pose and energy
# The numpy formulation of _compiled.site_pose_block and energy_block.
def _com_jacobians(tree, state, bd, qd: np.ndarray | None, Sd: np.ndarray | None):
    """Centre-of-mass points (N, B, 3), Jacobians (N, B, 6, nv) and ``Jdot qd`` (N, B, 6)."""
    T = state.T[:, bd.idx]
    p = (T[..., :3, :3] @ bd.com[:, :, None])[..., 0] + T[..., :3, 3]
    S = state.S
    A = tree.A[bd.idx]  # (B, nv)
    Sw, Sv = S[..., :3], S[..., 3:]
    Jw = Sw[:, None] * A[None, :, :, None]  # (N, B, nv, 3)
    Jv = (Sv[:, None] + np.cross(Sw[:, None], p[:, :, None])) * A[None, :, :, None]
    J = np.concatenate([Jw, Jv], axis=-1).swapaxes(-1, -2)
    a0 = None
    if qd is not None:
        V = A @ (S * qd[..., None])
        Vd = A @ (Sd * qd[..., None])
        w = V[..., :3]
        pd = V[..., 3:] + np.cross(w, p)
        a0 = np.concatenate([Vd[..., :3], Vd[..., 3:] + np.cross(Vd[..., :3], p) + np.cross(w, pd)], axis=-1)
    return p, J, a0


def numpy_energy(model, q: np.ndarray, qd: np.ndarray, gv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and potential energy (N,) each: the numpy formulation of ``_compiled.compiled_energy``."""
    tree = model.tree
    bd = model.bodies
    st = kinematics(tree, q)
    p, J, _ = _com_jacobians(tree, st, bd, None, None)
    V = np.einsum("nbik,nk->nbi", J, qd)
    R = st.T[:, bd.idx, :3, :3]
    Iw = R @ bd.inertia @ R.swapaxes(-1, -2)
    w, v = V[..., :3], V[..., 3:]
    T = 0.5 * (np.einsum("nbi,nbij,nbj->n", w, Iw, w) + np.einsum("b,nbi,nbi->n", bd.mass, v, v))
    U = -np.einsum("b,nbi,i->n", bd.mass, p, gv)
    return T, U


def numpy_kinematics(model, q: np.ndarray, screws: bool = True) -> tuple:
    """The numpy formulation of ``_compiled.compiled_kinematics``: body poses and coordinate screws."""
    if isinstance(model, Tables):  # the compile step of a mechanism compiled inside the block
        return _KERNELS["compiled_kinematics"](model, q, screws)
    st = _kin(model.tree, np.asarray(q, float), screws)
    return st.T, (st.S if screws else None)


def numpy_integrate(model, q: np.ndarray, dv: np.ndarray) -> np.ndarray:
    """The numpy formulation of ``_compiled.compiled_integrate``."""
    if isinstance(model, Tables):  # the compile step of a mechanism compiled inside the block
        return _KERNELS["compiled_integrate"](model, q, dv)
    return integrate(model.tree, np.asarray(q, float), np.asarray(dv, float))


def numpy_site_pose(model, q: np.ndarray, site: int) -> np.ndarray:
    """The numpy formulation of ``_compiled.compiled_site_pose``: the body pose times the site's."""
    tree = model.tree
    return kinematics(tree, q).T[:, tree.site_body[site]] @ tree.T_site[site]


_SWAPS = {
    "compiled_fk": numpy_fk,
    "compiled_site_jacobian": numpy_site_jacobian,
    "compiled_influence": numpy_compiled_influence,
    "compiled_project": numpy_project,
    "compiled_resjac": numpy_resjac,
    "compiled_jacobian_rate": numpy_jacobian_rate,
    "compiled_singular_values": numpy_singular_values,
    "compiled_site_pose": numpy_site_pose,
    "compiled_energy": numpy_energy,
    "compiled_kinematics": numpy_kinematics,
    "compiled_integrate": numpy_integrate,
}
_KERNELS = {k: getattr(_compiled, k) for k in _SWAPS}  # the kernels' wrappers, whatever is swapped in
_SWAPS_DYNAMICS = {
    "_inverse_compiled": lambda *a, **k: _inverse_flat(*a, **k),
    "_forward_compiled": lambda *a, **k: numpy_forward(*a, **k),
    "_inverse_full_flat": lambda *a, **k: numpy_inverse_full(*a, **k),
}


@contextlib.contextmanager
def numpy_reference():
    """Inside the block, tree kinematics (body poses and screws), integration, FK, the closure
    residual, K and dK/dt, the singularity measures' singular values, site poses, energies, site
    Jacobians, influence coefficients, site Hessians, the closure terms, the velocity projection,
    inverse and forward dynamics run the numpy formulation."""
    saved = {k: getattr(_compiled, k) for k in _SWAPS}
    saved_rank = _rnea_kernels.passive_rank_measures
    _rnea_kernels.passive_rank_measures = numpy_passive_rank_measures
    saved_d = {k: getattr(_dynamics, k) for k in _SWAPS_DYNAMICS}
    for k, fn in _SWAPS.items():
        setattr(_compiled, k, fn)
    for k, fn in _SWAPS_DYNAMICS.items():
        setattr(_dynamics, k, fn)
    try:
        yield
    finally:
        for k, fn in saved.items():
            setattr(_compiled, k, fn)
        for k, fn in saved_d.items():
            setattr(_dynamics, k, fn)
        _rnea_kernels.passive_rank_measures = saved_rank


# ----------------------------------------------------------------------------- the tree's RNEA and CRBA
# The numpy formulation of _compiled.rnea_block and _rnea_kernels.crba_block (batched over samples,
# Python loops over bodies), as _rnea's module docstring states the algorithms.
def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a x b`` over the last axis (component arithmetic: np.cross is slow on small batches)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def _motion_cross(V: np.ndarray, S: np.ndarray) -> np.ndarray:
    """``V x S`` for spatial motions ``[ω; v]``: ``[ω x ω_s; ω x v_s + v x ω_s]``."""
    w, v = V[..., :3], V[..., 3:]
    ws, vs = S[..., :3], S[..., 3:]
    return np.concatenate([_cross(w, ws), _cross(w, vs) + _cross(v, ws)], axis=-1)


def _world_inertia(bi, T: np.ndarray):
    """Per body: mass (nb,), world centre of mass ``c (N, nb, 3)``, world inertia about it (N, nb, 3, 3)."""
    R = T[..., :3, :3]
    c = (R @ bi.com[:, :, None])[..., 0] + T[..., :3, 3]
    Ic = R @ bi.inertia @ R.swapaxes(-1, -2)
    return bi.mass, c, Ic


def _apply_inertia(m: np.ndarray, c: np.ndarray, Ic: np.ndarray, X: np.ndarray) -> np.ndarray:
    """``I X`` for spatial inertias (mass ``m``, com ``c``, inertia about the com ``Ic``) and motions X
    ``[ω; v]`` about the world origin: ``f = m (v + ω x c)``, ``n = Ic ω + c x f``."""
    w, v = X[..., :3], X[..., 3:]
    f = m[..., None] * (v + _cross(w, c))
    n = (Ic @ w[..., None])[..., 0] + _cross(c, f)
    return np.concatenate([n, f], axis=-1)


def numpy_rnea(mech, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, g: np.ndarray) -> np.ndarray:
    """Tree inverse dynamics ``(N, nv)`` at normalised ``q (N, nq)``, ``qd``, ``qdd (N, nv)``, gravity g."""
    tree = mech.tree
    N, nb = q.shape[0], len(tree.body_names)
    st = kinematics(tree, q)
    S = st.S
    V = np.zeros((N, nb, 6))
    A = np.zeros((N, nb, 6))
    A[:, 0, 3:] = -g  # the base accelerates upwards at g: gravity on every body
    for b in range(1, nb):
        p = tree.parent[b]
        v, a = V[:, p].copy(), A[:, p].copy()
        for k in tree.body_jnts[b]:
            typ, da = tree.jnt_type[k], tree.jnt_dadr[k]
            n = (1, 1, 3, 6)[typ]
            Sk = S[:, da : da + n]  # (N, n, 6)
            vj = np.einsum("nkx,nk->nx", Sk, qd[:, da : da + n])
            aj = np.einsum("nkx,nk->nx", Sk, qdd[:, da : da + n])
            if typ <= 1:  # hinge / slide: the axis is carried by the frame before the joint
                aj = aj + _motion_cross(v, Sk[:, 0]) * qd[:, da, None]
            elif typ == 2:  # ball: axes of the frame after it (local angular velocity)
                aj = aj + np.einsum("nkx,nk->nx", _motion_cross((v + vj)[:, None], Sk), qd[:, da : da + 3])
            else:  # free: translation axes fixed in the world, rotation axes the body's own
                aj = aj + np.einsum(
                    "nkx,nk->nx", _motion_cross(vj[:, None], Sk[:, 3:]), qd[:, da + 3 : da + 6]
                )
            v, a = v + vj, a + aj
        V[:, b], A[:, b] = v, a
    m, c, Ic = _world_inertia(_rnea.body_inertias(mech), st.T)
    F = _apply_inertia(m, c, Ic, A)
    h = _apply_inertia(m, c, Ic, V)
    w, vl = V[..., :3], V[..., 3:]
    F = F + np.concatenate([_cross(w, h[..., :3]) + _cross(vl, h[..., 3:]), _cross(w, h[..., 3:])], axis=-1)
    for b in range(nb - 1, 0, -1):  # backward pass: each subtree's wrench into its parent
        F[:, tree.parent[b]] += F[:, b]
    return np.einsum("nkx,nkx->nk", S, F[:, tree.dof_body])


def numpy_crba(mech, q: np.ndarray) -> np.ndarray:
    """Tree mass matrix ``(N, nv, nv)`` at normalised ``q (N, nq)`` (composite-rigid-body algorithm)."""
    tree = mech.tree
    nb = len(tree.body_names)
    st = kinematics(tree, q)
    m, c, Ic = _world_inertia(_rnea.body_inertias(mech), st.T)
    # composite inertias as 6 x 6 matrices about the world origin (columns: I applied to unit motions)
    E = np.eye(6)
    I6 = np.stack([_apply_inertia(m, c, Ic, np.broadcast_to(E[j], (*c.shape[:-1], 6))) for j in range(6)], -1)
    for b in range(nb - 1, 0, -1):
        I6[:, tree.parent[b]] += I6[:, b]
    S = st.S
    F = (I6[:, tree.dof_body] @ S[..., None])[..., 0]  # (N, nv, 6): I^c_{body(i)} S_i
    Mf = F @ S.swapaxes(-1, -2)  # Mf[i, j] = S_i . I^c_{body(i)} S_j
    anc = tree.A[tree.dof_body].astype(bool)  # anc[i, j]: coordinate j moves body(i)
    return np.where(anc, Mf, np.where(anc.T, Mf.swapaxes(-1, -2), 0.0))


# ----------------------------------------------------------------------------- closed-chain inverse dynamics
# The numpy formulation of _compiled.inv_dyn_block (batched over samples): the derivation of
# _dynamics' module docstring, with the passive pseudo-inverse from a batched LU Gram inverse.
def _passive_inverse(Kp: np.ndarray, rank0: int, length: float = 1.0):
    """Pseudo-inverse of the passive block ``Kp (N, m, n)`` with (rank, sigma_min, cond) per sample.

    Fast path where the generic rank is ``min(m, n)`` (no idle motion *and* redundant rows at once):
    ``P0 = Kp^T (Kp Kp^T)^-1`` (wide) or ``(Kp^T Kp)^-1 Kp^T`` (tall) from a batched inverse, refined
    ``P_{k+1} = P_k + P0 (I - Kp P_k)`` (once above GRAM_REFINE_COND, twice above GRAM_REFINE2_COND:
    iterative refinement of the normal equations, for wide and tall alike); ``cond`` is then the 1-norm
    estimate ``sqrt(||Gram||_1 ||Gram^-1||_1)`` (between the 2-norm one and sqrt(rank) times it) and
    ``sigma_min`` ``1 / sqrt(||Gram^-1||_1)`` (a lower bound within rank^(1/4)).  Samples above
    GRAM_COND_MAX, and mechanisms without the fast path, get the SVD pseudo-inverse of the multibody layer.
    """
    N, m, n = Kp.shape
    if m == 0 or n == 0 or rank0 != min(m, n):
        return _pinv(Kp, length)
    wide = m <= n
    KT = Kp.swapaxes(-1, -2)
    Gm = Kp @ KT if wide else KT @ Kp
    with np.errstate(all="ignore"):
        try:
            Gi = np.linalg.inv(Gm)
        except np.linalg.LinAlgError:
            return _pinv(Kp, length)
        P = KT @ Gi if wide else Gi @ KT
        ni = np.linalg.norm(Gi, 1, axis=(-2, -1))
        cond = np.sqrt(np.linalg.norm(Gm, 1, axis=(-2, -1)) * ni)
        smin = 1.0 / np.sqrt(ni)
        # refine where the Gram matrix's squared conditioning could show: cond^2 eps > 1e-12
        for lim in (GRAM_REFINE_COND, GRAM_REFINE2_COND):
            r = np.flatnonzero(~(cond <= lim))
            if r.size:
                P0 = KT[r] @ Gi[r] if wide else Gi[r] @ KT[r]
                P[r] = P[r] + P0 @ (np.eye(m) - Kp[r] @ P[r])
    rank = np.full(N, rank0)
    bad = ~(np.isfinite(cond) & (cond <= GRAM_COND_MAX) & np.all(np.isfinite(P), axis=(-1, -2)))
    if np.any(bad):
        Pb, rb, sb, cb = _pinv(Kp[bad], length)
        P[bad], rank[bad], smin[bad], cond[bad] = Pb, rb, sb, cb
    return P, rank, smin, cond


def _cross_rows(a: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``a_col x p`` for every column of ``a (..., 3, k)`` with ``p (..., 3)`` (component arithmetic:
    np.cross on broadcast blocks moves axes and is several times slower here)."""
    x, y, z = p[..., 0, None], p[..., 1, None], p[..., 2, None]
    a0, a1, a2 = a[..., 0, :], a[..., 1, :], a[..., 2, :]
    return np.stack([a1 * z - a2 * y, a2 * x - a0 * z, a0 * y - a1 * x], axis=-2)


def _com_projected(tree, state, bd, qd, Sd, G, extra_qdd):
    """Centre-of-mass Jacobians through G, ``J_b G (N, B, 6, na)``, and the accelerations
    ``Jdot_b qd + J_b extra_qdd (N, B, 6)`` — without the (N, B, 6, nv) Jacobians' cross products."""
    T = state.T[:, bd.idx]
    p = (T[..., :3, :3] @ bd.com[:, :, None])[..., 0] + T[..., :3, 3]
    S = state.S
    A = tree.A[bd.idx]  # (B, nv)
    SG = np.empty((S.shape[0], len(bd.idx), 6, G.shape[-1]))  # (N, B, 6, na): sum over b's path of S_k G_k
    St = S.swapaxes(-1, -2)
    for i, b in enumerate(bd.idx):
        c = _path(tree, b)
        SG[:, i] = St[:, :, c] @ G[:, c]
    JG = np.concatenate([SG[..., :3, :], SG[..., 3:, :] + _cross_rows(SG[..., :3, :], p)], axis=-2)
    V = A @ (S * qd[..., None])
    Vd = A @ (Sd * qd[..., None] + S * extra_qdd[..., None])
    w = V[..., :3]
    pd = V[..., 3:] + np.cross(w, p)
    a0 = np.concatenate([Vd[..., :3], Vd[..., 3:] + np.cross(Vd[..., :3], p) + np.cross(w, pd)], axis=-1)
    return JG, a0


def _projector(mech, K, G, dof, w):
    """Redundant actuation: the rule's projector Pi (N, na, na); False where null(K G) is not ``dof``-wide."""
    N, _, na = G.shape
    KG = (K @ G) / mech.tree.length
    s_full = np.zeros((N, na))
    if KG.shape[1]:
        _, s, Vt = np.linalg.svd(KG, full_matrices=True)
        s_full[:, : s.shape[1]] = s[:, :na]
    else:
        Vt = np.broadcast_to(np.eye(na), (N, na, na))
    # singular values ascending over the right singular vectors: the last `dof` rows of Vt span null(KG)
    Nc = Vt[:, na - dof :].swapaxes(-1, -2)  # (N, na, dof)
    top = np.maximum(np.max(s_full, axis=-1), 1.0)
    gap_ok = np.all(s_full[:, na - dof :] <= RANK_RTOL * 1e2 * top[:, None], axis=-1)
    if dof < na:
        gap_ok &= s_full[:, na - dof - 1] > RANK_RTOL * 1e2 * top
    if w is None:
        Pi = Nc @ Nc.swapaxes(-1, -2)
    else:
        WN = w[:, None] * Nc
        A = Nc.swapaxes(-1, -2) @ WN
        ok = np.linalg.cond(A) < 1.0 / RANK_RTOL
        A = np.where(ok[:, None, None], A, np.eye(dof))
        Pi = WN @ np.linalg.solve(A, Nc.swapaxes(-1, -2))
        gap_ok &= ok
    return Pi, gap_ok


def _inverse_flat(mech, q, qd_a, qdd_a, wr, weights, gravity=True):
    tree = mech.tree
    rank0, dof = D._reference(mech)
    na = len(tree.act_dof)
    act = tree.act_dof
    pas = np.setdiff1d(np.arange(tree.nv), act)
    N = q.shape[0]
    state = kinematics(tree, q)
    K = constraint_matrix(mech, state, q)
    P, rank, smin, cond = _passive_inverse(K[..., pas], rank0, tree.length)
    G = np.zeros((N, tree.nv, na))
    G[:, act, np.arange(na)] = 1.0
    G[:, pas] = -P @ K[..., act]
    qd = D._mv(G, qd_a)
    Sd = screw_rates_flat(tree, state, qd)
    kdq = kdot_qd(mech, state, q, qd, Sd)
    qdd = D._mv(G, qdd_a)
    qdd[:, pas] -= D._mv(P, kdq)
    # Project each body's Jacobian through G first (6 x n_act instead of 6 x nv): the tree mass matrix is
    # never formed.  The convective acceleration J (qdd - G qdd_act) joins the velocity-product terms.
    bd = D._bodies(mech)
    R = state.T[:, bd.idx, :3, :3]
    Iw = R @ bd.inertia @ R.swapaxes(-1, -2)
    conv = qdd - D._mv(G, qdd_a)
    JG, a0 = _com_projected(tree, state, bd, qd, Sd, G, conv)
    gv = np.asarray(mech.gravity) if gravity else np.zeros(3)
    terms = _com_terms(np.broadcast_to(bd.mass, (N, len(bd.mass))), Iw, JG, a0, qd_a, qdd_a, gv[None])
    ext = site_terms(mech, state, wr)
    GT = G.swapaxes(-1, -2)
    M_a = terms.M
    vel = terms.velocity_terms
    grav = terms.gravity_terms
    ex = D._mv(GT, ext)
    ok = np.ones(N, dtype=bool)
    if na > dof or weights is not None:
        Pi, ok = _projector(mech, K, G, dof, weights)
        M_a = Pi @ M_a
        vel, grav, ex = (D._mv(Pi, x) for x in (vel, grav, ex))
    tau = D._mv(M_a, qdd_a) + vel + grav + ex
    L = tree.length
    sv = np.max(np.abs(qd), axis=-1) if tree.nv else np.zeros(N)
    sa = np.max(np.abs(qdd), axis=-1) + sv * sv if tree.nv else np.zeros(N)
    if K.shape[1]:
        e1 = np.max(np.abs(D._mv(K, qd)), axis=-1) / (L * np.maximum(sv, RATE_FLOOR))
        e2 = np.max(np.abs(D._mv(K, qdd) + kdq), axis=-1) / (L * np.maximum(sa, RATE_FLOOR))
        adm = np.maximum(e1, e2)
    else:
        adm = np.zeros(N)
    fin = np.all(np.isfinite(tau), axis=-1) & np.all(np.isfinite(M_a), axis=(-1, -2))
    valid = ok & fin & (rank >= rank0) & (cond <= SINGULAR_COND) & (adm <= ADMISSIBLE_RTOL)
    return dict(
        tau=tau,
        M_a=M_a,
        velocity_terms=vel,
        gravity_terms=grav,
        external_terms=ex,
        qd=qd,
        qdd=qdd,
        cond=cond,
        sigma_min=smin,
        admissibility=adm,
        valid=valid,
        closure=_closure_error(mech, state, q),
    )


# ----------------------------------------------------------------------------- full-rate inverse dynamics
# The numpy formulation of _rnea_kernels.inv_full_block (batched over samples).
def null_basis(mech: Mechanism, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormal basis ``(N, nv, d)`` of the admissible velocities ``null(K)`` at the mechanism's
    generic rank of ``K``, and ``s_1 / s_r`` of ``K`` (N,): 1 for a tree (the identity basis)."""
    N, m, nv = K.shape
    r = D._rank_K(mech) if m else 0
    if r == 0:
        return np.broadcast_to(np.eye(nv), (N, nv, nv)), np.ones(N)
    _, s, Vt = np.linalg.svd(K, full_matrices=True)
    sr = s[:, r - 1]
    cond = np.where(sr > 0, s[:, 0] / np.where(sr > 0, sr, 1.0), np.inf)
    return Vt[:, r:].swapaxes(-1, -2), cond


def numpy_inverse_full(mech, q, qd, qdd, wr, weights, gravity=True):
    """``_dynamics._inverse_full_flat`` (the compiled ``_rnea_kernels.inv_full_block``) in batched numpy:
    the derivation of that docstring, from numpy_crba, numpy_rnea and numpy_closure_terms."""
    model = D.compile_model(mech)
    tree = model.tree
    N, nv = q.shape[0], tree.nv
    act = tree.act_dof
    na = len(act)
    L = tree.length
    z = np.zeros_like(qd)
    gv = np.asarray(mech.gravity, float) if gravity else np.zeros(3)
    M = numpy_crba(mech, q)
    K, kdq, ext, closure = numpy_closure_terms(model, q, qd, *D._wrench_arrays(tree, wr, N))
    parts = (
        D._mv(M, qdd),
        numpy_rnea(mech, q, qd, z, np.zeros(3)),
        numpy_rnea(mech, q, z, z, gv),
        ext,
    )
    f = parts[0] + parts[1] + parts[2] + parts[3]
    Nb, condK = null_basis(mech, K)
    NbT = Nb.swapaxes(-1, -2)
    Na = Nb[:, act]  # (N, na, d): the actuated rows of the admissible motions
    ws = np.ones(na) if weights is None else np.sqrt(weights)
    A = NbT[:, :, act] * ws  # (N, d, na)
    d = Nb.shape[-1]
    if na and d:
        sA = np.linalg.svd(A, compute_uv=False)
        smin = sA[:, -1]
        cond_a = np.where(smin > RANK_RTOL * sA[:, 0], sA[:, 0] / np.where(smin > 0, smin, 1.0), np.inf)
        B = ws[:, None] * (np.linalg.pinv(A, rcond=RANK_RTOL) @ NbT)  # (N, na, nv)
    else:
        smin, cond_a = np.ones(N), np.ones(N)
        B = np.zeros((N, na, nv))
    tau_parts = [D._mv(B, x) for x in parts]
    tau = tau_parts[0] + tau_parts[1] + tau_parts[2] + tau_parts[3]
    b = D._mv(NbT, f)
    unact = D._mv(Nb, b - D._mv(Na.swapaxes(-1, -2), tau))
    # relative to the largest of the inertial, velocity, gravity and external terms (their sum is ~0 on a
    # free motion, whose rounding must not count as a force the actuators cannot give)
    scale = np.max(np.abs(np.stack(parts)), axis=(0, -1)) if nv else np.zeros(N)
    e_force = np.max(np.abs(unact), axis=-1) / np.maximum(scale, 1e-300) if nv else np.zeros(N)
    sv = np.max(np.abs(qd), axis=-1) if nv else np.zeros(N)
    sa = np.max(np.abs(qdd), axis=-1) + sv * sv if nv else np.zeros(N)
    if K.shape[1]:
        e1 = np.max(np.abs(D._mv(K, qd)), axis=-1) / (L * np.maximum(sv, RATE_FLOOR))
        e2 = np.max(np.abs(D._mv(K, qdd) + kdq), axis=-1) / (L * np.maximum(sa, RATE_FLOOR))
        adm = np.maximum(np.maximum(e1, e2), e_force)
    else:
        adm = e_force
    M_a = B @ M @ B.swapaxes(-1, -2)
    cond = np.maximum(condK, cond_a)
    fin = np.all(np.isfinite(tau), axis=-1) & np.all(np.isfinite(M_a), axis=(-1, -2))
    computed = fin & (cond <= SINGULAR_COND)
    return dict(
        _computed=computed,
        tau=tau,
        M_a=M_a,
        velocity_terms=tau_parts[1],
        gravity_terms=tau_parts[2],
        external_terms=tau_parts[3],
        qd=np.array(qd),
        qdd=np.array(qdd),
        cond=cond,
        sigma_min=L * smin,
        admissibility=adm,
        unactuated=unact,
        closure=closure,
        valid=computed & (adm <= ADMISSIBLE_RTOL),
    )


# ----------------------------------------------------------------------------- forward dynamics
# The numpy formulation of _rnea_kernels.fd_block (batched over samples): the closure a constraint on
# the tree accelerations, qdd = qdd_p + u, K qdd_p = -Kdot qd (minimum norm at the generic rank of K),
# Mc u = Pn (f - M qdd_p), Pn = I - K^+ K, Mc = Pn M Pn + (I - Pn), solved by LU (LAPACK gesv).
def _solve_each(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``A x = b`` per sample; an exactly singular matrix gives NaN for its sample only."""
    try:
        return np.linalg.solve(A, b[..., None])[..., 0]
    except np.linalg.LinAlgError:
        out = np.full(b.shape, np.nan)
        for i in range(A.shape[0]):
            try:
                out[i] = np.linalg.solve(A[i], b[i])
            except np.linalg.LinAlgError:
                pass
        return out


def numpy_forward(mech, q, rates, tau_a, wr, gravity, act_mode):
    """``(qd, qdd, cond, admissibility, closure, regular)`` of ``_dynamics._forward_compiled``."""
    tree = mech.tree
    N, nv = q.shape[0], tree.nv
    L = tree.length
    act = tree.act_dof
    pas = np.setdiff1d(np.arange(nv), act)
    rank0 = D._reference(mech)[0]
    state = kinematics(tree, q)
    K = constraint_matrix(mech, state, q)
    if act_mode:
        P, rank, _, cK = _pinv(K[..., pas], L)
        qd = np.zeros((N, nv))
        qd[:, act] = rates
        qd[:, pas] = -np.einsum("nij,njk,nk->ni", P, K[..., act], rates)
        reg = (rank >= rank0) & (cK <= SINGULAR_COND)
        e1 = np.zeros(N)
    else:
        qd = np.array(rates)
        reg = np.ones(N, dtype=bool)
        sv = np.max(np.abs(qd), axis=-1)
        e1 = np.max(np.abs(D._mv(K, qd)), axis=-1, initial=0.0) / (L * np.maximum(sv, RATE_FLOOR))
    kdq = kdot_qd(mech, state, q, qd, screw_rates_flat(tree, state, qd))
    g = np.asarray(mech.gravity, float) if gravity else np.zeros(3)
    M = numpy_crba(mech, q)
    f = -numpy_rnea(mech, q, qd, np.zeros_like(qd), g) - site_terms(mech, state, wr)
    f[:, act] += tau_a
    if K.shape[1]:
        Kp, _ = pinv_rank(K, D._rank_K(mech))  # (N, nv, m)
        qdd_p = -D._mv(Kp, kdq)
        Pn = np.eye(nv) - Kp @ K
    else:
        qdd_p = np.zeros((N, nv))
        Pn = np.broadcast_to(np.eye(nv), (N, nv, nv))
    Mc = Pn @ M @ Pn + (np.eye(nv) - Pn)
    rhs = D._mv(Pn, f - D._mv(M, qdd_p))
    s = np.linalg.svd(np.where(np.isfinite(Mc), Mc, 0.0), compute_uv=False)
    cond = np.where(s[:, -1] > 0, s[:, 0] / np.where(s[:, -1] > 0, s[:, -1], 1.0), np.inf)
    qdd = qdd_p + _solve_each(Mc, rhs)
    sa = np.max(np.abs(qdd), axis=-1) + np.max(np.abs(qd), axis=-1) ** 2
    e2 = np.max(np.abs(D._mv(K, qdd) + kdq), axis=-1, initial=0.0) / (L * np.maximum(sa, RATE_FLOOR))
    adm = np.maximum(e1, np.where(np.isfinite(e2), e2, np.inf))
    closure = np.max(np.abs(residual(mech.constraints, tree, state, q)), axis=-1, initial=0.0)
    if act_mode and np.any(~reg):  # a singular passive block: its measure against the generic rank
        bad = np.flatnonzero(~reg)
        cond[bad] = np.maximum(cond[bad], rank_measures(K[bad][..., pas], rank0, L)[1])
    return qd, qdd, cond, adm, closure, reg
