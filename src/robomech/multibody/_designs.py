"""Design-batched drivers: many designs of one structure times many poses in one kernel call.

A compiled model (``_compile.Model``) separates the *structure* of a mechanism (its topology, joint
types and coordinate addresses, which joints are actuated, how the closure rows pair bodies: the
integer fields of :class:`~robomech.multibody._compile.Tables` and the reference ranks) from its
*geometry* (the numbers: joint frames, anchors, axes, references, closure anchors and relative
rotations, coupling polynomials, the characteristic length).  :func:`design_batch` stacks the
geometry of designs that share a structure into :class:`Geometry` (a leading design axis); the
kernels here take a design index per sample and hand the per-sample kernels of ``_compiled`` (the
Levenberg–Marquardt solve :func:`~robomech.multibody._compiled.lm_solve`, the site Jacobian
:func:`~robomech.multibody._compiled.site_jac_one`) that design's :class:`Tables`, rebuilt in the
kernel from the structure and the design's rows (:func:`design_tables`; no copy).  Each sample runs
the same code as the single-design kernels with the same numbers, so a design evaluated in a batch
of many equals the design evaluated alone (bit for bit on one machine).

Designs whose structure differs (a ``build`` that changes topology with its parameters) cannot share
a batch: :func:`design_batch` refuses them (:class:`StructureMismatch`) and :func:`group_designs`
splits a list of designs into batches of one structure each.

The inverse dynamics is batched the same way: the bodies' masses, centres of mass and inertias are
numbers per design (:class:`Inertias`, the numbers of :class:`~robomech.multibody._compile.DynTables`;
which bodies carry mass is structure), and :func:`inverse_dynamics_designs` runs the compiled
inverse-dynamics kernel :func:`~robomech.multibody._compiled.inv_dyn_block` on each run of
consecutive samples of one design with that design's tables (:func:`design_dyn`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from . import _options as opt
from ._compile import DynTables, Model, Tables, compile_model
from ._compiled import BLOCK, _nj, inv_dyn_block, kin, lm_solve, numba, site_jac_one, writable

__all__ = [
    "DesignBatch",
    "Geometry",
    "Inertias",
    "StructureMismatch",
    "closure_designs",
    "design_batch",
    "group_designs",
    "ik_designs",
    "inverse_dynamics_designs",
    "single_design",
    "site_measures_designs",
    "site_poses_designs",
]


class Geometry(NamedTuple):
    """The numbers of :class:`Tables` per design (leading axis D), for designs of one structure."""

    T_off: NDArray[np.float64]  # (D, nb, 4, 4)
    jpos: NDArray[np.float64]  # (D, nj, 3)
    jaxis: NDArray[np.float64]  # (D, nj, 3)
    jref: NDArray[np.float64]  # (D, nj)
    px: NDArray[np.float64]  # (D, np, 2, 3)
    rR: NDArray[np.float64]  # (D, nr, 3, 3)
    cf: NDArray[np.float64]  # (D, nc, 8)
    L: NDArray[np.float64]  # (D,)


class Inertias(NamedTuple):
    """The numbers of :class:`DynTables` per design (leading axis D): the massive bodies' inertias."""

    mass: NDArray[np.float64]  # (D, B) kg
    com: NDArray[np.float64]  # (D, B, 3) m, body frame
    inertia: NDArray[np.float64]  # (D, B, 3, 3) kg m^2 about the com, body axes


# The fields of Tables that are structure (equal for every design of a batch); the others are Geometry's.
STRUCTURE_FIELDS = tuple(f for f in Tables._fields if f not in Geometry._fields)
# The same for DynTables and Inertias.
DYN_STRUCTURE_FIELDS = tuple(f for f in DynTables._fields if f not in Inertias._fields)


class StructureMismatch(ValueError):
    """Designs whose compiled structure differs cannot share one design-batched kernel call."""


