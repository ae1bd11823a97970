"""Skid-steer robot (paper 4) workloads for issue 9.

1. The estimator end to end: ``body_velocity`` (assembly of the 30×11 / 30×22 systems + batched
   Householder QR through ``lstsq.solve``) over 250,000 samples, each system different, against the
   per-sample Python loop of the same function.  (The generic ``lstsq.solve`` vs a loop of
   ``numpy.linalg.lstsq`` is the lead's workload.)
2. Forward kinematics (the six contact frames) and the wheel Jacobians over 10^6 configurations, and
   the assembly alone over 250,000, against per-sample loops.
Also the dead reckoning of 250,000 twists (prefix scan) against the sequential product, and the issue-17
pieces: ICR velocities from 10^6 encoder samples, the ICR identification of 10^5 samples, the planar EKF
(sequential by nature: µs per step) and the MuJoCo ground truth (1 s of simulated time).
"""

from __future__ import annotations

from functools import cache

import numpy as np

import robomech.mechanisms.skid_steer as ss
from robomech.spatial import exp_se3

from _harness import Workload

N_EST = 250_000  # paper 4, Sec. 2.2
N_KIN = 1_000_000
N_ALT = 1000
N_ENC = 1_000_000
N_IDENT = 100_000
N_EKF = 10_000
ROBOT = ss.ExplorationRobot.paper()
F8 = 8


