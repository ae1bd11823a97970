"""Paper 3 study: the cable-driven continuum robot (Qi et al., 2023).

* Fig. 9: the improved capstan tension ratio (eqs. (29)-(32)) against the classical law.
* Fig. 6 trends: tension loss of a cable-pulley system vs pretension and wrap angle (model, not data).
* Section 5 on a SIMULATED robot: friction identified from noisy simulated tensions, then planar bending
  0 -> 90 deg at beta = 0 and a spatial circle, tip error before and after the compensation q~ = q + delta.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robomech.mechanisms import continuum as C
from robomech.verify import continuum as V

from ._core import Figure, Progress, Study, StudyResult, Table, comparison_table
from ._papers import PAPERS, cite
from ._plot import plt, save_figure

# Simulated sensors (paper 3, Section 5): JLBS-MD 10 kg load cells, 0.05 % of full scale ~ 0.05 N;
# CTrac-380 laser tracker, 0.022 mm accuracy.
TENSION_NOISE = 0.05
TRACKER_NOISE = 0.022e-3
SEED = 3
# Fig. 6 assumptions (the paper gives no pulley or friction data for its test rig): 0.4 mm Dyneema on
# a 10 mm guide pulley (rho = 10 / 0.2 = 50), nonlinear friction alpha = 0.2, n = 0.8.
FIG6_RHO, FIG6_ALPHA, FIG6_N = 50.0, 0.2, 0.8
# Spatial circle: the paper gives no radius; bend 60 deg, full turn of beta.
CIRCLE_THETA_DEG = 60.0
Array = NDArray[np.float64]


# Hysteresis: simulate_history(memory="elastic") over a load-unload cycle of cable 1's drive (cables 2,
# 3 paying out half), at Table 1 mu, half of it and none.  The peak drive bends the paper robot to ~55
# deg; HYSTERESIS_STEPS steps each way.  The dead band is resolved at the top by paying cable 1 out
# alone in DEAD_BAND_STEP steps.
HYSTERESIS_DRIVE_MM = 4.0
HYSTERESIS_STEPS = 16
HYSTERESIS_FRICTION_SCALES = (1.0, 0.5, 0.0)
HYSTERESIS_COLORS = ("tab:red", "tab:orange", "k")
DEAD_BAND_STEP = 1e-6  # m
DEAD_BAND_STEPS = 40
# paper 3, Section 6, conclusion (4), translated from the Chinese.
PAPER_CONCLUSION_4 = (
    "“The robot shows some hysteresis in the experiments, probably caused by the stretch of the drive "
    "cables and their sliding friction on the guide pulleys; this error is small and can be neglected.”"
)
# Compensation against the disk-resolved reference: the drive is applied to the reference.
REFERENCE_COMPENSATION_BENDS_DEG = (45.0, 90.0)
# Backbones drawn at θ = 60° against the Cosserat rod: (tip force N, colour, label).
COSSERAT_SHAPE_LOADS = (
    ((0.0, 0.0, 0.0), "k", "no load"),
    ((0.1, 0.0, 0.0), "C0", "0.1 N lateral"),
    ((0.0, 0.0, -0.1), "C1", "0.1 N axial"),
)

SUMMARY = (
    "Exact: the constant-curvature kinematics (eqs. (1)-(6), with eq. (1)'s misprinted element "
    "corrected), cable lengths (arc model of eq. (4) and straight chords between disks), "
    "Jacobians and IK; virtual-work statics with the physical sign (tension positive) and the "
    "corrected null-space projector; the improved capstan equation (eqs. (29)-(32)) integrated to"
    " 1e-8 against a tight reference. SIMULATED, not measured: Section 5's 'experiments' run on a"
    " simulated robot whose ground truth is robomech's quasi-static model with straight cable "
    "chords, Coulomb friction at every disk hole with Table 1's μ, elastic Dyneema cables (E = "
    "4.96 GPa, 0.8 mm) over the body and a 0.1 m free length, and a 1.0 mm NiTi core (E = 60 "
    "GPa); those stiffnesses and lengths are not printed, so the error magnitudes depend on these"
    " assumed values. The compensation applied is the paper's: arc cable lengths (eq. (4)), "
    "virtual-work tensions with pretension and disk friction with the identified μ, cable stretch"
    " by Hooke's law, q~ = q + δ (eq. (37)). Fig. 6 is shown only as model trends (no data are "
    "given)."
)


# ---- compute: every number and curve of the report, no drawing ----------------------------------------


@dataclass(frozen=True)
class Capstan:
    """Fig. 9: tension ratios over the wrap angle, classical and improved (output tension 1 N)."""

    phi: Array
    classical: dict[float, Array]  # friction α -> exp(α φ)
    improved: dict[tuple[float, float, float], Array]  # (α, ρ, n) -> κ(φ)


def capstan_curves() -> Capstan:
    """The improved capstan ratio (eqs. (29)-(32)) and the classical law at α = 0.15 and 0.6."""
    phi = np.linspace(0.0, np.pi, 121)
    classical, improved = {}, {}
    for alpha in (0.15, 0.6):
        classical[alpha] = C.classical_capstan_ratio(phi, alpha)
        for rho in (1.0, 10.0):
            for n in (0.67, 1.0):
                improved[alpha, rho, n] = C.capstan_tension_ratio(phi, rho=rho, alpha=alpha, n=n, t_out=1.0)
    return Capstan(phi, classical, improved)


FIG6_PRETENSION = np.array([3.0, 5.0, 7.0, 9.0, 11.0])  # N
FIG6_WRAP_DEG = np.array([30.0, 60.0, 90.0, 120.0, 150.0])


def fig6_loss() -> Array:
    """Tension loss T_in − T_out (N) of the assumed pulley over pretension (rows) and wrap angle."""
    P, Wd = np.meshgrid(FIG6_PRETENSION, FIG6_WRAP_DEG, indexing="ij")
    k = C.capstan_tension_ratio(np.radians(Wd), rho=FIG6_RHO, alpha=FIG6_ALPHA, n=FIG6_N, t_out=P)
    return P * (k - 1.0)


def identify(truth: C.ContinuumRobot, rng: np.random.Generator) -> Any:
    """Paper 3, Section 5 / Table 1: friction identified from simulated noisy tensions and tracked tips
    at beta = 0, 120, 240 deg, theta 40 -> 90 deg in 5 deg steps; returns ``C.identify_friction``'s
    estimate."""
    theta = np.radians(np.arange(40.0, 90.1, 5.0))
    wraps, t_in, t_out, dirs = [], [], [], []
    for k, beta in enumerate(np.radians([0.0, 120.0, 240.0])):
        psi = np.stack([theta, np.full_like(theta, beta)], -1)
        direction = np.where(np.arange(3) == k, 1.0, -1.0) * np.ones((theta.size, 1))
        sim = C.simulate(truth, C.theoretical_drive(truth, psi, "arc"), direction, initial=psi)
        P = C.friction_factors(truth, sim.psi, direction)
        # measured: tensions at both cable ends (noisy load cells) and the pose from the tracked tip
        p_meas = C.tip_position(truth, sim.psi) + rng.normal(0.0, TRACKER_NOISE, (theta.size, 3))
        ik = C.inverse_kinematics(truth, p_meas)
        wraps.append(C.wrap_angles(truth, ik.psi).sum(-1))
        t_in.append(sim.tension + rng.normal(0.0, TENSION_NOISE, sim.tension.shape))
        t_out.append(sim.tension * P[..., -1] + rng.normal(0.0, TENSION_NOISE, sim.tension.shape))
        dirs.append(direction)
    cat = lambda xs: np.concatenate(xs, 0).T  # noqa: E731  (cables, measurements)
    taut = cat(t_out) > 10 * TENSION_NOISE  # a nearly slack cable carries no friction information
    return C.identify_friction(
        np.where(taut, cat(wraps), 0.0),
        np.where(taut, cat(t_in), 1.0),
        np.where(taut, cat(t_out), 1.0),
        np.where(taut, cat(dirs), 0.0),
        sigma_t=TENSION_NOISE,
    )


@dataclass(frozen=True)
class Compensated:
    """One trajectory on the simulated robot: uncompensated and with the paper's compensation."""

    desired_tip: Array  # (n, 3) m
    tips: list[Array]  # before, after (paper's method)
    errors: list[Array]  # tip errors (m): before, after, after with the simulation's own model
    converged: bool
    simulations: tuple[Any, Any]  # C.simulate results: before, after


