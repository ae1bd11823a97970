"""The compiled per-sample kernels (large batches) agree with the numpy path, sample by sample."""

from __future__ import annotations

import numpy as np
import pytest

from robomech import multibody as mb
from robomech.mechanisms import spherical_leg as sl
from robomech.multibody import _assembly

# Same algorithm, different operation order: configurations agree to rounding (~1e-15 measured),
# site Jacobians to ~1e-12 (the compiled path solves the passive rates by refined normal equations
# instead of an SVD; with redundant actuation the least-squares solutions agree to ~3e-12).
Q_TOL = 1e-12
J_TOL = 1e-10
N = 2 * _assembly.COMPILED_MIN  # large enough for the compiled path


def _inputs(mech, seed):
    rng = np.random.default_rng(seed)
    scale = np.where(mech.tree.dof_translational[mech.tree.act_dof], mech.length, 1.0)
    return mech.q0[mech.tree.act_qadr] + 0.08 * scale * rng.uniform(-1, 1, (N, len(mech.actuated)))


def _leg():
    leg = sl.SphericalLeg.paper()
    mech = sl.to_multibody(leg)
    ab = np.random.default_rng(3).uniform(-0.4, 0.4, (N, 2))
    l0 = np.linalg.norm(leg.platform_points_home - leg.base_points, axis=1)
    return mech, sl.inverse_kinematics(leg, ab[:, 0], ab[:, 1]).lengths - l0


@pytest.mark.slow
@pytest.mark.parametrize("name", ["delta", "stewart", "bennett", "spherical_leg"])
def test_compiled_equals_numpy(name, monkeypatch):
    if name == "spherical_leg":
        mech, qa = _leg()
    else:
        mech = mb.gallery.load(name)
        qa = _inputs(mech, 1)
    site = mech.sites[0].name
    fast = mb.forward_kinematics(mech, qa)
    J_fast = mb.site_jacobian(mech, fast.q, site)
    monkeypatch.setattr(_assembly, "COMPILED_MIN", 10**9)
    slow = mb.forward_kinematics(mech, qa)
    J_slow = mb.site_jacobian(mech, slow.q, site)
    assert fast.converged.all() and slow.converged.all()
    assert np.max(np.abs(fast.q - slow.q)) < Q_TOL
    assert np.max(np.abs(J_fast - J_slow)) < J_TOL


@pytest.mark.slow
def test_compiled_masks_bad_samples():
    mech = mb.gallery.load("stewart")
    qa = _inputs(mech, 2)
    qa[5, 0] = np.nan
    # legs alternately 2.65 m and 0.05 m: the triangle inequality through the 0.42 m platform edge and
    # the 0.26 m base pair bounds the long leg by 0.73 m, so no assembly exists
    qa[7] = [2.0, -0.6, 2.0, -0.6, 2.0, -0.6]
    fk = mb.forward_kinematics(mech, qa)
    assert not fk.converged[5] and not fk.converged[7]
    assert fk.converged[np.r_[0:5, 6, 8:N]].all()
    assert np.all(np.isnan(fk.q[5])) and np.all(np.isfinite(fk.q[7]))
