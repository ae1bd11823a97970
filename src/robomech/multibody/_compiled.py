"""The compiled (numba) per-sample kernels: assembly (FK), influence coefficients, site Jacobians and
Hessians, inverse dynamics.

The one implementation of each of these algorithms, for every batch size (batch 1 included): tree
kinematics (every body's pose and every coordinate's space screw, :func:`compiled_kinematics`, for the
compile step's reference rank, ``mobility``, drawing and export), integration ``q ⊕ dv``
(:func:`compiled_integrate`), closure residual and velocity constraint matrix (the rows of
``_constraints``, written per sample; :func:`resjac_block` for ``constraint_residual``,
``constraint_jacobian``, ``singularities``, ``mobility`` and the compile step's reference assembly and
rank, :func:`kdot_block` for ``dK/dt``, every column in one pass), the singular values of
``singularities``' scaled ``K``, ``K_p`` and site Jacobian (:func:`singular_block`), the
Levenberg–Marquardt assembly (damping, step cap and stopping rules of ``_options``),
``G = [I; -K_p^+ K_a]`` by the SVD pseudo-inverse (:func:`influence_G`) with the site's ``[ω; ṗ]``
Jacobian, the second-order coefficients ``∂G/∂q_act`` and site Hessians
(:func:`influence_block`, from ``(dK/dt along u) v``, :func:`kdot_uv`), the velocity projection of
``simulate`` (:func:`project_block`), and the closed-chain inverse dynamics (:func:`inv_dyn`: passive
pseudo-inverse, screw rates, ``K̇ q̇``, the bodies' Newton–Euler terms through ``G``, site wrenches, the
redundant-actuation rule and the validity flags). Every sample stays in cache; large batches run in
parallel over the cores (``numba.prange``). The mechanism is passed packed, as the named tuples
``_compile.Tables`` and ``_compile.DynTables`` of its compiled model. The numpy formulation stays in the
tests as the reference (tests/multibody/_reference.py).
"""

from __future__ import annotations

import importlib
from typing import Literal, overload

import numpy as np

from robomech._numba import import_numba
from robomech._validation import MAX_MAGNITUDE

from . import _options as opt
from ._compile import Tables, compile_model

__all__ = [
    "compiled_body_poses",
    "compiled_energy",
    "compiled_fk",
    "compiled_influence",
    "compiled_integrate",
    "compiled_jacobian_rate",
    "compiled_kinematics",
    "compiled_project",
    "compiled_resjac",
    "compiled_singular_values",
    "compiled_site_jacobian",
    "compiled_site_pose",
    "inv_dyn",
    "space_jacobians",
]

numba = import_numba()

_nj = numba.njit(cache=True, error_model="numpy")
opt_max_magnitude = MAX_MAGNITUDE  # a global: numba freezes it into the kernels
# Samples per parallel task: large enough that a task's scratch arrays are allocated rarely, small
# enough that two cores share a batch of a few thousand evenly.
BLOCK = 64


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
def kin(q, t, T, S):  # pragma: no cover
    """Body poses ``T (nb, 4, 4)`` and coordinate space screws ``S (nv, 6)`` at ``q``: body b's space twist
    is ``V_b = sum_k A[b, k] S_k qd_k`` (``[ω; v]``, v of the point at the world origin)."""
    kin_into(q, t, T, S, np.empty((3, 3)), np.empty((3, 3)), np.empty(3))


@_nj
def kin_into(q, t, T, S, Rj, Rn, anchor):  # pragma: no cover
    """:func:`kin` with the caller's scratch ``Rj``, ``Rn (3, 3)``, ``anchor (3,)`` (an iteration
    allocates nothing)."""
    parent, T_off, j0, jtype, jqadr, jdadr = t.parent, t.T_off, t.j0, t.jtype, t.jqadr, t.jdadr
    jpos, jaxis, jref = t.jpos, t.jaxis, t.jref
    nb = parent.shape[0]
    for i in range(4):
        for j in range(4):
            T[0, i, j] = 1.0 if i == j else 0.0
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
    p0 = T[b, 0, 3] + T[b, 0, 0] * x[0] + T[b, 0, 1] * x[1] + T[b, 0, 2] * x[2]
    p1 = T[b, 1, 3] + T[b, 1, 0] * x[0] + T[b, 1, 1] * x[1] + T[b, 1, 2] * x[2]
    p2 = T[b, 2, 3] + T[b, 2, 0] * x[0] + T[b, 2, 1] * x[1] + T[b, 2, 2] * x[2]
    r[row] += sign * p0
    r[row + 1] += sign * p1
    r[row + 2] += sign * p2
    if with_jac:
        nv = S.shape[0]
        for k in range(nv):
            if A[b, k] != 0.0:
                w0, w1, w2 = S[k, 0], S[k, 1], S[k, 2]
                K[row, k] += sign * (S[k, 3] + w1 * p2 - w2 * p1)
                K[row + 1, k] += sign * (S[k, 4] + w2 * p0 - w0 * p2)
                K[row + 2, k] += sign * (S[k, 5] + w0 * p1 - w1 * p0)


@_nj
def resjac(q, t, T, S, r, K, with_jac):  # pragma: no cover
    """Closure residual ``r (m)`` and, with ``with_jac``, the velocity constraint matrix ``K (m, nv)``."""
    A, pp, px, rr, rR, cc, cf, L = t.A, t.pp, t.px, t.rr, t.rR, t.cc, t.cf, t.L
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


@_nj
def site_rows(T, S, A, sb, Tsite, tgt, w, L, row, K, r, with_jac):  # pragma: no cover
    """Rows ``row:row + 6`` of the weighted pose error ``w * [L rot; pos]`` of the site (body ``sb``,
    pose ``Tsite`` in it) against the world pose ``tgt (4, 4)``, and their matrix
    (``site_error`` of tests/multibody/_reference.py): ``rot = L/2 sum_c (R_t e_c) x (R_s e_c)``,
    ``pos = p_s - p_t``."""
    nv = S.shape[0]
    for i in range(6):
        r[row + i] = 0.0
        if with_jac:
            for k in range(nv):
                K[row + i, k] = 0.0
    point_rows(T, S, A, sb, Tsite[:3, 3], 1.0, row + 3, K, r, with_jac)
    for i in range(3):
        r[row + 3 + i] -= tgt[i, 3]
    for c in range(3):
        s0 = T[sb, 0, 0] * Tsite[0, c] + T[sb, 0, 1] * Tsite[1, c] + T[sb, 0, 2] * Tsite[2, c]
        s1 = T[sb, 1, 0] * Tsite[0, c] + T[sb, 1, 1] * Tsite[1, c] + T[sb, 1, 2] * Tsite[2, c]
        s2 = T[sb, 2, 0] * Tsite[0, c] + T[sb, 2, 1] * Tsite[1, c] + T[sb, 2, 2] * Tsite[2, c]
        a0, a1, a2 = tgt[0, c], tgt[1, c], tgt[2, c]
        r[row] += 0.5 * L * (a1 * s2 - a2 * s1)
        r[row + 1] += 0.5 * L * (a2 * s0 - a0 * s2)
        r[row + 2] += 0.5 * L * (a0 * s1 - a1 * s0)
    for i in range(6):
        r[row + i] *= w[i]
    if with_jac:
        for k in range(nv):
            if A[sb, k] != 0.0:
                for i in range(3):
                    K[row + i, k] = L * S[k, i]
        for i in range(6):
            for k in range(nv):
                K[row + i, k] *= w[i]


@_nj
def _rows(q, t, T, S, r, K, sb, Tsite, tgt, w, with_jac):  # pragma: no cover
    """Closure rows of ``t`` and, with ``sb >= 0``, the site rows of :func:`site_rows` after them, at
    the tree state ``T``, ``S`` of ``q``."""
    resjac(q, t, T, S, r, K, with_jac)
    if sb >= 0:
        site_rows(T, S, t.A, sb, Tsite, tgt, w, t.L, t.m, K, r, with_jac)


@_nj
def lm_solve(
    q, t, free, wstep, max_iter, stop2, mu0, mu_min, mu_max, max_step, sb, Tsite, tgt, w, gtol
):  # pragma: no cover
    """The Levenberg–Marquardt solve of one sample ``q (nq,)``, in place, over the coordinates ``free``:
    the closure rows of ``t`` and, with ``sb >= 0``, the site's weighted pose error against ``tgt``
    (:func:`site_rows`; inverse kinematics).  With ``gtol > 0`` it also stops at a stationary point
    of the cost that leaves a residual: every column of the matrix at an angle to ``r`` whose cosine
    ``|K_j^T r| / (|K_j| |r|)`` is at most ``gtol`` (MINPACK's ``gtol`` test: a target out of reach).
    Returns (largest closure row, iterations, cost ``sum r^2``, largest site row); the cost is inf
    where the start is not finite."""
    nq = q.shape[0]
    nb = t.parent.shape[0]
    nv = t.A.shape[1]
    nf = free.shape[0]
    m, geom_row = t.m, t.geom_row
    mt = m + (6 if sb >= 0 else 0)
    jtype, jqadr, jdadr = t.jtype, t.jqadr, t.jdadr
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    r = np.empty(mt)
    K = np.empty((mt, nv))
    qt = np.empty(nq)
    rt = np.empty(mt)
    Rj = np.empty((3, 3))
    Rn = np.empty((3, 3))
    anchor = np.empty(3)
    dv = np.zeros(nv)
    H = np.empty((nf, nf))
    g = np.empty(nf)
    dx = np.empty(nf)
    geo = np.zeros(nf, dtype=np.bool_)
    kin_into(q, t, T, S, Rj, Rn, anchor)
    _rows(q, t, T, S, r, K, sb, Tsite, tgt, w, True)
    cost = 0.0
    for i in range(mt):
        cost += r[i] * r[i]
    finite = np.isfinite(cost)
    mu = mu0
    it = 0
    for a in range(nf):  # coordinates that move a closure point or the site (not a coupled spin alone)
        for i in range(mt):
            if (i >= m or geom_row[i]) and K[i, free[a]] != 0.0:
                geo[a] = True
                break
    active = finite and nf > 0
    while active and it < max_iter:
        if cost <= stop2:
            break
        for a in range(nf):
            fa = free[a]
            ga = 0.0
            for i in range(mt):
                ga += K[i, fa] * r[i]
            g[a] = ga
            for c in range(a + 1):
                fc = free[c]
                acc = 0.0
                for i in range(mt):
                    acc += K[i, fa] * K[i, fc]
                H[a, c] = acc
        if gtol > 0.0:
            cmax = 0.0
            for a in range(nf):
                if H[a, a] > 0.0:
                    cmax = max(cmax, abs(g[a]) / np.sqrt(H[a, a] * cost))
            if cmax <= gtol:
                break
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
        kin_into(qt, t, T, S, Rj, Rn, anchor)
        _rows(qt, t, T, S, rt, K, sb, Tsite, tgt, w, False)  # the trial's rows; its matrix if accepted
        ct = 0.0
        for i in range(mt):
            ct += rt[i] * rt[i]
        it += 1
        if np.isfinite(ct) and ct < cost:
            q[:] = qt
            _rows(q, t, T, S, r, K, sb, Tsite, tgt, w, True)  # the same rows, and their matrix
            cost = ct
            mu = max(mu / 10.0, mu_min)
        else:
            mu *= 10.0
            if mu > mu_max:
                break
    rc = 0.0
    for i in range(m):
        rc = max(rc, abs(r[i]))
    pe = 0.0
    for i in range(m, mt):
        pe = max(pe, abs(r[i]))
    if not finite:
        return np.inf, it, np.inf, np.inf
    return rc, it, cost, pe


@_nj
def fk_block(
    Q, lo, hi, free, wstep, t, max_iter, stop2, mu0, mu_min, mu_max, max_step, rc_out, it_out, cost_out
):  # pragma: no cover
    """The Levenberg–Marquardt closure solve (:func:`lm_solve`) of samples ``lo:hi`` of ``Q (N, nq)``,
    in place."""
    eye = np.eye(4)
    w0 = np.zeros(6)
    for n in range(lo, hi):
        q = Q[n].copy()
        rc, it, cost, _ = lm_solve(
            q, t, free, wstep, max_iter, stop2, mu0, mu_min, mu_max, max_step, -1, eye, eye, w0, 0.0
        )
        Q[n] = q
        rc_out[n] = rc
        it_out[n] = it
        cost_out[n] = cost


