"""The MuJoCo ground truth of the skid-steer robot: model built from the parameters, physics sanity,
bad input."""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pytest

from robomech.mechanisms.skid_steer import WHEELS, ExplorationRobot, contact_frames, wheel_radii
from robomech.verify._skid_steer_engine import EngineParams, Terrain, build_model, simulate_engine

ROBOT = ExplorationRobot.paper()
# Soft joint equalities and contact penetration (~0.5 mm under 20 kg) bound how exactly the engine's
# resting geometry matches the kinematic model.
REST_TOL = 2e-3


def test_model_is_generated_from_the_parameters():
    wide = dataclasses.replace(ROBOT, rocker_lateral_offset=0.3)
    for robot in (ROBOT, wide):
        model = build_model(robot).compile()
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        # every contact site sits where the kinematic model puts the contact, at zero joint angles
        T0 = contact_frames(robot, np.r_[0, 0, 0, robot.rear_wheel_drop, 0, 0, 0, robot.rear_wheel_drop])
        chassis = data.xpos[model.body("chassis").id]
        for w, name in enumerate(WHEELS):
            site = data.site_xpos[model.site(f"contact_{name}").id] - chassis
            np.testing.assert_allclose(site, T0[w, :3, 3], atol=1e-12)
        assert model.nu == 6 and model.neq == 3  # six drives; differential + two parallelograms


def test_robot_rests_on_its_six_wheels_and_drives_straight():
    run = simulate_engine(ROBOT, (0.2, 0.2), 1.5, rate=50.0)
    assert run.in_contact.all()
    # the chassis rests at the kinematic ride height (less the contact penetration) and level
    assert abs(run.T_GB[0, 2, 3] - ROBOT.ground_clearance_depth) < REST_TOL
    assert np.all(np.abs(run.config[:, [0, 4]]) < REST_TOL)
    np.testing.assert_allclose(run.config[:, 4], -run.config[:, 0], atol=1e-4)  # the differential
    # wheels spin at the command and the body moves at the rim speed (little creep)
    late = slice(50, None)
    np.testing.assert_allclose(run.wheel_rate[late] * wheel_radii(ROBOT), 0.2, rtol=0.01)
    np.testing.assert_allclose(run.twist[late, 3], 0.2, rtol=0.01)
    np.testing.assert_allclose(run.twist[late, 2], 0.0, atol=1e-6)


def test_turning_slides_sideways_and_yaws_less_than_the_no_slip_formula():
    run = simulate_engine(ROBOT, (0.25, 0.05), 2.0, rate=50.0)
    late = slice(60, None)
    rim = run.wheel_rate[late] * wheel_radii(ROBOT)
    no_slip = (rim[:, :3].mean(1) - rim[:, 3:].mean(1)) / ROBOT.track_width
    yaw = run.twist[late, 2]
    assert np.all(yaw > 0.01)  # right faster: turns left
    assert np.all(yaw < 0.6 * no_slip)  # skid: much less yaw than (v1 - v2)/S
    # the IMU: gyro equals the chassis angular velocity, accelerometer ~ gravity at low speed
    np.testing.assert_allclose(run.gyro, run.twist[:, :3], atol=1e-9)
    # (stick-slip of the skidding wheels shakes it by ~1 m/s² sample to sample; its mean is g)
    assert abs(np.mean(run.accel[late, 2]) - 9.81) < 0.2


def test_uneven_ground_is_a_height_field_and_leaving_it_is_flagged():
    small = Terrain(*[(v[0],) for v in (Terrain.uneven().amplitude, (4.0,), (1.0,), (0.3,))], half_size=0.6)
    run = simulate_engine(ROBOT, (0.3, 0.3), 2.5, terrain=small, rate=50.0)
    assert run.on_terrain[0]
    assert not run.on_terrain[-1]  # 0.6 m of terrain, driven ~0.7 m: off the edge, flagged per sample
    assert np.all(np.diff(run.on_terrain.astype(int)) <= 0)  # once off, stays off
    model = build_model(ROBOT, Terrain.uneven()).compile()
    assert model.nhfield == 1


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"track_speeds": (0.1, np.nan)}, "track_speeds"),
        ({"track_speeds": (0.1, 0.2, 0.3)}, "track_speeds"),
        ({"track_speeds": [[0, 0.1, 0.1], [0, 0.2, 0.2]]}, "strictly increasing"),
        ({"rate": 300.0}, "rate"),
        ({"duration": -1.0}, "duration"),
    ],
)
def test_bad_input_raises_naming_the_argument(kwargs, match):
    args = {"track_speeds": (0.1, 0.1), "duration": 0.1} | kwargs
    with pytest.raises(ValueError, match=match):
        simulate_engine(ROBOT, args.pop("track_speeds"), args.pop("duration"), **args)


def test_bad_parameters_raise():
    with pytest.raises(ValueError, match="friction"):
        EngineParams(friction=-0.1)
    with pytest.raises(ValueError, match="kx"):
        Terrain((0.01,), (), (1.0,), (0.0,))
    with pytest.raises(ValueError, match="robot"):
        build_model(None)


def test_accelerometer_sees_the_centripetal_acceleration_of_a_steady_turn():
    """Specific force in body axes, steady turn: (ω × v)_y + g (R^T z)_y (the body rolls a little)."""
    run = simulate_engine(ROBOT, (0.25, 0.05), 2.5, rate=50.0)
    late = slice(75, None)
    centripetal = run.twist[late, 3] * run.twist[late, 2] - run.twist[late, 5] * run.twist[late, 0]
    gravity = 9.81 * run.T_GB[late, 2, 1]  # (R^T z)_y = R[2, 1]
    assert np.mean(centripetal) > 0.005
    assert np.mean(run.accel[late, 1]) == pytest.approx(np.mean(centripetal + gravity), abs=2e-3)
