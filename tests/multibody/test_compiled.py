"""The compiled per-sample kernels agree with the numpy formulation (tests/multibody/_reference.py)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomech import multibody as mb
from robomech.mechanisms import spherical_leg as sl
from robomech.multibody import _compiled

from ._reference import numpy_reference

# Same algorithm, different operation order: configurations agree to rounding (~1e-15 measured), site
# Jacobians too (both take the passive rates from the SVD pseudo-inverse of K_p).
Q_TOL = 1e-12
J_TOL = 1e-12
N = 512  # several parallel blocks of the kernels
N_DYN = 256  # samples of the dynamics comparisons


def _inputs(mech, seed):
    rng = np.random.default_rng(seed)
    scale = np.where(mech.tree.dof_translational[mech.tree.act_dof], mech.length, 1.0)
    return mech.q0[mech.tree.act_qadr] + 0.08 * scale * rng.uniform(-1, 1, (N, len(mech.actuated)))


def _leg():
    leg = sl.SphericalLeg.paper()
    mech = sl.to_multibody(leg)
    ab = np.random.default_rng(3).uniform(-0.4, 0.4, (N, 2))
    l0 = np.linalg.norm(leg.platform_points_home - leg.base_points, axis=1)
    return mech, sl.inverse_kinematics(leg, ab[:, 0], ab[:, 1]).lengths - l0


@pytest.mark.slow
@pytest.mark.parametrize("name", ["delta", "stewart", "bennett", "spherical_leg"])
def test_compiled_equals_numpy(name):
    if name == "spherical_leg":
        mech, qa = _leg()
    else:
        mech = mb.gallery.load(name)
        qa = _inputs(mech, 1)
    site = mech.sites[0].name
    fast = mb.forward_kinematics(mech, qa)
    J_fast = mb.site_jacobian(mech, fast.q, site)
    with numpy_reference():
        slow = mb.forward_kinematics(mech, qa)
        J_slow = mb.site_jacobian(mech, slow.q, site)
    assert fast.converged.all() and slow.converged.all()
    assert np.max(np.abs(fast.q - slow.q)) < Q_TOL
    assert np.max(np.abs(J_fast - J_slow)) < J_TOL * max(1.0, float(np.max(np.abs(J_slow))))


@pytest.mark.slow
def test_compiled_masks_bad_samples():
    mech = mb.gallery.load("stewart")
    qa = _inputs(mech, 2)
    qa[5, 0] = np.nan
    # legs alternately 2.65 m and 0.05 m: the triangle inequality through the 0.42 m platform edge and
    # the 0.26 m base pair bounds the long leg by 0.73 m, so no assembly exists
    qa[7] = [2.0, -0.6, 2.0, -0.6, 2.0, -0.6]
    fk = mb.forward_kinematics(mech, qa)
    assert not fk.converged[5] and not fk.converged[7]
    assert fk.converged[np.r_[0:5, 6, 8:N]].all()
    assert np.all(np.isnan(fk.q[5])) and np.all(np.isfinite(fk.q[7]))


# ----------------------------------------------------------------------------- inverse dynamics
# The compiled inverse dynamics (_compiled.inv_dyn) against the numpy path (_dynamics._inverse_flat),
# the reference: the same formulas with a different operation order, and the passive pseudo-inverse
# from a Cholesky (compiled) instead of an LU (numpy) Gram inverse, refined alike.  Forces agree to
# rounding amplified by the passive block's conditioning (cond ~1e2..3e4 here: cond * eps <= 1e-11).
ID_RTOL = 1e-11
# cond and sigma_min are 1-norm estimates from the Gram inverse, whose rounding is ~cond^2 eps
# (6e-8 at the spherical leg's cond 2.6e4) before any refinement (the estimate is not refined).
COND_RTOL = 1e-6
# admissibility is a rounding-level residual (~1e-15); its two evaluations agree in absolute terms.
ADM_ATOL = 1e-12
_ID_KEYS = ("tau", "M_a", "velocity_terms", "gravity_terms", "external_terms", "qd", "qdd")


_numpy_path = numpy_reference  # every multibody kernel replaced by the numpy formulation


def _assert_same(fast, slow):
    assert np.array_equal(fast.valid, slow.valid)
    v = slow.valid
    for k in _ID_KEYS:
        a, b = getattr(fast, k), getattr(slow, k)
        assert np.array_equal(np.isnan(a), np.isnan(b)), k
        scale = max(1.0, float(np.nanmax(np.abs(b[v])))) if v.any() else 1.0
        assert np.nanmax(np.abs(a - b), initial=0.0) <= ID_RTOL * scale, k
    for k in ("cond", "sigma_min"):
        a, b = getattr(fast, k)[v], getattr(slow, k)[v]
        assert np.all(np.abs(a - b) <= COND_RTOL * np.abs(b)), k
    fin = np.isfinite(slow.admissibility)
    assert np.array_equal(fin, np.isfinite(fast.admissibility))
    assert np.max(np.abs(fast.admissibility[fin] - slow.admissibility[fin]), initial=0.0) <= ADM_ATOL


def _mechanism(name):
    if name == "spherical_leg":  # actuated by the three legs: redundant (3 actuators, 2 DOF)
        return sl.to_multibody(sl.SphericalLeg.paper())
    if name == "spherical_leg_angles":
        return sl.to_multibody(sl.SphericalLeg.paper(), actuate="platform")
    return mb.gallery.load(name)


def _states(mech, n_conf, n, seed, amp=0.08):
    """n samples over n_conf assembled configurations (numpy FK), random rates of the actuators.

    The redundantly actuated spherical leg gets consistent leg rates: those of a random platform
    motion of its angle-actuated twin (same bodies and coordinates), ``qd_legs = G[legs] u`` and
    ``qdd_legs = G[legs] u' + dG[legs] u u``."""
    rng = np.random.default_rng(seed)
    tree = mech.tree
    if mech.name.startswith("spherical") and len(mech.actuated) == 3:
        twin = _mechanism("spherical_leg_angles")
        assert twin.nq == mech.nq and twin.nv == mech.nv
        q, u, ud = _states(twin, n_conf, n, seed)
        with _numpy_path():
            infl = mb.influence(twin, q)
        legs = tree.act_dof
        qd = np.einsum("nij,nj->ni", infl.G[:, legs], u)
        qdd = np.einsum("nij,nj->ni", infl.G[:, legs], ud) + np.einsum(
            "nijk,nj,nk->ni", infl.dG[:, legs], u, u
        )
        return q, qd, qdd
    with _numpy_path():
        if mech.name.startswith("spherical"):
            qa = rng.uniform(-0.4, 0.4, (n_conf, 2))
        else:
            scale = np.where(tree.dof_translational[tree.act_dof], mech.length, 1.0)
            qa = mech.q0[tree.act_qadr] + amp * scale * rng.uniform(-1, 1, (n_conf, len(mech.actuated)))
        fk = mb.forward_kinematics(mech, qa, steps=2)
    q = fk.q[fk.converged]
    assert q.shape[0] > 0
    q = q[rng.integers(0, q.shape[0], n)]
    na = len(mech.actuated)
    return q, rng.normal(size=(n, na)), rng.normal(size=(n, na))


