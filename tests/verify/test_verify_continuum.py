"""robomech's constant-curvature continuum model against the Cosserat-rod reference (issue 8, paper 3)."""

import dataclasses

import numpy as np
import pytest

from robomech.mechanisms.continuum import ContinuumRobot
from robomech.verify import run_verifications
from robomech.verify.continuum import (
    _ONE_SEGMENT_PSI,
    LIBRARY_CC_TOLERANCE,
    cc_error_table,
    library_cc_error,
    rod_for,
)


@pytest.mark.slow  # ~10 s: every continuum check, reference solves included
def test_continuum_verification_passes():
    report = run_verifications(["continuum"])
    assert report.passed, report.table()
    assert any("library CC statics" in c.quantity for c in report.checks)
    # 1 segment: chord frictionless / friction / elongation, disk-wise; 2 and 3 segments: chord, disk-wise
    assert sum("disk reference" in c.quantity for c in report.checks) == 9
    assert sum("segments," in c.quantity for c in report.checks) == 4
    assert len(report.checks) >= 13


def test_check_has_teeth_a_wrong_stiffness_in_the_library_model_fails():
    true = ContinuumRobot.paper()
    wrong = dataclasses.replace(true, core_modulus=true.core_modulus * 1.05)  # 5 % stiffer core
    pos, _, taut, conv = library_cc_error(wrong, _ONE_SEGMENT_PSI, rod=rod_for(true))
    assert np.all(taut & conv)
    assert np.max(pos / true.segment_length) > 1e3 * LIBRARY_CC_TOLERANCE.value


def test_check_has_teeth_wrong_hole_radius_fails():
    true = ContinuumRobot.paper()
    wrong = dataclasses.replace(true, hole_radius=true.hole_radius * 0.98)
    pos, *_ = library_cc_error(wrong, _ONE_SEGMENT_PSI, rod=rod_for(true))
    assert np.max(pos / true.segment_length) > 1e3 * LIBRARY_CC_TOLERANCE.value


def test_error_table_is_physical():
    t = cc_error_table()
    assert np.all(t.valid)
    assert t.position_error.shape == (len(t.bend_deg), len(t.load_labels))
    # no load: constant curvature is exact
    assert np.max(t.position_error[:, 0]) < 1e-9 * 0.09
    # the error grows with the load magnitude, for both lateral and axial loads, at every bend
    lateral, axial = t.position_error[:, 1:4], t.position_error[:, 4:7]
    assert np.all(np.diff(lateral, axis=1) > 0) and np.all(np.diff(axial, axis=1) > 0)
    # and is not small: at 0.2 N the constant-curvature tip is off by millimetres (2.3-3.9 mm)
    assert np.min(t.position_error[:, 3]) > 1e-3


def test_convergence_table_small_slice():
    """Two cases of the docs' convergence table (the full one: benchmarks/continuum_reference.py):
    two segments at 15 N and 120° (the old reference failed at 5 N), loaded and unloaded."""
    from robomech.verify.continuum import convergence_table

    t = convergence_table((2,), (15.0,), (120.0,))
    assert t.taut.all() and t.converged.all() and t.loaded_converged.all()
    assert np.nanmax(t.tip_error) < 1e-9 * 0.18  # unloaded: the CC arcs are exact
    assert "✓" in t.markdown()


def test_disk_agreement_table_small_slice():
    """Two cases of the docs' agreement table: a taut one compared, a slack one reported with the push
    its cable would need and solved clipped (convergence only; the disk-wise model with the same
    clipped tensions is still compared)."""
    from robomech.verify.continuum import disk_agreement_table

    t = disk_agreement_table((1,), (3.0,), (30.0, 90.0), arc=False)
    assert t.converged.all() and t.residual.max() < 1e-10 and (t.load_fraction == 1.0).all()
    assert t.taut[0, 0, 0] and not t.taut[0, 0, 1] and t.min_tension[0, 0, 1] < 0.0
    assert t.valid[0, 0, 0] and not t.valid[0, 0, 1] and np.isnan(t.chord_error[0, 0, 1])
    # the disk-wise model is far closer to the reference than the segment-wise chord model
    assert t.diskwise_error[0, 0, 0] < 0.05 * t.chord_error[0, 0, 0]
    assert np.isfinite(t.diskwise_error).all() and np.isfinite(t.elongation_error[0, 0, 0])
    assert np.isnan(t.arc_error).all()  # arc=False
    assert "slack" in t.markdown()
    # the row's stability limit: the Euler load of one 18 mm disk interval under 3 T (29.9 N per cable)
    euler = np.pi**2 * ContinuumRobot.paper().bending_stiffness / (3.0 * 0.018**2)
    assert abs(t.buckling_tension[0] / euler - 1.0) < 2e-3


def test_one_paper_robot():
    """Issue 16: TendonRod.paper() and ContinuumRobot.paper() are one parameter set."""
    from robomech.verify._cosserat import TendonRod

    a, b = TendonRod.paper(), rod_for(ContinuumRobot.paper())
    assert a.segment_lengths == b.segment_lengths and a.tendon_radius == b.tendon_radius
    assert a.tendon_angle == b.tendon_angle and a.tendon_segment == b.tendon_segment
    assert np.isclose(a.bending_stiffness, b.bending_stiffness, rtol=1e-14)
    assert np.isclose(a.torsional_stiffness, b.torsional_stiffness, rtol=1e-14)
