"""Skid steering closed forms and dead reckoning."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomech.mechanisms.skid_steer import (
    ExplorationRobot,
    dead_reckoning,
    paper_lateral_slip,
    skid_steer_turn,
    wheel_lateral_velocity,
)
from robomech.spatial import exp_se3, rot_z

S = ExplorationRobot.paper().track_width


@settings(max_examples=80, deadline=None)
@given(st.floats(-2, 2), st.floats(-2, 2), st.floats(-3, 3))
def test_turning_quantities_reproduce_a_planar_rigid_motion(r, R, x_icr):
    """Build the track speeds from a rigid planar motion, then recover yaw rate and centre radius."""
    # Centre of rotation at (x_icr, R) in body axes; a contact on the track line y = ±S/2 moves forward
    # at r (R - y), whatever its x.
    v1 = r * (R + S / 2)  # right track, y = -S/2
    v2 = r * (R - S / 2)  # left track, y = +S/2
    turn = skid_steer_turn(v1, v2, S)
    assert turn.yaw_rate == pytest.approx(r, abs=1e-12)  # (v1 - v2)/S, not the printed 2 v_X / L
    assert turn.forward_speed == pytest.approx(r * R, abs=1e-12)  # speed of the body centre
    if abs(r) > 1e-6:
        assert turn.turning
        assert turn.radius == pytest.approx(R, abs=1e-9)  # radius of the body centre, not the inner wheel
    # lateral slip of a contact at x_w: y part of r z × (p - p_icr)
    xw = np.array([-0.3, 0.0, 0.25])
    np.testing.assert_allclose(wheel_lateral_velocity(r, xw, x_icr), r * (xw - x_icr), atol=1e-15)


def test_straight_and_spin_in_place():
    t = skid_steer_turn(np.array([0.3, 0.0, 0.2]), np.array([0.3, 0.0, -0.2]), S)
    assert t.turning.tolist() == [False, False, True]
    assert np.isinf(t.radius[:2]).all()
    assert t.radius[2] == 0.0
    assert t.yaw_rate[2] == pytest.approx(0.4 / S)


def test_paper_lateral_slip_is_the_outer_wheel_half_a_wheelbase_from_the_centre_of_rotation():
    # paper 4, Sec. 1.2: v_Y = v_X L/(2 R_s + S) with R_s the radius of the body centre.
    L, r, R = 0.5, 0.4, 0.9
    v_outer = r * (R + S / 2)  # right track when turning left
    lateral = wheel_lateral_velocity(r, -L / 2, 0.0)  # rear wheel, centre of rotation abeam the centre
    slip = paper_lateral_slip(v_outer, L, R, S)
    assert bool(slip.valid)
    assert abs(lateral) == pytest.approx(float(slip.lateral_speed), rel=1e-14)


def test_paper_lateral_slip_flags_its_singularity_instead_of_returning_inf():
    # issue 14: 2 R + S = 0 (centre of rotation on the inner track) used to return inf.
    slip = paper_lateral_slip([0.1, 0.1, 0.1], 0.5, [-S / 2, 0.9, -S / 2 * (1 + 1e-12)], S)
    assert slip.valid.tolist() == [False, True, False]
    assert np.isnan(slip.lateral_speed[~slip.valid]).all()
    assert np.isfinite(slip.lateral_speed[slip.valid]).all()
    with pytest.raises(ValueError, match="radius"):  # non-finite input: an error (the contract spec)
        paper_lateral_slip(0.1, 0.5, np.inf, S)


def test_skid_steer_rejects_bad_track_width():
    with pytest.raises(ValueError, match="track_width"):
        skid_steer_turn(0.1, 0.2, 0.0)
    with pytest.raises(ValueError, match="v_right"):
        skid_steer_turn(np.inf, 0.2, S)


def test_dead_reckoning_of_a_constant_twist_is_the_exponential():
    V = np.array([0.05, -0.1, 0.4, 0.3, 0.02, -0.01])
    n, dt = 2001, 0.01
    T0 = exp_se3(np.array([0.1, 0.2, 0.3, 1.0, 2.0, 0.5]))
    T = dead_reckoning(np.broadcast_to(V, (n, 6)), dt, T0)
    t = np.arange(n) * dt
    np.testing.assert_allclose(T, T0 @ exp_se3(t[:, None] * V), atol=1e-11)


def test_dead_reckoning_of_a_planar_circle():
    r, u = 0.3, 0.15
    n, dt = 4001, 0.005
    t = np.arange(n) * dt
    V = np.broadcast_to(np.array([0, 0, r, u, 0, 0.0]), (n, 6))
    T = dead_reckoning(V, dt)
    np.testing.assert_allclose(T[:, 0, 3], u / r * np.sin(r * t), atol=1e-11)
    np.testing.assert_allclose(T[:, 1, 3], u / r * (1 - np.cos(r * t)), atol=1e-11)
    np.testing.assert_allclose(T[:, :3, :3], rot_z(r * t), atol=1e-11)


def test_dead_reckoning_scan_equals_the_sequential_product():
    rng = np.random.default_rng(0)
    V = rng.normal(size=(2, 37, 6))
    dt = 0.02
    T = dead_reckoning(V, dt)
    for b in range(2):
        P = np.eye(4)
        for k in range(37):
            np.testing.assert_allclose(T[b, k], P, atol=1e-12)
            if k < 36:
                P = P @ exp_se3(0.5 * dt * (V[b, k] + V[b, k + 1]))


def test_dead_reckoning_is_second_order():
    # time-varying twist: the drift at the end must drop ~4x when dt halves
    def run(n):
        t = np.linspace(0.0, 2.0, n)
        V = np.stack([0.2 * np.sin(t), 0.1 * t, np.cos(t), 0.3 + 0 * t, 0.1 * t**2, 0 * t], -1)
        return dead_reckoning(V, t[1] - t[0])[-1]

    ref = run(64001)
    e1 = np.abs(run(501) - ref).max()
    e2 = np.abs(run(1001) - ref).max()
    assert 3.5 < e1 / e2 < 4.5


def test_dead_reckoning_rejects_bad_input():
    with pytest.raises(ValueError, match="twists"):
        dead_reckoning(np.zeros((10, 5)), 0.1)
    with pytest.raises(ValueError, match="dt"):
        dead_reckoning(np.zeros((10, 6)), -0.1)
