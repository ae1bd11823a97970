"""The composite system A0 ṗ = J q̇ and the batched least-squares estimator."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomech.mechanisms.skid_steer import (
    I_ROCKER1,
    I_ROCKER2,
    I_ROLL,
    I_YAW,
    ExplorationRobot,
    assemble,
    body_velocity,
    contact_frames,
    wheel_measurements,
)
from robomech.spatial import exp_se3

ROBOT = ExplorationRobot.paper()
EPS = np.finfo(float).eps
# Noise-free round trip: the target (observed ~1e-15 on these O(1) motions).
EXACT_TOL = 1e-9


def _motion(rng: np.random.Generator, n: int | None = None):
    """Random configuration, body twist and differential-consistent joint rates."""
    shape = () if n is None else (n,)
    q = rng.uniform(-0.3, 0.3, size=(*shape, 8))
    q[..., 3] += ROBOT.rear_wheel_drop
    q[..., 7] += ROBOT.rear_wheel_drop
    V = rng.uniform(-0.5, 0.5, size=(*shape, 6))
    qd = rng.uniform(-0.5, 0.5, size=(*shape, 8))
    qd[..., 4] = -qd[..., 0]  # the differential: the rockers turn oppositely relative to the body
    return q, V, qd


def test_shapes_are_30_by_11_and_30_by_22_batched():
    q, _, _ = _motion(np.random.default_rng(0), 12)
    A0, J = assemble(ROBOT, q.reshape(3, 4, 8))
    assert A0.shape == (3, 4, 30, 11)
    assert J.shape == (3, 4, 30, 22)


def test_exact_motion_satisfies_every_row():
    q, V, qd = _motion(np.random.default_rng(1), 100)
    A0, J = assemble(ROBOT, q)
    m = wheel_measurements(ROBOT, q, V, qd)
    p = np.concatenate([V[:, 3:], V[:, [0, 2]], qd[:, [1, 2, 5, 6, 3, 7]]], axis=-1)  # paper order
    r = np.einsum("nij,nj->ni", A0, p) - np.einsum("nij,nj->ni", J, m)
    assert np.max(np.abs(r)) < 1e-14


def test_measurements_are_contact_velocities_by_time_differences_of_the_chain():
    """Independent of the velocity kernel: differentiate T_GB(t) T_BP(q(t)) in time."""
    rng = np.random.default_rng(2)
    q0, V, qd = _motion(rng, 20)
    T0 = exp_se3(rng.normal(size=(20, 6)))
    h = 1e-5

    def contacts(t: float) -> np.ndarray:
        T_GB = T0 @ exp_se3(t * V)
        return T_GB[:, None] @ contact_frames(ROBOT, q0 + t * qd)

    v_world = (contacts(h)[..., :3, 3] - contacts(-h)[..., :3, 3]) / (2 * h)
    R_GP = contacts(0.0)[..., :3, :3]
    v_P = np.einsum("nwji,nwj->nwi", R_GP, v_world)
    m = wheel_measurements(ROBOT, q0, V, qd)
    np.testing.assert_allclose(m[:, :18].reshape(20, 6, 3), v_P, atol=1e-9)
    np.testing.assert_allclose(m[:, I_ROCKER1], V[:, 1] + qd[:, 0], atol=1e-15)
    np.testing.assert_allclose(m[:, I_ROCKER2], V[:, 1] + qd[:, 4], atol=1e-15)
    np.testing.assert_allclose(m[:, [I_ROLL, I_YAW]], V[:, [0, 2]], atol=0)


@settings(max_examples=80, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_noise_free_estimate_recovers_the_motion(seed):
    q, V, qd = _motion(np.random.default_rng(seed), 8)
    est = body_velocity(ROBOT, q, wheel_measurements(ROBOT, q, V, qd))
    assert np.all(est.valid)
    np.testing.assert_allclose(est.twist, V, atol=EXACT_TOL)
    np.testing.assert_allclose(est.config_rate, qd, atol=EXACT_TOL)
    assert np.all(est.residual_norm < EXACT_TOL)
    # the body pitch rate comes from the rockers through the differential
    m = wheel_measurements(ROBOT, q, V, qd)
    np.testing.assert_allclose(est.twist[:, 1], 0.5 * (m[:, I_ROCKER1] + m[:, I_ROCKER2]), atol=1e-15)


def test_condition_number_is_that_of_A0():
    q, _, _ = _motion(np.random.default_rng(3), 30)
    A0, _ = assemble(ROBOT, q)
    est = body_velocity(ROBOT, q, np.zeros(22), exact_cond=True)
    np.testing.assert_allclose(est.cond, np.linalg.cond(A0), rtol=1e-10)
    assert np.all(est.cond < 1e3)  # well conditioned across the suspension's range
    # the default (1-norm condition of R) is within a factor n = 11 of the 2-norm one
    c1 = body_velocity(ROBOT, q, np.zeros(22)).cond
    assert np.all((c1 >= np.linalg.cond(A0) / 11) & (c1 <= 11 * np.linalg.cond(A0)))


def test_without_the_differential_only_the_pitch_rate_is_lost():
    # The rocker pivots lie on the body y axis, so a wheel's rows see only its rocker's absolute pitch
    # rate ω_i = ω_BY + θ̇_i: the wheels cannot tell body pitch from rocker rotation, and the
    # differential (θ̇2 = -θ̇1) is what fixes ω_BY = (ω1 + ω2)/2.
    q, V, qd = _motion(np.random.default_rng(4), 10)
    qd[:, 4] = -qd[:, 0] + 0.1  # left rocker not opposite to the right one
    est = body_velocity(ROBOT, q, wheel_measurements(ROBOT, q, V, qd))
    assert np.all(est.residual_norm < EXACT_TOL)
    keep = [0, 2, 3, 4, 5]
    np.testing.assert_allclose(est.twist[:, keep], V[:, keep], atol=EXACT_TOL)
    np.testing.assert_allclose(est.twist[:, 1] - V[:, 1], 0.05, atol=1e-12)


def test_qr_and_normal_equations_agree_on_a_well_conditioned_noisy_system():
    # paper 4, Sec. 2.2 reports residual norms 472.9 (QR) vs 7017.8 (normal equations); on a
    # well-conditioned system both minimise the same norm, so the residuals must agree.
    rng = np.random.default_rng(5)
    q, V, qd = _motion(rng, 500)
    m = wheel_measurements(ROBOT, q, V, qd) + rng.normal(scale=0.01, size=(500, 22))
    qr = body_velocity(ROBOT, q, m)
    ne = body_velocity(ROBOT, q, m, solver="normal_equations")
    assert np.max(qr.cond) < 1e3
    np.testing.assert_allclose(qr.residual_norm, ne.residual_norm, rtol=1e-10)
    np.testing.assert_allclose(qr.unknowns, ne.unknowns, atol=1e-11)
    assert np.all(qr.residual_norm > 1e-3)  # the noise really is there


def test_qr_keeps_accuracy_where_normal_equations_lose_it():
    # Side-link hinges 1e-7 m from the bogie hinge: the bogie and side-link rates nearly coincide.
    bad = dataclasses.replace(ROBOT, side_link_hinge_offset=1e-7)
    q, V, qd = _motion(np.random.default_rng(6), 50)
    m = wheel_measurements(bad, q, V, qd)
    qr = body_velocity(bad, q, m)
    ne = body_velocity(bad, q, m, solver="normal_equations")
    assert np.min(qr.cond) >= 1e7
    err_qr = np.max(np.abs(qr.config_rate - qd), axis=-1)
    # QR: forward error ~ cond * eps (~1e-8); the normal equations: ~ cond^2 * eps, or singular A0ᵀA0.
    assert np.all(qr.valid)
    assert np.all(err_qr < 100 * qr.cond * EPS)
    err_ne = np.where(ne.valid, np.max(np.abs(np.nan_to_num(ne.config_rate) - qd), axis=-1), np.inf)
    assert np.all(err_ne > 1e3 * err_qr)


def test_nan_sample_is_flagged_not_fatal():
    q, V, qd = _motion(np.random.default_rng(7), 6)
    m = wheel_measurements(ROBOT, q, V, qd)
    m[2, 5] = np.nan
    q[4, 1] = np.nan
    est = body_velocity(ROBOT, q, m)
    assert est.valid.tolist() == [True, True, False, True, False, True]
    for a in (est.twist, est.config_rate, est.unknowns):
        assert np.all(np.isnan(a[~est.valid]))
        assert np.all(np.isfinite(a[est.valid]))
    np.testing.assert_allclose(est.twist[est.valid], V[est.valid], atol=EXACT_TOL)


def test_bad_inputs_name_the_argument():
    with pytest.raises(ValueError, match="state"):
        body_velocity(ROBOT, np.zeros(7), np.zeros(22))
    with pytest.raises(ValueError, match="measured"):
        body_velocity(ROBOT, np.zeros(8), np.zeros(21))
    with pytest.raises(ValueError, match="solver"):
        body_velocity(ROBOT, np.zeros(8), np.zeros(22), solver="lu")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="twist"):
        wheel_measurements(ROBOT, np.zeros(8), np.zeros(5), np.zeros(8))


def test_batched_equals_per_sample():
    rng = np.random.default_rng(8)
    q, V, qd = _motion(rng, 24)
    m = wheel_measurements(ROBOT, q, V, qd) + rng.normal(scale=0.01, size=(24, 22))
    batch = body_velocity(ROBOT, q.reshape(4, 6, 8), m.reshape(4, 6, 22))
    for k in range(24):
        one = body_velocity(ROBOT, q[k], m[k])
        i, j = divmod(k, 6)
        np.testing.assert_allclose(one.twist, batch.twist[i, j], rtol=0, atol=1e-12)
        np.testing.assert_allclose(one.residual_norm, batch.residual_norm[i, j], rtol=0, atol=1e-12)


def test_overflowing_sample_is_not_valid():
    """issue 14: a finite 1e160 sample overflowed the residual to inf with valid = True."""
    q = np.zeros(8)
    q[[3, 7]] = ROBOT.rear_wheel_drop
    m = np.full((3, 22), 0.1)
    m[1] = 1e160
    m[2] = 1e200
    est = body_velocity(ROBOT, q, m)
    assert est.valid.tolist() == [True, False, False]
    for a in (est.twist, est.config_rate, est.unknowns, est.residual_norm):
        assert np.all(np.isnan(a[~est.valid]))
        assert np.all(np.isfinite(a[est.valid]))
