"""Per-sample conditioning of the actuation and a physical bound on it (issue 14, defect 3)."""

from __future__ import annotations

import numpy as np
import pytest

from robomech.mechanisms import spherical_leg as sl

LEG = sl.SphericalLeg.paper()
BETA = np.pi / 3
A_SING = np.arctan(-LEG.h * np.cos(BETA) / LEG.r)  # dl3/dalpha = 0 on this curve
# sigma_min from the closed-form 2x2 Gram eigenvalues vs LAPACK's SVD: rounding of O(0.1) m/rad values.
SVD_TOL = 1e-12


def test_near_singular_sample_is_flagged_with_its_conditioning():
    q = np.array([[A_SING + 1e-6, BETA], [0.1, BETA]])
    z = np.zeros_like(q)
    for rule in (None, sl.PAPER_DRIVEN_LEGS):
        r = sl.inverse_dynamics(LEG, q, z, z, driven_legs=rule)
        # before issue 14: valid with forces of ~1e8 N
        assert r.valid.tolist() == [False, True]
        assert r.sigma_min[0] < 1e-6 < sl.ACTUATION_SIGMA_MIN < r.sigma_min[1]
        assert 0.0 < r.rcond[0] < r.rcond[1] <= 1.0
        assert np.all(np.isfinite(r.leg_forces[1]))


def test_sigma_min_is_the_smallest_singular_value_of_the_acting_jacobian():
    rng = np.random.default_rng(2)
    q = rng.uniform(-1.2, 1.2, (300, 2))
    J = sl.jacobian(LEG, q[:, 0], q[:, 1])
    tau = rng.normal(size=(300, 2))
    for rule, Ja in ((None, J), ((0, 2), J[:, [0, 2]]), ((1, 2), J[:, [1, 2]])):
        d = sl.distribute_forces(J, tau, rule)
        s = np.linalg.svd(Ja, compute_uv=False)
        np.testing.assert_allclose(d.sigma_min, s[:, -1], atol=SVD_TOL)
        np.testing.assert_allclose(d.rcond, s[:, -1] / s[:, 0], atol=SVD_TOL / 0.01)
        assert np.array_equal(d.valid, s[:, -1] >= sl.ACTUATION_SIGMA_MIN)


def test_valid_forces_obey_the_lever_arm_bound():
    # the physical meaning of the bound: |f| <= |tau| / sigma_min <= |tau| / ACTUATION_SIGMA_MIN
    rng = np.random.default_rng(3)
    q = np.stack([A_SING + rng.uniform(-0.2, 0.2, 2000), np.full(2000, BETA)], -1)
    tau = rng.normal(size=(2000, 2))
    d = sl.distribute_forces(sl.jacobian(LEG, q[:, 0], q[:, 1]), tau)
    assert 0 < d.valid.sum() < 2000
    f = np.linalg.norm(d.forces[d.valid], axis=-1)
    assert np.all(f <= np.linalg.norm(tau[d.valid], axis=-1) / d.sigma_min[d.valid] * (1 + 1e-9))
    assert np.all(f <= np.linalg.norm(tau[d.valid], axis=-1) / sl.ACTUATION_SIGMA_MIN)


def test_fig5a_peak_force_is_a_property_of_the_motion_not_of_the_sampling():
    # Fig. 5(a) crosses the singular curve: the raw peak |f3| depends on how near a grid point falls
    # (1.23e6 N on the 0.01 s grid), the peak over valid samples does not.
    peaks, raw = [], []
    for dt in (0.01, 0.0037, 0.0013):
        t = np.arange(0.0, 30.0 + 1e-9, dt)
        r = sl.inverse_dynamics(LEG, *sl.fig5_motion("a", t), driven_legs=sl.PAPER_DRIVEN_LEGS)
        raw.append(np.nanmax(np.abs(r.leg_forces[:, 2])))
        peaks.append(np.max(np.abs(r.leg_forces[r.valid, 2])))
    assert max(raw) / min(raw) > 2.0
    assert max(peaks) / min(peaks) < 1.2


def test_bound_is_validated_and_adjustable():
    J = sl.jacobian(LEG, A_SING + 1e-3, BETA)
    assert not sl.distribute_forces(J, [1.0, 1.0]).valid
    assert sl.distribute_forces(J, [1.0, 1.0], sigma_min_bound=0.0).valid
    for bad in (-1.0, np.nan, "1", None, True):
        with pytest.raises(ValueError, match="sigma_min_bound"):
            sl.distribute_forces(J, [1.0, 1.0], sigma_min_bound=bad)