def compensated_trajectory(
    truth: C.ContinuumRobot, model: C.ContinuumRobot, psi: Array, direction: Array
) -> Compensated:
    """Simulate ``psi`` driven rigidly (eq. (4)), with the paper's compensation (identified μ), and with
    the simulation's own model."""
    p_d = C.tip_position(truth, psi)
    q = C.theoretical_drive(truth, psi, "arc")  # the rigid, frictionless drive of eq. (4)
    sim0 = C.simulate(truth, q, direction, initial=psi)
    drive = C.compensated_drive(model, psi, direction, model="arc")  # paper's method, identified mu
    sim1 = C.simulate(truth, drive.q_compensated, direction, initial=psi)
    ideal = C.compensated_drive(truth, psi, direction, model="chord")  # same model as the simulation
    sim2 = C.simulate(truth, ideal.q_compensated, direction, initial=psi)
    errs = [np.linalg.norm(C.tip_position(truth, s.psi) - p_d, axis=-1) for s in (sim0, sim1, sim2)]
    ok = all(bool(s.converged.all()) for s in (sim0, sim1, sim2))
    tips = [C.tip_position(truth, s.psi) for s in (sim0, sim1)]
    return Compensated(p_d, tips, errs, ok, (sim0, sim1))


@dataclass(frozen=True)
class Section5:
    """Section 5's two experiments on the simulated robot."""

    theta: Array  # planar bend angles (rad), β = 0
    planar_direction: Array
    planar: Compensated
    beta: Array  # circle bending-plane angles (rad), θ = CIRCLE_THETA_DEG
    circle: Compensated


