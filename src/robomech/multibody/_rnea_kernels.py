"""Compiled (numba) per-sample kernels of the tree's composite-rigid-body algorithm (``_rnea``) and of
forward dynamics.

Per sample: the tree kinematics of ``_compiled.kin_into`` (body poses and space screws), then the CRBA in
world coordinates as the module docstring of :mod:`._rnea` states it; forward dynamics of any
mechanism (:func:`fd_block`: the closure a constraint on the tree accelerations, ``_dynamics``' module
docstring) from the CRBA, the RNEA (``_compiled.rnea_block``), the closure rows and their
velocity-product accelerations (``_compiled.resjac``, ``_compiled.rates_kdot``); large batches in
parallel blocks of ``_compiled.BLOCK`` samples (``numba.prange``).  The numpy formulation is the tests'
reference (tests/multibody/_reference.py).
"""

from __future__ import annotations

import numpy as np

from robomech._numba import import_numba

from ._compiled import (
    BLOCK,
    _all_finite,
    _amax_abs,
    _inertia_apply,
    chol_solve,
    entry,
    inertia_world,
    influence_G,
    kin_into,
    pinv_rank,
    prepare_one,
    rates_kdot,
    resjac,
    rnea_block,
    site_forces,
    writable,
)

__all__ = ["crba_batch", "forward", "inverse_full"]

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
        kin_into(Q[n], t, T, S, Rj, Rn, anchor)
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
    """The 2-norm condition number of the symmetric ``M (n, n)`` (its absolute eigenvalues, LAPACK
    ``syevd``: values only, and it converges where ``gesdd`` may not on clustered values; non-finite
    entries read as 0; inf where the smallest is 0); ``H (n, n)`` scratch."""
    n = M.shape[0]
    for i in range(n):
        for j in range(n):
            v = M[i, j]
            H[i, j] = v if np.isfinite(v) else 0.0
    try:  # symmetric: the singular values are the absolute eigenvalues (LAPACK syevd, values only)
        e = np.abs(np.linalg.eigvalsh(H))
    except Exception:  # no convergence: the singular values (gesdd)
        e = np.linalg.svd(H)[1]
    hi, lo = np.max(e), np.min(e)
    return hi / lo if lo > 0 else np.inf


@_nj
def solve_constrained(M, f, K, kdq, rank, P, Pn, Mc, H, x, qdd):  # pragma: no cover - compiled
    """``qdd (nv,)`` of ``M qdd = f + K^T lambda`` with ``K qdd = -kdq`` (closure rows ``K (m, nv)``,
    ``m`` may be 0), the derivation of ``_dynamics``' module docstring: ``qdd = qdd_p + u`` with
    ``qdd_p = -K^+ kdq`` (``K^+`` truncated to the generic rank ``rank``) and ``u`` from
    ``Mc u = Pn (f - M qdd_p)``, ``Pn = I - K^+ K``, ``Mc = Pn M Pn + (I - Pn)`` (symmetric positive
    definite where ``M`` is on ``null(K)``: Cholesky).  Returns the 2-norm condition number of ``Mc``
    (:func:`mass_cond`); ``f`` is overwritten; ``P (nv, m)``, ``Pn``, ``Mc``, ``H (nv, nv)``, ``x (nv,)``
    scratch."""
    nv, m = M.shape[0], K.shape[0]
    if m == 0 or rank == 0:  # no closure: Pn = I, Mc = M
        cond = mass_cond(M, H)
        for i in range(nv):
            for j in range(nv):
                H[i, j] = M[i, j]
        chol_solve(H, f, qdd)
        return cond
    if not pinv_rank(K, rank, P):  # non-finite K or no LAPACK convergence: the sample is flagged
        qdd[:] = np.nan
        return np.inf
    for i in range(nv):  # qdd_p = -K^+ kdq, Pn = I - K^+ K
        acc = 0.0
        for j in range(m):
            acc += P[i, j] * kdq[j]
        qdd[i] = -acc
        for k in range(nv):
            acc = 0.0
            for j in range(m):
                acc += P[i, j] * K[j, k]
            Pn[i, k] = (1.0 if i == k else 0.0) - acc
    for i in range(nv):  # H = M Pn, x = f - M qdd_p
        acc2 = f[i]
        for k in range(nv):
            acc = 0.0
            for j in range(nv):
                acc += M[i, j] * Pn[j, k]
            H[i, k] = acc
            acc2 -= M[i, k] * qdd[k]
        x[i] = acc2
    for i in range(nv):  # Mc = Pn (M Pn) + (I - Pn)
        for k in range(nv):
            acc = 0.0
            for j in range(nv):
                acc += Pn[i, j] * H[j, k]
            Mc[i, k] = acc + ((1.0 if i == k else 0.0) - Pn[i, k])
    for i in range(nv):  # rhs = Pn (f - M qdd_p), into f
        acc = 0.0
        for j in range(nv):
            acc += Pn[i, j] * x[j]
        f[i] = acc
    cond = mass_cond(Mc, H)
    for i in range(nv):
        for j in range(nv):
            H[i, j] = Mc[i, j]
    chol_solve(H, f, x)
    for i in range(nv):
        qdd[i] += x[i]
    return cond


