"""Failed samples chain through robomech.mechanisms.vectored_thrust (docs/conventions.md, "Failed
samples chain"): an inverse-kinematics sample with no joint solution (NaN ``q``, ``valid`` False) fed
into every function of the package that takes joint angles or rates gives NaN / False at that sample
and, at the other samples, what they give alone.  The functions of one configuration (the screw
systems and mobilities) refuse it."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from chain_check import check_chain, check_refused, check_strict_fails, functions_taking

from robomech.mechanisms import vectored_thrust as vt

TH = vt.VectoredThruster()
Q0 = np.array([[0.3, -0.2], [0.1, 0.2], [-0.5, 0.0], [0.2, 0.1]])
S = vt.forward_kinematics(TH, Q0).axis
S[1] = np.array([1.0, 0.0, -1.0]) / np.sqrt(2.0)  # thrust axis tilted 135 deg: no joint solution
IK = vt.inverse_kinematics(TH, S)
GOOD = [0, 2, 3]
QD = np.array([0.3, -0.2])  # broadcast over the batch: the same for the mixed and the good batch
W = np.array([0.1, -0.2, 0.3])


def _arcs(q: np.ndarray) -> tuple[np.ndarray, ...]:
    """Two arcs between joint axes of the configurations ``q`` (NaN rows where ``q`` failed)."""
    ax = vt.joint_axes(TH, q)
    return ax.s11, ax.s12, ax.s12, ax.s13


CHAIN: dict[str, Callable[[np.ndarray], Any]] = {
    "forward_kinematics": lambda q: vt.forward_kinematics(TH, q),
    "platform_rotation": lambda q: vt.platform_rotation(TH, q),
    "joint_axes": lambda q: vt.joint_axes(TH, q),
    "passive_angles": lambda q: vt.passive_angles(TH, q),
    "jacobian": lambda q: vt.jacobian(TH, q),
    "workspace_map": lambda q: vt.workspace_map(TH, q),
    "link_clearance": lambda q: vt.link_clearance(TH, q),
    "dexterity": lambda q: vt.dexterity(TH, q),
    "passive_rates": lambda q: vt.passive_rates(TH, q, QD),
    "angular_velocity": lambda q: vt.angular_velocity(TH, q, QD),
    "angular_acceleration": lambda q: vt.angular_acceleration(TH, q, QD, QD),
    "idle_input_curve": lambda q: vt.idle_input_curve(TH, q[:, 0]),
    "inverse_rates": lambda q: vt.inverse_rates(TH, q, W, W),
    "static_torques": lambda q: vt.static_torques(TH, q, np.concatenate([W, W])),
    # the failed sample's thrust axis and angular velocity (NaN rows of outputs) fed back
    "arc_clearance": lambda q: vt.arc_clearance(*_arcs(q)),
    "inverse_kinematics(s)": lambda q: vt.inverse_kinematics(TH, vt.forward_kinematics(TH, q).axis),
    "inverse_rates(omega)": lambda q: vt.inverse_rates(
        TH, np.nan_to_num(q), vt.angular_velocity(TH, q, QD).omega
    ),
}
# functions of one configuration: a failed sample has no screw system or mobility
SINGLE: dict[str, Callable[[np.ndarray], Any]] = {
    "chain_screws": lambda q: vt.chain_screws(TH, q[1]),
    "platform_mobility": lambda q: vt.platform_mobility(TH, q[1]),
    "mechanism_mobility": lambda q: vt.mechanism_mobility(TH, q[1]),
}
STATE = {"q", "qd", "qdd", "q1", "s", "omega", "omega_dot", "a1", "b1", "a2", "b2"}


def test_inverse_kinematics_returns_a_failed_sample():
    assert IK.valid.tolist() == [True, False, True, True]
    assert np.isnan(IK.q[1]).all() and np.isfinite(IK.q[GOOD]).all()


@pytest.mark.parametrize("name", sorted(CHAIN))
def test_a_failed_sample_chains(name):
    check_chain(CHAIN[name], IK.q, 1, GOOD)


@pytest.mark.parametrize("name", sorted(SINGLE))
def test_a_failed_configuration_is_refused_by_single_configuration_functions(name):
    with pytest.raises(ValueError, match=r"\bq\b"):
        SINGLE[name](IK.q)


def test_every_function_taking_a_state_is_in_the_chain():
    names = {n.split("(")[0] for n in CHAIN}
    assert functions_taking(vt, STATE) - names - set(SINGLE) == set()


def test_inf_and_overflowing_states_are_refused_not_chained():
    check_refused(lambda q: vt.jacobian(TH, q), IK.q, "Expected q finite")


def test_control_the_unwrapped_function_refuses_the_failed_sample():
    """Without the boundary that carries failed samples the chain check fails: the rule can fail."""
    check_strict_fails(lambda q: vt.angular_velocity.__wrapped__(TH, q, QD), IK.q, 1, GOOD)
