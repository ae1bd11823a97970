"""Study ``omnileg``: paper 2's kinematic and dynamic simulations of the OmniLeg, recomputed exactly.

* Fig. 9: inverse kinematics along the foot trajectory eq. (51) (T = 5 s): foot position, velocity,
  acceleration, and the joint motion the IK produces.
* Fig. 10: forward kinematics along the joint trajectory eq. (52): foot position, velocity, acceleration.
* Fig. 11: motor torques along eq. (52), 0-2 s, with the external force [0, -20, 20] N on the foot in 0-1 s.
* Fig. 19: motor torques of the gait eq. (53), 3 swing + 3 stance periods.
* The leg drawn at a few poses, and the Jacobian's singularity at γ = 0.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.lines import Line2D
from numpy.typing import NDArray

import robomech.mechanisms.omnileg as ol
from robomech.mechanisms.omnileg._dynamics import BODY_NAMES
from robomech.mechanisms.omnileg._trajectories import GAIT_PERIOD
from robomech.verify import omnileg as engine_check

from ._animate import Animation, animation_figure
from ._core import Figure, Progress, Study, StudyResult, Table, comparison_table
from ._papers import PAPERS, cite
from ._plot import plt, save_figure

# Fig. 11: external force on the foot during 0-1 s of eq. (52), N (paper 2, Section 4).
FIG11_FORCE = np.array([0.0, -20.0, 20.0])
FIG11_DURATION, FIG11_FORCE_END = 2.0, 1.0
# Fig. 19 stance: vertical ground reaction on the foot (N, against Z0).  Not given by the paper; sized so
# the γ torque is of the order Fig. 19 implies (0.37 N·m error = 8.7 % -> about 4 N·m).
STANCE_LOAD = 30.0
# Samples per second of the simulated curves (the curves are smooth: 200/s resolves them to the plot).
RATE = 400
MOTORS = ("M2 (α)", "M1 (β)", "M3 (γ)")  # torques are in q = (α, β, γ) order
AXES = ("X", "Y", "Z")
Array = NDArray[np.float64]


# ---- animation ----------------------------------------------------------------------------------
# One step of the gait eq. (53): a swing and a stance period (2 s), 51 frames (0.04 s apart) played
# at 25 frames/s, i.e. in real time.
ANIMATION_PERIODS = 2
ANIMATION_FRAMES = 51
ANIMATION_FPS = 25.0


def gait_animation(leg: ol.OmniLeg, out_dir: Path) -> tuple[Animation, dict[str, float]]:
    """The leg of ``ol.to_multibody`` stepping through eq. (53)'s swing and stance, as a GIF.

    Each frame's joint angles come from the analytic inverse kinematics of the gait's foot point; the
    generic description is assembled at them (thigh, drive and shank loops closed numerically).  Returns the
    animation and the largest distance between the drawn foot site and eq. (53)'s foot point.
    """
    mech = ol.to_multibody(leg)
    t = np.linspace(0.0, ANIMATION_PERIODS * GAIT_PERIOD, ANIMATION_FRAMES)
    gait = ol.gait_eq53(leg, t)
    ik = ol.inverse_kinematics(leg, gait.foot.q)
    anim = animation_figure(
        mech,
        ik.q,
        t,
        out_dir,
        "gait_motion",
        "One step of the gait eq. (53) in real time: swing (0–1 s, the foot moves 0.1 m along Y0 while "
        "lifting 0.05 m) and stance (1–2 s, back on the ground). The joint angles are the inverse "
        "kinematics of the foot point; the leg drawn is the generic description ol.to_multibody(leg) "
        "assembled at them, thigh, drive and shank loops closed numerically. Each body is drawn from "
        "its joint to the points it carries, coloured by the chain it hangs from: thigh chain 1 with "
        "the knee plate, the three shank crank-sliders and the foot blue, thigh chains 2 and 3 orange "
        "and green, the double-Cardan drive shaft red; circles are the loop cuts, the black dot the "
        "foot and the dotted curve its path; Z0 points down.",
        "Animated 3-D wireframe of the OmniLeg hanging from its hip: three thigh rods and a central "
        "drive shaft carry a knee plate, below which three crank-slider chains carry the foot; the "
        "foot swings forward with a small lift and then slides back along a straight line.",
        site="foot",
        fps=ANIMATION_FPS,
        title="paper 2, gait eq. (53)",
        view=(12.0, -50.0),
        invert_z=True,
    )
    err = float(np.max(np.abs(anim.site - gait.foot.q)))
    return anim, {"max_foot_error_m": err, "ik_reachable": float(np.mean(ik.reachable))}


# ---- compute: every number and curve of the report, no drawing ----------------------------------------


@dataclass(frozen=True)
class ThighClosure:
    """The thigh closed by the product of exponentials at 400 random poses, against eq. (11)."""

    foot_error: float  # m, |foot(PoE closure + crank-slider) − eq. (11)|
    plate_rotation: float  # rad
    residual: float
    converged: bool
    theta12_error: float  # rad, against eq. (12)
    theta22_printed_error: float  # rad, against the printed eq. (12)


def thigh_closure(leg: ol.OmniLeg) -> ThighClosure:
    """The numerical thigh closure against the closed forms at 400 random poses (seed 0)."""
    rng = np.random.default_rng(0)
    n_cl = 400
    qs = np.stack(
        [
            rng.uniform(-1, 1, n_cl) * leg.alpha_max,
            rng.uniform(-1, 1, n_cl) * leg.beta_max,
            rng.uniform(0, leg.gamma_max, n_cl),
        ],
        -1,
    )
    cl = ol.thigh_closure(leg, qs[:, 0], qs[:, 1])
    sh = ol.shank_crank_slider(leg, qs[:, 2])
    foot_chains = cl.knee + sh.E.mean(axis=-2) + np.array([0.0, 0.0, leg.foot_drop])
    return ThighClosure(
        foot_error=float(np.abs(foot_chains - ol.forward_kinematics(leg, qs)).max()),
        plate_rotation=float(cl.rotation_error.max()),
        residual=float(cl.residual.max()),
        converged=bool(cl.converged.all()),
        theta12_error=float(np.abs(cl.theta[:, 0, 1] - ol.passive_angles(leg, qs[:, 0], qs[:, 1])[0]).max()),
        theta22_printed_error=float(
            np.abs(cl.theta[:, 1, 1] - np.arctan(np.tan(qs[:, 1]) * np.cos(qs[:, 0]))).max()
        ),
    )


@dataclass(frozen=True)
class InverseEq51:
    """Fig. 9: inverse kinematics along the foot trajectory eq. (51), and its round trips."""

    t: Array
    foot: Any  # ol.foot_trajectory_eq51: q, qd, qdd
    displacement: Array  # from the start point (m)
    ik: Any  # ol.inverse_kinematics
    rates: Any  # ol.joint_rates: qd, qdd, singular
    round_trip: float  # m, |FK(IK(p)) − p|
    velocity_error: float  # m/s
    acceleration_error: float  # m/s²


def inverse_eq51(leg: ol.OmniLeg) -> InverseEq51:
    """IK, joint rates and their forward round trips along eq. (51) (T = 5 s)."""
    t51 = np.linspace(0.0, 5.0, 5 * RATE + 1)
    f51 = ol.foot_trajectory_eq51(leg, t51)
    ik = ol.inverse_kinematics(leg, f51.q)
    rates51 = ol.joint_rates(leg, ik.q, f51.qd, f51.qdd)
    return InverseEq51(
        t=t51,
        foot=f51,
        displacement=f51.q - ol.start_point(leg),
        ik=ik,
        rates=rates51,
        round_trip=float(np.abs(ol.forward_kinematics(leg, ik.q) - f51.q).max()),
        velocity_error=float(np.abs(ol.foot_velocity(leg, ik.q, rates51.qd) - f51.qd).max()),
        acceleration_error=float(
            np.abs(ol.foot_acceleration(leg, ik.q, rates51.qd, rates51.qdd) - f51.qdd).max()
        ),
    )


@dataclass(frozen=True)
class ForwardEq52:
    """Fig. 10: forward kinematics along the joint trajectory eq. (52)."""

    t: Array
    position: Array
    velocity: Array
    acceleration: Array
    acceleration_vs_differences: float  # m/s², against the 2nd difference of eq. (11)
    inverse_condition: Array  # σ_min/σ_max of the foot Jacobian


def forward_eq52(leg: ol.OmniLeg) -> ForwardEq52:
    """Foot position, velocity and acceleration along eq. (52), and the Jacobian's conditioning."""
    t52 = np.linspace(0.0, 6.0, 6 * RATE + 1)
    j52 = ol.joint_trajectory_eq52(t52)
    p52 = ol.forward_kinematics(leg, j52.q)
    a52 = ol.foot_acceleration(leg, j52.q, j52.qd, j52.qdd)
    dt52 = t52[1] - t52[0]
    a_fd = (p52[2:] - 2 * p52[1:-1] + p52[:-2]) / dt52**2
    sv = np.linalg.svd(ol.jacobian(leg, j52.q), compute_uv=False)
    return ForwardEq52(
        t=t52,
        position=p52,
        velocity=ol.foot_velocity(leg, j52.q, j52.qd),
        acceleration=a52,
        acceleration_vs_differences=float(np.abs(a_fd - a52[1:-1]).max()),
        inverse_condition=sv[:, -1] / sv[:, 0],
    )


