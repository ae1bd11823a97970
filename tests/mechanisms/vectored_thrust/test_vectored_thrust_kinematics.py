"""Kinematics of the vectored thruster (paper 5, Section 3) against independent references."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomech.mechanisms import vectored_thrust as vt
from robomech.spatial import exp_so3, rot_x, rot_y, transform
from robomech.testing import numerical_jacobian, numerical_space_jacobian

TH = vt.VectoredThruster.paper()
# Round trips are closed-form (atan2, one stable quadratic root): a few ulps of an O(1) angle.
ROUND_TRIP_TOL = 1e-10
# Central differences of O(1) functions with the FD_STEP of robomech.testing: ~1e-10 truncation,
# amplified near the q2 = pi/6 corner where the Jacobian grows (|J| ~ 10): 1e-7 is a safe bound.
FD_TOL = 1e-7
# Second time derivative by central differences of first derivatives (step 1e-5 s): O(h^2) ~ 1e-9
# relative, times |omega_dot| up to ~100 rad/s^2 on the trajectory.
ACC_FD_TOL = 1e-6

q_in_range = st.tuples(
    st.floats(-math.pi / 4, math.pi / 4, allow_nan=False),
    st.floats(-math.pi / 6, math.pi / 6, allow_nan=False),
)


def independent_axis(q1: float, q2: float) -> np.ndarray:
    """Propeller axis straight from eqs. (5), (7), (8), (11) with plain cross products."""
    s12 = np.array([math.sqrt(2) / 2, math.sqrt(2) / 2 * math.sin(q1), -math.sqrt(2) / 2 * math.cos(q1)])
    s22 = np.array([-math.cos(q2), 0.0, math.sin(q2)])
    n = np.cross(s22, s12)
    s13 = n / np.linalg.norm(n)
    s0 = np.cross(s22, s13)
    return s0 / np.linalg.norm(s0)


def test_home_pose_points_along_plus_z() -> None:
    fk = vt.forward_kinematics(TH, [0.0, 0.0])
    np.testing.assert_allclose(fk.axis, [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(fk.tip, [0, 0, 0.080], atol=1e-15)  # Table 1: 80 mm arm
    assert fk.valid and fk.within_limits


@given(q_in_range)
@settings(max_examples=80, deadline=None)
def test_fk_matches_cross_products_of_printed_axes(q: tuple[float, float]) -> None:
    fk = vt.forward_kinematics(TH, q)
    np.testing.assert_allclose(fk.axis, independent_axis(*q), atol=1e-12)
    assert abs(np.linalg.norm(fk.axis) - 1.0) < 1e-14


def test_printed_eq12_is_not_unit_but_corrected_is() -> None:
    # paper 5, eq. (12) as printed: L* = -sin(phi1) M, M* = sin(phi2) L + cos(phi2) N, N* = -cos(phi2) M.
    q1, q2 = 0.6, -0.3
    r = math.sqrt(2) / 2
    s1, c1, s2, c2 = math.sin(q1), math.cos(q1), math.sin(q2), math.cos(q2)
    L, M, N = -r * s1 * s2, r * (s2 - c1 * c2), -r * s1 * c2
    n = math.sqrt(L * L + M * M + N * N)
    L, M, N = L / n, M / n, N / n
    printed = np.array([-s1 * M, s2 * L + c2 * N, -c2 * M])
    corrected = np.array([-s2 * M, s2 * L + c2 * N, -c2 * M])
    assert abs(np.linalg.norm(printed) - 1.0) > 1e-2
    np.testing.assert_allclose(vt.forward_kinematics(TH, [q1, q2]).axis, corrected, atol=1e-14)


def test_printed_eq13_phi1_does_not_invert_but_ours_does() -> None:
    q = np.array([0.5, 0.2])
    L, M, N = vt.forward_kinematics(TH, q).axis
    printed_phi1 = -math.atan(M * N / L**2)  # paper 5, eq. (13)
    printed_phi2 = math.atan(L / N)
    assert abs(printed_phi1 - q[0]) > 0.1
    assert abs(printed_phi2 - q[1]) < 1e-14
    np.testing.assert_allclose(vt.inverse_kinematics(TH, [L, M, N]).q, q, atol=ROUND_TRIP_TOL)


@given(q_in_range)
@settings(max_examples=100, deadline=None)
def test_ik_of_fk_round_trip(q: tuple[float, float]) -> None:
    fk = vt.forward_kinematics(TH, q)
    ik = vt.inverse_kinematics(TH, fk.tip)  # the tip is a positive multiple of the axis
    assert ik.solved and ik.in_range
    np.testing.assert_allclose(ik.q, q, atol=ROUND_TRIP_TOL)
    assert bool(ik.tilt_ok) == bool(fk.tilt_ok)


@given(st.floats(0.0, math.pi / 4 * 0.999, allow_nan=False), st.floats(-math.pi, math.pi, allow_nan=False))
@settings(max_examples=100, deadline=None)
def test_fk_of_ik_round_trip_over_the_tilt_cone(tilt: float, azimuth: float) -> None:
    s = np.array([math.sin(tilt) * math.cos(azimuth), math.sin(tilt) * math.sin(azimuth), math.cos(tilt)])
    ik = vt.inverse_kinematics(TH, s)
    assert ik.solved and ik.tilt_ok
    np.testing.assert_allclose(vt.forward_kinematics(TH, ik.q).axis, s, atol=ROUND_TRIP_TOL)


def test_ik_flags_unreachable_directions_per_sample() -> None:
    s = np.array([[0, 0, 1.0], [0, 0, 0], [0, 0, -1.0], [0.9, 0, 0.1], [0, 0.8, 0.6]])
    ik = vt.inverse_kinematics(TH, s)
    assert ik.valid.tolist() == [True, False, False, False, False]
    assert not ik.solved[1] and np.all(np.isnan(ik.q[1]))  # no direction: NaN covered by the mask
    assert not ik.tilt_ok[2] and not ik.tilt_ok[3]  # beyond the universal joint's pi/4
    assert ik.solved[4] and not ik.tilt_ok[4]  # 53 deg tilt
    assert np.all(np.isfinite(ik.q[ik.solved]))


def test_rotation_closes_both_chains() -> None:
    rng = np.random.default_rng(3)
    q = rng.uniform([-0.8, -0.5], [0.8, 0.5], size=(200, 2))
    R = vt.platform_rotation(TH, q).R
    p = vt.passive_angles(TH, q).values
    a = np.array([1.0, 0.0, -1.0]) / math.sqrt(2)
    b = np.array([0.0, -1.0, 0.0])
    R_rr = rot_y(q[:, 1]) @ exp_so3(np.array([-1.0, 0, 0]) * p[:, 0:1])
    R_rrr = rot_x(q[:, 0]) @ exp_so3(a * p[:, 1:2]) @ exp_so3(b * p[:, 2:3])
    np.testing.assert_allclose(R_rr, R, atol=1e-13)
    np.testing.assert_allclose(R_rrr, R, atol=1e-13)


def test_jacobian_against_central_differences_of_orientation() -> None:
    rng = np.random.default_rng(4)
    q = rng.uniform([-math.pi / 4, -math.pi / 6], [math.pi / 4, math.pi / 6], size=(100, 2))

    def pose(qq: np.ndarray) -> np.ndarray:
        return transform(vt.platform_rotation(TH, qq).R, np.zeros((*qq.shape[:-1], 3)))

    J_fd = numerical_space_jacobian(pose, q)[..., :3, :]
    jr = vt.jacobian(TH, q)
    assert jr.valid.all()
    np.testing.assert_allclose(jr.J, J_fd, atol=FD_TOL)


def test_passive_rates_close_both_chains_and_differentiate_the_angles() -> None:
    rng = np.random.default_rng(5)
    q = rng.uniform([-0.8, -0.5], [0.8, 0.5], size=(100, 2))
    qd = rng.normal(size=(100, 2))
    r = vt.passive_rates(TH, q, qd).values
    ax = vt.joint_axes(TH, q)
    w = vt.angular_velocity(TH, q, qd).omega
    np.testing.assert_allclose(qd[:, :1] * ax.s11 + r[:, 1:2] * ax.s12 + r[:, 2:3] * ax.s13, w, atol=1e-13)
    np.testing.assert_allclose(qd[:, 1:2] * ax.s21 + r[:, 0:1] * ax.s22, w, atol=1e-13)
    dp = numerical_jacobian(lambda qq: vt.passive_angles(TH, qq).values, q)
    np.testing.assert_allclose(np.einsum("...ij,...j->...i", dp, qd), r, atol=FD_TOL)


def _trajectory(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A generic two-frequency input trajectory inside the input ranges."""
    q = np.stack([0.7 * np.sin(1.3 * t), -0.45 * np.sin(0.9 * t + 0.4)], -1)
    qd = np.stack([0.7 * 1.3 * np.cos(1.3 * t), -0.45 * 0.9 * np.cos(0.9 * t + 0.4)], -1)
    qdd = np.stack([-0.7 * 1.69 * np.sin(1.3 * t), 0.45 * 0.81 * np.sin(0.9 * t + 0.4)], -1)
    return q, qd, qdd


