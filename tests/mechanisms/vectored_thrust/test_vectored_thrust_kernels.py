"""The optimised kernels (issue 9) against straightforward reference implementations of the same model."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from robomech.mechanisms import vectored_thrust as vt
from robomech.mechanisms.vectored_thrust import _kinematics as K

TH = vt.VectoredThruster.paper()
# The kernels reorder a few roundings (sincos instead of np.sin/np.cos, multiplications by reciprocals):
# results agree with the references to a few ulps of O(1) quantities.
ROUNDING_TOL = 1e-14


def _unit_rows(rng: np.random.Generator, n: int) -> np.ndarray:
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _angle(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.sum(u * v, -1))


def _point_arc(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Reference (the first version): distance from p to the minor arc a -> b, perpendicular if inside."""
    n = np.cross(a, b)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    inside = (np.sum(p * np.cross(n, a), -1) >= 0) & (np.sum(p * np.cross(b, n), -1) >= 0)
    perp = np.arcsin(np.minimum(np.abs(np.sum(p * n, -1)), 1.0))
    return np.where(inside, perp, np.minimum(_angle(p, a), _angle(p, b)))


def _reference_clearance(a1: np.ndarray, b1: np.ndarray, a2: np.ndarray, b2: np.ndarray) -> np.ndarray:
    n1 = np.cross(a1, b1)
    n2 = np.cross(a2, b2)
    n1 /= np.linalg.norm(n1, axis=-1, keepdims=True)
    n2 /= np.linalg.norm(n2, axis=-1, keepdims=True)
    m = np.cross(n1, n2)
    m /= np.linalg.norm(m, axis=-1, keepdims=True)

    def on(n: np.ndarray, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return np.sum(m * np.cross(n, a), -1), np.sum(m * np.cross(b, n), -1)

    (p1, q1), (p2, q2) = on(n1, a1, b1), on(n2, a2, b2)
    plus = (p1 >= 0) & (q1 >= 0) & (p2 >= 0) & (q2 >= 0)
    crosses = plus | ((p1 <= 0) & (q1 <= 0) & (p2 <= 0) & (q2 <= 0))
    ends = np.minimum(
        np.minimum(_point_arc(a1, a2, b2), _point_arc(b1, a2, b2)),
        np.minimum(_point_arc(a2, a1, b1), _point_arc(b2, a1, b1)),
    )
    return np.where(crosses, 0.0, ends)


def test_arc_clearance_matches_the_point_to_arc_reference_on_random_arcs() -> None:
    rng = np.random.default_rng(11)
    n = 20000
    a1, a2 = _unit_rows(rng, n), _unit_rows(rng, n)
    # minor arcs of random length up to ~0.9 pi, so every case (crossing, end to end, end to interior) occurs
    b1 = a1 + rng.uniform(0.05, 6.0, (n, 1)) * _unit_rows(rng, n)
    b2 = a2 + rng.uniform(0.05, 6.0, (n, 1)) * _unit_rows(rng, n)
    b1 /= np.linalg.norm(b1, axis=-1, keepdims=True)
    b2 /= np.linalg.norm(b2, axis=-1, keepdims=True)
    got, ref = vt.arc_clearance(a1, b1, a2, b2), _reference_clearance(a1, b1, a2, b2)
    assert np.array_equal(got == 0.0, ref == 0.0)
    assert 0.02 < np.mean(ref == 0.0) < 0.98  # both kinds of sample are exercised
    np.testing.assert_allclose(got, ref, rtol=0, atol=ROUNDING_TOL)


@pytest.mark.parametrize("arc", [0.3, math.pi / 4, 1.0, 1.45])
def test_link_clearance_matches_the_reference_over_the_input_box(arc: float) -> None:
    th = dataclasses.replace(TH, arc_angle=arc)
    # all inputs (q2 beyond +-pi/2 too, outside any parameter range), so that every branch is exercised
    q = vt.input_grid(th, 150, [[-math.pi, math.pi], [-math.pi, math.pi]]).reshape(-1, 2)
    ax = vt.joint_axes(th, q)
    ok = ax.valid
    ref = _reference_clearance(ax.s11[ok], ax.s12[ok], ax.s22[ok], ax.s13[ok])
    res = vt.link_clearance(th, q)
    got = res.clearance
    assert np.array_equal(res.valid, ok)  # NaN exactly where flagged
    # the kernel specialises the geometry (closed-form normals and side vectors): the same to rounding,
    # which arcsin amplifies by 1 / cos(clearance) where a perpendicular distance approaches pi/2
    tol = ROUNDING_TOL / np.maximum(np.cos(ref), 1e-6)
    assert np.all(np.abs(got[ok] - ref) <= tol)
    assert np.array_equal(got[ok] == 0.0, ref == 0.0)
    assert np.all(np.isnan(got[~ok]))


def test_kernels_match_numpy_sin_cos_references() -> None:
    rng = np.random.default_rng(12)
    q = rng.uniform([-math.pi, -1.5], [math.pi, 1.5], size=(5000, 2))
    c1, s1, c2, s2 = np.cos(q[:, 0]), np.sin(q[:, 0]), np.cos(q[:, 1]), np.sin(q[:, 1])
    ca, sa = math.cos(TH.arc_angle), math.sin(TH.arc_angle)
    x, y = sa * c1 * c2 - ca * s2, -sa * s1
    d = np.hypot(x, y)
    ok = d > 1e-3  # away from the singularity, where the kernels' conditioning is O(1)
    ct, st = x[ok] / d[ok], y[ok] / d[ok]
    axis = np.stack([s2[ok] * ct, st, c2[ok] * ct], -1)
    fk = vt.forward_kinematics(TH, q)
    np.testing.assert_allclose(fk.axis[ok], axis, rtol=0, atol=ROUNDING_TOL)
    np.testing.assert_allclose(fk.tilt[ok], np.arccos(np.clip(axis[:, 2], -1, 1)), rtol=0, atol=1e-7)
    np.testing.assert_allclose(vt.joint_axes(TH, q).s0[ok], axis, rtol=0, atol=ROUNDING_TOL)
    d2 = d[ok] ** 2
    th1 = sa * (ca * c1[ok] * s2[ok] - sa * c2[ok]) / d2
    th2 = -sa * s1[ok] * (sa * c1[ok] * s2[ok] + ca * c2[ok]) / d2
    J = np.stack([np.stack([-c2[ok] * th1, 0 * th1, s2[ok] * th1], -1),
                  np.stack([-c2[ok] * th2, 1 + 0 * th2, s2[ok] * th2], -1)], -1)  # fmt: skip
    jr = vt.jacobian(TH, q)
    scale = 1.0 + np.abs(J).max(axis=(-2, -1), keepdims=True)  # J grows like 1/d near the singularity
    np.testing.assert_allclose(jr.J[ok] / scale, J / scale, rtol=0, atol=1e3 * ROUNDING_TOL)
    np.testing.assert_allclose(jr.distance, d, rtol=0, atol=ROUNDING_TOL)


def test_ik_special_directions() -> None:
    # along +-Y (cos theta = 0: no q2 information, q2 = 0 chosen); -0.0 components; a zero and a tiny vector
    s = np.array([[0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [-0.0, 0.3, 1.0], [0.0, 0.0, 0.0], [1e-13, 0.0, 0.0]])
    ik = vt.inverse_kinematics(TH, s)
    assert ik.solved.tolist() == [True, True, True, False, False]
    assert np.all(np.isnan(ik.q[~ik.solved]))
    np.testing.assert_allclose(ik.q[:2], [[-math.pi / 2, 0.0], [math.pi / 2, 0.0]], atol=1e-15)
    fk = vt.forward_kinematics(TH, ik.q[:3])
    np.testing.assert_allclose(fk.axis, s[:3] / np.linalg.norm(s[:3], axis=-1, keepdims=True), atol=1e-15)
    # a large and a tiny (but valid) magnitude give the same inputs as the unit vector
    big = vt.inverse_kinematics(TH, s[2] * 1e100).q
    small = vt.inverse_kinematics(TH, s[2] * 1e-11).q
    np.testing.assert_allclose(big, ik.q[2], atol=1e-15)
    np.testing.assert_allclose(small, ik.q[2], atol=1e-15)


def test_fk_of_a_fresh_block_size_sample_count_equals_per_sample() -> None:
    rng = np.random.default_rng(13)
    q = rng.uniform([-1.0, -0.7], [1.0, 0.7], size=(K.CHUNK + 7, 2))
    fk = vt.forward_kinematics(TH, q)
    ik = vt.inverse_kinematics(TH, fk.axis)
    for i in (0, K.CHUNK - 1, K.CHUNK, K.CHUNK + 6):
        np.testing.assert_allclose(vt.forward_kinematics(TH, q[i]).axis, fk.axis[i], rtol=0, atol=1e-12)
        np.testing.assert_allclose(vt.inverse_kinematics(TH, fk.axis[i]).q, ik.q[i], rtol=0, atol=1e-12)
        J1 = vt.jacobian(TH, q[i]).J
        np.testing.assert_allclose(J1, vt.jacobian(TH, q[i : i + 1]).J[0], rtol=0, atol=1e-12)
