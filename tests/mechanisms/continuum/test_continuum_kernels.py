"""The chunked one-segment kernels (issue 9): chunk boundaries, small-angle series inside a chunk,
half-angle trigonometry, strided inputs, and the one-segment IK fast path."""

from __future__ import annotations

import numpy as np

from robomech.mechanisms import continuum as C
from robomech.mechanisms.continuum._kinematics import CHUNK, _half_angle, _normalise
from robomech.spatial import SMALL_ANGLE, rot_y, rot_z, sincos

PAPER = C.ContinuumRobot.paper()
# Double-precision agreement of two closed forms of the same O(1) quantity.
EXACT_TOL = 1e-14
# numpy's sin/cos are correctly rounded to ~0.5 ulp; the half-angle forms add a few roundings (< 2 ulp of 1).
TRIG_TOL = 4.5e-16


def _awkward_psi(rng) -> np.ndarray:
    """More than two chunks: random poses with straight, series-range, boundary, negative and +-pi
    entries placed in the first and last chunk only (the middle chunk takes the closed-form path)."""
    n = 2 * CHUNK + 37
    psi = np.stack([rng.uniform(-3.0, 3.0, n), rng.uniform(-np.pi, np.pi, n)], -1)
    special = [0.0, -0.0, 1e-300, 1e-9, -3e-5, SMALL_ANGLE * (1 - 1e-12), SMALL_ANGLE, 1.5e-4, np.pi, -np.pi]
    psi[: len(special), 0] = special
    psi[-len(special) :, 0] = special
    psi[len(special) : 2 * len(special), 1] = [np.pi, -np.pi] * (len(special) // 2)
    return psi


def _reference_T(th: np.ndarray, be: np.ndarray, length: float) -> np.ndarray:
    """Paper 3, eqs. (1)-(2) from np.sin/np.cos, with the exact limits 1 - cos t ~ t^2/2, sin t ~ t."""
    T = np.zeros((*th.shape, 4, 4))
    T[..., :3, :3] = rot_z(be) @ rot_y(th) @ rot_z(-be)
    safe = np.where(th == 0.0, 1.0, th)
    fc = np.where(th == 0.0, 0.0, 2.0 * np.sin(th / 2) ** 2 / safe)  # (1 - cos t)/t without cancellation
    fs = np.where(th == 0.0, 1.0, np.sin(th) / safe)
    T[..., :3, 3] = length * np.stack([fc * np.cos(be), fc * np.sin(be), fs], -1)
    T[..., 3, 3] = 1.0
    return T


def test_half_angle_trigonometry_matches_numpy():
    x = np.concatenate([np.linspace(-7.0, 7.0, 20001), [0.0, 1e-300, 1e-8, np.pi, -np.pi, 3 * np.pi]])
    s, c, omc = _half_angle(x)
    assert np.abs(s - np.sin(x)).max() < TRIG_TOL
    assert np.abs(c - np.cos(x)).max() < TRIG_TOL
    # 1 - cos from 2 t^2/(1 + t^2): relative accuracy, also where 1 - np.cos(x) cancels
    ref = 2.0 * np.sin(x / 2) ** 2
    nz = ref > 0
    assert np.abs(omc[nz] / ref[nz] - 1.0).max() < 1e-15 and np.all(omc[~nz] == 0.0)
    s2, c2 = sincos(x)  # the shared kernel: the same bits
    assert np.array_equal(s2, s) and np.array_equal(c2, c)


def test_chunked_fk_and_jacobian_match_reference_across_chunks():
    rng = np.random.default_rng(11)
    psi = _awkward_psi(rng)
    T = C.forward_kinematics(PAPER, psi)[:, 0]
    assert np.all(np.isfinite(T))
    assert np.abs(T - _reference_T(psi[:, 0], psi[:, 1], PAPER.segment_length)).max() < EXACT_TOL
    # batched equals per-sample (the per-sample call runs the one-sample chunk, series or closed form)
    J = C.tip_jacobian(PAPER, psi)
    assert np.all(np.isfinite(J))
    for i in [*range(12), CHUNK - 1, CHUNK, CHUNK + 1, 2 * CHUNK + 30, psi.shape[0] - 1]:
        one = C.forward_kinematics(PAPER, psi[i])
        assert np.array_equal(one, C.forward_kinematics(PAPER, psi[i : i + 1])[0])
        assert np.abs(T[i] - one[0]).max() < 1e-12
        assert np.abs(J[i] - C.tip_jacobian(PAPER, psi[i])).max() < 1e-12


def test_jacobian_series_and_closed_form_agree_at_small_angle():
    th = np.array([SMALL_ANGLE * (1 - 1e-12), SMALL_ANGLE * (1 + 1e-12)])
    J = C.tip_jacobian(PAPER, np.stack([th, [0.4, 0.4]], -1))
    # the closed form (theta sin - (1 - cos))/theta^2 is ~eps/theta^2 ~ 1e-8 accurate, relative to O(l)
    assert np.abs(J[0] - J[1]).max() < 1e-9


def test_strided_and_multi_dimensional_inputs():
    rng = np.random.default_rng(12)
    psi = _awkward_psi(rng)
    big = np.zeros((psi.shape[0], 5))
    big[:, 1], big[:, 3] = psi[:, 0], psi[:, 1]
    view = big[:, 1::2][:, :2]  # strides (40, 16)
    for f in (C.forward_kinematics, C.tip_jacobian, C.tip_position):
        a, b = f(PAPER, psi), f(PAPER, view)
        assert np.array_equal(a, b)
        grid = f(PAPER, psi[: 6 * 1000].reshape(6, 1000, 2))
        assert np.array_equal(grid.reshape(a[: 6 * 1000].shape), a[: 6 * 1000])
        assert np.array_equal(f(PAPER, np.asfortranarray(psi)), a)


def test_one_segment_ik_across_chunks():
    rng = np.random.default_rng(13)
    psi = _awkward_psi(rng)
    psi[:, 0] = np.abs(psi[:, 0])
    p = C.tip_position(PAPER, psi)
    p[CHUNK + 5] = [0.0, 0.0, 0.05]  # unreachable: shorter than the straight segment, on its axis
    p[-20] = [0.2, 0.1, 0.0]  # unreachable: beyond the reach
    ik = C.inverse_kinematics(PAPER, p)
    bad = np.zeros(p.shape[0], bool)
    bad[[CHUNK + 5, p.shape[0] - 20]] = True
    assert np.array_equal(ik.reachable, ~bad)
    # the reported residual is that of the returned pose
    assert np.abs(np.linalg.norm(C.tip_position(PAPER, ik.psi) - p, axis=-1) - ik.residual).max() < 1e-15
    assert np.all(ik.psi[:, 0] >= 0) and np.all(np.abs(ik.psi[:, 1]) <= np.pi)
    assert np.all(ik.psi[ik.psi[:, 0] == 0.0, 1] == 0.0)  # straight: beta = 0 by convention
    for i in (0, 5, CHUNK - 1, CHUNK + 5, p.shape[0] - 20, p.shape[0] - 1):
        one = C.inverse_kinematics(PAPER, p[i])
        assert np.abs(one.psi - ik.psi[i]).max() < 1e-12 and abs(one.residual - ik.residual[i]) < 1e-12
        assert one.reachable == ik.reachable[i] and one.iterations == ik.iterations[i]


def test_normalise_in_place():
    theta = np.array([0.5, -0.5, 1.0, -2.0, 0.0])
    beta = np.array([3.0, 0.25, 4.0, -3.0, -np.pi])
    t0, b0 = theta.copy(), beta.copy()
    _normalise(theta, beta)
    assert np.all(theta == np.abs(t0))
    # same pose: (theta, beta) and (-theta, beta + pi) give the same bending vector
    u0 = np.stack([t0 * np.cos(b0), t0 * np.sin(b0)], -1)
    u1 = np.stack([theta * np.cos(beta), theta * np.sin(beta)], -1)
    assert np.abs(u0 - u1).max() < 1e-15
    assert np.all(np.abs(beta) <= np.pi)
    assert beta[0] == 3.0 and beta[4] == -np.pi  # entries already in range are untouched, bit for bit
