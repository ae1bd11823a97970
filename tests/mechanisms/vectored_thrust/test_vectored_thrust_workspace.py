"""Workspace, singularity and dexterity maps (paper 5, Section 4)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from robomech.analysis import workspace
from robomech.mechanisms import vectored_thrust as vt

TH = vt.VectoredThruster.paper()


def test_passive_axes_parallel_at_the_singular_points() -> None:
    for q in vt.singular_points(TH):
        ax = vt.joint_axes(TH, q)
        assert abs(abs(np.dot(ax.s22, ax.s12)) - 1.0) < 1e-15
        assert vt.dexterity(TH, q) == 0.0
    # the +-pi/4 trajectory box of Table 1 contains (0, pi/4) on its edge, the +-pi/6 range does not
    q = vt.singular_points(TH)[0]
    assert abs(q[1]) <= math.pi / 4 + 1e-15 and abs(q[1]) > TH.q2_limits[1]
    # dexterity falls continuously to 0 approaching it
    d = vt.dexterity(TH, np.stack([np.zeros(4), math.pi / 4 - np.array([1e-1, 1e-2, 1e-3, 1e-4])], -1))
    assert np.all(np.diff(d) < 0)


def test_idle_input_curve_has_rank_one_jacobian() -> None:
    q1 = np.linspace(-1.0, 1.0, 11)
    q = np.stack([q1, vt.idle_input_curve(TH, q1)], -1)
    J = vt.jacobian(TH, q[q1 != 0]).J
    np.testing.assert_allclose(J[..., 0], 0.0, atol=1e-14)  # q1 no longer moves the platform
    assert np.all(vt.dexterity(TH, q[q1 != 0]) < 1e-14)


def test_closed_form_dexterity_matches_svd() -> None:
    g = vt.input_grid(TH, 30, [[-1.2, 1.2], [-1.0, 1.0]])
    J = vt.jacobian(TH, g).J
    sm = workspace.singularity_map(J)
    np.testing.assert_allclose(vt.dexterity(TH, g), sm.dexterity, atol=1e-12)


def test_z_range_with_the_universal_joint_limit() -> None:
    m = vt.workspace_map(TH, vt.input_grid(TH, 201))
    z = m.tip[..., 2][m.reachable]
    assert z.max() == pytest.approx(0.080, abs=1e-12)
    assert z.min() >= 0.080 * math.cos(math.pi / 4) - 1e-12  # the tilt limit bounds z from below
    assert z.min() < 0.080 * math.cos(math.pi / 4) + 5e-4  # and is reached within the input ranges
    # without the tilt limit the stated input ranges reach far below the paper's 40 mm
    free = vt.workspace_map(dataclasses.replace(TH, tilt_limit=1.5), vt.input_grid(TH, 201))
    assert free.tip[..., 2][free.reachable].min() < 0.040


def test_arc_clearance_known_geometry() -> None:
    x, y, z = np.eye(3)
    d45 = np.array([1.0, 1.0, 0.0]) / math.sqrt(2)

    def el(e: float) -> np.ndarray:  # point above d45 at elevation e
        return np.cos(e) * d45 + np.sin(e) * z

    assert vt.arc_clearance(x, y, el(-0.3), el(0.3)) == 0.0  # crossing
    u = np.array([math.cos(0.2), math.sin(0.2), 0.0])
    assert vt.arc_clearance(x, u, y, z) == pytest.approx(math.pi / 2 - 0.2, abs=1e-14)  # end to end
    assert vt.arc_clearance(x, y, el(0.3), el(0.6)) == pytest.approx(0.3, abs=1e-14)  # end to interior
    assert vt.arc_clearance(el(0.3), el(0.6), x, y) == pytest.approx(0.3, abs=1e-14)  # symmetric


def test_interference_constraint_cuts_the_workspace_when_clearance_grows() -> None:
    g = vt.input_grid(TH, 101)
    base = vt.workspace_map(TH, g)
    assert np.nanmin(base.clearance) > TH.interference_clearance  # inactive for Table 1's geometry
    tight = vt.workspace_map(dataclasses.replace(TH, interference_clearance=1.2), g)
    assert 0 < tight.clear.sum() < tight.clear.size
    assert np.array_equal(tight.reachable, base.reachable & (base.clearance >= 1.2))


def test_input_grid_and_bad_inputs() -> None:
    g = vt.input_grid(TH, (3, 4))
    assert g.shape == (3, 4, 2)
    np.testing.assert_allclose(g[0, 0], [TH.q1_limits[0], TH.q2_limits[0]])
    with pytest.raises(ValueError, match="n"):
        vt.input_grid(TH, 1)
    with pytest.raises(ValueError, match="limits"):
        vt.input_grid(TH, 5, [[1.0, 0.0], [0.0, 1.0]])
    with pytest.raises(ValueError, match="q"):
        vt.workspace_map(TH, np.zeros((4, 3)))
    with pytest.raises(ValueError, match="b2"):
        vt.arc_clearance([1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [0, 1.0])
    with pytest.raises(ValueError, match="a1"):
        vt.arc_clearance([float("inf"), 0, 0], [0, 1.0, 0], [0, 0, 1.0], [0, 1.0, 0])
