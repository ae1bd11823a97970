"""The vectored thruster described generically (robomech.multibody) equals the analytic model of paper 5."""

from __future__ import annotations

import numpy as np

from robomech import multibody as mb
from robomech.mechanisms import vectored_thrust as vt

# Both sides are exact; they agree to rounding (measured ~3e-14 for the angular acceleration).
AGREE_TOL = 1e-10
ENGINE_TOL = 1e-12

TH = vt.VectoredThruster.paper()
MECH = vt.to_multibody(TH)
RNG = np.random.default_rng(13)
Q = np.column_stack([RNG.uniform(-0.75, 0.75, 8), RNG.uniform(-0.5, 0.5, 8)])  # Table 1: +-pi/4, +-pi/6


def test_fk_passive_angles_and_engine_closure():
    from tests.multibody._helpers import mujoco_closure

    fk = mb.forward_kinematics(MECH, Q)
    assert fk.converged.all()
    T = mb.site_pose(MECH, fk.q, "propeller")
    a = vt.forward_kinematics(TH, Q)
    assert np.max(np.abs(T[:, :3, 3] - a.tip)) < AGREE_TOL
    assert np.max(np.abs(T[:, :3, :3] - vt.platform_rotation(TH, Q).R)) < AGREE_TOL
    p = vt.passive_angles(TH, Q).values
    got = fk.q[:, [MECH.qpos_address("theta"), MECH.qpos_address("rho2")]]
    assert np.max(np.abs(got - p[:, :2])) < AGREE_TOL
    assert np.max(mujoco_closure(MECH, fk.q)) < ENGINE_TOL


def test_ik_from_the_tip():
    tip = vt.forward_kinematics(TH, Q).tip
    T = np.tile(np.eye(4), (len(Q), 1, 1))
    T[:, :3, 3] = tip
    ik = mb.inverse_kinematics(MECH, "propeller", T, weights=(0, 0, 0, 1, 1, 1))  # a point target
    assert ik.converged.all()
    assert np.max(np.abs(ik.q_act - Q)) < AGREE_TOL
    assert np.max(np.abs(ik.q_act - vt.inverse_kinematics(TH, tip).q)) < AGREE_TOL


def test_jacobian_and_angular_acceleration():
    fk = mb.forward_kinematics(MECH, Q)
    J = mb.site_jacobian(MECH, fk.q, "propeller")
    H = mb.site_hessian(MECH, fk.q, "propeller")
    assert np.max(np.abs(J[:, :3] - vt.jacobian(TH, Q).J)) < AGREE_TOL
    qd, qdd = RNG.standard_normal((8, 2)), RNG.standard_normal((8, 2))
    wdot = np.einsum("nij,nj->ni", J[:, :3], qdd) + np.einsum("nijk,nj,nk->ni", H[:, :3], qd, qd)
    acc = vt.angular_acceleration(TH, Q, qd, qdd)
    assert np.max(np.abs(wdot - acc.omega_dot)) < AGREE_TOL
    m = mb.mobility(MECH)
    assert (m.dof, m.platform_rotational_dof) == (2, 2)
