"""Derived inertial parameters follow the dimensions (issue 14, defect 1)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import robomech.mechanisms.omnileg as ol

Q = np.array([[0.3, 0.2, 0.5], [-0.4, 0.6, 1.1]])
FOOT = ol.RigidBody(0.5, (0.0, 0.0, 0.1), ((1e-3, 0, 0), (0, 1e-3, 0), (0, 0, 5e-4)))


def test_replace_dimensions_rederives_default_bodies():
    replaced = dataclasses.replace(ol.OmniLeg.paper(), L1=0.25, L4=0.12)
    built = ol.OmniLeg(L1=0.25, L3=0.075, L4=0.12, L5=0.16)
    for k in built.bodies:
        assert replaced.bodies[k] == built.bodies[k], k
    assert replaced == built
    np.testing.assert_array_equal(ol.gravity_torques(replaced, Q), ol.gravity_torques(built, Q))


def test_equality_sees_the_bodies():
    paper = ol.OmniLeg.paper()
    heavy = dataclasses.replace(paper, bodies={"foot": FOOT})
    assert heavy != paper
    assert not np.allclose(ol.gravity_torques(heavy, Q), ol.gravity_torques(paper, Q))
    # equal legs hash equal (the hash covers the dimensions only)
    assert hash(dataclasses.replace(paper)) == hash(paper)


def test_explicit_override_survives_a_change_of_dimensions():
    heavy = dataclasses.replace(ol.OmniLeg.paper(), bodies={"foot": FOOT})
    longer = dataclasses.replace(heavy, L1=0.2)
    assert longer.bodies["foot"] == FOOT
    assert longer.bodies.explicit == frozenset({"foot"})
    assert longer.bodies["thigh_rod"] == ol.OmniLeg(L1=0.2, L3=0.075, L4=0.095, L5=0.16).bodies["thigh_rod"]
    assert longer.bodies["thigh_rod"] != heavy.bodies["thigh_rod"]


def test_bodies_are_read_only_and_validated():
    leg = ol.OmniLeg.paper()
    with pytest.raises(TypeError):
        leg.bodies["foot"] = FOOT  # type: ignore[index]
    with pytest.raises(ValueError, match="bodies"):
        ol.OmniLeg(L1=0.15, L3=0.075, L4=0.095, L5=0.16, bodies=[FOOT])  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="unknown"):
        ol.OmniLeg(L1=0.15, L3=0.075, L4=0.095, L5=0.16, bodies={"shin": FOOT})
