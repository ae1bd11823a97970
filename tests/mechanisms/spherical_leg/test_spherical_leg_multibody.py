"""The spherical leg described generically (robomech.multibody) equals the closed forms of paper 1."""

from __future__ import annotations

import numpy as np
import pytest

from robomech import multibody as mb
from robomech.mechanisms import spherical_leg as sl

# Both sides are exact; they agree to rounding of O(0.1 m) lengths and O(1) angles (measured ~5e-15).
AGREE_TOL = 1e-10
# MuJoCo's own closure residual of the exported model at the generic layer's configurations.
ENGINE_TOL = 1e-12

LEG = sl.SphericalLeg.paper()
MECH = sl.to_multibody(LEG)
BY_ANGLES = sl.to_multibody(LEG, actuate="platform")
L0 = np.linalg.norm(LEG.platform_points_home - LEG.base_points, axis=1)
RNG = np.random.default_rng(11)
AB = RNG.uniform(-0.6, 0.6, (8, 2))  # inside Section 6's motions (|alpha|, |beta| <= pi/3 ~ 1.05)


def _lengths(q):
    return q[..., [MECH.qpos_address(f"l{k}") for k in (1, 2, 3)]] + L0


def test_ik_lengths():
    fk = mb.forward_kinematics(BY_ANGLES, AB)
    assert fk.converged.all()
    assert np.max(np.abs(_lengths(fk.q) - sl.inverse_kinematics(LEG, AB[:, 0], AB[:, 1]).lengths)) < AGREE_TOL
    # and as the generic IK of the redundantly actuated leg, from the platform pose
    T = mb.site_pose(BY_ANGLES, fk.q, "platform")
    ik = mb.inverse_kinematics(MECH, "platform", T)
    assert ik.converged.all()
    assert np.max(np.abs(ik.q_act + L0 - sl.inverse_kinematics(LEG, AB[:, 0], AB[:, 1]).lengths)) < AGREE_TOL


def test_fk_from_three_lengths():
    lengths = sl.inverse_kinematics(LEG, AB[:, 0], AB[:, 1]).lengths
    fk = mb.forward_kinematics(MECH, lengths - L0)  # three inputs, two DOF: consistent redundant actuation
    assert fk.converged.all()
    ana = sl.forward_kinematics(LEG, lengths)
    got = fk.q[:, [MECH.qpos_address("alpha"), MECH.qpos_address("beta")]]
    assert np.max(np.abs(got - np.stack([ana.alpha, ana.beta], -1))) < AGREE_TOL
    assert np.max(np.abs(got - AB)) < AGREE_TOL


def test_jacobian_and_hessian_of_the_lengths():
    fk = mb.forward_kinematics(BY_ANGLES, AB)
    inf = mb.influence(BY_ANGLES, fk.q)
    rows = [BY_ANGLES.dof_address(f"l{k}") for k in (1, 2, 3)]
    assert np.max(np.abs(inf.G[:, rows] - sl.jacobian(LEG, AB[:, 0], AB[:, 1]))) < AGREE_TOL
    assert np.max(np.abs(inf.dG[:, rows] - sl.hessian(LEG, AB[:, 0], AB[:, 1]))) < AGREE_TOL
    # platform angular velocity: the site Jacobian's angular rows are E(alpha)
    J = mb.site_jacobian(BY_ANGLES, fk.q, "platform")
    assert np.max(np.abs(J[:, :3] - sl.angular_velocity_jacobian(AB[:, 0]))) < AGREE_TOL


def test_redundant_actuation_mobility_and_engine_closure():
    m = mb.mobility(MECH)
    assert (m.dof, m.n_actuated, m.actuation, m.platform_rotational_dof) == (2, 3, "redundant", 2)
    lengths = sl.inverse_kinematics(LEG, AB[:, 0], AB[:, 1]).lengths
    fk = mb.forward_kinematics(MECH, lengths - L0)
    from tests.multibody._helpers import mujoco_closure

    assert np.max(mujoco_closure(MECH, fk.q)) < ENGINE_TOL
    # inconsistent lengths (a leg 1 mm too long) cannot assemble exactly: flagged, not hidden
    bad = mb.forward_kinematics(MECH, (lengths - L0) + np.array([1e-3, 0, 0]))
    assert not bad.converged.any() and np.all(bad.residual > 1e-5)


def test_screw_spin_coupling():
    fk = mb.forward_kinematics(BY_ANGLES, AB[:2])
    spin = fk.q[:, MECH.qpos_address("spin1")]
    assert np.max(np.abs(spin - LEG.spin_ratio[0] * fk.q[:, MECH.qpos_address("l1")])) < AGREE_TOL


def test_bad_parameters():
    with pytest.raises(ValueError, match="leg"):
        sl.to_multibody("paper")
    with pytest.raises(ValueError, match="actuate"):
        sl.to_multibody(LEG, actuate="motors")