def section5(truth: C.ContinuumRobot, model: C.ContinuumRobot, progress: Progress) -> Section5:
    """Planar bending 0 -> 90 deg at β = 0 and the spatial circle, before and after compensation."""
    progress.step("planar bending 0 -> 90 deg (simulated robot)")
    th = np.radians(np.linspace(0.0, 90.0, 91))
    psi_p = np.stack([th, np.zeros_like(th)], -1)
    dir_p = np.broadcast_to([1.0, -1.0, -1.0], (th.size, 3))  # cable 1 pulled, 2 and 3 paid out
    planar = compensated_trajectory(truth, model, psi_p, dir_p)
    progress.step("spatial circle (simulated robot)")
    be = np.linspace(0.0, 2.0 * np.pi, 181)
    psi_c = np.stack([np.full_like(be, np.radians(CIRCLE_THETA_DEG)), be], -1)
    dq = np.gradient(C.theoretical_drive(truth, psi_c, "arc"), axis=0)
    # each cable slides in the direction its actuator moves; at a turning point (dq = 0) it would stick
    # (paper 3, eq. (19)'s stuck branch, not modelled: the direction of the motion that follows is taken)
    dir_c = np.where(dq >= 0.0, 1.0, -1.0)
    circle = compensated_trajectory(truth, model, psi_c, dir_c)
    return Section5(th, dir_p, planar, be, circle)


def planar_tensions(truth: C.ContinuumRobot, s5: Section5) -> tuple[Any, Any]:
    """Virtual-work tensions along the planar bend: default pretension and the printed η = 1 N."""
    psi = np.stack([s5.theta, np.zeros_like(s5.theta)], -1)
    return (
        C.cable_tensions(truth, psi, direction=s5.planar_direction),
        C.cable_tensions(truth, psi, direction=s5.planar_direction, pretension=1.0),
    )


def cc_vs_cosserat(progress: Progress) -> tuple[Any, list[tuple[str, str, Array, Array]]]:
    """Constant curvature against a Cosserat rod (Rucker & Webster 2011) with the same parameters: the
    error table of ``robomech.verify.continuum`` and the backbones ``(label, colour, CC, Cosserat)`` at
    θ = 60°."""
    progress.step("constant curvature vs Cosserat rod (solve_bvp, 42 load cases)")
    table = V.cc_error_table()
    robot = C.ContinuumRobot.paper()
    shapes = []
    for force, color, label in COSSERAT_SHAPE_LOADS:
        _, p_cc, p_cos = V.compare_shapes(robot, (np.radians(60.0), 0.0), force)
        shapes.append((label, color, p_cc, p_cos))
    return table, shapes


@dataclass(frozen=True)
class Hysteresis:
    """Load-unload cycles of the paper robot with stick-slip memory, per friction scale."""

    drive: Array  # cable 1's drive q1 over the cycle (m)
    labels: list[str]
    bend_deg: list[Array]  # θ over the cycle, per friction scale
    tension: list[Array]  # cable 1's actuator tension over the cycle (N)
    rows: list[list]  # the table's rows
    n_steps: int
    seconds: float  # wall-clock time of the history solves
    all_valid: bool


