"""robomech.multibody second-order coefficients, mobility, singularities, maps and the drawing."""

from __future__ import annotations

import dataclasses

import matplotlib
import numpy as np
import pytest
from scipy.optimize import brentq

from robomech import multibody as mb
from robomech.analysis import workspace
from robomech.testing import numerical_jacobian

from .test_core import FD_TOL, FOUR_BAR, _rssr

matplotlib.use("Agg")

# Closed-chain acceleration identities (K qdd + Kdot qd = 0) hold to rounding of O(1) terms.
IDENTITY_TOL = 1e-12
# Second time-derivative by central differences (step 1e-4 s): truncation ~h^2 f'''' ~ 1e-8 for
# these O(1)-O(10) motions, rounding eps/h^2 ~ 2e-8.
ACCEL_FD_TOL = 1e-6


def test_dG_is_the_derivative_of_G():
    for mech in (FOUR_BAR, _rssr()):
        fk = mb.forward_kinematics(mech, np.linspace(-0.5, 0.5, 4)[:, None])
        inf = mb.influence(mech, fk.q)

        def G_of(x, guess=fk.q, mech=mech):
            return mb.influence(mech, mb.forward_kinematics(mech, x, guess=guess).q, second_order=False).G

        if mech is FOUR_BAR:  # the RSSR's coupler spin is idle: only the min-norm G is differentiable
            dG_num = numerical_jacobian(G_of, fk.q[:, mech.tree.act_qadr])
            assert np.max(np.abs(inf.dG - dG_num)) < FD_TOL


def test_accelerations_close_the_loops_and_match_the_trajectory():
    """qdd = G qdd_a + dG(qd_a, qd_a) satisfies K qdd + Kdot qd = 0; site accel = J qdd_a + H(qd_a, qd_a)."""
    mech = FOUR_BAR
    t = np.array([0.3])
    h = 1e-4

    def qa_of(t):
        return np.stack([0.7 * np.sin(1.3 * t) + 0.2 * t], axis=-1)

    qa, qda, qdda = (
        qa_of(t),
        0.7 * 1.3 * np.cos(1.3 * t)[:, None] + 0.2,
        -0.7 * 1.69 * np.sin(1.3 * t)[:, None],
    )
    fk = mb.forward_kinematics(mech, qa)
    inf = mb.influence(mech, fk.q)
    qd = np.einsum("nij,nj->ni", inf.G, qda)
    qdd = np.einsum("nij,nj->ni", inf.G, qdda) + np.einsum("nijk,nj,nk->ni", inf.dG, qda, qda)
    K = mb.constraint_jacobian(mech, fk.q)
    Kd = mb.constraint_jacobian_rate(mech, fk.q, qd)
    assert np.max(np.abs(np.einsum("nij,nj->ni", K, qdd) + np.einsum("nij,nj->ni", Kd, qd))) < IDENTITY_TOL
    J = mb.site_jacobian(mech, fk.q, "coupler_point")
    H = mb.site_hessian(mech, fk.q, "coupler_point")
    acc = np.einsum("nij,nj->ni", J, qdda) + np.einsum("nijk,nj,nk->ni", H, qda, qda)

    def p_of(tt):
        q = mb.forward_kinematics(mech, qa_of(np.array([tt])), guess=fk.q).q
        return mb.site_pose(mech, q, "coupler_point")[0, :3, 3]

    p_dd = (p_of(t[0] + h) - 2 * p_of(t[0]) + p_of(t[0] - h)) / h**2
    assert np.max(np.abs(acc[0, 3:] - p_dd)) < ACCEL_FD_TOL


def test_mobility_of_four_bars_and_the_rssr():
    m = mb.mobility(FOUR_BAR)
    assert (m.dof, m.idle_dof, m.gruebler_kutzbach, m.redundant_constraints) == (1, 0, 0, 1)
    assert not m.singular and m.actuation == "exact"
    # the coupler of the reference configuration translates (crank parallel to rocker): screw theory agrees
    assert m.platform == "coupler" and m.platform_dof == 1 and m.platform_rotational_dof == 0
    assert m.screw_theory.dof == 1 and m.screw_theory.rotational_dof == 0
    # RSSR with its output on the rocker: 1 DOF and the coupler's idle spin
    rssr = _rssr()
    rssr = dataclasses.replace(rssr, sites=(mb.Site("out", "rocker", (0.0, 0.2, 0.1)),))
    r = mb.mobility(rssr)
    assert (r.dof, r.idle_dof, r.total_dof, r.gruebler_kutzbach) == (1, 1, 2, 2)


def _parallelogram():
    """a = c = 0.5, b = d = 1: at theta2 = 0 every link is on the x axis, a change point."""
    b = mb.Builder("parallelogram")
    b.body("crank", joints=[b.hinge("t2")])
    b.body("coupler", parent="crank", pos=(0.5, 0, 0), joints=[b.hinge("t3")])
    b.body("rocker", pos=(1.0, 0, 0), joints=[b.hinge("t4")])
    b.connect("C", "coupler", "rocker", anchor1=(1.0, 0, 0), anchor2=(0.5, 0, 0))
    b.site("p", "coupler", pos=(0.5, 0.1, 0))
    b.actuate("t2")
    return b.build()