@_nj
def design_tables(t, g, d):  # pragma: no cover - compiled
    """The :class:`Tables` of design ``d``: the structure of ``t``, the numbers of row ``d`` of ``g``."""
    return Tables(
        t.parent,
        g.T_off[d],
        t.j0,
        t.jtype,
        t.jqadr,
        t.jdadr,
        g.jpos[d],
        g.jaxis[d],
        g.jref[d],
        t.A,
        t.C,
        t.dof_tr,
        t.pp,
        g.px[d],
        t.rr,
        g.rR[d],
        t.cc,
        g.cf[d],
        t.geom_row,
        t.m,
        g.L[d],
    )


@_nj
def design_dyn(dt, g, d):  # pragma: no cover - compiled
    """The :class:`DynTables` of design ``d``: the structure of ``dt``, the inertias of row ``d`` of ``g``."""
    return DynTables(
        dt.bidx,
        g.mass[d],
        g.com[d],
        g.inertia[d],
        dt.act,
        dt.pas,
        dt.rank0,
        dt.dof,
        dt.gram_cond_max,
        dt.gram_refine_cond,
        dt.gram_refine2_cond,
        dt.pinv_rtol,
        dt.rank_rtol,
        dt.singular_cond,
        dt.admissible_rtol,
        dt.rate_floor,
    )


def _structure(model: Model, site_body: int) -> tuple[Any, ...]:
    key: list[Any] = [site_body, model.tree.nq, model.tree.nv, model.rank_K, model.idle_dof, model.locked_dof]
    key += [model.act.tobytes(), model.pas.tobytes()]
    for tables, fields in ((model.tables, STRUCTURE_FIELDS), (model.dyn, DYN_STRUCTURE_FIELDS)):
        for f in fields:
            v = getattr(tables, f)
            key.append((v.shape, v.dtype.str, v.tobytes()) if isinstance(v, np.ndarray) else v)
    return tuple(key)


@dataclass(frozen=True, eq=False)
class DesignBatch:
    """Designs of one structure, packed for the design-batched kernels (made by :func:`design_batch`).

    ``tables`` holds the first design's tables (its structure fields are every design's);
    ``geometry`` the numbers per design; ``T_site (D, 4, 4)`` the site's pose in its body,
    ``q_ref (D, nq)`` the assembled references, ``length (D,)`` the characteristic lengths (m);
    ``dyn`` the first design's :class:`DynTables` (structure), ``inertias`` the numbers per design,
    ``gravity (D, 3)`` each design's gravity (m/s^2), ``tree`` the first design's compiled tree (its
    structure: the quaternion addresses)."""

    tables: Tables
    geometry: Geometry
    dyn: DynTables
    inertias: Inertias
    gravity: np.ndarray
    tree: Any
    act: np.ndarray
    pas: np.ndarray
    site_body: int
    T_site: np.ndarray
    q_ref: np.ndarray
    length: np.ndarray
    dof_translational: np.ndarray  # (nv,) bool
    rank_K: int
    locked_dof: int

    @property
    def n(self) -> int:
        """Number of designs."""
        return int(self.length.shape[0])


def design_batch(mechs: Sequence[Any], site: str) -> DesignBatch:
    """Stack the compiled geometry of ``mechs`` (one structure) with the output ``site``.

    Raises
    ------
    StructureMismatch
        If a design's structure (topology, joint types, actuation, closure pairing, reference ranks,
        the site's body) differs from the first's; :func:`group_designs` splits such a list instead.
    ValueError
        If ``mechs`` is empty or a design has no site ``site``.
    """
    if not len(mechs):
        raise ValueError("Expected mechs to hold at least one design, got none.")
    models = [compile_model(m) for m in mechs]
    sites = [m.tree.site_index(site) for m in models]
    keys = [_structure(m, int(m.tree.site_body[s])) for m, s in zip(models, sites, strict=True)]
    for i, k in enumerate(keys):
        if k != keys[0]:
            raise StructureMismatch(
                f"Expected designs of one structure (topology, joint types, actuation, closure pairing, "
                f"reference ranks), got design {i} differing from design 0: compile it on its own "
                "(group_designs splits a list by structure)."
            )
    m0 = models[0]
    geom = Geometry(
        *(
            np.ascontiguousarray(np.stack([getattr(m.tables, f) for m in models]), dtype=float)
            for f in Geometry._fields
        )
    )
    return DesignBatch(
        tables=m0.tables,
        geometry=geom,
        dyn=m0.dyn,
        inertias=Inertias(
            *(
                np.ascontiguousarray(np.stack([getattr(m.dyn, f) for m in models]), dtype=float)
                for f in Inertias._fields
            )
        ),
        gravity=np.array([np.asarray(m.gravity, dtype=float) for m in mechs]).reshape(-1, 3),
        tree=m0.tree,
        act=m0.act,
        pas=m0.pas,
        site_body=int(m0.tree.site_body[sites[0]]),
        T_site=np.ascontiguousarray(np.stack([m.tree.T_site[s] for m, s in zip(models, sites, strict=True)])),
        q_ref=np.stack([m.q_ref for m in models]),
        length=np.array([m.tree.length for m in models], dtype=float),
        dof_translational=np.asarray(m0.tree.dof_translational, bool),
        rank_K=int(m0.rank_K),
        locked_dof=int(m0.locked_dof),
    )