def hysteresis(progress: Progress) -> Hysteresis:
    """Stick-slip with memory that the pose feels (eq. (19) with memory): hysteresis loops."""
    progress.step("stick-slip hysteresis: load-unload cycles with memory fed back into the pose")
    paper = C.ContinuumRobot.paper()
    up = np.linspace(0.0, HYSTERESIS_DRIVE_MM * 1e-3, HYSTERESIS_STEPS + 1)
    q1 = np.concatenate([up, up[::-1][1:]])
    q = np.stack([q1, -0.5 * q1, -0.5 * q1], -1)
    back = up[-1] - DEAD_BAND_STEP * np.arange(1, DEAD_BAND_STEPS + 1)
    held = np.broadcast_to(q[HYSTERESIS_STEPS], (back.size, 3)).copy()
    held[:, 0] = back  # cable 1 paid out alone, cables 2, 3 held
    q_band = np.concatenate([q[: HYSTERESIS_STEPS + 1], held])
    rows, labels, bends, tensions = [], [], [], []
    n_steps, seconds = 0, 0.0
    all_valid = True
    for scale in HYSTERESIS_FRICTION_SCALES:
        robot = C.ContinuumRobot(friction=tuple(scale * m for m in paper.friction))
        t0 = time.perf_counter()
        h = C.simulate_history(robot, q)
        hb = C.simulate_history(robot, q_band)
        seconds += time.perf_counter() - t0
        n_steps += q.shape[0] + q_band.shape[0]
        all_valid &= bool(np.all(h.valid) and np.all(hb.valid))
        theta = np.degrees(h.psi[:, 0])
        label = f"μ = {scale:g} × Table 1" if scale else "μ = 0"
        labels.append(label)
        bends.append(theta)
        tensions.append(h.actuator_tension[:, 0])
        n = HYSTERESIS_STEPS
        gap = np.max(np.abs(theta[n:][::-1] - theta[: n + 1]))
        area_bend = abs(np.trapezoid(h.psi[:, 0], q1))  # rad m
        work = float(np.sum(np.trapezoid(h.actuator_tension, q, axis=0)))  # J, all cables, one cycle
        # dead band: actuator-tension drop of cable 1 before the tip moves after the reversal
        top = HYSTERESIS_STEPS
        moved = np.linalg.norm(hb.tip[top + 1 :] - hb.tip[top], axis=-1) > 1e-12
        still = int(np.argmax(moved)) if np.any(moved) else DEAD_BAND_STEPS
        band_t = float(hb.actuator_tension[top, 0] - hb.actuator_tension[top + still, 0]) if still else 0.0
        # the base-plate wrap of the disk-wise pose: half the first interval's bend (its arc's chord)
        mu_eta0 = float(robot.friction[0] * 0.5 * hb.bend[top, 0, 0])
        predicted = float(hb.span_tension[top, 0, 0] * (np.exp(mu_eta0) - np.exp(-mu_eta0)))
        rows.append(
            [
                label,
                float(gap),
                area_bend * 1e6,
                abs(work) * 1e3,
                still * DEAD_BAND_STEP * 1e6,
                band_t,
                predicted,
            ]
        )
    return Hysteresis(q1, labels, bends, tensions, rows, n_steps, seconds, all_valid)


REFERENCE_COMPENSATION_DRIVES = (
    ("rigid chord lengths (before)", "chord"),
    ("paper: q~ = q + δ (eq. 37)", "paper"),
    ("disk-wise model (method='disk')", "disk"),
)


def reference_compensation(progress: Progress) -> tuple[list[list], dict[str, list[float]]]:
    """Before/after compensation measured on the disk-resolved reference (not on the library's own
    simulate, whose compensated error is 0 by construction): table rows and tip errors (m) per bend
    (``robomech.verify.continuum.compensation_on_reference``; the 90° chord and disk cases are the
    verification's, read from its results when ``robomech verify --out`` stored them)."""
    progress.step("compensation measured on the disk-resolved reference (drive mode, 3 drives x 2 bends)")
    robot = C.ContinuumRobot.paper()
    rows, data = [], {}
    for bend in REFERENCE_COMPENSATION_BENDS_DEG:
        sols = [V.compensation_on_reference(robot, bend, drive) for _, drive in REFERENCE_COMPENSATION_DRIVES]
        err = np.array([s["tip_error"] for s in sols])
        ok = [bool(s["converged"] and s["taut"]) for s in sols]
        for i, (name, _) in enumerate(REFERENCE_COMPENSATION_DRIVES):
            cell = f"{1e3 * err[i]:.2f}" + ("" if ok[i] else " (slack or not converged)")
            factor = f"{err[0] / err[i]:.2f}" if ok[0] and ok[i] else "—"
            rows.append([f"{bend:g}°", name, cell, factor])
        data[f"{bend:g}"] = err.tolist()
    return rows, data


# ---- tables -------------------------------------------------------------------------------------------


def capstan_table(c: Capstan) -> Table:
    rows = [
        [alpha, rho, n, float(k[-1]), float(np.exp(alpha * np.pi))]
        for (alpha, rho, n), k in c.improved.items()
    ]
    return Table(
        "Fig. 9 at φ = 180° (output tension 1 N)",
        ["α", "ρ", "n", "improved κ", "classical exp(απ)"],
        rows,
        note="The paper prints only curves; the improved model loses less tension than "
        "the classical law everywhere, as the paper states.",
    )


def identification_table(truth: C.ContinuumRobot, est: Any) -> Table:
    rows = [
        [
            f"cable {j + 1} (β = {120 * j}°)",
            truth.friction[j],
            float(est.mu[j]),
            float(est.std[j]),
            float((est.mu[j] - truth.friction[j]) / est.std[j]),
            int(est.n_used[j]),
        ]
        for j in range(3)
    ]
    return Table(
        "Friction identification from simulated, noisy tensions (Table 1 μ as ground truth)",
        ["cable", "true μ (paper Table 1)", "identified μ", "std", "error / std", "measurements"],
        rows,
        note=f"Load-cell noise {TENSION_NOISE} N on both ends, tracker noise {TRACKER_NOISE * 1e3} mm; "
        "linear least squares on ln(T_in/T_out) = s μ η. Table 1's λ column is undefined in the "
        "paper and not reproduced.",
    )