def test_change_point_is_singular_and_a_generic_configuration_is_not():
    mech = _parallelogram()
    flat = mech.q0  # theta2 = theta3 = theta4 = 0: folded flat
    m = mb.mobility(mech, flat, platform="coupler")
    assert m.singular and m.total_dof == 2
    fk = mb.forward_kinematics(mech, np.array([[0.6]]), guess=np.array([0.3, -0.3, 0.3]))
    assert fk.converged.all()
    generic = mb.mobility(mech, fk.q[0])
    assert not generic.singular and generic.dof == 1
    s = mb.singularities(mech, np.stack([flat, fk.q[0]]), "p", reference=fk.q[0])
    assert s.constraint.tolist() == [True, False]
    assert s.singular.tolist() == [True, False]


def test_type_I_and_type_II_depend_on_which_joint_drives():
    """At the rocker's extreme (crank and coupler aligned): type I crank-driven, type II rocker-driven."""
    mech = dataclasses.replace(
        FOUR_BAR, sites=(*FOUR_BAR.sites, mb.Site("rocker_tip", "rocker", (0.8, 0, 0)))
    )

    def rate(x):
        fk = mb.forward_kinematics(mech, np.array([[x]]), steps=3)
        return mb.influence(mech, fk.q, second_order=False).G[0, 2, 0]  # dθ4/dθ2

    x0 = brentq(rate, 1.5, 3.5, xtol=1e-14)
    q = mb.forward_kinematics(mech, np.array([[x0]]), steps=3).q[0]
    crank = mb.singularities(mech, q, "rocker_tip")
    assert crank.type_I and not crank.type_II
    rocker_driven = dataclasses.replace(mech, actuated=("theta4",))
    rd = mb.singularities(rocker_driven, q, "coupler_point")
    assert rd.type_II and not rd.type_I and not rd.constraint
    assert rd.sigma_II < 1e-8 * rd.length and crank.sigma_I < 1e-8 * crank.length
    # a generic configuration is neither
    g = mb.singularities(rocker_driven, mb.forward_kinematics(mech, np.array([[0.3]])).q, "coupler_point")
    assert not g.singular.any()


def test_singularity_map_over_an_input_grid():
    """Driven by the rocker, the four-bar reaches theta4 only between its two dead points (closed form)."""
    rocker_driven = dataclasses.replace(FOUR_BAR, actuated=("theta4",))
    grid = workspace.grid([(-1.2, 1.2)], 49)
    mp = mb.singularity_map(rocker_driven, "coupler_point", q_act=grid, steps=6)
    assert mp.reachable.shape == (49,)
    # dead points: crank and coupler aligned, |AC| = b +- a with C = D + c (cos θ4, sin θ4)
    a, b, c, d = 0.3, np.sqrt(1.06), 0.8, 0.9
    lo, hi = (np.arccos(((b + s * a) ** 2 - c * c - d * d) / (2 * c * d)) - np.pi / 2 for s in (1, -1))
    inside = (grid[:, 0] > lo + 1e-6) & (grid[:, 0] < hi - 1e-6)
    outside = (grid[:, 0] < lo - 1e-6) | (grid[:, 0] > hi + 1e-6)
    assert mp.reachable[inside].all() and not mp.reachable[outside].any()
    assert np.all(np.isfinite(mp.dexterity[mp.reachable])) and np.all(np.isnan(mp.dexterity[~mp.reachable]))
    # sigma_II falls towards both dead points and is largest inside
    s2 = mp.singularity.sigma_II[mp.reachable]
    assert np.argmax(s2) not in (0, len(s2) - 1)
    assert s2[0] < 0.5 * s2.max() and s2[-1] < 0.5 * s2.max()


def test_drawing_closes_the_loop():
    fk = mb.forward_kinematics(FOUR_BAR, np.array([[0.4]]))
    segs = mb.body_segments(FOUR_BAR, fk.q[0])
    assert set(segs) == {"crank", "coupler", "rocker"}
    C = mb.site_pose(FOUR_BAR, fk.q[0], "coupler_point")  # any point of the coupler
    assert C.shape == (4, 4)
    ends = np.concatenate([s[:, 1] for s in segs.values()])
    # the closure point is drawn from both the coupler and the rocker, and coincides
    d = np.linalg.norm(ends[:, None] - ends[None], axis=-1)
    assert np.sum(d < 1e-12) > len(ends)
    ax = mb.draw(FOUR_BAR, fk.q[0])
    assert len(ax.lines) == sum(len(s) for s in segs.values())
    with pytest.raises(ValueError, match="q"):
        mb.draw(FOUR_BAR, np.zeros((2, 3)))


def test_singularity_map_over_an_output_grid():
    """Delta: a grid of platform positions (IK, orientation free), reachable near home, not 2 m away."""
    delta = mb.gallery.load("delta")
    p0 = mb.site_pose(delta, delta.q0, "tcp")[:3, 3]
    xy = workspace.grid([(-0.05, 0.05), (-0.05, 0.05)], 3).reshape(-1, 2)
    T = np.tile(np.eye(4), (len(xy) + 1, 1, 1))
    T[:-1, :3, 3] = p0 + np.column_stack([xy, np.zeros(len(xy))])
    T[-1, :3, 3] = p0 + np.array([2.0, 0.0, 0.0])  # beyond the arms' reach
    mp = mb.singularity_map(delta, "tcp", T=T, ik_weights=(0, 0, 0, 1, 1, 1), steps=1)
    assert mp.reachable[:-1].all() and not mp.reachable[-1]
    assert np.all(np.isfinite(mp.dexterity[:-1])) and np.isnan(mp.dexterity[-1])
    assert not mp.singular[:-1].any()
