"""Paper 1's forward solution as printed (issue 15, item 5): each misprint attributed."""

from __future__ import annotations

import numpy as np
import pytest

from robomech.mechanisms import spherical_leg as sl
from robomech.mechanisms.spherical_leg._as_printed import forward_as_printed

LEG = sl.SphericalLeg.paper()
PI = np.pi
GIVEN = np.array([[-PI / 6] * 2, [-PI / 12] * 2, [0.0, 0.0], [PI / 12] * 2, [PI / 6] * 2])
# paper 1, Table 1: "calculated pose" α column
PAPER_ALPHA = np.array([-0.5109, -0.2510, 0.0, 0.2523, 0.5339])
# Ferrari in complex arithmetic on a quartic with O(1) coefficients: rounding ~1e-13 rad.
FERRARI_TOL = 1e-11


def _lengths(q):
    return sl.inverse_kinematics(LEG, q[..., 0], q[..., 1]).lengths


def test_with_the_three_misprints_corrected_the_pipeline_is_exact():
    rng = np.random.default_rng(0)
    q = rng.uniform(-1.0, 1.0, (2000, 2))
    q = q[LEG.h * np.cos(q[:, 1]) * np.cos(q[:, 0]) + LEG.r * np.sin(q[:, 0]) > 0.02]  # branch 0 side
    a, b, res, ok = forward_as_printed(LEG, _lengths(q), fix_square=True, fix_resolvent=True, fix_arctan=True)
    assert ok.all()
    # both assembly branches are exact roots; the print's rule (fit l3 best) cannot tell them apart
    other = sl.forward_kinematics(LEG, _lengths(q), branch=1).alpha
    assert np.all((np.abs(a - q[:, 0]) < FERRARI_TOL) | (np.abs(a - other) < FERRARI_TOL))
    assert np.mean(np.abs(a - q[:, 0]) < FERRARI_TOL) > 0.9
    np.testing.assert_allclose(b, q[:, 1], atol=1e-12)
    assert res.max() < 1e-12


def test_as_printed_misses_the_exact_pose_and_says_so_in_its_residual():
    fk = sl.forward_kinematics(LEG, _lengths(GIVEN), paper_as_printed=True)
    assert fk.valid.all()
    np.testing.assert_allclose(fk.beta, GIVEN[:, 1], atol=1e-12)  # eq. (6) is right
    err = np.abs(fk.alpha - GIVEN[:, 0])
    assert err.max() > 0.1 and fk.residual.max() > 5e-3  # metres: the printed α does not assemble
    exact = sl.forward_kinematics(LEG, _lengths(GIVEN))
    assert exact.residual.max() < 1e-15
    # the paper's own Table 1 values come from neither the printed nor the exact pipeline
    assert np.abs(fk.alpha - PAPER_ALPHA).max() > 0.1
    assert np.abs(exact.alpha - PAPER_ALPHA).max() > 0.01


@pytest.mark.parametrize("fix", ["fix_square", "fix_resolvent", "fix_arctan"])
def test_each_misprint_alone_leaves_an_error(fix):
    a, _, _, _ = forward_as_printed(LEG, _lengths(GIVEN), **{fix: True})
    assert np.nanmax(np.abs(a - GIVEN[:, 0])) > 1e-3


def test_bad_input():
    with pytest.raises(ValueError, match="paper_as_printed"):
        sl.forward_kinematics(LEG, _lengths(GIVEN), paper_as_printed="yes")
    fk = sl.forward_kinematics(LEG, [[np.nan, 0.1, 0.1], [0.1, 0.1, 0.1]], paper_as_printed=True)
    assert not fk.valid[0] and np.isnan(fk.alpha[0])