@numba.njit(cache=True, error_model="numpy", parallel=True)
def fk_par(
    Q, free, wstep, t, max_iter, stop2, mu0, mu_min, mu_max, max_step, rc_out, it_out, cost_out
):  # pragma: no cover
    """:func:`fk_block` over ``Q`` in blocks of ``BLOCK`` samples, in parallel."""
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        fk_block(
            Q,
            k * BLOCK,
            min(N, (k + 1) * BLOCK),
            free,
            wstep,
            t,
            max_iter,
            stop2,
            mu0,
            mu_min,
            mu_max,
            max_step,
            rc_out,
            it_out,
            cost_out,
        )


@_nj
def influence_G(K, act, pas, rtol, L, Kp, P, G):  # pragma: no cover - compiled
    """The first-order influence coefficients ``G (nv, na) = [I; -K_p^+ K_a]`` of one sample from its
    constraint matrix ``K (m, nv)``, with the SVD pseudo-inverse ``P (npas, m)`` of ``K_p`` (:func:`svd_pinv`,
    singular values below ``rtol`` times the largest dropped): the minimum-norm passive rates.  Returns
    (rank, smallest kept singular value, cond) of ``K_p``; an empty block (an open chain or tree)
    cannot lose rank: (0, ``L``, 1).  ``Kp (m, npas)`` scratch."""
    m = K.shape[0]
    na, npas = act.shape[0], pas.shape[0]
    G[:, :] = 0.0
    for j in range(na):
        G[act[j], j] = 1.0
    if m == 0 or npas == 0:
        P[:, :] = 0.0
        return 0, L, 1.0
    for i in range(m):
        for j in range(npas):
            Kp[i, j] = K[i, pas[j]]
    rank, smin, cond = svd_pinv(Kp, rtol, P)
    for j in range(na):
        aj = act[j]
        for i in range(npas):
            acc = 0.0
            for c in range(m):
                acc += P[i, c] * K[c, aj]
            G[pas[i], j] = -acc
    return rank, smin, cond


@_nj
def site_point(T, sb, Tsite):  # pragma: no cover - compiled
    """World position of the site at ``Tsite`` in body ``sb``."""
    p0 = T[sb, 0, 3] + T[sb, 0, 0] * Tsite[0, 3] + T[sb, 0, 1] * Tsite[1, 3] + T[sb, 0, 2] * Tsite[2, 3]
    p1 = T[sb, 1, 3] + T[sb, 1, 0] * Tsite[0, 3] + T[sb, 1, 1] * Tsite[1, 3] + T[sb, 1, 2] * Tsite[2, 3]
    p2 = T[sb, 2, 3] + T[sb, 2, 0] * Tsite[0, 3] + T[sb, 2, 1] * Tsite[1, 3] + T[sb, 2, 2] * Tsite[2, 3]
    return p0, p1, p2


@_nj
def site_jac_one(q, act, pas, sb, Tsite, t, rtol, T, S, r, K, G, Kp, P, J):  # pragma: no cover
    """``J (6, na) = J_f G`` of the site (body ``sb``, pose ``Tsite`` in it) at one ``q``; leaves the
    tree state in ``T``, ``S`` and the constraint matrix in ``K`` (scratch ``r``, ``G``, ``Kp``, ``P``).

    ``G`` by :func:`influence_G`, as :func:`influence` has it."""
    kin(q, t, T, S)
    resjac(q, t, T, S, r, K, True)
    influence_G(K, act, pas, rtol, t.L, Kp, P, G)
    site_apply(T, S, t.A, sb, Tsite, G, J)


@_nj
def site_apply(T, S, A, sb, Tsite, X, J):  # pragma: no cover - compiled
    """``J (6, nc) = J_f X``: the site's ``[ω; ṗ]`` frame Jacobian over every velocity coordinate (body
    ``sb``, pose ``Tsite`` in it) applied to the columns of ``X (nv, nc)``."""
    nv, nc = X.shape
    p0, p1, p2 = site_point(T, sb, Tsite)
    for j in range(nc):
        for i in range(6):
            J[i, j] = 0.0
    for k in range(nv):
        if A[sb, k] == 0.0:
            continue
        w0, w1, w2 = S[k, 0], S[k, 1], S[k, 2]
        c3 = S[k, 3] + w1 * p2 - w2 * p1
        c4 = S[k, 4] + w2 * p0 - w0 * p2
        c5 = S[k, 5] + w0 * p1 - w1 * p0
        for j in range(nc):
            g = X[k, j]
            if g != 0.0:
                J[0, j] += w0 * g
                J[1, j] += w1 * g
                J[2, j] += w2 * g
                J[3, j] += c3 * g
                J[4, j] += c4 * g
                J[5, j] += c5 * g


@_nj
def influence_block(
    Q, lo, hi, act, pas, sb, Tsite, t, rtol, second, G_o, dG_o, H_o, rank_o, cons_o, smin_o, cond_o
):  # pragma: no cover - compiled
    """The influence coefficients of samples ``lo:hi``: ``G_o (N, nv, na)`` (:func:`influence_G`), the
    passive block's rank, smallest kept singular value and cond, ``cons_o = max |K G| / L``; with
    ``second`` the second-order coefficients ``dG_o[n, :, j, k] = [0; -K_p^+ (dK/dt along G e_k) G e_j]``
    (:func:`kdot_uv`) and, for a site body ``sb >= 0``, the site Hessian ``H_o[n, :, j, k] =
    (dJ_f/dt along G e_k) G e_j + J_f dG[:, j, k]`` (``_influence``' module docstring).  ``dG_o`` and
    ``H_o`` may have no samples where they are not asked for."""
    nb = t.parent.shape[0]
    m, L = t.m, t.L
    nv = t.A.shape[1]
    na, npas = act.shape[0], pas.shape[0]
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    r = np.empty(m)
    K = np.empty((m, nv))
    Kp = np.empty((m, npas))
    P = np.empty((npas, m))
    G = np.empty((nv, na))
    dG = np.zeros((nv, na, na))
    Sd = np.empty((nv, 6))
    Vu = np.empty((nb, 6))
    Vv = np.empty((nb, 6))
    Vd = np.empty((nb, 6))
    kd = np.empty(m)
    u = np.empty(nv)
    v = np.empty(nv)
    Jd = np.empty((6, na))
    KG = np.empty((m, na))
    p0 = p1 = p2 = 0.0
    for n in range(lo, hi):
        q = Q[n]
        kin(q, t, T, S)
        resjac(q, t, T, S, r, K, True)
        rank, smin, cond = influence_G(K, act, pas, rtol, L, Kp, P, G)
        cons = 0.0
        if m > 0 and na > 0:
            for i in range(m):
                for j in range(na):
                    acc = 0.0
                    for k in range(nv):
                        acc += K[i, k] * G[k, j]
                    KG[i, j] = acc
            cons = _amax_abs(KG.ravel()) / L
        G_o[n] = G
        rank_o[n] = rank
        cons_o[n] = cons
        smin_o[n] = smin
        cond_o[n] = cond
        if not second:
            continue
        if sb >= 0:
            p0, p1, p2 = site_point(T, sb, Tsite)
        for k in range(na):
            for i in range(nv):
                u[i] = G[i, k]
            screw_rates_into(t, S, u, Sd)
            for j in range(na):
                for i in range(nv):
                    v[i] = G[i, j]
                kdot_uv(q, t, T, S, Sd, u, v, Vu, Vv, Vd, kd)
                for i in range(npas):
                    acc = 0.0
                    for c in range(m):
                        acc += P[i, c] * kd[c]
                    dG[pas[i], j, k] = -acc
                if sb >= 0:
                    a0, a1, a2 = point_rate(Vu, Vv, Vd, sb, p0, p1, p2)
                    H_o[n, 0, j, k] = Vd[sb, 0]
                    H_o[n, 1, j, k] = Vd[sb, 1]
                    H_o[n, 2, j, k] = Vd[sb, 2]
                    H_o[n, 3, j, k] = a0
                    H_o[n, 4, j, k] = a1
                    H_o[n, 5, j, k] = a2
        dG_o[n] = dG
        if sb >= 0:
            for k in range(na):
                site_apply(T, S, t.A, sb, Tsite, dG[:, :, k], Jd)
                for i in range(6):
                    for j in range(na):
                        H_o[n, i, j, k] += Jd[i, j]


@numba.njit(cache=True, error_model="numpy", parallel=True)
def influence_par(
    Q, act, pas, sb, Tsite, t, rtol, second, G_o, dG_o, H_o, rank_o, cons_o, smin_o, cond_o
):  # pragma: no cover - compiled
    """:func:`influence_block` over ``Q`` in blocks of ``BLOCK`` samples, in parallel."""
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        influence_block(
            Q,
            k * BLOCK,
            min(N, (k + 1) * BLOCK),
            act,
            pas,
            sb,
            Tsite,
            t,
            rtol,
            second,
            G_o,
            dG_o,
            H_o,
            rank_o,
            cons_o,
            smin_o,
            cond_o,
        )


@_nj
def site_jac_block(Q, lo, hi, act, pas, sb, Tsite, t, rtol, J_out):  # pragma: no cover
    """:func:`site_jac_one` for samples ``lo:hi`` of ``Q`` into ``J_out (N, 6, na)``."""
    nb = t.parent.shape[0]
    m = t.m
    nv = t.A.shape[1]
    na, npas = act.shape[0], pas.shape[0]
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    r = np.empty(m)
    K = np.empty((m, nv))
    G = np.zeros((nv, na))
    Kp = np.empty((m, npas))
    P = np.empty((npas, m))
    for n in range(lo, hi):
        site_jac_one(Q[n], act, pas, sb, Tsite, t, rtol, T, S, r, K, G, Kp, P, J_out[n])


@numba.njit(cache=True, error_model="numpy", parallel=True)
def site_jac_par(Q, act, pas, sb, Tsite, t, rtol, J_out):  # pragma: no cover
    """:func:`site_jac_block` over ``Q`` in blocks of ``BLOCK`` samples, in parallel."""
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        site_jac_block(Q, k * BLOCK, min(N, (k + 1) * BLOCK), act, pas, sb, Tsite, t, rtol, J_out)


@_nj
def resjac_block(Q, lo, hi, t, with_jac, R_o, K_o):  # pragma: no cover - compiled
    """The closure residual ``R_o (N, m)`` and, with ``with_jac``, the velocity constraint matrix
    ``K_o (N, m, nv)`` (:func:`resjac`) of samples ``lo:hi`` of ``Q (N, nq)``."""
    nb = t.parent.shape[0]
    nv = t.A.shape[1]
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    K = np.empty((t.m, nv))
    for n in range(lo, hi):
        kin(Q[n], t, T, S)
        resjac(Q[n], t, T, S, R_o[n], K_o[n] if with_jac else K, with_jac)


@numba.njit(cache=True, error_model="numpy", parallel=True)
def resjac_par(Q, t, with_jac, R_o, K_o):  # pragma: no cover - compiled
    """:func:`resjac_block` over ``Q`` in blocks of ``BLOCK`` samples, in parallel."""
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        resjac_block(Q, k * BLOCK, min(N, (k + 1) * BLOCK), t, with_jac, R_o, K_o)


@_nj
def kdot_block(Q, QD, lo, hi, t, KD_o):  # pragma: no cover - compiled
    """``dK/dt`` along ``QD (N, nv)`` into ``KD_o (N, m, nv)`` for samples ``lo:hi``, every column in
    one pass per sample (:func:`kdot_columns`)."""
    nb = t.parent.shape[0]
    nv = t.A.shape[1]
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    Sd = np.empty((nv, 6))
    Vu = np.empty((nb, 6))
    for n in range(lo, hi):
        q, qd = Q[n], QD[n]
        kin(q, t, T, S)
        screw_rates_into(t, S, qd, Sd)
        kdot_columns(q, t, T, S, Sd, qd, Vu, KD_o[n])


@numba.njit(cache=True, error_model="numpy", parallel=True)
def kdot_par(Q, QD, t, KD_o):  # pragma: no cover - compiled
    """:func:`kdot_block` over ``Q`` in blocks of ``BLOCK`` samples, in parallel."""
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        kdot_block(Q, QD, k * BLOCK, min(N, (k + 1) * BLOCK), t, KD_o)


# ----------------------------------------------------------------------------- dK/dt and singular values
# LAPACK's gesdd without singular vectors (jobz 'N', the routine of numpy's ``svd(compute_uv=False)``,
# half the cost of numba's ``np.linalg.svd``, which always forms U and V): numba has it only as the
# helper of its ``np.linalg.norm`` / ``cond`` / ``matrix_rank``, so the kernels call that helper, and a
# numba without it the full SVD (the same values, at twice the cost) rather than failing at import.
@_nj
def singular_values_full(a):  # pragma: no cover - compiled
    """Singular values of ``a`` through numba's ``np.linalg.svd`` (which also forms U and V)."""
    return np.linalg.svd(a, full_matrices=False)[1]


