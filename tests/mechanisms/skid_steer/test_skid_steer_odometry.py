"""Sensor models, the planar EKF, and the weighted 30x11 estimate."""

from __future__ import annotations

import numpy as np
import pytest

from robomech.mechanisms.skid_steer import (
    I_ROCKER1,
    I_ROCKER2,
    I_ROLL,
    I_YAW,
    EncoderModel,
    ExplorationRobot,
    ICRModel,
    ImuModel,
    body_velocity,
    encoder_rates,
    icr_velocity,
    imu_measurements,
    planar_ekf,
    track_speed_sigma,
    wheel_measurements,
)

ROBOT = ExplorationRobot.paper()


def test_encoder_noise_is_the_stated_quantisation_noise_and_seeded():
    enc = EncoderModel(counts_per_rev=512)
    dt = 0.01
    # a varying rate, so that the count phase is well mixed (at a constant rate the quantisation error
    # cycles deterministically and the uniform-phase model does not apply sample by sample)
    t = np.arange(20001)[:, None] * dt
    w = np.linspace(1.0, 6.0, 6) + 0.7 * np.sin(np.linspace(0.3, 1.1, 6) * t)
    reading = encoder_rates(enc, w, dt, seed=3)
    m = reading.rate
    assert np.isnan(m[0]).all() and not reading.valid[0] and reading.valid[1:].all()  # no previous count
    err = m[1:] - w[1:]
    # pooled over rates the variance is the stated q²/(6 dt²); at one rate it is δ(1-δ) q²/dt² <= q²/(4 dt²)
    assert np.sqrt(np.mean(err**2)) == pytest.approx(enc.rate_sigma(dt), rel=0.05)
    assert np.all(err.std(axis=0) <= 2.0 * np.pi / 512 / (2 * dt) * 1.01)
    assert abs(err.mean()) < 0.05 * enc.rate_sigma(dt)
    np.testing.assert_array_equal(m, encoder_rates(enc, w, dt, seed=3).rate)
    assert not np.array_equal(m[1:], encoder_rates(enc, w, dt, seed=4).rate[1:])


def test_imu_noise_and_bias_are_as_stated():
    imu = ImuModel()
    dt = 0.01
    n = 40000
    w = np.zeros((n, 3))
    a = np.tile([0.0, 0.0, 9.81], (n, 1))
    g, acc = imu_measurements(imu, w, a, dt, seed=1)
    np.testing.assert_allclose(g.mean(0), imu.gyro_bias, atol=5 * imu.gyro_sigma(dt) / np.sqrt(n))
    np.testing.assert_allclose(g.std(0), imu.gyro_sigma(dt), rtol=0.03)
    np.testing.assert_allclose(acc.mean(0) - a[0], imu.accel_bias, atol=5 * imu.accel_sigma(dt) / np.sqrt(n))


def _circle(model: ICRModel, n=2001, dt=0.01, vr=0.3, vl=0.1):
    t = np.arange(n) * dt
    v = icr_velocity(model, np.full(n, vr), np.full(n, vl))
    psi = v.yaw_rate * t
    # exact ground track of a constant body twist (v_x, v_y, r)
    r = v.yaw_rate[0]
    x = (v.v_x[0] * np.sin(psi) + v.v_y[0] * (np.cos(psi) - 1)) / r
    y = (v.v_x[0] * (1 - np.cos(psi)) + v.v_y[0] * np.sin(psi)) / r
    return t, np.full(n, vr), np.full(n, vl), v, np.stack([x, y, psi], -1)


def test_ekf_tracks_a_circle_and_estimates_the_gyro_bias():
    model = ICRModel(0.6, -0.7, 0.02)
    t, vr, vl, v, pose = _circle(model)
    bias = 0.01
    rng = np.random.default_rng(0)
    gyro = v.yaw_rate + bias + 1e-3 * rng.normal(size=t.size)
    noisy_r = vr + 1e-3 * rng.normal(size=t.size)
    noisy_l = vl + 1e-3 * rng.normal(size=t.size)
    res = planar_ekf(t, noisy_r, noisy_l, gyro, model, sigma_track=1e-3, sigma_gyro=1e-3)
    assert res.encoder_used.all() and res.gyro_used.all()
    assert abs(res.state[-1, 5] - bias) < 2e-3  # the bias is observable through the encoders
    path = 20.0 * 0.01 * np.hypot(v.v_x[0], v.v_y[0]) * 100
    drift = np.hypot(*(res.state[-1, :2] - pose[-1, :2]))
    assert drift / path < 0.01  # < 1 cm per metre with the right model
    # the filter beats integrating the raw (biased) gyro heading
    assert abs(res.state[-1, 2] - pose[-1, 2]) < 0.2 * abs(bias * t[-1])


def test_ekf_flags_drop_outs_and_keeps_predicting():
    model = ICRModel(0.6, -0.7, 0.0)
    t, vr, vl, v, pose = _circle(model, n=501)
    vr = vr.copy()
    gyro = v.yaw_rate.copy()
    vr[100:110] = np.nan
    gyro[300] = np.nan
    with pytest.raises(ValueError, match="v_right"):  # unmarked NaN: an error, never skipped silently
        planar_ekf(t, vr, vl, gyro, model, sigma_track=1e-3, sigma_gyro=1e-3)
    enc_ok, gyro_ok = np.isfinite(vr), np.isfinite(gyro)
    res = planar_ekf(
        t, vr, vl, gyro, model, sigma_track=1e-3, sigma_gyro=1e-3, encoder_ok=enc_ok, gyro_ok=gyro_ok
    )
    assert (~res.encoder_used).sum() == 10 and not res.encoder_used[100:110].any()
    assert (~res.gyro_used).sum() == 1 and not res.gyro_used[300]
    assert np.all(np.isfinite(res.state)) and np.all(np.isfinite(res.covariance))
    assert np.hypot(*(res.state[-1, :2] - pose[-1, :2])) < 0.01