@cache
def _data(n: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(0)
    q = rng.uniform(-0.25, 0.25, size=(n, 8))
    q[:, [3, 7]] += ROBOT.rear_wheel_drop
    V = rng.uniform(-0.3, 0.3, size=(n, 6))
    qd = rng.uniform(-0.3, 0.3, size=(n, 8))
    qd[:, 4] = -qd[:, 0]
    m = ss.wheel_measurements(ROBOT, q, V, qd) + rng.normal(scale=0.005, size=(n, 22))
    return q, m


def _loop(fn, *arrays, n=N_ALT, **kw):
    return [fn(ROBOT, *(a[i] for a in arrays), **kw) for i in range(n)]


def _sequential_dead_reckoning(V: np.ndarray, dt: float) -> np.ndarray:
    T = np.eye(4)
    out = [T]
    for k in range(V.shape[0] - 1):
        T = T @ exp_se3(0.5 * dt * (V[k] + V[k + 1]))
        out.append(T)
    return np.stack(out)


@cache
def _encoder_data(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(2)
    rates = rng.uniform(0.0, 6.0, size=(n, 6))
    tr = ss.encoder_track_speeds(ROBOT, rates)
    model = ss.ICRModel(0.75, -0.62, -0.04)
    v = ss.icr_velocity(model, tr.right, tr.left)
    V = np.stack([v.v_x, v.v_y, v.yaw_rate], -1) + rng.normal(scale=0.005, size=(n, 3))
    return rates, tr.right, tr.left, V


def _icr_loop(rates: np.ndarray, model: ss.ICRModel) -> list:
    out = []
    for k in range(rates.shape[0]):
        tr = ss.encoder_track_speeds(ROBOT, rates[k])
        out.append(ss.icr_velocity(model, tr.right, tr.left))
    return out


def _ekf() -> object:
    t = np.arange(N_EKF) * 0.01
    vr, vl = 0.2 + 0.05 * np.sin(t), 0.1 + 0.05 * np.cos(t)
    model = ss.ICRModel(0.75, -0.62, -0.04)
    gyro = ss.icr_velocity(model, vr, vl).yaw_rate
    kw = {"sigma_track": 5e-3, "sigma_gyro": 1.4e-3, "icr_sigma": 0.3, "icr_psd": 1e-3}
    return ss.planar_ekf(t, vr, vl, gyro, model, **kw)


def _engine() -> object:
    from robomech.verify.skid_steer import simulate_engine

    return simulate_engine(ROBOT, (0.25, 0.05), 1.0, rate=100.0, settle=0.0, ramp=0.0)


def workloads() -> list[Workload]:
    # body_velocity: inputs config (8) + measured (22); outputs twist (6), config_rate (8), unknowns (11),
    # residual, cond (float64) and valid (bool).
    est_bytes = N_EST * ((8 + 22 + 6 + 8 + 11 + 2) * F8 + 1)
    q_est = lambda: _data(N_EST)[0]  # noqa: E731
    m_est = lambda: _data(N_EST)[1]  # noqa: E731
    q_kin = lambda: _data(N_KIN)[0]  # noqa: E731
    V = np.random.default_rng(1).normal(size=(N_EST, 6)) * 0.2
    return [
        Workload(
            name="skid_steer: body_velocity 30x11 QR (250k)", group="1",
            run=lambda: ss.body_velocity(ROBOT, q_est(), m_est()), n=N_EST, bytes_moved=est_bytes,
            alternative=lambda: _loop(ss.body_velocity, q_est(), m_est()), n_alt=N_ALT,
            alternative_name="per-sample loop, same fn", target_speedup=20.0,
        ),
        Workload(
            name="skid_steer: body_velocity QR + exact cond (250k)", group="1",
            run=lambda: ss.body_velocity(ROBOT, q_est(), m_est(), exact_cond=True), n=N_EST,
            bytes_moved=est_bytes,
            alternative=lambda: _loop(ss.body_velocity, q_est(), m_est(), exact_cond=True), n_alt=N_ALT,
            alternative_name="per-sample loop, same fn",
        ),
        Workload(
            name="skid_steer: body_velocity normal eqs (250k)", group="1",
            run=lambda: ss.body_velocity(ROBOT, q_est(), m_est(), solver="normal_equations"), n=N_EST,
            bytes_moved=est_bytes,
            alternative=lambda: _loop(ss.body_velocity, q_est(), m_est(), solver="normal_equations"),
            n_alt=N_ALT, alternative_name="per-sample loop, same fn",
        ),
        Workload(
            name="skid_steer: assemble A0, J (250k)", group="2",
            run=lambda: ss.assemble(ROBOT, q_est()), n=N_EST,
            bytes_moved=N_EST * (8 + 30 * 11 + 30 * 22) * F8,
            alternative=lambda: _loop(ss.assemble, q_est()), n_alt=N_ALT,
            alternative_name="per-sample Python loop", target_speedup=100.0, target_floor_ratio=20.0,
        ),
        Workload(
            name="skid_steer: contact frames FK (1e6)", group="2",
            run=lambda: ss.contact_frames(ROBOT, q_kin()), n=N_KIN, bytes_moved=N_KIN * (8 + 6 * 16) * F8,
            alternative=lambda: _loop(ss.contact_frames, q_kin()), n_alt=N_ALT,
            alternative_name="per-sample Python loop", target_speedup=100.0, target_floor_ratio=20.0,
            repeats=2,
        ),
        Workload(
            name="skid_steer: wheel Jacobians (1e6)", group="2",
            run=lambda: ss.wheel_jacobians(ROBOT, q_kin()), n=N_KIN, bytes_moved=N_KIN * (8 + 6 * 24) * F8,
            alternative=lambda: _loop(ss.wheel_jacobians, q_kin()), n_alt=N_ALT,
            alternative_name="per-sample Python loop", target_speedup=100.0, target_floor_ratio=20.0,
            repeats=2,
        ),
        Workload(
            name="skid_steer: dead reckoning (250k)", group="-",
            run=lambda: ss.dead_reckoning(V, 2e-4), n=N_EST, bytes_moved=N_EST * (6 + 16) * F8,
            alternative=lambda: _sequential_dead_reckoning(V[:N_ALT], 2e-4), n_alt=N_ALT,
            alternative_name="sequential product loop",
        ),
        Workload(
            name="skid_steer: encoders -> ICR velocity (1e6)", group="-",
            run=lambda: ss.icr_velocity(
                ss.ICRModel(0.75, -0.62, -0.04), *(lambda tr: (tr.right, tr.left))(
                    ss.encoder_track_speeds(ROBOT, _encoder_data(N_ENC)[0]))),
            n=N_ENC, bytes_moved=N_ENC * (6 + 2 + 3) * F8,
            alternative=lambda: _icr_loop(_encoder_data(N_ENC)[0][:N_ALT], ss.ICRModel(0.75, -0.62, -0.04)),
            n_alt=N_ALT, alternative_name="per-sample Python loop",
        ),
        Workload(
            name="skid_steer: identify_icr (1e5 samples)", group="-",
            run=lambda: ss.identify_icr(*_encoder_data(N_IDENT)[1:]), n=N_IDENT,
            bytes_moved=N_IDENT * (2 + 3) * F8,
        ),
        Workload(
            name="skid_steer: planar EKF, adaptive ICR (1e4 steps)", group="-",
            run=_ekf, n=N_EKF, bytes_moved=N_EKF * (4 + 8 + 64) * F8, repeats=1,
        ),
        Workload(
            name="skid_steer: MuJoCo engine, 1 s simulated (1000 steps)", group="-",
            run=_engine, n=1000, bytes_moved=100 * 200 * F8, repeats=1,
        ),
    ]  # fmt: skip
