"""Demonstration study: textbook mechanisms through the reusable machinery.

* Mobility of four classic mechanisms by screw theory, beside the Grübler–Kutzbach count (which fails
  for the over-constrained ones: that is the point of paper 5's screw-theory analysis).
* A UR5-like 6R arm: product-of-exponentials pose, space Jacobian checked against central differences,
  and its dexterity (1/condition) along a joint sweep.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from robomech.analysis import mobility, workspace
from robomech.kinematics import jacobian_space, poe_fk
from robomech.spatial import screw_from_axis
from robomech.testing import numerical_space_jacobian

from ._core import Figure, Progress, Study, StudyResult, Table
from ._plot import plt, save_figure

# Universal Robots UR5 in the space frame at home (Lynch & Park, Modern Robotics, Example 4.5), metres.
_W1, _W2, _L1, _L2, _H1, _H2 = 0.109, 0.082, 0.425, 0.392, 0.089, 0.095
UR5_M = np.array([[-1, 0, 0, _L1 + _L2], [0, 0, 1, _W1 + _W2], [0, 1, 0, _H1 - _H2], [0, 0, 0, 1.0]])
UR5_SCREWS = np.array(
    [
        [0, 0, 1, 0, 0, 0],
        [0, 1, 0, -_H1, 0, 0],
        [0, 1, 0, -_H1, 0, _L1],
        [0, 1, 0, -_H1, 0, _L1 + _L2],
        [0, 0, -1, -_W1, _L1 + _L2, 0],
        [0, 1, 0, _H2 - _H1, 0, _L1 + _L2],
    ],
    dtype=float,
)


def textbook_chains() -> dict[str, list[np.ndarray]]:
    """Joint screws of four textbook mechanisms at a generic configuration (unit lengths)."""
    z = np.array([0.0, 0.0, 1.0])
    four_bar = [
        screw_from_axis(np.stack([z, z]), np.array([[0.0, 0, 0], [0.3, 1.0, 0]])),
        screw_from_axis(np.stack([z, z]), np.array([[2.0, 0, 0], [1.6, 1.2, 0]])),
    ]
    rng = np.random.default_rng(1)
    spherical = [screw_from_axis(rng.normal(size=(3, 3)), np.zeros((3, 3))) for _ in range(3)]
    # 3-UPU translational (Tsai): in each leg the inner U axis is parallel to the outer U axis.
    upu = []
    for k in range(3):
        a = 2 * np.pi * k / 3
        base = np.array([np.cos(a), np.sin(a), 0.0])
        top = 0.5 * base + np.array([0.1, 0.05, 1.0])
        d = top - base
        u1 = np.array([-np.sin(a), np.cos(a), 0.0])
        u2 = np.cross(d, u1)
        upu.append(
            np.vstack(
                [
                    screw_from_axis(u1, base),
                    screw_from_axis(u2, base),
                    screw_from_axis(d, base, np.inf),
                    screw_from_axis(u2, top),
                    screw_from_axis(u1, top),
                ]
            )
        )
    # 3-RPS: revolute tangent at the base, prismatic leg, spherical joint at the platform.
    rps = []
    for k in range(3):
        a = 2 * np.pi * k / 3
        base = np.array([np.cos(a), np.sin(a), 0.0])
        top = np.array([0.5 * np.cos(a), 0.5 * np.sin(a), 1.0])
        tangent = np.array([-np.sin(a), np.cos(a), 0.0])
        rps.append(
            np.vstack(
                [
                    screw_from_axis(tangent, base),
                    screw_from_axis(top - base, base, np.inf),
                    screw_from_axis(np.eye(3), np.broadcast_to(top, (3, 3))),
                ]
            )
        )
    return {
        "planar four-bar (RR-RR)": four_bar,
        "3-RRR spherical": spherical,
        "3-UPU translational": upu,
        "3-RPS": rps,
    }


EXPECTED_DOF = {"planar four-bar (RR-RR)": 1, "3-RRR spherical": 3, "3-UPU translational": 3, "3-RPS": 3}
UR5_Q0 = np.array([0.3, -0.8, 1.2, -0.4, 0.9, 0.2])


# ---- compute ------------------------------------------------------------------------------------------


def textbook_mobility() -> dict[str, Any]:
    """``mobility.analyze`` of each textbook mechanism, by name."""
    return {name: mobility.analyze(chains) for name, chains in textbook_chains().items()}


def ur5_jacobian_error() -> tuple[float, float]:
    """Max |J − J_fd| of the UR5 space Jacobian at UR5_Q0 against central differences, and cond(J)."""
    J = jacobian_space(UR5_SCREWS, UR5_Q0)
    J_fd = numerical_space_jacobian(lambda q: poe_fk(UR5_M, UR5_SCREWS, q), UR5_Q0)
    return float(np.abs(J - J_fd).max()), float(workspace.condition_number(J))


def ur5_elbow_sweep() -> tuple[np.ndarray, np.ndarray]:
    """The elbow angle q3 over ±180° (other joints at UR5_Q0) and the dexterity 1/cond(J_s) along it."""
    q3 = np.linspace(-np.pi, np.pi, 721)
    qs = np.tile(UR5_Q0, (q3.size, 1))
    qs[:, 2] = q3
    return q3, workspace.singularity_map(jacobian_space(UR5_SCREWS, qs)).dexterity


# ---- tables and figures -------------------------------------------------------------------------------


def mobility_table(results: dict[str, Any]) -> Table:
    rows = [
        [
            name,
            EXPECTED_DOF[name],
            m.dof,
            f"{m.rotational_dof}R{m.translational_dof}T",
            m.common_constraints,
            m.redundant_constraints,
            m.gruebler_kutzbach,
            m.modified_gruebler_kutzbach,
        ]
        for name, m in results.items()
    ]
    return Table(
        "Mobility by screw theory vs Grübler–Kutzbach",
        ["mechanism", "textbook DOF", "screw DOF", "type", "common λ", "redundant ν", "G–K", "modified G–K"],
        rows,
    )


def jacobian_table(error: float, cond: float) -> Table:
    return Table(
        "UR5 space Jacobian at q0: analytic vs central differences",
        ["quantity", "value"],
        [["max |J - J_fd|", error], ["condition number", cond]],
    )


def dexterity_figure(q3: np.ndarray, dexterity: np.ndarray, out_dir: Path) -> Figure:
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(np.degrees(q3), dexterity)
    ax.set_xlabel("elbow angle q3 (deg)")
    ax.set_ylabel("dexterity 1/cond(J)")
    ax.set_title("UR5 dexterity along an elbow sweep (zeros: singular configurations)")
    ax.grid(True, alpha=0.3)
    caption = (
        "Dexterity 1/cond(J_s) of a UR5-like arm vs elbow angle (other joints fixed); it vanishes at the "
        "elbow singularities q3 = 0, ±180° and where the wrist aligns"
    )
    return save_figure(fig, out_dir, "ur5_dexterity", caption)


def run(out_dir: Path, progress: Progress) -> StudyResult:
    progress.plan(["mobility", "UR5"])
    progress.step("mobility of textbook mechanisms")
    mob = textbook_mobility()
    progress.step("UR5 Jacobian and dexterity sweep")
    jac_error, cond = ur5_jacobian_error()
    q3, dexterity = ur5_elbow_sweep()
    data: dict[str, Any] = {
        name: {"dof": m.dof, "gk": m.gruebler_kutzbach, "modified_gk": m.modified_gruebler_kutzbach}
        for name, m in mob.items()
    }
    data["ur5_min_dexterity_deg"] = float(np.degrees(q3[np.argmin(dexterity)]))
    return StudyResult(
        name="demo",
        title="Demonstration: screw-theory mobility and a 6R arm's Jacobian",
        source="textbook mechanisms; UR5 screw axes from Lynch & Park, Modern Robotics (2017), Example 4.5",
        summary=(
            "Mobility is computed from each chain's joint screws: constraint screws are the wrenches "
            "reciprocal to a chain's twists, the platform's twists are reciprocal to the union of the "
            "constraints. The spatial Grübler–Kutzbach count is shown beside it: it is wrong for the "
            "over-constrained planar and spherical mechanisms, which is why paper 5 counts constraints."
        ),
        tables=[mobility_table(mob), jacobian_table(jac_error, cond)],
        figures=[dexterity_figure(q3, dexterity, out_dir)],
        data=data,
    )


STUDY = Study(name="demo", title="Demonstration: mobility and a 6R Jacobian", source="textbook", run=run)