def mean_errors_mm(s5: Section5) -> tuple[list[float], list[float]]:
    """Mean tip errors (mm) before, after and with the simulation's own model: planar, circle."""
    e_p = [float(np.mean(e[1:]) * 1e3) for e in s5.planar.errors]  # theta = 0 excluded: no motion
    e_c = [float(np.mean(e) * 1e3) for e in s5.circle.errors]
    return e_p, e_c


def section5_table(s5: Section5) -> Table:
    e_p, e_c = mean_errors_mm(s5)
    rate = lambda before, after: 100.0 * (before - after) / before  # noqa: E731
    return comparison_table(
        "Section 5: mean tip error before and after compensation (simulated robot vs the paper's experiment)",
        [
            ("planar bending: before compensation", 3.03, e_p[0], "mm"),
            ("planar bending: after compensation", 1.48, e_p[1], "mm"),
            ("planar bending: compensation rate", 50.99, rate(e_p[0], e_p[1]), "%"),
            ("spatial circle: before compensation", 5.94, e_c[0], "mm"),
            ("spatial circle: after compensation", 3.15, e_c[1], "mm"),
            ("spatial circle: compensation rate", 46.97, rate(e_c[0], e_c[1]), "%"),
        ],
        note="The paper's values are measured on its prototype; robomech's come from a simulated robot "
        "(see summary). The remaining error after the paper's compensation comes from its arc cable "
        "model (real cables run in straight chords), its pretension rule, and the identified μ. "
        "(Compensating with the simulation's own model lands on the target by construction, so it is "
        "no evidence and is not shown; the compensation measured on the independent disk-resolved "
        "reference is the last table of this report.)",
    )


def cosserat_table(table: Any) -> Table:
    rows = []
    for i, bend in enumerate(table.bend_deg):
        row = [f"{bend:.0f}°"]
        for k in range(1, len(table.load_labels)):
            ok = table.valid[i, k]
            row.append(
                f"{1e3 * table.position_error[i, k]:.2f} mm / {np.degrees(table.angle_error[i, k]):.2f}°"
                if ok
                else "slack"
            )
        rows.append(row)
    return Table(
        "Constant-curvature tip error vs a Cosserat rod (position / orientation), paper robot, β = 0",
        ["bend θ", *table.load_labels[1:]],
        rows,
        note=(
            "Same lengths, core stiffness and cable holes in both models; frictionless, inextensible. "
            "robomech's virtual-work statics give the tensions that hold the constant-curvature robot at"
            " θ under the tip load; the Cosserat rod with those tensions and that load gives the true "
            f"shape. With no load the two agree to {1e3 * np.nanmax(table.position_error[:, 0]):.1e} mm "
            "(constant curvature is exact there; `robomech verify continuum`). The core is the assumed "
            "1.0 mm NiTi rod (EI = 2.9e-3 N m²), so already 0.1 N moves the tip by millimetres that "
            "constant curvature misplaces by tens of percent."
        ),
    )


def hysteresis_table(h: Hysteresis) -> Table:
    per_step = h.seconds / h.n_steps
    return Table(
        "Hysteresis over a load-unload cycle (simulate_history, memory='elastic')",
        [
            "friction",
            "max bend gap unloading − loading (deg)",
            "bend loop area (µrad m)",
            "work lost per cycle (mJ)",
            "dead band at the top, drive (µm)",
            "dead band, actuator tension (N)",
            "T_s0 (e^{μη₀} − e^{−μη₀}) (N)",
        ],
        h.rows,
        note=f"Paper 3, conclusion (4): {PAPER_CONCLUSION_4} Here the hysteresis comes from the disks' "
        "hole friction alone (no pulley): every span keeps its cable while its tension ratio lies inside "
        "the capstan cone and slides at a bound; the pose is solved under those tensions. The dead band "
        "is the actuator-tension drop of cable 1 before the tip moves when it is paid out alone after "
        "the load (1 µm steps, ~0.025 N each: the measured band is the last still step, so it lies "
        "within one step below the last column, the cone of the base-plate hole, which must be crossed "
        f"first). {h.n_steps} history steps in {h.seconds:.1f} s ({1e3 * per_step:.0f} ms per step).",
    )


def reference_compensation_table(rows: list[list]) -> Table:
    return Table(
        "Compensation measured on the disk-resolved reference (paper robot, β = 0, planar bend)",
        ["bend θ", "drive", "reference tip error (mm)", "factor (before / this)"],
        rows,
        note="Each drive is applied to the disk-resolved Cosserat reference with hole friction and "
        "elastic cables (drive mode) and its tip is compared with the commanded constant-curvature "
        "tip: measured, not by construction. The paper's q + δ raises the error: under friction the "
        "curvature falls from disk to disk (11.8, 9.7, 7.9, 6.5, 5.3° at 45°), which puts the tip "
        "~2 mm outward of the arc's tip, and adding the stretch bends it further. The disk-wise "
        "model (one arc per disk interval, beam-column correction; 46 µm from the reference for "
        "the same tensions at 90°) aims the drive at the tip; what remains is the gap between the "
        "disk-wise tip surface and the arc's (the least-squares point, 0.6 mm at 45°, 2.3 mm at 90°).",
    )


