"""Improved capstan equation (paper 3, eqs. (29)-(32)): accuracy against a tight reference, limits."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from robomech.mechanisms import continuum as C

# The accuracy target for the batched integrator.
CAPSTAN_TARGET = 1e-8
# DOP853 at rtol 1e-13 is ~1e-12 accurate on these smooth, moderately stiff problems.
REF_RTOL = 1e-13


def reference(phi, rho, alpha, n, t_out):
    """Tight per-point integration of eq. (29) in the original variables (T, T')."""
    c = C.capstan_coefficient(rho, alpha, n)
    p = (1 - n) / n
    sol = solve_ivp(
        lambda _, u: [u[1], -c * u[0] ** p * u[1] + rho * u[0]],
        (0.0, phi),
        [t_out, 0.0],
        method="DOP853",
        rtol=REF_RTOL,
        atol=REF_RTOL * t_out,
    )
    T, dT = sol.y[:, -1]
    return np.sqrt(rho**2 * T**2 + dT**2) / (rho * t_out)


def test_agrees_with_tight_reference_over_paper_box():
    rng = np.random.default_rng(0)
    m = 24
    phi = rng.uniform(0.0, np.pi, m)
    rho = rng.uniform(1.0, 10.0, m)
    alpha = rng.uniform(0.15, 0.6, m)
    n = rng.uniform(0.67, 1.0, m)
    t = 10 ** rng.uniform(-1, 1, m)
    # the corners: stiffest (rho 10, alpha 0.15, n 0.67) and fastest-growing (rho 1, alpha 0.6)
    phi[:6] = np.pi
    rho[:6] = [10, 10, 10, 1, 1, 1]
    alpha[:6] = [0.15, 0.15, 0.15, 0.6, 0.6, 0.6]
    n[:6] = 0.67
    t[:6] = [0.1, 1.0, 10.0, 0.1, 1.0, 10.0]
    # fastest slow-mode growth (rho 10, alpha 0.6) and weakest damping (rho 1, alpha 0.15), n near 1
    phi[6:12] = np.pi
    rho[6:12] = [10, 10, 10, 1, 1, 1]
    alpha[6:12] = [0.6, 0.6, 0.6, 0.15, 0.15, 0.15]
    n[6:12] = [0.8, 0.95, 0.999, 0.8, 0.95, 0.999]
    t[6:12] = 1.0
    k = C.capstan_tension_ratio(phi, rho=rho, alpha=alpha, n=n, t_out=t)
    ref = np.array([reference(*a) for a in zip(phi, rho, alpha, n, t, strict=True)])
    assert np.abs(k - ref).max() < CAPSTAN_TARGET
    assert np.abs(k / ref - 1).max() < CAPSTAN_TARGET


def test_n_equal_one_closed_form_matches_reference_and_integrator():
    phi, rho, alpha = np.linspace(0.1, np.pi, 5), np.array([1.0, 2.0, 5.0, 10.0, 3.0]), 0.3
    k = C.capstan_tension_ratio(phi, rho=rho, alpha=alpha, n=1.0)
    ref = np.array([reference(f, r, alpha, 1.0, 1.0) for f, r in zip(phi, rho, strict=True)])
    assert np.abs(k - ref).max() < 1e-11
    # the integrator path (n just below 1) joins the closed form continuously
    k_int = C.capstan_tension_ratio(phi, rho=rho, alpha=alpha, n=1.0 - 1e-9)
    assert np.abs(k_int - k).max() < 1e-7


def test_reduces_to_classical_capstan():
    phi = np.linspace(0.0, np.pi, 50)
    for alpha in (0.15, 0.6):
        classical = C.classical_capstan_ratio(phi, alpha)
        # vanishing bending stiffness (rho = pulley/cable radius -> inf) and Amontons friction (n = 1)
        assert np.abs(C.capstan_tension_ratio(phi, rho=np.inf, alpha=alpha, n=1.0) - classical).max() == 0
        near = C.capstan_tension_ratio(phi, rho=1e7, alpha=alpha, n=1.0)
        assert np.abs(near / classical - 1).max() < 1e-5


def test_rho_inf_limit_for_n_below_one():
    """rho -> inf, n < 1: (1/n) alpha^(-1/n) T^p T' = T; checked against its direct integration."""
    alpha, n, t_out, phi = 0.4, 0.8, 2.0, 2.5
    rhs = lambda _, T: n * alpha ** (1 / n) * T ** (1 - (1 - n) / n)  # noqa: E731
    T = solve_ivp(rhs, (0, phi), [t_out], rtol=1e-12, atol=1e-14).y[0, -1]
    k = C.capstan_tension_ratio(phi, rho=np.inf, alpha=alpha, n=n, t_out=t_out)
    assert abs(k - T / t_out) < 1e-10


def test_improved_model_loses_less_than_classical_fig9():
    phi = np.linspace(0.05, np.pi, 30)
    for rho in (1.0, 10.0):
        for alpha in (0.15, 0.6):
            for n in (0.67, 1.0):
                k = C.capstan_tension_ratio(phi, rho=rho, alpha=alpha, n=n, t_out=1.0)
                assert np.all(k < np.exp(alpha * phi))
                assert np.all(np.diff(k) > 0)  # monotone in the wrap angle
    assert C.capstan_tension_ratio(0.0, rho=3.0, alpha=0.3, n=0.8) == 1.0


def test_batched_broadcasting_equals_per_point():
    phi = np.linspace(0.2, 3.0, 6)[:, None]
    rho = np.array([1.0, 4.0, 10.0])[None, :]
    k = C.capstan_tension_ratio(phi, rho=rho, alpha=0.3, n=0.75, t_out=2.0)
    assert k.shape == (6, 3)
    single = np.array(
        [[C.capstan_tension_ratio(f, rho=r, alpha=0.3, n=0.75, t_out=2.0) for r in rho[0]] for f in phi[:, 0]]
    )
    assert np.abs(k - single).max() < 1e-12


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"phi": -0.1}, "phi"),
        ({"rho": 0.0}, "rho"),
        ({"rho": np.nan}, "rho"),
        ({"alpha": -1.0}, "alpha"),
        ({"n": 1.5}, "n"),
        ({"n": 0.0}, "n"),
        ({"t_out": 0.0}, "t_out"),
        ({"phi": np.inf}, "phi"),
    ],
)
def test_bad_input(kwargs, name):
    args = {"phi": 1.0, "rho": 2.0, "alpha": 0.3, "n": 0.8, "t_out": 1.0, **kwargs}
    phi = args.pop("phi")
    with pytest.raises(ValueError, match=name):
        C.capstan_tension_ratio(phi, **args)


def test_extreme_stiffness_is_refused_with_advice():
    with pytest.raises(ValueError, match="rho"):
        C.capstan_tension_ratio(3.0, rho=1e9, alpha=0.15, n=0.7)
