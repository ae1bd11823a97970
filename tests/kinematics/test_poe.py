"""Product of exponentials, Jacobians and Hessians: against Modern Robotics and central differences."""

import modern_robotics as mr
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from robomech.kinematics import (
    hessian_body,
    hessian_space,
    jacobian_body,
    jacobian_derivative,
    jacobian_space,
    poe_fk,
)
from robomech.spatial import adjoint, exp_se3, inverse_transform, screw_from_axis
from robomech.testing import numerical_hessian, numerical_jacobian, numerical_space_jacobian

INDEPENDENT_TOL = 1e-12  # same closed forms in double precision, O(n) products
# Central differences with step 6e-6 on O(1) functions: truncation ~h^2 ~ 4e-11, rounding ~eps/h ~ 4e-11.
FD_TOL = 1e-8


def random_chain(rng, n):
    axes = rng.normal(size=(n, 3))
    points = rng.normal(size=(n, 3))
    pitch = np.where(rng.random(n) < 0.2, np.inf, 0.0)
    S = screw_from_axis(axes, points, pitch)
    M = exp_se3(rng.normal(size=6))
    return M, S


@pytest.mark.parametrize("seed", range(5))
def test_fk_and_jacobians_match_modern_robotics(seed):
    rng = np.random.default_rng(seed)
    n = 6 + seed
    M, S = random_chain(rng, n)
    q = rng.uniform(-np.pi, np.pi, size=(20, n))
    T = poe_fk(M, S, q)
    Js = jacobian_space(S, q)
    B = np.einsum("ij,nj->ni", adjoint(inverse_transform(M)), S)  # body screws
    Jb = jacobian_body(B, q)
    for k in range(q.shape[0]):
        assert np.abs(T[k] - mr.FKinSpace(M, S.T, q[k])).max() < INDEPENDENT_TOL
        assert np.abs(Js[k] - mr.JacobianSpace(S.T, q[k])).max() < INDEPENDENT_TOL
        assert np.abs(Jb[k] - mr.JacobianBody(B.T, q[k])).max() < INDEPENDENT_TOL


def test_space_jacobian_matches_finite_differences():
    rng = np.random.default_rng(7)
    M, S = random_chain(rng, 7)
    q = rng.uniform(-2, 2, size=(10, 7))
    J_fd = numerical_space_jacobian(lambda x: poe_fk(M, S, x), q)
    assert np.abs(jacobian_space(S, q) - J_fd).max() < FD_TOL


@given(st.integers(0, 10_000), st.integers(1, 7))
def test_hessian_space_matches_central_differences(seed, n):
    rng = np.random.default_rng(seed)
    _, S = random_chain(rng, n)
    q = rng.uniform(-np.pi, np.pi, size=(3, n))
    H = hessian_space(S, q)
    assert H.shape == (3, 6, n, n)
    H_fd = numerical_hessian(lambda x: jacobian_space(S, x), q)
    assert np.abs(H - H_fd).max() < FD_TOL * max(1.0, np.abs(H).max())


def test_hessian_body_matches_central_differences():
    rng = np.random.default_rng(3)
    _, B = random_chain(rng, 6)
    q = rng.uniform(-np.pi, np.pi, size=(4, 6))
    H_fd = numerical_hessian(lambda x: jacobian_body(B, x), q)
    assert np.abs(hessian_body(B, q) - H_fd).max() < FD_TOL * 10


def test_jacobian_derivative_along_a_path():
    rng = np.random.default_rng(4)
    _, S = random_chain(rng, 5)
    q0, qd = rng.normal(size=5), rng.normal(size=5)
    dt = 1e-6
    Jdot_fd = (jacobian_space(S, q0 + qd * dt) - jacobian_space(S, q0 - qd * dt)) / (2 * dt)
    assert np.abs(jacobian_derivative(hessian_space(S, q0), qd) - Jdot_fd).max() < FD_TOL


def test_batch_broadcasting_and_identical_to_per_sample():
    rng = np.random.default_rng(5)
    M, S = random_chain(rng, 4)
    q = rng.normal(size=(3, 5, 4))
    T = poe_fk(M, S, q)
    assert T.shape == (3, 5, 4, 4)
    per = np.stack([[poe_fk(M, S, q[i, j]) for j in range(5)] for i in range(3)])
    assert np.abs(T - per).max() <= 1e-12
    assert jacobian_space(S, q).shape == (3, 5, 6, 4)


def test_finite_difference_helper_is_itself_correct():
    # d/dx sin(x) = cos(x): the reference used by every derivative test must be right.
    x = np.linspace(-3, 3, 7)[:, None]
    assert np.abs(numerical_jacobian(np.sin, x)[..., 0, 0] - np.cos(x[:, 0])).max() < 1e-10


@pytest.mark.parametrize(
    "screws, q, message",
    [
        (np.zeros((3, 5)), np.zeros(3), "screws"),
        (np.zeros((3, 6)), np.zeros(4), "q"),
        (np.zeros((3, 6)), [0.0, np.nan, 0.0], "q"),
    ],
)
def test_bad_input_names_the_argument(screws, q, message):
    with pytest.raises(ValueError, match=message):
        jacobian_space(screws, q)
    with pytest.raises(ValueError, match="M"):
        poe_fk(np.eye(3), np.zeros((3, 6)), np.zeros(3))
