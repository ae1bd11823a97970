"""Wheel chains: contact-frame Jacobians against central differences of the chain forward kinematics."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from robomech.mechanisms.skid_steer import ExplorationRobot, contact_frames, wheel_jacobians
from robomech.testing import numerical_space_jacobian

ROBOT = ExplorationRobot.paper()
# Central differences with step 6e-6 on O(0.3 m) chains: truncation ~h^2 ~ 4e-11, rounding ~eps/h ~ 4e-11.
FD_TOL = 1e-9


def _config(rng: np.random.Generator, n: int | None = None) -> np.ndarray:
    size = (8,) if n is None else (n, 8)
    q = rng.uniform(-0.4, 0.4, size=size)
    q[..., 3] = ROBOT.rear_wheel_drop + rng.uniform(-0.03, 0.03, size=size[:-1])
    q[..., 7] = ROBOT.rear_wheel_drop + rng.uniform(-0.03, 0.03, size=size[:-1])
    return q


def _side_fk(q: np.ndarray, wheel: int):
    side = wheel // 3

    def fk(x: np.ndarray) -> np.ndarray:
        qq = np.broadcast_to(q, (*x.shape[:-1], 8)).copy()
        qq[..., 4 * side : 4 * side + 4] = x
        return contact_frames(ROBOT, qq)[..., wheel, :, :]

    return fk, q[..., 4 * side : 4 * side + 4]


config_strategy = arrays(np.float64, (8,), elements=st.floats(-0.5, 0.5)).map(
    lambda q: q + np.array([0, 0, 0, ROBOT.rear_wheel_drop, 0, 0, 0, ROBOT.rear_wheel_drop])
)


@settings(max_examples=60, deadline=None)
@given(config_strategy)
def test_every_wheel_jacobian_matches_central_differences(q):
    J = wheel_jacobians(ROBOT, q)
    for w in range(6):
        fk, x = _side_fk(q, w)
        np.testing.assert_allclose(J[w], numerical_space_jacobian(fk, x), atol=FD_TOL)


def test_chain_structure_rear_wheel_has_no_bogie_columns_and_road_wheels_no_slide():
    J = wheel_jacobians(ROBOT, _config(np.random.default_rng(0)))
    for w in (2, 5):  # rear wheels: rocker + slide
        assert np.all(J[w][:, 1:3] == 0.0)
        np.testing.assert_allclose(J[w][:3, 3], 0.0)  # the slide is prismatic
        assert np.linalg.norm(J[w][3:, 3]) == pytest.approx(1.0)
    for w in (0, 1, 3, 4):  # road wheels: rocker, bogie, side link
        assert np.all(J[w][:, 3] == 0.0)


def test_parallelogram_keeps_both_road_wheels_of_a_side_parallel():
    T = contact_frames(ROBOT, _config(np.random.default_rng(1), 50))
    np.testing.assert_allclose(T[:, 0, :3, :3], T[:, 1, :3, :3], atol=1e-15)
    np.testing.assert_allclose(T[:, 3, :3, :3], T[:, 4, :3, :3], atol=1e-15)
    # and the two contacts stay 2 * side_link_hinge_offset apart
    d = np.linalg.norm(T[:, 0, :3, 3] - T[:, 1, :3, 3], axis=-1)
    np.testing.assert_allclose(d, 2 * ROBOT.side_link_hinge_offset, atol=1e-15)


def test_batched_equals_per_sample():
    q = _config(np.random.default_rng(2), 40).reshape(5, 8, 8)
    T, J = contact_frames(ROBOT, q), wheel_jacobians(ROBOT, q)
    for idx in np.ndindex(5, 8):
        np.testing.assert_allclose(contact_frames(ROBOT, q[idx]), T[idx], rtol=0, atol=1e-12)
        np.testing.assert_allclose(wheel_jacobians(ROBOT, q[idx]), J[idx], rtol=0, atol=1e-12)


@pytest.mark.parametrize("fn", [contact_frames, wheel_jacobians])
def test_bad_config_is_rejected_naming_the_argument(fn):
    with pytest.raises(ValueError, match="config"):
        fn(ROBOT, np.zeros(7))
    q = np.zeros(8)
    q[2] = np.inf  # NaN marks a failed sample (masked); inf is a wrong input
    with pytest.raises(ValueError, match="config"):
        fn(ROBOT, q)
