"""Influence coefficients, site Hessians, site wrenches, the full-rate inverse dynamics and the simulation's
projection: the compiled kernels (``_compiled.influence_block``, ``_rnea_kernels.inv_full_block``,
``_compiled.project_block``) against their numpy formulation (tests/multibody/_reference.py) on closed chains
(Delta, a five-bar typed unassembled, Sarrus, Tsai 3-UPU, the agile eye), an open chain, an
under-actuated floating-base tree, a passive pendulum and a cart, at batch 1 and at batches below and
above the kernels' block size (``_compiled.BLOCK`` samples run in one block in the calling thread, more
in parallel blocks); the Hessians also against finite differences of the site Jacobian.
"""

from __future__ import annotations

import numpy as np
import pytest

from robomech import multibody as mb
from robomech.multibody._compiled import BLOCK

from . import user_mechanisms as um
from ._helpers import fd_site_hessian
from ._reference import numpy_reference
from .test_kinematic_classes import MECH as CLASSES

# Same algorithm (the SVD pseudo-inverse of K_p, the same formulas), another operation order: G and its
# derivatives agree to rounding amplified by the passive block's conditioning (cond <= 1e3 on these
# samples: <= 1e3 * 1e-16 * |x|; 3e-13 measured at worst, rps_3's dG), relative to the largest entry.
INFLUENCE_RTOL = 1e-11
# The SVD's singular values of K_p computed twice: cond and sigma_min to a few ulps of cond * eps.
COND_RTOL = 1e-12
# The same per-sample code at every batch size (one block in the calling thread or parallel blocks):
# identical bits measured; a few ulps allowed.
BATCH_RTOL = 1e-13
# Central differences of the site Jacobian along the input (robomech.testing.numerical_jacobian):
# truncation ~h^2 |J'''| plus FK's closure tolerance over h: 1e-6 measured.
FD_TOL = 1e-5
SIZES = (1, BLOCK - 1, BLOCK + 1, 300)
N = max(SIZES)


def _closed(name):
    return {
        "delta": lambda: mb.gallery.load("delta"),
        "five_bar": lambda: um.five_bar_along_x(),
        "sarrus": lambda: um.sarrus(),
        "tsai": lambda: um.tsai_3upu(),
        "agile_eye": lambda: um.agile_eye(),
    }[name]()


CLOSED = ("delta", "five_bar", "sarrus", "tsai", "agile_eye")
TREES = ("arm6", "quadruped", "pendulum", "cart")


def _configurations(mech, n, seed=0, spread=0.08):
    """n assembled configurations near the reference (closed chains: FK of perturbed inputs; trees:
    random coordinates, quaternions normalised)."""
    rng = np.random.default_rng(seed)
    tree = mech.tree
    if mech.constraints.m == 0:
        dv = spread * rng.uniform(-1, 1, (n, tree.nv))
        from ._reference import integrate

        return integrate(tree, np.repeat(tree.q0[None], n, axis=0), dv)
    scale = np.where(tree.dof_translational[tree.act_dof], mech.length, 1.0)
    qa = mech.q0[tree.act_qadr] + spread * scale * rng.uniform(-1, 1, (n, len(mech.actuated)))
    fk = mb.forward_kinematics(mech, qa)
    assert fk.converged.all()
    return fk.q


def _mech(name):
    return CLASSES[name] if name in TREES else _closed(name)


def _close(a, b, rtol, what):
    scale = max(1.0, float(np.max(np.abs(b)))) if b.size else 1.0
    assert a.shape == b.shape, what
    assert np.max(np.abs(a - b), initial=0.0) <= rtol * scale, what


@pytest.mark.parametrize("name", CLOSED + TREES)
def test_influence_and_hessian_equal_numpy_at_every_batch_size(name):
    mech = _mech(name)
    q = _configurations(mech, N)
    site = mech.sites[0].name
    inf = mb.influence(mech, q)
    H = mb.site_hessian(mech, q, site)
    with numpy_reference():
        ref = mb.influence(mech, q)
        H_ref = mb.site_hessian(mech, q, site)
    _close(inf.G, ref.G, INFLUENCE_RTOL, "G")
    if len(mech.actuated) == 0:  # no input: no second-order coefficients, an empty Hessian
        assert inf.dG is None and ref.dG is None and H.shape == (N, 6, 0, 0)
    else:
        _close(inf.dG, ref.dG, INFLUENCE_RTOL, "dG")
    _close(H, H_ref, INFLUENCE_RTOL, "site_hessian")
    assert np.array_equal(inf.passive_rank, ref.passive_rank)
    assert np.all(np.abs(inf.cond - ref.cond) <= COND_RTOL * ref.cond)
    assert np.all(np.abs(inf.sigma_min - ref.sigma_min) <= COND_RTOL * ref.sigma_min)
    assert np.max(np.abs(inf.consistency - ref.consistency)) <= INFLUENCE_RTOL
    if mech.constraints.m:  # a closed chain: the motions of G are admissible
        assert np.max(inf.consistency) <= INFLUENCE_RTOL
    for n in SIZES[:-1]:  # the same samples in a smaller batch (batch 1 as a vector too)
        part = mb.influence(mech, q[:n] if n > 1 else q[0])
        Gn = part.G if n > 1 else part.G[None]
        _close(Gn, inf.G[:n], BATCH_RTOL, f"G at batch {n}")
        _close(mb.site_hessian(mech, q[:n], site), H[:n], BATCH_RTOL, f"site_hessian at batch {n}")


