"""SO(3)/SE(3)/screw algebra against Modern Robotics (an independent implementation) and identities."""

import modern_robotics as mr
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import array_shapes, arrays

from robomech import spatial as sp

# Agreement with an independent double-precision implementation of the same closed forms:
# both round at ~1e-16 per operation; 1e-12 leaves margin for O(10) operations on O(1-10) entries.
INDEPENDENT_TOL = 1e-12
# Round trips near the singular angles 0 and pi must stay at rounding level (no 1e-8 cancellation).
ROUND_TRIP_TOL = 1e-13

rng = np.random.default_rng(42)


def random_twists(n, scale=3.0):
    return rng.normal(size=(n, 6)) * np.array([scale / 3] * 3 + [scale] * 3)


def test_exp_se3_matches_modern_robotics():
    V = random_twists(200)
    ours = sp.exp_se3(V)
    ref = np.stack([mr.MatrixExp6(mr.VecTose3(v)) for v in V])
    assert np.abs(ours - ref).max() < INDEPENDENT_TOL


def test_log_se3_matches_modern_robotics():
    V = random_twists(200)
    V[:, :3] *= (np.pi * 0.95) / np.maximum(np.linalg.norm(V[:, :3], axis=1, keepdims=True), np.pi * 0.95)
    T = sp.exp_se3(V)
    ours = sp.log_se3(T)
    ref = np.stack([mr.se3ToVec(mr.MatrixLog6(t)) for t in T])
    assert np.abs(ours - ref).max() < 1e-10  # MR uses arccos for the angle: ~1e-11 accuracy of its own


def test_adjoint_matches_modern_robotics():
    T = sp.exp_se3(random_twists(50))
    ours = sp.adjoint(T)
    ref = np.stack([mr.Adjoint(t) for t in T])
    assert np.abs(ours - ref).max() < INDEPENDENT_TOL


def test_ad_and_lie_bracket_match_modern_robotics():
    V1, V2 = random_twists(50), random_twists(50)
    ref = np.stack([mr.ad(v) for v in V1])
    assert np.abs(sp.ad(V1) - ref).max() < INDEPENDENT_TOL
    assert np.abs(sp.lie_bracket(V1, V2) - np.einsum("nij,nj->ni", ref, V2)).max() < INDEPENDENT_TOL


def test_lie_bracket_is_the_matrix_commutator():
    V1, V2 = random_twists(20), random_twists(20)
    X1, X2 = sp.hat_se3(V1), sp.hat_se3(V2)
    assert np.allclose(sp.hat_se3(sp.lie_bracket(V1, V2)), X1 @ X2 - X2 @ X1, atol=1e-12)


