"""Paper 4 on contact physics: no-slip kinematics, the ICR model, the EKF and the 30×11 estimate against
MuJoCo's body motion.  Used by ``studies/skid_steer.py``; kept apart so it can be tested with
short runs.

Every manoeuvre is an engine run of ``robomech.verify.skid_steer.simulate_engine`` (six rolling wheels
with Coulomb friction, velocity-controlled); the estimators see only simulated sensors: quantised
encoders, a gyro with bias and white noise, and — for the paper's 30×11 system only — the velocities
of the carrier-fixed contact frames with white noise (which no real robot measures: that is the
paper's assumption, kept here for comparison).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robomech.mechanisms import skid_steer as ss
from robomech.verify.skid_steer import (
    IDENTIFICATION_RUNS,
    EngineRun,
    Terrain,
    planar_twist,
    simulate_engine,
)

from ._core import Figure, Progress, Table
from ._plot import plt, save_figure

__all__ = ["MANOEUVRES", "Comparison", "compare", "figures", "tables"]

# (name, (right, left) commanded track speeds in m/s, terrain)
MANOEUVRES = (
    ("straight, flat", (0.20, 0.20), "flat"),
    ("gentle turn, flat", (0.25, 0.15), "flat"),
    ("turn, flat", (0.25, 0.05), "flat"),
    ("tight turn, flat", (0.20, -0.05), "flat"),
    ("spin in place, flat", (0.15, -0.15), "flat"),
    ("straight, uneven", (0.20, 0.20), "uneven"),
    ("turn, uneven", (0.25, 0.10), "uneven"),
)
ESTIMATORS = (
    "no-slip (encoders)",
    "ICR model (encoders)",
    "ICR speed + gyro heading",
    "EKF, fixed ICR, bias estimated",
    "EKF, ICR adapted online",
    "30×11 OLS (contact velocities)",
    "30×11 WLS (contact velocities)",
)
# Below this mean yaw rate (rad/s) a manoeuvre counts as straight (the uneven straight run yaws ~1e-3).
TURNING_YAW_RATE = 0.01
RATE = 100.0  # Hz: encoder and IMU sample rate
ENCODER = ss.EncoderModel(counts_per_rev=2048)
IMU = ss.ImuModel()
# 1σ of the paper's contact-velocity "measurements" (m/s) and of the rocker pitch rates (rad/s), as in
# the kinematic part of this study.
SIGMA_CONTACT = 0.005
SIGMA_ROCKER = 0.002
# 1σ of the reference body twist used for identification (m/s, m/s, rad/s): e.g. motion capture.
SIGMA_REFERENCE = (0.005, 0.005, 0.002)
# Online ICR adaptation in the EKF: initial 1σ (m) and random-walk density (m²/s) of the track ICRs.
ICR_SIGMA = 0.3
ICR_PSD = 1e-3
IDENTIFICATION_S = 6.0  # s per identification manoeuvre
TRANSIENT_S = 1.0  # s discarded at the start of each identification run (commands ramp in)


@dataclass
class Comparison:
    """Everything the tables and figures need (plain arrays and numbers)."""

    icr: ss.ICRModel
    identification: ss.ICRIdentification
    chi: float
    sigma_track: float
    rows: list[dict] = field(default_factory=list)
    wls: list[list] = field(default_factory=list)


def _planar_T(T: np.ndarray) -> np.ndarray:
    """The planar part of poses ``(..., 4, 4)``: position x, y and heading, z = 0, level."""
    psi = np.arctan2(T[..., 1, 0], T[..., 0, 0])
    out = np.zeros(T.shape)
    c, s = np.cos(psi), np.sin(psi)
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1] = c, -s, s, c
    out[..., 2, 2] = out[..., 3, 3] = 1.0
    out[..., 0, 3], out[..., 1, 3] = T[..., 0, 3], T[..., 1, 3]
    return out


def _planar_dr(v: ss.PlanarVelocity | tuple, yaw: np.ndarray, T0: np.ndarray) -> np.ndarray:
    vx, vy = (v.v_x, v.v_y) if isinstance(v, ss.PlanarVelocity) else v
    tw = np.zeros((vx.size, 6))
    tw[:, 2], tw[:, 3], tw[:, 4] = yaw, vx, vy
    return ss.dead_reckoning(tw, 1.0 / RATE, T0)[:, :2, 3]


def _sensors(robot: ss.ExplorationRobot, run: EngineRun, seed: int):
    enc = ss.encoder_rates(ENCODER, run.wheel_rate, 1.0 / RATE, seed)
    gyro, _ = ss.imu_measurements(IMU, run.gyro, run.accel, 1.0 / RATE, seed + 1)
    return ss.encoder_track_speeds(robot, enc.rate), gyro


def _sigma_measured() -> np.ndarray:
    sig = np.full(ss.MEASURED_SIZE, SIGMA_CONTACT)
    sig[[ss.I_ROCKER1, ss.I_ROCKER2]] = SIGMA_ROCKER
    sig[[ss.I_YAW, ss.I_ROLL]] = IMU.gyro_sigma(1.0 / RATE)
    return sig


def identify(robot: ss.ExplorationRobot, progress: Progress, duration: float = IDENTIFICATION_S):
    """ICR model from the verification's identification manoeuvres (encoders + a noisy reference twist)."""
    rng = np.random.default_rng(2005)
    parts = []
    for k, v in enumerate(progress.iter(IDENTIFICATION_RUNS, "identification run")):
        run = simulate_engine(robot, v, duration, rate=RATE)
        tr, _ = _sensors(robot, run, 10 * k)
        ref = planar_twist(run) + rng.normal(size=(run.t.size, 3)) * np.asarray(SIGMA_REFERENCE)
        keep = run.t >= TRANSIENT_S
        parts.append((tr.right[keep], tr.left[keep], ref[keep]))
    vr, vl, V = (np.concatenate(x) for x in zip(*parts, strict=True))
    ident = ss.identify_icr(vr, vl, V)
    if not ident.identifiable:
        raise RuntimeError("the identification manoeuvres carry no turning")
    return ident


