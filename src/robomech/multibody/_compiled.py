"""Compiled (numba) per-sample kernels for large batches: forward kinematics and site Jacobians.

The same algorithms as the numpy path (``_tree``, ``_constraints``, ``_assembly``, ``_influence``),
written per sample in one parallel loop over the batch: tree kinematics, closure residual and
velocity constraint matrix, the Levenberg–Marquardt assembly with the same damping, step cap and
stopping rules, and ``G = [I; -K_p^+ K_a]`` with the site's ``[ω; ṗ]`` Jacobian.  A numpy batch pays
one Python-level operation per body and per closure on arrays of the whole batch; here every sample
stays in cache.  The tests check that both paths agree to rounding.  This module (and numba) loads
on the first large call.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._numba import import_numba

from ._assembly import COMPILED_MIN, MAX_ITER, MAX_STEP, MU_MAX, MU_MIN, MU_START, STOP_RTOL
from ._influence import PASSIVE_RANK_RTOL

__all__ = ["COMPILED_MIN", "Tables", "compiled_fk", "compiled_site_jacobian", "tables"]

# this module is imported on the first large batch only; the kernel cache lives in robomech's cache dir
numba = import_numba()


@dataclass(frozen=True, eq=False)
class Tables:
    parent: np.ndarray
    T_off: np.ndarray
    body_j0: np.ndarray  # (nb + 1,) joints of body b are body_j0[b]:body_j0[b + 1]
    jtype: np.ndarray
    jqadr: np.ndarray
    jdadr: np.ndarray
    jpos: np.ndarray
    jaxis: np.ndarray
    jref: np.ndarray
    A: np.ndarray
    dof_tr: np.ndarray
    # closure rows
    pp: np.ndarray  # (np, 3) int: b1, b2, first row
    px: np.ndarray  # (np, 2, 3) local points
    rr: np.ndarray  # (nr, 3) int: b1, b2, first row
    rR: np.ndarray  # (nr, 3, 3)
    cc: np.ndarray  # (nc, 5) int: d1, q1, d2, q2, row
    cf: np.ndarray  # (nc, 8) float: ref1, ref2, c0..c4, scale
    geom_row: np.ndarray  # (m,) bool
    m: int
    L: float


def tables(mech) -> Tables:
    tree, cs = mech.tree, mech.constraints
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
        body_j0=j0,
        jtype=tree.jnt_type.astype(np.int64),
        jqadr=tree.jnt_qadr.astype(np.int64),
        jdadr=tree.jnt_dadr.astype(np.int64),
        jpos=np.ascontiguousarray(tree.jnt_pos),
        jaxis=np.ascontiguousarray(tree.jnt_axis),
        jref=tree.jnt_ref.astype(float),
        A=np.ascontiguousarray(tree.A),
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


def _args(t: Tables) -> tuple:
    return (
        t.parent,
        t.T_off,
        t.body_j0,
        t.jtype,
        t.jqadr,
        t.jdadr,
        t.jpos,
        t.jaxis,
        t.jref,
        t.A,
        t.pp,
        t.px,
        t.rr,
        t.rR,
        t.cc,
        t.cf,
        t.m,
        t.L,
    )


_nj = numba.njit(cache=True, error_model="numpy")
# Site Jacobian: Tikhonov weight of the passive normal equations relative to their mean diagonal,
# and the refinement steps that remove its bias (each multiplies it by eps / sigma^2 <= 1e-8 / 1e-4
# for sigma_min / sigma_max >= 1e-2; three solves leave ~1e-18 relative).
REG = 1e-8
REFINE = 2


@_nj
def quat_mat(w, x, y, z, R):  # pragma: no cover - compiled
    R[0, 0] = 1 - 2 * (y * y + z * z)
    R[0, 1] = 2 * (x * y - w * z)
    R[0, 2] = 2 * (x * z + w * y)
    R[1, 0] = 2 * (x * y + w * z)
    R[1, 1] = 1 - 2 * (x * x + z * z)
    R[1, 2] = 2 * (y * z - w * x)
    R[2, 0] = 2 * (x * z - w * y)
    R[2, 1] = 2 * (y * z + w * x)
    R[2, 2] = 1 - 2 * (x * x + y * y)


@_nj
def kin(q, parent, T_off, j0, jtype, jqadr, jdadr, jpos, jaxis, jref, T, S):  # pragma: no cover
    nb = parent.shape[0]
    for i in range(4):
        for j in range(4):
            T[0, i, j] = 1.0 if i == j else 0.0
    Rj = np.empty((3, 3))
    Rn = np.empty((3, 3))
    anchor = np.empty(3)
    for b in range(1, nb):
        pb = parent[b]
        for i in range(4):
            for j in range(4):
                T[b, i, j] = (
                    T[pb, i, 0] * T_off[b, 0, j]
                    + T[pb, i, 1] * T_off[b, 1, j]
                    + T[pb, i, 2] * T_off[b, 2, j]
                    + T[pb, i, 3] * T_off[b, 3, j]
                )
        for k in range(j0[b], j0[b + 1]):
            typ, qa, da = jtype[k], jqadr[k], jdadr[k]
            if typ == 0 or typ == 2:
                for i in range(3):
                    anchor[i] = (
                        T[b, i, 3]
                        + T[b, i, 0] * jpos[k, 0]
                        + T[b, i, 1] * jpos[k, 1]
                        + T[b, i, 2] * jpos[k, 2]
                    )
                if typ == 0:
                    ax = jaxis[k]
                    th = q[qa] - jref[k]
                    s, c = np.sin(th), np.cos(th)
                    # Rodrigues: c I + s [a]x + (1 - c) a a^T (= axis_angle_matrix for a unit axis)
                    a0, a1, a2 = ax[0], ax[1], ax[2]
                    v = 1.0 - c
                    Rj[0, 0], Rj[0, 1], Rj[0, 2] = c + v * a0 * a0, v * a0 * a1 - s * a2, v * a0 * a2 + s * a1
                    Rj[1, 0], Rj[1, 1], Rj[1, 2] = v * a1 * a0 + s * a2, c + v * a1 * a1, v * a1 * a2 - s * a0
                    Rj[2, 0], Rj[2, 1], Rj[2, 2] = v * a2 * a0 - s * a1, v * a2 * a1 + s * a0, c + v * a2 * a2
                    for i in range(3):  # world axis before the rotation
                        w = T[b, i, 0] * ax[0] + T[b, i, 1] * ax[1] + T[b, i, 2] * ax[2]
                        S[da, i] = w
                else:
                    quat_mat(q[qa], q[qa + 1], q[qa + 2], q[qa + 3], Rj)
                for i in range(3):
                    for j in range(3):
                        Rn[i, j] = T[b, i, 0] * Rj[0, j] + T[b, i, 1] * Rj[1, j] + T[b, i, 2] * Rj[2, j]
                for i in range(3):
                    for j in range(3):
                        T[b, i, j] = Rn[i, j]
                    T[b, i, 3] = anchor[i] - (
                        Rn[i, 0] * jpos[k, 0] + Rn[i, 1] * jpos[k, 1] + Rn[i, 2] * jpos[k, 2]
                    )
                if typ == 0:
                    w0, w1, w2 = S[da, 0], S[da, 1], S[da, 2]
                    S[da, 3] = anchor[1] * w2 - anchor[2] * w1
                    S[da, 4] = anchor[2] * w0 - anchor[0] * w2
                    S[da, 5] = anchor[0] * w1 - anchor[1] * w0
                else:
                    for c in range(3):
                        w0, w1, w2 = Rn[0, c], Rn[1, c], Rn[2, c]
                        S[da + c, 0], S[da + c, 1], S[da + c, 2] = w0, w1, w2
                        S[da + c, 3] = anchor[1] * w2 - anchor[2] * w1
                        S[da + c, 4] = anchor[2] * w0 - anchor[0] * w2
                        S[da + c, 5] = anchor[0] * w1 - anchor[1] * w0
            elif typ == 1:
                ax = jaxis[k]
                d = q[qa] - jref[k]
                for i in range(3):
                    w = T[b, i, 0] * ax[0] + T[b, i, 1] * ax[1] + T[b, i, 2] * ax[2]
                    S[da, i] = 0.0
                    S[da, 3 + i] = w
                    T[b, i, 3] += w * d
            else:
                quat_mat(q[qa + 3], q[qa + 4], q[qa + 5], q[qa + 6], Rn)
                for i in range(3):
                    for j in range(3):
                        T[b, i, j] = Rn[i, j]
                    T[b, i, 3] = q[qa + i]
                    T[b, 3, i] = 0.0
                T[b, 3, 3] = 1.0
                p0, p1, p2 = q[qa], q[qa + 1], q[qa + 2]
                for c in range(3):
                    for i in range(6):
                        S[da + c, i] = 0.0
                    S[da + c, 3 + c] = 1.0
                    w0, w1, w2 = Rn[0, c], Rn[1, c], Rn[2, c]
                    S[da + 3 + c, 0], S[da + 3 + c, 1], S[da + 3 + c, 2] = w0, w1, w2
                    S[da + 3 + c, 3] = p1 * w2 - p2 * w1
                    S[da + 3 + c, 4] = p2 * w0 - p0 * w2
                    S[da + 3 + c, 5] = p0 * w1 - p1 * w0


@_nj
def point_rows(T, S, A, b, x, sign, row, K, r, with_jac):  # pragma: no cover
    p = np.empty(3)
    for i in range(3):
        p[i] = T[b, i, 3] + T[b, i, 0] * x[0] + T[b, i, 1] * x[1] + T[b, i, 2] * x[2]
        r[row + i] += sign * p[i]
    if with_jac:
        nv = S.shape[0]
        for k in range(nv):
            if A[b, k] != 0.0:
                w0, w1, w2 = S[k, 0], S[k, 1], S[k, 2]
                K[row, k] += sign * (S[k, 3] + w1 * p[2] - w2 * p[1])
                K[row + 1, k] += sign * (S[k, 4] + w2 * p[0] - w0 * p[2])
                K[row + 2, k] += sign * (S[k, 5] + w0 * p[1] - w1 * p[0])


@_nj
def resjac(q, T, S, A, pp, px, rr, rR, cc, cf, L, r, K, with_jac):  # pragma: no cover
    r[:] = 0.0
    if with_jac:
        K[:, :] = 0.0
    nv = S.shape[0]
    for i in range(pp.shape[0]):
        point_rows(T, S, A, pp[i, 0], px[i, 0], 1.0, pp[i, 2], K, r, with_jac)
        point_rows(T, S, A, pp[i, 1], px[i, 1], -1.0, pp[i, 2], K, r, with_jac)
    for i in range(rr.shape[0]):
        b1, b2, row = rr[i, 0], rr[i, 1], rr[i, 2]
        for c in range(3):  # 0.5 L sum_c (Rt e_c) x (R2 e_c), Rt = R1 R_rel
            a0 = T[b1, 0, 0] * rR[i, 0, c] + T[b1, 0, 1] * rR[i, 1, c] + T[b1, 0, 2] * rR[i, 2, c]
            a1 = T[b1, 1, 0] * rR[i, 0, c] + T[b1, 1, 1] * rR[i, 1, c] + T[b1, 1, 2] * rR[i, 2, c]
            a2 = T[b1, 2, 0] * rR[i, 0, c] + T[b1, 2, 1] * rR[i, 1, c] + T[b1, 2, 2] * rR[i, 2, c]
            c0, c1, c2 = T[b2, 0, c], T[b2, 1, c], T[b2, 2, c]
            r[row] += 0.5 * L * (a1 * c2 - a2 * c1)
            r[row + 1] += 0.5 * L * (a2 * c0 - a0 * c2)
            r[row + 2] += 0.5 * L * (a0 * c1 - a1 * c0)
        if with_jac:
            for k in range(nv):
                f = L * (A[b2, k] - A[b1, k])
                if f != 0.0:
                    K[row, k] += f * S[k, 0]
                    K[row + 1, k] += f * S[k, 1]
                    K[row + 2, k] += f * S[k, 2]
    for i in range(cc.shape[0]):
        d1, q1, d2, q2, row = cc[i, 0], cc[i, 1], cc[i, 2], cc[i, 3], cc[i, 4]
        ref1, ref2, s = cf[i, 0], cf[i, 1], cf[i, 7]
        x = q[q2] - ref2 if q2 >= 0 else 0.0
        c0, c1, c2, c3, c4 = cf[i, 2], cf[i, 3], cf[i, 4], cf[i, 5], cf[i, 6]
        f = c0 + x * (c1 + x * (c2 + x * (c3 + x * c4)))
        r[row] = s * ((q[q1] - ref1) - f)
        if with_jac:
            K[row, d1] += s
            if d2 >= 0:
                K[row, d2] -= s * (c1 + x * (2 * c2 + x * (3 * c3 + x * 4 * c4)))


@_nj
def chol_factor(H):  # pragma: no cover - compiled
    """Cholesky factor of symmetric positive definite H in place (lower triangle used and returned)."""
    n = H.shape[0]
    for j in range(n):
        d = H[j, j]
        for k in range(j):
            d -= H[j, k] * H[j, k]
        d = np.sqrt(d) if d > 0 else 1e-300
        H[j, j] = d
        for i in range(j + 1, n):
            v = H[i, j]
            for k in range(j):
                v -= H[i, k] * H[j, k]
            H[i, j] = v / d


@_nj
def chol_subst(Lm, g, x):  # pragma: no cover - compiled
    """x = (Lm Lm^T)^-1 g with the factor of chol_factor."""
    n = Lm.shape[0]
    for i in range(n):
        v = g[i]
        for k in range(i):
            v -= Lm[i, k] * x[k]
        x[i] = v / Lm[i, i]
    for i in range(n - 1, -1, -1):
        v = x[i]
        for k in range(i + 1, n):
            v -= Lm[k, i] * x[k]
        x[i] = v / Lm[i, i]


@_nj
def chol_solve(H, g, x):  # pragma: no cover - compiled
    """Solve H x = g for symmetric positive definite H (lower triangle used, overwritten)."""
    chol_factor(H)
    chol_subst(H, g, x)


@_nj
def integrate(q, dv, jtype, jqadr, jdadr, out):  # pragma: no cover
    out[:] = q
    for k in range(jtype.shape[0]):
        typ, qa, da = jtype[k], jqadr[k], jdadr[k]
        if typ <= 1:
            out[qa] += dv[da]
            continue
        o = qa if typ == 2 else qa + 3
        v = da if typ == 2 else da + 3
        if typ == 3:
            for i in range(3):
                out[qa + i] += dv[da + i]
        w0, w1, w2 = dv[v], dv[v + 1], dv[v + 2]
        th = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        kk = 0.5 - th * th / 48.0 if th < 1e-4 else np.sin(0.5 * th) / th
        bw, bx, by, bz = np.cos(0.5 * th), kk * w0, kk * w1, kk * w2
        aw, ax, ay, az = q[o], q[o + 1], q[o + 2], q[o + 3]
        nw = aw * bw - ax * bx - ay * by - az * bz
        nx = aw * bx + ax * bw + ay * bz - az * by
        ny = aw * by - ax * bz + ay * bw + az * bx
        nz = aw * bz + ax * by - ay * bx + az * bw
        n = np.sqrt(nw * nw + nx * nx + ny * ny + nz * nz)
        out[o], out[o + 1], out[o + 2], out[o + 3] = nw / n, nx / n, ny / n, nz / n


@numba.njit(cache=True, error_model="numpy")
def fk(
    Q,
    free,
    wstep,
    geom_row,
    parent,
    T_off,
    j0,
    jtype,
    jqadr,
    jdadr,
    jpos,
    jaxis,
    jref,
    A,
    pp,
    px,
    rr,
    rR,
    cc,
    cf,
    m,
    L,
    max_iter,
    stop2,
    mu0,
    mu_min,
    mu_max,
    max_step,
    rc_out,
    it_out,
):  # pragma: no cover
    N, nq = Q.shape
    nb = parent.shape[0]
    nv = A.shape[1]
    nf = free.shape[0]
    for n in numba.prange(N):
        q = Q[n].copy()
        T = np.empty((nb, 4, 4))
        S = np.zeros((nv, 6))
        r = np.empty(m)
        K = np.empty((m, nv))
        qt = np.empty(nq)
        rt = np.empty(m)
        Kt = np.empty((m, nv))
        dv = np.zeros(nv)
        H = np.empty((nf, nf))
        g = np.empty(nf)
        dx = np.empty(nf)
        geo = np.zeros(nf, dtype=np.bool_)
        kin(q, parent, T_off, j0, jtype, jqadr, jdadr, jpos, jaxis, jref, T, S)
        resjac(q, T, S, A, pp, px, rr, rR, cc, cf, L, r, K, True)
        cost = 0.0
        for i in range(m):
            cost += r[i] * r[i]
        finite = np.isfinite(cost)
        mu = mu0
        it = 0
        for a in range(nf):  # coordinates that move a closure point (not a coupled spin alone)
            for i in range(m):
                if geom_row[i] and K[i, free[a]] != 0.0:
                    geo[a] = True
                    break
        active = finite and nf > 0
        while active and it < max_iter:
            if cost <= stop2:
                break
            for a in range(nf):
                fa = free[a]
                ga = 0.0
                for i in range(m):
                    ga += K[i, fa] * r[i]
                g[a] = ga
                for c in range(a + 1):
                    fc = free[c]
                    acc = 0.0
                    for i in range(m):
                        acc += K[i, fa] * K[i, fc]
                    H[a, c] = acc
            tr = 0.0
            for a in range(nf):
                tr += H[a, a]
            scale = tr / nf + 1e-300
            for a in range(nf):
                H[a, a] += mu * scale
            chol_solve(H, g, dx)  # (K^T K + mu s I) dx = K^T r; the step is -dx
            big = 0.0
            for a in range(nf):
                if geo[a]:
                    big = max(big, abs(dx[a]) * wstep[a])
            f = max_step / big if big > max_step else 1.0
            dv[:] = 0.0
            for a in range(nf):
                dv[free[a]] = -dx[a] * f
            integrate(q, dv, jtype, jqadr, jdadr, qt)
            kin(qt, parent, T_off, j0, jtype, jqadr, jdadr, jpos, jaxis, jref, T, S)
            resjac(qt, T, S, A, pp, px, rr, rR, cc, cf, L, rt, Kt, True)
            ct = 0.0
            for i in range(m):
                ct += rt[i] * rt[i]
            it += 1
            if np.isfinite(ct) and ct < cost:
                q[:] = qt
                r[:] = rt
                K[:, :] = Kt
                cost = ct
                mu = max(mu / 10.0, mu_min)
            else:
                mu *= 10.0
                if mu > mu_max:
                    break
        Q[n] = q
        rc = 0.0
        for i in range(m):
            rc = max(rc, abs(r[i]))
        rc_out[n] = rc if finite else np.inf
        it_out[n] = it


@numba.njit(cache=True, error_model="numpy")
def site_jac(
    Q,
    act,
    pas,
    sb,
    Tsite,
    parent,
    T_off,
    j0,
    jtype,
    jqadr,
    jdadr,
    jpos,
    jaxis,
    jref,
    A,
    pp,
    px,
    rr,
    rR,
    cc,
    cf,
    m,
    L,
    rtol,
    J_out,
):  # pragma: no cover
    N = Q.shape[0]
    nb = parent.shape[0]
    nv = A.shape[1]
    na, npas = act.shape[0], pas.shape[0]
    for n in numba.prange(N):
        q = Q[n]
        T = np.empty((nb, 4, 4))
        S = np.zeros((nv, 6))
        r = np.empty(m)
        K = np.empty((m, nv))
        kin(q, parent, T_off, j0, jtype, jqadr, jdadr, jpos, jaxis, jref, T, S)
        resjac(q, T, S, A, pp, px, rr, rR, cc, cf, L, r, K, True)
        G = np.zeros((nv, na))
        for j in range(na):
            G[act[j], j] = 1.0
        if m > 0 and npas > 0:
            Kp = np.empty((m, npas))
            Ka = np.empty((m, na))
            for i in range(m):
                for j in range(npas):
                    Kp[i, j] = K[i, pas[j]]
                for j in range(na):
                    Ka[i, j] = K[i, act[j]]
            # least-squares passive rates: K_p^T K_p + eps I factored once, then refined twice
            # (x += M^-1 K_p^T (b - K_p x)), which converges to the least-squares solution at the rate
            # eps / (sigma^2 + eps) per step; idle directions (sigma = 0) keep a component of order
            # rounding / eps that moves no site, so the site Jacobian is the numpy path's (SVD) one.
            M = Kp.T @ Kp
            tr = 0.0
            for i in range(npas):
                tr += M[i, i]
            eps = REG * tr / npas + 1e-300
            for i in range(npas):
                M[i, i] += eps
            chol_factor(M)
            b = np.empty(m)
            b_tmp = np.empty(m)
            rhs = np.empty(npas)
            x = np.empty(npas)
            dxr = np.empty(npas)
            for j in range(na):
                for i in range(m):
                    b[i] = -Ka[i, j]
                x[:] = 0.0
                for _ in range(REFINE + 1):
                    for i in range(m):
                        acc = b[i]
                        for c in range(npas):
                            acc -= Kp[i, c] * x[c]
                        b_tmp[i] = acc  # residual b - K_p x
                    for c in range(npas):
                        acc = 0.0
                        for i in range(m):
                            acc += Kp[i, c] * b_tmp[i]
                        rhs[c] = acc
                    chol_subst(M, rhs, dxr)
                    for c in range(npas):
                        x[c] += dxr[c]
                for i in range(npas):
                    G[pas[i], j] = x[i]
        Ts = T[sb] @ Tsite
        p0, p1, p2 = Ts[0, 3], Ts[1, 3], Ts[2, 3]
        for j in range(na):
            for i in range(6):
                J_out[n, i, j] = 0.0
        for k in range(nv):
            if A[sb, k] == 0.0:
                continue
            w0, w1, w2 = S[k, 0], S[k, 1], S[k, 2]
            col = (
                w0,
                w1,
                w2,
                S[k, 3] + w1 * p2 - w2 * p1,
                S[k, 4] + w2 * p0 - w0 * p2,
                S[k, 5] + w0 * p1 - w1 * p0,
            )
            for j in range(na):
                g = G[k, j]
                if g != 0.0:
                    for i in range(6):
                        J_out[n, i, j] += col[i] * g


def _kernels():
    return fk, site_jac


def compiled_fk(mech, q: np.ndarray, free: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The LM closure solve of ``solve_closure`` (no extra rows) on ``q (N, nq)`` in place: (q, rc, iters)."""
    t = mech.compiled_tables
    fk, _ = _kernels()
    tree = mech.tree
    Q = np.ascontiguousarray(q, dtype=float).copy()
    N = Q.shape[0]
    rc, it = np.empty(N), np.zeros(N, dtype=np.int64)
    wstep = np.where(tree.dof_translational, 1.0 / tree.length, 1.0)[free].astype(float)
    fk(
        Q,
        free.astype(np.int64),
        wstep,
        t.geom_row,
        *_args(t),
        MAX_ITER,
        (STOP_RTOL * t.L) ** 2,
        MU_START,
        MU_MIN,
        MU_MAX,
        MAX_STEP,
        rc,
        it,
    )
    return Q, rc, it


def compiled_site_jacobian(mech, q: np.ndarray, site: int) -> np.ndarray:
    """``J (N, 6, n_act)`` of site index ``site`` at ``q (N, nq)`` (the numpy path's ``site_jacobian``)."""
    t = mech.compiled_tables
    _, sj = _kernels()
    tree = mech.tree
    act = tree.act_dof.astype(np.int64)
    pas = np.setdiff1d(np.arange(tree.nv), act).astype(np.int64)
    Q = np.ascontiguousarray(q, dtype=float)
    J = np.empty((Q.shape[0], 6, len(act)))
    sj(
        Q,
        act,
        pas,
        int(tree.site_body[site]),
        np.ascontiguousarray(tree.T_site[site]),
        *_args(t),
        PASSIVE_RANK_RTOL,
        J,
    )
    return J