@dataclass(frozen=True)
class TorquesFig11:
    """Fig. 11: motor torques along eq. (52), 0-2 s, with and without the foot force, and with the
    paper's simplified Cardan drive."""

    t: Array
    with_force: Array  # (n, 3) N·m
    free: Array  # (n, 3) N·m
    simplified_difference: Array  # (3,) N·m, max |exact − simplified| per motor


def torques_fig11(leg: ol.OmniLeg) -> TorquesFig11:
    """Inverse dynamics along eq. (52) with Fig. 11's foot force in 0-1 s."""
    t11 = np.linspace(0.0, FIG11_DURATION, int(FIG11_DURATION * RATE) + 1)
    j11 = ol.joint_trajectory_eq52(t11)
    F = np.where((t11 <= FIG11_FORCE_END)[:, None], FIG11_FORCE, 0.0)
    d11 = ol.inverse_dynamics(leg, j11.q, j11.qd, j11.qdd, foot_force=F)
    # paper 2's own theory: the simplified Cardan drive (eqs. (26)-(31)), to which it attributes its
    # 0.1-0.6 % theory-vs-ADAMS errors of Fig. 11
    d11_pr = ol.inverse_dynamics(leg, j11.q, j11.qd, j11.qdd, foot_force=F, paper_as_printed=True)
    return TorquesFig11(
        t=t11,
        with_force=d11.tau,
        free=ol.inverse_dynamics(leg, j11.q, j11.qd, j11.qdd).tau,
        simplified_difference=np.abs(d11_pr.tau - d11.tau).max(axis=0),
    )


@dataclass(frozen=True)
class EngineFig11:
    """Fig. 11 against MuJoCo: engine inverse dynamics and an open-loop forward simulation."""

    relative_error: float
    t: Array
    analytic: Array  # (n, 3) N·m
    engine: Array  # (n, 3) N·m
    motor_error: Array  # (3,) N·m, max |analytic − engine| per motor
    simulation: dict  # robomech.verify.omnileg.forward_simulation: t, q_sim, q_ref, drift