def compare(
    robot: ss.ExplorationRobot,
    progress: Progress,
    duration: float = 15.0,
    identification_s: float = IDENTIFICATION_S,
    manoeuvres: tuple = MANOEUVRES,
) -> Comparison:
    """Run the ``manoeuvres`` and every estimator; ``duration`` s per manoeuvre at ``RATE`` Hz."""
    progress.step(
        f"ICR identification: {len(IDENTIFICATION_RUNS)} flat manoeuvres of {identification_s:.0f} s"
    )
    ident = identify(robot, progress, identification_s)
    icr = ident.model
    dt = 1.0 / RATE
    sigma_track = ss.track_speed_sigma(ENCODER, ss.wheel_radii(robot)[:3], dt)
    sigma_model = float(np.mean(ident.residual_rms[:2]))
    comp = Comparison(icr, ident, icr.track_width_factor(robot.track_width), sigma_track)
    rng = np.random.default_rng(17)
    sig = _sigma_measured()
    no_slip = ss.ICRModel.no_slip(robot.track_width)
    for k, (name, speeds, ground) in enumerate(progress.iter(manoeuvres, "manoeuvre")):
        terrain = Terrain.uneven() if ground == "uneven" else None
        run = simulate_engine(robot, speeds, duration, rate=RATE, terrain=terrain)
        tr, gyro = _sensors(robot, run, 100 + 10 * k)
        k0 = int(np.argmax(tr.valid))  # the first encoder reading (sample 0 has no previous count)
        sl = slice(k0, None)
        truth = run.T_GB[sl, :2, 3]
        path = float(np.sum(np.linalg.norm(np.diff(truth, axis=0), axis=1)))
        T0 = _planar_T(run.T_GB[k0])
        yaw_true = run.twist[sl, 2]
        est_yaw, est_xy = {}, {}
        ns = ss.icr_velocity(no_slip, tr.right[sl], tr.left[sl])
        est_yaw[ESTIMATORS[0]], est_xy[ESTIMATORS[0]] = ns.yaw_rate, _planar_dr(ns, ns.yaw_rate, T0)
        ic = ss.icr_velocity(icr, tr.right[sl], tr.left[sl])
        est_yaw[ESTIMATORS[1]], est_xy[ESTIMATORS[1]] = ic.yaw_rate, _planar_dr(ic, ic.yaw_rate, T0)
        est_yaw[ESTIMATORS[2]], est_xy[ESTIMATORS[2]] = gyro[sl, 2], _planar_dr(ic, gyro[sl, 2], T0)
        psi0 = float(np.arctan2(T0[1, 0], T0[0, 0]))
        common = {
            "sigma_track": sigma_track,
            "sigma_gyro": IMU.gyro_sigma(dt),
            "sigma_model": sigma_model,
            "initial_pose": [T0[0, 3], T0[1, 3], psi0],
            "encoder_ok": tr.valid[sl],
        }
        hist = (run.t[sl], tr.right[sl], tr.left[sl], gyro[sl, 2], icr)
        # fixed ICR model, gyro bias estimated (it can only be seen through the encoders' yaw rate)
        ekf = ss.planar_ekf(*hist, **common)
        est_yaw[ESTIMATORS[3]], est_xy[ESTIMATORS[3]] = ekf.state[:, 4], ekf.state[:, :2]
        # ICRs adapted online; the bias is then not estimated (taken as zero after a start-up
        # calibration: the true residual bias ImuModel.gyro_bias stays in the data)
        ekf = ss.planar_ekf(
            *hist, **common, initial_bias_sigma=0.0, bias_psd=0.0, icr_sigma=ICR_SIGMA, icr_psd=ICR_PSD
        )
        est_yaw[ESTIMATORS[4]], est_xy[ESTIMATORS[4]] = ekf.state[:, 4], ekf.state[:, :2]
        meas = run.measured + rng.normal(size=run.measured.shape) * sig
        meas[:, ss.I_YAW], meas[:, ss.I_ROLL] = gyro[:, 2], gyro[:, 0]  # the same gyro as the EKF
        for j, weights in ((5, None), (6, sig)):
            bv = ss.body_velocity(robot, run.config, meas, measurement_sigma=weights)
            est_yaw[ESTIMATORS[j]] = bv.twist[sl, 2]
            est_xy[ESTIMATORS[j]] = ss.dead_reckoning(bv.twist[sl], dt, run.T_GB[k0])[:, :2, 3]
        v_mean = float(np.mean(run.twist[sl, 3]))
        r_mean = float(np.mean(yaw_true))
        own = ss.identify_icr(tr.right[sl], tr.left[sl], planar_twist(run)[sl])
        comp.rows.append(
            {
                "name": name,
                "speeds": speeds,
                "terrain": ground,
                "path_m": path,
                "yaw_rate": r_mean,
                "radius_m": v_mean / r_mean if abs(r_mean) > TURNING_YAW_RATE else float("inf"),
                "contact": run.in_contact.mean(axis=0),
                "on_terrain": bool(run.on_terrain.all()),
                "chi_own": own.model.track_width_factor(robot.track_width)
                if own.identifiable and own.model is not None
                else float("nan"),
                "yaw_rms": {e: float(np.sqrt(np.mean((y - yaw_true) ** 2))) for e, y in est_yaw.items()},
                "drift_per_m": {
                    e: float(np.linalg.norm(p[-1] - truth[-1]) / path) for e, p in est_xy.items()
                },
                "max_error_per_m": {
                    e: float(np.max(np.linalg.norm(p - truth, axis=1)) / path) for e, p in est_xy.items()
                },
                "t": run.t[sl],
                "truth_xy": truth,
                "est_xy": est_xy,
                "yaw_true": yaw_true,
                "est_yaw": est_yaw,
                "slip": ss.wheel_slip(robot, run.wheel_rate[sl], planar_twist(run)[sl], run.config[sl]),
            }
        )
        if name in ("turn, flat", "turn, uneven"):
            comp.wls += _wls_rows(robot, run, name, rng)
    return comp


