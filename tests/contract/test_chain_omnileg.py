"""Failed samples chain through robomech.mechanisms.omnileg (docs/conventions.md, "Failed samples
chain"): an inverse-kinematics sample that has no joint solution (NaN ``q``, ``exists`` False) fed
into every function of the package that takes joint angles or rates gives NaN / False at that sample
and, at the other samples, what they give alone."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from chain_check import check_chain, check_refused, check_strict_fails, functions_taking

from robomech.mechanisms import omnileg as ol

LEG = ol.OmniLeg.paper()
Q0 = np.array([[0.1, 0.2, 0.5], [-0.2, 0.1, 0.7], [0.0, 0.0, 0.3], [0.2, -0.1, 0.6]])
P_FOOT = ol.forward_kinematics(LEG, Q0)
P_FOOT[1] = [5.0, 5.0, 5.0]  # 5 m from the hip: no joint solution, sample 1 fails
IK = ol.inverse_kinematics(LEG, P_FOOT)
GOOD = [0, 2, 3]
QD = np.array([0.3, -0.2, 0.1])  # broadcast over the batch: the same for the mixed and the good batch
F = np.array([1.0, -2.0, 30.0])

CHAIN: dict[str, Callable[[np.ndarray], Any]] = {
    "forward_kinematics": lambda q: ol.forward_kinematics(LEG, q),
    "jacobian": lambda q: ol.jacobian(LEG, q),
    "hessian": lambda q: ol.hessian(LEG, q),
    "foot_velocity": lambda q: ol.foot_velocity(LEG, q, QD),
    "foot_acceleration": lambda q: ol.foot_acceleration(LEG, q, QD, QD),
    "body_poses": lambda q: ol.body_poses(LEG, q),
    "mass_matrix": lambda q: ol.mass_matrix(LEG, q),
    "gravity_torques": lambda q: ol.gravity_torques(LEG, q),
    "energy": lambda q: ol.energy(LEG, q, QD),
    "static_torques": lambda q: ol.static_torques(LEG, q, F),
    "joint_motion": lambda q: ol.joint_motion(LEG, q, QD, QD),
    "inverse_dynamics": lambda q: ol.inverse_dynamics(LEG, q, QD, QD, foot_force=F),
    "foot_force_from_torques": lambda q: ol.foot_force_from_torques(LEG, q, QD),
    "thigh_direction": lambda q: ol.thigh_direction(q[:, 0], q[:, 1]),
    "passive_angles": lambda q: ol.passive_angles(LEG, q[:, 0], q[:, 1]),
    "thigh_closure": lambda q: ol.thigh_closure(LEG, q[:, 0], q[:, 1]),
    "shank_crank_slider": lambda q: ol.shank_crank_slider(LEG, q[:, 2]),
    "joint_rates": lambda q: ol.joint_rates(LEG, q, QD, QD),
    "workspace_map": lambda q: ol.workspace_map(LEG, q),
    "within_limits": lambda q: ol.within_limits(LEG, q),
    # the failed sample's foot velocity (NaN row of foot_velocity's output) fed to joint_rates
    "joint_rates(foot_velocity)": lambda q: ol.joint_rates(
        LEG, np.nan_to_num(q), ol.foot_velocity(LEG, q, QD)
    ),
}
STATE = {"q", "qd", "qdd", "alpha", "beta", "gamma", "foot_velocity", "foot_acceleration"}
# alpha, beta of singular_surface are the axes of a grid, not samples: a NaN axis value has no row
GRID = {"singular_surface"}


def test_inverse_kinematics_returns_a_failed_sample():
    assert IK.exists.tolist() == [True, False, True, True]
    assert np.isnan(IK.q[1]).all() and np.isfinite(IK.q[GOOD]).all()


@pytest.mark.parametrize("name", sorted(CHAIN))
def test_a_failed_sample_chains(name):
    check_chain(CHAIN[name], IK.q, 1, GOOD)


def test_every_function_taking_a_state_is_in_the_chain():
    assert functions_taking(ol, STATE) - set(CHAIN) - GRID == set()


def test_inf_and_overflowing_states_are_refused_not_chained():
    check_refused(lambda q: ol.jacobian(LEG, q), IK.q, "Expected q finite")


def test_control_the_unwrapped_function_refuses_the_failed_sample():
    """Without the boundary that carries failed samples the chain check fails: the rule can fail."""
    check_strict_fails(lambda q: ol.mass_matrix.__wrapped__(LEG, q), IK.q, 1, GOOD)