@_nj
def fd_tree_block(lo, hi, Q, QD, F, gv, t, qdd_o, cond_o):  # pragma: no cover - compiled
    """Forward dynamics of an open tree (no closure rows, no site wrench), samples ``lo:hi``:
    ``M qdd = F - b`` (:func:`solve_constrained` without rows) with ``M`` the CRBA mass matrix, ``b``
    the RNEA forces at zero acceleration (velocity and gravity terms) and ``F (N, nv)`` the applied
    generalized forces; ``cond_o`` the 2-norm condition number of ``M``."""
    nv = QD.shape[1]
    M = np.empty((1, nv, nv))
    b = np.empty((1, nv))
    zero = np.zeros((1, nv))
    f = np.empty(nv)
    x = np.empty(nv)
    H = np.empty((nv, nv))
    K0 = np.empty((0, nv))
    P0 = np.empty((nv, 0))
    for n in range(lo, hi):
        q1 = Q[n : n + 1]
        crba_block(q1, 0, 1, t, M)
        rnea_block(0, 1, q1, QD[n : n + 1], zero, gv, t, b)
        for i in range(nv):
            f[i] = -b[0, i] + F[n, i]
        cond_o[n] = solve_constrained(M[0], f, K0, f[:0], 0, P0, H, H, H, x, qdd_o[n])


