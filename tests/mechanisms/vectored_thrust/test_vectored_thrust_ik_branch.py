"""Inverse kinematics of directions past the horizontal (issue 14, defect 5)."""

from __future__ import annotations

import numpy as np

import robomech.mechanisms.vectored_thrust as vt

TH = vt.VectoredThruster.paper()
# FK(IK(s)) vs s for unit directions: rounding of the closed form, amplified by 1/cos q2 near the
# parameters' bound |q2| = pi/2 (kept 0.05 rad away here: 1/cos q2 < 20).
ROUND_TRIP = 1e-10


def test_direction_beyond_90_degrees_tilt_round_trips():
    q0 = np.array([-np.pi / 4, np.pi / 4])  # on the edge of the paper's trajectory box: tilt > 90°
    s = vt.forward_kinematics(TH, q0).axis
    assert s[2] < 0
    ik = vt.inverse_kinematics(TH, s)
    assert ik.solved
    np.testing.assert_allclose(vt.forward_kinematics(TH, ik.q).axis, s, atol=ROUND_TRIP)
    np.testing.assert_allclose(ik.q, q0, atol=ROUND_TRIP)
    assert not ik.tilt_ok  # and it is outside the universal joint's ±45°


def test_round_trip_over_every_assembly_with_abs_q2_below_90_degrees():
    rng = np.random.default_rng(5)
    q = np.stack([rng.uniform(-np.pi, np.pi, 20000), rng.uniform(-1, 1, 20000) * (np.pi / 2 - 0.05)], -1)
    fk = vt.forward_kinematics(TH, q)
    s = fk.axis[fk.valid]
    ik = vt.inverse_kinematics(TH, s)
    assert (s[:, 2] < 0).sum() > 1000  # the test covers the branch past the horizontal
    assert ik.solved.all()
    assert np.all(np.abs(ik.q[:, 1]) < np.pi / 2)
    np.testing.assert_allclose(vt.forward_kinematics(TH, ik.q).axis, s, atol=ROUND_TRIP)


def test_solved_never_flags_a_wrong_direction():
    rng = np.random.default_rng(6)
    s = rng.normal(size=(20000, 3))
    s /= np.linalg.norm(s, axis=-1, keepdims=True)
    ik = vt.inverse_kinematics(TH, s)
    back = vt.forward_kinematics(TH, np.where(ik.solved[:, None], ik.q, 0.0))
    ok = ik.solved & back.valid & (np.cos(ik.q[:, 1]) > 0.05)
    assert ok.sum() > 10000
    np.testing.assert_allclose(back.axis[ok], s[ok], atol=ROUND_TRIP)
