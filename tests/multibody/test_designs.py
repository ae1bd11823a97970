"""The design-batched kernels (multibody._designs): many designs of one structure in one call.

References: each design evaluated alone (a batch of one: its own compiled tables), the numpy
inverse kinematics of tests/multibody/_reference.py (``numpy_ik``, the same Levenberg-Marquardt
iteration written over batches in numpy), ``mb.site_jacobian`` with an SVD, and ``mb.singularities``.
"""

import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomech import multibody as mb
from robomech.multibody import _designs as D

from ._reference import numpy_ik

MODELS = Path(__file__).resolve().parents[2] / "examples" / "models"
sys.path.insert(0, str(MODELS))
import delta  # noqa: E402
import five_bar  # noqa: E402

# Two formulations of the same converged configuration (the compiled and the numpy iteration sum in
# another order; both stop at STOP_RTOL): measured <= 7e-15 rad on these designs.
Q_ATOL = 1e-12
# Singular values of the same matrices from LAPACK (the public functions) and from the kernels (LAPACK,
# or the closed form of _sv_small for at most two columns or rows): measured <= 7e-14 relative.
SVD_RTOL = 1e-12
# _sv_small against LAPACK's SVD, relative to sigma_max: both are backward stable (an error of a few
# ulps of ||X||, on sigma_min too); measured <= 7.3e-16 on 14,000 random and nearly rank-one matrices.
SMALL_SVD_RTOL = 1e-14
XY = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 0.0])


def _targets(points):
    T = np.broadcast_to(np.eye(4), (points.shape[0], 4, 4)).copy()
    T[:, :3, 3] = points
    return T


@pytest.fixture(scope="module")
def five_bars():
    rng = np.random.default_rng(7)
    rows = np.column_stack(
        [rng.uniform(0.15, 0.25, 4), rng.uniform(0.15, 0.25, 4), rng.uniform(0.05, 0.15, 4)]
    )
    return [five_bar.build(*r) for r in rows]


@pytest.fixture(scope="module")
def grid():
    c = (np.arange(12) + 0.5) / 12 - 0.5
    P = np.stack(np.meshgrid(c, c, indexing="ij"), -1).reshape(-1, 2)
    return np.column_stack([P, np.zeros(len(P))])


def test_a_batch_of_designs_equals_each_design_alone_bit_for_bit(five_bars, grid):
    b = D.design_batch(five_bars, "tip")
    P = len(grid)
    di = np.repeat(np.arange(b.n), P)
    T = _targets(np.tile(grid, (b.n, 1)))
    T[5, 0, 3] = np.nan  # a failed sample: masked, its neighbours unchanged
    q, conv, rc, pe, it = D.ik_designs(b, di, T, b.q_ref[di], XY)
    assert not conv[5] and np.all(np.isnan(q[5])) and 0.2 < conv.mean() < 0.8
    ok = conv
    dex, s2, sc = D.site_measures_designs(b, di[ok], q[ok], [3, 4])
    for d, mech in enumerate(five_bars):
        one = D.design_batch([mech], "tip")
        sel = di == d
        z = np.zeros(P, dtype=np.int64)
        q1, c1, rc1, pe1, it1 = D.ik_designs(one, z, T[sel], one.q_ref[z], XY)
        for a, b1 in ((q1, q[sel]), (c1, conv[sel]), (rc1, rc[sel]), (pe1, pe[sel]), (it1, it[sel])):
            assert np.array_equal(a, b1, equal_nan=True)
        m1 = D.site_measures_designs(one, z[c1], q1[c1], [3, 4])
        for a, b1 in zip(m1, (dex, s2, sc), strict=True):
            assert np.array_equal(a, b1[di[ok] == d])


def test_batched_ik_equals_the_numpy_inverse_kinematics(five_bars, grid):
    b = D.design_batch(five_bars, "tip")
    P = len(grid)
    di = np.repeat(np.arange(b.n), P)
    T = _targets(np.tile(grid, (b.n, 1)))
    for steps in (1, 4):
        q, conv, *_ = D.ik_designs(b, di, T, b.q_ref[di], XY, steps=steps)
        for d, mech in enumerate(five_bars):
            qn, cn, *_ = numpy_ik(mech, "tip", T[di == d], b.q_ref[di[di == d]], XY, steps)
            assert np.array_equal(cn, conv[di == d])
            np.testing.assert_allclose(q[di == d][cn], qn[cn], rtol=0, atol=Q_ATOL)


