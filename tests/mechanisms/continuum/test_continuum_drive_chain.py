"""Issue 16, the drive chain: the actuator pulley (paper 3, eqs. (29)-(34)) in compensated_drive and
simulate, and simulate_history (path-dependent, hysteresis).

Independent check of the pulley: eq. (29) integrated with scipy's solve_ivp (Radau, a code path that
shares nothing with the library's closed form / RK4), the wrap integral of eq. (34) carried as an extra
state.
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from robomech.mechanisms import continuum as c

ROBOT = c.ContinuumRobot.paper()
PSI = np.array([[0.5, 0.3], [1.0, -1.0], [0.2, 2.5]])
DIR = np.array([[1.0, -1.0, -1.0], [1.0, 1.0, -1.0], [-1.0, 1.0, -1.0]])
# solve_ivp at rtol 1e-11 vs the library's closed form (n = 1) / RK4 + 24-node Gauss-Legendre (n < 1):
# agreement to 1e-8 relative in the tension ratio and the wrap integral (RK4 accuracy constant ~1e-9).
PULLEY_REL_TOL = 1e-8
# simulate must invert compensated_drive to its Newton tolerance: SIM_TOLERANCE 1e-10 N m on ~0.03 N m
# moments gives poses to ~1e-8 rad.
ROUND_TRIP_TOL = 1e-7
# Loop area of a frictionless robot: every step of the loop meets the same equilibrium; the area is
# rounding of ~15 Newton solves, |theta| error ~1e-10 rad times a 1.5 mm drive: << 1e-11 rad m.
FRICTIONLESS_AREA_TOL = 1e-11


def _ivp_pulley(rho, alpha, n, phi, t_out):
    """(T_in, int_0^phi T_in(phi') dphi') for eq. (29) from the output side, T(0) = t_out, T'(0) = 0."""
    cc = (rho / n) * ((1.0 + rho) / (alpha * rho)) ** (1.0 / n)
    p = (1.0 - n) / n

    def f(_, y):
        T, Z, _I = y
        return [Z, -cc * max(T, 1e-300) ** p * Z + rho * T, math.sqrt(rho**2 * T**2 + Z**2) / rho]

    sol = solve_ivp(f, (0.0, phi), [t_out, 0.0, 0.0], method="Radau", rtol=1e-11, atol=1e-13)
    T, Z, integral = sol.y[:, -1]
    return math.sqrt(rho**2 * T**2 + Z**2) / rho, integral


def test_pulley_off_reproduces_the_drive_without_pulley():
    base = c.compensated_drive(ROBOT, PSI, DIR)
    # today's formula, piece by piece
    t = c.cable_tensions(ROBOT, PSI, direction=DIR).tension
    expect = c.theoretical_drive(ROBOT, PSI, "chord") + c.cable_elongation(ROBOT, PSI, t, DIR)
    np.testing.assert_array_equal(base.q_compensated, expect)
    np.testing.assert_array_equal(base.actuator_tension, base.tension)
    np.testing.assert_array_equal(base.delta_pulley, 0.0)
    # a pulley with no wrap is no pulley, exactly (compensation and simulation)
    zero = c.compensated_drive(ROBOT, PSI, DIR, pulley=c.Pulley(wrap=0.0))
    np.testing.assert_array_equal(zero.q_compensated, base.q_compensated)
    np.testing.assert_array_equal(zero.actuator_tension, base.tension)
    s0 = c.simulate(ROBOT, base.q_compensated, DIR)
    s1 = c.simulate(ROBOT, base.q_compensated, DIR, pulley=c.Pulley(wrap=0.0))
    np.testing.assert_array_equal(s0.psi, s1.psi)
    np.testing.assert_array_equal(s0.tension, s1.tension)


@pytest.mark.parametrize(
    ("alpha", "n", "radius"), [(0.15, 1.0, 0.004), (0.6, 1.0, 0.004), (0.6, 0.67, 0.004)]
)
def test_pulley_matches_scipy_integration_of_eq29(alpha, n, radius):
    pulley = c.Pulley(radius=radius, wrap=2.0, alpha=alpha, n=n)
    r = c.compensated_drive(ROBOT, PSI, DIR, pulley=pulley)
    rho = radius / (0.5 * ROBOT.cable_diameter)
    R = radius + 0.5 * ROBOT.cable_diameter
    ea = ROBOT.cable_axial_stiffness
    for i in (0, 2):  # both directions occur in these rows
        for j in range(3):
            t = r.tension[i, j]
            if DIR[i, j] > 0:  # pulled in: the robot side is the output
                t_act, integral = _ivp_pulley(rho, alpha, n, pulley.wrap, t)
                assert r.actuator_tension[i, j] == pytest.approx(t_act, rel=PULLEY_REL_TOL)
            else:  # paid out: the actuator side is the output; integrating from it must give t back
                t_act = r.actuator_tension[i, j]
                t_back, integral = _ivp_pulley(rho, alpha, n, pulley.wrap, t_act)
                assert t_back == pytest.approx(t, rel=PULLEY_REL_TOL)
            dc = R * (integral - ROBOT.pretension * pulley.wrap) / ea
            # the integral's relative accuracy is absolute in delta: integral - T0 wrap cancels where the
            # tension stays near the pretension (10 N paper robot)
            tol = PULLEY_REL_TOL * R * integral / ea
            assert r.delta_pulley[i, j] == pytest.approx(dc, rel=PULLEY_REL_TOL, abs=max(tol, 1e-15))
    base = c.compensated_drive(ROBOT, PSI, DIR)
    np.testing.assert_allclose(r.q_compensated - base.q_compensated, r.delta_pulley, rtol=1e-12, atol=1e-18)


def test_frictionless_pulley_changes_no_tension():
    r = c.compensated_drive(ROBOT, PSI, DIR, pulley=c.Pulley(wrap=2.0, alpha=0.0))
    np.testing.assert_array_equal(r.actuator_tension, r.tension)
    # only the Hooke stretch of the wrapped length at the (uniform) tension remains
    R = 0.005 + 0.5 * ROBOT.cable_diameter
    expect = R * 2.0 * (r.tension - ROBOT.pretension) / ROBOT.cable_axial_stiffness
    np.testing.assert_allclose(r.delta_pulley, expect, rtol=1e-13, atol=1e-19)


@settings(max_examples=25, deadline=None)
@given(
    a1=st.floats(0.01, 0.8),
    a2=st.floats(0.01, 0.8),
    wrap=st.floats(0.1, math.pi),
)
def test_pulley_monotone_in_friction(a1, a2, wrap):
    lo, hi = sorted((a1, a2))
    r_lo = c.compensated_drive(ROBOT, PSI, DIR, pulley=c.Pulley(wrap=wrap, alpha=lo))
    r_hi = c.compensated_drive(ROBOT, PSI, DIR, pulley=c.Pulley(wrap=wrap, alpha=hi))
    pulled, paid = DIR > 0, DIR < 0
    ratio_lo, ratio_hi = r_lo.actuator_tension / r_lo.tension, r_hi.actuator_tension / r_hi.tension
    assert np.all(ratio_hi[pulled] >= ratio_lo[pulled]) and np.all(ratio_lo[pulled] > 1.0)
    assert np.all(ratio_hi[paid] <= ratio_lo[paid]) and np.all(ratio_lo[paid] < 1.0)
    # more friction: more stretch on the pulled cable, less on the paid-out one
    assert np.all(r_hi.delta_pulley[pulled] >= r_lo.delta_pulley[pulled])
    assert np.all(r_hi.delta_pulley[paid] <= r_lo.delta_pulley[paid])


def test_simulate_with_pulley_inverts_the_compensation_and_the_pulley_matters():
    pulley = c.Pulley(wrap=math.pi / 2, alpha=0.6)
    r = c.compensated_drive(ROBOT, PSI, DIR, pulley=pulley)
    s = c.simulate(ROBOT, r.q_compensated, DIR, pulley=pulley)
    assert np.all(s.converged & s.taut)
    np.testing.assert_allclose(s.psi, PSI, atol=ROUND_TRIP_TOL)
    np.testing.assert_allclose(s.actuator_tension, r.actuator_tension, rtol=1e-6)
    # the drive compensated without the pulley misses the pose on the robot with one
    q_nopulley = c.compensated_drive(ROBOT, PSI, DIR).q_compensated
    miss = c.simulate(ROBOT, q_nopulley, DIR, pulley=pulley)
    tip = np.linalg.norm(c.tip_position(ROBOT, miss.psi) - c.tip_position(ROBOT, PSI), axis=-1)
    assert np.all(tip > 1e-5)  # > 10 um: the pulley stretch (~5-10 um of drive) moves the tip


def _loop(robot, q_max=1.5e-3, m=8):
    up = np.linspace(0.0, q_max, m)
    qs = np.concatenate([up, up[::-1][1:]])
    q = np.zeros((qs.size, 3))
    q[:, 0], q[:, 1], q[:, 2] = qs, -0.5 * qs, -0.5 * qs
    return qs, q, c.simulate_history(robot, q)


def test_history_hysteresis_loop():
    qs, _, h = _loop(ROBOT)
    assert np.all(h.valid)
    area = abs(np.trapezoid(h.psi[:, 0], qs))  # closed loop theta(q_0)
    assert area > 1e-6  # measured 4.2e-6 rad m
    # same drive, loading vs unloading: different bend and tension
    m = (qs.size + 1) // 2
    assert abs(h.psi[m - 2, 0] - h.psi[m, 0]) > 1e-3
    assert abs(h.tension[m - 2, 0] - h.tension[m, 0]) > 1e-2
    np.testing.assert_array_equal(h.direction[1:m, 0], 1.0)
    np.testing.assert_array_equal(h.direction[m:, 0], -1.0)
    # the span tensions with memory: the first hole slides in (+1) on the way up and out (-1) on the
    # way down; right after the reversal distal holes stick (0) at their old tension
    np.testing.assert_array_equal(h.state[1:m, 0, 0], 1)
    np.testing.assert_array_equal(h.state[m:, 0, 0][h.state[m:, 0, 0] != 0], -1)
    np.testing.assert_array_equal(h.state[m:, 0, 1], -1)
    assert np.any(h.state[m, 0, :] == 0)
    _, _, h0 = _loop(c.ContinuumRobot(friction=(0.0, 0.0, 0.0)))
    assert abs(np.trapezoid(h0.psi[:, 0], qs)) < FRICTIONLESS_AREA_TOL


def test_history_step_equals_simulate_and_with_pulley():
    q = c.compensated_drive(ROBOT, PSI, np.ones((3, 3))).q_compensated
    h = c.simulate_history(ROBOT, q[None])  # one step, batch of 3
    s = c.simulate(ROBOT, q, np.where(q > 0, 1.0, np.where(q < 0, -1.0, 1.0)))
    np.testing.assert_array_equal(h.psi[0], s.psi)
    pulley = c.Pulley(alpha=0.3)
    hp = c.simulate_history(ROBOT, q[:, None, :], pulley=pulley, times=np.arange(3.0))  # 3 steps
    assert np.all(hp.valid)
    assert not np.allclose(hp.actuator_tension, hp.tension)


def test_history_flags_slack_cables_per_sample():
    q = np.zeros((3, 2, 3))
    q[:, 1, :] = -5e-3  # every cable paid out 5 mm: the pretension cannot keep them taut
    q[:, 0, 0] = [0.0, 2e-4, 4e-4]
    h = c.simulate_history(ROBOT, q)
    assert np.all(h.valid[:, 0])
    assert not np.any(h.taut[:, 1]) and not np.any(h.valid[:, 1])
    assert np.all(h.tension[:, 1] == 0.0)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"q": np.array([[0.0, 0.0, 0.0], [np.nan, 0.0, 0.0]])}, "q"),
        ({"q": np.zeros((3, 4))}, "q"),
        ({"q": np.zeros(3)}, "q"),
        ({"q": np.zeros((3, 3)), "times": np.array([0.0, 2.0, 1.0])}, "times"),
        ({"q": np.zeros((3, 3)), "times": np.array([0.0, 1.0])}, "times"),
        ({"q": np.zeros((3, 3)), "pulley": "pulley"}, "pulley"),
    ],
)
def test_history_bad_input(kwargs, name):
    with pytest.raises(ValueError, match=name):
        c.simulate_history(ROBOT, **kwargs)


def test_negative_friction_is_refused():
    with pytest.raises(ValueError, match="friction"):
        c.ContinuumRobot(friction=(0.2, -0.1, 0.2))
    with pytest.raises(ValueError, match="alpha"):
        c.Pulley(alpha=-0.1)