def single_design(mech: Any, site: str) -> DesignBatch:
    """:func:`design_batch` of the one design ``mech`` (kept with its compiled model: the public
    inverse kinematics runs the design-batched driver with every sample on design 0)."""
    cache = compile_model(mech).cache
    key = ("design_batch", site)
    hit = cache.get(key)
    if hit is None:
        hit = cache[key] = design_batch([mech], site)
    return hit


def group_designs(mechs: Sequence[Any], site: str) -> list[tuple[np.ndarray, DesignBatch]]:
    """Split ``mechs`` into batches of one structure: ``[(indices into mechs, DesignBatch), ...]`` in
    the order of each structure's first design."""
    groups: dict[tuple[Any, ...], list[int]] = {}
    for i, m in enumerate(mechs):
        model = compile_model(m)
        key = _structure(model, int(model.tree.site_body[model.tree.site_index(site)]))
        groups.setdefault(key, []).append(i)
    return [
        (np.array(idx, dtype=np.int64), design_batch([mechs[i] for i in idx], site))
        for idx in groups.values()
    ]


# ----------------------------------------------------------------------------- kernels
@_nj
def ik_block(
    Q,
    lo,
    hi,
    didx,
    tgt,
    w,
    free,
    wstep,
    t,
    g,
    sb,
    Tsite,
    stop2,
    max_iter,
    mu0,
    mu_min,
    mu_max,
    max_step,
    gtol,
    rc_out,
    it_out,
    pe_out,
):  # pragma: no cover - compiled
    """Inverse kinematics (:func:`~robomech.multibody._compiled.lm_solve` with the site rows) of samples
    ``lo:hi`` of ``Q (N, nq)``, in place, each with its design ``didx[n]`` and target ``tgt[n]``."""
    for n in range(lo, hi):
        d = didx[n]
        q = Q[n].copy()
        rc, it, _, pe = lm_solve(
            q,
            design_tables(t, g, d),
            free,
            wstep[d],
            max_iter,
            stop2[d],
            mu0,
            mu_min,
            mu_max,
            max_step,
            sb,
            Tsite[d],
            tgt[n],
            w,
            gtol,
        )
        Q[n] = q
        rc_out[n] = rc
        it_out[n] = it
        pe_out[n] = pe


@numba.njit(cache=True, error_model="numpy", parallel=True)
def ik_par(
    Q,
    didx,
    tgt,
    w,
    free,
    wstep,
    t,
    g,
    sb,
    Tsite,
    stop2,
    max_iter,
    mu0,
    mu_min,
    mu_max,
    max_step,
    gtol,
    rc_out,
    it_out,
    pe_out,
):  # pragma: no cover - compiled
    """:func:`ik_block` in blocks of ``BLOCK`` samples, in parallel."""
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        ik_block(
            Q,
            k * BLOCK,
            min(N, (k + 1) * BLOCK),
            didx,
            tgt,
            w,
            free,
            wstep,
            t,
            g,
            sb,
            Tsite,
            stop2,
            max_iter,
            mu0,
            mu_min,
            mu_max,
            max_step,
            gtol,
            rc_out,
            it_out,
            pe_out,
        )


