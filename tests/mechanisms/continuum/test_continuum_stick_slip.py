"""Stick-slip with memory along the disks (paper 3, eq. (19); issue 16 item 3)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomech.mechanisms import continuum as C

PAPER = C.ContinuumRobot.paper()
BOUND_TOL = 1e-12
"""Relative slack on the friction bounds: the clip is exact, only the exp() rounding differs."""


def _history(t_values, theta=np.pi / 2, beta=0.3):
    t = np.asarray(t_values, float)
    psi = np.broadcast_to([theta, beta], (t.shape[0], 2))
    return psi, t


@settings(max_examples=30, deadline=None)
@given(st.lists(st.floats(1.0, 15.0), min_size=2, max_size=12), st.floats(0.0, 2.0))
def test_tensions_stay_within_the_friction_bounds(values, theta):
    t = np.stack([values, np.full(len(values), 5.0), np.full(len(values), 5.0)], -1)
    psi, t = _history(t, theta)
    h = C.stick_slip_tensions(PAPER, psi, t)
    eta = C.wrap_angles(PAPER, psi)
    prox = np.concatenate([t[..., None], h.span_tension[..., :-1]], -1)
    ratio = h.span_tension / prox
    mu = PAPER.friction_array[:, None]
    assert np.all(ratio >= np.exp(-mu * eta) * (1 - BOUND_TOL))
    assert np.all(ratio <= np.exp(mu * eta) * (1 + BOUND_TOL))


def test_sustained_pull_reaches_the_sliding_profile():
    """Pulling in from a uniform state: every hole slides, the profile is eq. (23)'s exp(-mu eta) chain,
    the same as friction_factors(direction=+1)."""
    psi, t = _history([[5.0, 5.0, 5.0], [12.0, 12.0, 12.0]])
    h = C.stick_slip_tensions(PAPER, psi, t)
    assert np.all(h.state[1] == 1)
    P = C.friction_factors(PAPER, psi[1], [1.0, 1.0, 1.0])
    assert np.allclose(h.span_tension[1], 12.0 * P, rtol=1e-13, atol=0)


def test_small_reversal_sticks_and_keeps_the_tension():
    """After pulling in, a small release only slides the first holes; the distal spans keep their
    tension (memory: eq. (19)'s T(t^-1)), instead of the frictionless value."""
    psi, t = _history([[5.0] * 3, [12.0] * 3, [11.5] * 3, [10.5] * 3])
    h = C.stick_slip_tensions(PAPER, psi, t)
    assert np.all(h.state[2] == 0)  # 0.5 N release: inside the dead band, everything sticks
    assert np.all(h.state[3][:, 0] == -1)  # 1.5 N: the first hole slides back ...
    assert np.all(h.state[3][:, 1:5] == 0)  # ... the rest sticks
    assert np.allclose(h.distal[3], h.distal[1], rtol=0, atol=1e-15)


def test_loading_unloading_gives_a_hysteresis_loop():
    up = np.linspace(3.0, 12.0, 19)
    cycle = np.concatenate([up, up[::-1][1:]])
    t = np.stack([cycle, np.full_like(cycle, 5.0), np.full_like(cycle, 5.0)], -1)
    psi, t = _history(t)
    d = C.stick_slip_tensions(PAPER, psi, t).distal[:, 0]
    n = up.size
    rising, falling = d[:n], d[n - 1 :][::-1]
    assert np.all(falling[1:-1] > rising[1:-1])  # unloading above loading at the same actuator tension
    area = np.trapezoid(falling - rising, up)
    assert area > 0.5  # N^2: a loop, not a line (measured ~3.7 N^2 at 90 deg)
    # path dependence: same actuator tension and pose, different distal tension
    assert abs(rising[n // 2] - falling[n // 2]) > 0.5


def test_frictionless_cable_follows_the_actuator():
    robot = C.ContinuumRobot(friction=(0.0, 0.0, 0.0))
    psi, t = _history([[5.0, 4.0, 3.0], [9.0, 2.0, 3.5]])
    h = C.stick_slip_tensions(robot, psi, t)
    assert np.allclose(h.span_tension, t[..., None], rtol=0, atol=1e-15)


def test_bad_input():
    psi, t = _history([[5.0] * 3, [6.0] * 3])
    with pytest.raises(ValueError, match="t_act"):
        C.stick_slip_tensions(PAPER, psi, [[5.0] * 3, [0.0, 5.0, 5.0]])  # a slack cable
    with pytest.raises(ValueError, match="time"):
        C.stick_slip_tensions(PAPER, psi, t[:1])
    with pytest.raises(ValueError, match="psi"):
        C.stick_slip_tensions(PAPER, psi[:, :1], t)
    with pytest.raises(ValueError, match="t_act"):
        C.stick_slip_tensions(PAPER, psi, [[5.0] * 3, [np.nan] * 3])
    with pytest.raises(ValueError, match="friction"):
        C.ContinuumRobot(friction=(-0.1, 0.2, 0.2))
