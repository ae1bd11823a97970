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
    assert len(checks) >= 9


def test_a_wrong_inertia_fails_the_force_check():
    leg = sl.SphericalLeg.paper()
    wrong = replace(leg, upper=(replace(leg.upper[0], mass=1.6), leg.upper[1], leg.upper[2]))
    checks = _by_quantity(vsl.run_checks(wrong))
    assert not checks["actuator forces vs engine inverse dynamics"].passed
    assert checks["loop closure of analytic joints (m)"].passed  # kinematics untouched


def test_a_wrong_sign_or_dimension_fails():
    leg = sl.SphericalLeg.paper()
    flipped = replace(leg, gravity=(0.0, 0.0, 10.0))
    assert not _by_quantity(vsl.run_checks(flipped))["actuator forces vs engine inverse dynamics"].passed
    moved = replace(leg, r=0.031)
    checks = _by_quantity(vsl.run_checks(moved))
    assert not checks["loop closure of analytic joints (m)"].passed
    assert not checks["leg accelerations vs engine (Section 6.1 modes)"].passed