@_nj
def measures_block(
    Q, lo, hi, didx, act, pas, sb, Tsite, t, g, rtol, rows, colscale, col, Lc, kII, kC, want, out
):  # pragma: no cover - compiled
    """Per sample ``n`` of ``lo:hi`` (design ``didx[n]``): ``out[n] = (inverse condition number of the
    site Jacobian's ``rows`` with columns times ``colscale[d]``, sigma_II, sigma_C)``; ``col[d] (nv,)``
    scales the constraint matrix's columns (L for a rotation, 1 for a translation) and sigma_II /
    sigma_C are the ``kII``-th / ``kC``-th singular values of its passive block / of it (0 if fewer,
    ``L`` when ``k <= 0``: nothing to lose), as :func:`~robomech.multibody.singularities`."""
    nb = t.parent.shape[0]
    m = t.m
    nv = t.A.shape[1]
    na, npas = act.shape[0], pas.shape[0]
    nr = rows.shape[0]
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    r = np.empty(m)
    K = np.empty((m, nv))
    G = np.zeros((nv, na))
    Kp = np.empty((m, npas))
    P = np.empty((npas, m))
    J = np.empty((6, na))
    Jr = np.empty((nr, na))
    Ks = np.empty((m, nv))
    Ksp = np.empty((m, npas))
    for n in range(lo, hi):
        d = didx[n]
        td = design_tables(t, g, d)
        site_jac_one(Q[n], act, pas, sb, Tsite[d], td, rtol, T, S, r, K, G, Kp, P, J)
        for i in range(nr):
            for j in range(na):
                Jr[i, j] = J[rows[i], j] * colscale[d, j]
        dex = np.nan
        if want & 1 and nr > 0 and na > 0 and np.all(np.isfinite(Jr)):
            if min(nr, na) <= 2:
                smax, smin = _sv_small(Jr)
                dex = smin / smax if smax > 0 else 0.0
            else:
                s = np.linalg.svd(Jr, full_matrices=False)[1]
                dex = s[s.shape[0] - 1] / s[0] if s[0] > 0 else 0.0
        out[n, 0] = dex
        for i in range(m):
            for j in range(nv):
                Ks[i, j] = K[i, j] * col[d, j]
            for j in range(npas):
                Ksp[i, j] = K[i, pas[j]] * col[d, pas[j]]
        out[n, 1] = _kth(Ksp, kII, Lc[d]) if want & 2 else np.nan
        out[n, 2] = _kth(Ks, kC, Lc[d]) if want & 4 else np.nan


@_nj
def _kth(X, k, L):  # pragma: no cover - compiled
    """The k-th largest singular value of ``X`` (0 if it has fewer, ``L`` for ``k <= 0``, NaN if X is
    not finite)."""
    if k <= 0:
        return L
    if X.shape[0] == 0 or X.shape[1] == 0:
        return 0.0
    if not np.all(np.isfinite(X)):
        return np.nan
    if min(X.shape[0], X.shape[1]) <= 2:
        if k > min(X.shape[0], X.shape[1]):
            return 0.0
        smax, smin = _sv_small(X)
        return smax if k == 1 else smin
    s = np.linalg.svd(np.ascontiguousarray(X), full_matrices=False)[1]
    return s[k - 1] if s.shape[0] >= k else 0.0


