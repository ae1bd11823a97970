"""Trajectories of eqs. (51), (52), (53) against the printed polynomials."""

from __future__ import annotations

import numpy as np

import robomech.mechanisms.omnileg as ol

LEG = ol.OmniLeg.paper()


def test_eq51_equals_printed_polynomials():
    t = np.linspace(0.0, 5.0, 501)
    p = ol.foot_trajectory_eq51(LEG, t)
    d = p.q - ol.start_point(LEG)
    X = lambda s: 0.1 * (0.06144 * s**5 - 0.384 * s**4 + 0.64 * s**3)  # noqa: E731 - paper 2, eq. (51)
    x_printed = np.where(t <= 2.5, X(t), X(5.0 - t))
    y_printed = 0.1 * (0.00192 * t**5 - 0.024 * t**4 + 0.08 * t**3)
    z_printed = 0.05 * (-0.004096 * t**6 + 0.06144 * t**5 - 0.3072 * t**4 + 0.512 * t**3)
    np.testing.assert_allclose(d[:, 0], x_printed, atol=1e-14)
    np.testing.assert_allclose(d[:, 1], y_printed, atol=1e-14)
    np.testing.assert_allclose(-d[:, 2], z_printed, atol=1e-14)  # Z is a lift (against Z0)
    assert ol.inverse_kinematics(LEG, p.q).reachable.all()


def test_eq52_values_and_derivatives():
    t = np.linspace(0.0, 6.0, 6001)
    prof = ol.joint_trajectory_eq52(t)
    amp = np.array([np.pi / 6, np.pi / 6, 25 * np.pi / 180])
    np.testing.assert_allclose(prof.q, amp * np.sin(np.pi * t / 3)[:, None], atol=1e-15)
    dt = t[1] - t[0]
    np.testing.assert_allclose(prof.qd[1:-1], (prof.q[2:] - prof.q[:-2]) / (2 * dt), atol=1e-6)
    np.testing.assert_allclose(prof.qdd[1:-1], (prof.qd[2:] - prof.qd[:-2]) / (2 * dt), atol=1e-6)


def test_eq53_gait_swing_and_stance():
    t = np.linspace(0.0, 6.0, 6001)
    g = ol.gait_eq53(LEG, t)
    d = g.foot.q - ol.start_point(LEG)
    s = t - np.clip(np.floor(t), 0, 5)  # phase within the period (t = 6 s ends the last one)
    swing = ~g.stance
    H = 0.05
    z_printed = H * (-64 * s**6 + 192 * s**5 - 192 * s**4 + 64 * s**3)  # paper 2, eq. (53)
    np.testing.assert_allclose(-d[swing, 2], z_printed[swing], atol=1e-14)
    np.testing.assert_allclose(d[g.stance, 2], 0.0, atol=0)
    np.testing.assert_allclose(d[:, 0], 0.0, atol=0)  # L_h = 0
    q5 = 6 * s**5 - 15 * s**4 + 10 * s**3
    np.testing.assert_allclose(d[swing, 1], 0.1 * (q5[swing] - 0.5), atol=1e-14)
    np.testing.assert_allclose(d[g.stance, 1], -0.1 * (q5[g.stance] - 0.5), atol=1e-14)
    assert g.stance.sum() > 2500 and swing.sum() > 2500
    # continuous position and velocity across the phase changes
    dt = t[1] - t[0]
    assert np.abs(np.diff(g.foot.q, axis=0)).max() < 1e-3
    # central differences: error ~dt² jerk / 6 with jerk up to ~50 m/s³ (swing sextic)
    np.testing.assert_allclose(g.foot.qd[1:-1], (g.foot.q[2:] - g.foot.q[:-2]) / (2 * dt), atol=2e-5)
    assert ol.inverse_kinematics(LEG, g.foot.q).reachable.all()