@_nj
def fd_block(
    lo, hi, Q, R, F, W, wsb, wT, gv, act_mode, rank_K, t, rt, d, qd_o, qdd_o, cond_o, adm_o, clo_o, reg_o
):  # pragma: no cover - compiled
    """Forward dynamics of any mechanism, samples ``lo:hi``, the closure a constraint on the tree
    accelerations (:func:`solve_constrained`), with site wrenches ``W (N, ns, 6)`` on bodies ``wsb``
    at frames ``wT``, the applied generalized forces ``F (N, nv)`` and gravity ``gv``.  ``R`` the
    rates: ``(N, n_act)`` actuated rates (``act_mode``: ``qd = G qd_act``, ``G`` by ``_compiled.influence_G``,
    ``reg_o`` its rank and conditioning check) or ``(N, nv)`` every rate.  Outputs per
    sample: ``qd_o``, ``qdd_o (N, nv)``, ``cond_o`` (of the constrained mass matrix, or of the
    singular passive block against the generic rank if larger), ``adm_o`` (``|K qd|`` and
    ``|K qdd + Kdot qd|``, relative), ``clo_o`` (max closure row of ``q``) and ``reg_o``.  ``t``,
    ``rt``, ``d``: the compiled model's ``Tables``, ``RneaTables``, ``DynTables``."""
    nb = t.parent.shape[0]
    A, m, L = t.A, t.m, t.L
    nv = A.shape[1]
    act, pas = d.act, d.pas
    na, npas = act.shape[0], pas.shape[0]
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    Rj = np.empty((3, 3))
    Rn = np.empty((3, 3))
    anchor = np.empty(3)
    r = np.empty(m)
    K = np.empty((m, nv))
    Kp = np.empty((m, npas))
    Pp = np.empty((npas, m))
    Gq = np.empty((nv, na))
    qd = np.empty((1, nv))
    Sd = np.empty((nv, 6))
    V = np.empty((nb, 6))
    Vd = np.empty((nb, 6))
    kdq = np.zeros(m)
    M = np.empty((1, nv, nv))
    b = np.empty((1, nv))
    zero = np.zeros((1, nv))
    f = np.empty(nv)
    ext = np.empty(nv)
    ps = np.empty(3)
    P = np.empty((nv, m))
    Pn = np.empty((nv, nv))
    Mc = np.empty((nv, nv))
    H = np.empty((nv, nv))
    x = np.empty(nv)
    qdd = np.empty(nv)
    for n in range(lo, hi):
        q = Q[n]
        kin_into(q, t, T, S, Rj, Rn, anchor)
        resjac(q, t, T, S, r, K, True)
        clo_o[n] = _amax_abs(r)
        reg = True
        e1 = 0.0
        if act_mode:  # qd = G qd_act, G = [I; -K_p^+ K_a] (_compiled.influence_G)
            rank, _, cK = influence_G(K, act, pas, d.pinv_rtol, L, Kp, Pp, Gq)
            reg = rank >= d.rank0 and cK <= d.singular_cond
            for k in range(nv):
                acc = 0.0
                for j in range(na):
                    acc += Gq[k, j] * R[n, j]
                qd[0, k] = acc
        else:
            for i in range(nv):
                qd[0, i] = R[n, i]
            if m > 0:
                sv = _amax_abs(qd[0])
                for i in range(m):
                    acc = 0.0
                    for k in range(nv):
                        acc += K[i, k] * qd[0, k]
                    r[i] = acc
                e1 = _amax_abs(r) / (L * max(sv, d.rate_floor))
        if m > 0:
            rates_kdot(q, t, T, S, qd[0], Sd, V, Vd, kdq)
        q1 = Q[n : n + 1]
        crba_block(q1, 0, 1, rt, M)
        rnea_block(0, 1, q1, qd, zero, gv, rt, b)
        site_forces(T, S, A, W[n], wsb, wT, ps, ext)
        for i in range(nv):
            f[i] = F[n, i] - b[0, i] - ext[i]
        cond = solve_constrained(M[0], f, K, kdq, rank_K, P, Pn, Mc, H, x, qdd)
        e2 = 0.0
        if m > 0:
            sa = _amax_abs(qdd) + _amax_abs(qd[0]) ** 2
            for i in range(m):
                acc = kdq[i]
                for k in range(nv):
                    acc += K[i, k] * qdd[k]
                r[i] = acc
            e2 = _amax_abs(r) / (L * max(sa, d.rate_floor))
        adm_o[n] = max(e1, e2) if np.isfinite(e2) else np.inf
        if act_mode and not reg:  # a singular passive block: its measure against the generic rank
            cond = max(cond, rank_cond(Kp, d.rank0))
        for i in range(nv):
            qd_o[n, i] = qd[0, i]
            qdd_o[n, i] = qdd[i]
        cond_o[n] = cond
        reg_o[n] = reg


@_nj
def _nanmax(a, b):  # pragma: no cover - compiled
    """max(a, b) with NaN propagated (numpy's ``maximum``)."""
    if a != a or b != b:
        return np.nan
    return a if a > b else b


