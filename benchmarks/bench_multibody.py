"""Issue 12: forward kinematics + site Jacobian of 10^5 Delta and 10^5 Stewart configurations.

The batched generic layer (``mb.forward_kinematics`` then ``mb.site_jacobian``; large batches run the
compiled per-sample kernels of ``robomech/multibody/_compiled.py``) against

* the obvious per-sample alternative: a loop of ``scipy.optimize.least_squares`` on the same closure
  equations (the passive coordinates as unknowns, the residual and its analytic Jacobian ``K_p`` from
  the layer's own closure functions on one sample; ``method="trf"``: "lm" refuses the Delta, whose
  idle rod spins leave more unknowns than equations), then the site Jacobian of that
  one sample (``mb.site_jacobian``, numpy path);
* beside it, MuJoCo's own per-sample cost of evaluating the constraint Jacobian at one configuration
  (``mj_kinematics`` + ``mj_comPos`` + ``mj_makeConstraint`` on the exported model): no assembly, just
  what the engine pays to form the matrix the layer forms and solves with.

The loop baselines are timed on ``N_ALT_*`` samples and scaled to ``N`` (they are linear in the count).
"""

from __future__ import annotations

import numpy as np

from robomech import multibody as mb
from robomech.multibody._compile import compile_model
from robomech.multibody._compiled import compiled_integrate

from _harness import Workload

N = 100_000
# Per-sample loops are timed on this many samples and scaled: the scipy loop costs 0.1-0.4 s per
# sample here, MuJoCo's constraint Jacobian ~10 us.
N_ALT_SCIPY = 50
N_ALT_MUJOCO = 2000
# The batched runs take ~10-30 s each on the shared 2-core machine: one timed run after the warm-up.
REPEATS = 1
# Inputs within 0.08 rad (hinges) / 0.08 L (slides) of the reference configuration: inside the
# workspace (every sample assembles, checked in tests/multibody/test_gallery.py for the same spread).
SPREAD = 0.08


def _inputs(mech: mb.Mechanism, n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    scale = np.where(mech.tree.dof_translational[mech.tree.act_dof], mech.length, 1.0)
    return mech.q0[mech.tree.act_qadr] + SPREAD * scale * rng.uniform(-1, 1, (n, len(mech.actuated)))


def batched(mech: mb.Mechanism, qa: np.ndarray, site: str) -> tuple[np.ndarray, np.ndarray]:
    fk = mb.forward_kinematics(mech, qa)
    return fk.q, mb.site_jacobian(mech, fk.q, site)


def scipy_loop(mech: mb.Mechanism, qa: np.ndarray, site: str) -> list[np.ndarray]:
    """Per sample: least_squares on the closure residual over the passive coordinates, then J."""
    from scipy.optimize import least_squares

    tree, model = mech.tree, compile_model(mech)
    free = np.setdiff1d(np.arange(tree.nv), tree.act_dof)
    out = []
    for x in qa:
        q0 = tree.q0.copy()
        q0[tree.act_qadr] = x

        def q_of(dx, q0=q0):
            dv = np.zeros((1, tree.nv))
            dv[0, free] = dx
            return compiled_integrate(model, q0[None], dv)

        def fun(dx, q_of=q_of):
            q = q_of(dx)
            return mb.constraint_residual(mech, q)[0]

        def jac(dx, q_of=q_of):
            q = q_of(dx)
            return mb.constraint_jacobian(mech, q)[0][:, free]

        sol = least_squares(
            fun, np.zeros(len(free)), jac=jac, method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12
        )
        q = q_of(sol.x)
        out.append(mb.site_jacobian(mech, q, site))
    return out


def mujoco_loop(model, data, qs: np.ndarray) -> None:
    import mujoco

    for q in qs:
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        mujoco.mj_makeConstraint(model, data)


def workloads() -> list[Workload]:
    import mujoco

    out = []
    for name, site in (("delta", "tcp"), ("stewart", "platform")):
        mech = mb.gallery.load(name)
        qa = _inputs(mech, N)
        qa_alt = qa[:N_ALT_SCIPY]
        q_alt = mb.forward_kinematics(mech, qa[:N_ALT_MUJOCO]).q
        model = mujoco.MjModel.from_xml_path(str(mb.gallery.path(name)))
        data = mujoco.MjData(model)
        nb = 8 * N * (len(mech.actuated) + mech.nq + 6 * len(mech.actuated))  # q_act in; q, J out
        out.append(
            Workload(
                name=f"multibody {name}: FK + site Jacobian",
                group="12",
                run=lambda mech=mech, qa=qa, site=site: batched(mech, qa, site),
                n=N,
                bytes_moved=nb,
                alternative=lambda mech=mech, qa=qa_alt, site=site: scipy_loop(mech, qa, site),
                n_alt=N_ALT_SCIPY,
                alternative_name="loop: scipy least_squares + J",
                target_speedup=50,
                repeats=REPEATS,
            )
        )
        out.append(
            Workload(
                name=f"multibody {name}: FK + site Jacobian",
                group="12",
                run=lambda mech=mech, qa=qa, site=site: batched(mech, qa, site),
                n=N,
                bytes_moved=nb,
                alternative=lambda model=model, data=data, q=q_alt: mujoco_loop(model, data, q),
                n_alt=N_ALT_MUJOCO,
                alternative_name="loop: MuJoCo efc_J only",
                repeats=REPEATS,
            )
        )
    return out
