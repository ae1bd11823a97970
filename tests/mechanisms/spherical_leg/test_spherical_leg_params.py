"""Parameters and workspace maps of the spherical parallel leg."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from robomech.mechanisms import spherical_leg as sl

LEG = sl.SphericalLeg.paper()


def test_paper_values_in_si():
    assert (LEG.R, LEG.r, LEG.h) == (0.075, 0.030, 0.100)
    assert LEG.platform_mass == 5.0 and LEG.gravity == (0.0, 0.0, -10.0)
    assert [b.mass for b in LEG.lower] == [2.0, 1.0, 2.0] and [b.mass for b in LEG.upper] == [1.5, 1.0, 1.5]
    # solid cylinder 30 mm, 2 kg: I_axial = m r^2 / 2
    assert LEG.lower[0].axial_inertia == pytest.approx(0.5 * 2.0 * 0.015**2, rel=1e-15)
    # square tube 40 mm, wall 10 mm, 1 kg: polar moment m (a^2 + b^2)/6
    assert LEG.lower[1].axial_inertia == pytest.approx(1.0 * (0.04**2 + 0.02**2) / 6, rel=1e-15)
    assert LEG.spin_ratio[0] == pytest.approx(2 * np.pi / 0.010)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("R", -0.075),
        ("r", 0.0),
        ("h", np.nan),
        ("platform_mass", -1.0),
        ("screw_lead", 0.0),
        ("length_max", 0.02),
    ],
)
def test_impossible_parameters_are_rejected(field, value):
    with pytest.raises(ValueError, match=field):
        replace(LEG, **{field: value})


def test_bad_bodies_and_gravity():
    with pytest.raises(ValueError, match="gravity"):
        replace(LEG, gravity=(0.0, np.inf, -9.81))
    with pytest.raises(ValueError, match=r"piston\.length"):
        sl.LegBody("piston", -0.1, 0.03, 0.015, 1.0)
    with pytest.raises(ValueError, match="shape"):
        sl.LegBody("piston", 0.1, 0.03, 0.015, 1.0, "hexagonal")
    with pytest.raises(ValueError, match="lower"):
        replace(LEG, lower=LEG.lower[:2])


def test_workspace_map_matches_svd_and_limits():
    g = np.stack(np.meshgrid(np.linspace(-1.3, 1.3, 41), np.linspace(-1.3, 1.3, 41), indexing="ij"), -1)
    wm = sl.workspace_map(LEG, g[..., 0], g[..., 1])
    s = np.linalg.svd(sl.jacobian(LEG, g[..., 0], g[..., 1]), compute_uv=False)
    assert np.allclose(wm.sigma_max, s[..., 0], rtol=1e-12)
    assert np.allclose(wm.sigma_min, s[..., 1], rtol=1e-9, atol=1e-15)
    L = sl.inverse_kinematics(LEG, g[..., 0], g[..., 1]).lengths
    assert np.array_equal(wm.reachable, np.all((L >= LEG.length_min) & (L <= LEG.length_max), -1))
    assert wm.reachable.any() and not wm.reachable.all()
    # sign change of dl3/dalpha (assembly branch boundary) happens only through the singular curve
    assert np.all(
        np.sign(wm.dl3_dalpha[:, 20])
        == np.sign(np.cos(g[:, 20, 1]) * LEG.h * np.cos(g[:, 20, 0]) + LEG.r * np.sin(g[:, 20, 0]))
    )
