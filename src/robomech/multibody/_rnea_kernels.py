"""Compiled (numba) per-sample kernels of the tree's RNEA and CRBA (``_rnea``'s algorithms).

Per sample: the tree kinematics of ``_compiled.kin`` (body poses and space screws), then the
recursive Newton-Euler passes or the composite-rigid-body algorithm in world coordinates, exactly as
the module docstring of :mod:`._rnea` states them; large batches in parallel blocks of
``_compiled.BLOCK`` samples (``numba.prange``).
"""

from __future__ import annotations

import numpy as np

from robomech._numba import import_numba

from ._compiled import BLOCK, kin

__all__ = ["crba_batch", "rnea_batch"]

numba = import_numba()
_nj = numba.njit(cache=True, error_model="numpy")


@_nj
def _inertia_world(T, mass, com, inertia, b, c, Ic):  # pragma: no cover - compiled
    """World centre of mass ``c (3,)`` and inertia about it ``Ic (3, 3)`` of body ``b``."""
    for i in range(3):
        c[i] = T[b, i, 3] + T[b, i, 0] * com[b, 0] + T[b, i, 1] * com[b, 1] + T[b, i, 2] * com[b, 2]
    for i in range(3):
        for j in range(3):
            s = 0.0
            for k in range(3):
                for m in range(3):
                    s += T[b, i, k] * inertia[b, k, m] * T[b, j, m]
            Ic[i, j] = s


@_nj
def _apply(m, c, Ic, X, out):  # pragma: no cover - compiled
    """``out = I X``: ``f = m (v + w x c)``, ``n = Ic w + c x f`` (motions about the world origin)."""
    w0, w1, w2 = X[0], X[1], X[2]
    f0 = m * (X[3] + w1 * c[2] - w2 * c[1])
    f1 = m * (X[4] + w2 * c[0] - w0 * c[2])
    f2 = m * (X[5] + w0 * c[1] - w1 * c[0])
    out[0] = Ic[0, 0] * w0 + Ic[0, 1] * w1 + Ic[0, 2] * w2 + c[1] * f2 - c[2] * f1
    out[1] = Ic[1, 0] * w0 + Ic[1, 1] * w1 + Ic[1, 2] * w2 + c[2] * f0 - c[0] * f2
    out[2] = Ic[2, 0] * w0 + Ic[2, 1] * w1 + Ic[2, 2] * w2 + c[0] * f1 - c[1] * f0
    out[3], out[4], out[5] = f0, f1, f2


@_nj
def _add_motion_cross(V, Sk, scale, out):  # pragma: no cover - compiled
    """``out += scale * (V x Sk)``: ``[w x ws; w x vs + v x ws]``."""
    w0, w1, w2, v0, v1, v2 = V[0], V[1], V[2], V[3], V[4], V[5]
    a0, a1, a2, b0, b1, b2 = Sk[0], Sk[1], Sk[2], Sk[3], Sk[4], Sk[5]
    out[0] += scale * (w1 * a2 - w2 * a1)
    out[1] += scale * (w2 * a0 - w0 * a2)
    out[2] += scale * (w0 * a1 - w1 * a0)
    out[3] += scale * (w1 * b2 - w2 * b1 + v1 * a2 - v2 * a1)
    out[4] += scale * (w2 * b0 - w0 * b2 + v2 * a0 - v0 * a2)
    out[5] += scale * (w0 * b1 - w1 * b0 + v0 * a1 - v1 * a0)


@_nj
def rnea_sample(
    q, qd, qdd, g, t, mass, com, inertia, dof_body, T, S, V, A, F, tmp, h, c, Ic, out
):  # pragma: no cover
    kin(q, t, T, S)
    parent, j0, jtype, jdadr = t.parent, t.j0, t.jtype, t.jdadr
    nb = parent.shape[0]
    for i in range(6):
        V[0, i] = 0.0
        A[0, i] = 0.0
    for i in range(3):
        A[0, 3 + i] = -g[i]  # the base accelerates upwards at g: gravity on every body
    for b in range(1, nb):
        p = parent[b]
        for i in range(6):
            V[b, i] = V[p, i]
            A[b, i] = A[p, i]
        for k in range(j0[b], j0[b + 1]):
            typ, da = jtype[k], jdadr[k]
            if typ <= 1:  # the axis is carried by the frame before the joint
                _add_motion_cross(V[b], S[da], qd[da], A[b])
                for i in range(6):
                    A[b, i] += S[da, i] * qdd[da]
                    V[b, i] += S[da, i] * qd[da]
            elif typ == 2:  # ball: the frame after it carries its axes
                for cc in range(3):
                    for i in range(6):
                        V[b, i] += S[da + cc, i] * qd[da + cc]
                for cc in range(3):
                    _add_motion_cross(V[b], S[da + cc], qd[da + cc], A[b])
                    for i in range(6):
                        A[b, i] += S[da + cc, i] * qdd[da + cc]
            else:  # free (top level): translations fixed in the world, rotations the body's own
                for cc in range(6):
                    for i in range(6):
                        V[b, i] += S[da + cc, i] * qd[da + cc]
                for cc in range(6):
                    if cc >= 3:
                        _add_motion_cross(V[b], S[da + cc], qd[da + cc], A[b])
                    for i in range(6):
                        A[b, i] += S[da + cc, i] * qdd[da + cc]
    for b in range(nb):
        if mass[b] == 0.0 and inertia[b, 0, 0] == 0.0 and inertia[b, 1, 1] == 0.0 and inertia[b, 2, 2] == 0.0:
            for i in range(6):
                F[b, i] = 0.0
            continue
        _inertia_world(T, mass, com, inertia, b, c, Ic)
        _apply(mass[b], c, Ic, A[b], F[b])
        _apply(mass[b], c, Ic, V[b], h)
        w0, w1, w2, v0, v1, v2 = V[b, 0], V[b, 1], V[b, 2], V[b, 3], V[b, 4], V[b, 5]
        n0, n1, n2, f0, f1, f2 = h[0], h[1], h[2], h[3], h[4], h[5]
        F[b, 0] += w1 * n2 - w2 * n1 + v1 * f2 - v2 * f1
        F[b, 1] += w2 * n0 - w0 * n2 + v2 * f0 - v0 * f2
        F[b, 2] += w0 * n1 - w1 * n0 + v0 * f1 - v1 * f0
        F[b, 3] += w1 * f2 - w2 * f1
        F[b, 4] += w2 * f0 - w0 * f2
        F[b, 5] += w0 * f1 - w1 * f0
    for b in range(nb - 1, 0, -1):  # backward pass: each subtree's wrench into its parent
        for i in range(6):
            F[parent[b], i] += F[b, i]
    for k in range(out.shape[0]):
        s = 0.0
        for i in range(6):
            s += S[k, i] * F[dof_body[k], i]
        out[k] = s


