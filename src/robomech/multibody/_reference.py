"""The assembled reference configuration of a description (internal).

A description's own reference (MuJoCo's ``qpos0``: hinge/slide ``ref``, identity quaternions, a free
body's pose) need not satisfy its closures: a five-bar typed by link lengths with every link along x,
two ``connect`` sites that do not coincide at ``qpos0``.  As a CAD sketch solver would, the layer then
assembles it from that pose (the closure's Levenberg-Marquardt iteration over every coordinate but a
floating base, steps capped at 0.5 rad, from the pose and a few fixed perturbations of it: the
nearest assembly) and uses the result as the reference
``mech.q0`` (FK's default guess, mobility's generic configuration).  A description already assembled
keeps ``qpos0`` exactly; one that cannot assemble is a ``ValueError`` with its residual, raised when
it is loaded (``from_mjcf``, ``Builder.build``) or first used.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np

from ._assembly import CONVERGED_RTOL, floating_base_dofs

__all__ = ["ASSEMBLY_MAX_ITER", "PERTURBATION", "START_PERTURBATIONS", "assembled_reference"]

# Iterations allowed to assemble a reference: a description far from closed (links typed along one
# axis) may need many capped 0.5 rad steps before Newton's quadratic convergence; 400 leaves room for
# rotations of several radians and is still milliseconds.
ASSEMBLY_MAX_ITER = 400
# Extra starts around the given pose (fixed seed), each coordinate moved by up to PERTURBATION rad (or
# PERTURBATION L): enough to leave a singular sketch pose, small against the branch's extent.
START_PERTURBATIONS = 8
PERTURBATION = 0.2


def assembled_reference(mech, tree, cs, tables) -> np.ndarray:
    """``qpos0`` if it satisfies the closures to ``CONVERGED_RTOL * L``, else the assembly nearest to it.

    Called by the compile step (``_compile``) with the description's just-built tree, closure rows and
    their packed tables, before the reference rank is taken there (so the rank is that of the assembled
    reference); the residual and the assembly run on the compiled kernels."""
    from ._compiled import closure_solve, compiled_integrate, compiled_resjac  # numba loads on first call

    q0 = np.array(tree.q0, dtype=float)
    if cs.m == 0:
        return q0
    tol = CONVERGED_RTOL * tree.length
    r0 = float(np.max(np.abs(compiled_resjac(tables, q0[None], False)[0])))
    if r0 <= tol:
        return q0
    # the compiled model is being built: the assembly kernel runs on the tables of the tree and rows
    # given here (floating_base_dofs reads only .tree and .closures)
    view: Any = SimpleNamespace(tree=tree, closures=mech.closures)
    free = np.setdiff1d(np.arange(tree.nv), floating_base_dofs(view))
    # the pose itself and a few fixed perturbations of it: a sketch typed with every link along one axis
    # is a singular start (the closure's gradient vanishes there), as a CAD solver also perturbs it
    rng = np.random.default_rng(0)
    dv = np.zeros((1 + START_PERTURBATIONS, tree.nv))
    w = np.where(tree.dof_translational, tree.length, 1.0)[free]
    dv[1:, free] = PERTURBATION * w * rng.uniform(-1.0, 1.0, (START_PERTURBATIONS, len(free)))
    starts = compiled_integrate(tables, np.repeat(q0[None], 1 + START_PERTURBATIONS, axis=0), dv)
    wstep = np.where(tree.dof_translational, 1.0 / tree.length, 1.0)[free]
    q, rc, _, _ = closure_solve(tables, starts, free, wstep, ASSEMBLY_MAX_ITER)
    ok = rc <= tol
    if not ok.any():
        best = int(np.argmin(rc))
        worst = cs.row_owner[int(np.argmax(np.abs(compiled_resjac(tables, q[best : best + 1], False)[0][0])))]
        raise ValueError(
            f"Expected the description {mech.name!r} to assemble (closures closed to "
            f"{CONVERGED_RTOL:g} L = {tol:.3g} m): from its reference pose (residual {r0:.3g} m) the "
            f"closest configuration found leaves residual {float(rc[best]):.3g} m, largest at {worst!r}."
        )
    # the assembly nearest to the given pose (rotations in rad, translations over L); the unperturbed
    # start's own solution first
    if ok[0]:
        return q[0]
    wq = np.where(tree.dof_translational, 1.0 / tree.length, 1.0)
    dist = [
        np.inf if not ok[i] else float(np.linalg.norm(_difference(tree, q[i], q0) * wq))
        for i in range(len(q))
    ]
    return q[int(np.argmin(dist))]


def _difference(tree, q: np.ndarray, q0: np.ndarray) -> np.ndarray:
    """Velocity-coordinate difference ``q - q0`` (nv,): hinge/slide subtract; ball/free rotations by the
    rotation-vector norm of the relative quaternion (its direction does not matter for a distance)."""
    out = np.zeros(tree.nv)
    for k in range(len(tree.jnt_names)):
        typ, qa, da = tree.jnt_type[k], tree.jnt_qadr[k], tree.jnt_dadr[k]
        if typ <= 1:
            out[da] = q[qa] - q0[qa]
        else:
            a = qa if typ == 2 else qa + 3
            if typ == 3:
                out[da : da + 3] = q[qa : qa + 3] - q0[qa : qa + 3]
            c = min(1.0, abs(float(np.dot(q[a : a + 4], q0[a : a + 4]))))
            out[da + (0 if typ == 2 else 3)] = 2.0 * np.arccos(c)
    return out
