"""Kinematics of the spherical parallel leg (paper 1): Table 1, round trips, derivatives, bad input."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from robomech.mechanisms import spherical_leg as sl
from robomech.testing import numerical_jacobian

LEG = sl.SphericalLeg.paper()
PI = np.pi

# Paper 1, Table 1: given poses (alpha, beta) and printed input displacements l1, l2, l3 in mm (4 decimals).
TABLE1 = np.array(
    [
        [-PI / 6, -PI / 6, 141.8728, 71.6093, 78.3115],
        [-PI / 12, -PI / 12, 126.7305, 91.0826, 91.8060],
        [0.0, 0.0, 109.6586, 109.6586, 109.6586],
        [PI / 12, PI / 12, 91.0826, 126.7305, 126.2075],
        [PI / 6, PI / 6, 71.6093, 141.8728, 138.2862],
    ]
)
# The printed lengths are 4-decimal roundings in mm: half a unit of the last digit.
TABLE1_ROUNDING_MM = 0.5e-4 + 1e-9
# Round trip of exact lengths: rounding of the closed forms (conditioning of asin/atan2 ~ 1e2 near
# the workspace edges times eps), far below the 1e-10 rad.
ROUND_TRIP_TOL = 1e-10
# Central differences with step 6e-6 rad on O(0.1 m) lengths: truncation + rounding ~ 1e-10.
FD_TOL = 1e-8


def test_table1_lengths_are_the_exact_values_rounded():
    ik = sl.inverse_kinematics(LEG, TABLE1[:, 0], TABLE1[:, 1])
    assert np.max(np.abs(ik.lengths * 1e3 - TABLE1[:, 2:])) <= TABLE1_ROUNDING_MM


def test_table1_forward_kinematics_error_is_rounding_not_0_0127():
    ik = sl.inverse_kinematics(LEG, TABLE1[:, 0], TABLE1[:, 1])
    fk = sl.forward_kinematics(LEG, ik.lengths)
    assert fk.valid.all() and fk.converged.all()
    assert np.max(np.abs(fk.alpha - TABLE1[:, 0])) < 1e-14
    assert np.max(np.abs(fk.beta - TABLE1[:, 1])) < 1e-14
    # the printed (rounded) lengths are slightly inconsistent: a least-squares fit with a small residual
    fk_p = sl.forward_kinematics(LEG, TABLE1[:, 2:] * 1e-3)
    assert np.max(np.abs(fk_p.alpha - TABLE1[:, 0])) < 1e-5
    assert np.max(fk_p.residual) < 1e-7


@settings(max_examples=80, deadline=None)
@given(
    st.floats(-1.2, 1.2),
    st.floats(-1.2, 1.2),
)
def test_fk_of_ik_round_trip(alpha, beta):
    ik = sl.inverse_kinematics(LEG, alpha, beta)
    dl3 = sl.jacobian(LEG, alpha, beta)[2, 0]
    # On the singular curve dl3/dalpha = 0 alpha is ill-posed (error ~ eps / sqrt(1 - s^2)); 1e-4 R/rad
    # away from it the conditioning costs at most ~1e4 eps, still far below the 1e-10 rad target.
    assume(abs(dl3) > 1e-4 * LEG.R)
    # the assembly branch containing alpha = 0 is the one where dl3/dalpha > 0
    branch = 0 if dl3 > 0 else 1
    fk = sl.forward_kinematics(LEG, ik.lengths, branch=branch)
    assert fk.valid and fk.converged
    assert abs(fk.alpha - alpha) < ROUND_TRIP_TOL
    assert abs(fk.beta - beta) < ROUND_TRIP_TOL
    assert fk.residual < 1e-12


def test_branch_one_is_the_other_assembly():
    a, b = 0.4, 0.3
    L = sl.inverse_kinematics(LEG, a, b).lengths
    other = sl.forward_kinematics(LEG, L, branch=1)
    assert other.valid and abs(other.alpha - a) > 0.5
    L2 = sl.inverse_kinematics(LEG, other.alpha, other.beta).lengths
    assert np.max(np.abs(L2 - L)) < 1e-15
    assert sl.jacobian(LEG, other.alpha, other.beta)[2, 0] < 0


def test_ik_of_fk_round_trip_on_a_grid():
    g = np.stack(np.meshgrid(np.linspace(-1, 1, 21), np.linspace(-1, 1, 21)), -1)
    L = sl.inverse_kinematics(LEG, g[..., 0], g[..., 1]).lengths
    fk = sl.forward_kinematics(LEG, L)
    L2 = sl.inverse_kinematics(LEG, fk.alpha, fk.beta).lengths
    assert np.max(np.abs(L2 - L)) < 1e-14


def test_noisy_lengths_give_a_least_squares_fit_with_its_residual():
    rng = np.random.default_rng(3)
    q = rng.uniform(-0.8, 0.8, (200, 2))
    L = sl.inverse_kinematics(LEG, q[:, 0], q[:, 1]).lengths
    noise = rng.normal(scale=1e-4, size=L.shape)
    fk = sl.forward_kinematics(LEG, L + noise)
    assert fk.valid.all() and fk.converged.all()
    # optimality: the length residual is orthogonal to both pose directions (gradient of 1/2|r|^2 = 0)
    fitted = sl.inverse_kinematics(LEG, fk.alpha, fk.beta).lengths
    res = fitted - (L + noise)
    J = sl.jacobian(LEG, fk.alpha, fk.beta)
    grad = np.einsum("nij,ni->nj", J, res)
    assert np.max(np.abs(grad)) < 1e-15
    assert np.allclose(fk.residual, np.linalg.norm(res, axis=-1), rtol=1e-12, atol=1e-18)
    # the residual is of the order of the noise, the pose error of noise / sensitivity
    assert 1e-6 < np.median(fk.residual) < 3e-4
    # nudging beta in either direction only increases the misfit
    for d in (-1e-6, 1e-6):
        worse = sl.inverse_kinematics(LEG, fk.alpha, fk.beta + d).lengths[:, :2] - (L + noise)[:, :2]
        assert np.all(np.linalg.norm(worse, axis=-1) >= np.linalg.norm(res[:, :2], axis=-1) - 1e-15)


def test_unassemblable_and_bad_lengths_are_flagged_per_sample():
    good = sl.inverse_kinematics(LEG, 0.2, -0.1).lengths
    L = np.stack(
        [good, [0.1, 0.1, 0.5], [np.nan, 0.1, 0.1], [-0.1, 0.1, 0.1], [0.1, np.inf, 0.1], [0.0, 0.1, 0.1]]
    )
    fk = sl.forward_kinematics(LEG, L)
    assert fk.valid.tolist() == [True, False, False, False, False, False]
    assert np.all(np.isnan(fk.alpha[1:])) and np.all(np.isnan(fk.residual[1:]))
    assert abs(fk.alpha[0] - 0.2) < 1e-12


def test_bad_inputs_raise_clear_errors():
    with pytest.raises(ValueError, match="alpha"):
        sl.inverse_kinematics(LEG, np.inf, 0.0)
    assert np.isnan(sl.inverse_kinematics(LEG, np.nan, 0.0).lengths).all()  # a failed sample: masked
    with pytest.raises(ValueError, match="beta"):
        sl.jacobian(LEG, 0.0, np.inf)
    with pytest.raises(ValueError, match="lengths"):
        sl.forward_kinematics(LEG, np.ones((4, 2)))
    with pytest.raises(ValueError, match="branch"):
        sl.forward_kinematics(LEG, np.ones(3) * 0.1, branch=2)
    with pytest.raises(ValueError, match="broadcast"):
        sl.inverse_kinematics(LEG, np.zeros(3), np.zeros(4))
    with pytest.raises(ValueError, match="qd"):
        sl.leg_rates(LEG, np.zeros(2), np.zeros(3), np.zeros(2))


def test_jacobian_and_hessian_match_central_differences():
    rng = np.random.default_rng(0)
    q = rng.uniform(-1.2, 1.2, (100, 2))
    lengths = lambda x: sl.inverse_kinematics(LEG, x[..., 0], x[..., 1]).lengths  # noqa: E731
    jac = lambda x: sl.jacobian(LEG, x[..., 0], x[..., 1])  # noqa: E731
    J = jac(q)
    assert np.max(np.abs(J - numerical_jacobian(lengths, q))) < FD_TOL
    H = sl.hessian(LEG, q[:, 0], q[:, 1])
    assert np.max(np.abs(H - numerical_jacobian(jac, q))) < FD_TOL
    assert np.max(np.abs(H - np.swapaxes(H, -1, -2))) < 1e-15


def test_influence_coefficients_map_angular_velocity_to_leg_rates():
    rng = np.random.default_rng(1)
    q = rng.uniform(-1, 1, (50, 2))
    G = sl.influence_coefficients(LEG, q[:, 0], q[:, 1])
    E = sl.angular_velocity_jacobian(q[:, 0])
    assert np.max(np.abs(G[..., :3] @ E - sl.jacobian(LEG, q[:, 0], q[:, 1]))) < 1e-15
    # E is the angular velocity of T = Rx(a) Ry(b): dT/dt T^T = hat(E qd)
    qd = rng.normal(size=(50, 2))
    T = lambda x: sl.platform_rotation(x[..., 0], x[..., 1])  # noqa: E731
    Td = np.einsum("nijk,nk->nij", numerical_jacobian(T, q), qd)
    W = Td @ np.swapaxes(T(q), -1, -2)
    w = np.stack([W[:, 2, 1], W[:, 0, 2], W[:, 1, 0]], -1)
    assert np.max(np.abs(w - np.einsum("nij,nj->ni", E, qd))) < 1e-9
    # eq. (12) (corrected): leg 3's first influence coefficient with the P-referenced lever arm
    a, b = q[:, 0], q[:, 1]
    l3 = sl.inverse_kinematics(LEG, a, b).lengths[:, 2]
    R, r, h = LEG.R, LEG.r, LEG.h
    row1 = (
        (-r * r * np.cos(a) * np.sin(a) + h * r * np.sin(a) ** 2 * np.cos(b) + R * r * np.sin(a))
        + (r * r * np.cos(a) * np.sin(a) + h * r * np.cos(a) ** 2 * np.cos(b))
    ) / l3
    ik = sl.inverse_kinematics(LEG, a, b)
    PB3 = ik.platform_points[:, 2] - h * sl.platform_rotation(a, b)[:, :, 2]
    assert np.max(np.abs(np.cross(PB3, ik.unit_vectors[:, 2])[:, 0] - row1)) < 1e-15


def test_leg_accelerations_are_second_time_derivatives():
    t = np.linspace(0.0, 3.0, 3001)
    dt = t[1] - t[0]
    q = np.stack([0.9 * np.sin(1.1 * t), 0.5 * np.cos(0.7 * t) - 0.2], -1)
    qd = np.stack([0.99 * np.cos(1.1 * t), -0.35 * np.sin(0.7 * t)], -1)
    qdd = np.stack([-1.089 * np.sin(1.1 * t), -0.245 * np.cos(0.7 * t)], -1)
    l, ld, ldd = sl.leg_rates(LEG, q, qd, qdd)
    assert np.max(np.abs(np.gradient(l, dt, axis=0) - ld)[2:-2]) < 1e-7
    assert np.max(np.abs(np.gradient(ld, dt, axis=0) - ldd)[2:-2]) < 1e-7
    # paper 1, eq. (14) with the corrected (I - s s^T)/l term: lddot = s.a_B + (|v_B|^2 - ldot^2)/l
    ik = sl.inverse_kinematics(LEG, q[:, 0], q[:, 1])
    E = sl.angular_velocity_jacobian(q[:, 0])
    w = np.einsum("nij,nj->ni", E, qd)
    dw = (
        np.einsum("nij,nj->ni", E, qdd)
        + np.stack([0 * t, -np.sin(q[:, 0]), np.cos(q[:, 0])], -1) * (qd[:, 0] * qd[:, 1])[:, None]
    )
    B = ik.platform_points
    vB = np.cross(w[:, None], B)
    aB = np.cross(dw[:, None], B) + np.cross(w[:, None], vB)
    ldd_paper = np.sum(ik.unit_vectors * aB, -1) + (np.sum(vB * vB, -1) - ld**2) / l
    assert np.max(np.abs(ldd_paper - ldd)) < 1e-14


def test_batched_equals_per_sample():
    rng = np.random.default_rng(5)
    q = rng.uniform(-1, 1, (40, 2))
    L = sl.inverse_kinematics(LEG, q[:, 0], q[:, 1]).lengths + rng.normal(scale=1e-5, size=(40, 3))
    fk = sl.forward_kinematics(LEG, L)
    J = sl.jacobian(LEG, q[:, 0], q[:, 1])
    H = sl.hessian(LEG, q[:, 0], q[:, 1])
    for k in range(40):
        one = sl.forward_kinematics(LEG, L[k])
        assert abs(one.alpha - fk.alpha[k]) <= 1e-12 and abs(one.beta - fk.beta[k]) <= 1e-12
        assert np.max(np.abs(sl.jacobian(LEG, q[k, 0], q[k, 1]) - J[k])) <= 1e-12
        assert np.max(np.abs(sl.hessian(LEG, q[k, 0], q[k, 1]) - H[k])) <= 1e-12
    # leading batch dimensions broadcast
    assert sl.inverse_kinematics(LEG, np.zeros((2, 1)), np.zeros((1, 5))).lengths.shape == (2, 5, 3)


def test_chunked_batches_equal_per_sample_across_chunk_boundaries():
    from robomech.mechanisms.spherical_leg._kinematics import CHUNK

    rng = np.random.default_rng(8)
    n = CHUNK + 7
    q = rng.uniform(-1, 1, (n, 2))
    ik = sl.inverse_kinematics(LEG, q[:, 0], q[:, 1])
    L = ik.lengths + rng.normal(scale=1e-5, size=(n, 3))
    fk = sl.forward_kinematics(LEG, L)
    J = sl.jacobian(LEG, q[:, 0], q[:, 1])
    wm = sl.workspace_map(LEG, q[:, 0], q[:, 1])
    for k in (0, CHUNK - 1, CHUNK, n - 1):
        one_ik = sl.inverse_kinematics(LEG, q[k, 0], q[k, 1])
        assert np.max(np.abs(one_ik.unit_vectors - ik.unit_vectors[k])) <= 1e-12
        assert np.max(np.abs(one_ik.platform_points - ik.platform_points[k])) <= 1e-12
        one = sl.forward_kinematics(LEG, L[k])
        assert abs(one.alpha - fk.alpha[k]) <= 1e-12 and abs(one.residual - fk.residual[k]) <= 1e-12
        assert np.max(np.abs(sl.jacobian(LEG, q[k, 0], q[k, 1]) - J[k])) <= 1e-12
        assert abs(sl.workspace_map(LEG, q[k, 0], q[k, 1]).cond - wm.cond[k]) <= 1e-12 * wm.cond[k]


def test_compiled_forward_kinematics_on_exact_noisy_and_bad_samples():
    # the compiled kernels on noisy, exact, branch-1 and bad samples: exact lengths give the poses back,
    # the residual is the inverse kinematics' distance to the measured lengths, bad samples are masked
    rng = np.random.default_rng(11)
    n = 4101
    q = rng.uniform(-1.2, 1.2, (n, 2))
    L = sl.inverse_kinematics(LEG, q[:, 0], q[:, 1]).lengths
    L[: n // 2] += rng.normal(scale=1e-4, size=(n // 2, 3))
    L[1] = [np.nan, 0.1, 0.1]
    L[2] = [0.1, 0.1, 0.5]  # no assembly
    L[3] = [0.1, -0.1, 0.1]
    L[4] = [0.1, 0.1, np.inf]
    L[5] = [0.0, 0.1, 0.1]
    for branch in (0, 1):
        fk = sl.forward_kinematics(LEG, L, branch=branch)
        valid = fk.valid
        assert valid[0] and not valid[1:6].any() and valid[6:].mean() > 0.9
        assert not (fk.converged & ~valid).any()
        for got in (fk.alpha, fk.beta, fk.residual):
            assert np.array_equal(np.isnan(got), ~valid)
        back = sl.inverse_kinematics(LEG, fk.alpha[valid], fk.beta[valid]).lengths
        resid = np.linalg.norm(back - L[valid], axis=-1)
        assert np.max(np.abs(resid - fk.residual[valid])) <= 1e-12
        exact = valid.copy()
        exact[: n // 2] = False
        if branch == 0:  # the noise-free half: the poses themselves (branch 0 holds alpha = 0)
            same = exact & (np.abs(fk.alpha - q[:, 0]) < 1e-6)
            assert same.sum() > 0.5 * exact.sum()
            assert np.max(np.abs(fk.beta[same] - q[same, 1])) <= 1e-12
            assert np.max(np.abs(fk.alpha[same] - q[same, 0])) <= 1e-12