def engine_fig11(leg: ol.OmniLeg) -> EngineFig11:
    """The verification's engine inverse dynamics (201 samples) and forward simulation over 2 s."""
    em = engine_check.build_model(leg)
    err_rel, t_eng, tau_an_eng, tau_en = engine_check.torque_error(leg, em, n=201)
    sim = engine_check.forward_simulation(leg, em, duration=FIG11_DURATION)
    return EngineFig11(err_rel, t_eng, tau_an_eng, tau_en, np.abs(tau_an_eng - tau_en).max(axis=0), sim)


@dataclass(frozen=True)
class GaitFig19:
    """Fig. 19: the gait eq. (53), 3 swing + 3 stance periods."""

    t: Array
    ik: Any  # ol.inverse_kinematics of the foot points
    rates: Any  # ol.joint_rates
    tau: Array  # (n, 3) N·m


def gait_fig19(leg: ol.OmniLeg) -> GaitFig19:
    """IK, rates and inverse dynamics of eq. (53) with the assumed stance load."""
    t19 = np.linspace(0.0, 6.0, 6 * RATE + 1)
    gait = ol.gait_eq53(leg, t19)
    ik19 = ol.inverse_kinematics(leg, gait.foot.q)
    rates19 = ol.joint_rates(leg, ik19.q, gait.foot.qd, gait.foot.qdd)
    F19 = np.where(gait.stance[:, None], np.array([0.0, 0.0, -STANCE_LOAD]), 0.0)
    return GaitFig19(
        t19, ik19, rates19, ol.inverse_dynamics(leg, ik19.q, rates19.qd, rates19.qdd, foot_force=F19).tau
    )


DEXTERITY_LINES = ((0.0, 0.0), (0.6, 0.0), (0.8, 0.8))  # (α, β) of the dexterity-along-γ curves


@dataclass(frozen=True)
class Workspace:
    """The foot workspace, its symmetry (Fig. 3's claim) and its singularity maps."""

    fw: Any  # ol.foot_workspace
    symmetry: Any  # ol.workspace_symmetry of the Monte Carlo samples
    mc_volume: float  # m³
    swap_if_beta_max_06: float  # swap agreement with β_max = 0.6 rad
    grid_feet: Array  # FK of a 15 × 15 × 2 joint grid
    section: Any  # ol.workspace_map over the section β = 0
    singular_curve: Array  # γ = 0 along the section
    gamma_line: Array  # rad
    dexterity_lines: list[Array]  # per DEXTERITY_LINES


def workspace(leg: ol.OmniLeg) -> Workspace:
    """Foot workspace (quadrature and Monte Carlo with 2e5 samples, seed 3), symmetry and conditioning."""
    fw = ol.foot_workspace(leg)
    rng_w = np.random.default_rng(3)
    lo = np.array([-fw.radius_max, -fw.radius_max, fw.depth_min])
    hi = np.array([fw.radius_max, fw.radius_max, fw.depth_max])
    p_w = lo + (hi - lo) * rng_w.random((200_000, 3))
    sym = ol.workspace_symmetry(leg, p_w)
    n_a, n_g = 121, 86
    q_sec = np.stack(
        np.meshgrid(np.linspace(-leg.alpha_max, leg.alpha_max, n_a), [0.0],
                    np.linspace(leg.gamma_min, leg.gamma_max, n_g), indexing="ij"), -1
    )[:, 0]  # fmt: skip
    a_line = np.linspace(-leg.alpha_max, leg.alpha_max, 200)
    g_line = np.linspace(leg.gamma_min, leg.gamma_max, 300)
    return Workspace(
        fw=fw,
        symmetry=sym,
        mc_volume=float(sym.reachable.mean() * np.prod(hi - lo)),
        swap_if_beta_max_06=float(
            ol.workspace_symmetry(dataclasses.replace(leg, beta_max=0.6), p_w[:50_000]).swap.mean()
        ),
        grid_feet=ol.forward_kinematics(leg, ol.joint_grid(leg, (15, 15, 2)).reshape(-1, 3)),
        section=ol.workspace_map(leg, q_sec),
        singular_curve=ol.singular_surface(leg, a_line, 0.0 * a_line),
        gamma_line=g_line,
        dexterity_lines=[
            ol.workspace_map(leg, np.stack([0 * g_line + a0, 0 * g_line + b0, g_line], -1)).dexterity
            for a0, b0 in DEXTERITY_LINES
        ],
    )


LEG_POSES = [(0.0, 0.0, 0.0), (0.5, 0.0, 0.6), (-0.4, 0.7, 1.2)]


@dataclass(frozen=True)
class LegDrawing:
    """Points of the leg at one pose (hip frame, m): rods, plates, shank chains, foot."""

    q: tuple[float, float, float]
    hip_circle: Array
    knee: Array
    rods: Array  # (3, 2, 3): A_i, B_i
    shank_chains: list[Array]  # (3, 3) each: C_i, D_i, E_i
    shank_centre: Array
    foot: Array


def leg_drawings(leg: ol.OmniLeg) -> list[LegDrawing]:
    """The leg from the solved closure and the crank-slider at LEG_POSES."""
    drawings = []
    th = np.linspace(0, 2 * np.pi, 60)
    circ = np.stack([leg.L3 * np.cos(th), leg.L3 * np.sin(th), 0 * th], -1)
    for q in LEG_POSES:
        knee = ol.thigh_closure(leg, q[0], q[1]).knee
        A = np.array([[0, leg.L3, 0], [leg.L3, 0, 0], [0, -leg.L3, 0]])
        sh = ol.shank_crank_slider(leg, q[2])
        drawings.append(
            LegDrawing(
                q=q,
                hip_circle=circ,
                knee=knee,
                rods=np.stack([A, A + knee], 1),
                shank_chains=[np.stack([sh.C[i], sh.D[i], sh.E[i]]) + knee for i in range(3)],
                shank_centre=knee + sh.E.mean(axis=0),
                foot=ol.forward_kinematics(leg, np.array(q)),
            )
        )
    return drawings


