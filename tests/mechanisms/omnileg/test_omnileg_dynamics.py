"""Dynamics of the OmniLeg: mass matrix, Lagrange's equations, energy consistency, static force maps."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import robomech.mechanisms.omnileg as ol
from robomech.spatial import vee
from robomech.testing import numerical_jacobian

LEG = ol.OmniLeg.paper()


def _trajectory(n: int = 4001, duration: float = 2.0):
    """A smooth motion through most of the joint ranges (analytic q, q̇, q̈)."""
    t = np.linspace(0.0, duration, n)
    A = np.array([0.9, 0.8, 0.5])
    w = np.array([1.3, 0.9, 2.1])
    ph = np.array([0.0, 0.3, 0.0])
    off = np.array([0.0, 0.0, 0.8])
    arg = w * t[:, None] + ph
    return t, off + A * np.sin(arg), A * w * np.cos(arg), -A * w * w * np.sin(arg)


def test_mass_matrix_symmetric_positive_definite():
    _, q, _, _ = _trajectory(200)
    M = ol.mass_matrix(LEG, q)
    np.testing.assert_allclose(M, np.swapaxes(M, -1, -2), atol=1e-15)
    assert np.linalg.eigvalsh(M).min() > 0


def test_mass_matrix_matches_finite_differences_of_body_poses():
    # independent of the jets: body Jacobians by central differences of the body poses
    q = np.array([[0.4, -0.3, 0.7], [-0.9, 0.6, 0.2], [0.0, 0.0, 1.2]])
    R, _ = ol.body_poses(LEG, q)
    dR = numerical_jacobian(lambda x: ol.body_poses(LEG, x)[0], q)  # (..., B, 3, 3, n)
    Jv = numerical_jacobian(lambda x: ol.body_poses(LEG, x)[1], q)  # (..., B, 3, n)
    Jw = vee(np.einsum("...bijk,...blj->...bkil", dR, R))  # space ω per unit q̇_k: (..., B, n, 3)
    names = [b for b in ol.BODY_NAMES]
    keys = {n: n.rsplit("_", 1)[0] if n[-1].isdigit() else n for n in names}
    keys.update({"drive_cross_a": "drive_cross", "drive_cross_b": "drive_cross"})
    M = np.zeros((3, 3, 3))
    for b, name in enumerate(names):
        body = LEG.bodies[keys[name]]
        Is = R[:, b] @ body.inertia_matrix @ np.swapaxes(R[:, b], -1, -2)
        M += body.mass * np.einsum("nik,nil->nkl", Jv[:, b], Jv[:, b])
        M += np.einsum("nki,nij,nlj->nkl", Jw[:, b], Is, Jw[:, b])
    np.testing.assert_allclose(ol.mass_matrix(LEG, q), M, rtol=1e-7, atol=1e-10)


def test_body_rotations_are_proper_and_knee_bodies_translate():
    _, q, _, _ = _trajectory(50)
    R, _ = ol.body_poses(LEG, q)
    np.testing.assert_allclose(R @ np.swapaxes(R, -1, -2), np.broadcast_to(np.eye(3), R.shape), atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-14)
    i_plate = ol.BODY_NAMES.index("knee_plate")
    np.testing.assert_allclose(R[:, i_plate], np.broadcast_to(np.eye(3), R[:, i_plate].shape), atol=0)


def test_energy_consistency_along_a_trajectory():
    t, q, qd, qdd = _trajectory()
    F = np.array([3.0, -20.0, 20.0])
    res = ol.inverse_dynamics(LEG, q, qd, qdd, foot_force=F)
    T, V = ol.energy(LEG, q, qd)
    E = T + V
    dt = t[1] - t[0]
    dE = (E[2:] - E[:-2]) / (2 * dt)
    # power of the motors plus the power of the force applied to the foot = dE/dt
    power = np.sum(res.tau * qd, -1) + ol.foot_velocity(LEG, q, qd) @ F
    err = np.abs(dE - power[1:-1])
    # central difference error ~dt² E'''/6 with dt = 5e-4 s: ~1e-7 W against powers of ~1 W
    assert err.max() < 1e-6 * max(1.0, np.abs(power).max())
    assert np.abs(power).max() > 0.1  # the test is not vacuous


def test_lagrange_equations_by_finite_differences():
    # τ = d/dt(∂T/∂q̇) - ∂T/∂q + ∂V/∂q, each term by central differences of the energies
    t, q, qd, qdd = _trajectory(2001, 1.0)
    dt = t[1] - t[0]
    idx = np.arange(200, 1800, 100)
    tau = ol.inverse_dynamics(LEG, q[idx], qd[idx], qdd[idx]).tau
    p_mom = np.einsum("nij,nj->ni", ol.mass_matrix(LEG, q), qd)  # ∂T/∂q̇ = M q̇
    dp = (p_mom[idx + 1] - p_mom[idx - 1]) / (2 * dt)
    dT_dq = numerical_jacobian(lambda x: ol.energy(LEG, x, qd[idx])[0], q[idx])
    dV_dq = numerical_jacobian(lambda x: ol.energy(LEG, x, qd[idx])[1], q[idx])
    np.testing.assert_allclose(tau, dp - dT_dq + dV_dq, atol=2e-6 * np.abs(tau).max())
    np.testing.assert_allclose(ol.gravity_torques(LEG, q[idx]), dV_dq, atol=1e-8)


def test_inverse_dynamics_parts_and_foot_force_sign():
    q = np.array([0.3, -0.2, 0.6])
    qd = np.array([0.5, -0.4, 1.0])
    qdd = np.array([-1.0, 2.0, 0.5])
    F = np.array([0.0, -20.0, 20.0])
    r = ol.inverse_dynamics(LEG, q, qd, qdd, foot_force=F)
    np.testing.assert_allclose(
        r.tau, r.M @ qdd + r.velocity_terms + r.gravity_terms + r.foot_terms, atol=1e-14
    )
    np.testing.assert_allclose(r.foot_terms, ol.static_torques(LEG, q, F), atol=1e-14)
    z = np.zeros(3)
    np.testing.assert_allclose(ol.inverse_dynamics(LEG, q, z, z).tau, ol.gravity_torques(LEG, q), atol=1e-15)
    # velocity terms are quadratic in q̇
    r2 = ol.inverse_dynamics(LEG, q, 2 * qd, qdd)
    np.testing.assert_allclose(r2.velocity_terms, 4 * r.velocity_terms, atol=1e-13)


def test_inertia_change_changes_torques():
    q, qd, qdd = np.array([0.3, -0.2, 0.6]), np.array([0.5, -0.4, 1.0]), np.array([-1.0, 2.0, 0.5])
    heavier = dataclasses.replace(
        LEG, bodies={"knee_plate": dataclasses.replace(LEG.bodies["knee_plate"], mass=1.4)}
    )
    d = ol.inverse_dynamics(heavier, q, qd, qdd).tau - ol.inverse_dynamics(LEG, q, qd, qdd).tau
    assert np.abs(d).max() > 1e-2


def test_batched_dynamics_equals_per_sample():
    _, q, qd, qdd = _trajectory(12)
    F = np.random.default_rng(6).normal(size=(12, 3))
    r = ol.inverse_dynamics(LEG, q, qd, qdd, foot_force=F)
    for i in range(12):
        ri = ol.inverse_dynamics(LEG, q[i], qd[i], qdd[i], foot_force=F[i])
        np.testing.assert_allclose(ri.tau, r.tau[i], rtol=0, atol=1e-12)
        np.testing.assert_allclose(ri.M, r.M[i], rtol=0, atol=1e-12)
    assert ol.inverse_dynamics(LEG, q.reshape(3, 4, 3), qd.reshape(3, 4, 3), qdd[0]).tau.shape == (3, 4, 3)


def test_foot_force_from_torques_regular_and_singular():
    q = np.array([[0.3, -0.2, 0.6], [0.3, -0.2, 0.0], [0.0, 0.0, 1e-5]])
    F = np.array([1.0, -20.0, 20.0])
    tau = ol.static_torques(LEG, q, F)
    r = ol.foot_force_from_torques(LEG, q, tau)
    assert r.singular.tolist() == [False, True, True]
    np.testing.assert_allclose(r.force[0], F, atol=1e-10)
    assert np.all(np.isfinite(r.force))
    # at γ = 0 the torques carry no information about the force along the thigh direction u (the
    # shank cannot resist it through γ); its component tangent to the thigh sphere is still recovered
    u = ol.thigh_direction(q[1, 0], q[1, 1])
    P = np.eye(3) - np.outer(u, u)
    np.testing.assert_allclose(P @ r.force[1], P @ F, atol=1e-12 * np.linalg.norm(F))
    assert abs(u @ r.force[1]) < 1e-12 * np.linalg.norm(F)
    np.testing.assert_allclose(ol.static_torques(LEG, q[1], r.force[1]), tau[1], atol=1e-9)
    # a torque the singular Jacobian cannot balance leaves a residual, reported
    r2 = ol.foot_force_from_torques(LEG, q[1], tau[1] + np.array([0.0, 0.0, 1.0]))
    assert r2.residual > 0.5


@pytest.mark.parametrize("name", ["q", "qd", "qdd"])
def test_bad_dynamics_input_names_argument(name):
    args = {"q": np.zeros(3), "qd": np.zeros(3), "qdd": np.zeros(3)}
    args[name] = np.zeros(4)
    with pytest.raises(ValueError, match=name):
        ol.inverse_dynamics(LEG, **args)
    args[name] = np.array([0.0, -np.inf, 0.0])  # NaN marks a failed sample (masked), inf is refused
    with pytest.raises(ValueError, match=name):
        ol.inverse_dynamics(LEG, **args)


def test_chunked_dynamics_equals_one_block(monkeypatch):
    from robomech.mechanisms.omnileg import _dynamics

    _, q, qd, qdd = _trajectory(23)
    whole = ol.inverse_dynamics(LEG, q, qd, qdd)
    monkeypatch.setattr(_dynamics, "DYN_CHUNK", 5)  # 5 chunks, the last one partial
    chunked = ol.inverse_dynamics(LEG, q, qd, qdd)
    np.testing.assert_allclose(chunked.tau, whole.tau, rtol=0, atol=1e-15)
    np.testing.assert_allclose(chunked.M, whole.M, rtol=0, atol=1e-15)
