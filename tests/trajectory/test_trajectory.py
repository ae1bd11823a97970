"""Trajectory profiles: derivatives by finite differences, boundary conditions, paper 2 coefficients."""

import numpy as np
import pytest

from robomech import trajectory as tr

DT = 1e-6
FD_TOL = 1e-6  # central difference in time, step 1e-6 on O(1-100) values


def check_derivatives(f, t):
    p = f(t)
    assert np.abs(p.qd - (f(t + DT).q - f(t - DT).q) / (2 * DT)).max() < FD_TOL * max(1, np.abs(p.qd).max())
    assert np.abs(p.qdd - (f(t + DT).qd - f(t - DT).qd) / (2 * DT)).max() < FD_TOL * max(
        1, np.abs(p.qdd).max()
    )


def test_quintic_is_rest_to_rest_with_consistent_derivatives():
    t = np.linspace(0.01, 1.99, 50)
    check_derivatives(lambda s: tr.quintic(s, 2.0, 0.3, 1.1), t)
    p = tr.quintic(np.array([0.0, 2.0, 3.0]), 2.0, 0.3, 1.1)
    assert np.allclose(p.q, [0.3, 1.1, 1.1]) and np.allclose(p.qd, 0) and np.allclose(p.qdd, 0)


def test_swing_sextic_peaks_at_half_period_and_reproduces_paper2_eq51_coefficients():
    t = np.linspace(0.01, 4.99, 50)
    check_derivatives(lambda s: tr.swing_sextic(s, 5.0, 0.05), t)
    p = tr.swing_sextic(np.array([0.0, 2.5, 5.0]), 5.0, 0.05)
    assert np.allclose(p.q, [0.0, 0.05, 0.0]) and np.allclose(p.qd, 0.0, atol=1e-15)
    # paper 2, eq. (51): Z(t) = 0.05(-0.004096 t^6 + 0.06144 t^5 - 0.3072 t^4 + 0.512 t^3), T = 5 s
    z = 0.05 * (-0.004096 * t**6 + 0.06144 * t**5 - 0.3072 * t**4 + 0.512 * t**3)
    assert np.allclose(tr.swing_sextic(t, 5.0, 0.05).q, z, atol=1e-15)
    # and Y(t) = 0.1(0.00192 t^5 - 0.024 t^4 + 0.08 t^3) is the quintic over 5 s
    y = 0.1 * (0.00192 * t**5 - 0.024 * t**4 + 0.08 * t**3)
    assert np.allclose(tr.quintic(t, 5.0, 0.0, 0.1).q, y, atol=1e-15)


def test_sinusoid_and_polynomial():
    t = np.linspace(0, 10, 101)
    check_derivatives(lambda s: tr.sinusoid(s, np.pi / 3, 0.05, 0.2, 0.1), t)
    check_derivatives(lambda s: tr.polynomial(s, [1.0, -2.0, 0.5, 0.25]), t)
    p = tr.sinusoid(t, 2.0, 0.5)
    assert np.allclose(p.q, 2 * np.sin(np.pi * t))


def test_broadcasting_over_time_and_joints_and_stack():
    t = np.linspace(0, 1, 11)[:, None]
    p = tr.quintic(t, 1.0, np.zeros(3), np.array([1.0, 2.0, 3.0]))
    assert p.q.shape == (11, 3)
    s = tr.sinusoid(t[:, 0], 1.0, 1.0).stack(tr.quintic(t[:, 0], 1.0))
    assert s.q.shape == (11, 2)


def test_bad_input():
    with pytest.raises(ValueError, match="duration"):
        tr.quintic(np.zeros(3), 0.0)
    with pytest.raises(ValueError, match="t"):
        tr.sinusoid([0.0, np.nan], 1.0, 1.0)


def test_stack_refuses_what_is_not_a_profile_of_the_same_times():
    t5, t6 = np.linspace(0.0, 1.0, 5), np.linspace(0.0, 1.0, 6)
    a, b = tr.quintic(t5, 1.0), tr.quintic(t6, 1.0)
    with pytest.raises(ValueError, match="self"):
        tr.Profile.stack(None)
    with pytest.raises(ValueError, match=r"others\[0\]"):
        a.stack(None)
    with pytest.raises(ValueError, match=r"others\[0\].*shape"):
        a.stack(b)
    assert a.stack(tr.quintic(t5, 2.0)).q.shape == (5, 2)  # control: same times stack
