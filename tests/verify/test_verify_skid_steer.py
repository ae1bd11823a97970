"""Paper 4 verification: the estimator against the independent kinematic simulation."""

from __future__ import annotations

import dataclasses

import numpy as np

from robomech.mechanisms.skid_steer import ExplorationRobot
from robomech.verify import available_verifications
from robomech.verify.skid_steer import Terrain, run_checks, simulate


def test_every_check_passes():
    checks = run_checks()
    failed = [(c.quantity, c.max_error, c.tolerance.value) for c in checks if not c.passed]
    assert not failed
    assert len(checks) == 5


def test_registered_under_its_name():
    assert "skid-steer" in available_verifications()


def test_check_has_teeth_wrong_track_width_in_the_estimator():
    robot = ExplorationRobot.paper()
    wrong = dataclasses.replace(robot, rocker_lateral_offset=robot.rocker_lateral_offset + 0.001)  # 1 mm
    checks = {c.quantity: c for c in run_checks(robot, wrong)}
    assert not checks["noise-free body twist vs truth (m/s, rad/s)"].passed
    assert not checks["flat ground: yaw rate (v1-v2)/S vs truth (rad/s)"].passed


def test_check_has_teeth_wrong_bogie_geometry_in_the_estimator():
    robot = ExplorationRobot.paper()
    wrong = dataclasses.replace(robot, bogie_hinge_x=robot.bogie_hinge_x + 0.002)
    checks = {c.quantity: c for c in run_checks(robot, wrong)}
    assert not checks["noise-free joint rates vs truth (rad/s, m/s)"].passed


def test_simulation_keeps_the_differential_and_the_right_tracks_at_twice_the_left():
    gt = simulate(ExplorationRobot.paper(), duration=1.0, rate=50.0, terrain=Terrain.uneven())
    np.testing.assert_allclose(gt.config[:, 4], -gt.config[:, 0], atol=0)
    assert gt.track_speeds[0] == 2 * gt.track_speeds[1]
    assert np.all(gt.converged)
