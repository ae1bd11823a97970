"""Parameters of the vectored thruster: Table 1 values and validation."""

from __future__ import annotations

import dataclasses
import math

import pytest

from robomech.mechanisms.vectored_thrust import VectoredThruster


def test_paper_values_are_table_1_in_si() -> None:
    th = VectoredThruster.paper()
    assert th.platform_radius == pytest.approx(0.020)
    assert th.rr_arc_radius == pytest.approx(0.0225)
    assert th.rrr_arc1_radius == pytest.approx(0.025)
    assert th.rrr_arc2_radius == pytest.approx(0.0225)
    assert th.propeller_arm == pytest.approx(0.080)
    assert th.q1_limits == pytest.approx((-math.pi / 4, math.pi / 4))
    assert th.q2_limits == pytest.approx((-math.pi / 6, math.pi / 6))
    assert th.tilt_limit == pytest.approx(math.pi / 4)
    assert th.arc_angle == pytest.approx(math.pi / 4)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("arc_angle", 0.0),
        ("arc_angle", math.pi / 2),
        ("platform_radius", -0.01),
        ("propeller_arm", float("nan")),
        ("propeller_arm", 0.01),  # inside the links
        ("q1_limits", (0.5, -0.5)),
        ("q2_limits", (-2.0, 2.0)),  # |q2| must stay below pi/2
        ("tilt_limit", 2.0),
        ("interference_clearance", -0.1),
    ],
)
def test_impossible_parameters_raise_naming_the_field(field: str, value: object) -> None:
    name = "propeller_arm" if field == "propeller_arm" else field
    with pytest.raises(ValueError, match=name):
        dataclasses.replace(VectoredThruster.paper(), **{field: value})


def test_frozen() -> None:
    with pytest.raises(dataclasses.FrozenInstanceError):
        VectoredThruster.paper().propeller_arm = 0.1  # type: ignore[misc]