def _both(mech, q, qd, qdd, **kw):
    fast = mb.inverse_dynamics(mech, q, qd, qdd, **kw)
    with _numpy_path():
        slow = mb.inverse_dynamics(mech, q, qd, qdd, **kw)
    return fast, slow


_GALLERY = ["four_bar", "bennett", "planar_3rrr", "delta", "rps_3", "stewart"]


@pytest.mark.slow
@pytest.mark.parametrize("name", [*_GALLERY, "spherical_leg", "spherical_leg_angles"])
def test_compiled_inverse_dynamics_equals_numpy(name):
    mech = _mechanism(name)
    q, qd, qdd = _states(mech, 8, N_DYN, seed=11)
    site = mech.sites[0].name
    W = np.random.default_rng(12).normal(size=(q.shape[0], 6))
    fast, slow = _both(mech, q, qd, qdd, wrenches={site: W})
    assert slow.valid.mean() > 0.9  # the comparison is about valid forces
    _assert_same(fast, slow)
    # batch 1 runs the same kernel: the same forces, sample by sample
    one = mb.inverse_dynamics(mech, q[:1], qd[:1], qdd[:1], wrenches={site: W[:1]})
    assert np.array_equal(one.tau, fast.tau[:1], equal_nan=True)


@pytest.mark.slow
@settings(max_examples=30, deadline=None)
@given(
    name=st.sampled_from([*_GALLERY, "spherical_leg"]),
    seed=st.integers(0, 2**31),
    gravity=st.booleans(),
    wrench=st.booleans(),
    bad=st.sampled_from(["none", "nan", "huge", "inconsistent"]),
)
def test_property_compiled_inverse_dynamics_equals_numpy(name, seed, gravity, wrench, bad):
    """Random assembled states of any gallery mechanism (and the redundant spherical leg): the compiled
    kernel gives the numpy path's forces and the same flags, also for a bad sample in the batch."""
    mech = _mechanism(name)
    q, qd, qdd = _states(mech, 3, 6, seed)
    kw = {"gravity": gravity}
    if wrench:
        kw["wrenches"] = {mech.sites[-1].name: np.random.default_rng(seed).normal(size=(6, 6))}
    if bad == "nan":
        qdd[2, 0] = np.nan
    elif bad == "huge":
        qd[2] = 1e300  # overflows inside: flagged, forces NaN
    elif bad == "inconsistent":
        qd[2, -1] += 1.0  # not a motion of the mechanism unless every rate is free
    fast, slow = _both(mech, q, qd, qdd, **kw)
    _assert_same(fast, slow)
    if bad in ("nan", "huge"):
        assert not fast.valid[2]


