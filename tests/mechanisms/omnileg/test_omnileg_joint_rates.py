"""Inverse differential kinematics of the OmniLeg (issue 15, item 2)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import robomech.mechanisms.omnileg as ol

LEG = ol.OmniLeg.paper()
# Exact linear solves of well-conditioned 3x3 systems (rcond > 1e-2 here): rounding only.
SOLVE_TOL = 1e-10
# Central differences in time of IK angles along eq. (51) (dt = 1e-4 s): truncation dt² q''' ~ 1e-8 rad/s.
FD_RATE_TOL = 1e-6


def _regular(n, seed=0):
    rng = np.random.default_rng(seed)
    return np.stack(
        [
            rng.uniform(-1, 1, n) * LEG.alpha_max,
            rng.uniform(-1, 1, n) * LEG.beta_max,
            rng.uniform(0.2, LEG.gamma_max, n),
        ],
        -1,
    )


def test_round_trip_with_the_forward_rates_and_accelerations():
    q = _regular(500)
    rng = np.random.default_rng(1)
    qd, qdd = rng.normal(size=q.shape), rng.normal(size=q.shape)
    v = ol.foot_velocity(LEG, q, qd)
    a = ol.foot_acceleration(LEG, q, qd, qdd)
    r = ol.joint_rates(LEG, q, v, a)
    assert r.valid.all() and not r.singular.any()
    np.testing.assert_allclose(r.qd, qd, atol=SOLVE_TOL)
    np.testing.assert_allclose(r.qdd, qdd, atol=SOLVE_TOL)
    assert r.velocity_residual.max() < 1e-12 and r.acceleration_residual.max() < 1e-11


def test_rates_match_finite_differences_of_the_inverse_kinematics_along_eq51():
    t = np.linspace(1.0, 4.0, 31)
    dt = 1e-4
    traj = ol.foot_trajectory_eq51(LEG, t)
    q = ol.inverse_kinematics(LEG, traj.q).q
    qp = ol.inverse_kinematics(LEG, ol.foot_trajectory_eq51(LEG, t + dt).q).q
    qm = ol.inverse_kinematics(LEG, ol.foot_trajectory_eq51(LEG, t - dt).q).q
    r = ol.joint_rates(LEG, q, traj.qd, traj.qdd)
    assert r.valid.all()
    np.testing.assert_allclose(r.qd, (qp - qm) / (2 * dt), atol=FD_RATE_TOL)
    np.testing.assert_allclose(r.qdd, (qp - 2 * q + qm) / dt**2, atol=1e-3)


def test_gamma_zero_is_flagged_and_damped_not_blown_up():
    q = np.array([[0.3, -0.2, 0.0], [0.3, -0.2, 1e-5], [0.3, -0.2, 0.5]])
    v = np.array([0.01, 0.02, 0.05])  # has a component along the thigh direction: unreachable at γ = 0
    r = ol.joint_rates(LEG, q, v, np.zeros(3))
    assert r.singular.tolist() == [True, True, False]
    assert r.valid.tolist() == [False, False, True]
    assert np.all(np.isfinite(r.qd)) and np.all(np.isfinite(r.qdd))
    assert np.abs(r.qd[:2, 2]).max() < 1.0 / (2 * ol._dynamics.SINGULAR_RCOND)  # bounded by the damping
    assert r.velocity_residual[0] > 1e-3 and r.velocity_residual[2] < 1e-12
    # the tangential part of the motion is still realised exactly at γ = 0
    u = ol.thigh_direction(0.3, -0.2)
    P = np.eye(3) - np.outer(u, u)
    np.testing.assert_allclose(P @ ol.foot_velocity(LEG, q[0], r.qd[0]), P @ v, atol=1e-12)
    # damping 0: at γ = 0 exactly (σ = 0) the null direction gets 0, γ̇ = 0 ...
    assert ol.joint_rates(LEG, q[0], v, damping=0.0).qd[2] == 0.0


def test_damping_zero_inverts_the_weak_direction_fully():
    # ... but next to it the weak direction is inverted fully (1/σ, the exact inverse), not dropped:
    # what the docstring says, and what a truncated pseudo-inverse would not do (γ̇ would stay 0)
    q = np.array([0.3, -0.2, 1e-5])
    v = np.array([0.0, 0.0, 1e-4])
    r = ol.joint_rates(LEG, q, v, damping=0.0)
    exact = np.linalg.solve(ol.jacobian(LEG, q), v)
    np.testing.assert_allclose(r.qd, exact, rtol=1e-9, atol=1e-9 * np.abs(exact).max())  # rounding of the SVD
    assert abs(r.qd[2]) > 1.0 and r.velocity_residual < 1e-12 and r.singular and not r.valid
    damped = ol.joint_rates(LEG, q, v)  # the default damping bounds it
    assert abs(damped.qd[2]) < abs(r.qd[2]) / 10


def test_batch_equals_per_sample_and_no_acceleration():
    q = _regular(6, seed=3)
    v = np.random.default_rng(4).normal(size=(6, 3))
    r = ol.joint_rates(LEG, q, v)
    assert np.all(np.isnan(r.qdd)) and np.all(np.isnan(r.acceleration_residual))
    for i in range(6):
        np.testing.assert_allclose(ol.joint_rates(LEG, q[i], v[i]).qd, r.qd[i], atol=1e-14)
    assert ol.joint_rates(LEG, q.reshape(2, 3, 3), v[0]).qd.shape == (2, 3, 3)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"q": np.full(3, np.inf)}, "q"),
        ({"foot_velocity": np.zeros(4)}, "foot_velocity"),
        ({"foot_acceleration": [np.inf, 0, 0]}, "foot_acceleration"),
        ({"damping": -1.0}, "damping"),
        ({"damping": np.nan}, "damping"),
        ({"damping": "0.1"}, "damping"),
    ],
)
def test_bad_input_names_the_argument(kwargs, name):
    args = {"q": np.array([0.1, 0.2, 0.3]), "foot_velocity": np.zeros(3), "foot_acceleration": None}
    damping = kwargs.pop("damping", ol._rates.DEFAULT_DAMPING)
    args.update(kwargs)
    with pytest.raises(ValueError, match=name):
        ol.joint_rates(LEG, args["q"], args["foot_velocity"], args["foot_acceleration"], damping=damping)


@settings(max_examples=60, deadline=None)
@given(
    st.tuples(
        st.floats(-LEG.alpha_max, LEG.alpha_max),
        st.floats(-LEG.beta_max, LEG.beta_max),
        st.floats(0.05, LEG.gamma_max),
    ),
    st.tuples(*(st.floats(-2.0, 2.0) for _ in range(3))),
    st.tuples(*(st.floats(-5.0, 5.0) for _ in range(3))),
)
def test_property_rates_invert_the_forward_map(q, qd, qdd):
    q, qd, qdd = (np.array(x) for x in (q, qd, qdd))
    r = ol.joint_rates(LEG, q, ol.foot_velocity(LEG, q, qd), ol.foot_acceleration(LEG, q, qd, qdd))
    assert r.valid
    # the γ direction's sensitivity is 2 L4 sin γ >= 0.0095 m/rad here: rounding / that
    np.testing.assert_allclose(r.qd, qd, atol=1e-9)
    np.testing.assert_allclose(r.qdd, qdd, atol=1e-8)


def test_overflowing_sample_is_flagged_not_warned():
    # either the boundary rejects the magnitude (naming foot_velocity) or the sample is flagged
    q = np.array([[0.1, 0.1, 0.5]] * 2)
    try:
        r = ol.joint_rates(LEG, q, [[1e308] * 3, [0.0, 0.0, 0.01]])
    except ValueError as exc:
        assert "foot_velocity" in str(exc)
        return
    assert r.valid.tolist() == [False, True]
    np.testing.assert_array_equal(r.qd[1], ol.joint_rates(LEG, q[1], [0.0, 0.0, 0.01]).qd)
