"""Inverse dynamics of the spherical parallel leg: energy, Lagrange, statics, force distribution."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from robomech.mechanisms import spherical_leg as sl
from robomech.testing import numerical_jacobian

LEG = sl.SphericalLeg.paper()


def _trajectory(t: np.ndarray):
    q = np.stack([0.8 * np.sin(1.3 * t + 0.2), 0.6 * np.sin(2.1 * t) + 0.1], -1)
    qd = np.stack([1.04 * np.cos(1.3 * t + 0.2), 1.26 * np.cos(2.1 * t)], -1)
    qdd = np.stack([-1.352 * np.sin(1.3 * t + 0.2), -2.646 * np.sin(2.1 * t)], -1)
    return q, qd, qdd


@pytest.mark.parametrize(("spin", "printed"), [(True, False), (False, False), (True, True), (False, True)])
def test_power_of_generalized_forces_equals_rate_of_energy(spin, printed):
    leg = replace(LEG, screw_spin=spin)
    t = np.linspace(0.0, 4.0, 8001)
    dt = t[1] - t[0]
    q, qd, qdd = _trajectory(t)
    tau = sl.generalized_forces(leg, q, qd, qdd, paper_as_printed=printed)
    T, V = sl.mechanical_energy(leg, q, qd, paper_as_printed=printed)
    E = T + V
    # fourth-order central difference in time: error ~ dt^4 E^(5) ~ 1e-13 of the power scale
    dE = (E[:-4] - 8 * E[1:-3] + 8 * E[3:-1] - E[4:]) / (12 * dt)
    P = np.sum(tau * qd, -1)[2:-2]
    assert np.max(np.abs(dE - P)) < 1e-8 * np.max(np.abs(P))
    # a wrong platform mass breaks it
    bad = sl.generalized_forces(replace(leg, platform_mass=5.5), q, qd, qdd)
    assert np.max(np.abs(np.sum(bad * qd, -1)[2:-2] - dE)) > 1e-3 * np.max(np.abs(P))


@pytest.mark.parametrize(("spin", "printed"), [(True, False), (False, False), (False, True)])
def test_kane_equals_lagrange_from_the_energy_function(spin, printed):
    """With universal joints at the base every body's orientation is a function of q (the screw's spin
    angle too), so the motion is holonomic: tau = d/dt dL/dqd - dL/dq (by differences).  The former
    model (``paper_as_printed``: legs that do not spin) is holonomic only without the screw spin (a
    screw spinning relative to a non-spinning sleeve is not)."""
    leg = replace(LEG, screw_spin=spin)
    t = np.linspace(0.5, 0.7, 5)
    h = 1e-5
    q, qd, qdd = _trajectory(t)

    def lagrangian(qq, qqd):
        T, V = sl.mechanical_energy(leg, qq, qqd, paper_as_printed=printed)
        return T - V

    dL_dq = numerical_jacobian(lambda x: lagrangian(x, qd), q)

    # d/dt of dL/dqd along the trajectory, by central differences in time of the exact path
    def p_at(tt):
        qq, qqd, _ = _trajectory(tt)
        return numerical_jacobian(lambda v: lagrangian(qq, v), qqd)

    dp = (p_at(t + h) - p_at(t - h)) / (2 * h)
    tau_lagrange = dp - dL_dq
    tau = sl.generalized_forces(leg, q, qd, qdd, paper_as_printed=printed)
    assert np.max(np.abs(tau - tau_lagrange)) < 1e-5 * np.max(np.abs(tau))


def test_static_forces_are_the_potential_gradient_and_mass_matrix_is_the_kinetic_energy():
    rng = np.random.default_rng(2)
    q = rng.uniform(-1, 1, (30, 2))
    z = np.zeros_like(q)
    tau0 = sl.generalized_forces(LEG, q, z, z)
    dV = numerical_jacobian(lambda x: sl.mechanical_energy(LEG, x, z)[1], q)
    assert np.max(np.abs(tau0 - dV)) < 1e-8
    M = sl.mass_matrix(LEG, q)
    assert np.max(np.abs(M - np.swapaxes(M, -1, -2))) < 1e-15
    assert np.all(np.linalg.eigvalsh(M) > 0)
    qd = rng.normal(size=q.shape)
    T = sl.mechanical_energy(LEG, q, qd)[0]
    assert np.max(np.abs(T - 0.5 * np.einsum("ni,nij,nj->n", qd, M, qd))) < 1e-15
    # the generalized forces are affine in qdd with slope M
    qdd = rng.normal(size=q.shape)
    lin = sl.generalized_forces(LEG, q, qd, qdd) - sl.generalized_forces(LEG, q, qd, z)
    assert np.max(np.abs(lin - np.einsum("nij,nj->ni", M, qdd))) < 1e-13


def test_external_wrench_enters_by_virtual_work():
    q, qd, qdd = np.array([0.3, -0.2]), np.array([0.1, 0.2]), np.array([0.0, 0.1])
    f = np.array([1.0, -2.0, 30.0])
    p = sl.inverse_kinematics(LEG, *q).platform_points[0]  # force applied at B1
    wrench = np.concatenate([np.cross(p, f), f])
    d = sl.generalized_forces(LEG, q, qd, qdd, platform_wrench=wrench) - sl.generalized_forces(
        LEG, q, qd, qdd
    )
    # tau_ext = -(dB1/dq)^T f
    dB = numerical_jacobian(
        lambda x: sl.inverse_kinematics(LEG, x[..., 0], x[..., 1]).platform_points[..., 0, :], q
    )
    assert np.allclose(d, -dB.T @ f, atol=1e-9)


def test_force_distribution_rules():
    rng = np.random.default_rng(4)
    q = rng.uniform(-0.9, 0.9, (50, 2))
    qd, qdd = rng.normal(size=q.shape), rng.normal(size=q.shape)
    J = sl.jacobian(LEG, q[:, 0], q[:, 1])
    mn = sl.inverse_dynamics(LEG, q, qd, qdd)
    pd = sl.inverse_dynamics(LEG, q, qd, qdd, driven_legs=sl.PAPER_DRIVEN_LEGS)
    for res in (mn, pd):
        assert res.valid.all()
        assert np.max(np.abs(np.einsum("nki,nk->ni", J, res.leg_forces) - res.generalized_forces)) < 1e-12
        assert np.max(res.residual) < 1e-12
    assert np.all(pd.leg_forces[:, 1] == 0.0)
    # minimum norm: no component along the null space of J^T, smaller than any other solution
    null = np.cross(J[:, :, 0], J[:, :, 1])
    assert np.max(np.abs(np.sum(mn.leg_forces * null, -1)) / np.linalg.norm(null, axis=-1)) < 1e-10
    assert np.all(np.linalg.norm(mn.leg_forces, axis=-1) <= np.linalg.norm(pd.leg_forces, axis=-1) + 1e-12)
    with pytest.raises(ValueError, match="driven_legs"):
        sl.inverse_dynamics(LEG, q, qd, qdd, driven_legs=(1, 1))


def test_actuation_singularity_is_flagged_not_nan():
    # dl3/dalpha = 0 where h cos(b) cos(a) + r sin(a) = 0: alpha cannot be actuated
    b = np.pi / 3
    a = -np.arctan2(LEG.h * np.cos(b), LEG.r)
    res = sl.inverse_dynamics(LEG, np.array([[a, b], [0.1, b]]), np.zeros((2, 2)), np.zeros((2, 2)))
    assert res.valid.tolist() == [False, True]
    assert np.all(np.isnan(res.leg_forces[0])) and np.all(np.isfinite(res.leg_forces[1]))
    wm = sl.workspace_map(LEG, a, b)
    assert wm.singular and abs(wm.dl3_dalpha) < 1e-15


def test_batched_equals_per_sample_and_bad_input():
    rng = np.random.default_rng(6)
    q, qd, qdd = (rng.uniform(-1, 1, (20, 2)) for _ in range(3))
    res = sl.inverse_dynamics(LEG, q, qd, qdd)
    for k in range(20):
        one = sl.inverse_dynamics(LEG, q[k], qd[k], qdd[k])
        assert np.max(np.abs(one.leg_forces - res.leg_forces[k])) <= 1e-12
        assert np.max(np.abs(one.generalized_forces - res.generalized_forces[k])) <= 1e-12
    with pytest.raises(ValueError, match="qdd"):
        sl.inverse_dynamics(LEG, q, qd, np.full((20, 2), 1e300))
    assert not sl.inverse_dynamics(LEG, q, qd, np.full((20, 2), np.nan)).valid.any()  # failed samples
    with pytest.raises(ValueError, match="q"):
        sl.inverse_dynamics(LEG, np.zeros((20, 3)), qd, qdd)
    with pytest.raises(ValueError, match="platform_wrench"):
        sl.inverse_dynamics(LEG, q, qd, qdd, platform_wrench=np.zeros(3))
    with pytest.raises(ValueError, match="paper_as_printed"):
        sl.inverse_dynamics(LEG, q, qd, qdd, paper_as_printed="yes")


@pytest.mark.parametrize(
    ("kind", "arg"), [("sway", "x"), ("sway", "y"), ("fig5", "a"), ("fig5", "b"), ("fig5", "c")]
)
def test_paper_motions_are_consistent(kind, arg):
    t = np.linspace(0.0, 24.0, 24001)
    dt = t[1] - t[0]
    q, qd, qdd = sl.sway(t, arg) if kind == "sway" else sl.fig5_motion(arg, t)
    # Fig. 5(b) as printed starts the sine sway from rest at t = 5 s: alpha_dot steps by A*2*pi*f there
    keep = np.abs(t - 5.0) > 2 * dt if (kind, arg) == ("fig5", "b") else np.ones(t.size, dtype=bool)
    keep[[0, -1]] = False
    assert np.max(np.abs(np.gradient(q, dt, axis=0) - qd)[keep]) < 1e-6
    assert np.max(np.abs(np.gradient(qd, dt, axis=0) - qdd)[keep]) < 1e-3  # the quintic's jerk step at 5 s
    assert np.max(np.abs(q)) <= np.pi / 3 + 1e-12
    if kind == "fig5" and arg == "b":
        assert q[0, 1] == pytest.approx(np.pi / 3) and q[-1, 1] == pytest.approx(np.pi / 6)
        jump = qd[t >= 5.0][0, 0] - qd[t < 5.0][-1, 0]
        assert jump == pytest.approx(np.pi / 3 * 2 * np.pi * 0.05)
    with pytest.raises(ValueError, match=r"about|case"):
        sl.sway(t, "z") if kind == "sway" else sl.fig5_motion("d", t)
