"""Idle motions are motions with every actuator locked that move no output body (the bodies that carry
sites).  Two descriptions a user writes show the rule counting real degrees of freedom as idle; both
are known defects of the reference mobility (``_compile`` / ``_mobility``), kept here as strict
expected failures so that the fix turns them into passes that must be unmarked."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robomech import multibody as mb

mujoco = pytest.importorskip("mujoco")

# Three links hanging straight down at qpos0, no actuator, one site at the tip.
TRIPLE_PENDULUM = (Path(__file__).parent / "data" / "triple_pendulum.xml").read_text()

# A cart on a slide (actuated) with a passive pole; the only site is on the cart.
CART_POLE = """<mujoco model="cart_pole"><worldbody>
  <body name="cart" pos="0 0 0.3"><joint name="x" type="slide" axis="1 0 0"/>
    <site name="cart_site"/><inertial pos="0 0 0" mass="2.0" diaginertia="0.02 0.03 0.04"/>
    <body name="pole"><joint name="theta" axis="0 1 0"/>
      <inertial pos="0.01 0 0.3" mass="0.4" fullinertia="0.012 0.0121 0.0002 0 0.0003 0"/></body></body>
</worldbody><actuator><motor joint="x"/></actuator></mujoco>"""


@pytest.mark.xfail(
    strict=True,
    raises=AssertionError,
    reason="the tip's Jacobian loses a rank at the straight pose: one swing is counted idle (DOF 2 + 1 idle)",
)
def test_a_passive_chain_hanging_straight_has_three_degrees_of_freedom():
    m = mb.mobility(mb.from_mjcf(TRIPLE_PENDULUM))
    assert (m.dof, m.idle_dof) == (3, 0)


def test_the_same_chain_away_from_straight_has_three():
    """Control: bent, the same description counts 3 DOF and no idle motion."""
    m = mb.mobility(mb.from_mjcf(TRIPLE_PENDULUM), np.array([0.3, -0.5, 0.8]))
    assert (m.dof, m.idle_dof) == (3, 0)


@pytest.mark.xfail(
    strict=True,
    raises=AssertionError,
    reason="the pole moves no site, so its swing counts idle: the actuated-rate form is accepted and "
    "returns valid forces for a motion the pole's gravity torque does not allow",
)
def test_an_unactuated_pole_without_a_site_is_not_idle():
    mech = mb.from_mjcf(CART_POLE)
    q, qd_act, qdd_act = np.array([[0.1, 0.4]]), np.array([[0.5]]), np.array([[1.0]])
    try:
        inv = mb.inverse_dynamics(mech, q, qd_act, qdd_act)
    except ValueError:
        return  # refused like the same cart with a site on the pole: the actuators do not determine it
    # otherwise the forces must produce the motion they were asked for (MuJoCo's forward dynamics)
    m = mujoco.MjModel.from_xml_string(CART_POLE)
    d = mujoco.MjData(m)
    d.qpos[:], d.qvel[:], d.ctrl[:] = q[0], inv.qd[0], inv.tau[0]
    mujoco.mj_forward(m, d)
    assert not inv.valid[0] or np.allclose(d.qacc[:1], qdd_act[0], atol=1e-9)