@_nj
def null_basis(K, r, Nb):  # pragma: no cover - compiled
    """An orthonormal basis ``Nb (nv, nv - r)`` of ``null(K)`` at the rank ``r`` (the trailing right
    singular vectors of ``K (m, nv)``); returns ``s_1 / s_r`` (inf where ``s_r`` is 0), or -1 where
    ``K`` is not finite or LAPACK does not converge."""
    if not _all_finite(K):
        return -1.0
    try:
        _, sK, Vt = np.linalg.svd(K, full_matrices=True)
    except Exception:  # no convergence (LAPACK)
        return -1.0
    nv, dd = Nb.shape
    for i in range(nv):
        for j in range(dd):
            Nb[i, j] = Vt[r + j, i]
    sr = sK[r - 1]
    return sK[0] / sr if sr > 0 else np.inf


@_nj
def inv_full_block(
    lo, hi, Q, QD, QDD, W, wsb, wT, gv, ws, rank_K, t, rt, d,
    tau_o, Ma_o, vel_o, grav_o, ext_o, cond_o, smin_o, adm_o, unact_o, clo_o, comp_o, valid_o,
):  # pragma: no cover - compiled  # fmt: skip
    """Inverse dynamics from every coordinate's rates and accelerations, samples ``lo:hi`` (``_dynamics``'
    module docstring, "Every kinematic class"): the tree's generalized forces ``f = M qdd + c + g -
    J_s^T W`` in parts (CRBA, RNEA, :func:`site_forces`), an orthonormal basis ``Nb`` of ``null(K)`` at the
    generic rank ``rank_K`` (SVD), ``tau = B f`` with ``B = ws pinv(Nb_a^T ws) Nb^T`` (``ws`` the square
    roots of the weights, ones for minimum norm), ``unact = Nb (Nb^T f - Nb_a^T tau)``, the admissibility
    (``|K qd|``, ``|K qdd + Kdot qd|``, the size of ``unact`` against the largest part), ``M_a = B M B^T``
    and ``cond = max(cond K, cond of Nb_a^T ws)``; ``comp_o``: forces finite and not singular."""
    nb = t.parent.shape[0]
    A, m, L = t.A, t.m, t.L
    nv = A.shape[1]
    act = d.act
    na = act.shape[0]
    r_ = rank_K if m > 0 else 0
    dd = nv - r_
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    Rj = np.empty((3, 3))
    Rn = np.empty((3, 3))
    anchor = np.empty(3)
    r = np.empty(m)
    K = np.empty((m, nv))
    Sd = np.empty((nv, 6))
    V = np.empty((nb, 6))
    Vd = np.empty((nb, 6))
    kdq = np.zeros(m)
    M = np.empty((1, nv, nv))
    fv = np.empty((1, nv))
    fg = np.empty((1, nv))
    zero = np.zeros((1, nv))
    z3 = np.zeros(3)
    ext = np.empty(nv)
    ps = np.empty(3)
    parts = np.empty((4, nv))
    f = np.empty(nv)
    Nb = np.empty((nv, dd))
    Aw = np.empty((dd, na))
    B = np.zeros((na, nv))
    tp = np.empty((4, na))
    tau = np.empty(na)
    bb = np.empty(dd)
    un = np.empty(nv)
    BM = np.empty((na, nv))
    res = np.empty(m)
    for n in range(lo, hi):
        q = Q[n]
        qd = QD[n]
        qdd = QDD[n]
        kin_into(q, t, T, S, Rj, Rn, anchor)
        resjac(q, t, T, S, r, K, True)
        clo_o[n] = _amax_abs(r)
        if m > 0:
            rates_kdot(q, t, T, S, qd, Sd, V, Vd, kdq)
        q1 = Q[n : n + 1]
        crba_block(q1, 0, 1, rt, M)
        rnea_block(0, 1, q1, QD[n : n + 1], zero, z3, rt, fv)
        rnea_block(0, 1, q1, zero, zero, gv, rt, fg)
        site_forces(T, S, A, W[n], wsb, wT, ps, ext)
        scale = 0.0
        for i in range(nv):
            acc = 0.0
            for j in range(nv):
                acc += M[0, i, j] * qdd[j]
            parts[0, i] = acc
            parts[1, i] = fv[0, i]
            parts[2, i] = fg[0, i]
            parts[3, i] = ext[i]
            f[i] = parts[0, i] + parts[1, i] + parts[2, i] + parts[3, i]
            for c in range(4):
                scale = _nanmax(scale, abs(parts[c, i]))
        # the admissible motions: an orthonormal basis of null(K) at the generic rank
        condK = 1.0
        if r_ == 0:
            for i in range(nv):
                for j in range(dd):
                    Nb[i, j] = 1.0 if i == j else 0.0
        else:
            condK = null_basis(K, r_, Nb)
            if condK < 0.0:  # non-finite K or no LAPACK convergence: the sample is flagged
                tau_o[n] = np.nan
                Ma_o[n] = np.nan
                vel_o[n] = np.nan
                grav_o[n] = np.nan
                ext_o[n] = np.nan
                unact_o[n] = np.nan
                cond_o[n] = np.inf
                smin_o[n] = np.nan
                adm_o[n] = np.nan
                comp_o[n] = False
                valid_o[n] = False
                continue
        # the least-squares rule on the actuated rows of the admissible motions
        smin, cond_a = 1.0, 1.0
        B[:, :] = 0.0
        if na > 0 and dd > 0:
            for i in range(dd):
                for j in range(na):
                    Aw[i, j] = Nb[act[j], i] * ws[j]
            if _all_finite(Aw):
                sA = np.linalg.svd(Aw)[1]
                smin = sA[sA.shape[0] - 1]
                cond_a = sA[0] / (smin if smin > 0 else 1.0) if smin > d.rank_rtol * sA[0] else np.inf
                Ap = np.linalg.pinv(Aw, d.rank_rtol)  # (na, dd)
                for j in range(na):
                    for k in range(nv):
                        acc = 0.0
                        for i in range(dd):
                            acc += Ap[j, i] * Nb[k, i]
                        B[j, k] = ws[j] * acc
            else:
                smin, cond_a = np.nan, np.nan
                B[:, :] = np.nan
        for c in range(4):
            for j in range(na):
                acc = 0.0
                for k in range(nv):
                    acc += B[j, k] * parts[c, k]
                tp[c, j] = acc
        for j in range(na):
            tau[j] = tp[0, j] + tp[1, j] + tp[2, j] + tp[3, j]
        for i in range(dd):
            acc = 0.0
            for k in range(nv):
                acc += Nb[k, i] * f[k]
            for j in range(na):
                acc -= Nb[act[j], i] * tau[j]
            bb[i] = acc
        for k in range(nv):
            acc = 0.0
            for i in range(dd):
                acc += Nb[k, i] * bb[i]
            un[k] = acc
        e_force = _amax_abs(un) / max(scale, 1e-300) if nv > 0 else 0.0
        adm = e_force
        if m > 0:
            sv = _amax_abs(qd)
            sa = _amax_abs(qdd) + sv * sv
            for i in range(m):
                acc = 0.0
                for k in range(nv):
                    acc += K[i, k] * qd[k]
                r[i] = acc
            e1 = _amax_abs(r) / (L * max(sv, d.rate_floor))
            for i in range(m):
                acc = kdq[i]
                for k in range(nv):
                    acc += K[i, k] * qdd[k]
                res[i] = acc
            e2 = _amax_abs(res) / (L * max(sa, d.rate_floor))
            adm = _nanmax(_nanmax(e1, e2), e_force)
        for j in range(na):
            for k in range(nv):
                acc = 0.0
                for i in range(nv):
                    acc += B[j, i] * M[0, i, k]
                BM[j, k] = acc
        for j in range(na):
            for c in range(na):
                acc = 0.0
                for k in range(nv):
                    acc += BM[j, k] * B[c, k]
                Ma_o[n, j, c] = acc
        cond = _nanmax(condK, cond_a)
        fin = _all_finite(tau) and _all_finite(Ma_o[n])
        comp = fin and cond <= d.singular_cond
        for j in range(na):
            tau_o[n, j] = tau[j]
            vel_o[n, j] = tp[1, j]
            grav_o[n, j] = tp[2, j]
            ext_o[n, j] = tp[3, j]
        for k in range(nv):
            unact_o[n, k] = un[k]
        cond_o[n] = cond
        smin_o[n] = L * smin
        adm_o[n] = adm
        comp_o[n] = comp
        valid_o[n] = comp and adm <= d.admissible_rtol


