"""Closure equations ``phi(q) = 0`` compiled to rows (internal); the compiled kernels evaluate them.

:func:`compile_constraints` turns a description's closures and couplings into the row blocks below,
which the compile step packs into ``_compile.Tables``; the residual, ``K`` and ``dK/dt`` are evaluated
by the kernels (``_compiled.resjac``, ``kdot_block``), their numpy formulation being the tests'
reference (tests/multibody/_reference.py).

Rows, in the order of ``mech.closures`` then ``mech.couplings`` (all in length units, so that a
rotation error counts as the arc it sweeps at the characteristic length ``L``):

* point pair (``connect``; ``revolute`` gives two, the second ``L`` along the axis): ``p1 - p2`` (3);
* rigid (``weld``): ``p1 - p2`` at MuJoCo's anchor (3), then the rotation error
  ``L/2 sum_i (R_t e_i) × (R_2 e_i)`` with ``R_t = R_1 R_rel`` (3);
* coupling: ``s ((q1 - ref1) - poly(q2 - ref2))`` with ``s = L`` for a hinge ``q1``, 1 for a slide.

``K (N, m, nv)`` is the velocity constraint matrix: ``K qd`` is the time derivative of the point and
coupling rows and ``L (ω_2 - ω_1)`` for the rotation rows, which is the exact derivative of the
rotation residual wherever it vanishes (on the constraint manifold).  So ``K qd = 0`` is exactly the
set of admissible velocities, and ``K qdd + Kdot qd = 0`` exactly the admissible accelerations, at
every assembled configuration; away from it, Newton with ``K`` converges as with the exact Jacobian.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._tree import Tree, quat_to_matrix

__all__ = ["Constraints", "compile_constraints"]


@dataclass(frozen=True, eq=False)
class Constraints:
    """Compiled closure rows.  ``blocks``: (kind, data) with kind in ``point``, ``rot``, ``coupling``."""

    blocks: tuple[tuple, ...]
    m: int
    row_owner: tuple[str, ...]  # (m,) the closure or coupling each row comes from
    row_kind: tuple[str, ...]  # (m,) "point", "rot" or "coupling"


def _h(x) -> np.ndarray:
    return np.array([*x, 1.0])


def compile_constraints(mech, tree: Tree) -> Constraints:
    L = tree.length
    blocks: list[tuple] = []
    owner: list[str] = []
    kind: list[str] = []

    def add(k: str, data: tuple, name: str, rows: int) -> None:
        blocks.append((k, data))
        owner.extend([name] * rows)
        kind.extend([k] * rows)

    for c in mech.closures:
        b1, b2 = tree.body_index(c.body1), tree.body_index(c.body2)
        if c.kind == "point":
            add("point", (b1, _h(c.anchor1), b2, _h(c.anchor2)), c.name, 3)
        elif c.kind == "revolute":
            add("point", (b1, _h(c.anchor1), b2, _h(c.anchor2)), c.name, 3)
            a1 = np.asarray(c.anchor1) + L * np.asarray(c.axis)
            a2 = np.asarray(c.anchor2) + L * np.asarray(c.axis2)
            add("point", (b1, _h(a1), b2, _h(a2)), c.name, 3)
        else:
            Rrel = quat_to_matrix(np.asarray(c.relquat))
            p1_local = np.asarray(c.relpos) + Rrel @ np.asarray(c.anchor2)  # MuJoCo's eq_data[3:6]
            add("point", (b1, _h(p1_local), b2, _h(c.anchor2)), c.name, 3)
            add("rot", (b1, Rrel, b2), c.name, 3)
    for c in mech.couplings:
        j1 = tree.joint_index(c.joint1)
        s = L if tree.jnt_type[j1] == 0 else 1.0
        if c.joint2 is None:
            j2d, j2q, ref2 = -1, -1, 0.0
        else:
            j2 = tree.joint_index(c.joint2)
            j2d, j2q, ref2 = int(tree.jnt_dadr[j2]), int(tree.jnt_qadr[j2]), float(tree.jnt_ref[j2])
        data = (
            int(tree.jnt_dadr[j1]),
            int(tree.jnt_qadr[j1]),
            float(tree.jnt_ref[j1]),
            j2d,
            j2q,
            ref2,
            np.asarray(c.polycoef, float),
            s,
        )
        add("coupling", data, c.name, 1)
    return Constraints(blocks=tuple(blocks), m=len(owner), row_owner=tuple(owner), row_kind=tuple(kind))
