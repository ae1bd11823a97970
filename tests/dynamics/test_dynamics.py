"""Jacobian-form rigid-body inverse dynamics vs Modern Robotics' recursive Newton–Euler, and energy."""

import modern_robotics as mr
import numpy as np
import pytest

from robomech import dynamics
from robomech.kinematics import hessian_body, jacobian_body, jacobian_derivative, poe_fk
from robomech.spatial import adjoint, exp_se3, inverse_transform, screw_from_axis

# Newton–Euler and the Jacobian form are algebraically identical; 1e-10 allows for O(n^2) products
# of O(1-10) terms in double precision.
AGREE_TOL = 1e-10


def random_robot(rng, n):
    S = screw_from_axis(rng.normal(size=(n, 3)), rng.normal(size=(n, 3)) * 0.5)
    M_links = exp_se3(rng.normal(size=(n, 6)) * 0.5)  # home pose of each link's CoM frame in space
    G = []
    for _ in range(n):
        m = rng.uniform(0.5, 3.0)
        A = rng.normal(size=(3, 3))
        Ic = A @ A.T + 0.1 * np.eye(3)
        G.append(dynamics.spatial_inertia(m, np.zeros(3), Ic))
    return S, M_links, np.stack(G)


def body_jacobians(S, M_links, q):
    """Body Jacobian of each link's CoM frame (link i moves with joints 1..i) and its Hessian."""
    n = S.shape[0]
    J = np.zeros((*q.shape[:-1], n, 6, n))
    H = np.zeros((*q.shape[:-1], n, 6, n, n))
    for i in range(n):
        B = np.einsum("ij,nj->ni", adjoint(inverse_transform(M_links[i])), S[: i + 1])
        J[..., i, :, : i + 1] = jacobian_body(B, q[..., : i + 1])
        H[..., i, :, : i + 1, : i + 1] = hessian_body(B, q[..., : i + 1])
    return J, H


def link_poses(S, M_links, q):
    return np.stack([poe_fk(M_links[i], S[: i + 1], q[..., : i + 1]) for i in range(S.shape[0])], axis=-3)


@pytest.mark.parametrize("seed", range(3))
def test_inverse_dynamics_matches_newton_euler(seed):
    rng = np.random.default_rng(seed)
    n = 5
    S, M_links, G = random_robot(rng, n)
    g = np.array([0.0, 0.0, -9.81])
    Mlist = [M_links[0]] + [inverse_transform(M_links[i - 1]) @ M_links[i] for i in range(1, n)] + [np.eye(4)]
    for _ in range(5):
        q, qd, qdd = rng.normal(size=(3, n))
        J, H = body_jacobians(S, M_links, q)
        Jdot = jacobian_derivative(H, qd)
        R = link_poses(S, M_links, q)[..., :3, :3]
        g_body = np.einsum("bji,j->bi", R, g)
        ours = dynamics.inverse_dynamics(G, J, Jdot, qd, qdd, gravity_body=g_body)
        ref = mr.InverseDynamics(q, qd, qdd, g, np.zeros(6), Mlist, list(G), S.T)
        assert np.abs(ours.tau - ref).max() < AGREE_TOL * max(1.0, np.abs(ref).max())
        assert np.allclose(ours.M, mr.MassMatrix(q, Mlist, list(G), S.T), atol=AGREE_TOL)


def test_power_equals_rate_of_kinetic_energy_without_gravity():
    rng = np.random.default_rng(9)
    n = 4
    S, M_links, G = random_robot(rng, n)
    t = np.linspace(0, 1, 2001)
    q = np.stack([np.sin(1.3 * t + k) for k in range(n)], -1)
    qd = np.stack([1.3 * np.cos(1.3 * t + k) for k in range(n)], -1)
    qdd = np.stack([-1.69 * np.sin(1.3 * t + k) for k in range(n)], -1)
    J, H = body_jacobians(S, M_links, q)
    tau = dynamics.inverse_dynamics(G, J, jacobian_derivative(H, qd[..., None, :]), qd, qdd).tau
    E = dynamics.kinetic_energy(G, J, qd)
    dEdt = np.gradient(E, t)
    power = np.sum(tau * qd, axis=-1)
    # second-order central differences in time with dt = 5e-4: error ~ dt^2 E''' ~ 1e-6
    assert np.abs(power - dEdt)[1:-1].max() < 1e-5 * max(1.0, np.abs(power).max())


def test_spatial_inertia_is_symmetric_positive_definite_and_shifts_correctly():
    Ic = np.diag([0.1, 0.2, 0.3])
    c = np.array([0.1, -0.2, 0.3])
    G = dynamics.spatial_inertia(2.0, c, Ic)
    assert np.allclose(G, G.T)
    assert np.all(np.linalg.eigvalsh(G) > 0)
    # shifting the frame: G_origin = Ad(T_com,origin)^T G_com Ad(T_com,origin)
    G_com = dynamics.spatial_inertia(2.0, np.zeros(3), Ic)
    T_com_o = np.eye(4)
    T_com_o[:3, 3] = -c
    Ad = adjoint(T_com_o)
    assert np.allclose(G, Ad.T @ G_com @ Ad)
    with pytest.raises(ValueError, match="mass"):
        dynamics.spatial_inertia(-1.0, c, Ic)
    with pytest.raises(ValueError, match="inertia_com"):
        dynamics.spatial_inertia(1.0, c, np.eye(2))


def test_static_torques_and_redundant_actuator_forces():
    rng = np.random.default_rng(1)
    J = rng.normal(size=(10, 6, 3))
    w = rng.normal(size=(10, 6))
    tau = dynamics.static_torques(J, w)
    assert np.allclose(tau, np.einsum("kij,ki->kj", J, w))
    J_act = rng.normal(size=(10, 3, 2))  # 3 actuators, 2 DOF: redundant
    r = dynamics.actuator_forces(J_act, tau[:, :2])
    f, resid = r.forces, r.residual
    assert r.valid.all()
    assert np.allclose(np.einsum("kij,ki->kj", J_act, f), tau[:, :2])
    assert resid.max() < 1e-12
    # minimum norm: f is in the range of J_act (orthogonal to its left null space)
    null = np.cross(J_act[..., 0], J_act[..., 1])
    assert np.abs(np.sum(f * null, axis=1)).max() < 1e-10
    with pytest.raises(ValueError, match="wrench"):
        dynamics.static_torques(J, np.zeros((10, 5)))