@pytest.mark.slow
def test_compiled_redundant_weights_and_singular_flags():
    """Paper 1's weighting rule and a type II singularity, compiled as in numpy."""
    mech = _mechanism("spherical_leg")
    q, qd, qdd = _states(mech, 4, 8, seed=3)
    for w in ([1.0, 0.0, 1.0], [1.0, 2.0, 3.0]):
        fast, slow = _both(mech, q, qd, qdd, weights=w)
        assert fast.valid.all()
        _assert_same(fast, slow)
    b = mb.Builder("toggle", gravity=(0, -9.81, 0))
    inertial = mb.Inertial(1.0, (0.1, 0.0, 0.0), diaginertia=(0.01,) * 3)
    b.body("crank", joints=[b.hinge("a")], inertial=inertial)
    b.body("coupler", parent="crank", pos=(0, 1, 0), joints=[b.hinge("b")], inertial=inertial)
    b.body("rocker", pos=(2, 0, 0), joints=[b.hinge("c")], inertial=inertial)
    b.connect("C", "coupler", "rocker", anchor1=(1.0, -0.5, 0.0))  # B, C, D collinear at q0
    b.actuate("a")
    toggle = b.build()
    with _numpy_path():
        fk = mb.forward_kinematics(toggle, [-0.05], guess=toggle.q0)
    q = np.stack([toggle.q0, fk.q])
    fast, slow = _both(toggle, q, [[0.0], [0.3]], [[0.0], [0.1]])
    assert fast.valid.tolist() == [False, True]
    _assert_same(fast, slow)


