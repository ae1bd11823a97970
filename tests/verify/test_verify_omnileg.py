"""OmniLeg vs MuJoCo: the verification passes, and it fails when the analytic model is wrong (teeth)."""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pytest

import robomech.mechanisms.omnileg as ol
from robomech.verify import omnileg as vo

LEG = ol.OmniLeg.paper()


@pytest.fixture(scope="module")
def engine():
    return vo.build_model(LEG)


def test_verification_passes():
    checks = vo.run()
    assert len(checks) == 7
    failed = [(c.quantity, c.max_error, c.tolerance.value) for c in checks if not c.passed]
    assert not failed, failed


def test_registered():
    from robomech.verify import available_verifications

    assert "omnileg" in available_verifications()


def test_wrong_inertia_fails_the_torque_check(engine):
    plate = LEG.bodies["knee_plate"]
    wrong = dataclasses.replace(
        LEG, bodies={"knee_plate": dataclasses.replace(plate, mass=plate.mass * 1.02)}
    )
    err, *_ = vo.torque_error(wrong, engine, n=25)
    assert err > 100 * vo.TOL_TORQUE.value


def test_wrong_gravity_sign_fails_the_torque_check(engine):
    wrong = dataclasses.replace(LEG, gravity=tuple(-g for g in LEG.gravity))
    err, *_ = vo.torque_error(wrong, engine, n=25)
    assert err > 100 * vo.TOL_TORQUE.value


def test_printed_theta22_sign_breaks_the_engine_closure(engine):
    q = np.array([[0.4, -0.5, 0.3]])
    jm = ol.joint_motion(LEG, q, np.zeros_like(q), np.zeros_like(q))
    qpos = jm.q[0].copy()
    i22, i23 = ol.TREE_JOINTS.index("theta22"), ol.TREE_JOINTS.index("theta23")
    qpos[i22], qpos[i23] = -qpos[i22], -qpos[i23]  # paper 2, eq. (12) as printed
    m, d = engine.model, engine.data
    d.qpos[engine.qpos_index] = qpos
    mujoco.mj_forward(m, d)
    rows = np.flatnonzero(d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    assert np.abs(d.efc_pos[rows]).max() > 1e-3


def test_mjcf_follows_parameters():
    longer = dataclasses.replace(LEG, L1=0.17)
    em = vo.build_model(longer)
    jm = ol.joint_motion(longer, np.array([0.2, 0.3, 0.4]), np.zeros(3), np.zeros(3))
    em.data.qpos[em.qpos_index] = jm.q
    mujoco.mj_forward(em.model, em.data)
    np.testing.assert_allclose(
        em.data.site_xpos[em.foot_site], ol.forward_kinematics(longer, [0.2, 0.3, 0.4]), atol=1e-14
    )
