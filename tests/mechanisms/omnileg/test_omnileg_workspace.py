"""Foot workspace, singularity map and paper 2's symmetry claim (issue 15, item 1)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import robomech.mechanisms.omnileg as ol

LEG = ol.OmniLeg.paper()
# Monte Carlo volume with N uniform samples in the bounding box: relative standard error
# sqrt((1 - f) / (f N)) ~ 1.5e-3 at f ≈ 0.46, N = 2.5e5; the test allows 4 standard errors.
MC_SAMPLES = 250_000
MC_REL_TOL = 6e-3
# Shoelace area of the 800-point boundary polygon vs the quadrature: chord error ~ (h/R)²/12 ~ 2e-5.
POLYGON_REL_TOL = 1e-4


def _box_samples(fw, n, seed=0):
    rng = np.random.default_rng(seed)
    lo = np.array([-fw.radius_max, -fw.radius_max, fw.depth_min])
    hi = np.array([fw.radius_max, fw.radius_max, fw.depth_max])
    return lo + (hi - lo) * rng.random((n, 3)), float(np.prod(hi - lo))


def test_volume_by_quadrature_matches_monte_carlo_and_the_boundary_area():
    fw = ol.foot_workspace(LEG)
    p, box = _box_samples(fw, MC_SAMPLES)
    mc = ol.inverse_kinematics(LEG, p).reachable.mean() * box
    assert abs(mc - fw.volume) < MC_REL_TOL * fw.volume
    x, y = fw.boundary[:, 0], fw.boundary[:, 1]
    shoelace = 0.5 * abs(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
    assert abs(shoelace - fw.projected_area) < POLYGON_REL_TOL * fw.projected_area
    # quadrature converged: doubling the nodes changes the area by rounding only
    assert abs(ol.foot_workspace(LEG, nodes=96).projected_area - fw.projected_area) < 1e-13
    # stroke: Table 2's shank range 2 L4 (1 - cos 85°)
    np.testing.assert_allclose(fw.stroke, 2 * LEG.L4 * (1 - np.cos(LEG.gamma_max)), rtol=1e-14)
    np.testing.assert_allclose(fw.depth_max, LEG.L1 + LEG.L5 + 2 * LEG.L4, rtol=1e-14)


def test_every_reachable_sample_lies_inside_the_extents():
    fw = ol.foot_workspace(LEG)
    q = ol.joint_grid(LEG, 9).reshape(-1, 3)
    p = ol.forward_kinematics(LEG, q)
    assert np.all(p[:, 2] >= fw.depth_min - 1e-12) and np.all(p[:, 2] <= fw.depth_max + 1e-12)
    assert np.all(np.linalg.norm(p[:, :2], axis=-1) <= fw.radius_max + 1e-12)


# The joint maps behind paper 2's symmetry claim (measured once, then asserted): the foot mirrored
# in x is the foot at (α, -β, γ), mirrored in y at (-α, β, γ), swapped (x, y) -> (-y, -x) at (β, α, γ).
# With the box |α|, |β| <= 65° they make workspace_symmetry hold by construction (an identity of the
# box), so the claim is tested on the kinematics instead: the forward and inverse kinematics must
# carry these maps (a sign or axis error in either breaks them), and the reachable set must follow
# the box on both sides of its boundary.
_IMAGES = (
    (lambda p: p * [-1.0, 1.0, 1.0], lambda q: q * [1.0, -1.0, 1.0]),
    (lambda p: p * [1.0, -1.0, 1.0], lambda q: q * [-1.0, 1.0, 1.0]),
    (lambda p: np.stack([-p[..., 1], -p[..., 0], p[..., 2]], -1), lambda q: q[..., [1, 0, 2]]),
)
# FK of mirrored joint angles vs the mirrored FK: the same floating-point operations up to signs and
# one rounding of a sum's order.
EQUIVARIANCE_TOL = 1e-15
# IK of a mirrored foot vs the mirrored joint angles: the closed form's rounding, amplified near the
# joint-limit corners (measured 9.5e-15 over 2000 samples of the box).
IK_IMAGE_TOL = 1e-12


def _equivariance_error(fk, q):
    p = fk(q)
    return max(float(np.abs(fk(jmap(q)) - pmap(p)).max()) for pmap, jmap in _IMAGES)


def _inside(n, seed):
    rng = np.random.default_rng(seed)
    return rng.uniform([-1, -1, 0.05], [1, 1, 1], (n, 3)) * [LEG.alpha_max, LEG.beta_max, LEG.gamma_max]


def test_the_kinematics_carry_the_symmetry_maps():
    q = _inside(2000, seed=1)
    assert _equivariance_error(lambda x: ol.forward_kinematics(LEG, x), q) <= EQUIVARIANCE_TOL
    p = ol.forward_kinematics(LEG, q)
    for pmap, jmap in _IMAGES:
        ik = ol.inverse_kinematics(LEG, pmap(p))
        assert ik.reachable.all()
        np.testing.assert_allclose(ik.q, jmap(q), atol=IK_IMAGE_TOL)


def test_the_equivariance_check_catches_a_sign_error():
    # control: a forward kinematics with one sign wrong (β entering as -β in the y coordinate only)
    def wrong(q):
        p = ol.forward_kinematics(LEG, q)
        return p + np.stack([0 * p[..., 0], 0.01 * np.sin(q[..., 1]) * np.cos(q[..., 0]), 0 * p[..., 2]], -1)

    assert _equivariance_error(wrong, _inside(200, seed=2)) > 1e-3


def test_reachability_follows_the_box_on_both_sides_of_its_boundary():
    # feet just inside and just outside |α| = α_max (and |β| = β_max): reachable exactly inside, for
    # the sample and for each image -- the classification of the inverse kinematics, not of the box
    eps = 1e-6
    rng = np.random.default_rng(3)
    n = 200
    other = rng.uniform(-0.9, 0.9, n) * LEG.beta_max
    gamma = rng.uniform(0.1, 1.0, n) * LEG.gamma_max
    sign = rng.choice([-1.0, 1.0], n)
    for k in (0, 1):  # the α limit, then the β limit
        lim = (LEG.alpha_max, LEG.beta_max)[k]
        for scale, expected in ((1 - eps, True), (1 + eps, False)):
            q = np.zeros((n, 3))
            q[:, k], q[:, 1 - k], q[:, 2] = sign * lim * scale, other, gamma
            p = ol.forward_kinematics(LEG, q)
            assert np.all(ol.inverse_kinematics(LEG, p).reachable == expected)
            for pmap, _ in _IMAGES:
                assert np.all(ol.inverse_kinematics(LEG, pmap(p)).reachable == expected)


def test_paper_symmetry_claim_holds_for_table_2():
    fw = ol.foot_workspace(LEG)
    p, _ = _box_samples(fw, 100_000, seed=1)
    s = ol.workspace_symmetry(LEG, p)
    assert 0.3 < s.reachable.mean() < 0.7  # the samples probe the boundary, not only the inside
    assert s.holds.all()
    # and the boundary of the projected workspace (foot_workspace's quadrature) maps onto itself
    b = fw.boundary
    for img in (b * [-1, 1], b * [1, -1], np.stack([-b[:, 1], -b[:, 0]], -1)):
        d = np.min(np.linalg.norm(img[:, None] - b[None], axis=-1), axis=1)
        assert d.max() < 1e-12


def test_symmetry_test_fails_where_the_claim_fails():
    # unequal ranges: the mirrors still hold, the α <-> β swap does not (the test has teeth)
    leg = dataclasses.replace(LEG, beta_max=0.6)
    fw = ol.foot_workspace(leg)
    p, _ = _box_samples(fw, 50_000, seed=2)
    s = ol.workspace_symmetry(leg, p)
    assert s.mirror_x.all() and s.mirror_y.all()
    assert not s.swap.all() and not s.holds.all()


def test_singularity_map_gamma_zero_surface():
    q = ol.joint_grid(LEG, (7, 7, 12))
    wm = ol.workspace_map(LEG, q)
    assert wm.within_limits.all()
    sing = wm.singular
    assert np.array_equal(sing, np.broadcast_to(q[..., 2] == 0.0, sing.shape))
    assert np.all(wm.det[..., 0] == 0.0) and np.all(np.abs(wm.det[..., 1:]) > 0)
    np.testing.assert_allclose(wm.det, np.linalg.det(ol.jacobian(LEG, q)), atol=1e-18)
    # the γ = 0 surface is the bottom of the workspace: FK at γ = 0
    np.testing.assert_allclose(
        ol.singular_surface(LEG, q[..., 0, 0], q[..., 0, 1]), wm.foot[..., 0, :], atol=1e-15
    )
    assert np.all(wm.cond[..., 0] == np.inf) and np.all(np.isfinite(wm.cond[..., 1:]))
    np.testing.assert_allclose(wm.dexterity[..., 1:], 1 / wm.cond[..., 1:], rtol=1e-12)


def test_bad_input():
    with pytest.raises(ValueError, match="leg"):
        ol.workspace_map(None, [0, 0, 0])  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="q"):
        ol.workspace_map(LEG, [0, 0])
    with pytest.raises(ValueError, match="n"):
        ol.joint_grid(LEG, 1)
    with pytest.raises(ValueError, match="nodes"):
        ol.foot_workspace(LEG, nodes=1)
    with pytest.raises(ValueError, match="p_foot"):
        ol.workspace_symmetry(LEG, np.zeros((4, 2)))
    s = ol.workspace_symmetry(LEG, [[np.nan, 0, 0.4], [0, 0, 0.4]])
    assert s.reachable.tolist() == [False, True] and s.holds.all()
