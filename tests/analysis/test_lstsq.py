"""Batched Householder least squares: agreement, accuracy at high condition, per-system failure."""

import numpy as np
import pytest

from robomech.analysis import lstsq

# Well-conditioned systems: both solvers are backward stable; 1e-12 allows cond ~10 times eps growth.
AGREE_TOL = 1e-12


def random_stack(rng, k, m, n, cond=None):
    A = rng.normal(size=(k, m, n))
    if cond is not None:
        U, _, Vt = np.linalg.svd(A, full_matrices=False)
        s = np.logspace(0, -np.log10(cond), n)
        A = np.einsum("kmi,i,kin->kmn", U, s, Vt)
    return A


def test_matches_numpy_lstsq_on_well_conditioned_stacks():
    rng = np.random.default_rng(0)
    A = random_stack(rng, 500, 30, 11, cond=10.0)
    b = rng.normal(size=(500, 30))
    r = lstsq.solve(A, b, exact_cond=True)
    ref = np.stack([np.linalg.lstsq(a, y, rcond=None)[0] for a, y in zip(A, b, strict=True)])
    assert np.abs(r.x - ref).max() < AGREE_TOL
    assert np.all(r.full_rank) and np.all(r.ok) and np.all(r.rank == 11)
    assert np.allclose(r.cond, 10.0, rtol=1e-8)
    # the default 1-norm condition of R is within a factor n of the 2-norm one (Higham, Table 6.2)
    c1 = lstsq.solve(A, b).cond
    assert np.all((c1 >= 10.0 / 11 * (1 - 1e-9)) & (c1 <= 10.0 * 11))
    assert np.abs(lstsq.solve(A, b).x - r.x).max() == 0.0
    ref_res = np.linalg.norm(np.einsum("kmn,kn->km", A, ref) - b, axis=1)
    assert np.allclose(r.residual_norm, ref_res, rtol=1e-12)
    # On a well-conditioned system the normal equations give the same residual (paper 4's comparison).
    ne = lstsq.solve_normal_equations(A, b)
    assert np.allclose(ne.residual_norm, r.residual_norm, rtol=1e-10)


def test_qr_keeps_accuracy_where_normal_equations_lose_cond_squared():
    rng = np.random.default_rng(1)
    cond = 1e8
    A = random_stack(rng, 200, 30, 11, cond=cond)
    x_true = rng.normal(size=(200, 11))
    b = np.einsum("kmn,kn->km", A, x_true)  # consistent: zero residual, so error is pure forward error
    eps = np.finfo(float).eps
    err_qr = np.linalg.norm(lstsq.solve(A, b).x - x_true, axis=1) / np.linalg.norm(x_true, axis=1)
    err_ne = np.linalg.norm(lstsq.solve_normal_equations(A, b).x - x_true, axis=1) / np.linalg.norm(
        x_true, axis=1
    )
    # QR: forward error ~ cond * eps = 2e-8 (Higham, Thm 20.3, zero-residual case); allow 100x.
    assert np.median(err_qr) < 100 * cond * eps
    # Normal equations: error grows like cond^2 * eps = 2e0 (capped by O(1)); at least 1e3 times worse.
    assert np.median(err_ne) > 1e3 * np.median(err_qr)


def test_rank_deficient_and_non_finite_systems_are_flagged_not_raised():
    rng = np.random.default_rng(2)
    A = rng.normal(size=(4, 8, 3))
    b = rng.normal(size=(4, 8))
    A[1, :, 2] = A[1, :, 0] + A[1, :, 1]  # rank 2
    A[2, 3, 1] = np.nan
    b[3, 0] = np.inf
    r = lstsq.solve(A, b)
    assert r.ok.tolist() == [True, True, False, False]
    assert r.full_rank.tolist() == [True, False, False, False]
    assert r.rank[1] == 2
    assert np.all(np.isfinite(r.x[:2])) and np.all(np.isnan(r.x[2:]))
    # the rank-deficient system gets the minimum-norm solution
    assert np.allclose(r.x[1], np.linalg.pinv(A[1]) @ b[1])
    # and the good system is unaffected by its neighbours
    assert np.allclose(r.x[0], np.linalg.lstsq(A[0], b[0], rcond=None)[0], atol=1e-13)


def test_batched_equals_per_system():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(3, 4, 12, 5))
    b = rng.normal(size=(3, 4, 12))
    r = lstsq.solve(A, b)
    assert r.x.shape == (3, 4, 5) and r.residual_norm.shape == (3, 4)
    for i in range(3):
        for j in range(4):
            assert np.abs(lstsq.solve(A[i, j], b[i, j]).x - r.x[i, j]).max() <= 1e-12


def test_broadcasts_one_matrix_against_many_right_hand_sides():
    rng = np.random.default_rng(4)
    A = rng.normal(size=(9, 4))
    b = rng.normal(size=(100, 9))
    r = lstsq.solve(A, b)
    assert r.x.shape == (100, 4)
    assert np.allclose(r.x, np.linalg.lstsq(A, b.T, rcond=None)[0].T)


@pytest.mark.parametrize(
    "A, b, match",
    [
        (np.zeros((3, 5)), np.zeros(3), "at least as many rows"),
        (np.zeros((5, 3)), np.zeros(4), "b"),
        (np.zeros(5), np.zeros(5), "A"),
        ("abc", np.zeros(5), "A"),
    ],
)
def test_bad_shapes_name_the_argument(A, b, match):
    with pytest.raises(ValueError, match=match):
        lstsq.solve(A, b)
