"""Screw-theory mobility of the vectored thruster (paper 5, Section 2), computed from the joint screws."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomech.mechanisms import vectored_thrust as vt
from robomech.spatial import virtual_power

TH = vt.VectoredThruster.paper()


def _in_span(v: np.ndarray, basis: np.ndarray, tol: float = 1e-9) -> bool:
    coef, *_ = np.linalg.lstsq(basis.T, v, rcond=None)
    return bool(np.linalg.norm(basis.T @ coef - v) < tol)


@given(st.floats(-math.pi / 4, math.pi / 4), st.floats(-math.pi / 6, math.pi / 6))
@settings(max_examples=40, deadline=None)
def test_platform_has_two_rotations_everywhere(q1: float, q2: float) -> None:
    m = vt.platform_mobility(TH, (q1, q2))
    assert (m.dof, m.rotational_dof, m.translational_dof) == (2, 2, 0)
    rrr, rr = m.chains
    assert rrr.constraints.shape[0] == 3  # three forces through O (eq. 6)
    assert rr.constraints.shape[0] == 4  # three forces through O and a couple (eq. 4)
    assert m.common_constraints == 3 and m.redundant_constraints == 0
    assert m.gruebler_kutzbach == -1 and m.modified_gruebler_kutzbach == 2  # G-K fails: over-constrained
    # The twists are the rotations about the RR chain's two axes (Y and s22), not about X and Y.
    ax = vt.joint_axes(TH, (q1, q2))
    basis = np.stack([np.r_[0, 1, 0, 0, 0, 0], np.r_[ax.s22, 0, 0, 0]])
    for tw in m.platform_twists:
        assert _in_span(tw, basis)
    # each chain's constraints are reciprocal to its joint screws; the union to the platform twists
    for chain, S in zip(m.chains, vt.chain_screws(TH, (q1, q2)), strict=True):
        np.testing.assert_allclose(virtual_power(chain.constraints[:, None], S[None]), 0.0, atol=1e-12)
    P = m.platform_twists
    np.testing.assert_allclose(virtual_power(m.constraint_wrenches[:, None], P[None]), 0.0, atol=1e-12)


def test_paper_eq10_basis_holds_at_home() -> None:
    m = vt.platform_mobility(TH, (0.0, 0.0))
    for e in (np.r_[1.0, 0, 0, 0, 0, 0], np.r_[0, 1.0, 0, 0, 0, 0]):
        assert _in_span(e, m.platform_twists)


def test_moving_an_axis_off_the_centre_changes_the_mobility() -> None:
    q = (0.3, -0.2)
    s22 = vt.joint_axes(TH, q).s22
    side = np.cross(s22, [0.0, 1.0, 0.0])
    side /= np.linalg.norm(side)
    # s22 moved 5 mm sideways: its rotation leaves the RRR chain's sphere; only the rotation about Y survives
    off = vt.platform_mobility(TH, q, {"s22": 0.005 * side})
    assert (off.dof, off.rotational_dof) == (1, 1)
    assert _in_span(np.r_[0, 1.0, 0, 0, 0, 0], off.platform_twists)
    # moved along its own line, the axis is unchanged, and so is the mobility
    along = vt.platform_mobility(TH, q, {"s22": 0.01 * s22})
    assert along.dof == 2
    # an RRR axis moved off the centre: the RRR chain no longer makes pure rotations about O
    off_rrr = vt.platform_mobility(TH, q, {"s12": [0.0, 0.004, 0.002]})
    assert off_rrr.dof < 2
    for m in (off, off_rrr):
        W, P = m.constraint_wrenches, m.platform_twists
        np.testing.assert_allclose(virtual_power(W[:, None], P[None]), 0.0, atol=1e-12)


def test_whole_mechanism_with_central_universal_joint() -> None:
    mm = vt.mechanism_mobility(TH, (0.3, -0.2))
    assert mm.platform.dof == 2
    assert (mm.propeller.dof, mm.propeller.rotational_dof) == (3, 3)  # 2 steering rotations + propeller spin
    off = vt.mechanism_mobility(TH, (0.3, -0.2), ujoint_centre=[0.0, 0.0, 0.005])
    assert off.propeller.dof == 1  # universal joint off the common centre: the propeller can only spin


def test_bad_inputs() -> None:
    with pytest.raises(ValueError, match="offsets"):
        vt.platform_mobility(TH, (0, 0), {"s99": [0, 0, 0]})
    with pytest.raises(ValueError, match="singularity"):
        vt.platform_mobility(TH, (0.0, math.pi / 4))
    with pytest.raises(ValueError, match="q"):
        vt.platform_mobility(TH, (0.0, float("nan")))
