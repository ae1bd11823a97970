"""The closure residual, the velocity constraint matrix K, its rate dK/dt, the singularity measures, site
poses and energies: the compiled kernels (``_compiled.resjac_block``, ``kdot_block``, ``site_pose_block``,
``energy_block``) against their numpy formulation (tests/multibody/_reference.py) on closed chains (Delta,
a five-bar typed unassembled, Sarrus, Tsai 3-UPU, Bennett's weld), a polynomial coupling, an open chain
and a floating-base tree, at batch 1 and at batches below and above the kernels' block size
(``_compiled.BLOCK`` samples run in one block in the calling thread, more in parallel blocks).
"""

from __future__ import annotations

import numpy as np
import pytest

from robomech import multibody as mb
from robomech.multibody import Builder, Inertial

from ._reference import numpy_reference
from .test_compiled_influence import BATCH_RTOL, SIZES, _close, _configurations, _mech

N = max(SIZES)
# The same formulas per row in another operation order (sums of products of O(1) poses and screws):
# a few ulps of the largest entry (8.9e-16 measured, the Delta's dK/dt).
CONSTRAINT_RTOL = 1e-13
# Singular values of the scaled K, K_p and J from the same SVD of matrices equal to a few ulps: the
# measures agree to the ulps times the conditioning (4.5e-15 relative measured on the Delta).
SINGULAR_RTOL = 1e-11


def _coupled():
    """Two hinges and a slide in series, the second hinge a cubic of the first and the slide a linear
    function of it: coupling rows with a non-zero second derivative and with none."""
    b = Builder("coupled", gravity=(0.0, 0.0, -9.81))
    rod = Inertial(mass=1.0, pos=(0.1, 0, 0), diaginertia=(1e-3, 1e-3, 1e-3))
    b.body("a", joints=[b.hinge("h1", axis=(0, 0, 1))], inertial=rod)
    b.body("b", "a", joints=[b.hinge("h2", pos=(0.2, 0, 0), axis=(0, 1, 0))], inertial=rod)
    b.body("c", "b", joints=[b.slide("s", pos=(0.4, 0, 0), axis=(1, 0, 0))], inertial=rod)
    b.site("tip", "c", pos=(0.5, 0, 0))
    b.couple("cubic", "h2", "h1", (0.1, 0.5, -0.7, 0.3, 0.2))
    b.couple("lin", "s", "h1", (0.0, 0.05))
    b.actuate("h1")
    return b.build()


NAMES = ("delta", "five_bar", "sarrus", "tsai", "bennett", "coupled", "arm6", "quadruped")


def _get(name):
    if name == "bennett":
        return mb.gallery.load("bennett")
    if name == "coupled":
        return _coupled()
    return _mech(name)


@pytest.mark.parametrize("name", NAMES)
def test_residual_jacobian_and_rate_equal_numpy_at_every_batch_size(name):
    mech = _get(name)
    rng = np.random.default_rng(1)
    q = _configurations(mech, N)
    # unassembled samples too: the residual where it is not zero (the tree's coordinates moved)
    from ._reference import integrate

    q_off = integrate(mech.tree, q, 0.05 * rng.uniform(-1, 1, (N, mech.nv)))
    qd = rng.normal(size=(N, mech.nv))
    got = (
        mb.constraint_residual(mech, q_off),
        mb.constraint_jacobian(mech, q_off),
        mb.constraint_jacobian_rate(mech, q_off, qd),
        mb.constraint_residual(mech, q),
    )
    with numpy_reference():
        ref = (
            mb.constraint_residual(mech, q_off),
            mb.constraint_jacobian(mech, q_off),
            mb.constraint_jacobian_rate(mech, q_off, qd),
            mb.constraint_residual(mech, q),
        )
    for a, b, what in zip(got, ref, ("residual", "K", "dK/dt", "assembled residual"), strict=True):
        _close(a, b, CONSTRAINT_RTOL, what)
    if mech.constraints.m:
        assert np.max(np.abs(ref[0])) > 1e-3  # the unassembled residual is not zero
    for n in SIZES[:-1]:  # the same samples in a smaller batch (batch 1 as a vector too)
        qs, qds = (q_off[:n], qd[:n]) if n > 1 else (q_off[0], qd[0])
        part = (
            mb.constraint_residual(mech, qs),
            mb.constraint_jacobian(mech, qs),
            mb.constraint_jacobian_rate(mech, qs, qds),
        )
        for a, b, what in zip(part, got[:3], ("residual", "K", "dK/dt"), strict=True):
            _close(a if n > 1 else a[None], b[:n], BATCH_RTOL, f"{what} at batch {n}")