def _wls_rows(robot: ss.ExplorationRobot, run: EngineRun, name: str, rng: np.random.Generator) -> list[list]:
    """30×11 by ordinary vs weighted least squares for equal and for unequal sensor noise."""
    rows = []
    for label, scale_rear in (("equal noise", 1.0), ("rear-wheel contacts 5× noisier", 5.0)):
        sig = _sigma_measured()
        sig[6:9] *= scale_rear  # right rear wheel (WHEELS order), x/y/z
        sig[15:18] *= scale_rear  # left rear wheel
        meas = run.measured + rng.normal(size=run.measured.shape) * sig
        out: list[object] = [name, label]
        for weights in (None, sig):
            bv = ss.body_velocity(robot, run.config, meas, measurement_sigma=weights)
            e = bv.twist - run.twist
            out += [
                float(np.sqrt(np.mean(e[:, 2] ** 2))),
                float(np.sqrt(np.mean(np.sum(e[:, 3:] ** 2, axis=1)))),
            ]
        rows.append(out)
    return rows


def tables(comp: Comparison, robot: ss.ExplorationRobot) -> list[Table]:
    m = comp.icr
    ident = comp.identification
    out = [
        Table(
            "MuJoCo ground truth: identified ICR model and sensors",
            ["quantity", "value", "unit"],
            [
                ["y_left (left-track ICR)", m.y_left, "m"],
                ["y_right (right-track ICR)", m.y_right, "m"],
                ["x_icr (longitudinal ICR)", m.x_icr, "m"],
                ["χ = (y_left − y_right)/S", comp.chi, "—"],
                [
                    "residual RMS (right, left, lateral)",
                    ", ".join(f"{v:.4f}" for v in ident.residual_rms),
                    "m/s",
                ],
                ["samples used", ident.n_used, "—"],
                ["encoder", f"{ENCODER.counts_per_rev} counts/rev at {RATE:.0f} Hz", "—"],
                ["track-speed noise from quantisation (1σ)", comp.sigma_track, "m/s"],
                [
                    "gyro noise (1σ at the sample rate) / bias z",
                    f"{IMU.gyro_sigma(1 / RATE):.2e} / {IMU.gyro_bias[2]:.2e}",
                    "rad/s",
                ],
                ["contact-velocity noise for the 30×11 system (1σ)", SIGMA_CONTACT, "m/s"],
            ],
            note="Identified by linear least squares (analysis.lstsq) from the encoder track speeds and a "
            f"reference body twist with noise {SIGMA_REFERENCE} (m/s, m/s, rad/s) over the "
            f"{len(IDENTIFICATION_RUNS)} flat manoeuvres of robomech verify skid-steer. χ is a property "
            "of MuJoCo's soft Coulomb contact at μ = 0.6, not of terrain (docs/mechanisms/skid_steer.md).",
        )
    ]
    rows = []
    for r in comp.rows:
        rows.append(
            [
                r["name"],
                f"{r['speeds'][0]:.2f} / {r['speeds'][1]:.2f}",
                r["path_m"],
                r["yaw_rate"],
                r["radius_m"],
                r["chi_own"],
                float(np.min(r["contact"])),
            ]
        )
    out.append(
        Table(
            "Manoeuvres (MuJoCo)",
            [
                "manoeuvre",
                "commanded right / left (m/s)",
                "path (m)",
                "mean yaw rate (rad/s)",
                "radius of the body centre (m)",
                "χ identified on this manoeuvre",
                "least contact fraction of a wheel",
            ],
            rows,
            note="χ changes with the turn: one constant ICR model cannot fit every radius exactly. The least "
            "loaded wheel (a road wheel; the bogie hinge is ahead of its wheels' midpoint) leaves the ground "
            "for part of some turns: load transfer from the drive torques through the differential.",
        )
    )
    out.append(
        Table(
            "Yaw-rate RMS error vs MuJoCo (rad/s)",
            ["manoeuvre", *ESTIMATORS, "no-slip / ICR"],
            [
                [
                    r["name"],
                    *(r["yaw_rms"][e] for e in ESTIMATORS),
                    r["yaw_rms"][ESTIMATORS[0]] / r["yaw_rms"][ESTIMATORS[1]],
                ]
                for r in comp.rows
            ],
            note="No-slip: (v_right − v_left)/S from the encoders. The last column is the factor by which "
            "the identified ICR model reduces the no-slip error.",
        )
    )
    out.append(
        Table(
            "Dead-reckoning drift per metre travelled (final horizontal position error / path length)",
            ["manoeuvre", *ESTIMATORS],
            [[r["name"], *(r["drift_per_m"][e] for e in ESTIMATORS)] for r in comp.rows],
            note="All estimates start from the true pose at the first encoder reading. The 30×11 estimates "
            "use the carrier-fixed contact velocities, which a real robot cannot measure (paper 4's inputs); "
            "the others use only encoders and the gyro. With a fixed ICR model the EKF's gyro-bias state "
            "absorbs the model's yaw error in turns (the encoders are its only view of the bias), so it is "
            "no better than the ICR model alone; adapting the ICRs online (bias from a start-up calibration) "
            "removes much of that, and what remains is the ICR model's error in the forward speed.",
        )
    )
    out.append(
        Table(
            "30×11 system: ordinary vs weighted least squares (weights 1/var of each row)",
            [
                "manoeuvre",
                "noise",
                "OLS yaw RMS (rad/s)",
                "OLS |v_B| RMS (m/s)",
                "WLS yaw RMS (rad/s)",
                "WLS |v_B| RMS (m/s)",
            ],
            comp.wls,
            note="With equal noise the weighting changes little (the yaw error is the gyro's bias, which no "
            "weighting removes; diagonal weights also neglect that the gyro appears in six rows). With the "
            "rear-wheel contacts noisier, weighting by the covariances recovers most of the accuracy.",
        )
    )
    return out


