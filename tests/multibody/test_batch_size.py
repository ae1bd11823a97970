"""Same samples, same result, whatever the batch they come in (batch 1 included).

Every multibody algorithm has one implementation (the compiled kernels run small batches in one
block and large ones in parallel blocks of the same per-sample code; influence and site Hessians are
batched numpy), so a sample's result must not depend on the batch around it: here batches of 1, 150,
300 and 1000 (below and above the kernels' block size and the former numpy/compiled threshold) of the
same samples agree to ``BATCH_RTOL`` for FK, site Jacobians, site Hessians, influence coefficients and
inverse dynamics on the gallery; inverse kinematics bit for bit at 1, 150, 255, 256, 257, 300 and 1000.
"""

from __future__ import annotations

import numpy as np
import pytest

from robomech import multibody as mb

# Identical per-sample code gives identical bits; batched BLAS products (influence, Hessians) may
# reassociate sums by batch size: a few ulps.  1e-12 relative to each quantity's largest entry.
BATCH_RTOL = 1e-12
SIZES = (1, 150, 300, 1000)
GALLERY = ("four_bar", "bennett", "planar_3rrr", "delta", "rps_3", "stewart")
# Inputs within 0.08 rad / 0.08 L of the reference configuration (inside every gallery workspace).
SPREAD = 0.08


def _close(a: np.ndarray, b: np.ndarray, what: str) -> None:
    scale = max(1.0, float(np.nanmax(np.abs(b)))) if b.size else 1.0
    assert np.array_equal(np.isnan(a), np.isnan(b)), what
    assert np.nanmax(np.abs(a - b), initial=0.0) <= BATCH_RTOL * scale, what


@pytest.mark.slow
@pytest.mark.parametrize("name", GALLERY)
def test_results_do_not_depend_on_the_batch_size(name):
    mech = mb.gallery.load(name)
    tree = mech.tree
    rng = np.random.default_rng(7)
    n = max(SIZES)
    scale = np.where(tree.dof_translational[tree.act_dof], mech.length, 1.0)
    qa = mech.q0[tree.act_qadr] + SPREAD * scale * rng.uniform(-1, 1, (n, len(mech.actuated)))
    qd, qdd = rng.normal(size=qa.shape), rng.normal(size=qa.shape)
    site = mech.sites[0].name

    def run(k: int) -> dict[str, np.ndarray]:
        fk = mb.forward_kinematics(mech, qa[:k])
        q = fk.q
        inf = mb.influence(mech, q)
        r = mb.inverse_dynamics(mech, q, qd[:k], qdd[:k])
        return {
            "fk": q,
            "site_jacobian": mb.site_jacobian(mech, q, site),
            "site_hessian": mb.site_hessian(mech, q, site),
            "G": inf.G,
            "dG": inf.dG,
            "tau": r.tau,
            "M_a": r.M_a,
        }

    out = {k: run(k) for k in SIZES}
    ref = out[max(SIZES)]
    assert mb.forward_kinematics(mech, qa).converged.all()
    for k in SIZES[:-1]:
        for key, v in out[k].items():
            _close(v, ref[key][:k], f"{key} at batch {k}")


@pytest.mark.parametrize("name", ("four_bar", "delta", "stewart"))
def test_one_sample_call_is_the_batch_call(name):
    """A single sample given as vectors takes the shortest way into the kernel: every field equal to
    the same sample in a batch (bit for bit), with and without gravity; a bad sample still falls back
    to the general path's flags."""
    mech = mb.gallery.load(name)
    tree = mech.tree
    fk = mb.forward_kinematics(mech, mech.q0[tree.act_qadr][None] + 0.01)
    na = len(mech.actuated)
    q, qd, qdd = fk.q[0], np.linspace(0.3, 1.0, na), np.linspace(-1.0, 1.0, na)
    for gravity in (True, False):
        one = mb.inverse_dynamics(mech, q, qd, qdd, gravity=gravity)
        batch = mb.inverse_dynamics(mech, q[None], qd[None], qdd[None], gravity=gravity)
        assert bool(one.valid)
        for k in one.__dataclass_fields__:
            a, b = np.asarray(getattr(one, k)), np.asarray(getattr(batch, k))[0]
            assert a.shape == b.shape and np.array_equal(a, b, equal_nan=True), k
    bad = qdd.copy()
    bad[0] = np.nan
    r = mb.inverse_dynamics(mech, q, qd, bad)
    assert not bool(r.valid) and np.all(np.isnan(r.tau))


# The compiled RNEA and the numpy formulation (_rnea._rnea_flat) sum the same terms in another order:
# rounding of the largest force, ~1e-16 relative measured.
RNEA_RTOL = 1e-13