def test_angular_acceleration_is_the_time_derivative_of_j_qd() -> None:
    t = np.linspace(0.0, 7.0, 300)
    h = 1e-5
    q, qd, qdd = _trajectory(t)
    acc = vt.angular_acceleration(TH, q, qd, qdd)
    w_plus = vt.angular_velocity(TH, *_trajectory(t + h)[:2]).omega
    w_minus = vt.angular_velocity(TH, *_trajectory(t - h)[:2]).omega
    wd_fd = (w_plus - w_minus) / (2 * h)
    assert acc.valid.all()
    np.testing.assert_allclose(acc.omega_dot, wd_fd, atol=ACC_FD_TOL)
    np.testing.assert_allclose(acc.omega, vt.angular_velocity(TH, q, qd).omega, atol=1e-14)
    # omega_dot = J qdd + (Lie-bracket velocity products); those products are not negligible:
    J = vt.jacobian(TH, q).J
    J_qdd = np.einsum("...ij,...j->...i", J, qdd)
    np.testing.assert_allclose(acc.omega_dot, J_qdd + acc.velocity_product, atol=1e-12)
    assert np.abs(acc.velocity_product).max() > 0.1 * np.abs(acc.omega_dot).max()


def test_singularity_is_flagged_not_raised() -> None:
    q = np.array([[0.0, math.pi / 4], [0.1, 0.1]])  # passive axes s22 and s12 parallel at (0, pi/4)
    ax = vt.joint_axes(TH, q)
    assert ax.distance[0] < 1e-15 and not ax.valid[0] and ax.valid[1]
    fk = vt.forward_kinematics(TH, q)
    assert fk.valid.tolist() == [False, True] and np.all(np.isnan(fk.axis[0]))
    jr = vt.jacobian(TH, q)
    assert jr.valid.tolist() == [False, True] and np.all(np.isnan(jr.J[0]))
    acc = vt.angular_acceleration(TH, q, np.ones((2, 2)), np.ones((2, 2)))
    assert acc.valid.tolist() == [False, True] and np.all(np.isfinite(acc.omega_dot[1]))
    vel = vt.angular_velocity(TH, q, np.ones((2, 2)))
    assert vel.valid.tolist() == [False, True] and np.all(np.isnan(vel.omega[0]))
    pr = vt.passive_rates(TH, q, np.ones((2, 2)))
    assert not pr.valid[0] and np.all(np.isnan(pr.values[0]))