ESTIMATOR_COLORS = dict(zip(ESTIMATORS, ("C3", "C1", "C4", "C2", "C5", "C0", "C9"), strict=True))


def figures(comp: Comparison, out_dir: Path) -> list[Figure]:
    """The comparison's five figures."""
    return [
        tracks_figure(comp, out_dir),
        yaw_rate_figure(comp, out_dir),
        drift_figure(comp, out_dir),
        slip_figure(comp, out_dir),
        chi_figure(comp, out_dir),
    ]


def _flat_turn(comp: Comparison) -> dict:
    return next(x for x in comp.rows if x["name"] == "turn, flat")


def tracks_figure(comp: Comparison, out_dir: Path) -> Figure:
    colors = ESTIMATOR_COLORS
    n = len(comp.rows)
    cols = 4
    fig, axes = plt.subplots(2, cols, figsize=(16, 8))
    for ax, r in zip(axes.flat, comp.rows, strict=False):
        ax.plot(r["truth_xy"][:, 0], r["truth_xy"][:, 1], "k", lw=2.5, label="MuJoCo")
        for e, p in r["est_xy"].items():
            ax.plot(p[:, 0], p[:, 1], lw=1.1, color=colors[e], label=e)
        ax.set_title(r["name"], fontsize=9)
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, alpha=0.3)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    handles, labels = axes.flat[0].get_legend_handles_labels()
    list(axes.flat)[-1].legend(handles, labels, loc="center", fontsize=8)
    fig.suptitle("Ground tracks (m): MuJoCo vs the estimators")
    return save_figure(
        fig, out_dir, "engine_tracks", "Ground tracks on contact physics (MuJoCo) and estimates"
    )