@numba.njit(cache=True, error_model="numpy", parallel=True)
def inv_full_par(
    Q, QD, QDD, W, wsb, wT, gv, ws, rank_K, t, rt, d,
    tau_o, Ma_o, vel_o, grav_o, ext_o, cond_o, smin_o, adm_o, unact_o, clo_o, comp_o, valid_o,
):  # pragma: no cover - compiled  # fmt: skip
    """:func:`inv_full_block` over ``Q`` in blocks of ``BLOCK`` samples, in parallel."""
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        inv_full_block(
            k * BLOCK, min(N, (k + 1) * BLOCK), Q, QD, QDD, W, wsb, wT, gv, ws, rank_K, t, rt, d,
            tau_o, Ma_o, vel_o, grav_o, ext_o, cond_o, smin_o, adm_o, unact_o, clo_o, comp_o, valid_o,
        )  # fmt: skip


def inverse_full(model, q, qd, qdd, W, wsb, wT, gv, weights, out: dict) -> dict:
    """:func:`inv_full_block` on every sample (normalised ``q (N, nq)``, ``qd``, ``qdd (N, nv)``, site
    wrenches packed as ``_dynamics._wrench_arrays``, ``weights (n_act,)`` or None) into ``out`` (the
    kernel's outputs in its argument order, ``_dynamics._id_outputs``), returned with ``qd`` and ``qdd``
    copied; one block in this thread for a small batch, parallel blocks for a large one (the same
    per-sample code either way)."""
    Q, QD, QDD, WW = writable(q), writable(qd), writable(qdd), writable(W)
    N, na = Q.shape[0], len(model.act)
    ws = np.ones(na) if weights is None else np.sqrt(np.asarray(weights, dtype=float))
    args = (Q, QD, QDD, WW, wsb, wT, writable(gv), ws, model.rank_K, model.tables, model.rnea, model.dyn)
    if N <= BLOCK:
        entry(model, inv_full_block, "inv_full_block", (0, N, *args, *out.values()))
    else:
        inv_full_par(*args, *out.values())
    out["qd"], out["qdd"] = QD.copy(), QDD.copy()
    return out