# ----------------------------------------------------------------------------- forward dynamics
# The compiled forward dynamics (_rnea_kernels.fd_block) against its numpy formulation
# (_reference.numpy_forward): the same constrained solve with the projected mass matrix Mc factorised
# by Cholesky (compiled) instead of LU (numpy).  Accelerations agree to rounding amplified by Mc's
# conditioning (the Delta's idle leg spins: cond ~3e5, measured difference 3e-10 on |qdd| ~7, i.e.
# 1.7e-16 * cond * |qdd|); FD_COND_RTOL bounds it with a 60x margin.
FD_COND_RTOL = 1e-14
# cond itself is a ratio of LAPACK singular values of two Mc that differ by rounding: relative
# agreement to ~cond * eps (6e-11 measured on the Delta).
FD_CONDNUM_RTOL = 1e-9
# Same samples at any batch size: one kernel, the same per-sample code (measured identical).
BATCH_TOL = 1e-12


def _assert_same_forward(fast, slow):
    assert np.array_equal(fast.valid, slow.valid)
    v = slow.valid
    tol = FD_COND_RTOL * slow.cond[v] * np.maximum(1.0, np.max(np.abs(slow.qdd[v]), axis=-1))
    assert np.all(np.max(np.abs(fast.qdd[v] - slow.qdd[v]), axis=-1) <= tol)
    assert np.array_equal(np.isnan(fast.qd), np.isnan(slow.qd))
    assert np.nanmax(np.abs(fast.qd - slow.qd)) <= ID_RTOL * max(1.0, float(np.nanmax(np.abs(slow.qd))))
    assert np.all(np.abs(fast.cond[v] - slow.cond[v]) <= FD_CONDNUM_RTOL * slow.cond[v])
    assert np.max(np.abs(fast.admissibility[v] - slow.admissibility[v]), initial=0.0) <= ADM_ATOL
    assert np.array_equal(np.isnan(fast.closure), np.isnan(slow.closure))
    assert np.nanmax(np.abs(fast.closure - slow.closure)) <= ADM_ATOL


def _arm():
    """A 3-DOF open chain with a site (no closure rows): the kernel's tree case."""
    b = mb.Builder("arm3")
    parent = "world"
    for i, ax in enumerate([(0, 0, 1), (0, 1, 0), (1, 0, 0)]):
        inertial = mb.Inertial(1.0 + 0.2 * i, pos=(0.05, 0.01, 0.02), diaginertia=(0.01, 0.012, 0.008))
        b.body(
            f"l{i}",
            parent=parent,
            pos=(0.2 * (i > 0), 0, 0),
            joints=[b.hinge(f"j{i}", axis=ax)],
            inertial=inertial,
        )
        parent = f"l{i}"
    b.site("tool", parent, pos=(0.1, 0, 0))
    b.actuate("j0", "j1", "j2")
    return b.build()