@pytest.mark.parametrize("name", ("delta", "five_bar", "sarrus", "tsai", "arm6", "quadruped"))
def test_singularities_equal_numpy_at_every_batch_size(name):
    mech = _get(name)
    q = _configurations(mech, N, seed=2)
    site = mech.sites[0].name
    s = mb.singularities(mech, q, site)
    with numpy_reference():
        r = mb.singularities(mech, q, site)
    for f in ("type_I", "type_II", "constraint", "singular", "assembled"):
        assert np.array_equal(getattr(s, f), getattr(r, f)), f
    for f in ("sigma_I", "sigma_II", "sigma_C", "cond_I", "cond_II", "cond_C", "closure"):
        a, b = getattr(s, f), getattr(r, f)
        assert np.array_equal(np.isfinite(a), np.isfinite(b)), f
        fin = np.isfinite(b)
        assert np.all(np.abs(a[fin] - b[fin]) <= SINGULAR_RTOL * np.maximum(1.0, np.abs(b[fin]))), f
    for output in ("position", (0, 4)):  # a part of the site's rows: the kernel's row selection
        a = mb.singularities(mech, q, site, output=output)
        with numpy_reference():
            b = mb.singularities(mech, q, site, output=output)
        assert np.array_equal(a.type_I, b.type_I), output
        _close(np.nan_to_num(a.sigma_I), np.nan_to_num(b.sigma_I), SINGULAR_RTOL, f"sigma_I {output}")
    for n in SIZES[:-1]:
        part = mb.singularities(mech, q[:n] if n > 1 else q[0], site)
        for f in ("sigma_I", "sigma_II", "sigma_C", "closure"):
            a = np.atleast_1d(getattr(part, f))
            _close(np.nan_to_num(a), np.nan_to_num(getattr(s, f)[:n]), BATCH_RTOL, f"{f} at batch {n}")


def test_singular_values_kernel_against_numpy_and_on_bad_matrices():
    """``_compiled.singular_values_into`` (LAPACK gesdd without vectors): numpy's values on wide, tall and
    rank-deficient matrices; NaN for a non-finite matrix (where numpy's batched SVD raises and would end
    the batch), nothing written for an empty one."""
    from robomech.multibody._compiled import singular_values_into

    rng = np.random.default_rng(8)
    low = rng.normal(size=(6, 2)) @ rng.normal(size=(2, 5))  # rank 2
    for X in (rng.normal(size=(4, 7)), rng.normal(size=(7, 4)), low):
        s = np.empty(min(X.shape))
        singular_values_into(X, s)
        _close(s, np.linalg.svd(X, compute_uv=False), BATCH_RTOL, f"shape {X.shape}")
    X = rng.normal(size=(3, 4))
    X[1, 2] = np.nan
    s = np.zeros(3)
    singular_values_into(X, s)
    assert np.isnan(s).all()
    s = np.zeros(0)
    singular_values_into(np.zeros((0, 3)), s)  # an open chain's empty K
    assert s.shape == (0,)


def test_the_full_svd_fallback_gives_the_same_singular_values():
    """``singular_values_full``: what the kernels call where numba has no vector-free SVD helper."""
    from robomech.multibody._compiled import singular_values_full

    rng = np.random.default_rng(9)
    for X in (rng.normal(size=(4, 7)), rng.normal(size=(7, 4))):
        _close(singular_values_full(X), np.linalg.svd(X, compute_uv=False), BATCH_RTOL, f"shape {X.shape}")


# dK/dt applied to v against the per-product kernel (dK/dt along u) v: the same products and sums per
# entry, identical bits measured; a few ulps of the largest entry allowed.
PRODUCT_RTOL = 1e-14
# Central differences of K along qd (step H_FD): truncation h^2 |d3K/dt3| ~ 1e-12 plus rounding
# eps |K| / h ~ 1e-10 (K's entries are O(1) m).
H_FD = 1e-6
FD_RTOL = 1e-8


@pytest.mark.parametrize("name", NAMES)
def test_rate_columns_equal_the_per_product_kernel(name):
    """Every column of dK/dt in one pass (``_compiled.kdot_columns``) against ``kdot_uv``, the kernel that
    forms ``(dK/dt along u) v`` for one ``v`` (inverse dynamics, second-order influence coefficients),
    with random ``v``, on assembled and unassembled samples, at every batch size."""
    from robomech.multibody import _compiled as C
    from robomech.multibody._compile import compile_model

    from ._reference import integrate

    mech = _get(name)
    t = compile_model(mech).tables
    rng = np.random.default_rng(6)
    q = _configurations(mech, N, seed=6)
    q = np.concatenate([q, integrate(mech.tree, q, 0.05 * rng.uniform(-1, 1, (N, mech.nv)))])
    qd, v = rng.normal(size=(2, 2 * N, mech.nv))
    nb, nv, m = t.parent.shape[0], mech.nv, t.m
    T, S, Sd = np.empty((nb, 4, 4)), np.zeros((nv, 6)), np.empty((nv, 6))
    Vu, Vv, Vd, kd = np.empty((nb, 6)), np.empty((nb, 6)), np.empty((nb, 6)), np.empty(m)
    picks = np.arange(0, 2 * N, 23)  # a spread of samples, assembled and not
    ref = np.empty((len(picks), m))
    for i, n in enumerate(picks):
        C.kin(q[n], t, T, S)
        C.screw_rates_into(t, S, qd[n], Sd)
        C.kdot_uv(q[n], t, T, S, Sd, qd[n], v[n], Vu, Vv, Vd, kd)
        ref[i] = kd
    for n in (*SIZES, 2 * N):
        sel = picks[picks < n]
        Kd = mb.constraint_jacobian_rate(mech, q[:n], qd[:n])
        _close(np.einsum("nij,nj->ni", Kd[sel], v[sel]), ref[: len(sel)], PRODUCT_RTOL, f"batch {n}")


