"""Cable elongation, compensated drive, the simulated robot, and friction identification."""

from __future__ import annotations

import numpy as np
import pytest

from robomech.mechanisms import continuum as C

PAPER = C.ContinuumRobot.paper()
TWO = C.ContinuumRobot(n_segments=2, friction=(0.26, 0.31, 0.28) * 2)


def test_elongation_is_hookes_law():
    psi = np.zeros(2)
    d0 = C.cable_elongation(PAPER, psi, np.full(3, PAPER.pretension))
    assert np.abs(d0).max() < 1e-18  # the straight, pretensioned pose is the reference
    dT = np.array([1.0, 2.0, 3.0])
    d = C.cable_elongation(PAPER, psi, PAPER.pretension + dT)
    expected = dT * (PAPER.free_length + PAPER.segment_length) / PAPER.cable_axial_stiffness
    assert np.abs(d - expected).max() < 1e-18


def test_compensated_drive_reaches_pose_on_its_own_model():
    """The simulated robot driven with q~ = q + delta from the same model lands on the target pose."""
    rng = np.random.default_rng(0)
    for robot in (PAPER, TWO):
        th = rng.uniform(0.1, 1.4, (4, robot.n_segments))
        be = rng.uniform(-np.pi, np.pi, (4, robot.n_segments))
        psi = np.stack([th, be], -1).reshape(4, -1)
        direction = rng.choice([-1.0, 1.0], size=(4, robot.n_cables))
        dr = C.compensated_drive(robot, psi, direction)
        assert dr.taut.all()
        sim = C.simulate(robot, dr.q_compensated, direction, initial=psi)
        assert sim.converged.all() and sim.taut.all()
        assert np.abs(C.tip_position(robot, sim.psi) - C.tip_position(robot, psi)).max() < 1e-10
        assert np.abs(sim.tension - dr.tension).max() < 1e-6


def test_simulated_equilibrium_satisfies_statics():
    psi_d = np.array([[0.9, 0.3], [1.5, 2.0]])
    direction = np.array([[1.0, -1.0, -1.0], [-1.0, 1.0, -1.0]])
    sim = C.simulate(PAPER, C.theoretical_drive(PAPER, psi_d, "arc"), direction)
    assert sim.converged.all()
    tr = C.cable_tensions(PAPER, sim.psi, direction=direction, pretension=0.0)
    G = C.cable_jacobian(PAPER, sim.psi, "chord")
    P = C.friction_factors(PAPER, sim.psi, direction)
    J = C.span_jacobian(PAPER, sim.psi, "chord")
    Geff = np.einsum("...ck,...ckj->...cj", P, J)
    balance = -np.einsum("...cj,...c->...j", Geff, sim.tension) - C.elastic_gradient(PAPER, sim.psi)
    assert np.abs(balance).max() < 1e-9
    assert G.shape == (2, 3, 2) and tr.residual.max() < 1e-12


def test_uncompensated_drive_undershoots_and_compensation_helps():
    psi_d = np.array([[np.pi / 2, 0.0]])
    direction = np.array([[1.0, -1.0, -1.0]])
    sim0 = C.simulate(PAPER, C.theoretical_drive(PAPER, psi_d, "arc"), direction)
    assert sim0.psi[0, 0] < psi_d[0, 0]  # cable stretch and friction lose bend
    dr = C.compensated_drive(PAPER, psi_d, direction)
    assert np.all(dr.delta[0, 0] > 0)  # the pulled cable stretches: pull it further
    sim1 = C.simulate(PAPER, dr.q_compensated, direction)
    e0 = np.linalg.norm(C.tip_position(PAPER, sim0.psi) - C.tip_position(PAPER, psi_d))
    e1 = np.linalg.norm(C.tip_position(PAPER, sim1.psi) - C.tip_position(PAPER, psi_d))
    assert e1 < 1e-9 < e0


def test_slack_cables_are_flagged():
    q = np.array([[0.0, 0.0, 0.0], [0.006, -0.01, -0.01]])  # second: cables 2, 3 paid out far too much
    sim = C.simulate(PAPER, q)
    assert sim.converged.all()
    assert sim.taut.tolist() == [True, False]
    assert np.all(sim.tension >= 0)
    assert np.abs(sim.psi[0]).max() < 1e-12


def test_simulate_batched_equals_per_sample():
    rng = np.random.default_rng(3)
    q = rng.uniform(-0.002, 0.004, (5, 3))
    d = rng.choice([-1.0, 1.0], (5, 3))
    a = C.simulate(PAPER, q, d)
    b = np.stack([C.simulate(PAPER, q[i], d[i]).psi for i in range(5)])
    assert np.abs(a.psi - b).max() < 1e-12


