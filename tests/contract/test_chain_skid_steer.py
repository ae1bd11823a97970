"""Failed samples chain through robomech.mechanisms.skid_steer (docs/conventions.md, "Failed samples
chain"): a body-velocity estimate from a lost measurement (NaN twist and configuration rate, ``valid``
False) fed into every function of the package that takes a configuration, a twist or a body velocity
gives NaN / False at that sample and, at the other samples, what they give alone."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from chain_check import check_chain, check_refused, check_strict_fails, functions_taking

from robomech.mechanisms import skid_steer as ss

ROBOT = ss.ExplorationRobot.paper()
CFG = np.random.default_rng(0).normal(scale=0.05, size=8)  # one configuration, broadcast over the batch
TWIST = np.array([0.1, 0.0, 0.2, 0.3, 0.0, 0.0])
QD = np.full(8, 0.01)
MEASURED = ss.wheel_measurements(ROBOT, np.tile(CFG, (4, 1)), TWIST, QD)
MEASURED[1] = np.nan  # the measurement of sample 1 was lost
BV = ss.body_velocity(ROBOT, np.tile(CFG, (4, 1)), MEASURED)
GOOD = [0, 2, 3]
RATES = np.full(6, 6.0)  # wheel rates (rad/s), broadcast


def _rows(tw: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``x`` at every sample of ``tw``: NaN where ``tw`` is a failed sample (its configuration or rate)."""
    return x + 0.0 * tw[:, :1]


TRACK = 0.5  # m


def _tracks(tw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Right and left track speeds of the body twist ``tw`` (forward speed +- yaw rate x half track)."""
    return tw[:, 3] + 0.5 * TRACK * tw[:, 2], tw[:, 3] - 0.5 * TRACK * tw[:, 2]


CHAIN: dict[str, Callable[[np.ndarray], Any]] = {
    "assemble": lambda tw: ss.assemble(ROBOT, _rows(tw, CFG)),
    "contact_frames": lambda tw: ss.contact_frames(ROBOT, _rows(tw, CFG)),
    "wheel_jacobians": lambda tw: ss.wheel_jacobians(ROBOT, _rows(tw, CFG)),
    "wheel_measurements": lambda tw: ss.wheel_measurements(ROBOT, CFG, tw, QD),
    "wheel_measurements(config_rate)": lambda tw: ss.wheel_measurements(ROBOT, CFG, TWIST, _rows(tw, QD)),
    "body_velocity": lambda tw: ss.body_velocity(ROBOT, _rows(tw, CFG), MEASURED[0]),
    "wheel_slip": lambda tw: ss.wheel_slip(ROBOT, RATES, tw[:, [3, 4, 2]], CFG),
    "skid_steer_turn": lambda tw: ss.skid_steer_turn(*_tracks(tw), TRACK),
    "wheel_lateral_velocity": lambda tw: ss.wheel_lateral_velocity(tw[:, 2], 0.3),
    "paper_lateral_slip": lambda tw: ss.paper_lateral_slip(
        _tracks(tw)[0], 0.5, ss.skid_steer_turn(*_tracks(tw), TRACK).radius, TRACK
    ),
}
STATE = {
    "config",
    "twist",
    "config_rate",
    "body_velocity",
    "state",
    "v_right",
    "v_left",
    "yaw_rate",
    "radius",
}
# masked per sample by design (a measured speed: NaN or inf), or one model fitted to all samples
MASKED = {"identify_icr", "icr_velocity"}
# a time series through a filter: lost steps are given by its encoder_ok / gyro_ok flags, NaN is refused
SERIES = {"planar_ekf"}


def test_body_velocity_returns_a_failed_sample():
    assert BV.valid.tolist() == [True, False, True, True]
    assert np.isnan(BV.twist[1]).all() and np.isfinite(BV.twist[GOOD]).all()


@pytest.mark.parametrize("name", sorted(CHAIN))
def test_a_failed_sample_chains(name):
    check_chain(CHAIN[name], BV.twist, 1, GOOD)


def test_every_function_taking_a_state_is_in_the_chain():
    names = {n.split("(")[0] for n in CHAIN}
    assert functions_taking(ss, STATE) - names - MASKED - SERIES == set()


def test_inf_and_overflowing_states_are_refused_not_chained():
    check_refused(lambda tw: ss.wheel_measurements(ROBOT, CFG, tw, QD), BV.twist, "Expected twist finite")


def test_control_the_unwrapped_function_refuses_the_failed_sample():
    """Without the boundary that carries failed samples the chain check fails: the rule can fail."""
    strict = ss.wheel_jacobians.__wrapped__
    check_strict_fails(lambda tw: strict(ROBOT, _rows(tw, CFG)), BV.twist, 1, GOOD)