@pytest.mark.parametrize(
    "change, match",
    [
        ({"gyro_z": np.zeros(250)}, "one sample rate"),
        ({"t": np.r_[np.arange(250) * 0.01, np.arange(250) * 0.02 + 2.5]}, "uniformly sampled"),
        ({"t": np.r_[np.arange(499) * 0.01, 0.0]}, "strictly increasing"),
        ({"v_left": np.full(500, np.inf)}, "v_left"),
        ({"encoder_ok": np.ones(500)}, "encoder_ok"),
        ({"icr": None}, "icr"),
        ({"sigma_track": 0.0}, "sigma_track"),
    ],
)
def test_ekf_rejects_bad_histories(change, match):
    args = {
        "t": np.arange(500) * 0.01,
        "v_right": np.zeros(500),
        "v_left": np.zeros(500),
        "gyro_z": np.zeros(500),
        "icr": ICRModel(0.5, -0.5),
    }
    kw = {"sigma_track": 1e-3, "sigma_gyro": 1e-3}
    for k, v in change.items():
        (kw if k.startswith(("sigma", "encoder_ok")) else args)[k] = v
    with pytest.raises(ValueError, match=match):
        planar_ekf(*args.values(), **kw)


def test_track_speed_sigma_is_the_mean_of_independent_rims():
    enc = EncoderModel(1000)
    radii = np.array([0.05, 0.05, 0.1])
    assert track_speed_sigma(enc, radii, 0.01) == pytest.approx(
        enc.rate_sigma(0.01) * np.sqrt(0.05**2 + 0.05**2 + 0.1**2) / 3
    )


def test_weighted_30x11_beats_the_unweighted_one_with_unequal_noise():
    rng = np.random.default_rng(5)
    n = 4000
    q = rng.uniform(-0.2, 0.2, (n, 8))
    q[:, [3, 7]] += ROBOT.rear_wheel_drop
    V = rng.uniform(-0.3, 0.3, (n, 6))
    qd = rng.uniform(-0.3, 0.3, (n, 8))
    qd[:, 4] = -qd[:, 0]
    m = wheel_measurements(ROBOT, q, V, qd)
    sigma = np.full(22, 0.002)
    sigma[6:9] = sigma[15:18] = 0.05  # the rear wheels (large, slipping) are poor sensors
    sigma[[I_ROCKER1, I_ROCKER2, I_YAW, I_ROLL]] = 0.001
    noisy = m + rng.normal(size=m.shape) * sigma
    plain = body_velocity(ROBOT, q, noisy)
    weighted = body_velocity(ROBOT, q, noisy, measurement_sigma=sigma)
    e_plain = np.sqrt(np.mean((plain.twist - V) ** 2, axis=0))
    e_w = np.sqrt(np.mean((weighted.twist - V) ** 2, axis=0))
    assert np.all(e_w[[3, 4, 5]] < e_plain[[3, 4, 5]])  # the linear velocity improves
    assert e_w[3] < 0.7 * e_plain[3]
    # noise-free data: weighting does not move the exact solution
    exact = body_velocity(ROBOT, q[:50], m[:50], measurement_sigma=sigma)
    np.testing.assert_allclose(exact.twist, V[:50], atol=1e-9)
    with pytest.raises(ValueError, match="measurement_sigma"):
        body_velocity(ROBOT, q[:5], m[:5], measurement_sigma=np.zeros(22))


def test_ekf_adapts_the_track_icrs_online():
    """Synthetic data from an ICR model the filter is not told: varying turns, calibrated gyro.  Encoders
    and a gyro see the ICR spread y_left - y_right (the yaw-rate scale χ S); their mean trades with v_x."""
    true = ICRModel(0.7, -0.6, 0.0)
    start = ICRModel(0.45, -0.45, 0.0)  # no-slip guess
    n, dt = 3001, 0.01
    t = np.arange(n) * dt
    vr = 0.2 + 0.1 * np.sin(0.3 * t)
    vl = 0.2 - 0.1 * np.sin(0.3 * t + 1.0)
    v = icr_velocity(true, vr, vl)
    rng = np.random.default_rng(2)
    gyro = v.yaw_rate + 1e-3 * rng.normal(size=n)
    kw = {"sigma_track": 2e-3, "sigma_gyro": 1e-3, "initial_bias_sigma": 0.0, "bias_psd": 0.0}
    fixed = planar_ekf(t, vr + 2e-3 * rng.normal(size=n), vl, gyro, start, **kw)
    adapted = planar_ekf(
        t, vr + 2e-3 * rng.normal(size=n), vl, gyro, start, **kw, icr_sigma=0.3, icr_psd=1e-6
    )
    assert adapted.state[-1, 6] - adapted.state[-1, 7] == pytest.approx(1.3, abs=0.01)
    np.testing.assert_array_equal(
        fixed.state[:, 6:], np.broadcast_to([0.45, -0.45], (n, 2))
    )  # fixed: unchanged