@_nj
def rank_measures(Kp, rank0, L):  # pragma: no cover - compiled
    """``(s_rank0, s_1 / s_rank0)`` of ``Kp (m, n)`` against the mechanism's generic passive rank
    ``rank0`` (non-finite entries read as 0; cond inf where ``s_rank0`` is 0, or where LAPACK does not
    converge).  A truncated pseudo-inverse keeps only the non-zero values, so its own ratio is 1 at a
    rank drop (a type II singularity); this is the measure reported wherever a sample is not valid.  An
    empty block or a generic rank 0: ``(L, 1)``, as ``_compiled.influence_G`` has it."""
    m, n = Kp.shape
    if m == 0 or n == 0 or rank0 == 0:
        return L, 1.0
    H = np.empty((m, n))
    for i in range(m):
        for j in range(n):
            v = Kp[i, j]
            H[i, j] = v if np.isfinite(v) else 0.0
    try:
        s = np.linalg.svd(H)[1]
    except Exception:  # no convergence (LAPACK): no measure
        return 0.0, np.inf
    sr = s[rank0 - 1] if s.shape[0] >= rank0 else 0.0
    return sr, (s[0] / sr if sr > 0 else np.inf)


@_nj
def rank_cond(Kp, rank0):  # pragma: no cover - compiled
    """The conditioning of :func:`rank_measures` (1 for an empty block or a generic rank 0)."""
    return rank_measures(Kp, rank0, 1.0)[1]


