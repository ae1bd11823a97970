"""OmniLeg vs MuJoCo: the verification passes, and it fails when the analytic model is wrong (teeth)."""

from __future__ import annotations

import dataclasses
import inspect

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
    assert len(checks) == 8
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


def test_engine_model_is_the_generic_export():
    """No hand-written MJCF: the engine model is mb.to_mjcf of the description, with its inertias."""
    from robomech import multibody as mb

    assert "<body" not in inspect.getsource(vo)
    back = mb.from_mjcf(vo.build_mjcf(LEG))
    mech = ol.to_multibody(LEG)
    assert [b.name for b in back.bodies] == [b.name for b in mech.bodies]
    for b1, b2 in zip(back.bodies, mech.bodies, strict=True):
        assert b2.inertial is not None and b1.inertial is not None
        assert abs(b1.inertial.mass - b2.inertial.mass) <= 1e-15 * b2.inertial.mass
    assert back.actuated == vo.ACTUATED_JOINTS
    m = engine_model = vo.build_model(LEG).model
    assert m.opt.timestep == vo.SIM_TIMESTEP and engine_model.nv == len(ol.TREE_JOINTS)
    assert abs(m.body_mass.sum() - sum(LEG.bodies[k].mass for _, k in _body_kinds())) < 1e-12


def _body_kinds():
    from robomech.mechanisms.omnileg._dynamics import _body_list

    return _body_list()


def test_energy_check_passes_and_has_teeth(engine):
    assert vo.energy_error(LEG, engine) < vo.TOL_ENERGY.value
    rod = LEG.bodies["thigh_rod"]
    I = np.array(rod.inertia)
    I[:2, :2] *= 1.05  # a 5 % error in the transverse moments of inertia of the three thigh rods
    wrong = dataclasses.replace(LEG, bodies={"thigh_rod": dataclasses.replace(rod, inertia=I)})
    assert vo.energy_error(wrong, engine) > 100 * vo.TOL_ENERGY.value


def test_engine_tells_the_exact_drive_from_the_papers_simplification(engine):
    """paper 2, eqs. (26)-(31) (the simplified Cardan drive) disagree with the engine beyond TOL_TORQUE."""
    _, t, _, tau_en = vo.torque_error(LEG, engine, n=25)
    prof = ol.joint_trajectory_eq52(t)
    F = np.where((t <= 1.0)[:, None], vo.FIG11_FORCE, 0.0)
    tau_pp = ol.inverse_dynamics(LEG, prof.q, prof.qd, prof.qdd, foot_force=F, paper_as_printed=True).tau
    assert np.abs(tau_pp - tau_en).max() / np.abs(tau_en).max() > 100 * vo.TOL_TORQUE.value


def test_engine_from_a_perturbed_leg_fails_the_torque_check():
    """Teeth on the engine side: the analytic paper leg against an engine whose foot is 3 % heavier."""
    foot = LEG.bodies["foot"]
    heavy = dataclasses.replace(LEG, bodies={"foot": dataclasses.replace(foot, mass=foot.mass * 1.03)})
    err, *_ = vo.torque_error(LEG, vo.build_model(heavy), n=25)
    assert err > 100 * vo.TOL_TORQUE.value
