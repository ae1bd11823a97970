"""ICR kinematics, its identification, per-wheel slip."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomech.mechanisms.skid_steer import (
    ExplorationRobot,
    ICRModel,
    encoder_track_speeds,
    icr_velocity,
    identify_icr,
    skid_steer_turn,
    wheel_radii,
    wheel_slip,
)

ROBOT = ExplorationRobot.paper()
S = ROBOT.track_width
# Noise-free identification recovers the parameters to QR rounding on O(1) data.
EXACT_TOL = 1e-12


@settings(max_examples=60, deadline=None)
@given(st.floats(0.05, 1.0), st.floats(-1.0, -0.05), st.floats(-0.3, 0.3), st.floats(-1, 1), st.floats(-1, 1))
def test_icr_velocity_is_the_rigid_motion_that_zeroes_the_belt_velocity_at_the_icrs(yl, yr, xi, vr, vl):
    m = ICRModel(yl, yr, xi)
    v = icr_velocity(m, vr, vl)
    # ground velocity of the right belt at its ICR (x_icr, y_right): (v_x - r y - v_right, v_y + r x) = 0
    for y, vt in ((yr, vr), (yl, vl)):
        assert v.v_x - v.yaw_rate * y - vt == pytest.approx(0.0, abs=1e-12)
        assert v.v_y + v.yaw_rate * xi == pytest.approx(0.0, abs=1e-12)


def test_no_slip_model_is_the_differential_drive_formula():
    vr, vl = np.array([0.3, 0.2, -0.1]), np.array([0.1, 0.2, 0.1])
    v = icr_velocity(ICRModel.no_slip(S), vr, vl)
    turn = skid_steer_turn(vr, vl, S)
    np.testing.assert_allclose(v.yaw_rate, turn.yaw_rate, atol=1e-15)
    np.testing.assert_allclose(v.v_x, turn.forward_speed, atol=1e-15)
    assert ICRModel.no_slip(S).track_width_factor(S) == 1.0


def test_identification_recovers_the_parameters_and_flags_nan_samples():
    true = ICRModel(0.7, -0.8, 0.03)
    rng = np.random.default_rng(0)
    vr, vl = rng.uniform(-0.3, 0.3, (2, 200))
    v = icr_velocity(true, vr, vl)
    V = np.stack([v.v_x, v.v_y, v.yaw_rate], -1)
    V[5, 1] = np.nan
    vr[7] = np.nan
    ident = identify_icr(vr, vl, V)
    assert ident.identifiable
    assert ident.n_used == 198 and not ident.used[5] and not ident.used[7]
    for k in ("y_left", "y_right", "x_icr"):
        assert getattr(ident.model, k) == pytest.approx(getattr(true, k), abs=EXACT_TOL)
    assert np.all(ident.residual_rms < 1e-12)


def test_weighted_identification_downweights_a_corrupted_sample():
    true = ICRModel(0.6, -0.6, 0.0)
    vr, vl = np.linspace(0.0, 0.3, 50), np.linspace(0.3, 0.0, 50)
    v = icr_velocity(true, vr, vl)
    V = np.stack([v.v_x, v.v_y, v.yaw_rate], -1)
    V[10, 0] += 0.5  # one bad measurement
    w = np.ones(50)
    plain = identify_icr(vr, vl, V).model
    w[10] = 1e-8
    weighted = identify_icr(vr, vl, V, weights=w).model
    assert abs(weighted.y_left - 0.6) < 1e-6 < abs(plain.y_left - 0.6)


def test_straight_data_are_not_identifiable():
    v = np.full(20, 0.2)
    ident = identify_icr(v, v, np.stack([v, 0 * v, 0 * v], -1))
    assert not ident.identifiable and ident.model is None


@pytest.mark.parametrize(
    "args, match",
    [
        ((np.ones(5), np.ones(4), np.ones((5, 3))), "one N"),
        ((np.ones(5), np.ones(5), np.ones((5, 2))), "body_velocity"),
        ((np.ones((5, 1)), np.ones(5), np.ones((5, 3))), "v_right"),
    ],
)
def test_identification_rejects_inconsistent_histories(args, match):
    with pytest.raises(ValueError, match=match):
        identify_icr(*args)


def test_icr_model_rejects_bad_parameters():
    with pytest.raises(ValueError, match="y_left > y_right"):
        ICRModel(-0.2, 0.2)
    with pytest.raises(ValueError, match="x_icr"):
        ICRModel(0.2, -0.2, np.nan)
    with pytest.raises(ValueError, match="y_left"):
        ICRModel("0.2", -0.2)
    with pytest.raises(ValueError, match="model"):
        icr_velocity(None, 0.1, 0.1)


def test_encoder_track_speeds_and_slip_of_a_rolling_and_a_skidding_robot():
    radii = wheel_radii(ROBOT)
    assert radii.tolist() == [0.05, 0.05, 0.1, 0.05, 0.05, 0.1]
    # rolling straight at 0.2 m/s: zero slip everywhere
    rate = np.full(6, 0.2) / radii
    tr = encoder_track_speeds(ROBOT, rate)
    assert tr.right == pytest.approx(0.2) and tr.left == pytest.approx(0.2) and tr.valid
    drop = encoder_track_speeds(ROBOT, np.stack([rate, np.r_[np.nan, rate[1:]]]))
    assert drop.valid.tolist() == [True, False] and np.isnan(drop.right[1]) and np.isnan(drop.left[1])
    slip = wheel_slip(ROBOT, rate, [0.2, 0.0, 0.0])
    np.testing.assert_allclose(slip.ratio, 0.0, atol=1e-15)
    np.testing.assert_allclose(slip.lateral_velocity, 0.0, atol=1e-15)
    # skid turn: right rims at 0.3, left at 0.1 m/s, body turning at a third of the no-slip rate
    rate = np.r_[np.full(3, 0.3), np.full(3, 0.1)] / radii
    r = (0.3 - 0.1) / S / 3
    slip = wheel_slip(ROBOT, rate, [0.2, 0.0, r])
    ground_right = 0.2 + r * S / 2
    np.testing.assert_allclose(slip.ratio[:3], (0.3 - ground_right) / 0.3, rtol=1e-12)  # traction slip
    assert np.all(slip.ratio[3:] < 0)  # inner side skids (the rims are slower than the ground)
    x = np.array([0.2666, 0.1306, -0.3])  # contact x of the road wheels and the rear wheel (zero angles)
    np.testing.assert_allclose(slip.lateral_velocity[:3], r * x, atol=1e-5)
    # at rest: 0/0, flagged; NaN encoder: that wheel flagged
    rest = wheel_slip(ROBOT, [np.nan, 0, 0, 0, 0, 0.0], [0.0, 0.0, 0.0])
    assert not rest.valid.any() and np.isnan(rest.ratio).all()
    drop = wheel_slip(ROBOT, [np.nan, 4, 4, 4, 4, 2.0], [0.2, 0.0, 0.0])
    assert drop.valid.tolist() == [False, True, True, True, True, True]


def test_icr_velocity_flags_drop_outs():
    v = icr_velocity(ICRModel.no_slip(S), [0.1, np.nan, np.inf], [0.1, 0.1, 0.1])
    assert v.valid.tolist() == [True, False, False]
    assert np.isnan(v.yaw_rate[1:]).all() and np.isfinite(v.v_x[0])


@settings(max_examples=40, deadline=None)
@given(
    st.floats(0.2, 1.0),
    st.floats(-1.0, -0.2),
    st.floats(-0.2, 0.2),
    st.integers(0, 2**31 - 1),
)
def test_identification_round_trip_on_random_models(yl, yr, xi, seed):
    true = ICRModel(yl, yr, xi)
    rng = np.random.default_rng(seed)
    vr, vl = rng.uniform(-0.4, 0.4, (2, 50))
    v = icr_velocity(true, vr, vl)
    ident = identify_icr(vr, vl, np.stack([v.v_x, v.v_y, v.yaw_rate], -1))
    assert ident.identifiable
    for k in ("y_left", "y_right", "x_icr"):
        assert getattr(ident.model, k) == pytest.approx(getattr(true, k), abs=1e-9)


def test_zero_weights_are_unused_samples():
    import warnings

    rng = np.random.default_rng(7)
    true = ICRModel(y_left=0.3, y_right=-0.32, x_icr=0.02)
    r = rng.uniform(0.1, 0.5, 8) * rng.choice([-1, 1], 8)
    vx = rng.uniform(0.1, 0.5, 8)
    V = np.stack([vx, -r * true.x_icr, r], axis=-1)
    vr, vl = vx - r * true.y_right, vx - r * true.y_left
    w = np.array([1, 1, 1, 1, 1, 0, 0, 0], dtype=float)
    vr_bad = vr.copy()
    vr_bad[5:] += 10.0  # garbage where the weight is 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ident = identify_icr(vr_bad, vl, V, weights=w)
        none = identify_icr(vr, vl, V, weights=np.zeros(8))  # no warning from inside lstsq either
    assert ident.n_used == 5 and ident.used.tolist() == [True] * 5 + [False] * 3
    assert ident.identifiable and abs(ident.model.y_right - true.y_right) < 1e-12
    np.testing.assert_allclose(ident.residual_rms, 0.0, atol=1e-12)  # the garbage is not in the rms
    assert none.n_used == 0 and not none.identifiable and none.model is None