def test_dexterity_and_singular_values_equal_the_public_functions(five_bars, grid):
    b = D.design_batch(five_bars, "tip")
    P = len(grid)
    di = np.repeat(np.arange(b.n), P)
    q, conv, *_ = D.ik_designs(b, di, _targets(np.tile(grid, (b.n, 1))), b.q_ref[di], XY)
    for L in (None, 0.3):
        dex, s2, sc = D.site_measures_designs(b, di[conv], q[conv], [3, 4], L)
        for d, mech in enumerate(five_bars):
            sel = di[conv] == d
            qd = q[conv][sel]
            Ld = mech.length if L is None else L
            J = mb.site_jacobian(mech, qd, "tip")[:, [3, 4], :] / Ld  # both actuators are hinges
            s = np.linalg.svd(J, compute_uv=False)
            np.testing.assert_allclose(dex[sel], s[:, -1] / s[:, 0], rtol=SVD_RTOL)
            sg = mb.singularities(mech, qd, "tip", length=L)
            np.testing.assert_allclose(s2[sel], sg.sigma_II, rtol=SVD_RTOL)
            np.testing.assert_allclose(sc[sel], sg.sigma_C, rtol=SVD_RTOL)


def test_a_spatial_mechanism_with_masses_batches_too():
    rows = [(0.25, 0.6, 0.2, 0.05), (0.22, 0.65, 0.18, 0.045), (0.28, 0.55, 0.22, 0.06)]
    mechs = [delta.build(*r) for r in rows]
    b = D.design_batch(mechs, "tcp")
    t, pts = delta.pick_and_place()
    di = np.repeat(np.arange(b.n), len(t))
    T = _targets(np.tile(pts, (b.n, 1)))
    w = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    q, conv, *_ = D.ik_designs(b, di, T, b.q_ref[di], w, steps=4)
    assert conv.all()
    for d, mech in enumerate(mechs):
        qn, cn, *_ = numpy_ik(mech, "tcp", T[di == d], b.q_ref[di[di == d]], w, 4)
        assert cn.all()
        np.testing.assert_allclose(q[di == d], qn, rtol=0, atol=Q_ATOL)
        np.testing.assert_allclose(
            D.site_poses_designs(b, di[di == d], q[di == d]), mb.site_pose(mech, qn, "tcp"), atol=1e-12
        )


def test_batched_inverse_dynamics_equals_each_designs_public_inverse_dynamics():
    """32 Sobol Delta designs along the pick-and-place path, with random actuator rates, the samples
    shuffled across designs, and failures: a non-finite and a huge configuration, an unassembled one,
    a huge rate.  Each design's samples equal ``mb.inverse_dynamics`` of that design (the same
    per-sample kernel with the same numbers: bit for bit), its flags included; at any batch size."""
    from robomech.explore import design_matrix

    X = design_matrix(delta.study().variables, 32, "sobol", 0, 32)
    mechs = [delta.build(*r) for r in X]
    b = D.design_batch(mechs, "tcp")
    t, pts = delta.pick_and_place()
    di = np.repeat(np.arange(b.n), len(t))
    w = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    q, conv, *_ = D.ik_designs(b, di, _targets(np.tile(pts, (b.n, 1))), b.q_ref[di], w, steps=4)
    assert conv.all()
    rng = np.random.default_rng(3)
    qd, qdd = rng.normal(size=(2, q.shape[0], 3))
    q[5] = np.nan
    q[40, 0] = 1e301
    q[100, 0] += 0.05  # the closure opened: not assembled
    qdd[200, 1] = 1e305
    perm = rng.permutation(q.shape[0])
    di, q, qd, qdd = di[perm], q[perm], qd[perm], qdd[perm]
    res = D.inverse_dynamics_designs(b, di, q, qd, qdd)
    assert 0 < np.count_nonzero(~res["valid"]) < 8
    few = D.inverse_dynamics_designs(b, di[:50], q[:50], qd[:50], qdd[:50])  # one serial call
    for k in ("tau", "valid", "closure"):
        np.testing.assert_array_equal(few[k], res[k][:50])
    for d, mech in enumerate(mechs):
        s = di == d
        pub = mb.inverse_dynamics(mech, q[s], qd[s], qdd[s])
        np.testing.assert_array_equal(res["valid"][s], pub.valid)
        for k in ("tau", "M_a", "velocity_terms", "gravity_terms", "external_terms", "closure", "qd", "qdd"):
            np.testing.assert_array_equal(res[k][s], getattr(pub, k), err_msg=k)
        for k in ("cond", "sigma_min", "admissibility"):
            np.testing.assert_array_equal(res[k][s][pub.valid], getattr(pub, k)[pub.valid], err_msg=k)