def _simulated_measurements(rng, mu, trials, m, sigma):
    eta = rng.uniform(0.6, 1.5, (trials, mu.size, m))
    s = np.ones_like(eta)
    t_out = rng.uniform(2.0, 12.0, eta.shape)
    t_in = t_out * np.exp(s * mu[:, None] * eta)
    return eta, t_in + rng.normal(0, sigma, eta.shape), t_out + rng.normal(0, sigma, eta.shape), s


def test_identification_recovers_mu_within_stated_uncertainty():
    rng = np.random.default_rng(7)
    mu = np.array([0.26, 0.31, 0.28])  # paper 3, Table 1
    sigma = 0.05  # N: a 10 kg load cell at 0.05 % of full scale
    eta, t_in, t_out, s = _simulated_measurements(rng, mu, trials=400, m=11, sigma=sigma)
    est = C.identify_friction(eta, t_in, t_out, s, sigma_t=sigma)
    z = (est.mu - mu) / est.std  # (400, 3)
    coverage = np.mean(np.abs(z) < 2.0)
    assert 0.92 < coverage < 0.98  # 95.4 % for a correct uncertainty
    assert abs(z.mean()) < 0.15  # unbiased (the standard error of the mean of 1200 z-values is 0.03)
    assert 0.85 < z.std() < 1.15
    assert np.all(np.abs(est.chi2_per_dof.mean(axis=0) - 1.0) < 0.1)
    # without a noise model, the uncertainty comes from the scatter and still covers the truth
    est2 = C.identify_friction(eta, t_in, t_out, s)
    assert 0.9 < np.mean(np.abs(est2.mu - mu) / est2.std < 2.0) < 0.99


def test_identification_bad_input():
    with pytest.raises(ValueError, match="t_in"):
        C.identify_friction([1.0], [-1.0], [1.0], [1.0])
    with pytest.raises(ValueError, match="direction"):
        C.identify_friction([1.0], [2.0], [1.0], [0.0])
    with pytest.raises(ValueError, match="sigma_t"):
        C.identify_friction([1.0], [2.0], [1.0], [1.0], sigma_t=0.0)
    with pytest.raises(ValueError, match="wrap"):
        C.identify_friction([np.nan], [2.0], [1.0], [1.0])


def test_simulate_bad_input():
    with pytest.raises(ValueError, match="q"):
        C.simulate(PAPER, [0.0, 0.0])
    with pytest.raises(ValueError, match="direction"):
        C.simulate(PAPER, [0.0, 0.0, 0.0], [1.0, 0.0])


def test_identification_end_to_end_on_simulated_robot():
    """Paper 3, Section 5: beta = 0, 120, 240 deg, theta 40 -> 90 deg; tensions at both cable ends with
    0.05 N noise, pose from a noisy tracked tip (0.022 mm) through IK; Table 1's mu recovered within 3 std."""
    rng = np.random.default_rng(11)
    sigma = 0.05
    theta = np.radians(np.arange(40.0, 90.1, 5.0))
    wraps, t_in, t_out, dirs = [], [], [], []
    for k, beta in enumerate(np.radians([0.0, 120.0, 240.0])):
        psi = np.stack([theta, np.full_like(theta, beta)], -1)
        direction = np.where(np.arange(3) == k, 1.0, -1.0) * np.ones((theta.size, 1))
        sim = C.simulate(PAPER, C.theoretical_drive(PAPER, psi, "arc"), direction, initial=psi)
        assert sim.converged.all()
        P = C.friction_factors(PAPER, sim.psi, direction)
        tracked = C.tip_position(PAPER, sim.psi) + rng.normal(0, 0.022e-3, (theta.size, 3))
        ik = C.inverse_kinematics(PAPER, tracked)  # least-squares pose of an off-surface tip
        wraps.append(C.wrap_angles(PAPER, ik.psi).sum(-1))
        t_in.append(sim.tension + rng.normal(0, sigma, sim.tension.shape))
        t_out.append(sim.tension * P[..., -1] + rng.normal(0, sigma, sim.tension.shape))
        dirs.append(direction)
    cat = lambda xs: np.concatenate(xs, 0).T  # noqa: E731
    taut = cat(t_out) > 10 * sigma
    est = C.identify_friction(
        np.where(taut, cat(wraps), 0.0),
        np.where(taut, cat(t_in), 1.0),
        np.where(taut, cat(t_out), 1.0),
        np.where(taut, cat(dirs), 0.0),
        sigma_t=sigma,
    )
    assert np.all(np.abs(est.mu - PAPER.friction_array) < 3 * est.std)
    assert np.all(est.std < 0.01)