def yaw_rate_figure(comp: Comparison, out_dir: Path) -> Figure:
    r = _flat_turn(comp)
    fig, ax = plt.subplots(figsize=(11, 4))
    ax.plot(r["t"], r["yaw_true"], "k", lw=2, label="MuJoCo")
    for e in ESTIMATORS[:5]:
        ax.plot(r["t"], r["est_yaw"][e], lw=0.9, color=ESTIMATOR_COLORS[e], label=e)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("yaw rate (rad/s)")
    ax.set_title("Yaw rate in a flat turn: the no-slip formula vs the skid")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return save_figure(fig, out_dir, "engine_yaw_rate", "Yaw rate in a flat turn (MuJoCo vs estimators)")


def drift_figure(comp: Comparison, out_dir: Path) -> Figure:
    n = len(comp.rows)
    fig, ax = plt.subplots(figsize=(13, 4.8))
    width = 0.8 / len(ESTIMATORS)
    x = np.arange(n)
    for j, e in enumerate(ESTIMATORS):
        vals = [max(rr["drift_per_m"][e], 1e-5) for rr in comp.rows]
        ax.bar(x + (j - len(ESTIMATORS) / 2 + 0.5) * width, vals, width, color=ESTIMATOR_COLORS[e], label=e)
    ax.set_yscale("log")
    ax.set_xticks(x, [rr["name"] for rr in comp.rows], rotation=15, fontsize=8)
    ax.set_ylabel("drift per metre travelled (m/m)")
    ax.set_title("Dead-reckoning drift per metre, per manoeuvre")
    ax.grid(True, alpha=0.3, which="both", axis="y")
    ax.set_ylim(top=30.0)  # room for the legend above the bars
    ax.legend(fontsize=7, ncol=4, loc="upper center")
    return save_figure(
        fig, out_dir, "engine_drift", "Dead-reckoning drift per metre by estimator and manoeuvre"
    )