_singular_values = getattr(
    importlib.import_module("numba.np.linalg"), "_compute_singular_values", singular_values_full
)


@_nj
def kdot_columns(q, t, T, S, Sd, u, Vu, KD):  # pragma: no cover - compiled
    """``KD = dK/dt (m, nv)`` along ``u (nv,)`` in one pass, ``Sd`` the screw rates along ``u``
    (:func:`screw_rates_into`); column ``k`` is :func:`kdot_uv` with ``v`` the ``k``-th unit vector.

    A point row's column ``k`` is, per anchor ``p`` on body ``b`` (sign + for the first, - for the
    second), the rate of ``A_bk (v_k + w_k x p)``: ``A_bk (dv_k + dw_k x p + w_k x pdot)`` with ``pdot =
    v_b + w_b x p`` the anchor's velocity along ``u``; a rotation row's is ``L (A_b2k - A_b1k) dw_k``; a
    coupling row's is ``-s poly''(x) u_2`` in the column of its second coordinate (its first column is
    constant).  Also fills the body twists ``Vu = A S u (nb, 6)``."""
    A, L = t.A, t.L
    nb, nv = A.shape
    for b in range(nb):
        for i in range(6):
            acc = 0.0
            for k in range(nv):
                if A[b, k] != 0.0:
                    acc += A[b, k] * S[k, i] * u[k]
            Vu[b, i] = acc
    KD[:, :] = 0.0
    for i in range(t.pp.shape[0]):
        row = t.pp[i, 2]
        for side in range(2):
            b = t.pp[i, side]
            x = t.px[i, side]
            sign = 1.0 if side == 0 else -1.0
            p0 = T[b, 0, 3] + T[b, 0, 0] * x[0] + T[b, 0, 1] * x[1] + T[b, 0, 2] * x[2]
            p1 = T[b, 1, 3] + T[b, 1, 0] * x[0] + T[b, 1, 1] * x[1] + T[b, 1, 2] * x[2]
            p2 = T[b, 2, 3] + T[b, 2, 0] * x[0] + T[b, 2, 1] * x[1] + T[b, 2, 2] * x[2]
            w0, w1, w2 = Vu[b, 0], Vu[b, 1], Vu[b, 2]
            pd0 = Vu[b, 3] + w1 * p2 - w2 * p1
            pd1 = Vu[b, 4] + w2 * p0 - w0 * p2
            pd2 = Vu[b, 5] + w0 * p1 - w1 * p0
            for k in range(nv):
                a = A[b, k]
                if a == 0.0:
                    continue
                e0, e1, e2 = a * Sd[k, 0], a * Sd[k, 1], a * Sd[k, 2]
                x0, x1, x2 = a * S[k, 0], a * S[k, 1], a * S[k, 2]
                KD[row, k] += sign * (a * Sd[k, 3] + (e1 * p2 - e2 * p1) + (x1 * pd2 - x2 * pd1))
                KD[row + 1, k] += sign * (a * Sd[k, 4] + (e2 * p0 - e0 * p2) + (x2 * pd0 - x0 * pd2))
                KD[row + 2, k] += sign * (a * Sd[k, 5] + (e0 * p1 - e1 * p0) + (x0 * pd1 - x1 * pd0))
    for i in range(t.rr.shape[0]):
        b1, b2, row = t.rr[i, 0], t.rr[i, 1], t.rr[i, 2]
        for k in range(nv):
            a1, a2 = A[b1, k], A[b2, k]
            if a1 != 0.0 or a2 != 0.0:
                for c in range(3):
                    KD[row + c, k] = L * (a2 * Sd[k, c] - a1 * Sd[k, c])
    for i in range(t.cc.shape[0]):
        d2, q2, row = t.cc[i, 2], t.cc[i, 3], t.cc[i, 4]
        if d2 >= 0:
            x = q[q2] - t.cf[i, 1]
            dd = 2 * t.cf[i, 4] + x * (6 * t.cf[i, 5] + x * 12 * t.cf[i, 6])
            KD[row, d2] = -t.cf[i, 7] * dd * u[d2]


@_nj
def singular_values_into(X, s):  # pragma: no cover - compiled
    """The singular values of ``X (m, n)``, largest first, into ``s (min(m, n),)``: LAPACK's gesdd
    without singular vectors, as ``np.linalg.svd(X, compute_uv=False)``; NaN where ``X`` is not finite
    or LAPACK does not converge, nothing for an empty ``X``."""
    if X.shape[0] == 0 or X.shape[1] == 0:
        return
    if not _all_finite(X):
        s[:] = np.nan
        return
    try:
        s[:] = _singular_values(X)
    except Exception:  # no convergence (LAPACK)
        s[:] = np.nan


@_nj
def singular_block(
    Q, lo, hi, act, pas, sb, Tsite, t, rtol, L, rows, C_o, sK_o, sP_o, sJ_o
):  # pragma: no cover - compiled
    """The singularity measures' matrices of samples ``lo:hi`` in one pass per sample (``_singularity``'s
    module docstring): the largest closure row ``C_o (N,)`` and the singular values, largest first, of
    the scaled ``K`` (``sK_o (N, min(m, nv))``), of its passive columns (``sP_o (N, min(m, npas))``) and of
    the scaled site Jacobian's ``rows`` (``sJ_o (N, min(len(rows), na))``).  Hinge columns are multiplied
    by the length ``L`` (slides by 1), the Jacobian's rotation rows by ``L`` and its columns divided by
    their input's; ``J = J_f G`` by :func:`site_jac_one` (``G`` with the passive-rank ``rtol``)."""
    nb = t.parent.shape[0]
    m = t.m
    nv = t.A.shape[1]
    na, npas, nr = act.shape[0], pas.shape[0], rows.shape[0]
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    r = np.empty(m)
    K = np.empty((m, nv))
    G = np.zeros((nv, na))
    Kp = np.empty((m, npas))
    P = np.empty((npas, m))
    J = np.empty((6, na))
    col = np.empty(nv)
    for k in range(nv):
        col[k] = 1.0 if t.dof_tr[k] else L
    Ks = np.empty((m, nv))
    Ksp = np.empty((m, npas))
    Js = np.empty((nr, na))
    for n in range(lo, hi):
        site_jac_one(Q[n], act, pas, sb, Tsite, t, rtol, T, S, r, K, G, Kp, P, J)
        C_o[n] = _amax_abs(r)
        for i in range(m):
            for k in range(nv):
                Ks[i, k] = K[i, k] * col[k]
            for j in range(npas):
                Ksp[i, j] = Ks[i, pas[j]]
        for i in range(nr):
            f = L if rows[i] < 3 else 1.0
            for j in range(na):
                Js[i, j] = f * J[rows[i], j] / col[act[j]]
        singular_values_into(Ks, sK_o[n])
        singular_values_into(Ksp, sP_o[n])
        singular_values_into(Js, sJ_o[n])


@numba.njit(cache=True, error_model="numpy", parallel=True)
def singular_par(Q, act, pas, sb, Tsite, t, rtol, L, rows, C_o, sK_o, sP_o, sJ_o):  # pragma: no cover
    """:func:`singular_block` over ``Q`` in blocks of ``BLOCK`` samples, in parallel."""
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        singular_block(
            Q,
            k * BLOCK,
            min(N, (k + 1) * BLOCK),
            act,
            pas,
            sb,
            Tsite,
            t,
            rtol,
            L,
            rows,
            C_o,
            sK_o,
            sP_o,
            sJ_o,
        )


def compiled_singular_values(model, q: np.ndarray, site: int, L: float, rows: tuple[int, ...]) -> tuple:
    """``(closure (N,), sK, sP, sJ)`` at ``q (N, nq)`` for site index ``site``, length ``L`` and the
    Jacobian's ``rows`` (:func:`singular_block`): the largest closure row and the singular values of the
    scaled ``K (N, min(m, nv))``, ``K_p (N, min(m, npas))`` and site Jacobian ``(N, min(len(rows), na))``."""
    tree, m = model.tree, model.tables.m
    Q = writable(q)
    N, nv, na, npas = Q.shape[0], tree.nv, len(model.act), len(model.pas)
    out = (
        np.empty(N),
        np.empty((N, min(m, nv))),
        np.empty((N, min(m, npas))),
        np.empty((N, min(len(rows), na))),
    )
    args = (
        model.act,
        model.pas,
        int(tree.site_body[site]),
        np.ascontiguousarray(tree.T_site[site], dtype=float),
        model.tables,
        opt.PASSIVE_RANK_RTOL,
        float(L),
        np.array(rows, dtype=np.int64),
        *out,
    )
    if N <= BLOCK:
        entry(model, singular_block, "singular_block", (Q, 0, N, *args))
    else:
        singular_par(Q, *args)
    return out


# ----------------------------------------------------------------------------- inverse dynamics
@_nj
def _all_finite(x):  # pragma: no cover - compiled
    for v in x.ravel():
        if not np.isfinite(v):
            return False
    return True


@_nj
def _amax_abs(x):  # pragma: no cover - compiled
    """max |x| with NaN propagated (as numpy's max); 0 for an empty x."""
    out = 0.0
    for v in x:
        a = abs(v)
        if a != a:
            return np.nan
        if a > out:
            out = a
    return out


@_nj
def svd_pinv(Kp, rtol, P):  # pragma: no cover - compiled
    """``_influence._pinv`` for one matrix: P (n, m) and (rank, smallest kept singular value, cond)."""
    m, n = Kp.shape
    if not _all_finite(Kp):  # LAPACK refuses it; the sample is flagged (rank 0)
        P[:, :] = np.nan
        return 0, np.inf, np.inf
    try:
        U, s, Vt = np.linalg.svd(np.ascontiguousarray(Kp), full_matrices=False)
    except Exception:  # no convergence (LAPACK): flagged as a non-finite block is
        P[:, :] = np.nan
        return 0, np.inf, np.inf
    cut = rtol * s[0]
    rank = 0
    smin = np.inf
    P[:, :] = 0.0
    for c in range(s.shape[0]):
        if s[c] > cut:
            rank += 1
            smin = min(smin, s[c])
            inv = 1.0 / s[c]
            for i in range(n):
                f = Vt[c, i] * inv
                for j in range(m):
                    P[i, j] += f * U[j, c]
    cond = s[0] / (smin if np.isfinite(smin) else 1.0) if rank > 0 else np.inf
    return rank, smin, cond


@_nj
def pinv_rank(K, rank, P):  # pragma: no cover - compiled
    """``P (n, m)``: the pseudo-inverse of ``K (m, n)`` truncated to its ``rank`` largest singular values
    (the mechanism's generic rank rather than a tolerance: a state ~1e-12 off the manifold lifts the
    zero singular values of an over-constrained closure to ~1e-12, which a tolerance would invert; a
    zero ``s_rank`` leaves the kept values unscaled).  False (``P`` untouched) where ``K`` is not
    finite or LAPACK does not converge."""
    m, n = K.shape
    if not _all_finite(K):
        return False
    try:
        U, s, Vt = np.linalg.svd(np.ascontiguousarray(K), full_matrices=False)
    except Exception:  # no convergence (LAPACK)
        return False
    ok = s[rank - 1] > 0
    P[:, :] = 0.0
    for c in range(rank):
        inv = 1.0 / s[c] if ok else 1.0
        for i in range(n):
            g = Vt[c, i] * inv
            for j in range(m):
                P[i, j] += g * U[j, c]
    return True


@_nj
def project_block(Q, QD, lo, hi, t, rank_K, QD_o):  # pragma: no cover - compiled
    """Velocities onto the admissible ones, samples ``lo:hi``: ``qd - K^+ K qd`` (minimum-norm
    correction, ``K^+`` by :func:`pinv_rank` at the generic rank ``rank_K``) at the configurations ``Q``;
    NaN where the pseudo-inverse fails."""
    nb = t.parent.shape[0]
    m = t.m
    nv = t.A.shape[1]
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    r = np.empty(m)
    K = np.empty((m, nv))
    P = np.empty((nv, m))
    x = np.empty(m)
    for n in range(lo, hi):
        qd = QD[n]
        if m == 0 or rank_K == 0:
            QD_o[n] = qd
            continue
        kin(Q[n], t, T, S)
        resjac(Q[n], t, T, S, r, K, True)
        if not pinv_rank(K, rank_K, P):
            QD_o[n] = np.nan
            continue
        for i in range(m):
            acc = 0.0
            for k in range(nv):
                acc += K[i, k] * qd[k]
            x[i] = acc
        for i in range(nv):
            acc = 0.0
            for j in range(m):
                acc += P[i, j] * x[j]
            QD_o[n, i] = qd[i] - acc