def test_batched_equals_per_sample() -> None:
    rng = np.random.default_rng(6)
    q = rng.uniform([-0.8, -0.5], [0.8, 0.5], size=(4, 5, 2))
    qd, qdd = rng.normal(size=(4, 5, 2)), rng.normal(size=(4, 5, 2))
    fk, ik = vt.forward_kinematics(TH, q), None
    ik = vt.inverse_kinematics(TH, fk.axis)
    J = vt.jacobian(TH, q).J
    acc = vt.angular_acceleration(TH, q, qd, qdd).omega_dot
    for i in range(4):
        for j in range(5):
            one_fk = vt.forward_kinematics(TH, q[i, j]).axis
            np.testing.assert_allclose(one_fk, fk.axis[i, j], rtol=0, atol=1e-12)
            one_ik = vt.inverse_kinematics(TH, fk.axis[i, j]).q
            np.testing.assert_allclose(one_ik, ik.q[i, j], rtol=0, atol=1e-12)
            np.testing.assert_allclose(vt.jacobian(TH, q[i, j]).J, J[i, j], rtol=0, atol=1e-12)
            one = vt.angular_acceleration(TH, q[i, j], qd[i, j], qdd[i, j]).omega_dot
            np.testing.assert_allclose(one, acc[i, j], rtol=0, atol=1e-12)


