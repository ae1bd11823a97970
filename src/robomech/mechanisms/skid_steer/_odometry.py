"""Sensor models (wheel encoders, IMU) with stated, seeded noise, and an extended Kalman filter for planar
odometry from encoders and a gyro, with the ICR model as its measurement model.  The noise models:
``docs/mechanisms/skid_steer.md``, "Sensors and fusion"."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from robomech._validation import (
    as_array,
    check_int,
    check_params,
    check_positive,
    coerce_float_fields,
    coerce_int_fields,
)

from ._chains import N_WHEELS
from ._icr import ICRModel

__all__ = [
    "N_STATE",
    "SAMPLE_RATE_RTOL",
    "EKFResult",
    "EncoderModel",
    "EncoderReadings",
    "ImuModel",
    "encoder_rates",
    "imu_measurements",
    "planar_ekf",
    "track_speed_sigma",
]

# Relative spread of the sample intervals dt_k beyond which the histories do not share one sample rate
# (1e-6: far above the rounding of arange(n)/rate, far below any real jitter worth modelling).
SAMPLE_RATE_RTOL = 1e-6
# State of planar_ekf: [x, y, ψ, v_x, r, b_gyro, y_left, y_right].
N_STATE = 8


@dataclass(frozen=True)
class EncoderModel:
    """Incremental wheel encoder (quantisation only).

    Parameters
    ----------
    counts_per_rev : int, optional
        Encoder counts per wheel revolution (>= 1).
    """

    counts_per_rev: int = 2048

    def __post_init__(self) -> None:
        coerce_int_fields(self, ("counts_per_rev",), low=1)

    def rate_sigma(self, dt: float) -> float:
        """Standard deviation of the measured spin rate (rad/s) at sample interval ``dt`` (s), averaged
        over rates, ``q / (dt √6)``; the worst rate gives ``√1.5`` times this."""
        return 2.0 * math.pi / self.counts_per_rev / (check_positive(dt, "dt") * math.sqrt(6.0))


@dataclass(frozen=True)
class ImuModel:
    """Gyro and accelerometer: white noise (σ = density · √(rate)) and constant biases, SI units.
    Defaults: a MEMS IMU of the ADIS16470 class, biases as a start-up calibration leaves.

    Parameters
    ----------
    gyro_noise_density, accel_noise_density : float, optional
        White-noise densities (rad/s/√Hz, m/s²/√Hz; >= 0).
    gyro_bias, accel_bias : tuple of float, optional
        Constant biases per body axis (rad/s, m/s²).
    """

    gyro_noise_density: float = math.radians(0.008)  # rad/s/√Hz
    gyro_bias: tuple[float, float, float] = (0.0, 0.0, math.radians(0.1))  # rad/s
    accel_noise_density: float = 0.5e-3 * 9.80665  # m/s²/√Hz
    accel_bias: tuple[float, float, float] = (0.02, -0.01, 0.0)  # m/s²

    def __post_init__(self) -> None:
        coerce_float_fields(
            self, ("gyro_noise_density", "accel_noise_density"), positive=True, allow_zero=True
        )
        for name in ("gyro_bias", "accel_bias"):
            b = as_array(getattr(self, name), name, (3,))
            if b.ndim != 1:
                raise ValueError(f"Expected {name} to have shape (3,), got {b.shape}.")
            object.__setattr__(self, name, tuple(float(v) for v in b))

    def gyro_sigma(self, dt: float) -> float:
        return self.gyro_noise_density / math.sqrt(check_positive(dt, "dt"))

    def accel_sigma(self, dt: float) -> float:
        return self.accel_noise_density / math.sqrt(check_positive(dt, "dt"))


def _rng(seed: object) -> np.random.Generator:
    if isinstance(seed, np.random.Generator):
        return seed
    return np.random.default_rng(check_int(seed, "seed", low=0))


@dataclass(frozen=True)
class EncoderReadings:
    """Measured wheel spin rates from quantised encoder counts (from :func:`encoder_rates`).

    Attributes
    ----------
    rate : ndarray, shape (N, 6)
        Spin rate of each wheel (rad/s, ``WHEELS`` order); NaN exactly where ``valid`` is false.
    valid : ndarray of bool, shape (N,)
        False where there is no reading (the first sample: no previous count).
    """

    rate: np.ndarray
    valid: np.ndarray


def encoder_rates(
    model: EncoderModel, wheel_rate: ArrayLike, dt: float, seed: int | np.random.Generator = 0
) -> EncoderReadings:
    """Measured spin rates from true rates ``wheel_rate (N, 6)`` (rad/s) sampled every ``dt`` s:
    :class:`EncoderReadings`.  The trapezoidal angle from a random initial phase (``seed``: an int or a
    ``numpy.random.Generator``) is counted and differenced; the first sample has no reading.

    Returns
    -------
    EncoderReadings
    """
    check_params(model, EncoderModel, "model")
    w = as_array(wheel_rate, "wheel_rate", (None, N_WHEELS), min_ndim=2)
    if w.ndim != 2:
        raise ValueError(f"Expected wheel_rate to have shape (N, 6), got {w.shape}.")
    h = check_positive(dt, "dt")
    q = 2.0 * math.pi / model.counts_per_rev
    rng = _rng(seed)
    angle = np.concatenate([np.zeros((1, N_WHEELS)), np.cumsum(0.5 * h * (w[1:] + w[:-1]), axis=0)])
    angle += rng.uniform(0.0, q, size=N_WHEELS)
    counts = np.floor(angle / q)
    out = np.full(w.shape, np.nan)
    out[1:] = np.diff(counts, axis=0) * q / h
    valid = np.ones(w.shape[0], dtype=bool)
    valid[:1] = False  # (an empty history has no first sample)
    return EncoderReadings(rate=out, valid=valid)


def imu_measurements(
    model: ImuModel,
    angular_velocity: ArrayLike,
    specific_force: ArrayLike,
    dt: float,
    seed: int | np.random.Generator = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """Gyro (rad/s) and accelerometer (m/s²) readings ``(N, 3)`` each from the true body-axis
    ``angular_velocity`` and ``specific_force`` ``(N, 3)`` sampled every ``dt`` s (noise from ``seed``).

    Returns
    -------
    gyro, accel : ndarray, shape (N, 3)
    """
    check_params(model, ImuModel, "model")
    w = as_array(angular_velocity, "angular_velocity", (3,))
    a = as_array(specific_force, "specific_force", (3,))
    if w.shape != a.shape:
        raise ValueError(
            f"Expected angular_velocity and specific_force of one shape, got {w.shape}, {a.shape}."
        )
    rng = _rng(seed)
    gyro = w + np.asarray(model.gyro_bias) + model.gyro_sigma(dt) * rng.normal(size=w.shape)
    acc = a + np.asarray(model.accel_bias) + model.accel_sigma(dt) * rng.normal(size=a.shape)
    return gyro, acc


def track_speed_sigma(encoder: EncoderModel, radii: ArrayLike, dt: float) -> float:
    """Standard deviation (m/s) of a side's encoder track speed (the mean rim speed of its wheels of
    ``radii (k,)`` m, independent quantisation errors) at sample period ``dt`` (s).

    Returns
    -------
    float
    """
    check_params(encoder, EncoderModel, "encoder")
    r = as_array(radii, "radii", (None,))
    if r.ndim != 1 or r.size == 0 or np.any(r <= 0):
        raise ValueError(f"Expected radii a non-empty 1-d array of positive radii, got {r!r}.")
    return float(encoder.rate_sigma(dt) * np.sqrt(np.sum(r**2)) / r.size)


@dataclass(frozen=True)
class EKFResult:
    """Filtered planar odometry over ``N`` samples (from :func:`planar_ekf`).

    Attributes
    ----------
    state : ndarray, shape (N, 8)
        ``[x, y, ψ, v_x, r, b_gyro, y_left, y_right]`` (m, m, rad, m/s, rad/s, rad/s, m, m).
    covariance : ndarray, shape (N, 8, 8)
        Covariance of ``state`` (in the squared units of its entries).
    encoder_used, gyro_used : ndarray of bool, shape (N,)
        Whether that sample's measurement updated the filter (false at the marked drop-outs).
    """

    state: np.ndarray
    covariance: np.ndarray
    encoder_used: np.ndarray
    gyro_used: np.ndarray


def _check_times(t: ArrayLike) -> np.ndarray:
    ta = as_array(t, "t", (None,))
    if ta.ndim != 1 or ta.size < 2:
        raise ValueError(f"Expected t to have shape (N,) with N >= 2, got {ta.shape}.")
    dt = np.diff(ta)
    if np.any(dt <= 0):
        raise ValueError(
            f"Expected t strictly increasing, got {int(np.sum(dt <= 0))} non-increasing step(s)."
        )
    return ta


def planar_ekf(
    t: ArrayLike,
    v_right: ArrayLike,
    v_left: ArrayLike,
    gyro_z: ArrayLike,
    icr: ICRModel,
    *,
    sigma_track: float,
    sigma_gyro: float,
    sigma_model: float = 0.0,
    accel_psd: float = 0.5,
    yaw_accel_psd: float = 2.0,
    bias_psd: float = 1e-8,
    initial_pose: ArrayLike = (0.0, 0.0, 0.0),
    initial_bias_sigma: float = 0.01,
    icr_sigma: float = 0.0,
    icr_psd: float = 0.0,
    encoder_ok: ArrayLike | None = None,
    gyro_ok: ArrayLike | None = None,
) -> EKFResult:
    """Extended Kalman filter for planar odometry from encoders (ICR model) and a gyro: :class:`EKFResult`.

    State ``[x, y, ψ, v_x, r, b, y_left, y_right]`` (``N_STATE``); ``v_x``, ``r``, ``b`` and (with
    ``icr_sigma > 0``) the track ICRs are random walks; measurements ``v_right = v_x - r y_right``,
    ``v_left = v_x - r y_left``, gyro ``r + b`` (``docs/mechanisms/skid_steer.md``, "Sensors and fusion").
    Only the ICRs' spread is observable; adapting them needs a calibrated gyro bias.  All histories
    ``(N,)`` share the uniform time stamps ``t``; drop-outs are marked in ``encoder_ok`` / ``gyro_ok``
    (a non-finite value elsewhere raises) and reported in ``encoder_used`` / ``gyro_used``.

    Parameters
    ----------
    t, v_right, v_left, gyro_z : array_like, shape (N,)
        Uniform sample times (s), encoder track speeds (m/s), gyro yaw-rate readings (rad/s).
    icr : ICRModel
    sigma_track, sigma_gyro : float
        Measurement noise of a track speed (m/s) and of the gyro (rad/s).
    sigma_model : float, optional
        Extra per-side model noise (m/s).
    accel_psd, yaw_accel_psd, bias_psd : float, optional
        Random-walk spectral densities (m²/s³, rad²/s³, rad²/s³).
    initial_pose : array_like, shape (3,), optional
        ``(x, y, ψ)`` at ``t[0]`` (m, m, rad).
    initial_bias_sigma : float, optional
        Initial 1σ of the gyro bias (rad/s).
    icr_sigma, icr_psd : float, optional
        Initial 1σ (m) and random-walk density (m²/s) of the track ICRs (0: fixed).
    encoder_ok, gyro_ok : array_like of bool, shape (N,), optional
        Samples with a reading (default all).
    """
    ta = _check_times(t)
    n = ta.size
    dts = np.diff(ta)
    if np.max(np.abs(dts - dts.mean())) > SAMPLE_RATE_RTOL * dts.mean():
        raise ValueError(
            "Expected t uniformly sampled (one sample rate for all histories), got steps from "
            f"{dts.min():.6g} s to {dts.max():.6g} s."
        )
    oks = {}
    for a, name in ((encoder_ok, "encoder_ok"), (gyro_ok, "gyro_ok")):
        if a is None:
            oks[name] = np.ones(n, dtype=bool)
            continue
        arr = np.asarray(a)
        if arr.dtype != bool or arr.shape != (n,):
            raise ValueError(
                f"Expected {name} a bool array of shape ({n},) (one flag per sample of t), "
                f"got {arr.dtype} {arr.shape}."
            )
        oks[name] = arr
    hist = {}
    for a, name, ok in (
        (v_right, "v_right", oks["encoder_ok"]),
        (v_left, "v_left", oks["encoder_ok"]),
        (gyro_z, "gyro_z", oks["gyro_ok"]),
    ):
        arr = as_array(a, name, finite="mask")  # beyond MAX_MAGNITUDE counts as non-finite
        if arr.shape != (n,):
            raise ValueError(
                f"Expected {name} to have shape ({n},) like t (one sample rate for all histories), "
                f"got {arr.shape}."
            )
        bad = ok & ~np.isfinite(arr)
        if np.any(bad):
            raise ValueError(
                f"Expected {name} finite where it is marked as read, got {int(bad.sum())} non-finite "
                "value(s); mark drop-outs in encoder_ok / gyro_ok."
            )
        hist[name] = arr
    check_params(icr, ICRModel, "icr")
    s_tr = check_positive(sigma_track, "sigma_track")
    s_g = check_positive(sigma_gyro, "sigma_gyro")
    s_m = check_positive(sigma_model, "sigma_model", allow_zero=True)
    qa = check_positive(accel_psd, "accel_psd")
    qr = check_positive(yaw_accel_psd, "yaw_accel_psd")
    qb = check_positive(bias_psd, "bias_psd", allow_zero=True)
    pose0 = as_array(initial_pose, "initial_pose", (3,))
    if pose0.shape != (3,):
        raise ValueError(f"Expected initial_pose to have shape (3,), got {pose0.shape}.")
    sb0 = check_positive(initial_bias_sigma, "initial_bias_sigma", allow_zero=True)
    s_icr = check_positive(icr_sigma, "icr_sigma", allow_zero=True)
    q_icr = check_positive(icr_psd, "icr_psd", allow_zero=True)

    xi = icr.x_icr
    H_g = np.array([[0, 0, 0, 0, 1.0, 1.0, 0, 0]])
    R_g = np.array([[s_g**2]])
    R_enc = np.eye(2) * (s_tr**2 + s_m**2)
    s = np.zeros(N_STATE)
    s[:3] = pose0
    s[6], s[7] = icr.y_left, icr.y_right
    P = np.diag([0.0, 0.0, 0.0, 1.0, 1.0, sb0**2, s_icr**2, s_icr**2])
    states = np.empty((n, N_STATE))
    covs = np.empty((n, N_STATE, N_STATE))
    enc_used = np.zeros(n, dtype=bool)
    gyro_used = np.zeros(n, dtype=bool)
    eye = np.eye(N_STATE)

    def update(s, P, z, h, H, R):
        S = H @ P @ H.T + R
        K = np.linalg.solve(S, H @ P).T
        s = s + K @ (z - h)
        IKH = eye - K @ H
        return s, IKH @ P @ IKH.T + K @ R @ K.T  # Joseph form: stays symmetric positive semi-definite

    for k in range(n):
        if k > 0:
            h = dts[k - 1]
            psi, v, r = s[2], s[3], s[4]
            c, sn = math.cos(psi), math.sin(psi)
            vy = -r * xi
            s = s.copy()
            s[:3] += h * np.array([v * c - vy * sn, v * sn + vy * c, r])
            F = eye.copy()
            F[0, 2] = -h * (v * sn + vy * c)
            F[0, 3] = h * c
            F[0, 4] = h * xi * sn
            F[1, 2] = h * (v * c - vy * sn)
            F[1, 3] = h * sn
            F[1, 4] = -h * xi * c
            F[2, 4] = h
            Q = np.diag([0.0, 0.0, 0.0, qa * h, qr * h, qb * h, q_icr * h, q_icr * h])
            P = F @ P @ F.T + Q
        if oks["encoder_ok"][k]:
            v, r, yl, yr = s[3], s[4], s[6], s[7]
            # v_right = v_x - r y_right, v_left = v_x - r y_left (bilinear when the ICRs are estimated)
            H = np.zeros((2, N_STATE))
            H[:, 3] = 1.0
            H[0, 4], H[0, 7] = -yr, -r
            H[1, 4], H[1, 6] = -yl, -r
            z = np.array([hist["v_right"][k], hist["v_left"][k]])
            s, P = update(s, P, z, np.array([v - r * yr, v - r * yl]), H, R_enc)
            enc_used[k] = True
        if oks["gyro_ok"][k]:
            s, P = update(s, P, np.array([hist["gyro_z"][k]]), H_g @ s, H_g, R_g)
            gyro_used[k] = True
        states[k] = s
        covs[k] = P
    return EKFResult(state=states, covariance=covs, encoder_used=enc_used, gyro_used=gyro_used)