@pytest.mark.parametrize("name", ("delta", "tsai", "sarrus", "five_bar", "bennett"))
def test_rate_equals_finite_differences_of_k(name):
    """dK/dt against central differences of K along qd, at assembled and unassembled configurations:
    the rate of every closure row (points, rotations) from an independent formula."""
    from ._reference import integrate

    mech = _get(name)
    rng = np.random.default_rng(7)
    q = _configurations(mech, 8, seed=7)
    q = np.concatenate([q, integrate(mech.tree, q, 0.05 * rng.uniform(-1, 1, (len(q), mech.nv)))])
    qd = rng.normal(size=(len(q), mech.nv))
    fd = (
        mb.constraint_jacobian(mech, integrate(mech.tree, q, H_FD * qd))
        - mb.constraint_jacobian(mech, integrate(mech.tree, q, -H_FD * qd))
    ) / (2 * H_FD)
    Kd = mb.constraint_jacobian_rate(mech, q, qd)
    assert np.max(np.abs(Kd)) > 0.1  # a rate that is not zero
    assert np.max(np.abs(Kd - fd)) <= FD_RTOL * max(1.0, float(np.max(np.abs(Kd))))


def test_coupling_rate_equals_finite_differences():
    """dK/dt of the cubic coupling row (the only row here whose K depends on q) against central
    differences of K along qd: an independent check of the kernel's second derivative of the polynomial."""
    mech = _coupled()
    q = _configurations(mech, 4, seed=3)
    qd = np.random.default_rng(4).normal(size=(4, mech.nv))
    h = 1e-6
    from ._reference import integrate

    fd = (
        mb.constraint_jacobian(mech, integrate(mech.tree, q, h * qd))
        - mb.constraint_jacobian(mech, integrate(mech.tree, q, -h * qd))
    ) / (2 * h)
    # central differences: truncation h^2 |K'''| ~ 1e-12 plus rounding eps / h ~ 1e-10
    assert np.max(np.abs(mb.constraint_jacobian_rate(mech, q, qd) - fd)) <= 1e-8


# Poses: products of a few 4x4 matrices in another order, a few ulps.  Energies: sums over the bodies of
# products of O(1) rates and O(1-10) masses and inertias, a few ulps of the largest term.
POSE_RTOL = 1e-13


@pytest.mark.parametrize("name", NAMES)
def test_site_pose_and_energy_equal_numpy_at_every_batch_size(name):
    mech = _get(name)
    rng = np.random.default_rng(5)
    q = _configurations(mech, N, seed=5)
    qd = rng.normal(size=(N, mech.nv))
    site = mech.sites[0].name
    got = (mb.site_pose(mech, q, site), *mb.energy(mech, q, qd))
    with numpy_reference():
        ref = (mb.site_pose(mech, q, site), *mb.energy(mech, q, qd))
    for a, b, what in zip(got, ref, ("site_pose", "kinetic", "potential"), strict=True):
        _close(a, b, POSE_RTOL, what)
    assert np.all(got[1] > 0.0)  # every sample moves: a kinetic energy that is not zero by construction
    for n in SIZES[:-1]:
        qs, qds = (q[:n], qd[:n]) if n > 1 else (q[0], qd[0])
        part = (mb.site_pose(mech, qs, site), *mb.energy(mech, qs, qds))
        for a, b, what in zip(part, got, ("site_pose", "kinetic", "potential"), strict=True):
            _close(a if n > 1 else a[None], b[:n], BATCH_RTOL, f"{what} at batch {n}")


# Integration: the same quaternion products and normalisation in another operation order, a few ulps.
INTEGRATE_RTOL = 1e-13
# Central differences of the body poses along q ⊕ (±h qd): truncation h^2 |T'''| ~ 1e-12 plus rounding
# eps / h ~ 1e-10 (O(1) poses); 1e-8 leaves a 100x margin and is far below a wrong screw (O(|qd|)).
TWIST_FD_TOL = 1e-8
TWIST_FD_STEP = 1e-6


