"""The numpy formulation of the compiled kernels, kept here as the tests' reference.

The library runs one implementation per algorithm (the compiled kernels of
``robomech/multibody/_compiled.py``, at every batch size).  The same algorithms written batched in
numpy, from the layer's own tree and closure functions, are the independent formulation the kernels
are checked against: :func:`numpy_reference` swaps them in for the kernels inside a ``with`` block.
"""

from __future__ import annotations

import contextlib

import numpy as np

from robomech.multibody import _compiled, _dynamics, _rnea
from robomech.multibody._assembly import solve_closure
from robomech.multibody._influence import _influence_flat
from robomech.multibody._tree import frame_jacobian, kinematics


def _no_rows(state, q, idx):
    """No extra rows: ``solve_closure`` then runs its numpy Levenberg–Marquardt iteration."""
    n = len(idx)
    return np.zeros((n, 0)), np.zeros((n, 0, state.S.shape[1]))


def numpy_fk(mech, q, free):
    """The assembly of ``_compiled.compiled_fk`` by the numpy iteration: (q, rc, iterations, residual)."""
    q, rc, res, it = solve_closure(mech, np.array(q, dtype=float), np.asarray(free), _no_rows)
    return q, rc, it, res


def numpy_site_jacobian(mech, q, site):
    """``J = J_f G`` (``_compiled.compiled_site_jacobian``) from the numpy influence coefficients."""
    tree = mech.tree
    state, _, G, _, _, _ = _influence_flat(mech, q, False)
    b = tree.site_body[site]
    p = (state.T[:, b] @ tree.T_site[site])[:, :3, 3]
    return frame_jacobian(tree, state, b, p) @ G


@contextlib.contextmanager
def numpy_reference():
    """Inside the block, FK, site Jacobians and inverse dynamics run the numpy formulation."""
    saved = (_compiled.compiled_fk, _compiled.compiled_site_jacobian, _dynamics._inverse_compiled)
    _compiled.compiled_fk = numpy_fk
    _compiled.compiled_site_jacobian = numpy_site_jacobian
    _dynamics._inverse_compiled = _dynamics._inverse_flat
    try:
        yield
    finally:
        _compiled.compiled_fk, _compiled.compiled_site_jacobian, _dynamics._inverse_compiled = saved


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
