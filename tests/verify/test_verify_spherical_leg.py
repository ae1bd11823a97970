"""MuJoCo verification of the spherical parallel leg: all checks pass, and they have teeth."""

from __future__ import annotations

from dataclasses import replace

import pytest

pytest.importorskip("mujoco")

from robomech.mechanisms import spherical_leg as sl
from robomech.verify import available_verifications
from robomech.verify import spherical_leg as vsl


def _by_quantity(checks):
    return {c.quantity: c for c in checks}


def test_all_checks_pass_and_are_registered():
    assert "spherical-leg" in available_verifications()
    checks = vsl.run_checks()
    failed = [(c.quantity, c.max_error, c.tolerance.value) for c in checks if not c.passed]
    assert not failed, failed
    assert len(checks) >= 13  # 10 with the hand-written model before issue 13
    by = _by_quantity(checks)
    assert "mass matrix G^T M G vs engine (mj_fullM)" in by
    assert "actuator forces vs engine inverse dynamics (minimum norm)" in by


def test_the_engine_model_is_the_generic_export():
    """No hand-written MJCF: the engine's joints and closures are those of sl.to_multibody."""
    import mujoco

    from robomech import multibody as mb

    m = vsl.build_model(sl.SphericalLeg.paper())
    mech = sl.to_multibody(sl.SphericalLeg.paper())
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(m.njnt)]
    assert names == [j.name for b in mech.bodies for j in b.joints]
    assert m.neq == len(mb.from_mjcf(mb.to_mjcf(mech)).closures) + len(mech.couplings)
    # the description's massless bodies (central chain, cardans) are massless in the engine too
    for b in mech.bodies:
        bid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, b.name)
        assert m.body_mass[bid] == (0.0 if b.inertial is None else b.inertial.mass)


def test_the_former_model_without_the_cardan_spin_fails_the_dynamics():
    """Issue 13: paper 1's leg energy (eq. (23), no spin about the leg axes) against the engine."""
    by = _by_quantity(vsl.run_checks(paper_as_printed=True))
    assert not by["mass matrix G^T M G vs engine (mj_fullM)"].passed
    assert not by["actuator forces vs engine inverse dynamics"].passed
    assert not by["actuator forces vs engine inverse dynamics (minimum norm)"].passed
    assert by["loop closure of analytic joints (m)"].passed  # kinematics untouched
    assert by["leg Jacobian dl/dq vs engine"].passed


def test_a_wrong_inertia_fails_the_force_check():
    leg = sl.SphericalLeg.paper()
    wrong = replace(leg, upper=(replace(leg.upper[0], mass=1.6), leg.upper[1], leg.upper[2]))
    checks = _by_quantity(vsl.run_checks(wrong))
    assert not checks["actuator forces vs engine inverse dynamics"].passed
    assert not checks["mass matrix G^T M G vs engine (mj_fullM)"].passed
    assert checks["loop closure of analytic joints (m)"].passed  # kinematics untouched


def test_a_wrong_sign_or_dimension_fails():
    leg = sl.SphericalLeg.paper()
    flipped = replace(leg, gravity=(0.0, 0.0, 10.0))
    assert not _by_quantity(vsl.run_checks(flipped))["actuator forces vs engine inverse dynamics"].passed
    moved = replace(leg, r=0.031)
    checks = _by_quantity(vsl.run_checks(moved))
    assert not checks["loop closure of analytic joints (m)"].passed
    assert not checks["leg accelerations vs engine (Section 6.1 modes)"].passed
    assert not checks["leg Jacobian dl/dq vs engine"].passed
    assert not checks["forward kinematics of engine lengths (rad)"].passed