def _two_link_arm():
    """An open 2R arm with a site "tip": another structure than the five-bar."""
    b = mb.Builder("arm")
    b.body("l1", joints=[b.hinge("j1")])
    b.body("l2", "l1", pos=(0.2, 0, 0), joints=[b.hinge("j2")])
    b.site("tip", "l2", pos=(0.2, 0, 0))
    b.actuate("j1", "j2")
    return b.build()


def test_designs_of_another_structure_are_refused_or_grouped(five_bars):
    arm = _two_link_arm()
    with pytest.raises(D.StructureMismatch, match="one structure"):
        D.design_batch([five_bars[0], arm], "tip")
    with pytest.raises(ValueError, match="at least one design"):
        D.design_batch([], "tip")
    groups = D.group_designs([five_bars[0], arm, five_bars[1]], "tip")
    assert [g[0].tolist() for g in groups] == [[0, 2], [1]]
    assert groups[0][1].n == 2 and groups[1][1].n == 1


@settings(max_examples=300, deadline=None)
@given(
    shape=st.sampled_from([(2, 2), (5, 2), (2, 5), (3, 2), (6, 2), (1, 4), (4, 1), (1, 1)]),
    seed=st.integers(0, 2**32 - 1),
    gap=st.floats(-15.0, 0.0),
)
def test_small_singular_values_equal_lapack(shape, seed, gap):
    """The closed-form singular values of a matrix with at most two columns or rows equal LAPACK's to a
    few ulps of sigma_max, down to sigma_min / sigma_max ~ 1e-15 (second column or row nearly parallel
    to the first)."""
    rng = np.random.default_rng(seed)
    X = rng.standard_normal(shape)
    if min(shape) == 2:
        Y = X if shape[1] == 2 else X.T
        Y[:, 1] = Y[:, 0] * rng.uniform(-2, 2) + 10.0**gap * rng.standard_normal(Y.shape[0])
        X = np.ascontiguousarray(Y if shape[1] == 2 else Y.T)
    s = np.linalg.svd(X, compute_uv=False)
    smax, smin = D._sv_small(X)
    assert abs(smax - s[0]) <= SMALL_SVD_RTOL * s[0]
    assert abs(smin - s[-1]) <= SMALL_SVD_RTOL * s[0]


def test_small_singular_values_of_degenerate_matrices():
    """Exact zeros: a zero matrix, a zero first column, exactly parallel columns (LAPACK as reference)."""
    for X in (np.zeros((3, 2)), np.array([[0.0, 3.0], [0.0, 4.0]]), np.array([[1.0, 2.0], [2.0, 4.0]])):
        s = np.linalg.svd(X, compute_uv=False)
        smax, smin = D._sv_small(X)
        assert abs(smax - s[0]) <= SMALL_SVD_RTOL * max(s[0], 1.0)
        assert abs(smin - s[-1]) <= SMALL_SVD_RTOL * max(s[0], 1.0)
    assert D._sv_small(np.zeros((2, 2))) == (0.0, 0.0)
    assert D._sv_small(np.array([[0.0, 3.0], [0.0, 4.0]])) == (5.0, 0.0)
