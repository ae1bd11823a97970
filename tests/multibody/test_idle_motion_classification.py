"""Idle motions: motions with every actuated joint locked that move no output body (the bodies that
carry sites, every body if there is none), turn no welded body, and move none of the points that connect
or carry mass (every tree joint's anchor, the closure points, the centres of mass of the bodies with
mass) -- a Delta forearm or an RSSR coupler spinning about its own axis. Three descriptions a user
writes where watching the output bodies alone would count real degrees of freedom as idle (a passive
chain straight at its reference, a cart-pole whose only site is on the cart, a chain of more links than
its tip has twist directions), and the rule itself: an RSSR linkage whose coupler's spin is idle or not
by where its mass is, and a pendulum whose massless links carry only joint anchors."""

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


def test_a_passive_chain_hanging_straight_has_three_degrees_of_freedom():
    m = mb.mobility(mb.from_mjcf(TRIPLE_PENDULUM))
    assert (m.dof, m.idle_dof) == (3, 0)


def test_the_same_chain_away_from_straight_has_three():
    """Control: bent, the same description counts 3 DOF and no idle motion."""
    m = mb.mobility(mb.from_mjcf(TRIPLE_PENDULUM), np.array([0.3, -0.5, 0.8]))
    assert (m.dof, m.idle_dof) == (3, 0)


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


# ----------------------------------------------------------------------------- the rule on an RSSR linkage
# A spatial RSSR linkage: crank (hinge z at the origin, actuated) -- coupler (ball at the crank tip C,
# 0.5 m long along u = (0.6, 0.8, 0)) -- connect at R -- rocker (hinge x at G = (0.5, 0.4, 0.3), its
# tip R = G - 0.3 z).  Assembled at q0 by construction: C = (0.2, 0, 0), R = (0.5, 0.4, 0), |R - C| = 0.5.
# Gruebler-Kutzbach: 5 coordinates - 3 equations = 2, the textbook RSSR count of one DOF plus the
# coupler's spin about the line through its two spherical joints (Hartenberg & Denavit, Kinematic
# Synthesis of Linkages, 1964, sec. 3.6: a passive "idle" freedom).  Whether that spin is idle depends
# on the coupler's mass: it moves no joint anchor, closure point or site, so it is idle as long as the
# coupler's centre of mass is on that line (or it has none); off the line, gravity does work along it
# and it is a second degree of freedom.
COUPLER_LENGTH = 0.5
COUPLER_AXIS = np.array([0.6, 0.8, 0.0])
# rotation and finite motions of the spin are built from unit vectors and 0.5 m lengths: rounding only
ROUNDING_TOL = 1e-12
SPIN = 0.7  # rad, a finite spin of the coupler about its own axis


def _rssr(coupler: mb.Inertial | None) -> mb.Mechanism:
    c, s = COUPLER_AXIS[:2]
    b = mb.Builder("rssr")
    b.body(
        "crank",
        joints=[b.hinge("theta", axis=(0, 0, 1))],
        inertial=mb.Inertial(0.5, pos=(0.1, 0, 0), diaginertia=(1e-4, 2e-3, 2e-3)),
    )
    # the coupler's body x axis is u: a rotation about z by atan2(0.8, 0.6)
    b.body(
        "coupler",
        "crank",
        pos=(0.2, 0, 0),
        quat=(np.sqrt((1 + c) / 2), 0, 0, s / np.sqrt(2 * (1 + c))),
        joints=[b.ball("s1")],
        inertial=coupler,
    )
    b.body(
        "rocker",
        pos=(0.5, 0.4, 0.3),
        joints=[b.hinge("phi", axis=(1, 0, 0))],
        inertial=mb.Inertial(0.3, pos=(0, 0, -0.15), diaginertia=(2e-3, 2e-3, 1e-4)),
    )
    b.connect("s2", "coupler", "rocker", anchor1=(COUPLER_LENGTH, 0, 0), anchor2=(0, 0, -0.3))
    b.site("tip", "rocker", pos=(0, 0, -0.3))
    b.actuate("theta")
    return b.build()


RSSR = {
    "massless coupler": _rssr(None),
    "coupler with its centre of mass on its axis": _rssr(
        mb.Inertial(0.4, pos=(0.25, 0, 0), diaginertia=(2e-5, 8e-3, 8e-3))
    ),
    "coupler with its centre of mass off its axis": _rssr(
        mb.Inertial(0.4, pos=(0.25, 0.04, 0), diaginertia=(2e-5, 8e-3, 8e-3))
    ),
}
IDLE = {
    "massless coupler": 1,
    "coupler with its centre of mass on its axis": 1,
    "coupler with its centre of mass off its axis": 0,
}


