"""Failed samples chain through robomech.mechanisms.continuum (docs/conventions.md, "Failed samples
chain"): the inverse kinematics of a failed tip target (a NaN row: a failed sample of an earlier call)
is a failed pose (NaN ``psi``, ``reachable`` False); fed into every function of the package that takes
a pose, a drive or tensions it gives NaN / False at that sample and, at the other samples, what they
give alone.  Histories (a leading time axis) and the friction identifications (one estimate from all
samples) are no per-sample functions: they refuse NaN."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from chain_check import check_chain, check_refused, check_strict_fails, functions_taking

from robomech.mechanisms import continuum as c

ROBOT = c.ContinuumRobot.paper()
PSI0 = np.array([[0.3, 0.1], [0.5, -1.0], [0.1, 2.0], [0.4, 0.5]])
TIP = c.tip_position(ROBOT, PSI0)
TIP[1] = np.nan  # a failed sample of an earlier call
IK = c.inverse_kinematics(ROBOT, TIP)
GOOD = [0, 2, 3]
DIRECTION = np.ones(3)  # broadcast over the batch: the same for the mixed and the good batch
PULLEY = c.Pulley(radius=0.005, wrap=1.5, alpha=0.15, n=1.0)


def _q(psi: np.ndarray) -> np.ndarray:
    return c.compensated_drive(ROBOT, psi).q


def _tension(psi: np.ndarray) -> np.ndarray:
    return c.cable_tensions(ROBOT, psi).tension


CHAIN: dict[str, Callable[[np.ndarray], Any]] = {
    **{
        n: (lambda f: lambda psi: f(ROBOT, psi))(getattr(c, n))
        for n in (
            "forward_kinematics",
            "tip_position",
            "tip_jacobian",
            "disk_transforms",
            "elastic_energy",
            "elastic_gradient",
            "coupling_moments",
            "wrap_angles",
            "span_lengths",
            "span_jacobian",
            "cable_lengths",
            "cable_jacobian",
            "theoretical_drive",
            "cable_tensions",
            "compensated_drive",
        )
    },
    "friction_factors": lambda psi: c.friction_factors(ROBOT, psi, DIRECTION),
    "segment_transform": lambda psi: c.segment_transform(psi[:, 0], psi[:, 1], ROBOT.segment_length),
    "inverse_kinematics": lambda psi: c.inverse_kinematics(ROBOT, c.tip_position(ROBOT, psi)),
    "cable_elongation": lambda psi: c.cable_elongation(ROBOT, psi, _tension(psi), DIRECTION),
    "disk_equilibrium": lambda psi: c.disk_equilibrium(ROBOT, tension=_tension(psi), direction=DIRECTION),
    "simulate": lambda psi: c.simulate(ROBOT, _q(psi), DIRECTION, pulley=PULLEY),
    # a wrap angle of the failed pose (rad): the bend of its segment, NaN there
    "classical_capstan_ratio": lambda psi: c.classical_capstan_ratio(np.abs(psi[:, 0]), 0.2),
    "capstan_tension_ratio": lambda psi: c.capstan_tension_ratio(
        np.abs(psi[:, 0]), rho=2.5, alpha=1.0, n=0.5
    ),
}
STATE = {"psi", "q", "theta", "beta", "tension", "p_tip", "phi"}
# a leading time axis (a history) or one estimate from all samples: refuse NaN
NOT_PER_SAMPLE = {"simulate_history", "stick_slip_tensions", "identify_friction_from_pose"}


def test_inverse_kinematics_returns_a_failed_sample():
    assert IK.reachable.tolist() == [True, False, True, True]
    assert np.isnan(IK.psi[1]).all() and np.isfinite(IK.psi[GOOD]).all()


@pytest.mark.parametrize("name", sorted(CHAIN))
def test_a_failed_sample_chains(name):
    check_chain(CHAIN[name], IK.psi, 1, GOOD)


def test_every_function_taking_a_state_is_in_the_chain():
    assert functions_taking(c, STATE) - set(CHAIN) - NOT_PER_SAMPLE == set()


def test_inf_and_overflowing_states_are_refused_not_chained():
    check_refused(lambda psi: c.tip_jacobian(ROBOT, psi), IK.psi, "Expected psi finite")


def test_control_the_unwrapped_function_refuses_the_failed_sample():
    """Without the boundary that carries failed samples the chain check fails: the rule can fail."""
    check_strict_fails(lambda psi: c.cable_lengths.__wrapped__(ROBOT, psi), IK.psi, 1, GOOD)