@_nj
def _sv_small(X):  # pragma: no cover - compiled
    """``(sigma_max, sigma_min)`` of a finite matrix ``X`` with at most two columns or two rows (one of
    them: ``sigma_min`` is its only singular value), without LAPACK's allocations: the two columns
    (or rows) reduced to the triangle ``[[a, b], [0, c]]`` (``a`` the first's norm, ``b`` and ``c`` the
    second's components along and across it, re-orthogonalized once), whose singular values
    :func:`_sv_triangle` takes.  The reduction is orthogonal to rounding, so the values differ from an
    SVD's by a few ulps of ``sigma_max`` (as LAPACK's own backward error)."""
    rows = X.shape[1] > 2  # two rows: the singular values of the transpose
    n = X.shape[1] if rows else X.shape[0]
    k = X.shape[0] if rows else X.shape[1]
    a = 0.0
    for i in range(n):
        x = X[0, i] if rows else X[i, 0]
        a += x * x
    a = np.sqrt(a)
    if k == 1:
        return a, a
    u = np.empty(n)
    for i in range(n):
        u[i] = X[1, i] if rows else X[i, 1]
    if a == 0.0:
        c = 0.0
        for i in range(n):
            c += u[i] * u[i]
        return np.sqrt(c), 0.0
    b = 0.0
    for _ in range(2):  # Gram-Schmidt twice: orthogonal to rounding
        p = 0.0
        for i in range(n):
            p += (X[0, i] if rows else X[i, 0]) * u[i]
        p /= a
        for i in range(n):
            u[i] -= p * (X[0, i] if rows else X[i, 0]) / a
        b += p
    c = 0.0
    for i in range(n):
        c += u[i] * u[i]
    return _sv_triangle(a, b, np.sqrt(c))


@_nj
def _sv_triangle(f, g, h):  # pragma: no cover - compiled
    """``(sigma_max, sigma_min)`` of the triangle ``[[f, g], [0, h]]`` to high relative accuracy
    (LAPACK's ``dlas2``)."""
    fa, ga, ha = abs(f), abs(g), abs(h)
    fhmn, fhmx = min(fa, ha), max(fa, ha)
    if fhmn == 0.0:
        if fhmx == 0.0:
            return ga, 0.0
        big, small = max(fhmx, ga), min(fhmx, ga)
        return big * np.sqrt(1.0 + (small / big) ** 2), 0.0
    if ga < fhmx:
        as_ = 1.0 + fhmn / fhmx
        at = (fhmx - fhmn) / fhmx
        au = (ga / fhmx) ** 2
        c = 2.0 / (np.sqrt(as_ * as_ + au) + np.sqrt(at * at + au))
        return fhmx / c, fhmn * c
    au = fhmx / ga
    if au == 0.0:
        return ga, (fhmn * fhmx) / ga
    as_ = 1.0 + fhmn / fhmx
    at = (fhmx - fhmn) / fhmx
    c = 1.0 / (np.sqrt(1.0 + (as_ * au) ** 2) + np.sqrt(1.0 + (at * au) ** 2))
    return ga / (c + c), 2.0 * (fhmn * c) * au


