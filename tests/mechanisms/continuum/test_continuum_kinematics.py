"""Kinematics of the continuum robot: segment transform, FK, cable lengths, Jacobians, IK."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomech.mechanisms import continuum as C
from robomech.mechanisms.continuum._kinematics import (
    IK_MAX_ITERATIONS,
    IK_STARTS,
    _tip_jacobian_u,
    _tip_u,
)
from robomech.spatial import rot_y, rot_z
from robomech.testing import numerical_jacobian, numerical_space_jacobian

PAPER = C.ContinuumRobot.paper()
TWO = C.ContinuumRobot(n_segments=2, friction=(0.26, 0.31, 0.28) * 2)
THREE = C.ContinuumRobot(n_segments=3, friction=(0.26, 0.31, 0.28) * 3)
# Bend range of the multi-segment IK property tests: up to pi per segment, beyond the 2 rad of the
# package's random poses and benchmarks (10^5 random 2- and 3-segment targets in this range all reached).
THETA_MAX_IK = np.pi
# Central differences of O(0.1 m) functions with step 6e-6: truncation + rounding ~1e-10.
FD_TOL = 1e-9
# Double-precision agreement of two closed forms of the same O(1) quantity.
EXACT_TOL = 1e-14


def random_psi(rng, robot, batch=(7,), theta_max=2.0):
    th = rng.uniform(0.0, theta_max, (*batch, robot.n_segments))
    be = rng.uniform(-np.pi, np.pi, (*batch, robot.n_segments))
    return np.stack([th, be], -1).reshape(*batch, 2 * robot.n_segments)


def test_segment_rotation_is_rz_ry_rz():
    rng = np.random.default_rng(0)
    th, be = rng.uniform(-3, 3, 50), rng.uniform(-3, 3, 50)
    T = C.segment_transform(th, be, 0.09)
    R = rot_z(be) @ rot_y(th) @ rot_z(-be)
    assert np.abs(T[..., :3, :3] - R).max() < EXACT_TOL


def test_paper_eq1_except_misprinted_element_and_eq2():
    th, be = 0.7, 0.4
    ct, st_, cb, sb = np.cos(th), np.sin(th), np.cos(be), np.sin(be)
    printed = np.array(
        [  # paper 3, eq. (1) as printed
            [ct * cb**2 + sb**2, cb * sb * (ct - 1), cb * st_],
            [cb * sb * ct, sb**2 * ct + cb**2, sb * st_],
            [-cb * st_, -sb * st_, ct],
        ]
    )
    T = C.segment_transform(th, be, 0.09)
    mask = np.ones((3, 3), bool)
    mask[1, 0] = False
    assert np.abs(T[:3, :3][mask] - printed[mask]).max() < EXACT_TOL
    assert abs(T[1, 0] - printed[1, 0]) > 0.1  # the misprint is real: cb sb ct != cb sb (ct - 1)
    p = 0.09 / th * np.array([cb * (1 - ct), sb * (1 - ct), st_])  # paper 3, eq. (2)
    assert np.abs(T[:3, 3] - p).max() < EXACT_TOL


def test_segment_transform_finite_and_continuous_at_straight():
    T0 = C.segment_transform(0.0, 1.3, 0.09)
    assert np.allclose(T0, np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0.09], [0, 0, 0, 1.0]]), atol=0)
    for t in (1e-5, 1e-4 * (1 - 1e-12), 1e-4 * (1 + 1e-12), 1e-3):
        # the series branch and the closed form agree across SMALL_ANGLE
        Ts = C.segment_transform(t, 1.3, 0.09)
        ref = 0.09 / t * np.array([np.cos(1.3) * (1 - np.cos(t)), np.sin(1.3) * (1 - np.cos(t)), np.sin(t)])
        assert np.abs(Ts[:3, 3] - ref).max() < 1e-12


def test_fk_is_product_of_segment_transforms():
    rng = np.random.default_rng(1)
    psi = random_psi(rng, TWO)
    T = C.forward_kinematics(TWO, psi)
    T1 = C.segment_transform(psi[:, 0], psi[:, 1], 0.09)
    T2 = C.segment_transform(psi[:, 2], psi[:, 3], 0.09)
    assert np.abs(T[:, 1] - T1 @ T2).max() < EXACT_TOL


def test_cable_lengths_arc_is_eq4_and_jacobian_is_eq5():
    th, be, r, l = 1.1, 0.3, PAPER.hole_radius, PAPER.segment_length
    L = C.cable_lengths(PAPER, [th, be], "arc")
    ref = l - r * th * np.cos(np.array([be, be - 2 * np.pi / 3, be + 2 * np.pi / 3]))  # eq. (4)
    assert np.abs(L - ref).max() < EXACT_TOL
    J = C.cable_jacobian(PAPER, [th, be], "arc")
    ang = np.array([be, be - 2 * np.pi / 3, be + 2 * np.pi / 3])
    assert np.abs(J - np.stack([-r * np.cos(ang), r * th * np.sin(ang)], -1)).max() < EXACT_TOL  # eq. (5)


def test_chord_lengths_match_hole_geometry_and_tend_to_arc():
    rng = np.random.default_rng(2)
    for robot in (PAPER, TWO):
        psi = random_psi(rng, robot)
        T = C.disk_transforms(robot, psi)
        sig = robot.hole_angles
        holes = np.stack([robot.hole_radius * np.cos(sig), robot.hole_radius * np.sin(sig), 0 * sig], -1)
        pts = np.einsum("...kab,cb->...cka", T[..., :3, :3], holes) + T[..., None, :, :3, 3]
        chords = np.linalg.norm(np.diff(pts, axis=-2), axis=-1)
        spans = C.span_lengths(robot, psi, "chord")
        active = spans > 0
        assert np.abs(np.where(active, chords - spans, 0)).max() < 1e-15
    fine = C.ContinuumRobot(disks_per_segment=2000)
    psi = [1.2, 0.4]
    assert np.abs(C.cable_lengths(fine, psi, "chord") - C.cable_lengths(fine, psi, "arc")).max() < 1e-8


@pytest.mark.parametrize("model", ["arc", "chord"])
@pytest.mark.parametrize("robot", [PAPER, TWO], ids=["one", "two"])
def test_cable_jacobian_vs_central_differences(model, robot):
    psi = random_psi(np.random.default_rng(3), robot)
    J = C.cable_jacobian(robot, psi, model)
    Jn = numerical_jacobian(lambda p: C.cable_lengths(robot, p, model), psi)
    assert np.abs(J - Jn).max() < FD_TOL


@pytest.mark.parametrize("robot", [PAPER, TWO], ids=["one", "two"])
def test_tip_jacobian_vs_central_differences(robot):
    psi = random_psi(np.random.default_rng(4), robot)
    J = C.tip_jacobian(robot, psi)
    Jv = numerical_jacobian(lambda p: C.tip_position(robot, p), psi)
    Js = numerical_space_jacobian(lambda p: C.forward_kinematics(robot, p)[..., -1, :, :], psi)
    assert np.abs(J[..., 3:, :] - Jv).max() < FD_TOL
    assert np.abs(J[..., :3, :] - Js[..., :3, :]).max() < FD_TOL


def test_tip_jacobian_equals_paper_eq6():
    th, be, l = 0.9, -0.6, PAPER.segment_length
    ct, st_, cb, sb = np.cos(th), np.sin(th), np.cos(be), np.sin(be)
    Jv = np.array(
        [
            [l * cb * (th * st_ + ct - 1) / th**2, l * (ct - 1) / th * sb],
            [l * sb * (th * st_ + ct - 1) / th**2, -l * (ct - 1) / th * cb],
            [l * (th * ct - st_) / th**2, 0.0],
        ]
    )
    Jw = np.array([[-sb, -cb * st_], [cb, -sb * st_], [0.0, 1 - ct]])
    J = C.tip_jacobian(PAPER, [th, be])
    assert np.abs(J[:3] - Jw).max() < EXACT_TOL
    assert np.abs(J[3:] - Jv).max() < EXACT_TOL


def test_jacobians_finite_at_straight_pose():
    for robot in (PAPER, TWO):
        z = np.zeros(2 * robot.n_segments)
        assert np.all(np.isfinite(C.tip_jacobian(robot, z)))
        Jn = numerical_jacobian(lambda p, r=robot: C.tip_position(r, p), z)
        assert np.abs(C.tip_jacobian(robot, z)[3:] - Jn).max() < FD_TOL


@settings(max_examples=60, deadline=None)
@given(theta=st.floats(0.0, 3.0), beta=st.floats(-np.pi, np.pi))
def test_ik_fk_round_trip_one_segment(theta, beta):
    psi = np.array([theta, beta])
    p = C.tip_position(PAPER, psi)
    ik = C.inverse_kinematics(PAPER, p)
    assert ik.reachable and ik.residual < C.IK_TOLERANCE
    assert np.abs(C.tip_position(PAPER, ik.psi) - p).max() < C.IK_TOLERANCE
    if theta > 1e-6:  # beta is undefined at the straight pose
        assert abs(ik.psi[0] - theta) < 1e-9
        assert abs(np.angle(np.exp(1j * (ik.psi[1] - beta)))) < 1e-9


def _assert_ik_round_trip(robot, psi):
    p = C.tip_position(robot, psi)
    ik = C.inverse_kinematics(robot, p)
    assert ik.reachable and ik.converged, (ik.residual, ik.iterations)
    assert ik.residual < C.IK_TOLERANCE
    assert np.abs(C.tip_position(robot, ik.psi) - p).max() < C.IK_TOLERANCE
    th, be = ik.psi[0::2], ik.psi[1::2]
    assert np.all(th >= 0.0) and np.all(np.abs(be) <= np.pi) and np.all(be[th == 0.0] == 0.0)
    return ik


@settings(max_examples=60, deadline=None)
@given(
    th=st.lists(st.floats(0.0, THETA_MAX_IK), min_size=2, max_size=2),
    be=st.lists(st.floats(-np.pi, np.pi), min_size=2, max_size=2),
)
def test_ik_round_trip_two_segments(th, be):
    _assert_ik_round_trip(TWO, np.array([th[0], be[0], th[1], be[1]]))


@settings(max_examples=60, deadline=None)
@given(
    th=st.lists(st.floats(0.0, THETA_MAX_IK), min_size=3, max_size=3),
    be=st.lists(st.floats(-np.pi, np.pi), min_size=3, max_size=3),
)
def test_ik_round_trip_three_segments(th, be):
    _assert_ik_round_trip(THREE, np.stack([th, be], -1).ravel())


def test_ik_regression_segments_bent_against_each_other():
    """Found by hypothesis: the old undamped Gauss-Newton in (theta, beta) from the single arc stalled
    at a 0.17 m residual on this pose (distal segment bent back against the proximal one)."""
    ik = _assert_ik_round_trip(TWO, np.array([0.25, 0.0, 1.0, 3.0]))
    assert ik.iterations <= IK_MAX_ITERATIONS * (1 + len(IK_STARTS))


@pytest.mark.parametrize(
    ("robot", "psi"),
    [
        (TWO, [0.0, 0.0, 1.2, 0.7]),  # straight proximal segment
        (TWO, [1.2, -2.0, 0.0, 0.0]),  # straight distal segment
        (TWO, [0.0, 1.3, 0.0, -0.4]),  # straight robot (beta arbitrary in the target pose)
        (THREE, [0.9, 0.3, 0.0, 0.0, 1.4, 2.5]),  # straight middle segment
        (THREE, [0.0, 0.0, 0.0, 0.0, 2.0, -3.0]),
    ],
)
def test_ik_round_trip_through_straight_segments(robot, psi):
    ik = _assert_ik_round_trip(robot, np.array(psi))
    if not np.any(psi[0::2]):  # straight target: the solution is the straight robot with beta = 0
        assert np.all(ik.psi == 0.0)


@pytest.mark.parametrize("robot", [TWO, THREE], ids=["two", "three"])
def test_ik_jacobian_in_bending_vectors_vs_central_differences(robot):
    """d p_tip / d u is continuous through u = 0 (theta = 0, beta undefined); it is evaluated at the
    IK_THETA_FLOOR there, which must not spoil it."""
    n = robot.n_segments
    rng = np.random.default_rng(6)
    u = rng.uniform(-2.0, 2.0, (8, n, 2))
    u[0] = 0.0  # all segments straight
    u[1, 0] = 0.0  # one straight segment
    u[2, -1] = [1e-9, -2e-9]  # below the floor
    u[3, 0] = [3e-5, 0.0]  # below SMALL_ANGLE (series branch)
    J = _tip_jacobian_u(robot, u)
    Jn = numerical_jacobian(lambda x: _tip_u(robot, x.reshape(*x.shape[:-1], n, 2)), u.reshape(8, 2 * n))
    assert J.shape == (8, 3, 2 * n)
    assert np.abs(J - Jn).max() < FD_TOL


def test_ik_flags_unreachable_per_sample():
    p = np.array([[0.0, 0.0, 0.09], [0.0, 0.0, 0.05], [0.0, 0.0, 0.2], [0.03, 0.0, 0.08]])
    p[3] = C.tip_position(PAPER, [0.8, 0.0])
    ik = C.inverse_kinematics(PAPER, p)
    assert ik.reachable.tolist() == [True, False, False, True]
    assert np.all(np.isfinite(ik.psi))


@pytest.mark.parametrize("robot", [TWO, THREE], ids=["two", "three"])
def test_ik_flags_unreachable_per_sample_multi_segment(robot):
    n, L = robot.n_segments, robot.segment_length
    rng = np.random.default_rng(7)
    dirs = rng.normal(size=(6, 3))
    dirs /= np.linalg.norm(dirs, axis=-1, keepdims=True)
    far = dirs * n * L * np.array([1.01, 1.2, 1.5, 2.0, 3.0, 10.0])[:, None]  # beyond the reach n l
    near = C.tip_position(robot, random_psi(rng, robot, batch=(4,)))
    p = np.concatenate([near[:2], far, near[2:]])
    ik = C.inverse_kinematics(robot, p)
    assert ik.reachable.tolist() == [True] * 2 + [False] * 6 + [True] * 2
    assert np.all(np.isfinite(ik.psi)) and np.all(np.isfinite(ik.residual))
    # the tip is never farther than n l from the base: a lower bound of the residual
    assert np.all(ik.residual[2:8] >= np.linalg.norm(far, axis=-1) - n * L)
    # the reported residual is that of the returned pose
    assert np.abs(np.linalg.norm(C.tip_position(robot, ik.psi) - p, axis=-1) - ik.residual).max() < 1e-15
    # beyond the reach, no restart: one solve only (the cost of an unreachable target is bounded)
    assert np.all(ik.iterations[2:8] <= IK_MAX_ITERATIONS)
    assert np.all(ik.converged[[0, 1, 8, 9]])


# Poses whose tips the single-arc start does not reach (found by a search over random poses): they
# exercise the alternative starts.
NEEDS_RESTART = {2: [3.11, -0.59, 3.02, -1.03], 3: [1.3, 0.36, 2.31, 3.09, 2.23, -2.29]}


@pytest.mark.parametrize("robot", [TWO, THREE], ids=["two", "three"])
def test_ik_batched_equals_per_sample_with_restarts_and_failures(robot):
    """A batch mixing easy targets, targets that need the alternative starts, straight ones and
    unreachable ones gives per sample exactly what the sample gives alone."""
    rng = np.random.default_rng(8)
    psi = random_psi(rng, robot, batch=(12,), theta_max=THETA_MAX_IK)
    psi[0, 0::2] = 0.0
    psi[5] = NEEDS_RESTART[robot.n_segments]
    p = C.tip_position(robot, psi)
    p = np.concatenate([p, [[0.0, 0.0, 0.0], [0.3, -0.2, 0.1]]])  # base point, beyond the reach
    ik = C.inverse_kinematics(robot, p.reshape(2, 7, 3))
    assert ik.psi.shape == (2, 7, 2 * robot.n_segments) and ik.reachable.shape == (2, 7)
    single = [C.inverse_kinematics(robot, q) for q in p]
    for name in ("psi", "residual"):
        ref = np.stack([getattr(s, name) for s in single]).reshape(getattr(ik, name).shape)
        assert np.abs(getattr(ik, name) - ref).max() < 1e-12
    for name in ("reachable", "converged", "iterations"):
        ref = np.stack([getattr(s, name) for s in single]).reshape(2, 7)
        assert np.array_equal(getattr(ik, name), ref)
    assert ik.reachable.ravel()[:12].all() and not ik.reachable.ravel()[13]
    assert ik.iterations.ravel()[5] > IK_MAX_ITERATIONS  # the alternative starts were used


def test_batched_equals_per_sample():
    rng = np.random.default_rng(5)
    psi = random_psi(rng, TWO, batch=(6,))
    funcs = [
        lambda p: C.forward_kinematics(TWO, p),
        lambda p: C.tip_jacobian(TWO, p),
        lambda p: C.cable_lengths(TWO, p, "chord"),
        lambda p: C.cable_jacobian(TWO, p, "chord"),
        lambda p: C.inverse_kinematics(TWO, C.tip_position(TWO, p)).psi,
    ]
    for f in funcs:
        batched = f(psi)
        single = np.stack([f(q) for q in psi])
        assert np.abs(batched - single).max() < 1e-12
    grid = psi.reshape(2, 3, 4)
    assert C.tip_jacobian(TWO, grid).shape == (2, 3, 6, 4)


def test_bad_input():
    with pytest.raises(ValueError, match="psi"):
        C.tip_position(PAPER, [0.1, 0.2, 0.3])
    with pytest.raises(ValueError, match="psi"):
        C.forward_kinematics(PAPER, [np.inf, 0.0])
    with pytest.raises(ValueError, match="theta"):
        C.segment_transform(np.inf, 0.0, 0.09)
    with pytest.raises(ValueError, match="length"):
        C.segment_transform(0.1, 0.0, -0.09)
    with pytest.raises(ValueError, match="p_tip"):
        C.inverse_kinematics(PAPER, [0.0, 0.09])
    with pytest.raises(ValueError, match="model"):
        C.cable_lengths(PAPER, [0.1, 0.0], "spline")


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"segment_length": -0.09}, "segment_length"),
        ({"n_segments": 0}, "n_segments"),
        ({"friction": (0.2, 0.3)}, "friction"),
        ({"hole_radius": 0.2}, "hole_radius"),
        ({"pretension": np.nan}, "pretension"),
        ({"disks_per_segment": 0}, "disks_per_segment"),
        ({"friction": (0.2, -0.1, 0.3)}, "friction"),
    ],
)
def test_impossible_parameters(kwargs, field):
    with pytest.raises(ValueError, match=field):
        C.ContinuumRobot(**kwargs)


def test_paper_values():
    r = C.ContinuumRobot.paper()
    assert r.segment_length == 0.090 and r.disks_per_segment == 5 and r.cable_diameter == 0.8e-3
    assert r.cable_modulus == 4.96e9 and r.friction == (0.26, 0.31, 0.28)