def _spun(mech: mb.Mechanism, q: np.ndarray, angle: float) -> np.ndarray:
    """``q`` with the coupler turned by ``angle`` about its own axis (body x): a finite motion with the
    crank locked, written directly on the ball's quaternion (right-multiplied: a body-frame rotation)."""
    k = mech.tree.jnt_qadr[mech.tree.joint_index("s1")]
    w, x, y, z = q[k : k + 4]
    c, s = np.cos(angle / 2), np.sin(angle / 2)
    out = q.copy()
    out[k : k + 4] = [w * c - x * s, w * s + x * c, y * c + z * s, z * c - y * s]
    return out


@pytest.mark.parametrize("name", list(RSSR))
def test_an_rssr_coupler_spin_is_idle_exactly_when_its_mass_is_on_its_axis(name):
    mech, idle = RSSR[name], IDLE[name]
    m = mb.mobility(mech)
    assert m.gruebler_kutzbach == 2 and m.total_dof == 2
    assert (m.dof, m.idle_dof) == (2 - idle, idle)
    # the same counts at another assembled configuration
    q1 = mb.forward_kinematics(mech, np.array([[0.4]])).q[0]
    m1 = mb.mobility(mech, q1)
    assert (m1.dof, m1.idle_dof) == (m.dof, m.idle_dof)
    # the spin, as a finite motion, keeps the closure, the crank and the rocker's site: with the mass on
    # the axis it changes no energy either (nothing that matters moves: idle); off it, gravity does
    # work along it (a degree of freedom the crank does not determine)
    q = mech.q0
    qs = _spun(mech, q, SPIN)
    assert np.max(np.abs(mb.constraint_residual(mech, qs))) < ROUNDING_TOL
    assert np.allclose(mb.site_pose(mech, qs, "tip"), mb.site_pose(mech, q, "tip"), atol=ROUNDING_TOL)
    zero = np.zeros(mech.nv)
    dU = float(mb.energy(mech, qs, zero)[1] - mb.energy(mech, q, zero)[1])
    if idle:
        assert abs(dU) < ROUNDING_TOL
        mb.inverse_dynamics(mech, q[None], np.array([[0.5]]), np.array([[1.0]]))  # the crank determines it
    else:
        assert abs(dU) > 1e-3  # 0.4 kg, 4 cm off the axis: ~0.1 J over 0.7 rad
        with pytest.raises(ValueError, match="do not determine"):
            mb.inverse_dynamics(mech, q[None], np.array([[0.5]]), np.array([[1.0]]))


def _pendulum_with_massless_upper_links() -> mb.Mechanism:
    """The triple pendulum's geometry with its first two links massless: only the joint anchors they
    carry (a2 on l1, a3 on l2) tie their motion to anything watched."""
    b = mb.Builder("massless_upper_links")
    b.body("l1", pos=(0, 0, 2), joints=[b.hinge("a1", axis=(0, 1, 0))])
    b.body("l2", "l1", pos=(0, 0, -0.5), joints=[b.hinge("a2", axis=(0, 1, 0))])
    b.body(
        "l3",
        "l2",
        pos=(0, 0, -0.4),
        joints=[b.hinge("a3", axis=(0, 1, 0))],
        inertial=mb.Inertial(0.6, pos=(0, 0, -0.16), diaginertia=(0.0061, 0.006, 0.0005)),
    )
    b.site("tip", "l3", pos=(0, 0, -0.3))
    return b.build()


def test_the_joint_anchors_keep_massless_links_from_counting_idle():
    """Straight, l3 (the output) stays still to first order when a1 turns at w, a2 at -9w/4 (a3's anchor
    stays put: 0.9 w - 0.4 (9w/4) = 0) and a3 at 5w/4 (l3 keeps its orientation): only the anchor a2 that
    the massless l1 carries moves.  Watched, it makes the three swings degrees of freedom, straight as
    bent."""
    mech = _pendulum_with_massless_upper_links()
    for q in (np.zeros(3), np.array([0.3, -0.5, 0.8])):
        m = mb.mobility(mech, q)
        assert (m.total_dof, m.dof, m.idle_dof) == (3, 3, 0)


def test_a_chain_of_more_links_than_its_tip_has_twist_directions_has_a_dof_per_link():
    """Ten massive links (hinges alternately about y and z, links along x), actuated at the first, a site
    at the tip: the tip's twist spans 4 directions over the 9 locked swings (it never turns about x), so
    the output body alone would leave 5 of them idle at any pose; every swing moves a centre of mass, so
    each is a degree of freedom."""
    b = mb.Builder("chain")
    parent = "world"
    for i in range(10):
        parent = b.body(
            f"b{i}",
            parent=parent,
            pos=(0.1, 0, 0) if i else (0, 0, 0),
            joints=[b.hinge(f"j{i}", (0, 0, 1) if i % 2 else (0, 1, 0))],
            inertial=mb.Inertial(1.0, pos=(0.05, 0, 0), diaginertia=(0.01, 0.01, 0.01)),
        )
    b.site("tip", parent, pos=(0.1, 0, 0))
    b.actuate("j0")
    m = mb.mobility(b.build())
    assert (m.total_dof, m.dof, m.idle_dof, m.locked_dof) == (10, 10, 0, 9)
