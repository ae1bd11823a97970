"""Inverse rates/accelerations (paper 5, Section 3.3) and statics of the thruster (issue 15, item 3)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import robomech.mechanisms.vectored_thrust as vt
from robomech.spatial import log_so3

TH = vt.VectoredThruster.paper()
# Least-squares solves of 3x2 systems with sigma_min >= 0.47 (Table 1's box): rounding only.
SOLVE_TOL = 1e-10
# Central differences of the platform rotation (step 1e-6 rad): truncation ~1e-12, rounding ~1e-10.
FD_TOL = 1e-8


def _box(n, seed=0):
    rng = np.random.default_rng(seed)
    (a1, b1), (a2, b2) = TH.q1_limits, TH.q2_limits
    return np.stack([rng.uniform(a1, b1, n), rng.uniform(a2, b2, n)], -1)


def test_round_trip_with_the_forward_acceleration():
    q = _box(400)
    rng = np.random.default_rng(1)
    qd, qdd = rng.normal(size=q.shape), rng.normal(size=q.shape)
    fwd = vt.angular_acceleration(TH, q, qd, qdd)
    r = vt.inverse_rates(TH, q, fwd.omega, fwd.omega_dot)
    assert r.valid.all() and r.sigma_min.min() > 0.4
    np.testing.assert_allclose(r.qd, qd, atol=SOLVE_TOL)
    np.testing.assert_allclose(r.qdd, qdd, atol=SOLVE_TOL)
    assert r.omega_residual.max() < 1e-12 and r.omega_dot_residual.max() < 1e-11


def test_unrealisable_angular_velocity_leaves_a_residual():
    q = _box(50, seed=2)
    J = vt.jacobian(TH, q).J
    n = np.cross(J[:, :, 0], J[:, :, 1])
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    r = vt.inverse_rates(TH, q, n)  # normal to J's range: no input motion produces it
    np.testing.assert_allclose(r.qd, 0.0, atol=1e-12)
    np.testing.assert_allclose(r.omega_residual, 1.0, atol=1e-12)
    assert not r.valid.any()  # a command the mechanism cannot produce is not a valid solution


def test_valid_means_the_command_is_realised():
    th = vt.VectoredThruster.paper()
    r = vt.inverse_rates(th, [0.0, 0.0], [0.0, 0.0, 1.0])
    assert float(r.omega_residual) == pytest.approx(1.0) and not r.valid
    # control: a realisable command at the same configuration is valid, and a component outside J's
    # range just above the tolerance is not
    q = _box(50, seed=4)
    J = vt.jacobian(th, q).J
    w = np.einsum("...ij,...j->...i", J, np.random.default_rng(5).normal(size=(50, 2)))
    assert vt.inverse_rates(th, q, w).valid.all()
    n = np.cross(J[:, :, 0], J[:, :, 1])
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    scale = 10.0 * vt.RATE_RESIDUAL_RTOL * np.linalg.norm(w, axis=-1, keepdims=True)
    assert not vt.inverse_rates(th, q, w + scale * n).valid.any()
    # the same for ω̇: a realisable ω with an unrealisable ω̇
    wd = np.einsum("...ij,...j->...i", J, np.ones((50, 2)))
    ok = vt.inverse_rates(
        th, q, w, vt.angular_acceleration(th, q, vt.inverse_rates(th, q, w).qd, 0 * w[:, :2]).omega_dot
    )
    assert ok.valid.all()
    assert not vt.inverse_rates(th, q, w, wd + n).valid.any()


def test_link_clearance_is_flagged_where_singular():
    th = vt.VectoredThruster.paper()
    r = vt.link_clearance(th, [[0.0, np.pi / 4], [0.1, 0.2]])
    assert r.valid.tolist() == [False, True]
    assert np.isnan(r.clearance[0]) and np.isfinite(r.clearance[1])
    assert np.array_equal(r.valid, vt.joint_axes(th, [[0.0, np.pi / 4], [0.1, 0.2]]).valid)


def test_idle_input_curve_and_singular_points_are_flagged():
    q1 = np.linspace(-0.7, 0.7, 8)  # not q1 = 0: (0, a) is the passive-axes-parallel point
    q_curve = np.stack([q1, vt.idle_input_curve(TH, q1)], -1)
    r = vt.inverse_rates(TH, q_curve, [0.1, 0.2, 0.3], [0.0, 0.0, 1.0])
    assert r.singular.all() and not r.valid.any()
    assert np.all(np.isfinite(r.qd)) and np.all(np.isfinite(r.qdd))  # damped, bounded
    assert np.abs(r.qd).max() <= 0.5 * vt.INPUT_GAIN_MAX * np.sqrt(0.14) + 1e-9
    sp = vt.inverse_rates(TH, vt.singular_points(TH), [0.0, 1.0, 0.0], [0.0, 0.0, 0.0])
    assert sp.singular.all() and np.all(np.isnan(sp.qd)) and np.all(sp.sigma_min == 0.0)


def test_statics_by_virtual_work_match_finite_differences_of_the_rotation():
    q = _box(60, seed=3)
    m = np.random.default_rng(4).normal(size=(60, 3))
    f = np.random.default_rng(5).normal(size=(60, 3))
    st = vt.static_torques(TH, q, np.concatenate([m, f], -1))
    assert st.valid.all()
    h = 1e-6
    cols = []
    for k in range(2):
        e = np.zeros(2)
        e[k] = h
        Rp, Rm = vt.platform_rotation(TH, q + e).R, vt.platform_rotation(TH, q - e).R
        # space angular velocity per unit input rate: log(R(q+h) R(q-h)^T) / 2h
        cols.append(log_so3(Rp @ np.swapaxes(Rm, -1, -2)) / (2 * h))
    J_fd = np.stack(cols, -1)
    np.testing.assert_allclose(st.tau, -np.einsum("nij,ni->nj", J_fd, m), atol=FD_TOL)
    # the force needs no torque; the moment part outside J's range is carried by the closure
    np.testing.assert_allclose(vt.static_torques(TH, q, np.concatenate([0 * m, f], -1)).tau, 0.0, atol=0)
    J = vt.jacobian(TH, q).J
    np.testing.assert_allclose(np.einsum("nij,ni->nj", J, st.unloaded), 0.0, atol=1e-12)


def test_propeller_thrust_needs_no_motor_torque_its_reaction_torque_does():
    q = _box(20, seed=6)
    s0 = vt.forward_kinematics(TH, q).axis
    thrust = vt.static_torques(TH, q, np.concatenate([0 * s0, 5.0 * s0], -1))
    np.testing.assert_allclose(thrust.tau, 0.0, atol=1e-15)
    torque = vt.static_torques(TH, q, np.concatenate([0.2 * s0, 0 * s0], -1))
    assert np.abs(torque.tau).max() > 1e-3
    # power balance with the forward velocity
    qd = np.random.default_rng(7).normal(size=q.shape)
    w = vt.angular_velocity(TH, q, qd).omega
    np.testing.assert_allclose(np.sum(torque.tau * qd, -1), -np.sum(0.2 * s0 * w, -1), atol=1e-13)


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: vt.inverse_rates(None, [0, 0], [0, 0, 1]), "th"),
        (lambda: vt.inverse_rates(TH, [0, 0], [0, 1]), "omega"),
        (lambda: vt.inverse_rates(TH, [0, 0], [0, 0, 1], [-np.inf, 0, 0]), "omega_dot"),
        (lambda: vt.inverse_rates(TH, [0, 0], [0, 0, 1], damping=-1.0), "damping"),
        (lambda: vt.inverse_rates(TH, np.zeros((2, 2)), np.zeros((3, 3))), "broadcast"),
        (lambda: vt.static_torques(TH, [0, 0], np.zeros(3)), "wrench"),
        (lambda: vt.static_torques(TH, [np.inf, 0], np.zeros(6)), "q"),
    ],
)
def test_bad_input(call, name):
    with pytest.raises(ValueError, match=name):
        call()


@settings(max_examples=60, deadline=None)
@given(
    st.tuples(st.floats(*TH.q1_limits), st.floats(*TH.q2_limits)),
    st.tuples(*(st.floats(-3.0, 3.0) for _ in range(2))),
    st.tuples(*(st.floats(-10.0, 10.0) for _ in range(2))),
)
def test_property_inverse_rates_invert_the_forward_acceleration(q, qd, qdd):
    q, qd, qdd = (np.array(x) for x in (q, qd, qdd))
    fwd = vt.angular_acceleration(TH, q, qd, qdd)
    r = vt.inverse_rates(TH, q, fwd.omega, fwd.omega_dot)
    assert r.valid
    np.testing.assert_allclose(r.qd, qd, atol=SOLVE_TOL * 10)
    np.testing.assert_allclose(r.qdd, qdd, atol=SOLVE_TOL * 100)


def test_overflowing_sample_is_flagged_not_warned_and_its_neighbour_unchanged():
    # either the boundary rejects the magnitude (naming omega) or the overflowing sample is flagged
    q = np.array([[0.1, 0.1], [0.2, 0.1]])
    good = vt.inverse_rates(TH, q[1], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0])
    try:
        r = vt.inverse_rates(TH, q, [[1e308] * 3, [0.0, 0.0, 1.0]], [[0.0] * 3, [0.0, 0.0, 1.0]])
    except ValueError as exc:
        assert "omega" in str(exc)
        return
    assert r.valid.tolist() == [False, True]
    np.testing.assert_array_equal(r.qdd[1], good.qdd)
