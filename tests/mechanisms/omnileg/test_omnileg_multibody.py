"""The OmniLeg described generically (robomech.multibody) equals the analytic model of paper 2."""

from __future__ import annotations

import numpy as np
import pytest

from robomech import multibody as mb
from robomech.mechanisms import omnileg as ol

# Both sides are exact; they agree to rounding (measured ~5e-15 m, rad).
AGREE_TOL = 1e-10
ENGINE_TOL = 1e-12

LEG = ol.OmniLeg.paper()
MECH = ol.to_multibody(LEG)
RNG = np.random.default_rng(12)
# inside Table 2's ranges (|alpha|, |beta| <= 65 deg, 0 < gamma <= 85 deg), away from gamma = 0 (singular)
Q = np.column_stack([RNG.uniform(-0.9, 0.9, 8), RNG.uniform(-0.9, 0.9, 8), RNG.uniform(0.2, 1.4, 8)])


@pytest.fixture(scope="module")
def fk():
    r = mb.forward_kinematics(MECH, Q, steps=3)
    assert r.converged.all()
    return r


def test_foot_position_is_eq_11(fk):
    T = mb.site_pose(MECH, fk.q, "foot")
    assert np.max(np.abs(T[:, :3, 3] - ol.forward_kinematics(LEG, Q))) < AGREE_TOL
    assert np.max(np.abs(T[:, :3, :3] - np.eye(3))) < AGREE_TOL  # the foot only translates


def test_thigh_closure_equals_the_poe_closure(fk):
    th = ol.thigh_closure(LEG, Q[:, 0], Q[:, 1])
    for k in range(3):
        for j in range(4 if k == 0 else 3):
            got = fk.q[:, MECH.qpos_address(f"theta{k + 1}{j + 1}")]
            assert np.max(np.abs(got - th.theta[:, k, j])) < AGREE_TOL
    t12, t22 = ol.passive_angles(LEG, Q[:, 0], Q[:, 1])  # eq. (12), sign corrected
    assert np.max(np.abs(fk.q[:, MECH.qpos_address("theta12")] - t12)) < AGREE_TOL
    assert np.max(np.abs(fk.q[:, MECH.qpos_address("theta22")] - t22)) < AGREE_TOL


def test_foot_jacobian_and_hessian(fk):
    J = mb.site_jacobian(MECH, fk.q, "foot")
    H = mb.site_hessian(MECH, fk.q, "foot")
    assert np.max(np.abs(J[:, 3:] - ol.jacobian(LEG, Q))) < AGREE_TOL
    assert np.max(np.abs(H[:, 3:] - ol.hessian(LEG, Q))) < AGREE_TOL
    assert np.max(np.abs(J[:, :3])) < AGREE_TOL and np.max(np.abs(H[:, :3])) < AGREE_TOL


def test_ik_round_trip_and_engine_closure(fk):
    from tests.multibody._helpers import mujoco_closure

    T = mb.site_pose(MECH, fk.q, "foot")
    ik = mb.inverse_kinematics(MECH, "foot", T, guess=fk.q)
    assert ik.converged.all()
    assert np.max(np.abs(ik.q_act - Q)) < AGREE_TOL
    assert np.max(np.abs(ol.inverse_kinematics(LEG, T[:, :3, 3]).q - Q)) < AGREE_TOL
    assert np.max(mujoco_closure(MECH, fk.q)) < ENGINE_TOL
    m = mb.mobility(MECH)
    assert (m.dof, m.platform_rotational_dof) == (3, 0)