@pytest.mark.parametrize("name", ["five_bar", "sarrus", "tsai", "agile_eye"])
def test_site_hessian_equals_finite_differences(name):
    mech = _closed(name)
    q = _configurations(mech, 3, seed=1)
    site = mech.sites[0].name
    H = mb.site_hessian(mech, q, site)
    assert np.max(np.abs(H - fd_site_hessian(mech, q, site))) <= FD_TOL


def test_influence_of_an_open_chain_is_the_identity():
    """No closure rows: G is the identity on the actuated coordinates, dG zero, the empty passive
    block's measures finite (cond 1, sigma_min L)."""
    mech = CLASSES["arm6"]
    inf = mb.influence(mech, _configurations(mech, 5))
    assert np.array_equal(inf.G, np.broadcast_to(np.eye(mech.nv)[:, mech.tree.act_dof], inf.G.shape))
    assert not inf.dG.any()
    assert np.all(inf.cond == 1.0) and np.all(inf.sigma_min == mech.length)


@pytest.mark.parametrize("name", ["delta", "tsai", "five_bar"])
def test_site_wrench_equals_numpy(name):
    mech = _closed(name)
    q = _configurations(mech, 80, seed=2)
    tau = np.random.default_rng(3).normal(size=(80, len(mech.actuated)))
    site = mech.sites[0].name
    fast = mb.site_wrench(mech, q, site, tau)
    with numpy_reference():
        slow = mb.site_wrench(mech, q, site, tau)
    assert np.array_equal(fast.valid, slow.valid) and fast.valid.mean() > 0.9
    v = slow.valid
    _close(fast.wrench[v], slow.wrench[v], INFLUENCE_RTOL, "wrench")
    _close(fast.residual[v], slow.residual[v], INFLUENCE_RTOL, "residual")
    one = mb.site_wrench(mech, q[7], site, tau[7])
    _close(one.wrench, fast.wrench[7], BATCH_RTOL, "wrench at batch 1")


# The full-rate inverse dynamics: the compiled kernel (_rnea_kernels.inv_full_block) against its numpy
# formulation (_reference.numpy_inverse_full): the same SVDs of K and of the actuated rows, another
# operation order, so forces agree to rounding times the conditioning of the admissible-motion basis
# (cond <= 1e4 here).
FULL_RTOL = 1e-10


@pytest.mark.parametrize("name", ["delta", "sarrus", "quadruped", "pendulum", "arm6"])
def test_full_rate_inverse_dynamics_equals_numpy(name):
    mech = _mech(name)
    n = BLOCK + 1
    q = _configurations(mech, n, seed=4)
    rng = np.random.default_rng(5)
    if mech.constraints.m and len(mech.actuated):  # admissible rates from the actuated ones
        na = len(mech.actuated)
        r = mb.inverse_dynamics(mech, q, rng.normal(size=(n, na)), rng.normal(size=(n, na)))
        qd, qdd = r.qd, r.qdd
    else:
        qd, qdd = rng.normal(size=(n, mech.nv)), rng.normal(size=(n, mech.nv))
    W = {mech.sites[0].name: rng.normal(size=(n, 6))}
    fast = mb.inverse_dynamics(mech, q, qd=qd, qdd=qdd, wrenches=W)
    with numpy_reference():
        slow = mb.inverse_dynamics(mech, q, qd=qd, qdd=qdd, wrenches=W)
    assert np.array_equal(fast.valid, slow.valid)
    for k in ("tau", "M_a", "unactuated", "external_terms", "admissibility", "closure"):
        a, b = getattr(fast, k), getattr(slow, k)
        assert np.array_equal(np.isnan(a), np.isnan(b)), k
        fin = np.isfinite(b)
        _close(a[fin], b[fin], FULL_RTOL, k)
    one = mb.inverse_dynamics(mech, q[3], qd=qd[3], qdd=qdd[3], wrenches={k: v[3] for k, v in W.items()})
    _close(np.nan_to_num(one.tau), np.nan_to_num(fast.tau[3]), BATCH_RTOL, "tau at batch 1")


# A short simulation: the projection at each output time (compiled) against numpy's; the integrator
# is the same, so the trajectories agree to the integration tolerance's amplification of rounding.
SIM_TOL = 1e-9


@pytest.mark.parametrize("name", ["four_bar", "pendulum"])
def test_simulation_projection_equals_numpy(name):
    mech = CLASSES["pendulum"] if name == "pendulum" else mb.gallery.load("four_bar")
    t = np.linspace(0.0, 0.05, 4)
    q0 = _configurations(mech, 2, seed=6)
    kw = {"qd0": np.ones((2, mech.nv))} if name == "pendulum" else {"qd_act0": np.ones((2, 1))}
    fast = mb.simulate(mech, q0, t=t, **kw)
    with numpy_reference():
        slow = mb.simulate(mech, q0, t=t, **kw)
    assert fast.success.all() and slow.success.all()
    _close(fast.q, slow.q, SIM_TOL, "q")
    _close(fast.qd, slow.qd, SIM_TOL, "qd")
