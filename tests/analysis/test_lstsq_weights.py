"""Weighted least squares in ``lstsq.solve(A, b, weights=w)`` (issue 17)."""

import numpy as np
import pytest

from robomech.analysis import lstsq

# Well-conditioned random systems (cond ~10): QR vs the explicit weighted normal equations agree to
# cond² eps growth, well below this.
AGREE_TOL = 1e-11


def test_matches_the_weighted_normal_equations():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(50, 30, 11))
    b = rng.normal(size=(50, 30))
    w = rng.uniform(0.1, 10.0, size=(50, 30))
    r = lstsq.solve(A, b, weights=w)
    AtW = np.swapaxes(A, -1, -2) * w[:, None, :]
    x_ref = np.linalg.solve(AtW @ A, np.einsum("kij,kj->ki", AtW, b)[..., None])[..., 0]
    np.testing.assert_allclose(r.x, x_ref, atol=AGREE_TOL)
    res = np.einsum("kij,kj->ki", A, r.x) - b
    np.testing.assert_allclose(r.residual_norm, np.sqrt(np.sum(w * res**2, axis=-1)), rtol=1e-12)
    assert np.all(r.ok & r.full_rank)


def test_weight_two_is_a_repeated_row_and_weight_zero_drops_it():
    rng = np.random.default_rng(4)
    A = rng.normal(size=(8, 3))
    b = rng.normal(size=8)
    w = np.ones(8)
    w[0], w[1] = 2.0, 0.0
    r = lstsq.solve(A, b, weights=w)
    A_rep = np.vstack([A[:1], A[:1], A[2:]])
    b_rep = np.concatenate([b[:1], b[:1], b[2:]])
    np.testing.assert_allclose(r.x, np.linalg.lstsq(A_rep, b_rep, rcond=None)[0], atol=AGREE_TOL)


def test_weights_change_the_answer_and_broadcast():
    rng = np.random.default_rng(5)
    A = rng.normal(size=(4, 10, 2))
    b = rng.normal(size=(4, 10))
    plain = lstsq.solve(A, b)
    w = np.linspace(0.5, 5.0, 10)  # one weight vector for the whole stack
    weighted = lstsq.solve(A, b, weights=w)
    assert np.max(np.abs(weighted.x - plain.x)) > 1e-3
    np.testing.assert_allclose(lstsq.solve(A, b, weights=np.ones(10)).x, plain.x, atol=1e-14)
    for k in range(4):
        np.testing.assert_allclose(lstsq.solve(A[k], b[k], weights=w).x, weighted.x[k], atol=1e-14)


@pytest.mark.parametrize(
    "w, match",
    [
        (-np.ones(10), "weights >= 0"),
        (np.ones(9), "weights"),
        (np.full(10, np.nan), "weights"),
    ],
)
def test_bad_weights_name_the_argument(w, match):
    with pytest.raises(ValueError, match=match):
        lstsq.solve(np.ones((10, 2)), np.ones(10), weights=w)