@pytest.mark.parametrize("name", ["four_bar", "delta", "bennett", "arm"])
def test_compiled_forward_dynamics_equals_numpy(name):
    """Closed chains in both rate forms, with a site wrench and a NaN sample, and an open tree (no
    closure rows) with a site wrench: kernel = numpy formulation; batch 1, 150, 300 and 1000 agree."""
    if name == "arm":
        mech = _arm()
        rng = np.random.default_rng(5)
        q, qd = rng.uniform(-1, 1, (40, 3)), rng.normal(size=(40, 3))
    else:
        mech = _mechanism(name)
        q, qd, _ = _states(mech, 6, 40, seed=21)
    rng = np.random.default_rng(22)
    tau = rng.normal(size=(q.shape[0], len(mech.actuated)))
    W = {mech.sites[0].name: rng.normal(size=(q.shape[0], 6))}
    full = mb.inverse_dynamics(mech, q, qd, np.zeros_like(qd)).qd  # every coordinate's rate
    qd_bad, full_bad = qd.copy(), full.copy()
    qd_bad[3, 0] = full_bad[3, 0] = np.nan
    cases = (
        dict(qd_act=qd_bad),
        dict(qd=full_bad),
        dict(qd_act=qd, wrenches=W),
        dict(qd=full, gravity=False),
    )
    for kw in cases:
        fast = mb.forward_dynamics(mech, q, tau=tau, **kw)
        with _numpy_path():
            slow = mb.forward_dynamics(mech, q, tau=tau, **kw)
        assert slow.valid.mean() > 0.9
        _assert_same_forward(fast, slow)
    bad = mb.forward_dynamics(mech, q, qd_bad, tau)
    assert not bad.valid[3] and np.all(np.isnan(bad.qdd[3])) and bad.valid[np.r_[0:3, 4:40]].all()
    ref = mb.forward_dynamics(mech, q, qd, tau)
    for n in (1, 150, 300, 1000):  # the same samples at any batch size
        i = np.arange(n) % q.shape[0]
        got = mb.forward_dynamics(mech, q[i], qd[i], tau[i])
        assert np.max(np.abs(got.qdd - ref.qdd[i])) <= BATCH_TOL
    one = mb.forward_dynamics(mech, q[7], qd[7], tau[7])  # one sample as vectors
    assert np.max(np.abs(one.qdd - ref.qdd[7])) <= BATCH_TOL


def test_forward_dynamics_where_the_svd_does_not_converge():
    """A Delta state (from its verify trajectory) whose projected mass matrix, with its clustered
    eigenvalues, makes the kernels' LAPACK ``gesdd`` fail to converge: the kernel takes the absolute
    eigenvalues instead and agrees with the numpy formulation (whose LAPACK converges)."""
    mech = mb.gallery.load("delta")
    fk = mb.forward_kinematics(mech, [0.4840417982516419, 0.7126031330937269, 0.5836989511254661])
    qd = np.array([0.13238181720076647, 0.09335912850589508, 0.6005314480740297])
    tau = np.array([-0.7684453161520064, -0.8910961554337876, -0.8506684344461466])
    fast = mb.forward_dynamics(mech, fk.q[None], qd[None], tau[None])
    with _numpy_path():
        slow = mb.forward_dynamics(mech, fk.q[None], qd[None], tau[None])
    assert fk.converged and fast.valid.all()
    _assert_same_forward(fast, slow)


# ----------------------------------------------------------------------------- inverse kinematics
# The public inverse kinematics runs the compiled Levenberg–Marquardt solve (_compiled.lm_solve through
# _designs.ik_designs); the numpy iteration of tests/multibody/_reference.py (numpy_ik) is the reference.
# A full pose target has isolated solutions: the two agree to rounding (~1e-15 measured).
IK_Q_TOL = 1e-10
# A point target (rotation weights 0) on a mechanism with more DOF than the 3 targeted rows has a
# manifold of solutions: the step's component along it is set by the damping alone, whose matrix
# K^T K + mu s I has a condition number up to 1 / MU_MIN = 1e14, so the two solves' rounding (Cholesky
# compiled, LU numpy) moves the solution along the manifold: 1.2e-8 L measured (stewart); both are
# solutions (converged is checked on each), the tolerance bounds that drift with a 100x margin.
IK_POINT_Q_RTOL = 1e-6
IK_N = 40
GALLERY = ["four_bar", "planar_3rrr", "rps_3", "delta", "stewart", "bennett"]


def _ik_targets(mech, seed):
    """Site poses of perturbed assemblies, every fifth moved 0.5 L away (out of reach for most)."""
    site = mech.sites[0].name
    rng = np.random.default_rng(seed)
    scale = np.where(mech.tree.dof_translational[mech.tree.act_dof], mech.length, 1.0)
    qa = mech.q0[mech.tree.act_qadr] + 0.1 * scale * rng.uniform(-1, 1, (IK_N, len(mech.actuated)))
    fk = mb.forward_kinematics(mech, qa)
    T = mb.site_pose(mech, np.where(fk.converged[:, None], fk.q, mech.q0), site)
    T[::5, :3, 3] += 0.5 * mech.length
    return site, T


