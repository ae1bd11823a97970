"""Thigh closure by the product of exponentials (eqs. (1)-(8)) and the shank crank-slider (eq. (10))."""

from __future__ import annotations

import numpy as np
import pytest

import robomech.mechanisms.omnileg as ol
from robomech.kinematics import poe_fk

LEG = ol.OmniLeg.paper()
# The closure is solved to CLOSURE_TOL (1e-14); positions then agree with eq. (11) to rounding.
CLOSURE_AGREEMENT = 1e-12


@pytest.fixture(scope="module")
def grid():
    a = np.linspace(-LEG.alpha_max, LEG.alpha_max, 9)
    b = np.linspace(-LEG.beta_max, LEG.beta_max, 9)
    A, B = np.meshgrid(a, b)
    rng = np.random.default_rng(4)
    A = np.concatenate([A.ravel(), rng.uniform(-1, 1, 60) * LEG.alpha_max])
    B = np.concatenate([B.ravel(), rng.uniform(-1, 1, 60) * LEG.beta_max])
    return A, B, ol.thigh_closure(LEG, A, B)


def test_closure_converges_and_knee_plate_only_translates(grid):
    _, _, c = grid
    assert c.converged.all()
    assert c.translation_only.all()
    assert c.residual.max() <= 1e-13
    np.testing.assert_allclose(
        c.T_knee[..., :3, :3], np.broadcast_to(np.eye(3), c.T_knee[..., :3, :3].shape), atol=CLOSURE_AGREEMENT
    )


def test_closure_knee_equals_eq9_eq11(grid):
    A, B, c = grid
    q = np.stack([A, B, np.zeros_like(A)], axis=-1)
    foot = ol.forward_kinematics(LEG, q)
    np.testing.assert_allclose(c.knee[:, :2], foot[:, :2], atol=CLOSURE_AGREEMENT)
    np.testing.assert_allclose(c.knee[:, 2], foot[:, 2] - 2 * LEG.L4 - LEG.L5, atol=CLOSURE_AGREEMENT)
    # eq. (9) as printed lacks sin β in the x component (errata): it disagrees with the closure
    printed_x = LEG.L1 * np.cos(np.arctan(np.tan(A) * np.cos(B)))
    assert np.abs(printed_x - c.knee[:, 0]).max() > 0.1


def test_all_three_chains_reach_the_same_pose(grid):
    _, _, c = grid
    S, M = ol.chain_screws(LEG)
    T = [poe_fk(M, S[k], c.theta[:, k, :]) for k in range(3)]
    np.testing.assert_allclose(T[1], T[0], atol=CLOSURE_AGREEMENT)
    np.testing.assert_allclose(T[2], T[0], atol=CLOSURE_AGREEMENT)


def test_passive_angles_eq12_and_parallelogram_structure(grid):
    A, B, c = grid
    th12, th22 = ol.passive_angles(LEG, A, B)
    np.testing.assert_allclose(c.theta[:, 0, 1], th12, atol=CLOSURE_AGREEMENT)  # eq. (12) as printed
    np.testing.assert_allclose(c.theta[:, 1, 1], th22, atol=CLOSURE_AGREEMENT)
    # eq. (12) prints θ22 = +arctan(tan β cos α); the closure with ω22 = [0 -1 0] gives the opposite sign
    np.testing.assert_allclose(c.theta[:, 1, 1], -np.arctan(np.tan(B) * np.cos(A)), atol=CLOSURE_AGREEMENT)
    np.testing.assert_allclose(c.theta[:, 0, 2], -c.theta[:, 0, 1], atol=CLOSURE_AGREEMENT)  # θ13 = -θ12
    np.testing.assert_allclose(c.theta[:, 0, 3], -B, atol=CLOSURE_AGREEMENT)  # θ14 = -β (eq. (16) sign)
    np.testing.assert_allclose(c.theta[:, 2, 0], -B, atol=CLOSURE_AGREEMENT)  # chain 3's first joint