def moving_mass(leg: ol.OmniLeg) -> float:
    """Mass (kg) of the moving bodies of the Lagrangian model."""
    mass = sum(
        leg.bodies[k].mass for k in ("knee_plate", "drive_shaft_in", "drive_rod", "drive_shaft_out", "foot")
    )
    mass += 3 * sum(leg.bodies[k].mass for k in ("hip_cross", "thigh_rod", "knee_cross", "crank", "coupler"))
    mass += 2 * leg.bodies["drive_cross"].mass
    return mass


# ---- tables -------------------------------------------------------------------------------------------


def printed_comparison_table(
    leg: ol.OmniLeg,
    ik51: InverseEq51,
    fk52: ForwardEq52,
    f11: TorquesFig11,
    eng: EngineFig11,
    gait: GaitFig19,
) -> Table:
    """Printed values (and magnitudes implied by the printed errors and percentages) vs robomech."""
    disp51, f51, d11_tau, d19_tau, err_motor = (
        ik51.displacement,
        ik51.foot,
        f11.with_force,
        gait.tau,
        eng.motor_error,
    )
    rows = [
        ("Table 2: shank length L2 max = 2 L4 (m)", 0.19, 2 * leg.L4, "m"),
        (
            "Table 2: shank length L2 min = 2 L4 cos 85° (m)",
            0.017,
            float(2 * leg.L4 * np.cos(leg.gamma_max)),
            "m",
        ),
        (
            "eq. (51) max displacement (implied by 42.5 µm = 0.04 %)",
            42.5e-6 / 0.0004,
            float(np.abs(disp51).max()),
            "m",
        ),
        (
            "eq. (51) max speed (implied by 74 µm/s = 0.09 %)",
            74e-6 / 0.0009,
            float(np.abs(f51.qd).max()),
            "m/s",
        ),
        (
            "eq. (51) max acceleration (implied by 1.5 mm/s² = 1.8 %)",
            1.5e-3 / 0.018,
            float(np.abs(f51.qdd).max()),
            "m/s²",
        ),
        (
            "eq. (52) max foot speed (implied by 63 µm/s = 0.08 %)",
            63e-6 / 0.0008,
            float(np.abs(fk52.velocity).max()),
            "m/s",
        ),
        (
            "eq. (52) max foot acceleration (implied by 2.89 mm/s² = 1.9 %)",
            2.89e-3 / 0.019,
            float(np.abs(fk52.acceleration).max()),
            "m/s²",
        ),
        (
            "Fig. 11 max |M1 torque| (implied by 2.1 mN·m = 0.1 %)",
            2.1,
            float(np.abs(d11_tau[:, 1]).max()),
            "N·m",
        ),
        (
            "Fig. 11 max |M2 torque| (implied by 1.5 mN·m = 0.6 %)",
            0.25,
            float(np.abs(d11_tau[:, 0]).max()),
            "N·m",
        ),
        (
            "Fig. 11 max |M3 torque| (implied by 5.2 mN·m = 0.2 %)",
            2.6,
            float(np.abs(d11_tau[:, 2]).max()),
            "N·m",
        ),
        (
            "Fig. 19 max |M2 torque| (implied by 0.14 N·m = 6.3 %)",
            0.14 / 0.063,
            float(np.abs(d19_tau[:, 0]).max()),
            "N·m",
        ),
        (
            "Fig. 19 max |M3 torque| (implied by 0.37 N·m = 8.7 %)",
            0.37 / 0.087,
            float(np.abs(d19_tau[:, 2]).max()),
            "N·m",
        ),
        ("Fig. 19 M1 theoretical torque ('0')", 0.0, float(np.abs(d19_tau[:, 1]).max()), "N·m"),
        ("IK sim vs theory max position error (paper: ADAMS)", 42.5e-6, ik51.round_trip, "m"),
        (
            "Fig. 11 M1 max |theory − simulation| (paper: ADAMS; here MuJoCo)",
            2.1e-3,
            float(err_motor[1]),
            "N·m",
        ),
        (
            "Fig. 11 M2 max |theory − simulation| (paper: ADAMS; here MuJoCo)",
            1.5e-3,
            float(err_motor[0]),
            "N·m",
        ),
        (
            "Fig. 11 M3 max |theory − simulation| (paper: ADAMS; here MuJoCo)",
            5.2e-3,
            float(err_motor[2]),
            "N·m",
        ),
    ]
    return comparison_table(
        "Printed values (and magnitudes implied by the printed errors and percentages) vs robomech",
        rows,
        note=(
            "Rows 'implied by' divide the paper's absolute error by its percentage; they are the "
            "magnitudes the paper's curves must have had. Torque magnitudes depend on the inertias, "
            "which the paper does not give (robomech's are documented assumptions), so they agree in "
            "order of magnitude only. The last four rows compare the paper's ADAMS-vs-theory errors "
            "with robomech's FK(IK(p)) round trip and with the MuJoCo engine built from the same "
            "parameters (robomech.verify.omnileg): the engine agrees to rounding because both are "
            "exact rigid-body models of the same bodies, while the paper's theory simplified the drive."
        ),
    )


def closure_table(c: ThighClosure) -> Table:
    return Table(
        "Thigh closure by the product of exponentials (400 random poses over the joint ranges)",
        ["quantity", "value"],
        [
            ["max |foot(PoE closure + crank-slider) − eq. (11)| (m)", c.foot_error],
            ["max knee-plate rotation (rad) — 'only translates'", c.plate_rotation],
            ["max closure residual |log(T_k T_1⁻¹)|", c.residual],
            ["all converged", c.converged],
            ["max |θ12 − eq. (12)| (rad)", c.theta12_error],
            ["max |θ22 − printed eq. (12)| (rad) (sign error in the print)", c.theta22_printed_error],
        ],
    )