# ---- figures: each draws computed data -----------------------------------------------------------------


def capstan_figure(c: Capstan, out_dir: Path) -> Figure:
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    phi_deg = np.degrees(c.phi)
    for ax, alpha in zip(axes, c.classical, strict=True):
        ax.plot(phi_deg, c.classical[alpha], "k-", lw=2, label="classical exp(α φ)")
        for rho, ls in ((1.0, "--"), (10.0, "-")):
            for n, color in ((0.67, "tab:red"), (1.0, "tab:blue")):
                k = c.improved[alpha, rho, n]
                ax.plot(phi_deg, k, ls=ls, color=color, label=f"improved ρ={rho:g}, n={n:g}")
        ax.set_xlabel("wrap angle φ (deg)")
        ax.set_title(f"tension ratio, friction α = {alpha}")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    axes[0].set_ylabel("T_in / T_out (output tension 1 N)")
    return save_figure(
        fig, out_dir, "fig9_capstan", "Fig. 9: improved capstan ratio (eqs. 29-32) vs the classical law"
    )


def fig6_figure(loss: Array, out_dir: Path) -> Figure:
    pre, wrap_deg = FIG6_PRETENSION, FIG6_WRAP_DEG
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for j, w in enumerate(wrap_deg):
        axes[0].plot(pre, loss[:, j], "o-", label=f"wrap {w:g}°")
    axes[0].set_xlabel("pretension (output tension) T_out (N)")
    axes[0].set_ylabel("tension loss T_in − T_out (N)")
    axes[0].set_title("trend: loss vs pretension")
    for i, t in enumerate(pre):
        axes[1].plot(wrap_deg, loss[i, :], "s-", label=f"T_out {t:g} N")
    axes[1].set_xlabel("wrap angle (deg)")
    axes[1].set_ylabel("tension loss T_in − T_out (N)")
    axes[1].set_title("trend: loss vs wrap angle")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    return save_figure(
        fig,
        out_dir,
        "fig6_trends",
        f"Fig. 6 trends from the improved capstan model (assumed ρ = {FIG6_RHO:g}, α = {FIG6_ALPHA}, "
        f"n = {FIG6_N}); the paper's measured curves are not reproduced (no data given)",
    )


def planar_compensation_figure(s5: Section5, out_dir: Path) -> Figure:
    th, (sim_p, sim_p1), errs_p = s5.theta, s5.planar.simulations, s5.planar.errors
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    ax = axes[0]
    ax.plot(np.degrees(th), np.degrees(sim_p.psi[:, 0] - th), "r--", label="before compensation")
    ax.plot(np.degrees(th), np.degrees(sim_p1.psi[:, 0] - th), "b-.", label="after compensation")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel("commanded bend angle θ (deg)")
    ax.set_ylabel("achieved − commanded bend angle (deg)")
    ax.set_title("Planar bending 0→90° at β = 0: bend-angle error")
    ax.legend()
    ax.grid(True, alpha=0.3)
    ax = axes[1]
    ax.plot(np.degrees(th), errs_p[0] * 1e3, "r--", label="before compensation")
    ax.plot(np.degrees(th), errs_p[1] * 1e3, "b-.", label="after compensation (paper's method)")
    ax.set_xlabel("commanded bend angle θ (deg)")
    ax.set_ylabel("tip position error (mm)")
    ax.set_title("planar bending: tip error before and after compensation (SIMULATED robot)")
    ax.legend()
    ax.grid(True, alpha=0.3)
    return save_figure(
        fig,
        out_dir,
        "planar_compensation",
        "Planar bending on the simulated robot: tip path and error before/after "
        "compensation (Fig. 12 analogue)",
    )


def circle_compensation_figure(s5: Section5, out_dir: Path) -> Figure:
    mm, pd_c, tips_c, errs_c, be = 1e3, s5.circle.desired_tip, s5.circle.tips, s5.circle.errors, s5.beta
    fig = plt.figure(figsize=(11, 4.2))
    ax = fig.add_subplot(1, 2, 1)
    ax.plot(pd_c[:, 0] * mm, pd_c[:, 1] * mm, "k-", lw=2, label="desired")
    ax.plot(tips_c[0][:, 0] * mm, tips_c[0][:, 1] * mm, "r--", label="before compensation")
    ax.plot(tips_c[1][:, 0] * mm, tips_c[1][:, 1] * mm, "b-.", label="after compensation")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_aspect("equal")
    ax.set_title(f"Spatial circle θ = {CIRCLE_THETA_DEG:g}°, β 0→360° (top view)")
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    ax = fig.add_subplot(1, 2, 2)
    ax.plot(np.degrees(be), errs_c[0] * mm, "r--", label="before compensation")
    ax.plot(np.degrees(be), errs_c[1] * mm, "b-.", label="after compensation (paper's method)")
    ax.set_xlabel("bending-plane angle β (deg)")
    ax.set_ylabel("tip position error (mm)")
    ax.set_title("spatial circle: tip error before and after compensation (SIMULATED robot)")
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    return save_figure(
        fig,
        out_dir,
        "circle_compensation",
        "Spatial circle on the simulated robot: tip path and error before/after "
        "compensation (Fig. 13 analogue)",
    )


