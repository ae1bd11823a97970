"""Failed samples chain through robomech.mechanisms.spherical_leg (docs/conventions.md, "Failed samples
chain"): a forward-kinematics sample that has no pose (NaN angles, ``valid`` False) fed into every
function of the package that takes platform angles or a motion state gives NaN / False at that sample
and, at the other samples, what they give alone."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from chain_check import check_chain, check_refused, check_strict_fails, functions_taking

from robomech.mechanisms import spherical_leg as sl

LEG = sl.SphericalLeg.paper()
A0 = np.array([0.1, 0.2, -0.3, 0.05])
B0 = np.array([0.0, 0.1, 0.2, -0.15])
LENGTHS = sl.inverse_kinematics(LEG, A0, B0).lengths.copy()
LENGTHS[1] = [0.01, 0.5, 0.01]  # no platform pose has these leg lengths: sample 1 fails
FK = sl.forward_kinematics(LEG, LENGTHS)
Q = np.stack([FK.alpha, FK.beta], -1)  # (4, 2), row 1 NaN
GOOD = [0, 2, 3]
RATES = np.array([0.3, -0.2])  # broadcast over the batch: the same for the mixed and the good batch
W = np.array([0.0, 0.1, 0.0, 1.0, 0.0, -2.0])

# call(q) with q (N, 2) = (alpha, beta) of the FK output
CHAIN: dict[str, Callable[[np.ndarray], Any]] = {
    "inverse_kinematics": lambda q: sl.inverse_kinematics(LEG, q[:, 0], q[:, 1]),
    "platform_rotation": lambda q: sl.platform_rotation(q[:, 0], q[:, 1]),
    "jacobian": lambda q: sl.jacobian(LEG, q[:, 0], q[:, 1]),
    "hessian": lambda q: sl.hessian(LEG, q[:, 0], q[:, 1]),
    "influence_coefficients": lambda q: sl.influence_coefficients(LEG, q[:, 0], q[:, 1]),
    "angular_velocity_jacobian": lambda q: sl.angular_velocity_jacobian(q[:, 0]),
    "workspace_map": lambda q: sl.workspace_map(LEG, q[:, 0], q[:, 1]),
    "leg_rates": lambda q: sl.leg_rates(LEG, q, RATES, RATES),
    "generalized_forces": lambda q: sl.generalized_forces(LEG, q, RATES, RATES, platform_wrench=W),
    "mass_matrix": lambda q: sl.mass_matrix(LEG, q),
    "mechanical_energy": lambda q: sl.mechanical_energy(LEG, q, RATES),
    "inverse_dynamics": lambda q: sl.inverse_dynamics(LEG, q, RATES, RATES, platform_wrench=W),
    # a failed rate (the NaN row of leg_rates' output fed back as qd / qdd)
    "inverse_dynamics(qd)": lambda q: sl.inverse_dynamics(LEG, np.nan_to_num(q), q, RATES),
    "forward_kinematics(lengths)": lambda q: sl.forward_kinematics(
        LEG, sl.inverse_kinematics(LEG, q[:, 0], q[:, 1]).lengths
    ),
}
STATE = {"alpha", "beta", "q", "qd", "qdd", "lengths"}
# state-like arguments that are masked per sample by design (a measured length: NaN or inf)
MASKED = {"forward_kinematics", "track_branches", "distribute_forces"}
# functions of time only (their argument is a time grid, no output of the package)
NO_STATE = {"sway", "fig5_motion"}


def test_forward_kinematics_returns_a_failed_sample():
    assert FK.valid.tolist() == [True, False, True, True]
    assert np.isnan(Q[1]).all() and np.isfinite(Q[GOOD]).all()


@pytest.mark.parametrize("name", sorted(CHAIN))
def test_a_failed_sample_chains(name):
    check_chain(CHAIN[name], Q, 1, GOOD)


def test_every_function_taking_a_state_is_in_the_chain():
    assert functions_taking(sl, STATE) - set(CHAIN) - MASKED == set()


def test_inf_and_overflowing_states_are_refused_not_chained():
    check_refused(lambda q: sl.mass_matrix(LEG, q), Q, "Expected q finite")


def test_control_the_unwrapped_function_refuses_the_failed_sample():
    """Without the boundary that carries failed samples the chain check fails: the rule can fail."""
    check_strict_fails(lambda q: sl.jacobian.__wrapped__(LEG, q[:, 0], q[:, 1]), Q, 1, GOOD)
