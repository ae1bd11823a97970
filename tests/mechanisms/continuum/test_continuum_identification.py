"""Eq. (38) identification from actuator-side tensions and the measured pose (issue 16 item 5).

The reference-generated case (disk-resolved reference, tracker and load-cell noise) takes minutes and
is recorded in docs/mechanisms/continuum_cosserat.md (benchmarks/continuum_reference.py ident); here the
estimator's statistics are checked on data whose model is known exactly."""

from __future__ import annotations

import numpy as np
import pytest

from robomech.mechanisms import continuum as C

TRUTH = C.ContinuumRobot.paper()
NOISE = 0.05  # N, load cells


def _protocol():
    """Table 1's protocol: beta = 0, 120, 240 deg with cable 1, 2, 3 pulled in, theta 40-90 deg, 5 deg."""
    th = np.radians(np.arange(40.0, 90.1, 5.0))
    psi, d = [], []
    for k, b in enumerate(np.radians([0.0, 120.0, 240.0])):
        psi.append(np.stack([th, np.full_like(th, b)], -1))
        d.append(np.where(np.arange(3) == k, 1.0, -1.0) * np.ones((th.size, 1)))
    return np.concatenate(psi), np.concatenate(d)


def test_recovers_mu_with_covering_confidence_intervals():
    psi, d = _protocol()
    t = C.cable_tensions(TRUTH, psi, direction=d).tension
    start = C.ContinuumRobot(friction=(0.2, 0.2, 0.2))
    covered = 0
    trials = 20
    for seed in range(trials):
        rng = np.random.default_rng(seed)
        e = C.identify_friction_from_pose(start, psi, t + rng.normal(0, NOISE, t.shape), d, sigma_t=NOISE)
        assert e.success and np.all(e.identifiable)
        covered += int(np.sum((e.ci_low <= TRUTH.friction_array) & (TRUTH.friction_array <= e.ci_high)))
        assert np.all(np.abs(e.mu - TRUTH.friction_array) < 6 * e.std)
    # 95 % intervals: 60 intervals, expect ~57; below 51 (binomial p < 1e-3) means the std is wrong
    assert covered >= 51


def test_bad_input():
    psi, d = _protocol()
    t = C.cable_tensions(TRUTH, psi, direction=d).tension
    with pytest.raises(ValueError, match="direction"):
        C.identify_friction_from_pose(TRUTH, psi, t, np.zeros_like(d))
    with pytest.raises(ValueError, match="t_act"):
        C.identify_friction_from_pose(TRUTH, psi, -t, d)
    with pytest.raises(ValueError, match="sigma_t"):
        C.identify_friction_from_pose(TRUTH, psi, t, d, sigma_t=-1.0)
    with pytest.raises(ValueError, match="robot"):
        C.identify_friction_from_pose(None, psi, t, d)
    with pytest.raises(ValueError, match="psi"):
        C.identify_friction_from_pose(TRUTH, psi[:3], t, d)