def test_out_of_range_inputs_are_flagged() -> None:
    fk = vt.forward_kinematics(TH, [[0.0, 0.6], [0.9, 0.0], [0.2, -0.2]])  # q2 > pi/6, q1 > pi/4, fine
    assert fk.in_range.tolist() == [False, False, True]


@pytest.mark.parametrize(
    ("fn", "args", "name"),
    [
        (vt.forward_kinematics, ([0.1, float("inf")],), "q"),  # NaN: a failed sample, masked
        (vt.forward_kinematics, ([0.1, 0.2, 0.3],), "q"),
        (vt.inverse_kinematics, ([0.0, 1.0],), "s"),
        (vt.inverse_kinematics, ([0.0, float("inf"), 1.0],), "s"),
        (vt.jacobian, (np.zeros((3, 1)),), "q"),
        (vt.angular_acceleration, ([0, 0], [0, 0], [0, 1e300]), "qdd"),
        (vt.passive_rates, ([0, 0], [0, 0, 0]), "qd"),
    ],
)
def test_bad_input_names_the_argument(fn, args, name) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ValueError, match=rf"\b{name}\b"):
        fn(TH, *args)


def test_passive_angles_cover_the_full_circle() -> None:
    # Table 1's trajectory reaches q = (-pi/4, pi/4), where the propeller tilts beyond the horizontal
    q = np.array([-math.pi / 4, math.pi / 4])
    p = vt.passive_angles(TH, q).values
    assert p[0] > math.pi / 2
    R = rot_y(q[1]) @ exp_so3(np.array([-1.0, 0, 0]) * p[0])
    np.testing.assert_allclose(R, vt.platform_rotation(TH, q).R, atol=1e-14)


def test_chunked_evaluation_equals_whole_array_kernels() -> None:
    from robomech.mechanisms.vectored_thrust import _kinematics as K

    rng = np.random.default_rng(8)
    n = 2 * K.CHUNK + 123  # several blocks and a ragged tail
    q = rng.uniform([-1.0, -0.7], [1.0, 0.7], size=(n, 2))
    q[5] = [0.0, math.pi / 4]  # a singular sample inside the first block
    fk, fk_ref = vt.forward_kinematics(TH, q.reshape(3, -1, 2) if n % 3 == 0 else q), K._fk(TH, q)
    np.testing.assert_array_equal(fk.axis.reshape(-1, 3), fk_ref.axis)
    np.testing.assert_array_equal(fk.valid.reshape(-1), fk_ref.valid)
    tips = np.where(fk_ref.valid[:, None], fk_ref.tip, [0.0, 0.0, 1.0])
    ik, ik_ref = vt.inverse_kinematics(TH, tips), K._ik(TH, tips)
    np.testing.assert_array_equal(ik.q, ik_ref.q)
    np.testing.assert_array_equal(ik.valid, ik_ref.valid)
    jr, jr_ref = vt.jacobian(TH, q), K._jacobian(TH, q)
    np.testing.assert_array_equal(jr.J, jr_ref.J)
    np.testing.assert_array_equal(jr.valid, jr_ref.valid)
    assert not jr.valid[5] and not fk.valid.reshape(-1)[5]
    m = vt.workspace_map(TH, q.reshape(-1, 1, 2))
    assert m.tip.shape == (n, 1, 3) and m.singular[5, 0]


@given(st.floats(0.3, 1.3), st.floats(-0.6, 0.6), st.floats(-0.25, 0.25))
@settings(max_examples=60, deadline=None)
def test_other_arc_angles_round_trip_and_jacobian(arc: float, q1: float, q2_frac: float) -> None:
    import dataclasses

    th = dataclasses.replace(TH, arc_angle=arc)
    q = np.array([q1, q2_frac * arc * 2])  # |q2| < a/2: away from the singular point (0, a)
    fk = vt.forward_kinematics(th, q)
    assert fk.valid and abs(np.linalg.norm(fk.axis) - 1) < 1e-14
    np.testing.assert_allclose(vt.inverse_kinematics(th, fk.axis).q, q, atol=ROUND_TRIP_TOL)
    pose = lambda qq: transform(vt.platform_rotation(th, qq).R, np.zeros((*qq.shape[:-1], 3)))  # noqa: E731
    np.testing.assert_allclose(vt.jacobian(th, q).J, numerical_space_jacobian(pose, q)[:3], atol=FD_TOL)