@numba.njit(cache=True, error_model="numpy", parallel=True)
def measures_par(
    Q, didx, act, pas, sb, Tsite, t, g, rtol, rows, colscale, col, Lc, kII, kC, want, out
):  # pragma: no cover - compiled
    """:func:`measures_block` in blocks of ``BLOCK`` samples, in parallel."""
    N = Q.shape[0]
    for k in numba.prange((N + BLOCK - 1) // BLOCK):
        measures_block(
            Q,
            k * BLOCK,
            min(N, (k + 1) * BLOCK),
            didx,
            act,
            pas,
            sb,
            Tsite,
            t,
            g,
            rtol,
            rows,
            colscale,
            col,
            Lc,
            kII,
            kC,
            want,
            out,
        )


@_nj
def site_pose_block(Q, lo, hi, didx, t, g, sb, Tsite, out):  # pragma: no cover - compiled
    """World pose ``out[n] (4, 4)`` of the site (body ``sb``, pose ``Tsite[d]`` in it) at ``Q[n]``."""
    nb = t.parent.shape[0]
    nv = t.A.shape[1]
    T = np.empty((nb, 4, 4))
    S = np.zeros((nv, 6))
    for n in range(lo, hi):
        d = didx[n]
        kin(Q[n], design_tables(t, g, d), T, S)
        for i in range(4):
            for j in range(4):
                out[n, i, j] = (
                    T[sb, i, 0] * Tsite[d, 0, j]
                    + T[sb, i, 1] * Tsite[d, 1, j]
                    + T[sb, i, 2] * Tsite[d, 2, j]
                    + T[sb, i, 3] * Tsite[d, 3, j]
                )


# ----------------------------------------------------------------------------- drivers
def _index(x: np.ndarray) -> np.ndarray:
    """Design indices as a C-contiguous, writable int64 array (one kernel specialization)."""
    a = np.ascontiguousarray(x, dtype=np.int64)
    return a if a.flags.writeable else a.copy()


def site_poses_designs(batch: DesignBatch, didx: np.ndarray, q: np.ndarray) -> np.ndarray:
    """World poses ``(N, 4, 4)`` of the batch's site at ``q (N, nq)``, sample n on design ``didx[n]``."""
    Q, di = writable(q), _index(didx)
    out = np.empty((Q.shape[0], 4, 4))
    site_pose_block(Q, 0, Q.shape[0], di, batch.tables, batch.geometry, batch.site_body, batch.T_site, out)
    return out


def ik_designs(
    batch: DesignBatch,
    didx: np.ndarray,
    T_target: np.ndarray,
    guess: np.ndarray,
    weights: np.ndarray,
    steps: int = 1,
    gtol: float = 0.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Inverse kinematics of the batch's site, sample n on design ``didx[n]``: every coordinate moves
    from ``guess (N, nq)`` to put the site at ``T_target (N, 4, 4)`` with the loops closed, the error
    rows ``[L rot; pos]`` weighted by ``weights (6,)``; ``steps > 1`` moves the target from the guess's
    site pose in stages (as :func:`~robomech.multibody.inverse_kinematics`).  ``gtol > 0`` also stops
    a sample at a stationary point that leaves a residual (``_compiled.lm_solve``): a target out of
    reach stops there instead of spending the iteration limit (0: the public function's iteration).

    Returns ``q (N, nq)`` (NaN where the target is not finite), ``converged (N,)`` (closure and pose
    error both within ``CONVERGED_RTOL * L`` of the design), the largest closure row (m), the pose
    error (m) and the iterations."""
    from ._assembly import _interp_pose

    di = _index(didx)
    Tf = np.array(T_target, dtype=float).reshape(-1, 4, 4)
    Q = writable(np.array(guess, dtype=float).reshape(-1, batch.q_ref.shape[1]))
    N = Q.shape[0]
    ok = np.all(np.isfinite(Tf), axis=(-1, -2)) & np.all(np.isfinite(Q), axis=-1)
    Tf[~ok] = np.eye(4)
    Q[~ok] = batch.q_ref[di[~ok]]
    t = batch.tables
    nv = t.A.shape[1]
    free = np.arange(nv, dtype=np.int64)
    wstep = np.where(batch.dof_translational, 1.0 / batch.length[:, None], 1.0)
    stop2 = (opt.STOP_RTOL * batch.length) ** 2
    w = writable(weights)
    rc, it, pe = np.empty(N), np.zeros(N, dtype=np.int64), np.empty(N)
    iters = np.zeros(N, dtype=np.int64)
    start = site_poses_designs(batch, di, Q) if steps > 1 else None
    for s in range(1, steps + 1):
        Ts = Tf if start is None or s == steps else _interp_pose(start, Tf, s / steps)
        args = (
            di,
            writable(Ts),
            w,
            free,
            writable(wstep),
            t,
            batch.geometry,
            batch.site_body,
            batch.T_site,
            stop2,
            opt.MAX_ITER,
            opt.MU_START,
            opt.MU_MIN,
            opt.MU_MAX,
            opt.MAX_STEP,
            float(gtol),
            rc,
            it,
            pe,
        )
        if N <= BLOCK:
            ik_block(Q, 0, N, *args)
        else:
            ik_par(Q, *args)
        iters += it
    tol = opt.CONVERGED_RTOL * batch.length[di]
    conv = ok & (rc <= tol) & (pe <= tol)
    Q[~ok] = np.nan
    return Q, conv, np.where(ok, rc, np.nan), np.where(ok, pe, np.nan), iters


def site_measures_designs(
    batch: DesignBatch,
    didx: np.ndarray,
    q: np.ndarray,
    rows: Sequence[int],
    length: float | None = None,
    want: tuple[bool, bool, bool] = (True, True, True),
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per sample (design ``didx[n]``, assembled ``q[n]``): the dexterity (inverse condition number
    ``sigma_min / sigma_max`` of the site Jacobian's ``rows`` of ``[ω; ṗ]``, hinge actuator columns
    divided by L), and ``sigma_II``, ``sigma_C`` of :func:`~robomech.multibody.singularities`
    (m; L scales rotations).  ``length`` is L (m; default each design's characteristic length);
    ``want`` says which of the three to compute (the others are NaN)."""
    di = _index(didx)
    Q = writable(q)
    N = Q.shape[0]
    L = batch.length if length is None else np.full(batch.n, float(length))
    hinge = ~batch.dof_translational[batch.act]  # an actuated joint is a hinge or a slide
    colscale = writable(np.where(hinge[None, :], 1.0 / L[:, None], 1.0))
    col = writable(np.where(batch.dof_translational[None, :], 1.0, L[:, None]))
    kII = len(batch.pas) - batch.locked_dof
    out = np.empty((N, 3))
    args = (
        di,
        batch.act,
        batch.pas,
        batch.site_body,
        batch.T_site,
        batch.tables,
        batch.geometry,
        opt.PASSIVE_RANK_RTOL,
        np.asarray(rows, np.int64),
        colscale,
        col,
        writable(L),
        kII,
        batch.rank_K,
        int(want[0]) | 2 * int(want[1]) | 4 * int(want[2]),
        out,
    )
    if N <= BLOCK:
        measures_block(Q, 0, N, *args)
    else:
        measures_par(Q, *args)
    return out[:, 0].copy(), out[:, 1].copy(), out[:, 2].copy()


# ----------------------------------------------------------------------------- inverse dynamics
@_nj
def inv_dyn_runs(lo, hi, starts, rd, Q, QD, QDD, W, wsb, wT, gv, wts, t, g, dt, dg, outs):  # pragma: no cover
    """The inverse dynamics (:func:`~robomech.multibody._compiled.inv_dyn_block`, the one
    implementation) of the runs ``lo:hi``: run ``k`` is samples ``starts[k]:starts[k + 1]``, all of
    design ``rd[k]``, with that design's tables and gravity ``gv[rd[k]]``; ``outs`` the kernel's
    output arrays, in its order."""
    for k in range(lo, hi):
        d = rd[k]
        td, dd = design_tables(t, g, d), design_dyn(dt, dg, d)
        inv_dyn_block(starts[k], starts[k + 1], Q, QD, QDD, W, wsb, wT, gv[d], wts, td, dd, *outs)


@numba.njit(cache=True, error_model="numpy", parallel=True)
def inv_dyn_runs_par(starts, rd, Q, QD, QDD, W, wsb, wT, gv, wts, t, g, dt, dg, outs):  # pragma: no cover
    """:func:`inv_dyn_runs` over every run, in parallel (a run holds at most ``BLOCK`` samples)."""
    for k in numba.prange(rd.shape[0]):
        inv_dyn_runs(k, k + 1, starts, rd, Q, QD, QDD, W, wsb, wT, gv, wts, t, g, dt, dg, outs)


def _runs(di: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(starts (R + 1,), design of each run (R,))``: the samples cut where the design changes and
    every ``BLOCK`` samples within a design."""
    N = di.shape[0]
    cut = np.flatnonzero(np.diff(di)) + 1
    starts = np.unique(np.concatenate([[0], cut, np.arange(0, N, BLOCK), [N]]).astype(np.int64))
    return starts, di[starts[:-1]].copy()


def inverse_dynamics_designs(
    batch: DesignBatch,
    didx: np.ndarray,
    q: np.ndarray,
    qd_act: np.ndarray,
    qdd_act: np.ndarray,
    gravity: bool = True,
) -> dict[str, np.ndarray]:
    """Actuator forces for the motions ``(q (N, nq), qd_act, qdd_act (N, n_act))``, sample n on design
    ``didx[n]``: :func:`~robomech.multibody.inverse_dynamics` (actuated-rates form, no site wrench,
    minimum-norm rule; each design's own gravity unless ``gravity=False``) of every design in one
    kernel call, the same per-sample kernel and the same validity rule (the kernel's flags, the input's
    closure within ``CLOSURE_RTOL * L`` of its design, finite inputs and outputs; forces NaN where not
    valid).  Returns the public result's fields as flat arrays (``tau``, ``M_a``, ``velocity_terms``,
    ``gravity_terms``, ``external_terms``, ``qd``, ``qdd``, ``cond``, ``sigma_min``,
    ``admissibility``, ``closure``, ``valid``); ``cond`` and ``sigma_min`` of a sample that is not
    valid are the kernel's (the public function re-measures them against the generic rank)."""
    from robomech._validation import MAX_MAGNITUDE

    from ._dynamics import _FORCE_KEYS, _id_outputs, _shape
    from ._options import CLOSURE_RTOL
    from ._tree import normalize_quaternions

    di = _index(didx)
    N = di.shape[0]
    na, nv = batch.act.shape[0], batch.tables.A.shape[1]
    flat = [np.array(a, dtype=float).reshape(N, -1) for a in (q, qd_act, qdd_act)]
    ok = np.ones(N, bool)
    for a in flat:
        ok &= np.all(np.isfinite(a) & (np.abs(np.where(np.isfinite(a), a, 0.0)) <= MAX_MAGNITUDE), axis=-1)
    flat[0][~ok] = batch.q_ref[di[~ok]]
    flat[1][~ok] = 0.0
    flat[2][~ok] = 0.0
    Q = writable(normalize_quaternions(batch.tree, flat[0]))
    out = _id_outputs(N, na, nv, ("qd", "qdd", "valid", "closure"))
    starts, rd = _runs(di)
    gv = writable(batch.gravity if gravity else np.zeros_like(batch.gravity))
    args = (
        starts,
        rd,
        Q,
        writable(flat[1]),
        writable(flat[2]),
        np.zeros((N, 0, 6)),
        np.zeros(0, dtype=np.int64),
        np.zeros((0, 4, 4)),
        gv,
        np.zeros(0),
        batch.tables,
        batch.geometry,
        batch.dyn,
        batch.inertias,
        tuple(out.values()),
    )
    with np.errstate(all="ignore"):
        if N <= BLOCK:
            inv_dyn_runs(0, rd.shape[0], *args)
        else:
            inv_dyn_runs_par(*args)
        L = batch.length[di]
        if batch.tables.m == 0 or batch.pas.shape[0] == 0:  # the empty passive block's measures
            out["sigma_min"], out["cond"] = L.copy(), np.ones(N)
        out["valid"] &= out["closure"] <= CLOSURE_RTOL * L
        return _shape(out, (N,), ok, _FORCE_KEYS)


# ----------------------------------------------------------------------------- assembly
def closure_designs(
    batch: DesignBatch, didx: np.ndarray, q: np.ndarray, free: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The closure solve of :func:`~robomech.multibody.forward_kinematics` (one stage), sample n on
    design ``didx[n]``: the coordinates ``free`` move from ``q (N, nq)`` (finite) until the loops
    close (:func:`ik_block` without site rows: the arguments of ``_compiled.fk_block``'s
    :func:`~robomech.multibody._compiled.lm_solve`).  Returns ``q``, the largest closure row (m) and
    the iterations."""
    di = _index(didx)
    Q = writable(np.array(q, dtype=float))
    N = Q.shape[0]
    fr = np.ascontiguousarray(free, dtype=np.int64)
    eye = np.broadcast_to(np.eye(4), (max(N, batch.n), 4, 4))
    rc, it, pe = np.empty(N), np.zeros(N, dtype=np.int64), np.empty(N)
    args = (
        di,
        writable(eye[:N]),
        np.zeros(6),
        fr,
        writable(np.where(batch.dof_translational, 1.0 / batch.length[:, None], 1.0)[:, fr]),
        batch.tables,
        batch.geometry,
        -1,
        writable(eye[: batch.n]),
        writable((opt.STOP_RTOL * batch.geometry.L) ** 2),
        int(opt.MAX_ITER),
        opt.MU_START,
        opt.MU_MIN,
        opt.MU_MAX,
        opt.MAX_STEP,
        0.0,
        rc,
        it,
        pe,
    )
    if N <= BLOCK:
        ik_block(Q, 0, N, *args)
    else:
        ik_par(Q, *args)
    return Q, rc, it
