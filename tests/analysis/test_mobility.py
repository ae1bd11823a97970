"""Screw-theory mobility on textbook mechanisms (issue 2 must-show) and its failure modes."""

import numpy as np
import pytest

from robomech.analysis import mobility
from robomech.spatial import screw_from_axis, virtual_power
from robomech.studies.demo import textbook_chains

CHAINS = textbook_chains()


def test_planar_four_bar_has_one_dof():
    m = mobility.analyze(CHAINS["planar four-bar (RR-RR)"])
    assert m.dof == 1
    assert (m.rotational_dof, m.translational_dof) == (1, 0)
    # over-constrained in space: the spatial Grübler–Kutzbach count is wrong, the modified one right
    assert m.gruebler_kutzbach == -2
    assert m.common_constraints == 3
    assert m.modified_gruebler_kutzbach == 1


def test_spherical_3rrr_has_three_rotations_about_the_centre():
    m = mobility.analyze(CHAINS["3-RRR spherical"])
    assert m.dof == 3 and m.rotational_dof == 3 and m.translational_dof == 0
    # every platform twist is a rotation about the common point (origin): v = 0
    assert np.abs(m.platform_twists[:, 3:]).max() < 1e-9
    assert m.gruebler_kutzbach == -3


def test_3upu_is_translational():
    m = mobility.analyze(CHAINS["3-UPU translational"])
    assert m.dof == 3 and m.translational_dof == 3 and m.rotational_dof == 0
    assert np.abs(m.platform_twists[:, :3]).max() < 1e-9
    # the constraints are three independent couples (pure moments)
    assert np.abs(m.constraint_wrenches[:, 3:]).max() < 1e-9


def test_3rps_is_one_translation_two_rotations():
    m = mobility.analyze(CHAINS["3-RPS"])
    assert m.dof == 3
    assert (m.rotational_dof, m.translational_dof) == (2, 1)
    assert m.gruebler_kutzbach == 3


def test_constraint_wrenches_do_no_work_on_any_chain_twist():
    for chains in CHAINS.values():
        m = mobility.analyze(chains)
        for chain, info in zip(chains, m.chains, strict=True):
            W = mobility.constraint_wrenches(chain)
            assert np.abs(np.einsum("ki,ji->kj", W, chain)).max() < 1e-9
            assert info.constraints.shape[0] == 6 - np.linalg.matrix_rank(chain)
        # and the platform twists are reciprocal to every constraint of the union
        assert (
            np.abs(virtual_power(m.constraint_wrenches[:, None, :], m.platform_twists[None, :, :])).max()
            < 1e-9
        )


def test_moving_one_axis_off_the_centre_removes_the_spherical_motion():
    chains = [c.copy() for c in CHAINS["3-RRR spherical"]]
    # shift the middle joint of one chain off the common point
    axis = chains[0][1, :3]
    chains[0][1] = screw_from_axis(axis, np.array([0.0, 0.3, 0.2]) + np.cross(axis, [1.0, 0, 0]) * 0.2)
    m = mobility.analyze(chains)
    assert m.dof < 3


def test_length_scale_does_not_change_the_result():
    chains = [c * np.array([1, 1, 1, 1000, 1000, 1000]) for c in CHAINS["3-RPS"]]  # same mechanism in mm
    m = mobility.analyze(chains, length_scale=1000.0)
    assert m.dof == 3 and m.rotational_dof == 2
    # the returned screws are in the caller's units: the wrenches still do no work on the mm twists
    W = m.constraint_wrenches / np.linalg.norm(m.constraint_wrenches, axis=1, keepdims=True)
    P = m.platform_twists / np.linalg.norm(m.platform_twists, axis=1, keepdims=True)
    assert np.abs(virtual_power(W[:, None, :], P[None, :, :])).max() < 1e-9
    m1 = mobility.analyze(CHAINS["3-RPS"])
    # same constraint system as in metres, with moments scaled by 1000 (N·mm)
    Wm = m1.constraint_wrenches * np.array([1000, 1000, 1000, 1, 1, 1])
    both = np.vstack([Wm, m.constraint_wrenches])
    assert np.linalg.matrix_rank(both / np.linalg.norm(both, axis=1, keepdims=True), tol=1e-8) == 3


def test_bad_input_names_the_argument():
    with pytest.raises(ValueError, match="chains"):
        mobility.analyze([])
    with pytest.raises(ValueError, match=r"chains\[1\]"):
        mobility.analyze([CHAINS["3-RPS"][0], np.zeros((2, 5))])
    with pytest.raises(ValueError, match=r"chains\[0\]"):
        mobility.analyze([np.full((2, 6), np.nan)])
    with pytest.raises(ValueError, match="length_scale"):
        mobility.analyze(CHAINS["3-RPS"], length_scale=0.0)
