"""Foot kinematics of the OmniLeg (paper 2): eq. (11), corrected eq. (13), Jacobian, Hessian."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import robomech.mechanisms.omnileg as ol
from robomech.testing import numerical_hessian, numerical_jacobian

LEG = ol.OmniLeg.paper()
# Round trips are exact up to rounding: a few ulps of O(1) angles / O(0.1 m) positions.
ROUND_TRIP_RAD = 1e-10
ROUND_TRIP_M = 1e-12
# Central differences (step 6e-6) of O(0.1) functions: truncation ~h² f''' ~ 1e-11, rounding ~eps/h ~ 1e-11.
FD_TOL = 1e-8
# IK∘FK in γ is ill-conditioned near γ = 0 (∂p/∂γ = -2 L4 sin γ): the property test starts at this γ,
# where the rounding of P_z (~1e-16 m) maps to a γ error ~1e-16 / (2 L4 sin γ) < 1e-13 rad.
GAMMA_WELL_CONDITIONED = 0.01

angles = st.tuples(
    st.floats(-LEG.alpha_max, LEG.alpha_max),
    st.floats(-LEG.beta_max, LEG.beta_max),
    st.floats(LEG.gamma_min, LEG.gamma_max),
)


def _rand_q(n: int, seed: int = 0, gamma_min: float = 0.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.stack(
        [
            rng.uniform(-1, 1, n) * LEG.alpha_max,
            rng.uniform(-1, 1, n) * LEG.beta_max,
            rng.uniform(gamma_min, LEG.gamma_max, n),
        ],
        axis=-1,
    )


def test_home_pose_and_table2_shank_lengths():
    # Fully extended, vertical leg: depth L1 + 2 L4 + L5 (eq. (11) at q = 0).
    p = ol.forward_kinematics(LEG, [0.0, 0.0, 0.0])
    np.testing.assert_allclose(p, [0.0, 0.0, 0.15 + 0.19 + 0.16], atol=1e-15)
    # Table 2 prints the shank length range L2 = 0.017 ~ 0.19 m: 2 L4 cos γ over γ in [0°, 85°]
    # (at α = β = 0 the thigh contributes L1 to the depth, the knee height L5)
    shank = lambda g: ol.forward_kinematics(LEG, [0.0, 0.0, g])[2] - LEG.L1 - LEG.L5  # noqa: E731
    assert round(shank(0.0), 3) == 0.19
    assert round(shank(LEG.gamma_max), 3) == 0.017


def test_eq11_equals_thigh_direction_form():
    q = _rand_q(500)
    p = ol.forward_kinematics(LEG, q)
    u = ol.thigh_direction(q[:, 0], q[:, 1])
    np.testing.assert_allclose(np.linalg.norm(u, axis=-1), 1.0, atol=1e-15)
    knee = LEG.L1 * u
    np.testing.assert_allclose(p[:, :2], knee[:, :2], atol=1e-15)
    np.testing.assert_allclose(p[:, 2], knee[:, 2] + LEG.L5 + 2 * LEG.L4 * np.cos(q[:, 2]), atol=1e-15)


@settings(max_examples=80, deadline=None)
@given(angles)
def test_ik_of_fk_round_trip(q):
    q = np.array(q)
    q[2] = max(q[2], GAMMA_WELL_CONDITIONED)
    r = ol.inverse_kinematics(LEG, ol.forward_kinematics(LEG, q))
    assert r.reachable and r.exists and r.within_limits
    np.testing.assert_allclose(r.q, q, atol=ROUND_TRIP_RAD)


@settings(max_examples=80, deadline=None)
@given(angles)
def test_fk_of_ik_round_trip(q):
    # positions from anywhere in the joint ranges, including the singular γ = 0
    p = ol.forward_kinematics(LEG, np.array(q))
    r = ol.inverse_kinematics(LEG, p)
    assert r.exists
    np.testing.assert_allclose(ol.forward_kinematics(LEG, r.q), p, atol=ROUND_TRIP_M)
    assert r.residual <= ROUND_TRIP_M


def test_ik_gamma_zero_is_exactly_reached():
    r = ol.inverse_kinematics(LEG, ol.forward_kinematics(LEG, [0.3, -0.2, 0.0]))
    assert r.reachable
    np.testing.assert_allclose(r.q[:2], [0.3, -0.2], atol=ROUND_TRIP_RAD)
    assert abs(r.q[2]) < 1e-7  # sqrt(rounding of cos γ) at the flat extremum


def test_ik_sign_of_alpha_follows_eq11():
    # paper 2, eq. (13) prints α = arctan(P_y / s); by eq. (11) P_y = -L1 cos β tan α / ... < 0 for α > 0.
    p = ol.forward_kinematics(LEG, [0.4, 0.0, 0.5])
    assert p[1] < 0
    r = ol.inverse_kinematics(LEG, p)
    assert r.q[0] > 0
    s = np.sqrt(LEG.L1**2 - p[0] ** 2 - p[1] ** 2)
    printed_alpha = np.arctan(p[1] / s)
    assert abs(printed_alpha + r.q[0]) < 1e-12  # the print has the opposite sign
    printed_gamma_arg = p[2] - LEG.L5 - s / (2 * LEG.L4)  # eq. (13)'s misplaced bracket
    assert abs(printed_gamma_arg - np.cos(0.5)) > 0.1  # not cos γ: the print is not an inverse


def test_ik_flags_unreachable_and_out_of_range_per_sample():
    good = ol.forward_kinematics(LEG, [0.1, 0.2, 0.3])
    pts = np.array(
        [
            good,
            [0.2, 0.0, 0.3],  # farther than L1 from Z0: no thigh pose
            [0.0, 0.0, 0.6],  # deeper than the fully extended leg
            [0.0, 0.0, 0.2],  # shallower than the folded shank can reach (cos γ <= 0)
            [np.nan, 0.0, 0.4],  # not finite: flagged, not raised
            ol.forward_kinematics(LEG, [np.radians(70.0), 0.0, 0.3]),  # exists, α beyond 65°
            ol.forward_kinematics(LEG, [0.0, 0.0, np.radians(88.0)]),  # exists, γ beyond 85°
        ]
    )
    r = ol.inverse_kinematics(LEG, pts)
    assert r.exists.tolist() == [True, False, False, False, False, True, True]
    assert r.reachable.tolist() == [True, False, False, False, False, False, False]
    assert np.all(np.isnan(r.q[~r.exists]))
    assert np.all(np.isfinite(r.q[r.exists]))
    np.testing.assert_allclose(r.q[5, 0], np.radians(70.0), atol=ROUND_TRIP_RAD)


def test_within_limits_reads_table2_as_magnitudes():
    d = np.radians
    q = np.array(
        [
            [d(-65), d(65), d(0)],
            [d(-65.1), 0, d(10)],
            [0, d(65.1), d(10)],
            [0, 0, d(-1)],
            [0, 0, d(85)],
            [0, 0, d(85.1)],
        ]
    )
    assert ol.within_limits(LEG, q).tolist() == [True, False, False, False, True, False]


def test_jacobian_and_hessian_match_central_differences():
    q = _rand_q(300, seed=1)
    J = ol.jacobian(LEG, q)
    J_fd = numerical_jacobian(lambda x: ol.forward_kinematics(LEG, x), q)
    np.testing.assert_allclose(J, J_fd, atol=FD_TOL)
    H = ol.hessian(LEG, q)
    H_fd = numerical_hessian(lambda x: ol.jacobian(LEG, x), q)
    np.testing.assert_allclose(H, H_fd, atol=FD_TOL)
    np.testing.assert_allclose(H, np.swapaxes(H, -1, -2), atol=1e-15)  # symmetric in (j, k)


def test_jacobian_singular_at_gamma_zero():
    # errata: the foot Jacobian is singular at γ = 0, including the start of eq. (52)
    J = ol.jacobian(LEG, [[0.0, 0.0, 0.0], [0.3, -0.4, 0.0], [0.3, -0.4, 0.2]])
    sv = np.linalg.svd(J, compute_uv=False)
    assert sv[0, -1] == 0.0 and sv[1, -1] == 0.0
    assert sv[2, -1] > 1e-3


def test_foot_acceleration_along_eq52_matches_second_derivative():
    t = np.linspace(0.0, 6.0, 6001)
    dt = t[1] - t[0]
    prof = ol.joint_trajectory_eq52(t)
    p = ol.forward_kinematics(LEG, prof.q)
    v = ol.foot_velocity(LEG, prof.q, prof.qd)
    a = ol.foot_acceleration(LEG, prof.q, prof.qd, prof.qdd)
    v_fd = (p[2:] - p[:-2]) / (2 * dt)
    a_fd = (p[2:] - 2 * p[1:-1] + p[:-2]) / dt**2
    # central differences in time: error ~dt² p'''/6 ~ 1e-7 m/s, dt² p''''/12 + 4 eps p / dt² ~ 1e-6 m/s²
    np.testing.assert_allclose(v[1:-1], v_fd, atol=1e-6)
    np.testing.assert_allclose(a[1:-1], a_fd, atol=1e-5)


def test_batched_equals_per_sample():
    q = _rand_q(40, seed=2)
    qd = np.random.default_rng(3).normal(size=q.shape)
    p = ol.forward_kinematics(LEG, q)
    r = ol.inverse_kinematics(LEG, p)
    J, H = ol.jacobian(LEG, q), ol.hessian(LEG, q)
    a = ol.foot_acceleration(LEG, q, qd, qd)
    for i in range(q.shape[0]):
        np.testing.assert_allclose(ol.forward_kinematics(LEG, q[i]), p[i], rtol=0, atol=1e-12)
        np.testing.assert_allclose(ol.inverse_kinematics(LEG, p[i]).q, r.q[i], rtol=0, atol=1e-12)
        np.testing.assert_allclose(ol.jacobian(LEG, q[i]), J[i], rtol=0, atol=1e-12)
        np.testing.assert_allclose(ol.hessian(LEG, q[i]), H[i], rtol=0, atol=1e-12)
        np.testing.assert_allclose(ol.foot_acceleration(LEG, q[i], qd[i], qd[i]), a[i], rtol=0, atol=1e-12)
    # leading batch dimensions broadcast
    assert ol.jacobian(LEG, q.reshape(4, 10, 3)).shape == (4, 10, 3, 3)
    assert ol.hessian(LEG, q.reshape(4, 10, 3)).shape == (4, 10, 3, 3, 3)


@pytest.mark.parametrize("fn", [ol.forward_kinematics, ol.jacobian, ol.hessian])
def test_bad_joint_input_names_q(fn):
    with pytest.raises(ValueError, match="q"):
        fn(LEG, np.zeros((5, 2)))
    with pytest.raises(ValueError, match="q"):
        fn(LEG, [np.inf, 0.0, 0.0])
    assert np.isnan(fn(LEG, [np.nan, 0.0, 0.0])).all()  # a failed sample: NaN out


def test_bad_foot_input_names_p_foot():
    with pytest.raises(ValueError, match="p_foot"):
        ol.inverse_kinematics(LEG, np.zeros((3, 4)))
    with pytest.raises(ValueError, match="qd"):
        ol.foot_velocity(LEG, np.zeros(3), np.zeros(2))


def test_fast_kernels_equal_the_printed_formulas():
    # the kernels evaluate cos/sin through half-angle tangents (speed); they must equal eq. (11) as printed
    q = np.concatenate([_rand_q(2000, seed=8), [[0.0, 0.0, 0.0], [1.1, -1.1, 1.4], [-1.5, 1.5, -1.5]]])
    a, b, g = q[:, 0], q[:, 1], q[:, 2]
    den = np.sqrt(1 + np.cos(b) ** 2 * np.tan(a) ** 2)
    printed = np.stack([LEG.L1 * np.sin(b) / den, -LEG.L1 * np.cos(b) * np.tan(a) / den,
                        LEG.L1 * np.cos(b) / den + 2 * LEG.L4 * np.cos(g) + LEG.L5], -1)  # fmt: skip
    np.testing.assert_allclose(ol.forward_kinematics(LEG, q), printed, rtol=0, atol=4e-16)
    np.testing.assert_allclose(ol.jacobian(LEG, q)[:, 2, 2], -2 * LEG.L4 * np.sin(g), rtol=0, atol=1e-16)
    # chunked evaluation: a batch longer than one chunk gives the same values as small batches
    big = _rand_q(70000, seed=9)
    np.testing.assert_array_equal(ol.forward_kinematics(LEG, big)[-5:], ol.forward_kinematics(LEG, big[-5:]))