def test_chain_screws_follow_eqs_1_2_5():
    S, _ = ol.chain_screws(LEG)
    # chain 1, eq. (1)/(2): ω11 = y through (0, L3, 0) -> v = q × ω = 0
    np.testing.assert_allclose(S[0, 0], [0, 1, 0, 0, 0, 0], atol=1e-15)
    # chain 2 = Rz(-π/2) chain 1 (eq. (5) as printed): first axis along +X0 through (L3, 0, 0)
    np.testing.assert_allclose(S[1, 0], [1, 0, 0, 0, 0, 0], atol=1e-15)
    np.testing.assert_allclose(S[1, 1, :3], [0, -1, 0], atol=1e-15)


def test_shank_crank_slider_equals_eq10_and_foot_equals_eq11():
    g = np.linspace(LEG.gamma_min, LEG.gamma_max, 50)
    s = ol.shank_crank_slider(LEG, g)
    np.testing.assert_allclose(s.delta_L2, 2 * LEG.L4 - 2 * LEG.L4 * np.cos(g), atol=1e-15)  # eq. (10)
    np.testing.assert_allclose(np.linalg.norm(s.D - s.C, axis=-1), LEG.L4, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(s.E - s.D, axis=-1), LEG.L4, atol=1e-15)
    np.testing.assert_allclose(s.E[..., :2], s.C[..., :2], atol=1e-15)  # slider straight below C_i
    np.testing.assert_allclose(s.coupler_angle, -g, atol=1e-15)
    # whole foot from the solved thigh closure and the shank, against eq. (11)
    rng = np.random.default_rng(5)
    q = np.stack([rng.uniform(-1, 1, 50) * LEG.alpha_max, rng.uniform(-1, 1, 50) * LEG.beta_max, g], -1)
    c = ol.thigh_closure(LEG, q[:, 0], q[:, 1])
    foot = c.knee + s.E.mean(axis=-2) + np.array([0.0, 0.0, LEG.foot_drop])
    np.testing.assert_allclose(foot, ol.forward_kinematics(LEG, q), atol=CLOSURE_AGREEMENT)


def test_shank_flags_flat_crank_per_sample():
    s = ol.shank_crank_slider(LEG, [0.3, np.pi / 2, -2.0, -0.3])
    assert s.valid.tolist() == [True, False, False, True]
    assert np.all(np.isnan(s.slider[~s.valid])) and np.all(np.isfinite(s.slider[s.valid]))
    assert np.all(np.isnan(s.E[~s.valid]))
    with pytest.raises(ValueError, match="gamma"):
        ol.shank_crank_slider(LEG, [np.inf])
    assert not ol.shank_crank_slider(LEG, [np.nan]).valid.any()  # a failed sample stays failed


def test_joint_motion_rates_are_time_derivatives_and_match_the_closure():
    t = np.linspace(0.0, 1.0, 2001)
    dt = t[1] - t[0]
    q = np.stack([0.6 * np.sin(2 * t), 0.5 * np.cos(3 * t), 0.7 + 0.3 * np.sin(t)], -1)
    qd = np.stack([1.2 * np.cos(2 * t), -1.5 * np.sin(3 * t), 0.3 * np.cos(t)], -1)
    qdd = np.stack([-2.4 * np.sin(2 * t), -4.5 * np.cos(3 * t), -0.3 * np.sin(t)], -1)
    jm = ol.joint_motion(LEG, q, qd, qdd)
    assert jm.q.shape == (t.size, len(ol.TREE_JOINTS))
    # central differences in time: error ~dt² q''' / 6 ~ 1e-6
    np.testing.assert_allclose(jm.qd[1:-1], (jm.q[2:] - jm.q[:-2]) / (2 * dt), atol=1e-5)
    np.testing.assert_allclose(jm.qdd[1:-1], (jm.qd[2:] - jm.qd[:-2]) / (2 * dt), atol=1e-4)
    c = ol.thigh_closure(LEG, q[::400, 0], q[::400, 1])
    # the tree keeps θ11..θ14, θ21..θ23, θ31..θ33 (the closure's theta is (chain, joint) = 3 x 4)
    np.testing.assert_allclose(jm.q[::400, :10], c.theta.reshape(-1, 12)[:, [0, 1, 2, 3, 4, 5, 6, 8, 9, 10]],
                               atol=CLOSURE_AGREEMENT)  # fmt: skip