def simplified_drive_table(f11: TorquesFig11, eng: EngineFig11) -> Table:
    return Table(
        "Fig. 11: the paper's simplified Cardan drive (paper_as_printed=True) against the exact drive",
        [
            "motor",
            "max |exact − simplified| (N·m)",
            "paper: theory vs ADAMS (N·m)",
            "MuJoCo vs robomech (N·m)",
        ],
        [
            [
                MOTORS[j],
                float(f11.simplified_difference[j]),
                (1.5e-3, 2.1e-3, 5.2e-3)[j],
                float(eng.motor_error[j]),
            ]
            for j in range(3)
        ],
        note="inverse_dynamics(..., paper_as_printed=True) lets the crosses CS_A4, CS_B4 and the rod "
        "A4B4 turn like chain 1's bodies plus an independent spin γ̇ about Z0 (eqs. (26)-(31)). With "
        "robomech's documented drive inertias (7 g crosses, a 33 g rod) this changes the torques by "
        "~1e-5 N·m, two orders of magnitude below the errors the paper reports against ADAMS and "
        "attributes to this simplification: those errors must have another source (inertias, "
        "the ADAMS model's contacts or solver tolerances; the paper gives neither).",
    )


def workspace_table(w: Workspace) -> Table:
    fw, sym = w.fw, w.symmetry
    return Table(
        "Foot workspace and paper 2's symmetry claim (Section 1: 'the foot workspace is completely "
        "symmetric')",
        ["quantity", "value", "unit"],
        [
            ["volume (quadrature of the horizontal section × stroke)", fw.volume, "m³"],
            ["volume (Monte Carlo, 2e5 IK samples in the bounding box)", w.mc_volume, "m³"],
            ["horizontal section", fw.projected_area, "m²"],
            ["shank stroke 2 L4 (1 − cos 85°)", fw.stroke, "m"],
            ["depth range along Z0", f"{fw.depth_min:.4f} … {fw.depth_max:.4f}", "m"],
            ["max horizontal reach", fw.radius_max, "m"],
            ["samples whose mirror x → −x agrees", float(sym.mirror_x.mean()), "fraction"],
            ["samples whose mirror y → −y agrees", float(sym.mirror_y.mean()), "fraction"],
            ["samples whose swap (x, y) → (−y, −x) agrees", float(sym.swap.mean()), "fraction"],
            [
                "swap agreement if β_max were 0.6 rad (the claim needs α_max = β_max)",
                w.swap_if_beta_max_06,
                "fraction",
            ],
        ],
        note="The workspace has the symmetry of a square about Z0 (mirrors in X0 and Y0, and the α ↔ β "
        "exchange), not rotational symmetry; the horizontal section is a curved square. The claim "
        "holds on every sample for Table 2's ranges read as magnitudes.",
    )


def exactness_table(ik51: InverseEq51, fk52: ForwardEq52, gait: GaitFig19) -> Table:
    return Table(
        "Exactness checks along the paper's trajectories",
        ["check", "max error", "unit"],
        [
            ["eq. (51): |FK(IK(p)) − p|", ik51.round_trip, "m"],
            ["eq. (51): |J q̇ − v| from the IK rates", ik51.velocity_error, "m/s"],
            ["eq. (51): |J q̈ + q̇ᵀHq̇ − a|", ik51.acceleration_error, "m/s²"],
            ["eq. (51): all reachable within Table 2 ranges", float(not ik51.ik.reachable.all()), "—"],
            [
                "eq. (52): foot acceleration vs 2nd difference of eq. (11) (dt = 2.5 ms)",
                fk52.acceleration_vs_differences,
                "m/s²",
            ],
            ["eq. (53): all reachable", float(not gait.ik.reachable.all()), "—"],
            [
                "eq. (51), (53): samples flagged singular by joint_rates (γ ≈ 0)",
                float(ik51.rates.singular.sum() + gait.rates.singular.sum()),
                "—",
            ],
        ],
    )


# ---- figures: each draws computed data -----------------------------------------------------------------


def _three_panel(t, rows, labels, title, ylabels, out_dir: Path, name: str, caption: str) -> Figure:
    """One panel per quantity in ``rows`` (each (n, 3), one line per component) over time ``t``."""
    fig, axs = plt.subplots(len(rows), 1, figsize=(8, 2.6 * len(rows)), sharex=True)
    for ax, data, yl in zip(axs, rows, ylabels, strict=True):
        for j in range(data.shape[-1]):
            ax.plot(t, data[:, j], label=labels[j])
        ax.set_ylabel(yl)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    axs[-1].set_xlabel("time t (s)")
    axs[0].set_title(title)
    return save_figure(fig, out_dir, name, caption)


def ik_foot_figure(ik51: InverseEq51, out_dir: Path) -> Figure:
    return _three_panel(
        ik51.t,
        [ik51.displacement, ik51.foot.qd, ik51.foot.qdd],
        AXES,
        "foot trajectory eq. (51) (displacement from FK(0, 0, 60°))",
        ["displacement (m)", "velocity (m/s)", "acceleration (m/s²)"],
        out_dir,
        "fig09_ik_foot",
        "Fig. 9: foot position, velocity and acceleration of eq. (51), T = 5 s; Z is a lift (against Z0).",
    )


def ik_joints_figure(ik51: InverseEq51, out_dir: Path) -> Figure:
    return _three_panel(
        ik51.t,
        [np.degrees(ik51.ik.q), np.degrees(ik51.rates.qd), np.degrees(ik51.rates.qdd)],
        ("α", "β", "γ"),
        "joint motion from the inverse kinematics of eq. (51)",
        ["angle (deg)", "rate (deg/s)", "acceleration (deg/s²)"],
        out_dir,
        "fig09_ik_joints",
        "Fig. 9: joint angles, rates and accelerations from the IK; FK of them returns the foot trajectory.",
    )