@pytest.mark.parametrize("name", NAMES)
def test_body_poses_jacobians_and_integration_equal_numpy_at_every_batch_size(name):
    """Every body's pose, every coordinate's space screw and every body's space Jacobian
    (``_compiled.compiled_kinematics``, ``space_jacobians``) and ``q ⊕ dv`` (``compiled_integrate``)
    against the numpy formulation, at batch 1, below and above the block size; the poses-only call
    and the compile step's call on the packed tables give the same bits."""
    from robomech.multibody import _compiled
    from robomech.multibody._compile import compile_model

    from . import _reference as R

    mech = _get(name)
    model, tree = compile_model(mech), mech.tree
    nb = len(tree.body_names)
    rng = np.random.default_rng(7)
    q = _configurations(mech, N, seed=7)
    dv = 0.3 * rng.uniform(-1, 1, (N, mech.nv))
    T, S = _compiled.compiled_kinematics(model, q)
    J = _compiled.space_jacobians(tree.A, S, range(nb))
    qi = _compiled.compiled_integrate(model, q, dv)
    st = R.kinematics(tree, q)
    _close(T, st.T, POSE_RTOL, "body poses")
    _close(S, st.S, POSE_RTOL, "coordinate screws")
    _close(J, np.stack([R.space_jacobian(tree, st, b) for b in range(nb)], axis=1), POSE_RTOL, "J")
    _close(qi, R.integrate(tree, q, dv), INTEGRATE_RTOL, "integrate")
    assert np.max(np.abs(qi - q)) > 1e-2  # the increment moves every mechanism
    assert np.array_equal(_compiled.compiled_body_poses(model, q), T)
    for n in SIZES[:-1]:
        Tn, Sn = _compiled.compiled_kinematics(model, q[:n])
        _close(Tn, T[:n], BATCH_RTOL, f"poses at batch {n}")
        _close(Sn, S[:n], BATCH_RTOL, f"screws at batch {n}")
        assert np.array_equal(_compiled.compiled_kinematics(model.tables, q[:n])[0], Tn)
        assert np.array_equal(_compiled.compiled_body_poses(model.tables, q[:n]), Tn)
        _close(_compiled.compiled_integrate(model.tables, q[:n], dv[:n]), qi[:n], BATCH_RTOL, f"q+ at {n}")
    # the twist V_b = J_b qd is the rate of the pose along q ⊕ t qd: [ω]x = Ṙ Rᵀ, v = ṗ - ω × p
    qd = rng.normal(size=(4, mech.nv))
    h = TWIST_FD_STEP
    Tp = _compiled.compiled_body_poses(model, _compiled.compiled_integrate(model, q[:4], h * qd))
    Tm = _compiled.compiled_body_poses(model, _compiled.compiled_integrate(model, q[:4], -h * qd))
    Td = (Tp - Tm) / (2 * h)
    W = Td[..., :3, :3] @ T[:4, :, :3, :3].swapaxes(-1, -2)
    w = np.stack([W[..., 2, 1], W[..., 0, 2], W[..., 1, 0]], axis=-1)
    v = Td[..., :3, 3] - np.cross(w, T[:4, :, :3, 3])
    V = np.einsum("nbik,nk->nbi", J[:4], qd)
    assert np.max(np.abs(V - np.concatenate([w, v], axis=-1))) <= TWIST_FD_TOL


REFERENCE_MECHS = ("four_bar", "bennett", "planar_3rrr", "delta", "rps_3", "stewart", "five_bar", "sarrus")


@pytest.mark.parametrize("name", REFERENCE_MECHS)
def test_reference_rank_equals_numpy(name):
    """The compile step's reference rank (``_compile.instantaneous_mobility`` on the kernels: K and the
    bodies' space Jacobians) against the same computation on the numpy formulation."""
    from robomech.multibody._compile import compile_model, instantaneous_mobility

    mech = mb.gallery.load(name) if name in mb.gallery.NAMES else _get(name)
    model = compile_model(mech)
    got = instantaneous_mobility(mech.tree, model.tables, model.q_ref[None], model.bodies)
    with numpy_reference():
        ref = instantaneous_mobility(mech.tree, model, model.q_ref[None], model.bodies)
    assert (got.rank, got.idle, got.locked.shape[1]) == (ref.rank, ref.idle, ref.locked.shape[1])
    assert (model.dof, model.idle_dof) == (mech.nv - got.rank - got.idle, got.idle)
    _close(got.K, ref.K, CONSTRAINT_RTOL, "scaled K")
    _close(got.T, ref.T, POSE_RTOL, "poses")
    _close(got.S, ref.S, POSE_RTOL, "screws")