@_nj
def rnea_block(Q, QD, QDD, g, lo, hi, t, mass, com, inertia, dof_body, out):  # pragma: no cover
    nb, nv = t.parent.shape[0], QD.shape[1]
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    V = np.empty((nb, 6))
    A = np.empty((nb, 6))
    F = np.empty((nb, 6))
    tmp = np.empty(6)
    h = np.empty(6)
    c = np.empty(3)
    Ic = np.empty((3, 3))
    for n in range(lo, hi):
        rnea_sample(
            Q[n], QD[n], QDD[n], g, t, mass, com, inertia, dof_body, T, S, V, A, F, tmp, h, c, Ic, out[n]
        )


@numba.njit(cache=True, error_model="numpy", parallel=True)
def rnea_par(Q, QD, QDD, g, t, mass, com, inertia, dof_body, out):  # pragma: no cover
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        rnea_block(Q, QD, QDD, g, k * BLOCK, min(N, (k + 1) * BLOCK), t, mass, com, inertia, dof_body, out)


@_nj
def crba_block(Q, lo, hi, t, mass, com, inertia, dof_body, Aanc, out):  # pragma: no cover
    nb, nv = t.parent.shape[0], out.shape[1]
    parent = t.parent
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    I6 = np.empty((nb, 6, 6))
    X = np.empty(6)
    col = np.empty(6)
    c = np.empty(3)
    Ic = np.empty((3, 3))
    Fi = np.empty(6)
    for n in range(lo, hi):
        kin(Q[n], t, T, S)
        for b in range(nb):
            _inertia_world(T, mass, com, inertia, b, c, Ic)
            for j in range(6):
                for i in range(6):
                    X[i] = 1.0 if i == j else 0.0
                _apply(mass[b], c, Ic, X, col)
                for i in range(6):
                    I6[b, i, j] = col[i]
        for b in range(nb - 1, 0, -1):  # composite inertias
            for i in range(6):
                for j in range(6):
                    I6[parent[b], i, j] += I6[b, i, j]
        M = out[n]
        for i in range(nv):
            bi = dof_body[i]
            for r in range(6):
                s = 0.0
                for m in range(6):
                    s += I6[bi, r, m] * S[i, m]
                Fi[r] = s
            for j in range(nv):
                if Aanc[bi, j] != 0.0:
                    s = 0.0
                    for r in range(6):
                        s += Fi[r] * S[j, r]
                    M[i, j] = s
                    M[j, i] = s
                elif Aanc[dof_body[j], i] == 0.0:
                    M[i, j] = 0.0


@numba.njit(cache=True, error_model="numpy", parallel=True)
def crba_par(Q, t, mass, com, inertia, dof_body, Aanc, out):  # pragma: no cover
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        crba_block(Q, k * BLOCK, min(N, (k + 1) * BLOCK), t, mass, com, inertia, dof_body, Aanc, out)


def rnea_batch(model, bi, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, g: np.ndarray) -> np.ndarray:
    """``(N, nv)`` tree inverse dynamics of the compiled ``model`` with inertias ``bi`` (``_rnea``)."""
    tree = model.tree
    f = np.ascontiguousarray
    Q, QD, QDD = f(q, dtype=np.float64), f(qd, dtype=np.float64), f(qdd, dtype=np.float64)
    out = np.empty((Q.shape[0], tree.nv))
    args = (model.tables, f(bi.mass), f(bi.com), f(bi.inertia), tree.dof_body.astype(np.int64), out)
    gv = f(g, dtype=np.float64)
    if Q.shape[0] <= BLOCK:
        rnea_block(Q, QD, QDD, gv, 0, Q.shape[0], *args)
    else:
        rnea_par(Q, QD, QDD, gv, *args)
    return out


def crba_batch(model, bi, q: np.ndarray) -> np.ndarray:
    """``(N, nv, nv)`` tree mass matrix of the compiled ``model`` with inertias ``bi`` (``_rnea``)."""
    tree = model.tree
    f = np.ascontiguousarray
    Q = f(q, dtype=np.float64)
    out = np.empty((Q.shape[0], tree.nv, tree.nv))
    args = (
        model.tables,
        f(bi.mass),
        f(bi.com),
        f(bi.inertia),
        tree.dof_body.astype(np.int64),
        f(tree.A),
        out,
    )
    if Q.shape[0] <= BLOCK:
        crba_block(Q, 0, Q.shape[0], *args)
    else:
        crba_par(Q, *args)
    return out