def fk_foot_figure(fk52: ForwardEq52, out_dir: Path) -> Figure:
    return _three_panel(
        fk52.t,
        [fk52.position, fk52.velocity, fk52.acceleration],
        AXES,
        "foot motion for the joint trajectory eq. (52)",
        ["position (m)", "velocity (m/s)", "acceleration (m/s²)"],
        out_dir,
        "fig10_fk_foot",
        "Fig. 10: foot position, velocity and acceleration (hip frame, Z0 down) for eq. (52).",
    )


def jacobian_singularity_figure(fk52: ForwardEq52, out_dir: Path) -> Figure:
    fig, ax = plt.subplots(figsize=(8, 3.2))
    ax.semilogy(fk52.t, fk52.inverse_condition, label="σ_min/σ_max of J")
    ax.axhline(1e-3, color="k", ls=":", label="singular flag threshold (1e-3)")
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("1/cond(J)")
    ax.set_title("Foot Jacobian along eq. (52): singular whenever γ = 0 (t = 0, 3, 6 s)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return save_figure(
        fig,
        out_dir,
        "jacobian_singularity",
        "Conditioning of the foot Jacobian along eq. (52): eq. (47)'s (Jᵀ)⁻¹ does not exist at γ = 0.",
    )


def torques_figure(f11: TorquesFig11, out_dir: Path) -> Figure:
    fig, axs = plt.subplots(3, 1, figsize=(8, 7.5), sharex=True)
    for j in range(3):
        axs[j].plot(f11.t, f11.with_force[:, j], label="with [0, −20, 20] N on the foot in 0–1 s")
        axs[j].plot(f11.t, f11.free[:, j], ls="--", label="no external force")
        axs[j].set_ylabel(f"{MOTORS[j]} torque (N·m)")
        axs[j].grid(True, alpha=0.3)
        axs[j].legend(fontsize=8)
    axs[-1].set_xlabel("time t (s)")
    axs[0].set_title("motor torques along eq. (52), 0–2 s")
    return save_figure(
        fig,
        out_dir,
        "fig11_torques",
        "Fig. 11: motor torques from the "
        "Lagrangian model (22 bodies, documented inertias); the force is applied "
        "to the foot (−JᵀF).",
    )


def engine_figure(eng: EngineFig11, out_dir: Path) -> Figure:
    sim = eng.simulation
    fig, axs = plt.subplots(3, 1, figsize=(8, 7.5), sharex=True)
    for j in range(3):
        col = f"C{j}"
        axs[0].plot(eng.t, eng.analytic[:, j], color=col, label=MOTORS[j])
        axs[0].plot(eng.t, eng.engine[:, j], color=col, ls="none", marker="o", mfc="none", ms=3,
                    markevery=4)  # fmt: skip
        axs[1].semilogy(
            eng.t, np.abs(eng.analytic[:, j] - eng.engine[:, j]) + 1e-18, color=col, label=MOTORS[j]
        )
        drift = np.asarray(sim["q_sim"])[:, j] - np.asarray(sim["q_ref"])[:, j]  # dict of arrays and floats
        axs[2].plot(sim["t"], np.degrees(drift), color=col,
                    ls=("-", "--", "-")[j], label=("α", "β (= α in eq. (52))", "γ")[j])  # fmt: skip
    axs[0].set_ylabel("torque (N·m)")
    axs[0].set_title("analytic torques and MuJoCo inverse dynamics (force in 0–1 s)")
    axs[1].set_ylabel("|analytic − engine| (N·m)")
    axs[2].set_ylabel("drift (deg)")
    axs[2].set_xlabel("time t (s)")
    axs[2].set_title("MuJoCo forward simulation driven by the analytic torques (no foot force)", fontsize=9)
    for ax in axs:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, ncol=3)
    # one entry per motor (colour) and one per source (style), not "MuJoCo" once per motor
    handles, labels = axs[0].get_legend_handles_labels()
    handles += [Line2D([], [], color="k"), Line2D([], [], color="k", ls="", marker="o", mfc="none", ms=3)]
    axs[0].legend(handles, [*labels, "robomech", "MuJoCo"], fontsize=7, ncol=5)
    return save_figure(
        fig,
        out_dir,
        "fig11_engine",
        "Fig. 11c analogue: robomech's torques against "
        "MuJoCo's tree inverse dynamics projected through the closure constraints, "
        "and the drift of an open-loop MuJoCo simulation driven by them.",
    )


def gait_torques_figure(gait: GaitFig19, out_dir: Path) -> Figure:
    fig, axs = plt.subplots(3, 1, figsize=(8, 7.5), sharex=True)
    for j in range(3):
        axs[j].plot(gait.t, gait.tau[:, j], label="robomech")
        for k in range(6):
            if k % 2:
                axs[j].axvspan(k, k + 1, color="0.9")
        axs[j].set_ylabel(f"{MOTORS[j]} torque (N·m)")
        axs[j].grid(True, alpha=0.3)
    axs[0].legend(["motor torque (shaded: stance, 30 N ground reaction)"], fontsize=8)
    axs[-1].set_xlabel("time t (s)")
    axs[0].set_title("motor torques of the gait eq. (53): swing, stance, swing, ...")
    return save_figure(
        fig,
        out_dir,
        "fig19_gait_torques",
        "Fig. 19: gait torques, 3 swing "
        "+ 3 stance periods (T = 1 s, L = 0.1 m, H = 0.05 m); stance load assumed.",
    )


