"""Parameters: Table 2 values, validation of impossible values, inertial parameters."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import robomech.mechanisms.omnileg as ol


def test_paper_values_table2():
    leg = ol.OmniLeg.paper()
    assert (leg.L1, leg.L3, leg.L4, leg.L5) == (0.15, 0.075, 0.095, 0.160)
    np.testing.assert_allclose([leg.alpha_max, leg.beta_max, leg.gamma_max], np.radians([65, 65, 85]))
    assert leg.gamma_min == 0.0
    assert leg.gravity[2] > 0  # Z0 points down, toward the foot
    assert set(leg.bodies) == {
        "hip_cross",
        "thigh_rod",
        "knee_cross",
        "knee_plate",
        "drive_shaft_in",
        "drive_cross",
        "drive_rod",
        "drive_shaft_out",
        "crank",
        "coupler",
        "foot",
    }


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("L1", 0.0),
        ("L3", -0.1),
        ("L4", np.nan),
        ("L5", np.inf),
        ("alpha_max", np.pi / 2),
        ("beta_max", -0.1),
        ("gamma_max", np.pi / 2),
        ("knee_to_crank", 0.2),
        ("shank_radius", 0.0),
    ],
)
def test_impossible_values_name_the_field(field, value):
    with pytest.raises(ValueError, match=field):
        dataclasses.replace(ol.OmniLeg.paper(), **{field: value})


def test_gamma_range_order_and_gravity_shape():
    with pytest.raises(ValueError, match="gamma_min"):
        dataclasses.replace(ol.OmniLeg.paper(), gamma_min=0.5, gamma_max=0.4)
    with pytest.raises(ValueError, match="gravity"):
        dataclasses.replace(ol.OmniLeg.paper(), gravity=(0.0, 9.81))


def test_rigid_body_validation():
    with pytest.raises(ValueError, match="mass"):
        ol.RigidBody(0.0, (0, 0, 0), np.eye(3).tolist())
    with pytest.raises(ValueError, match="inertia"):
        ol.RigidBody(1.0, (0, 0, 0), [[1, 0, 0], [0, 1, 0], [0, 0, 3]])  # violates the triangle inequality
    with pytest.raises(ValueError, match="inertia"):
        ol.RigidBody(1.0, (0, 0, 0), [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]])  # not symmetric
    with pytest.raises(ValueError, match="com"):
        ol.RigidBody(1.0, (0, 0), np.eye(3).tolist())


def test_bodies_are_user_replaceable():
    heavy_foot = ol.RigidBody(2.0, (0.0, 0.0, 0.1), (np.eye(3) * 1e-3).tolist())
    leg = dataclasses.replace(ol.OmniLeg.paper(), bodies={"foot": heavy_foot})
    assert leg.bodies["foot"] is heavy_foot
    assert leg.bodies["thigh_rod"] == ol.OmniLeg.paper().bodies["thigh_rod"]
    with pytest.raises(ValueError, match="bodies"):
        dataclasses.replace(ol.OmniLeg.paper(), bodies={"shin": heavy_foot})


def test_default_inertias_are_physical():
    for name, b in ol.OmniLeg.paper().bodies.items():
        ev = np.linalg.eigvalsh(b.inertia_matrix)
        assert ev[0] > 0, name
        assert 1e-3 < b.mass < 1.0, name  # grams to hundreds of grams for a 0.5 m leg