def compiled_project(model, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """:func:`project_block` on ``q (N, nq)``, ``qd (N, nv)`` (one sample per call in ``simulate``)."""
    Q, QD = writable(q), writable(qd)
    out = np.empty_like(QD)
    entry(model, project_block, "project_block", (Q, QD, 0, Q.shape[0], model.tables, model.rank_K, out))
    return out


@_nj
def passive_inverse(Kp, d, Gi, P):  # pragma: no cover - compiled
    """The passive block's pseudo-inverse for one sample: (mode, rank, sigma_min, cond).

    Gram path (mode 1 wide, 2 tall) where the generic rank is min(m, n): ``P = Kp^T (Kp Kp^T)^-1`` or
    ``(Kp^T Kp)^-1 Kp^T``, with the Gram inverse ``Gi`` by Cholesky (numpy's path: LU; equal to rounding)
    and ``cond`` the same 1-norm estimate ``sqrt(||Gram||_1 ||Gi||_1)``; P is applied to vectors by
    :func:`passive_solve` (refined as the numpy path is).  Mode 0: the SVD pseudo-inverse ``P``
    (``_influence._pinv``), also beyond ``gram_cond_max``.
    """
    m, n = Kp.shape
    if m == 0 or n == 0:
        P[:, :] = 0.0
        return 0, 0, np.inf, 1.0
    if d.rank0 == min(m, n):
        wide = m <= n
        k = m if wide else n
        Gm = np.empty((k, k))
        if wide:
            for i in range(m):
                for j in range(i + 1):
                    acc = 0.0
                    for c in range(n):
                        acc += Kp[i, c] * Kp[j, c]
                    Gm[i, j] = acc
                    Gm[j, i] = acc
        else:
            for i in range(n):
                for j in range(i + 1):
                    acc = 0.0
                    for r in range(m):
                        acc += Kp[r, i] * Kp[r, j]
                    Gm[i, j] = acc
                    Gm[j, i] = acc
        Lc = Gm.copy()
        chol_factor(Lc)
        # Gi = L^-T L^-1: the lower-triangular inverse by forward substitution, then the product
        Li = np.zeros((k, k))
        for j in range(k):
            Li[j, j] = 1.0 / Lc[j, j]
            for i in range(j + 1, k):
                acc = 0.0
                for c in range(j, i):
                    acc += Lc[i, c] * Li[c, j]
                Li[i, j] = -acc / Lc[i, i]
        for i in range(k):
            for j in range(i + 1):
                acc = 0.0
                for c in range(i, k):
                    acc += Li[c, i] * Li[c, j]
                Gi[i, j] = acc
                Gi[j, i] = acc
        n1 = 0.0
        n1i = 0.0
        nan = False
        for j in range(k):
            s1 = 0.0
            s2 = 0.0
            for i in range(k):
                s1 += abs(Gm[i, j])
                s2 += abs(Gi[i, j])
            nan = nan or s1 != s1 or s2 != s2
            n1 = max(n1, s1)
            n1i = max(n1i, s2)
        cond = np.sqrt(n1 * n1i) if not nan else np.nan
        smin = 1.0 / np.sqrt(n1i) if not nan else np.nan
        if np.isfinite(cond) and cond <= d.gram_cond_max:
            return (1 if wide else 2), d.rank0, smin, cond
    rank, smin, cond = svd_pinv(Kp, d.pinv_rtol, P)
    return 0, rank, smin, cond


@_nj
def _gram_apply(Kp, Gi, mode, b, x, tmp):  # pragma: no cover - compiled
    """x = P b with the Gram pseudo-inverse (mode 1: Kp^T (Gi b); mode 2: Gi (Kp^T b))."""
    m, n = Kp.shape
    if mode == 1:
        for i in range(m):
            acc = 0.0
            for c in range(m):
                acc += Gi[i, c] * b[c]
            tmp[i] = acc
        for j in range(n):
            acc = 0.0
            for i in range(m):
                acc += Kp[i, j] * tmp[i]
            x[j] = acc
    else:
        for j in range(n):
            acc = 0.0
            for i in range(m):
                acc += Kp[i, j] * b[i]
            tmp[j] = acc
        for i in range(n):
            acc = 0.0
            for c in range(n):
                acc += Gi[i, c] * tmp[c]
            x[i] = acc


@_nj
def passive_solve(Kp, Gi, P, mode, nref, b, x, res, dx, tmp):  # pragma: no cover - compiled
    """``x = P b`` for the pseudo-inverse of :func:`passive_inverse`.  The numpy path refines the matrix,
    ``P_{k+1} = P_k + P0 (I - Kp P_k)``; applied to b that is ``x += P0 (b - Kp x)``, done here per
    right-hand side ``nref`` times."""
    m, n = Kp.shape
    if mode == 0:
        for i in range(n):
            acc = 0.0
            for c in range(m):
                acc += P[i, c] * b[c]
            x[i] = acc
        return
    _gram_apply(Kp, Gi, mode, b, x, tmp)
    for _ in range(nref):
        for i in range(m):
            acc = b[i]
            for c in range(n):
                acc -= Kp[i, c] * x[c]
            res[i] = acc
        _gram_apply(Kp, Gi, mode, res, dx, tmp)
        for i in range(n):
            x[i] += dx[i]


@_nj
def row_twist(a, S, u):  # pragma: no cover - compiled
    """The twist ``sum_j a_j u_j S_j`` (6 floats) of the screws ``S (nv, 6)`` at rates ``u`` over the row
    ``a (nv,)`` of a 0/1 ancestry matrix (``A[b]``: body b's twist; ``C[k]``: coordinate k's carrier)."""
    c0 = c1 = c2 = c3 = c4 = c5 = 0.0
    for j in range(S.shape[0]):
        if a[j] != 0.0:
            f = a[j] * u[j]
            c0 += f * S[j, 0]
            c1 += f * S[j, 1]
            c2 += f * S[j, 2]
            c3 += f * S[j, 3]
            c4 += f * S[j, 4]
            c5 += f * S[j, 5]
    return c0, c1, c2, c3, c4, c5


@_nj
def screw_rates_into(t, S, u, Sd):  # pragma: no cover - compiled
    """The screw rates ``Sd (nv, 6)`` along the motion ``u (nv,)``: ``dS_k = [w_c x w_k; w_c x v_k -
    w_k x v_c]``, ``V_c`` the carrier twist of coordinate ``k`` (``screw_rates`` of the tests' numpy
    reference)."""
    C = t.C
    nv = S.shape[0]
    for k in range(nv):
        c0, c1, c2, c3, c4, c5 = row_twist(C[k], S, u)
        w0, w1, w2, v0, v1, v2 = S[k, 0], S[k, 1], S[k, 2], S[k, 3], S[k, 4], S[k, 5]
        Sd[k, 0] = c1 * w2 - c2 * w1
        Sd[k, 1] = c2 * w0 - c0 * w2
        Sd[k, 2] = c0 * w1 - c1 * w0
        Sd[k, 3] = (c1 * v2 - c2 * v1) - (w1 * c5 - w2 * c4)
        Sd[k, 4] = (c2 * v0 - c0 * v2) - (w2 * c3 - w0 * c5)
        Sd[k, 5] = (c0 * v1 - c1 * v0) - (w0 * c4 - w1 * c3)


@_nj
def point_rate(Vu, Vv, Vd, b, p0, p1, p2):  # pragma: no cover - compiled
    """``(dJ_p/dt along u) v`` of the world point ``p`` fixed in body ``b``, from the body twists ``Vu``
    (of ``u``), ``Vv`` (of ``v``) and ``Vd = sum_k A Sd_k(u) v_k``: ``dVd_v + dVd_w x p + w_v x pdot_u``
    with ``pdot_u = v_u + w_u x p`` (the tests' numpy ``frame_jacobian_rate`` applied to ``v``)."""
    w0, w1, w2 = Vu[b, 0], Vu[b, 1], Vu[b, 2]
    pd0 = Vu[b, 3] + w1 * p2 - w2 * p1
    pd1 = Vu[b, 4] + w2 * p0 - w0 * p2
    pd2 = Vu[b, 5] + w0 * p1 - w1 * p0
    x0, x1, x2 = Vv[b, 0], Vv[b, 1], Vv[b, 2]
    e0, e1, e2 = Vd[b, 0], Vd[b, 1], Vd[b, 2]
    return (
        Vd[b, 3] + (e1 * p2 - e2 * p1) + (x1 * pd2 - x2 * pd1),
        Vd[b, 4] + (e2 * p0 - e0 * p2) + (x2 * pd0 - x0 * pd2),
        Vd[b, 5] + (e0 * p1 - e1 * p0) + (x0 * pd1 - x1 * pd0),
    )


@_nj
def kdot_uv(q, t, T, S, Sd, u, v, Vu, Vv, Vd, kd):  # pragma: no cover - compiled
    """``kd = (dK/dt along u) v (m,)`` with ``Sd`` the screw rates along ``u`` (:func:`screw_rates_into`),
    block by block as the tests' numpy ``jacobian_rate`` builds ``dK/dt``: a point row is the difference
    of the two anchors' :func:`point_rate`, a rotation row ``L (Vd_w2 - Vd_w1)``, a coupling row
    ``-s poly''(x) u_2 v_2``.  Also fills the body twists ``Vu = A S u``, ``Vv = A S v`` and ``Vd =
    sum_k A Sd_k v_k`` (nb, 6); ``Vu`` and ``Vv`` may be one array where ``u`` is ``v``."""
    A, L = t.A, t.L
    nb, nv = A.shape
    for b in range(nb):
        for i in range(6):
            acc = 0.0
            acc1 = 0.0
            acc2 = 0.0
            for k in range(nv):
                if A[b, k] != 0.0:
                    acc += A[b, k] * S[k, i] * u[k]
                    acc1 += A[b, k] * S[k, i] * v[k]
                    acc2 += A[b, k] * Sd[k, i] * v[k]
            Vu[b, i] = acc
            Vv[b, i] = acc1
            Vd[b, i] = acc2
    for i in range(t.pp.shape[0]):
        row = t.pp[i, 2]
        for c in range(3):
            kd[row + c] = 0.0
        for side in range(2):
            b = t.pp[i, side]
            x = t.px[i, side]
            sign = 1.0 if side == 0 else -1.0
            p0 = T[b, 0, 3] + T[b, 0, 0] * x[0] + T[b, 0, 1] * x[1] + T[b, 0, 2] * x[2]
            p1 = T[b, 1, 3] + T[b, 1, 0] * x[0] + T[b, 1, 1] * x[1] + T[b, 1, 2] * x[2]
            p2 = T[b, 2, 3] + T[b, 2, 0] * x[0] + T[b, 2, 1] * x[1] + T[b, 2, 2] * x[2]
            a0, a1, a2 = point_rate(Vu, Vv, Vd, b, p0, p1, p2)
            kd[row] += sign * a0
            kd[row + 1] += sign * a1
            kd[row + 2] += sign * a2
    for i in range(t.rr.shape[0]):
        b1, b2, row = t.rr[i, 0], t.rr[i, 1], t.rr[i, 2]
        for c in range(3):
            kd[row + c] = L * (Vd[b2, c] - Vd[b1, c])
    for i in range(t.cc.shape[0]):
        d2, q2, row = t.cc[i, 2], t.cc[i, 3], t.cc[i, 4]
        if d2 >= 0:
            x = q[q2] - t.cf[i, 1]
            dd = 2 * t.cf[i, 4] + x * (6 * t.cf[i, 5] + x * 12 * t.cf[i, 6])
            kd[row] = -t.cf[i, 7] * dd * u[d2] * v[d2]
        else:
            kd[row] = 0.0


@_nj
def rates_kdot(q, t, T, S, qd, Sd, V, Vd, kdq):  # pragma: no cover - compiled
    """At the kinematics ``T``, ``S`` and rates ``qd (nv,)``: the screw rates ``Sd (nv, 6)``, the body
    twists ``V (nb, 6)`` (space, ``[w; v at the origin]``), ``Vd = sum_k A Sd_k qd_k (nb, 6)`` and the
    closure rows' velocity-product accelerations ``Kdot qd (m,)`` (:func:`kdot_uv` with ``u = v = qd``)."""
    screw_rates_into(t, S, qd, Sd)
    kdot_uv(q, t, T, S, Sd, qd, qd, V, V, Vd, kdq)


@_nj
def site_forces(T, S, A, Wn, wsb, wT, ps, ext):  # pragma: no cover - compiled
    """``ext = -sum_s J_s^T W_s (nv,)`` for the wrenches ``Wn (ns, 6)`` applied at the sites on bodies
    ``wsb`` with frames ``wT (ns, 4, 4)`` (``ps (3,)`` scratch)."""
    nv = S.shape[0]
    nw = wsb.shape[0]
    ext[:] = 0.0
    for s in range(nw):
        b = wsb[s]
        Ts = wT[s]
        for i in range(3):
            ps[i] = T[b, i, 3] + T[b, i, 0] * Ts[0, 3] + T[b, i, 1] * Ts[1, 3] + T[b, i, 2] * Ts[2, 3]
        Wn_s = Wn[s]
        for k in range(nv):
            if A[b, k] != 0.0:
                w0, w1, w2 = S[k, 0], S[k, 1], S[k, 2]
                ext[k] -= (
                    w0 * Wn_s[0]
                    + w1 * Wn_s[1]
                    + w2 * Wn_s[2]
                    + (S[k, 3] + w1 * ps[2] - w2 * ps[1]) * Wn_s[3]
                    + (S[k, 4] + w2 * ps[0] - w0 * ps[2]) * Wn_s[4]
                    + (S[k, 5] + w0 * ps[1] - w1 * ps[0]) * Wn_s[5]
                )


@_nj
def inv_dyn_block(
    lo,
    hi,
    Q,
    QD,
    QDD,
    W,
    wsb,
    wT,
    gv,
    wts,
    t,
    d,
    tau_o,
    Ma_o,
    vel_o,
    grav_o,
    ex_o,
    qd_o,
    qdd_o,
    cond_o,
    smin_o,
    adm_o,
    valid_o,
    clo_o,
):  # pragma: no cover - compiled
    """The closed-chain inverse dynamics of samples ``lo:hi`` (derivation: ``_dynamics``' docstring)."""
    nb = t.parent.shape[0]
    A, m, L = t.A, t.m, t.L
    nv = A.shape[1]
    act, pas = d.act, d.pas
    na, npas = act.shape[0], pas.shape[0]
    B = d.bidx.shape[0]
    dof = d.dof
    redundant = na > dof or wts.shape[0] > 0
    ps = np.empty(3)
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    r = np.empty(m)
    K = np.empty((m, nv))
    Kp = np.empty((m, npas))
    P = np.empty((npas, m))
    Gi = np.empty((min(m, npas), min(m, npas)))
    bm = np.empty(m)
    xp = np.empty(npas)
    dxp = np.empty(npas)
    res = np.empty(m)
    tmpk = np.empty(max(m, npas))
    G = np.empty((nv, na))
    qd = np.empty(nv)
    qdd = np.empty(nv)
    conv = np.empty(nv)
    Sd = np.empty((nv, 6))
    V = np.empty((nb, 6))  # body twists (space, [w; v at the origin])
    Vd = np.empty((nb, 6))  # sum_k A Sd_k qd_k
    Vc = np.empty((nb, 6))  # sum_k A S_k conv_k
    kdq = np.empty(m)
    SG = np.empty((6, na))
    JG = np.empty((6, na))
    a0 = np.empty(6)
    rhs = np.empty(6)
    Iw = np.empty((3, 3))
    IJ = np.empty((3, na))
    wb = np.empty(3)
    Iwb = np.empty(3)
    Ma = np.empty((na, na))
    vel = np.empty(na)
    grav = np.empty(na)
    ex = np.empty(na)
    ext = np.empty(nv)
    KG = np.empty((m, na))
    tmpm = np.empty(m)
    for n in range(lo, hi):
        q = Q[n]
        qa = QD[n]
        qdda = QDD[n]
        kin(q, t, T, S)
        resjac(q, t, T, S, r, K, True)
        clo_o[n] = _amax_abs(r)  # the closure of the input q (largest row, m)
        for i in range(m):
            for j in range(npas):
                Kp[i, j] = K[i, pas[j]]
        mode, rank, smin, cond = passive_inverse(Kp, d, Gi, P)
        # refinement steps as numpy (NaN cond refines too, and is then recomputed by the SVD)
        nref = (0 if cond <= d.gram_refine_cond else 1) + (0 if cond <= d.gram_refine2_cond else 1)
        # G = [I; -P K_a]
        G[:, :] = 0.0
        for j in range(na):
            G[act[j], j] = 1.0
            for i in range(m):
                bm[i] = K[i, act[j]]
            passive_solve(Kp, Gi, P, mode, nref, bm, xp, res, dxp, tmpk)
            for i in range(npas):
                G[pas[i], j] = -xp[i]
        for k in range(nv):
            acc = 0.0
            acc2 = 0.0
            for j in range(na):
                acc += G[k, j] * qa[j]
                acc2 += G[k, j] * qdda[j]
            qd[k] = acc
            qdd[k] = acc2
        rates_kdot(q, t, T, S, qd, Sd, V, Vd, kdq)
        # qdd = G qdd_act - [0; P kdq]; the convective part conv = qdd - G qdd_act
        conv[:] = 0.0
        passive_solve(Kp, Gi, P, mode, nref, kdq, xp, res, dxp, tmpk)
        for i in range(npas):
            conv[pas[i]] = -xp[i]
            qdd[pas[i]] -= xp[i]
        for b in range(nb):
            for i in range(6):
                acc = 0.0
                for k in range(nv):
                    if A[b, k] != 0.0 and conv[k] != 0.0:
                        acc += A[b, k] * S[k, i] * conv[k]
                Vc[b, i] = acc
        # bodies: J_b G, accelerations, Newton-Euler about the com (robomech.dynamics._com_terms)
        Ma[:, :] = 0.0
        vel[:] = 0.0
        grav[:] = 0.0
        for ib in range(B):
            b = d.bidx[ib]
            cx = d.com[ib]
            p0 = T[b, 0, 3] + T[b, 0, 0] * cx[0] + T[b, 0, 1] * cx[1] + T[b, 0, 2] * cx[2]
            p1 = T[b, 1, 3] + T[b, 1, 0] * cx[0] + T[b, 1, 1] * cx[1] + T[b, 1, 2] * cx[2]
            p2 = T[b, 2, 3] + T[b, 2, 0] * cx[0] + T[b, 2, 1] * cx[1] + T[b, 2, 2] * cx[2]
            Ib = d.inertia[ib]
            for i in range(3):  # R I R^T
                for j in range(3):
                    acc = 0.0
                    for u in range(3):
                        ru = 0.0
                        for v in range(3):
                            ru += Ib[u, v] * T[b, j, v]
                        acc += T[b, i, u] * ru
                    Iw[i, j] = acc
            SG[:, :] = 0.0
            for k in range(nv):
                if A[b, k] != 0.0:
                    for j in range(na):
                        g = G[k, j]
                        if g != 0.0:
                            for i in range(6):
                                SG[i, j] += S[k, i] * g
            for j in range(na):
                s0, s1, s2 = SG[0, j], SG[1, j], SG[2, j]
                JG[0, j], JG[1, j], JG[2, j] = s0, s1, s2
                JG[3, j] = SG[3, j] + (s1 * p2 - s2 * p1)
                JG[4, j] = SG[4, j] + (s2 * p0 - s0 * p2)
                JG[5, j] = SG[5, j] + (s0 * p1 - s1 * p0)
            w0, w1, w2 = V[b, 0], V[b, 1], V[b, 2]
            pd0 = V[b, 3] + w1 * p2 - w2 * p1
            pd1 = V[b, 4] + w2 * p0 - w0 * p2
            pd2 = V[b, 5] + w0 * p1 - w1 * p0
            e0, e1, e2 = Vd[b, 0] + Vc[b, 0], Vd[b, 1] + Vc[b, 1], Vd[b, 2] + Vc[b, 2]
            a0[0], a0[1], a0[2] = e0, e1, e2
            a0[3] = Vd[b, 3] + Vc[b, 3] + (e1 * p2 - e2 * p1) + (w1 * pd2 - w2 * pd1)
            a0[4] = Vd[b, 4] + Vc[b, 4] + (e2 * p0 - e0 * p2) + (w2 * pd0 - w0 * pd2)
            a0[5] = Vd[b, 5] + Vc[b, 5] + (e0 * p1 - e1 * p0) + (w0 * pd1 - w1 * pd0)
            for i in range(3):  # the angular velocity J_w G qd_act, as _com_terms has it
                acc = 0.0
                for j in range(na):
                    acc += JG[i, j] * qa[j]
                wb[i] = acc
            for i in range(3):
                Iwb[i] = Iw[i, 0] * wb[0] + Iw[i, 1] * wb[1] + Iw[i, 2] * wb[2]
            mb = d.mass[ib]
            for i in range(3):
                rhs[i] = Iw[i, 0] * a0[0] + Iw[i, 1] * a0[1] + Iw[i, 2] * a0[2]
                rhs[3 + i] = mb * a0[3 + i]
            rhs[0] += wb[1] * Iwb[2] - wb[2] * Iwb[1]
            rhs[1] += wb[2] * Iwb[0] - wb[0] * Iwb[2]
            rhs[2] += wb[0] * Iwb[1] - wb[1] * Iwb[0]
            for i in range(3):
                for j in range(na):
                    IJ[i, j] = Iw[i, 0] * JG[0, j] + Iw[i, 1] * JG[1, j] + Iw[i, 2] * JG[2, j]
            for j in range(na):
                acc = 0.0
                for i in range(6):
                    acc += JG[i, j] * rhs[i]
                vel[j] += acc
                grav[j] -= mb * (JG[3, j] * gv[0] + JG[4, j] * gv[1] + JG[5, j] * gv[2])
                for c in range(na):
                    Ma[j, c] += (
                        JG[0, j] * IJ[0, c]
                        + JG[1, j] * IJ[1, c]
                        + JG[2, j] * IJ[2, c]
                        + mb * (JG[3, j] * JG[3, c] + JG[4, j] * JG[4, c] + JG[5, j] * JG[5, c])
                    )
        # site wrenches: ex = -G^T sum_s J_s^T W_s
        site_forces(T, S, A, W[n], wsb, wT, ps, ext)
        for j in range(na):
            acc = 0.0
            for k in range(nv):
                acc += G[k, j] * ext[k]
            ex[j] = acc
        ok = True
        if redundant:  # the redundant-actuation rule's projector Pi (module docstring of _dynamics)
            for i in range(m):
                for j in range(na):
                    acc = 0.0
                    for k in range(nv):
                        acc += K[i, k] * G[k, j]
                    KG[i, j] = acc / L
            sf = np.zeros(na)
            if m > 0 and _all_finite(KG):
                _, sv, Vt_ = np.linalg.svd(KG, full_matrices=True)
                Vt = np.ascontiguousarray(Vt_)
                for i in range(min(sv.shape[0], na)):
                    sf[i] = sv[i]
            elif m > 0:
                Vt = np.eye(na)
                sf[:] = np.nan
            else:
                Vt = np.eye(na)
            Nc = np.ascontiguousarray(Vt[na - dof :].T)  # (na, dof) spans null(K G)
            top = 1.0
            for i in range(na):
                if not sf[i] <= top:
                    top = sf[i] if sf[i] == sf[i] else np.nan
            thr = d.rank_rtol * 1e2 * top
            for i in range(na - dof, na):
                if not sf[i] <= thr:
                    ok = False
            if dof < na and not sf[na - dof - 1] > thr:
                ok = False
            if wts.shape[0] == 0:
                Pi = Nc @ Nc.T
            else:
                WN = np.empty((na, dof))
                for i in range(na):
                    for j in range(dof):
                        WN[i, j] = wts[i] * Nc[i, j]
                Aw = Nc.T @ WN
                if _all_finite(Aw):
                    sa = np.linalg.svd(Aw, full_matrices=False)[1]
                    cw = sa[0] / sa[-1] if sa[-1] > 0 else np.inf
                else:
                    cw = np.nan
                if not cw < 1.0 / d.rank_rtol:
                    ok = False
                    Aw = np.eye(dof)
                Pi = WN @ np.linalg.solve(Aw, np.ascontiguousarray(Nc.T))
            Ma[:, :] = Pi @ Ma
            vel[:] = Pi @ vel
            grav[:] = Pi @ grav
            ex[:] = Pi @ ex
        fin = True
        for j in range(na):
            acc = vel[j] + grav[j] + ex[j]
            s_ = 0.0
            for c in range(na):
                s_ += Ma[j, c] * qdda[c]
                if not np.isfinite(Ma[j, c]):
                    fin = False
            tau_o[n, j] = s_ + acc
            if not np.isfinite(tau_o[n, j]):
                fin = False
        # admissibility of the prescribed motion
        adm = 0.0
        if m > 0:
            sv_ = _amax_abs(qd)
            sa_ = _amax_abs(qdd) + sv_ * sv_
            for i in range(m):
                acc = 0.0
                acc2 = kdq[i]
                for k in range(nv):
                    acc += K[i, k] * qd[k]
                    acc2 += K[i, k] * qdd[k]
                tmpm[i] = acc
                r[i] = acc2
            e1 = _amax_abs(tmpm) / (L * max(sv_, d.rate_floor))
            e2 = _amax_abs(r) / (L * max(sa_, d.rate_floor))
            if e1 != e1 or e2 != e2 or sv_ != sv_ or sa_ != sa_:
                adm = np.nan
            else:
                adm = max(e1, e2)
        Ma_o[n] = Ma
        vel_o[n] = vel
        grav_o[n] = grav
        ex_o[n] = ex
        qd_o[n] = qd
        qdd_o[n] = qdd
        cond_o[n] = cond
        smin_o[n] = smin
        adm_o[n] = adm
        valid_o[n] = ok and fin and rank >= d.rank0 and cond <= d.singular_cond and adm <= d.admissible_rtol


@numba.njit(cache=True, error_model="numpy", parallel=True)
def inv_dyn_par(
    Q,
    QD,
    QDD,
    W,
    wsb,
    wT,
    gv,
    wts,
    t,
    d,
    tau_o,
    Ma_o,
    vel_o,
    grav_o,
    ex_o,
    qd_o,
    qdd_o,
    cond_o,
    smin_o,
    adm_o,
    valid_o,
    clo_o,
):  # pragma: no cover - compiled
    """:func:`inv_dyn_block` over ``Q`` in blocks of ``BLOCK`` samples, in parallel."""
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        inv_dyn_block(
            k * BLOCK,
            min(N, (k + 1) * BLOCK),
            Q,
            QD,
            QDD,
            W,
            wsb,
            wT,
            gv,
            wts,
            t,
            d,
            tau_o,
            Ma_o,
            vel_o,
            grav_o,
            ex_o,
            qd_o,
            qdd_o,
            cond_o,
            smin_o,
            adm_o,
            valid_o,
            clo_o,
        )


def inv_dyn(*args) -> None:
    """:func:`inv_dyn_block` on every sample: one block in this thread for a small batch, in parallel
    blocks for a large one (the same per-sample code either way: results do not depend on the batch)."""
    N = args[0].shape[0]
    if N <= BLOCK:
        inv_dyn_block(0, N, *args)
    else:
        inv_dyn_par(*args)


_NO_W = (np.zeros((1, 0, 6)), np.zeros(0, dtype=np.int64), np.zeros((0, 4, 4)))
_ZERO_G = np.zeros(3)
_NO_WTS = np.zeros(0)


def inv_dyn_one(model, q: np.ndarray, qd_a: np.ndarray, qdd_a: np.ndarray, gravity, on: bool) -> tuple | None:
    """One sample through :func:`inv_dyn_block` with the least Python around it: the kernel's outputs
    ``(tau, M_a, vel, grav, ext, qd, qdd, cond, smin, adm, valid, closure)`` with a leading axis of 1,
    or None where the sample is not valid or not assembled (the caller's general path then flags it)."""
    tree = model.tree
    na, nv = len(model.act), tree.nv
    gv = model.cache.get("gravity_vector")
    if gv is None:
        gv = model.cache["gravity_vector"] = np.array(gravity, dtype=float)
    if not on:
        gv = _ZERO_G
    outs = (
        np.empty((1, na)),
        np.empty((1, na, na)),
        np.empty((1, na)),
        np.empty((1, na)),
        np.empty((1, na)),
        np.empty((1, nv)),
        np.empty((1, nv)),
        np.empty(1),
        np.empty(1),
        np.empty(1),
        np.empty(1, dtype=np.bool_),
        np.empty(1),
    )
    args = (0, 1, q.reshape(1, -1), qd_a.reshape(1, -1), qdd_a.reshape(1, -1), *_NO_W, gv, _NO_WTS)
    call = (*args, model.tables, model.dyn, *outs)
    fn = model.cache.get("inv_dyn_entry")
    if fn is None:
        inv_dyn_block(*call)  # compiles or loads the kernel, then its entry point skips the type dispatch
        sig = tuple(numba.typeof(a) for a in call)
        fn = model.cache["inv_dyn_entry"] = inv_dyn_block.overloads[sig].entry_point
    else:
        fn(*call)
    if not outs[10][0] or not outs[11][0] <= opt.CLOSURE_RTOL * model.tables.L:
        return None
    if model.tables.m == 0 or len(model.pas) == 0:  # the empty passive block's measures
        outs[7][0], outs[8][0] = 1.0, model.tables.L
    return outs


def compiled_fk(
    mech, q: np.ndarray, free: np.ndarray, max_iter: int = opt.MAX_ITER
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The closure solve on ``q (N, nq)`` over the velocity coordinates ``free``: (q, rc, iterations,
    total residual ``sqrt(sum r^2)``), ``rc`` the largest closure row (m)."""
    model = compile_model(mech)
    tree = model.tree
    key = ("fk_wstep", free.tobytes())
    wstep = model.cache.get(key)
    if wstep is None:
        wstep = model.cache[key] = np.where(tree.dof_translational, 1.0 / tree.length, 1.0)[free].astype(
            float
        )
    return closure_solve(model.tables, q, free, wstep, max_iter)


def closure_solve(
    t, q: np.ndarray, free: np.ndarray, wstep: np.ndarray, max_iter: int = opt.MAX_ITER
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`compiled_fk` on the packed tables ``t`` (``wstep (nf,)``: 1 / L for a translation of
    ``free``, 1 for a rotation), for the compile step that assembles a reference before its model exists."""
    Q = np.array(q, dtype=np.float64, order="C")
    N = Q.shape[0]
    rc, it, cost = np.empty(N), np.zeros(N, dtype=np.int64), np.empty(N)
    args = (
        np.ascontiguousarray(free, dtype=np.int64),
        writable(wstep),
        t,
        int(max_iter),
        (opt.STOP_RTOL * t.L) ** 2,
        opt.MU_START,
        opt.MU_MIN,
        opt.MU_MAX,
        opt.MAX_STEP,
        rc,
        it,
        cost,
    )
    if N <= BLOCK:
        fk_block(Q, 0, N, *args)
    else:
        fk_par(Q, *args)
    return Q, rc, it, np.sqrt(cost)


def compiled_site_jacobian(mech, q: np.ndarray, site: int) -> np.ndarray:
    """``J (N, 6, n_act)`` of site index ``site`` at ``q (N, nq)`` (:func:`site_jac_block`)."""
    model = compile_model(mech)
    tree = model.tree
    Q = np.ascontiguousarray(q, dtype=np.float64)
    J = np.empty((Q.shape[0], 6, len(model.act)))
    args = (
        model.act,
        model.pas,
        int(tree.site_body[site]),
        np.ascontiguousarray(tree.T_site[site]),
        model.tables,
        opt.PASSIVE_RANK_RTOL,
        J,
    )
    if Q.shape[0] <= BLOCK:
        site_jac_block(Q, 0, Q.shape[0], *args)
    else:
        site_jac_par(Q, *args)
    return J


def compiled_influence(model, q: np.ndarray, second: bool, site: int = -1) -> tuple:
    """``(G, dG, H, rank, consistency, sigma_min, cond)`` at ``q (N, nq)`` (:func:`influence_block`):
    ``G (N, nv, na)``; with ``second`` also ``dG (N, nv, na, na)`` and, for a site index ``site >= 0``,
    the site Hessian ``H (N, 6, na, na)`` (else None)."""
    tree = model.tree
    Q = writable(q)
    N, nv, na = Q.shape[0], tree.nv, len(model.act)
    sb = int(tree.site_body[site]) if site >= 0 else -1
    Tsite = np.ascontiguousarray(tree.T_site[site], dtype=float) if site >= 0 else np.eye(4)
    G = np.empty((N, nv, na))
    dG = np.empty((N if second else 0, nv, na, na))
    H = np.empty((N if second and site >= 0 else 0, 6, na, na))
    rank, cons, smin, cond = np.empty(N, dtype=np.int64), np.empty(N), np.empty(N), np.empty(N)
    args = (model.act, model.pas, sb, Tsite, model.tables, opt.PASSIVE_RANK_RTOL, bool(second))
    outs = (G, dG, H, rank, cons, smin, cond)
    if N <= BLOCK:
        entry(model, influence_block, f"influence_block_{second}", (Q, 0, N, *args, *outs))
    else:
        influence_par(Q, *args, *outs)
    second = second and na > 0  # no input: no second-order coefficients (None, as without second)
    return G, (dG if second else None), (H if second and site >= 0 else None), rank, cons, smin, cond


@overload
def compiled_resjac(
    model_or_tables, q: np.ndarray, with_jac: Literal[True]
) -> tuple[np.ndarray, np.ndarray]: ...
@overload
def compiled_resjac(
    model_or_tables, q: np.ndarray, with_jac: bool
) -> tuple[np.ndarray, np.ndarray | None]: ...
def compiled_resjac(model_or_tables, q: np.ndarray, with_jac: bool) -> tuple[np.ndarray, np.ndarray | None]:
    """The closure residual ``(N, m)`` and, with ``with_jac``, the velocity constraint matrix
    ``K (N, m, nv)`` (else None) at ``q (N, nq)`` (:func:`resjac_block`).  ``model_or_tables``: a
    compiled model or its :class:`Tables` (:func:`compiled_kinematics`)."""
    t, model = _tables_of(model_or_tables)
    Q = writable(q)
    N, m, nv = Q.shape[0], t.m, t.A.shape[1]
    R = np.empty((N, m))
    K = np.empty((N if with_jac else 0, m, nv))
    if N > BLOCK:
        resjac_par(Q, t, bool(with_jac), R, K)
    elif model is None:
        resjac_block(Q, 0, N, t, bool(with_jac), R, K)
    else:
        entry(model, resjac_block, "resjac_block", (Q, 0, N, t, bool(with_jac), R, K))
    return R, (K if with_jac else None)


def compiled_jacobian_rate(model, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """``dK/dt (N, m, nv)`` along ``qd (N, nv)`` at ``q (N, nq)`` (:func:`kdot_block`)."""
    Q, QD = writable(q), writable(qd)
    N = Q.shape[0]
    KD = np.empty((N, model.tables.m, model.tree.nv))
    if N <= BLOCK:
        entry(model, kdot_block, "kdot_block", (Q, QD, 0, N, model.tables, KD))
    else:
        kdot_par(Q, QD, model.tables, KD)
    return KD


# ----------------------------------------------------------------------------- tree inverse dynamics (RNEA)
@_nj
def _mcross(w0, w1, w2, v0, v1, v2, S, k, out, f):  # pragma: no cover - compiled
    """``out += f * (V x S_k)`` for the spatial motion ``V = [w; v]``: ``[w x ws; w x vs + v x ws]``."""
    a0, a1, a2, b0, b1, b2 = S[k, 0], S[k, 1], S[k, 2], S[k, 3], S[k, 4], S[k, 5]
    out[0] += f * (w1 * a2 - w2 * a1)
    out[1] += f * (w2 * a0 - w0 * a2)
    out[2] += f * (w0 * a1 - w1 * a0)
    out[3] += f * ((w1 * b2 - w2 * b1) + (v1 * a2 - v2 * a1))
    out[4] += f * ((w2 * b0 - w0 * b2) + (v2 * a0 - v0 * a2))
    out[5] += f * ((w0 * b1 - w1 * b0) + (v0 * a1 - v1 * a0))


@_nj
def _inertia_apply(mb, c, Ic, X, out):  # pragma: no cover - compiled
    """``out = I X`` for the spatial inertia (mass ``mb``, world com ``c``, inertia about it ``Ic``) and
    a motion ``X = [w; v]`` about the world origin: ``f = m (v + w x c)``, ``n = Ic w + c x f``."""
    w0, w1, w2 = X[0], X[1], X[2]
    f0 = mb * (X[3] + w1 * c[2] - w2 * c[1])
    f1 = mb * (X[4] + w2 * c[0] - w0 * c[2])
    f2 = mb * (X[5] + w0 * c[1] - w1 * c[0])
    out[3], out[4], out[5] = f0, f1, f2
    out[0] = Ic[0, 0] * w0 + Ic[0, 1] * w1 + Ic[0, 2] * w2 + (c[1] * f2 - c[2] * f1)
    out[1] = Ic[1, 0] * w0 + Ic[1, 1] * w1 + Ic[1, 2] * w2 + (c[2] * f0 - c[0] * f2)
    out[2] = Ic[2, 0] * w0 + Ic[2, 1] * w1 + Ic[2, 2] * w2 + (c[0] * f1 - c[1] * f0)


@_nj
def inertia_world(T, t, ib, c, Ic, RI):  # pragma: no cover - compiled
    """World centre of mass ``c (3,)`` and inertia about it ``Ic = R I R^T (3, 3)`` of the massive body
    ``t.bidx[ib]`` (``RI (3, 3)`` scratch: ``I R^T``)."""
    b = t.bidx[ib]
    cx = t.com[ib]
    Ib = t.inertia[ib]
    for i in range(3):
        c[i] = T[b, i, 3] + T[b, i, 0] * cx[0] + T[b, i, 1] * cx[1] + T[b, i, 2] * cx[2]
    for u in range(3):
        for j in range(3):
            RI[u, j] = Ib[u, 0] * T[b, j, 0] + Ib[u, 1] * T[b, j, 1] + Ib[u, 2] * T[b, j, 2]
    for i in range(3):
        for j in range(3):
            Ic[i, j] = T[b, i, 0] * RI[0, j] + T[b, i, 1] * RI[1, j] + T[b, i, 2] * RI[2, j]


@_nj
def rnea_block(lo, hi, Q, QD, QDD, gv, t, tau_o):  # pragma: no cover - compiled
    """The spanning tree's recursive Newton-Euler inverse dynamics of samples ``lo:hi`` (world frame,
    the formulation of ``_rnea``: forward pass of twists and accelerations, the base accelerating at
    ``[0; -g]``, body wrenches ``I A + V x* I V``, backward pass, ``tau_k = S_k . F_subtree``)."""
    nb = t.parent.shape[0]
    nv = t.nv
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    V = np.empty((nb, 6))
    Acc = np.empty((nb, 6))
    F = np.empty((nb, 6))
    vj = np.empty(6)
    c = np.empty(3)
    Ic = np.empty((3, 3))
    RI = np.empty((3, 3))
    h = np.empty(6)
    fa = np.empty(6)
    Rj = np.empty((3, 3))
    Rn = np.empty((3, 3))
    anchor = np.empty(3)
    for n in range(lo, hi):
        q, qd, qdd = Q[n], QD[n], QDD[n]
        kin_into(q, t, T, S, Rj, Rn, anchor)
        for i in range(6):
            V[0, i] = 0.0
            Acc[0, i] = 0.0
        for i in range(3):
            Acc[0, 3 + i] = -gv[i]
        for b in range(1, nb):
            p = t.parent[b]
            for i in range(6):
                V[b, i] = V[p, i]
                Acc[b, i] = Acc[p, i]
            for k in range(t.j0[b], t.j0[b + 1]):
                typ, da = t.jtype[k], t.jdadr[k]
                nd = 1 if typ <= 1 else (3 if typ == 2 else 6)
                for i in range(6):
                    acc = 0.0
                    acc2 = 0.0
                    for j in range(nd):
                        acc += S[da + j, i] * qd[da + j]
                        acc2 += S[da + j, i] * qdd[da + j]
                    vj[i] = acc
                    Acc[b, i] += acc2
                w0, w1, w2, v0, v1, v2 = V[b, 0], V[b, 1], V[b, 2], V[b, 3], V[b, 4], V[b, 5]
                if typ <= 1:  # the axis is carried by the frame before the joint
                    _mcross(w0, w1, w2, v0, v1, v2, S, da, Acc[b], qd[da])
                elif typ == 2:  # ball: axes of the frame after it
                    for j in range(3):
                        _mcross(
                            w0 + vj[0],
                            w1 + vj[1],
                            w2 + vj[2],
                            v0 + vj[3],
                            v1 + vj[4],
                            v2 + vj[5],
                            S,
                            da + j,
                            Acc[b],
                            qd[da + j],
                        )
                else:  # free: rotation axes the body's own, moved by the joint's own twist
                    for j in range(3, 6):
                        _mcross(vj[0], vj[1], vj[2], vj[3], vj[4], vj[5], S, da + j, Acc[b], qd[da + j])
                for i in range(6):
                    V[b, i] += vj[i]
        F[:, :] = 0.0
        for ib in range(t.bidx.shape[0]):
            b = t.bidx[ib]
            inertia_world(T, t, ib, c, Ic, RI)
            _inertia_apply(t.mass[ib], c, Ic, Acc[b], fa)
            _inertia_apply(t.mass[ib], c, Ic, V[b], h)
            w0, w1, w2, v0, v1, v2 = V[b, 0], V[b, 1], V[b, 2], V[b, 3], V[b, 4], V[b, 5]
            F[b, 0] = fa[0] + (w1 * h[2] - w2 * h[1]) + (v1 * h[5] - v2 * h[4])
            F[b, 1] = fa[1] + (w2 * h[0] - w0 * h[2]) + (v2 * h[3] - v0 * h[5])
            F[b, 2] = fa[2] + (w0 * h[1] - w1 * h[0]) + (v0 * h[4] - v1 * h[3])
            F[b, 3] = fa[3] + (w1 * h[5] - w2 * h[4])
            F[b, 4] = fa[4] + (w2 * h[3] - w0 * h[5])
            F[b, 5] = fa[5] + (w0 * h[4] - w1 * h[3])
        for b in range(nb - 1, 0, -1):
            p = t.parent[b]
            for i in range(6):
                F[p, i] += F[b, i]
        for b in range(1, nb):
            for k in range(t.j0[b], t.j0[b + 1]):
                typ, da = t.jtype[k], t.jdadr[k]
                nd = 1 if typ <= 1 else (3 if typ == 2 else 6)
                for j in range(nd):
                    acc = 0.0
                    for i in range(6):
                        acc += S[da + j, i] * F[b, i]
                    tau_o[n, da + j] = acc


@numba.njit(cache=True, error_model="numpy", parallel=True)
def rnea_par(Q, QD, QDD, gv, t, tau_o):  # pragma: no cover - compiled
    """:func:`rnea_block` over ``Q`` in blocks of ``BLOCK`` samples, in parallel."""
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        rnea_block(k * BLOCK, min(N, (k + 1) * BLOCK), Q, QD, QDD, gv, t, tau_o)


@_nj
def prepare_one(q, vs, jtype, jqadr, qs):  # pragma: no cover - compiled
    """The boundary check of one sample, in the kernel: 0 where every entry of ``q`` and of the
    vectors ``vs`` is within ``MAX_MAGNITUDE`` (False for NaN and inf) and every quaternion is
    non-zero, with ``qs`` = ``q``, its quaternions normalised (``sqrt`` of the sum of squares, as
    ``_rnea._rnea_one``); 1 otherwise (the caller's general path then validates and masks)."""
    big = opt_max_magnitude
    for i in range(q.shape[0]):
        if not abs(q[i]) <= big:
            return 1
        qs[i] = q[i]
    for v in vs:
        for i in range(v.shape[0]):
            if not abs(v[i]) <= big:
                return 1
    for k in range(jtype.shape[0]):
        if jtype[k] >= 2:
            a = jqadr[k] + (3 if jtype[k] == 3 else 0)
            w, x, y, z = qs[a], qs[a + 1], qs[a + 2], qs[a + 3]
            nrm = np.sqrt(w * w + x * x + y * y + z * z)
            if not nrm >= 1e-9:
                return 1
            for i in range(4):
                qs[a + i] /= nrm
    return 0


@_nj
def rnea_one(q, qd, qdd, gv, t, qs, tau):  # pragma: no cover - compiled
    """One sample, checked (:func:`prepare_one`), then :func:`rnea_block` into ``tau (nv,)``."""
    if prepare_one(q, (qd, qdd), t.jtype, t.jqadr, qs) != 0:
        return 1
    nq, nv = qs.shape[0], qd.shape[0]
    rnea_block(0, 1, qs.reshape(1, nq), qd.reshape(1, nv), qdd.reshape(1, nv), gv, t, tau.reshape(1, nv))
    return 0


def entry(model, kernel, key: str, args: tuple):
    """Run ``kernel(*args)`` through its compiled entry point (cached on the model after the first
    call): a direct call skips numba's type dispatch, a few microseconds per call."""
    fn = model.cache.get(key)
    if fn is None:
        out = kernel(*args)  # compiles or loads the kernel
        sig = tuple(numba.typeof(a) for a in args)
        model.cache[key] = kernel.overloads[sig].entry_point
        return out
    return fn(*args)


def writable(x: np.ndarray) -> np.ndarray:
    """``x`` as a C-contiguous, writable float64 array: numba types a read-only array (a broadcast
    view, say) as another argument type, i.e. another specialization to compile at first use."""
    a = np.ascontiguousarray(x, dtype=np.float64)
    return a if a.flags.writeable else a.copy()


def compiled_rnea(model, Q: np.ndarray, QD: np.ndarray, QDD: np.ndarray, gv: np.ndarray) -> np.ndarray:
    """Tree inverse dynamics ``(N, nv)`` (:func:`rnea_block`) at normalised ``Q (N, nq)``, ``QD``, ``QDD``."""
    Q, QD, QDD, gv = writable(Q), writable(QD), writable(QDD), writable(gv)
    N = Q.shape[0]
    tau = np.empty((N, model.tree.nv))
    if N <= BLOCK:
        fn = model.cache.get("rnea_entry")
        args = (0, N, Q, QD, QDD, gv, model.rnea, tau)
        if fn is None:
            rnea_block(*args)
            sig = tuple(numba.typeof(a) for a in args)
            model.cache["rnea_entry"] = rnea_block.overloads[sig].entry_point
        else:
            fn(*args)
    else:
        rnea_par(Q, QD, QDD, gv, model.rnea, tau)
    return tau


# ----------------------------------------------------------------------------- body poses and integration
@_nj
def kin_block(Q, lo, hi, t, T_o, S_o):  # pragma: no cover - compiled
    """World pose of every body ``T_o (N, nb, 4, 4)`` (body 0 the world) and every velocity coordinate's
    space screw ``S_o (N, nv, 6)`` (:func:`kin`) for samples ``lo:hi``; an ``S_o`` of no rows
    (``(0, nv, 6)``): poses only."""
    nv = t.A.shape[1]
    screws = S_o.shape[0] > 0
    S = np.empty((nv, 6))
    Rj, Rn, anchor = np.empty((3, 3)), np.empty((3, 3)), np.empty(3)
    for n in range(lo, hi):
        kin_into(Q[n], t, T_o[n], S_o[n] if screws else S, Rj, Rn, anchor)


@numba.njit(cache=True, error_model="numpy", parallel=True)
def kin_par(Q, t, T_o, S_o):  # pragma: no cover - compiled
    """:func:`kin_block` over ``Q`` in blocks of ``BLOCK`` samples, in parallel."""
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        kin_block(Q, k * BLOCK, min(N, (k + 1) * BLOCK), t, T_o, S_o)


@_nj
def integrate_block(Q, DV, t, Q_o):  # pragma: no cover - compiled
    """``Q_o = Q ⊕ DV`` (:func:`integrate`) for every sample."""
    for n in range(Q.shape[0]):
        integrate(Q[n], DV[n], t.jtype, t.jqadr, t.jdadr, Q_o[n])


def _tables_of(model_or_tables):
    """The packed tables and the model (None when given the tables alone: the compile step, before
    the model exists, calls the kernels through numba's dispatcher)."""
    if isinstance(model_or_tables, Tables):
        return model_or_tables, None
    return model_or_tables.tables, model_or_tables


@overload
def compiled_kinematics(
    model_or_tables, q: np.ndarray, screws: Literal[True] = True
) -> tuple[np.ndarray, np.ndarray]: ...
@overload
def compiled_kinematics(
    model_or_tables, q: np.ndarray, screws: bool
) -> tuple[np.ndarray, np.ndarray | None]: ...
def compiled_kinematics(
    model_or_tables, q: np.ndarray, screws: bool = True
) -> tuple[np.ndarray, np.ndarray | None]:
    """Every body's world pose ``(N, nb, 4, 4)`` and, with ``screws``, every velocity coordinate's
    space screw ``S (N, nv, 6)`` (else None) at normalised ``q (N, nq)`` (:func:`kin_block`).

    Body b's space Jacobian is ``S[:, k]`` over the coordinates ``k`` with ``A[b, k]``: its twist is
    ``V_b = sum_k A[b, k] S_k qd_k``.  ``model_or_tables``: a compiled model or its :class:`Tables`."""
    t, model = _tables_of(model_or_tables)
    Q = writable(q)
    N, nb, nv = Q.shape[0], t.parent.shape[0], t.A.shape[1]
    T = np.empty((N, nb, 4, 4))
    S = np.empty((N if screws else 0, nv, 6))
    if N > BLOCK:
        kin_par(Q, t, T, S)
    elif model is None:
        kin_block(Q, 0, N, t, T, S)
    else:
        entry(model, kin_block, "kin_block", (Q, 0, N, t, T, S))
    return T, (S if screws else None)


def compiled_body_poses(model_or_tables, q: np.ndarray) -> np.ndarray:
    """Every body's world pose ``(N, nb, 4, 4)`` (body 0 the world) at normalised ``q (N, nq)``."""
    return compiled_kinematics(model_or_tables, q, screws=False)[0]


def space_jacobians(A: np.ndarray, S: np.ndarray, bodies) -> np.ndarray:
    """Space-twist Jacobians ``(N, len(bodies), 6, nv)`` of ``bodies`` from the screws ``S (N, nv, 6)``
    of :func:`compiled_kinematics` and the tree's incidence ``A (nb, nv)``: ``V_b = J_b qd`` (``[ω; v]``,
    v of the point at the world origin)."""
    Ab = A[np.asarray(bodies, dtype=np.int64)]  # (nb', nv)
    return (S[:, None] * Ab[None, :, :, None]).swapaxes(-1, -2)


def compiled_integrate(model_or_tables, q: np.ndarray, dv: np.ndarray) -> np.ndarray:
    """``q ⊕ dv (N, nq)``: hinge/slide add, ball/free rotate by ``exp`` of the *local* angular increment
    and renormalise (MuJoCo's ``mj_integratePos``), for ``q (N, nq)``, ``dv (N, nv)``."""
    t, _ = _tables_of(model_or_tables)
    Q, DV = writable(q), writable(dv)
    out = np.empty_like(Q)
    integrate_block(Q, DV, t, out)
    return out


# ----------------------------------------------------------------------------- site pose and energy
@_nj
def site_pose_block(Q, lo, hi, t, sb, Tsite, T_o):  # pragma: no cover - compiled
    """World pose ``T_o (N, 4, 4)`` of the site at ``Tsite`` in body ``sb`` for samples ``lo:hi``."""
    nb = t.parent.shape[0]
    nv = t.A.shape[1]
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    for n in range(lo, hi):
        kin(Q[n], t, T, S)
        for i in range(4):
            for j in range(4):
                T_o[n, i, j] = (
                    T[sb, i, 0] * Tsite[0, j]
                    + T[sb, i, 1] * Tsite[1, j]
                    + T[sb, i, 2] * Tsite[2, j]
                    + T[sb, i, 3] * Tsite[3, j]
                )


@_nj
def energy_block(Q, QD, lo, hi, t, d, gv, K_o, U_o):  # pragma: no cover - compiled
    """Kinetic ``K_o (N,)`` and potential ``U_o (N,)`` energy of the massive bodies (``d`` the dynamics
    tables) for samples ``lo:hi``: ``1/2 (w . I_c w + m |v_c|^2)`` with the centre of mass velocity
    ``v_c = v + w x c`` of the body twist ``[w; v] = sum_k A S_k qd_k``, and ``-m g . c``."""
    nb = t.parent.shape[0]
    nv = t.A.shape[1]
    A = t.A
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    c, Ic, RI = np.empty(3), np.empty((3, 3)), np.empty((3, 3))
    for n in range(lo, hi):
        qd = QD[n]
        kin(Q[n], t, T, S)
        kin_e = 0.0
        pot = 0.0
        for ib in range(d.bidx.shape[0]):
            b = d.bidx[ib]
            m = d.mass[ib]
            inertia_world(T, d, ib, c, Ic, RI)
            w0, w1, w2, v0, v1, v2 = row_twist(A[b], S, qd)
            c0 = v0 + w1 * c[2] - w2 * c[1]
            c1 = v1 + w2 * c[0] - w0 * c[2]
            c2 = v2 + w0 * c[1] - w1 * c[0]
            Iw0 = Ic[0, 0] * w0 + Ic[0, 1] * w1 + Ic[0, 2] * w2
            Iw1 = Ic[1, 0] * w0 + Ic[1, 1] * w1 + Ic[1, 2] * w2
            Iw2 = Ic[2, 0] * w0 + Ic[2, 1] * w1 + Ic[2, 2] * w2
            kin_e += 0.5 * (w0 * Iw0 + w1 * Iw1 + w2 * Iw2 + m * (c0 * c0 + c1 * c1 + c2 * c2))
            pot -= m * (gv[0] * c[0] + gv[1] * c[1] + gv[2] * c[2])
        K_o[n] = kin_e
        U_o[n] = pot


@numba.njit(cache=True, error_model="numpy", parallel=True)
def energy_par(Q, QD, t, d, gv, K_o, U_o):  # pragma: no cover - compiled
    """:func:`energy_block` over ``Q`` in blocks of ``BLOCK`` samples, in parallel."""
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        energy_block(Q, QD, k * BLOCK, min(N, (k + 1) * BLOCK), t, d, gv, K_o, U_o)


@numba.njit(cache=True, error_model="numpy", parallel=True)
def site_pose_par(Q, t, sb, Tsite, T_o):  # pragma: no cover - compiled
    """:func:`site_pose_block` over ``Q`` in blocks of ``BLOCK`` samples, in parallel."""
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        site_pose_block(Q, k * BLOCK, min(N, (k + 1) * BLOCK), t, sb, Tsite, T_o)


def compiled_site_pose(model, q: np.ndarray, site: int) -> np.ndarray:
    """World pose ``(N, 4, 4)`` of site index ``site`` at ``q (N, nq)`` (:func:`site_pose_block`)."""
    tree = model.tree
    Q = writable(q)
    N = Q.shape[0]
    T = np.empty((N, 4, 4))
    sb, Tsite = int(tree.site_body[site]), np.ascontiguousarray(tree.T_site[site], dtype=float)
    if N <= BLOCK:
        entry(model, site_pose_block, "site_pose_block", (Q, 0, N, model.tables, sb, Tsite, T))
    else:
        site_pose_par(Q, model.tables, sb, Tsite, T)
    return T


def compiled_energy(model, q: np.ndarray, qd: np.ndarray, gv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and potential energy ``(N,)`` each at ``q (N, nq)``, ``qd (N, nv)`` under gravity ``gv``
    (:func:`energy_block`)."""
    Q, QD, gv = writable(q), writable(qd), writable(gv)
    N = Q.shape[0]
    Kin, U = np.empty(N), np.empty(N)
    if N <= BLOCK:
        entry(model, energy_block, "energy_block", (Q, QD, 0, N, model.tables, model.dyn, gv, Kin, U))
    else:
        energy_par(Q, QD, model.tables, model.dyn, gv, Kin, U)
    return Kin, U


WARM_PARTS = 2  # warm(part) for part in range(WARM_PARTS) covers every kernel; each fits one process


def warm(part: int | None = None) -> None:
    """Compile (or load) every kernel of this module on a small mechanism, so that a user's first
    call finds them in the on-disk cache (``make install`` runs it).  The kernels' argument types do
    not depend on the mechanism (packed tables of fixed array types), so one specialization per kernel
    serves every mechanism.

    ``part`` (0 or 1) compiles one half: the closed-chain kernels, or the single-sample, design-batched
    and tree-dynamics kernels, so that ``make install`` compiles the halves in two processes at once
    (numba compiles on one thread; the cache's files are written atomically).  ``None``: both.
    """
    import logging

    from . import _dynamics
    from ._singularity import singularities
    from .gallery import load

    if not logging.getLogger("robomech").handlers and not logging.getLogger().handlers:
        logging.basicConfig(level=logging.INFO, format="%(name)s: %(message)s")
        logging.getLogger("robomech").setLevel(logging.INFO)
    if part not in (None, *range(WARM_PARTS)):
        raise ValueError(f"Expected part to be None or one of {list(range(WARM_PARTS))}, got {part!r}.")
    mech = load("four_bar")
    model = compile_model(mech)
    site = mech.tree.site_index(mech.sites[0].name)
    for n in (1, 2 * BLOCK + 1) if part in (None, 0) else ():  # one block in this thread, then parallel
        q = np.tile(mech.q0, (n, 1))
        qf, _, _, _ = compiled_fk(mech, q, model.pas)
        compiled_site_jacobian(mech, qf, site)
        compiled_influence(model, qf, True, site)  # influence coefficients and site Hessians
        singularities(mech, qf, mech.sites[0].name)  # singular values of the scaled K, K_p and J
        zv = np.zeros((n, mech.nv))
        _dynamics.inverse_dynamics(mech, qf, qd=zv, qdd=zv)  # the full-rate inverse dynamics kernel
        if n == 1:
            compiled_project(model, qf, zv)  # simulate's projection (one sample per call)
        z = np.zeros((n, len(model.act)))
        _dynamics._inverse_compiled(mech, qf, z, z, {}, None, True)
        _dynamics.forward_dynamics(mech, qf, z, tau=z)  # the closed-chain forward dynamics kernel
    if part == 0:
        return
    inv_dyn_one(model, mech.q0, np.zeros(1), np.zeros(1), mech.gravity, True)
    from ._designs import design_batch, ik_designs, site_measures_designs

    batch = design_batch([mech, mech], mech.sites[0].name)  # the design-batched drivers
    for n in (1, 2 * BLOCK + 1):
        di = np.arange(n) % 2
        T = np.broadcast_to(np.eye(4), (n, 4, 4)).copy()
        ik_designs(batch, di, T, batch.q_ref[di], np.ones(6), steps=2)
        site_measures_designs(batch, di, batch.q_ref[di], [3, 4, 5])
    from ._rnea import generalized_forces, mass_matrix

    tree_mech = _open_chain()  # the tree dynamics through the public calls (forward dynamics too)
    for n in (1, 2 * BLOCK + 1):
        q = np.tile(mech.q0, (n, 1))
        z = np.zeros((n, mech.nv))
        generalized_forces(mech, q, z, z)
        mass_matrix(mech, q)
        z = np.zeros((n, tree_mech.nv))
        _dynamics.forward_dynamics(tree_mech, z, tau=z, qd=z)
    z1 = np.zeros(mech.nv)
    generalized_forces(mech, np.array(mech.q0, dtype=float), z1, z1)
    mass_matrix(mech, np.array(mech.q0, dtype=float))
    z = np.zeros(tree_mech.nv)
    _dynamics.forward_dynamics(tree_mech, z, tau=z, qd=z)
    from ._designs import closure_designs, inverse_dynamics_designs
    from ._influence import constraint_jacobian, constraint_jacobian_rate, constraint_residual, site_pose
    from ._rnea_kernels import passive_rank_measures

    name = mech.sites[0].name
    for n in (1, 2 * BLOCK + 1):  # closure rows, dK/dt, site poses, energies, rank measures
        q = np.tile(mech.q0, (n, 1))
        compiled_kinematics(model, q)  # body poses and screws (drawing, export, the compile step)
        compiled_integrate(model.tables, q, np.zeros((n, mech.nv)))
        zv, za = np.zeros((n, mech.nv)), np.zeros((n, len(model.act)))
        constraint_residual(mech, q)
        constraint_jacobian(mech, q)
        constraint_jacobian_rate(mech, q, zv)
        site_pose(mech, q, name)
        _dynamics.energy(mech, q, zv)
        passive_rank_measures(model, q)
        di = np.arange(n) % 2  # the design-batched inverse dynamics and closure solve
        inverse_dynamics_designs(batch, di, q, za, za)
        closure_designs(batch, di, q.copy(), model.pas)


def _open_chain():
    """A two-link open chain (both joints actuated), for :func:`warm`."""
    from ._model import Builder, Inertial

    b = Builder("warm_2r")
    b.body("l1", joints=[b.hinge("j1", axis=(0, 0, 1))], inertial=Inertial(1.0, pos=(0.1, 0, 0)))
    b.body(
        "l2",
        parent="l1",
        pos=(0.2, 0, 0),
        joints=[b.hinge("j2", axis=(0, 1, 0))],
        inertial=Inertial(1.0, pos=(0.1, 0, 0)),
    )
    b.actuate("j1", "j2")
    return b.build()