def tensions_figure(truth: C.ContinuumRobot, th: Array, tensions: tuple[Any, Any], out_dir: Path) -> Figure:
    tr, tr_printed = tensions
    fig, ax = plt.subplots(figsize=(7, 4))
    for j in range(3):
        ax.plot(np.degrees(th), tr.tension[:, j], label=f"cable {j + 1}, pretension {truth.pretension:g} N")
        ax.plot(np.degrees(th), tr_printed.tension[:, j], ls=":", label=f"cable {j + 1}, printed η = 1 N")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel("bend angle θ (deg), β = 0")
    ax.set_ylabel("cable tension at the base (N)")
    ax.set_title("Virtual-work tensions with disk friction (pulling cable 1)")
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    return save_figure(
        fig,
        out_dir,
        "tensions",
        "Cable tensions from virtual work (tension positive), default pretension "
        "vs the paper's η = (1, 1, 1) N, which lets cables 2 and 3 go slack",
    )


def cosserat_figure(table: Any, shapes: list[tuple[str, str, Array, Array]], out_dir: Path) -> Figure:
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for k in range(1, len(table.load_labels)):
        ls = "-" if "lateral" in table.load_labels[k] else "--"
        axes[0].plot(
            table.bend_deg, 1e3 * table.position_error[:, k], ls, marker="o", label=table.load_labels[k]
        )
    axes[0].set_xlabel("bend angle θ (deg)")
    axes[0].set_ylabel("constant-curvature tip error (mm)")
    axes[0].set_title("Constant curvature vs Cosserat rod")
    axes[0].legend(fontsize=7)
    axes[0].grid(True, alpha=0.3)
    for label, color, p_cc, p_cos in shapes:
        if label == "no load":
            axes[1].plot(
                1e3 * p_cc[:, 0],
                1e3 * p_cc[:, 2],
                color="0.75",
                lw=6,
                zorder=1,
                label="constant curvature (commanded arc)",
            )
        style = ":" if label == "no load" else "-"
        axes[1].plot(
            1e3 * p_cos[:, 0], 1e3 * p_cos[:, 2], style, color=color, lw=1.8, label=f"Cosserat, {label}"
        )
    axes[1].set_aspect("equal")
    axes[1].set_xlabel("x (mm)")
    axes[1].set_ylabel("z (mm)")
    axes[1].set_title("Backbone at θ = 60°: tensions from the CC model")
    axes[1].legend(fontsize=7)
    axes[1].grid(True, alpha=0.3)
    return save_figure(
        fig,
        out_dir,
        "cc_vs_cosserat",
        "Left: constant-curvature tip error against a Cosserat-rod reference vs bend and tip load. "
        "Right: "
        "backbones at θ = 60°; with no load the Cosserat rod lies on the commanded arc (grey), under "
        "0.1 N it departs from it",
    )


def hysteresis_figure(h: Hysteresis, out_dir: Path) -> Figure:
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6))
    q1_mm = h.drive * 1e3
    for tension, color, label in zip(h.tension, HYSTERESIS_COLORS, h.labels, strict=True):
        axes[1].plot(q1_mm, tension, color=color, lw=1.5, label=label)
    # the loop is ~1 deg on a 52 deg bend: shown as the difference to the frictionless bend
    theta_free = h.bend_deg[HYSTERESIS_FRICTION_SCALES.index(0.0)]
    for theta, color, label in zip(h.bend_deg, HYSTERESIS_COLORS, h.labels, strict=True):
        axes[0].plot(q1_mm, theta - theta_free, color=color, lw=1.5, label=label)
    for ax in axes:
        ax.set_xlabel("drive of cable 1, q₁ (mm; cables 2, 3 pay out q₁/2)")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    axes[0].set_ylabel("bend θ − frictionless bend θ(μ = 0) (deg)")
    axes[0].set_title("Bend vs drive: load, unload (memory fed back into the pose)")
    axes[1].set_ylabel("actuator tension of cable 1 (N)")
    axes[1].set_title("Actuator tension vs drive over the cycle")
    return save_figure(
        fig,
        out_dir,
        "hysteresis",
        f"Hysteresis loops of the paper robot (disk-wise model, stick-slip with memory at every hole, "
        f"β = 0): cable 1 driven 0 → {HYSTERESIS_DRIVE_MM:g} → 0 mm at Table 1 μ, half and zero "
        f"friction. Paper 3, conclusion (4): {PAPER_CONCLUSION_4}",
    )


# ---- report -------------------------------------------------------------------------------------------


