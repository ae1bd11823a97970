"""Generic closed-chain inverse dynamics (robomech.multibody) of the spherical leg vs paper 1's Kane model.

Finding (issue 13): the two differ by exactly one effect.  The description (``sl.to_multibody``) puts a
universal joint at each leg's base A_i, so every leg body turns about its own axis at the rate the
cardan imposes, ``w . s = sin(u_b) du_a/dt``; the analytic model (``_dynamics.py``) assumes the leg
bodies "do not spin about the leg axis (the S-P-S motion of an axisymmetric leg)".  With the legs'
axial inertias set to zero (and the lead-screw spin off) both models agree to rounding, and with them
the whole difference in the mass matrix is the kinetic energy of that spin, ``1/2 I_ax (w . s)^2`` per
leg body — checked below to rounding.  Whether the analytic model is "wrong" depends on the base joint:
for the paper's U-jointed legs the spin is kinematically forced and the analytic model misses it (a
0.1-1% error in M for the paper's inertias); for S-P-S legs it is an idle motion and the analytic model
is the at-rest choice.  The strict xfail records the disagreement until the owners of
``mechanisms/spherical_leg`` decide (fix: add ``1/2 I_ax (w . s)^2`` with the cardan's spin rate).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from robomech import multibody as mb
from robomech.mechanisms import spherical_leg as sl
from robomech.multibody._tree import body_twists, kinematics

# Both models are exact rigid-body dynamics; agreement to rounding (measured ~1e-15 relative).
AGREE_RTOL = 1e-10
# The acceptance bar of issue 13 for generic vs analytic dynamics.
ISSUE_RTOL = 1e-8

LEG = sl.SphericalLeg.paper()
RNG = np.random.default_rng(5)
AB = RNG.uniform(-0.5, 0.5, (5, 2))
QD = RNG.normal(size=(5, 2))
QDD = RNG.normal(size=(5, 2))


def _no_axial(mech):
    """The description with the leg bodies' inertia about their own axis (local x) set to zero."""
    bodies = []
    for b in mech.bodies:
        if b.inertial is not None and b.name != "platform":
            d = b.inertial.diaginertia
            inertial = dataclasses.replace(b.inertial, diaginertia=(0.0, d[1], d[2]))
            b = dataclasses.replace(b, inertial=inertial)
        bodies.append(b)
    return dataclasses.replace(mech, bodies=tuple(bodies))


def _leg_motion(by_angles, q):
    inf = mb.influence(by_angles, q)
    rows = [by_angles.dof_address(f"l{k}") for k in (1, 2, 3)]
    ld = np.einsum("nij,nj->ni", inf.G[:, rows], QD)
    ldd = np.einsum("nij,nj->ni", inf.G[:, rows], QDD) + np.einsum("nijk,nj,nk->ni", inf.dG[:, rows], QD, QD)
    return ld, ldd


def _rel(a, b):
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


def test_generic_equals_kane_model_without_leg_spin():
    leg = dataclasses.replace(LEG, screw_spin=False)
    by_angles = _no_axial(sl.to_multibody(leg, actuate="platform"))
    by_legs = _no_axial(sl.to_multibody(leg))
    q = mb.forward_kinematics(by_angles, AB).q
    # a wrench on the platform: analytic [m_O; f] about O, generic about the platform site
    W = RNG.normal(size=(5, 6))
    p = mb.site_pose(by_angles, q, "platform")[:, :3, 3]
    W_site = np.concatenate([W[:, :3] - np.cross(p, W[:, 3:]), W[:, 3:]], axis=-1)
    gen = mb.inverse_dynamics(by_angles, q, QD, QDD, wrenches={"platform": W_site})
    ana = sl.inverse_dynamics(leg, AB, QD, QDD, platform_wrench=W)
    assert gen.valid.all() and ana.valid.all()
    assert _rel(gen.tau, ana.generalized_forces) < AGREE_RTOL
    assert _rel(gen.M_a, sl.mass_matrix(leg, AB)) < AGREE_RTOL
    # leg forces of the redundantly actuated leg: minimum norm, and paper 1's two driven legs
    ld, ldd = _leg_motion(by_angles, q)
    f = mb.inverse_dynamics(by_legs, q, ld, ldd, wrenches={"platform": W_site})
    assert f.valid.all()
    assert _rel(f.tau, ana.leg_forces) < AGREE_RTOL
    driven = sl.inverse_dynamics(leg, AB, QD, QDD, platform_wrench=W, driven_legs=sl.PAPER_DRIVEN_LEGS)
    w = np.zeros(3)
    w[list(sl.PAPER_DRIVEN_LEGS)] = 1.0
    f2 = mb.inverse_dynamics(by_legs, q, ld, ldd, wrenches={"platform": W_site}, weights=w)
    assert _rel(f2.tau, driven.leg_forces) < AGREE_RTOL


def test_the_whole_difference_is_the_spin_the_universal_joints_impose():
    by_angles = sl.to_multibody(LEG, actuate="platform")
    q = mb.forward_kinematics(by_angles, AB).q
    gen = mb.inverse_dynamics(by_angles, q, QD, QDD)
    T_gen = 0.5 * np.einsum("ni,nij,nj->n", QD, gen.M_a, QD)
    T_ana = 0.5 * np.einsum("ni,nij,nj->n", QD, sl.mass_matrix(LEG, AB), QD)
    tree = by_angles.tree
    st = kinematics(tree, q)
    V = body_twists(tree, st, gen.qd)
    spin_energy = np.zeros(len(AB))
    for k in (1, 2, 3):
        cardan = tree.body_index(f"cardan{k}")
        s = st.T[:, cardan, :3, 0]  # the leg axis (the cardan's local x)
        w_u = np.einsum("ni,ni->n", V[:, cardan, :3], s)  # the spin the universal joint imposes
        for name in (f"screw{k}" if k != 2 else f"lower{k}", f"upper{k}"):
            b = tree.body_index(name)
            I_ax = by_angles.bodies[b - 1].inertial.diaginertia[0]
            w_b = np.einsum("ni,ni->n", V[:, b, :3], s)
            spin_energy += 0.5 * I_ax * (w_b**2 - (w_b - w_u) ** 2)  # (w_b - w_u): the screw's own spin
    assert np.max(np.abs(spin_energy)) > 1e3 * AGREE_RTOL * np.max(T_ana)  # the effect is real
    assert np.max(np.abs(T_gen - T_ana - spin_energy)) < AGREE_RTOL * np.max(T_ana)


@pytest.mark.xfail(
    strict=True,
    reason="paper 1 Kane model omits the leg spin imposed by the universal joints (see module docstring)",
)
def test_generic_equals_kane_model_as_described():
    by_angles = sl.to_multibody(LEG, actuate="platform")
    q = mb.forward_kinematics(by_angles, AB).q
    gen = mb.inverse_dynamics(by_angles, q, QD, QDD)
    ana = sl.inverse_dynamics(LEG, AB, QD, QDD)
    assert _rel(gen.tau, ana.generalized_forces) < ISSUE_RTOL