@pytest.mark.parametrize("name", GALLERY)
@pytest.mark.parametrize("point", [False, True])
def test_compiled_inverse_kinematics_equals_numpy(name, point):
    from ._reference import numpy_ik

    mech = mb.gallery.load(name)
    site, T = _ik_targets(mech, 4)
    w = np.array([0, 0, 0, 1, 1, 1.0]) if point else np.ones(6)
    ik = mb.inverse_kinematics(mech, site, T, weights=w)
    q, conv, *_ = numpy_ik(mech, site, T, np.tile(mech.q0, (IK_N, 1)), w)
    assert np.array_equal(ik.converged, conv)
    assert conv.sum() >= IK_N // 2  # the comparison covers solved samples
    tol = IK_POINT_Q_RTOL * mech.length if point else IK_Q_TOL
    assert np.max(np.abs(ik.q[conv] - q[conv])) <= tol
    lim = mb.CONVERGED_RTOL * mech.length  # the flags say what the numbers say
    assert np.all(ik.residual[ik.converged] <= lim) and np.all(ik.pose_error[ik.converged] <= lim)
    assert np.all(np.isfinite(ik.q[ik.converged]))


# The reference assembly of a description typed unassembled (_reference.assembled_reference) runs the
# compiled closure solve over every coordinate: with more coordinates than closure rows the assemblies
# form a manifold, and the step's component along it is set by the damping alone (condition number up
# to 1 / MU_MIN = 1e14), so the compiled and numpy solves' rounding moves the solution along it: up to
# 2e-5 rad measured on this five-bar (2-dimensional manifold), in the same iterations.  Both close the
# loops; the difference is tangent to the manifold: |K dq| is second order, the manifold's curvature
# times |dq|^2 (<= 0.03 |dq|^2 / L measured), where a difference across it would give |K dq| ~ |dq|.
# ASSEMBLY_DRIFT bounds the drift along the manifold (5x margin), ASSEMBLY_NORMAL_RTOL the normal
# component in units of |dq|^2 / L (30x margin).
ASSEMBLY_DRIFT = 1e-4
ASSEMBLY_NORMAL_RTOL = 1.0


def test_reference_assembly_equals_numpy():
    from robomech.multibody import _reference as R
    from robomech.multibody._compile import _tables

    from ._reference import integrate, numpy_lm
    from .test_kinematic_classes import _five_bar_by_lengths

    mech = _five_bar_by_lengths(0.5).build()
    tree = mech.tree
    free = np.arange(tree.nv)
    dv = 0.2 * np.random.default_rng(0).uniform(-1.0, 1.0, (R.START_PERTURBATIONS, tree.nv))
    starts = integrate(tree, np.repeat(tree.q0[None], R.START_PERTURBATIONS, axis=0), dv)
    wstep = np.where(tree.dof_translational, 1.0 / tree.length, 1.0)
    qc, rc_c, it_c, _ = _compiled.closure_solve(_tables(tree, mech.constraints), starts, free, wstep, 400)
    qn, rc_n, _, it_n = numpy_lm(mech, starts, free, None, 400)
    tol = mb.CONVERGED_RTOL * mech.length
    assert np.array_equal(rc_c <= tol, rc_n <= tol) and (rc_c <= tol).all()
    assert np.array_equal(it_c, it_n)
    K = mb.constraint_jacobian(mech, qc)
    d = qn - qc
    assert np.max(np.abs(d)) <= ASSEMBLY_DRIFT
    dn = np.linalg.norm(d, axis=-1)
    Kd = np.linalg.norm(np.einsum("nij,nj->ni", K, d), axis=-1)
    assert np.all(Kd <= ASSEMBLY_NORMAL_RTOL * dn**2 / mech.length + 1e-14)  # + rounding of K dq