def slip_figure(comp: Comparison, out_dir: Path) -> Figure:
    r = _flat_turn(comp)
    fig, axes = plt.subplots(1, 2, figsize=(13, 4))
    for w, name in enumerate(ss.WHEELS):
        axes[0].plot(r["t"], r["slip"].ratio[:, w], lw=0.9, label=name)
        axes[1].plot(r["t"], r["slip"].lateral_velocity[:, w], lw=0.9, label=name)
    axes[0].set_ylabel("longitudinal slip ratio")
    axes[1].set_ylabel("lateral sliding velocity (m/s)")
    for ax in axes:
        ax.set_xlabel("time (s)")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Per-wheel slip in a flat turn (MuJoCo truth)")
    return save_figure(
        fig, out_dir, "engine_slip", "Per-wheel slip ratios and lateral sliding in a flat turn"
    )


def chi_figure(comp: Comparison, out_dir: Path) -> Figure:
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    turns = [rr for rr in comp.rows if np.isfinite(rr["chi_own"])]
    ax.plot([abs(rr["radius_m"]) for rr in turns], [rr["chi_own"] for rr in turns], "o")
    for rr in turns:
        ax.annotate(rr["name"], (abs(rr["radius_m"]), rr["chi_own"]), fontsize=7)
    ax.axhline(comp.chi, color="0.4", ls="--", label=f"identified model χ = {comp.chi:.2f}")
    ax.axhline(1.0, color="C3", ls=":", label="no slip χ = 1")
    ax.set_xlabel("|radius of the body centre| (m)")
    ax.set_ylabel("χ identified on the manoeuvre")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return save_figure(fig, out_dir, "engine_chi", "Effective track-width factor χ per manoeuvre")