def workspace_figure(w: Workspace, out_dir: Path) -> Figure:
    fw = w.fw
    fig, axs = plt.subplots(1, 3, figsize=(15, 4.6))
    ax = axs[0]
    ax.plot(fw.boundary[:, 0], fw.boundary[:, 1], "k-", lw=1.5, label="boundary (|α| or |β| = 65°)")
    ax.plot(w.grid_feet[:, 0], w.grid_feet[:, 1], ".", ms=2, color="C0", label="joint grid (15 × 15)")
    ax.set_aspect("equal")
    ax.set_xlabel("X0 (m)")
    ax.set_ylabel("Y0 (m)")
    ax.set_title("top view: four-fold symmetric (α_max = β_max)", fontsize=9)
    ax.legend(fontsize=7, loc="upper right")
    ax.grid(True, alpha=0.3)
    ax = axs[1]
    wm_sec = w.section
    cond_plot = np.log10(np.where(np.isfinite(wm_sec.cond), wm_sec.cond, np.nan))
    pc = ax.pcolormesh(
        wm_sec.foot[..., 1], -wm_sec.foot[..., 2], cond_plot, shading="gouraud", cmap="viridis"
    )
    fig.colorbar(pc, ax=ax, label="log10 cond(J)")
    surf = w.singular_curve
    ax.plot(surf[:, 1], -surf[:, 2], "r-", lw=2, label="γ = 0: singular (J's 3rd column vanishes)")
    ax.set_xlabel("Y0 (m)")
    ax.set_ylabel("−Z0 (m, up)")
    ax.set_title("section X0 = 0 (β = 0): conditioning of the foot Jacobian", fontsize=9)
    ax.legend(fontsize=7, loc="upper center")
    ax = axs[2]
    for (a0, b0), dexterity, col in zip(DEXTERITY_LINES, w.dexterity_lines, ("C0", "C1", "C2"), strict=True):
        ax.semilogy(np.degrees(w.gamma_line), dexterity, color=col,
                    label=f"α = {np.degrees(a0):.0f}°, β = {np.degrees(b0):.0f}°")  # fmt: skip
    ax.axhline(1e-3, color="k", ls=":", label="singular flag (1e-3)")
    ax.set_xlabel("γ (deg)")
    ax.set_ylabel("1 / cond(J)")
    ax.set_title("dexterity along γ: → 0 at γ = 0 only", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.suptitle(
        f"Foot workspace over Table 2's ranges: volume {fw.volume * 1e3:.2f} L "
        f"(horizontal section {fw.projected_area * 1e4:.0f} cm² × stroke {fw.stroke * 1e3:.0f} mm)"
    )
    return save_figure(
        fig,
        out_dir,
        "workspace_singularity",
        "Fig. 3's claim made precise: the foot workspace (a vertical sweep of the knee's sphere patch "
        "over the shank stroke) and its singularity map; the whole bottom surface (γ = 0, the leg "
        "fully extended) is singular.",
    )


def _draw_leg(ax, d: LegDrawing, color: str) -> None:
    """Draw one pose (Z0 down: −z is plotted up)."""
    knee = d.knee
    for P, lw in ((d.hip_circle, 1.0), (d.hip_circle + knee, 1.0)):
        ax.plot(P[:, 0], P[:, 1], -P[:, 2], color=color, lw=lw)
    for A, B in d.rods:
        ax.plot([A[0], B[0]], [A[1], B[1]], [-A[2], -B[2]], color=color, lw=2)
    ax.plot([0, knee[0]], [0, knee[1]], [0, -knee[2]], color=color, lw=1, ls="--")
    for pts in d.shank_chains:
        ax.plot(pts[:, 0], pts[:, 1], -pts[:, 2], color=color, lw=1.5, marker="o", ms=2)
    e_c, foot = d.shank_centre, d.foot
    ax.plot([e_c[0], foot[0]], [e_c[1], foot[1]], [-e_c[2], -foot[2]], color=color, lw=2)
    ax.scatter([foot[0]], [foot[1]], [-foot[2]], color=color, s=20)


def leg_poses_figure(drawings: list[LegDrawing], out_dir: Path) -> Figure:
    fig = plt.figure(figsize=(9, 4.5))
    colors = ["tab:blue", "tab:orange", "tab:green"]
    for i, (d, col) in enumerate(zip(drawings, colors, strict=True)):
        q = d.q
        ax = fig.add_subplot(1, 3, i + 1, projection="3d")
        _draw_leg(ax, d, col)
        ax.set_title(
            f"α={np.degrees(q[0]):.0f}°, β={np.degrees(q[1]):.0f}°, γ={np.degrees(q[2]):.0f}°", fontsize=9
        )
        ax.set_xlabel("X0 (m)", fontsize=7)
        ax.set_ylabel("Y0 (m)", fontsize=7)
        ax.set_zlabel("−Z0 (m, up)", fontsize=7)
        ax.set_xlim(-0.15, 0.15)
        ax.set_ylim(-0.15, 0.15)
        ax.set_zlim(-0.52, 0.02)
        ax.tick_params(labelsize=6)
        ax.set_box_aspect((0.3, 0.3, 0.54))
    fig.suptitle("OmniLeg at three poses: thigh rods A_iB_i, plates, shank chains C_iD_iE_i, foot")
    return save_figure(
        fig,
        out_dir,
        "leg_poses",
        "The leg drawn from the solved closure and the crank-slider (hip plate at the top; Z0 points down).",
    )


# ---- report -------------------------------------------------------------------------------------------


def summary(leg: ol.OmniLeg, closure: ThighClosure, f11: TorquesFig11, eng: EngineFig11, w: Workspace) -> str:
    """The report's opening paragraphs, from the computed results."""
    fw, mass, simplified = w.fw, moving_mass(leg), float(f11.simplified_difference.max())
    drift_deg = np.degrees(float(eng.simulation["drift"]))
    text = (
        "Exact: the foot position is eq. (11); the thigh is also solved as three product-of-exponentials "
        "chains with the closure T1 = T2 = T3 solved numerically, and the foot from that closure plus the "
        f"crank-slider shank agrees with eq. (11) to {closure.foot_error:.1e} m, with the knee plate purely "
        "translating. The inverse kinematics is eq. (13) corrected (sign of α, bracket of γ); the "
        "Jacobian and Hessian are analytic and the foot accelerations along eqs. (51)-(53) are exact.\n\n"
        "Simulated with assumptions: the paper gives no masses or inertias, so the torques of Figs. 11 "
        f"and 19 come from a Lagrangian model of {len(BODY_NAMES)} rigid bodies with documented, "
        f"plausible inertial parameters ({mass:.2f} kg moving); they agree with the paper in order of "
        "magnitude only. The start point of eqs. (51)/(53), the direction of Z (a lift), the stance "
        f"reversal of eq. (53) and the stance load ({STANCE_LOAD:.0f} N) are stated readings, not printed "
        "values. The external force of Fig. 11 is applied to the foot (−JᵀF), while eqs. (49)-(50) add "
        "+JᵀF_f.\n\n"
        "Departures from the print: eq. (9) x lacks sin β, eq. (12) θ22 sign, eq. (13) α sign and γ "
        "bracket, eq. (16) sign, eq. (44) potential, eq. (46) garbled; the foot Jacobian is singular at "
        "γ = 0 (t = 0, 3, 6 s of eq. (52)), so eq. (47)'s (Jᵀ)⁻¹ is replaced by a flagged, damped solve. "
        "eq. (52) drives γ below Table 2's 0° for 3 < t < 6 s. See docs/mechanisms/omnileg.md."
    )
    text += (
        f"\n\nWorkspace: {fw.volume * 1e3:.2f} L over Table 2's ranges, with the four-fold symmetry of a "
        "square about Z0 (Section 1's 'completely symmetric' holds on every sample for α_max = β_max); its "
        "whole bottom surface (γ = 0) is singular. The paper's simplified Cardan drive "
        f"(paper_as_printed=True) moves the Fig. 11 torques by only {simplified:.1e} N·m: "
        "it does not explain the paper's "
        "mN·m theory-vs-ADAMS errors."
    )
    text += (
        "\n\nVerified against MuJoCo (the paper used ADAMS): torques agree to "
        f"{eng.relative_error:.1e} relative "
        "along eq. (52) with Fig. 11's force; driven open-loop by the analytic torques, the engine follows "
        f"eq. (52) within {drift_deg:.1e}° over {FIG11_DURATION:.0f} s "
        "(soft-constraint drift)."
    )
    return text


def report_data(
    leg: ol.OmniLeg,
    closure: ThighClosure,
    ik51: InverseEq51,
    f11: TorquesFig11,
    eng: EngineFig11,
    gait: GaitFig19,
    w: Workspace,
    animation: dict,
) -> dict:
    """The machine-readable results (``results.json``'s ``data``)."""
    return {
        "fig11_simplified_drive_max_diff_Nm": f11.simplified_difference,
        "animation": animation,
        "workspace_volume_m3": w.fw.volume,
        "workspace_symmetry_holds": bool(w.symmetry.holds.all()),
        "engine_torque_rel_error": eng.relative_error,
        "engine_sim_drift_rad": float(eng.simulation["drift"]),
        "closure_error_m": closure.foot_error,
        "ik_round_trip_m": ik51.round_trip,
        "fig11_max_torque_Nm": np.abs(f11.with_force).max(axis=0),
        "fig19_max_torque_Nm": np.abs(gait.tau).max(axis=0),
        "moving_mass_kg": moving_mass(leg),
    }


def run(out_dir: Path, progress: Progress) -> StudyResult:
    leg = ol.OmniLeg.paper()
    progress.plan(
        [
            "thigh closure",
            "Figs. 9, 10",
            "Fig. 11",
            "Fig. 11 against MuJoCo",
            "Fig. 19",
            "workspace",
            "animation",
        ]
    )
    progress.step("thigh closure (product of exponentials) vs eq. (11)")
    closure = thigh_closure(leg)
    progress.step("Figs. 9, 10: inverse kinematics along eq. (51), forward kinematics along eq. (52)")
    ik51, fk52 = inverse_eq51(leg), forward_eq52(leg)
    progress.step("Fig. 11: inverse dynamics along eq. (52) with a foot force")
    f11 = torques_fig11(leg)
    progress.step("Fig. 11 against MuJoCo: engine inverse dynamics and forward simulation")
    eng = engine_fig11(leg)
    progress.step("Fig. 19: gait eq. (53), 3 swing + 3 stance")
    gait = gait_fig19(leg)
    progress.step("foot workspace, singularity map and the symmetry claim")
    w, drawings = workspace(leg), leg_drawings(leg)

    tables = [
        printed_comparison_table(leg, ik51, fk52, f11, eng, gait),
        closure_table(closure),
        simplified_drive_table(f11, eng),
        workspace_table(w),
        exactness_table(ik51, fk52, gait),
    ]
    figures = [
        ik_foot_figure(ik51, out_dir),
        ik_joints_figure(ik51, out_dir),
        fk_foot_figure(fk52, out_dir),
        jacobian_singularity_figure(fk52, out_dir),
        torques_figure(f11, out_dir),
        engine_figure(eng, out_dir),
        gait_torques_figure(gait, out_dir),
    ]
    progress.step("animation of the gait eq. (53)")
    anim, anim_check = gait_animation(leg, out_dir)
    figures += [anim.figure, workspace_figure(w, out_dir), leg_poses_figure(drawings, out_dir)]
    return StudyResult(
        name="omnileg",
        title="Paper 2: the OmniLeg serial-parallel leg — kinematics and dynamics",
        source=cite(2),
        summary=summary(leg, closure, f11, eng, w),
        tables=tables,
        figures=figures,
        data=report_data(leg, closure, ik51, f11, eng, gait, w, {**anim.summary(), **anim_check}),
    )


STUDY = Study(
    name="omnileg",
    title="Paper 2: OmniLeg serial-parallel leg",
    source=PAPERS[2].short(),
    run=run,
    requires=("mujoco",),  # the engine overlays (robomech.verify); skipped without robomech[verify]
)