@_nj
def rank_measures_block(Q, lo, hi, pas, rank0, t, smin_o, cond_o):  # pragma: no cover - compiled
    """:func:`rank_measures` of the passive block ``K_p`` at each configuration ``Q[lo:hi]``."""
    nb = t.parent.shape[0]
    m = t.m
    nv = t.A.shape[1]
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    Rj = np.empty((3, 3))
    Rn = np.empty((3, 3))
    anchor = np.empty(3)
    r = np.empty(m)
    K = np.empty((m, nv))
    Kp = np.empty((m, pas.shape[0]))
    for n in range(lo, hi):
        kin_into(Q[n], t, T, S, Rj, Rn, anchor)
        resjac(Q[n], t, T, S, r, K, True)
        for i in range(m):
            for j in range(pas.shape[0]):
                Kp[i, j] = K[i, pas[j]]
        smin_o[n], cond_o[n] = rank_measures(Kp, rank0, t.L)


def passive_rank_measures(model, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(sigma_min, cond)`` of :func:`rank_measures` at ``q (N, nq)`` (the samples that are not valid)."""
    Q = writable(q)
    N = Q.shape[0]
    smin, cond = np.empty(N), np.empty(N)
    entry(
        model,
        rank_measures_block,
        "rank_measures_block",
        (Q, 0, N, model.pas, model.rank0, model.tables, smin, cond),
    )
    return smin, cond


@numba.njit(cache=True, error_model="numpy", parallel=True)
def fd_par(
    Q, R, F, W, wsb, wT, gv, act_mode, rank_K, t, rt, d, qd_o, qdd_o, cond_o, adm_o, clo_o, reg_o
):  # pragma: no cover - compiled
    """:func:`fd_block` over ``Q`` in blocks of ``BLOCK`` samples, in parallel."""
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        fd_block(
            k * BLOCK,
            min(N, (k + 1) * BLOCK),
            Q,
            R,
            F,
            W,
            wsb,
            wT,
            gv,
            act_mode,
            rank_K,
            t,
            rt,
            d,
            qd_o,
            qdd_o,
            cond_o,
            adm_o,
            clo_o,
            reg_o,
        )


def forward(model, q, rates, F, W, wsb, wT, gv, act_mode: bool) -> tuple:
    """:func:`fd_block` on every sample (normalised ``q (N, nq)``): ``(qd, qdd, cond, adm, closure,
    regular)``; one block in this thread for a small batch, parallel blocks for a large one (the same
    per-sample code either way)."""
    Q, Rt, FF, WW, G = writable(q), writable(rates), writable(F), writable(W), writable(gv)
    N, nv = Q.shape[0], model.tree.nv
    outs = (
        np.empty((N, nv)),
        np.empty((N, nv)),
        np.empty(N),
        np.empty(N),
        np.empty(N),
        np.empty(N, np.bool_),
    )
    args = (Q, Rt, FF, WW, wsb, wT, G, act_mode, model.rank_K, model.tables, model.rnea, model.dyn, *outs)
    if N <= BLOCK:
        entry(model, fd_block, f"fd_block_{act_mode}", (0, N, *args))
    else:
        fd_par(*args)
    return outs


@_nj
def fd_tree_one(q, qd, F, gv, t, qs, qdd, cond):  # pragma: no cover - compiled
    """One sample of an open tree without site wrenches, checked (``_compiled.prepare_one``), then
    :func:`fd_tree_block` (fewer tables to pass than :func:`fd_block`, the same per-sample code)."""
    if prepare_one(q, (qd, F), t.jtype, t.jqadr, qs) != 0:
        return 1
    nq, nv = qs.shape[0], qd.shape[0]
    fd_tree_block(
        0, 1, qs.reshape(1, nq), qd.reshape(1, nv), F.reshape(1, nv), gv, t, qdd.reshape(1, nv), cond
    )
    return 0
