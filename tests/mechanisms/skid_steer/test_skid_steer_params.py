"""ExplorationRobot: the paper's printed lengths, documented defaults, validation."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from robomech.mechanisms.skid_steer import ExplorationRobot, contact_frames


def test_paper_lengths_are_the_printed_millimetres():
    # paper 4, Sec. 2.2: L^D_R1Y = 225, L^R_Q1Z = 28, L^H_LF1 = 68, L^K_AF1Z = 50, L^R_W1Z = 190,
    # L^W_P1Z = 100 mm
    r = ExplorationRobot.paper()
    printed = {
        "rocker_lateral_offset": 225,
        "spring_mount_offset": 28,
        "side_link_hinge_offset": 68,
        "road_wheel_radius": 50,
        "rear_wheel_drop": 190,
        "rear_wheel_radius": 100,
    }
    for name, mm in printed.items():
        assert getattr(r, name) == pytest.approx(mm * 1e-3, abs=1e-15), name
    assert r.track_width == pytest.approx(0.45)


def test_zero_configuration_puts_all_six_contacts_on_one_level():
    # The documented choice of bogie_hinge_drop: at zero joint angles the robot stands on flat ground.
    r = ExplorationRobot.paper()
    q0 = np.array([0, 0, 0, r.rear_wheel_drop, 0, 0, 0, r.rear_wheel_drop])
    z = contact_frames(r, q0)[:, 2, 3]
    np.testing.assert_allclose(z, -r.ground_clearance_depth, atol=1e-15)
    x = contact_frames(r, q0)[:, 0, 3]
    assert r.wheelbase == pytest.approx(0.5 * (x[0] + x[1]) - x[2], abs=1e-15)


@pytest.mark.parametrize(
    "field", ["rocker_lateral_offset", "road_wheel_radius", "rear_arm_length", "side_link_length"]
)
@pytest.mark.parametrize("bad", [0.0, -0.1, math.nan, math.inf])
def test_non_positive_or_non_finite_length_names_the_field(field, bad):
    with pytest.raises(ValueError, match=field):
        dataclasses.replace(ExplorationRobot.paper(), **{field: bad})


@pytest.mark.parametrize("bad", [0.0, math.pi / 2, -0.3, math.nan])
def test_side_link_rake_outside_open_quarter_turn_is_rejected(bad):
    with pytest.raises(ValueError, match="side_link_rake"):
        dataclasses.replace(ExplorationRobot.paper(), side_link_rake=bad)


def test_robot_is_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        ExplorationRobot.paper().road_wheel_radius = 0.1  # type: ignore[misc]