@pytest.mark.parametrize("name", ("four_bar", "delta", "stewart"))
def test_generalized_forces_one_kernel_at_every_batch_size(name):
    from robomech.multibody._tree import normalize_quaternions

    from ._reference import numpy_rnea

    mech = mb.gallery.load(name)
    rng = np.random.default_rng(5)
    n = 300
    q = normalize_quaternions(mech.tree, mech.q0 + 0.05 * rng.normal(size=(n, mech.nq)))
    qd, qdd = rng.normal(size=(n, mech.nv)), rng.normal(size=(n, mech.nv))
    ref = numpy_rnea(mech, q, qd, qdd, np.asarray(mech.gravity))
    got = mb.generalized_forces(mech, q, qd, qdd)
    assert np.max(np.abs(got - ref)) <= RNEA_RTOL * np.max(np.abs(ref))
    for k in (1, 150):
        assert np.array_equal(mb.generalized_forces(mech, q[:k], qd[:k], qdd[:k]), got[:k])
    assert np.array_equal(mb.generalized_forces(mech, q[7], qd[7], qdd[7]), got[7])
    bad = qdd[7].copy()
    bad[0] = np.nan
    assert np.all(np.isnan(mb.generalized_forces(mech, q[7], qd[7], bad)))


# The open tree's forward dynamics (one kernel: CRBA, RNEA, Cholesky) against the numpy formulation it
# replaced (numpy CRBA and RNEA, LAPACK gesv, singular values by numpy): Cholesky and LU of the same
# mass matrix round differently, cond(M) eps ~1e-14 for these trees.
FD_RTOL = 1e-12


@pytest.mark.parametrize("name", ("arm6", "quadruped", "cart"))
def test_tree_forward_dynamics_one_kernel_at_every_batch_size(name):
    from ._reference import numpy_crba, numpy_rnea
    from .test_kinematic_classes import MECH, _states

    mech = MECH[name]
    n = 300
    q, qd, _, tau = _states(mech, n, seed=11)
    g = np.asarray(mech.gravity, float)
    M = numpy_crba(mech, q)
    f = -numpy_rnea(mech, q, qd, np.zeros_like(qd), g)
    f[:, mech.tree.act_dof] += tau
    ref = np.linalg.solve(M, f[..., None])[..., 0]
    s = np.linalg.svd(M, compute_uv=False)
    cond = s[:, 0] / s[:, -1]
    got = mb.forward_dynamics(mech, q, tau=tau, qd=qd)
    assert got.valid.all()
    assert np.max(np.abs(got.qdd - ref)) <= FD_RTOL * np.max(np.abs(ref))
    assert np.max(np.abs(got.cond - cond) / cond) <= FD_RTOL
    for k in (1, 150):
        part = mb.forward_dynamics(mech, q[:k], tau=tau[:k], qd=qd[:k])
        assert np.array_equal(part.qdd, got.qdd[:k]) and np.array_equal(part.cond, got.cond[:k])
    one = mb.forward_dynamics(mech, q[7], tau=tau[7], qd=qd[7])
    assert np.array_equal(one.qdd, got.qdd[7]) and one.cond == got.cond[7] and bool(one.valid)
    bad = tau[7].copy()
    bad[0] = np.nan
    nan = mb.forward_dynamics(mech, q[7], tau=bad, qd=qd[7])
    assert np.all(np.isnan(nan.qdd)) and not nan.valid


def test_inverse_kinematics_any_batch_size():
    mech = mb.gallery.load("stewart")
    site = mech.sites[0].name
    rng = np.random.default_rng(5)
    n = 1000
    qa = mech.q0[mech.tree.act_qadr] + 0.05 * mech.length * rng.uniform(-1, 1, (n, len(mech.actuated)))
    fk = mb.forward_kinematics(mech, qa)
    T = mb.site_pose(mech, fk.q, site)
    T[3, 0, 3] = np.nan  # a failed sample of an earlier call
    T[::7, :3, 3] += 20.0 * mech.length  # out of reach
    guess = np.tile(mech.q0, (n, 1))
    guess[11] = np.nan  # a failed guess row
    full = mb.inverse_kinematics(mech, site, T, guess)
    assert not full.converged[3] and not full.converged[11] and not full.converged[7]
    assert np.all(np.isnan(full.q[3])) and np.all(np.isnan(full.q[11])) and np.isnan(full.residual[11])
    assert full.converged.sum() > n // 2
    for k in (1, 150, 255, 256, 257, 300):
        part = mb.inverse_kinematics(mech, site, T[:k], guess[:k])
        for f in ("q", "residual", "pose_error", "converged", "iterations"):
            np.testing.assert_array_equal(getattr(part, f), getattr(full, f)[:k], err_msg=f"{f} at batch {k}")
    one = mb.inverse_kinematics(mech, site, T[257], guess[257])  # unbatched
    np.testing.assert_array_equal(one.q, full.q[257])
