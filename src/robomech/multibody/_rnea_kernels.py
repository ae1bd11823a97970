"""Compiled (numba) per-sample kernel of the tree's composite-rigid-body algorithm (``_rnea``).

Per sample: the tree kinematics of ``_compiled.kin_ws`` (body poses and space screws), then the CRBA in
world coordinates as the module docstring of :mod:`._rnea` states it; large batches in parallel
blocks of ``_compiled.BLOCK`` samples (``numba.prange``).  The RNEA kernel is ``_compiled.rnea_block``.
"""

from __future__ import annotations

import numpy as np

from robomech._numba import import_numba

from ._compiled import (
    BLOCK,
    _inertia_apply,
    chol_solve,
    entry,
    inertia_world,
    kin_ws,
    prepare_one,
    rnea_block,
    writable,
)

__all__ = ["crba_batch", "fd_tree"]

numba = import_numba()
_nj = numba.njit(cache=True, error_model="numpy")


@_nj
def crba_block(Q, lo, hi, t, out):  # pragma: no cover
    """The composite-rigid-body mass matrix of samples ``lo:hi`` into ``out (N, nv, nv)`` (``t`` the
    compiled model's ``RneaTables``: the tree, its massive bodies, ``dof_body`` and the sparsity ``A``)."""
    nb, nv = t.parent.shape[0], out.shape[1]
    parent, dof_body, Aanc = t.parent, t.dof_body, t.A
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    I6 = np.empty((nb, 6, 6))
    X = np.empty(6)
    col = np.empty(6)
    c = np.empty(3)
    Ic = np.empty((3, 3))
    RI = np.empty((3, 3))
    Fi = np.empty(6)
    Rj = np.empty((3, 3))
    Rn = np.empty((3, 3))
    anchor = np.empty(3)
    for n in range(lo, hi):
        kin_ws(Q[n], t, T, S, Rj, Rn, anchor)
        I6[:, :, :] = 0.0
        for ib in range(t.bidx.shape[0]):  # bodies without mass or inertia stay zero
            b = t.bidx[ib]
            inertia_world(T, t, ib, c, Ic, RI)
            for j in range(6):
                for i in range(6):
                    X[i] = 1.0 if i == j else 0.0
                _inertia_apply(t.mass[ib], c, Ic, X, col)
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
def crba_par(Q, t, out):  # pragma: no cover
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        crba_block(Q, k * BLOCK, min(N, (k + 1) * BLOCK), t, out)


@_nj
def crba_one(q, t, qs, out):  # pragma: no cover - compiled
    """One sample, checked (``_compiled.prepare_one``), then :func:`crba_block` into ``out (nv, nv)``."""
    if prepare_one(q, (q,), t.jtype, t.jqadr, qs) != 0:
        return 1
    nv = out.shape[0]
    crba_block(qs.reshape(1, qs.shape[0]), 0, 1, t, out.reshape(1, nv, nv))
    return 0


def crba_batch(model, q: np.ndarray) -> np.ndarray:
    """``(N, nv, nv)`` tree mass matrix of the compiled ``model`` at normalised ``q (N, nq)``."""
    Q = writable(q)
    nv = model.tree.nv
    out = np.empty((Q.shape[0], nv, nv))
    if Q.shape[0] <= BLOCK:
        entry(model, crba_block, "crba_block", (Q, 0, Q.shape[0], model.rnea, out))
    else:
        crba_par(Q, model.rnea, out)
    return out


# ----------------------------------------------------------------------------- tree forward dynamics
@_nj
def mass_cond(M, H):  # pragma: no cover - compiled
    """The 2-norm condition number of ``M (n, n)`` (LAPACK singular values; non-finite entries read as
    0; inf where the smallest is 0); ``H (n, n)`` scratch."""
    n = M.shape[0]
    for i in range(n):
        for j in range(n):
            v = M[i, j]
            H[i, j] = v if np.isfinite(v) else 0.0
    s = np.linalg.svd(H)[1]
    return s[0] / s[n - 1] if s[n - 1] > 0 else np.inf


@_nj
def fd_tree_block(lo, hi, Q, QD, F, gv, t, qdd_o, cond_o):  # pragma: no cover - compiled
    """Forward dynamics of an open tree (no closure rows), samples ``lo:hi``: ``M qdd = F - b`` with
    ``M`` the CRBA mass matrix, ``b`` the RNEA forces at zero acceleration (velocity and gravity terms)
    and ``F (N, nv)`` the applied generalized forces, solved by Cholesky; ``cond_o`` the 2-norm
    condition number of ``M`` (singular values, LAPACK; inf where the smallest is 0)."""
    nv = QD.shape[1]
    M = np.empty((1, nv, nv))
    b = np.empty((1, nv))
    zero = np.zeros((1, nv))
    f = np.empty(nv)
    x = np.empty(nv)
    H = np.empty((nv, nv))
    for n in range(lo, hi):
        q1 = Q[n : n + 1]
        crba_block(q1, 0, 1, t, M)
        rnea_block(0, 1, q1, QD[n : n + 1], zero, gv, t, b)
        for i in range(nv):
            f[i] = -b[0, i] + F[n, i]
        cond_o[n] = mass_cond(M[0], H)
        for i in range(nv):
            for j in range(nv):
                H[i, j] = M[0, i, j]
        chol_solve(H, f, x)
        for i in range(nv):
            qdd_o[n, i] = x[i]


@numba.njit(cache=True, error_model="numpy", parallel=True)
def fd_tree_par(Q, QD, F, gv, t, qdd_o, cond_o):  # pragma: no cover - compiled
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        fd_tree_block(k * BLOCK, min(N, (k + 1) * BLOCK), Q, QD, F, gv, t, qdd_o, cond_o)


@_nj
def fd_tree_one(q, qd, F, gv, t, qs, qdd, cond):  # pragma: no cover - compiled
    """One sample, checked (``_compiled.prepare_one``), then :func:`fd_tree_block`."""
    if prepare_one(q, (qd, F), t.jtype, t.jqadr, qs) != 0:
        return 1
    nq, nv = qs.shape[0], qd.shape[0]
    fd_tree_block(
        0, 1, qs.reshape(1, nq), qd.reshape(1, nv), F.reshape(1, nv), gv, t, qdd.reshape(1, nv), cond
    )
    return 0


def fd_tree(model, q: np.ndarray, qd: np.ndarray, F: np.ndarray, gv: np.ndarray) -> tuple:
    """``(qdd (N, nv), cond (N,))`` of an open tree at normalised ``q (N, nq)`` (:func:`fd_tree_block`)."""
    Q, QD, FF, G = writable(q), writable(qd), writable(F), writable(gv)
    N = Q.shape[0]
    qdd, cond = np.empty((N, model.tree.nv)), np.empty(N)
    if N <= BLOCK:
        entry(model, fd_tree_block, "fd_tree_block", (0, N, Q, QD, FF, G, model.rnea, qdd, cond))
    else:
        fd_tree_par(Q, QD, FF, G, model.rnea, qdd, cond)
    return qdd, cond