@pytest.mark.parametrize(
    "angle", [0.0, 1e-12, 1e-8, 1e-5, 1e-4, 2e-4, 0.5, np.pi / 2, np.pi - 1e-4, np.pi - 1e-9, np.pi]
)
def test_so3_round_trip_near_singular_angles(angle):
    axes = rng.normal(size=(20, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    w = axes * angle
    w_back = sp.log_so3(sp.exp_so3(w))
    if angle == np.pi:  # +-axis are the same rotation at pi
        same = np.minimum(np.abs(w_back - w).max(axis=1), np.abs(w_back + w).max(axis=1))
        assert same.max() < ROUND_TRIP_TOL * 10
    else:
        assert np.abs(w_back - w).max() < ROUND_TRIP_TOL * max(1.0, angle) * 10


@pytest.mark.parametrize("angle", [0.0, 1e-9, 1e-4, 1.0, np.pi - 1e-7])
def test_se3_round_trip_near_singular_angles(angle):
    axes = rng.normal(size=(20, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    V = np.concatenate([axes * angle, rng.normal(size=(20, 3))], axis=1)
    T = sp.exp_se3(V)
    assert np.abs(sp.exp_se3(sp.log_se3(T)) - T).max() < 1e-12
    assert np.abs(sp.log_se3(T) - V).max() < 1e-9  # near pi, v scales with 1/(pi - angle) rounding


@given(
    arrays(
        np.float64,
        array_shapes(min_dims=1, max_dims=3, max_side=4).map(lambda s: (*s, 6)),
        elements=st.floats(-3, 3),
    )
)
def test_exp_se3_batch_shapes_and_group_properties(V):
    T = sp.exp_se3(V)
    assert T.shape == (*V.shape[:-1], 4, 4)
    R = T[..., :3, :3]
    assert np.allclose(R @ np.swapaxes(R, -1, -2), np.eye(3), atol=1e-12)
    assert np.allclose(np.linalg.det(R), 1.0, atol=1e-12)
    assert np.allclose(sp.inverse_transform(T) @ T, np.eye(4), atol=1e-12)
    # Adjoint is a homomorphism: Ad(T1 T2) = Ad(T1) Ad(T2)
    T2 = np.flip(T, axis=0)
    assert np.allclose(sp.adjoint(T @ T2), sp.adjoint(T) @ sp.adjoint(T2), atol=1e-10)


def test_hat_vee_round_trip_and_cross():
    a, b = rng.normal(size=(10, 3)), rng.normal(size=(10, 3))
    assert np.allclose(np.einsum("nij,nj->ni", sp.hat(a), b), np.cross(a, b))
    assert np.allclose(sp.vee(sp.hat(a)), a)
    V = random_twists(10)
    assert np.allclose(sp.vee_se3(sp.hat_se3(V)), V)


def test_elementary_rotations_match_exp():
    t = rng.uniform(-4, 4, size=30)
    for f, axis in ((sp.rot_x, 0), (sp.rot_y, 1), (sp.rot_z, 2)):
        w = np.zeros((30, 3))
        w[:, axis] = t
        assert np.allclose(f(t), sp.exp_so3(w), atol=1e-14)


def test_screw_axis_round_trip_and_pitch():
    axis = rng.normal(size=(30, 3))
    point = rng.normal(size=(30, 3))
    pitch = rng.normal(size=30)
    S = sp.screw_from_axis(axis, point, pitch)
    d, p, h = sp.screw_to_axis(S)
    assert np.allclose(d, axis / np.linalg.norm(axis, axis=1, keepdims=True))
    assert np.allclose(h, pitch)
    # recovered point lies on the original line
    off = np.cross(p - point, d)
    assert np.abs(off).max() < 1e-12
    Sp = sp.screw_from_axis(axis[0], point[0], np.inf)
    assert np.allclose(Sp[:3], 0) and np.isinf(sp.screw_to_axis(Sp)[2])


def test_reciprocal_product_of_force_through_revolute_axis_is_zero():
    axis, point = rng.normal(size=(20, 3)), rng.normal(size=(20, 3))
    S = sp.screw_from_axis(axis, point)
    f = rng.normal(size=(20, 3))
    # A force through a point of the axis does no work on the rotation, in both notations:
    force_screw = sp.screw_from_axis(f, point) * np.linalg.norm(f, axis=1, keepdims=True)  # [f; r x f]
    assert np.abs(sp.reciprocal_product(force_screw, S)).max() < 1e-12
    W = sp.wrench_at(f, point)  # [m; f]
    assert np.abs(sp.virtual_power(W, S)).max() < 1e-12
    # and for any twist, the virtual power equals the reciprocal product with the halves swapped
    V = random_twists(20)
    assert np.allclose(sp.virtual_power(W, V), sp.reciprocal_product(W[:, [3, 4, 5, 0, 1, 2]], V))
    assert np.allclose(force_screw, W[:, [3, 4, 5, 0, 1, 2]])


# sincos: absolute error of the half-angle formulas, ~2 ulp of 1 (measured 2.2e-16 on 10^6 angles).
SINCOS_TOL = 4.5e-16


def test_sincos_matches_numpy_everywhere_including_odd_multiples_of_pi():
    x = np.concatenate(
        [
            np.random.default_rng(0).uniform(-100, 100, 100_000),
            np.linspace(-4 * np.pi, 4 * np.pi, 10_001),
            np.pi * np.arange(-7, 8),
            [0.0, -0.0, 1e-300, np.pi / 2],
        ]
    )
    s, c = sp.sincos(x)
    assert np.abs(s - np.sin(x)).max() < SINCOS_TOL
    assert np.abs(c - np.cos(x)).max() < SINCOS_TOL
    small = np.logspace(-300, -1, 500)
    assert np.abs(sp.sincos(small)[0] / np.sin(small) - 1).max() < SINCOS_TOL  # relative near 0
    assert sp.sincos(np.zeros((2, 3)))[0].shape == (2, 3)