def report_data(
    loss: Array, est: Any, s5: Section5, cosserat: Any, h: Hysteresis, reference_errors: dict
) -> dict:
    """The machine-readable results (``results.json``'s ``data``)."""
    e_p, e_c = mean_errors_mm(s5)
    return {
        "fig6_loss_N": loss,
        "identified_mu": est.mu,
        "identified_mu_std": est.std,
        "planar_mean_error_mm": e_p,
        "circle_mean_error_mm": e_c,
        "all_converged": bool(s5.planar.converged and s5.circle.converged),
        "planar_slack_fraction_uncompensated": float(1.0 - np.mean(s5.planar.simulations[0].taut)),
        "circle_slack_fraction_uncompensated": float(1.0 - np.mean(s5.circle.simulations[0].taut)),
        "cc_vs_cosserat": {
            "bend_deg": cosserat.bend_deg,
            "loads": cosserat.load_labels,
            "position_error_m": cosserat.position_error,
            "angle_error_rad": cosserat.angle_error,
        },
        "hysteresis_loop_area_rad_m": [r[2] * 1e-6 for r in h.rows],
        "hysteresis_work_mJ": [r[3] for r in h.rows],
        "hysteresis_dead_band_N": [r[5] for r in h.rows],
        "hysteresis_ms_per_step": 1e3 * h.seconds / h.n_steps,
        "hysteresis_all_valid": h.all_valid,
        "reference_compensation_tip_error_m": reference_errors,
    }


def notes(s5: Section5, printed_tensions: Any, data: dict) -> list[str]:
    """Remarks on slack cables and convergence."""
    th = s5.theta
    slack_deg = np.degrees(th[~printed_tensions.taut])
    out = [
        f"With the printed η = (1, 1, 1) N, cables 2 and 3 would have to push beyond θ = "
        f"{slack_deg.min() if slack_deg.size else float('nan'):.0f}°; robomech flags these poses "
        "(taut = False).",
        f"Uncompensated drive: cables 2 and 3 go slack in "
        f"{100 * data['planar_slack_fraction_uncompensated']:.0f} % of the planar poses (the arc model "
        "pays out more cable than the chord geometry needs); the simulated "
        "robot handles slack cables (zero tension) and flags them.",
    ]
    slack_after = np.degrees(th[~s5.planar.simulations[1].taut])
    if slack_after.size:
        out.append(
            f"After the paper's compensation, cables 2 and 3 go slack from θ = {slack_after.min():.0f}° on "
            "(its arc-model payout exceeds what the chord geometry needs); there cable 1 alone bends the "
            "core, the bend-angle error changes sign and the tip error grows again (kinks in the curves)."
        )
    if not data["all_converged"]:
        out.append("WARNING: some simulated equilibria did not converge.")
    if not data["hysteresis_all_valid"]:
        out.append("WARNING: some stick-slip history steps did not converge or went slack.")
    return out


def run(out_dir: Path, progress: Progress) -> StudyResult:
    progress.plan(
        [
            "capstan",
            "identification",
            "planar bending",
            "spatial circle",
            "statics",
            "Cosserat rod",
            "hysteresis",
            "compensation on the disk reference",
        ]
    )
    progress.step("Figs. 9 and 6: improved capstan equation")
    capstan, loss = capstan_curves(), fig6_loss()
    truth = C.ContinuumRobot.paper()
    progress.step("identification of friction from simulated tensions")
    est = identify(truth, np.random.default_rng(SEED))
    model = C.ContinuumRobot(friction=tuple(float(m) for m in est.mu))
    s5 = section5(truth, model, progress)
    progress.step("statics: tensions along the planar bend")
    tensions = planar_tensions(truth, s5)
    cosserat, shapes = cc_vs_cosserat(progress)
    hyst = hysteresis(progress)
    reference_rows, reference_errors = reference_compensation(progress)

    tables = [
        capstan_table(capstan),
        identification_table(truth, est),
        section5_table(s5),
        cosserat_table(cosserat),
        hysteresis_table(hyst),
        reference_compensation_table(reference_rows),
    ]
    figures = [
        capstan_figure(capstan, out_dir),
        fig6_figure(loss, out_dir),
        planar_compensation_figure(s5, out_dir),
        circle_compensation_figure(s5, out_dir),
        tensions_figure(truth, s5.theta, tensions, out_dir),
        cosserat_figure(cosserat, shapes, out_dir),
        hysteresis_figure(hyst, out_dir),
    ]
    data = report_data(loss, est, s5, cosserat, hyst, reference_errors)
    return StudyResult(
        name="continuum",
        title="Paper 3: cable-driven continuum robot — capstan friction, statics and drive compensation",
        source=cite(3),
        summary=SUMMARY,
        tables=tables,
        figures=figures,
        data=data,
        notes=notes(s5, tensions[1], data),
    )


STUDY = Study(
    name="continuum",
    title="Paper 3: cable-driven continuum robot (capstan friction, statics, compensation)",
    source=PAPERS[3].short(),
    run=run,
)
