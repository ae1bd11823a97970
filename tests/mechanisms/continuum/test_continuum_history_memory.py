"""Stick-slip with memory that the pose feels: ``simulate_history(memory="elastic")`` (issue 16 item 3).

The pose is the disk-wise equilibrium under span tensions with memory: the cable material of every span
is the state, a hole sticks while its tension ratio lies inside the capstan cone and slides at a bound.
Checked against independently computed quantities: the full-slip disk-wise equilibrium (monotone
loading), the dead band from exp(+-mu eta) of a wrap angle computed here from the disk poses, the
sequential clip of ``stick_slip_tensions`` (fixed geometry, any EA), the friction cone at every hole.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from robomech.mechanisms import continuum as C
from robomech.mechanisms.continuum import _disks

PAPER = C.ContinuumRobot.paper()
EA = PAPER.cable_axial_stiffness
H = PAPER.segment_length / PAPER.disks_per_segment
# Same physics as disk_equilibrium(drive=, direction=) when every hole slides: both meet DISK_TOLERANCE
# (1e-10 N m on interval stiffnesses EI/h ~ 0.16 N m/rad: ~1e-9 rad); 1e-7 rad / 1e-8 m.  Tensions:
# both stop the column-shortening fixed point after COLUMN_PASSES = 8 passes of different maps (the
# base tension there, every piece's tension here): measured 3e-10 N apart at 51 deg on the paper robot
# (3e-6 N with the 0.8 mm core assumed before, whose column is softer); 1e-7 N.
FULL_SLIP_ANGLE_TOL = 1e-7
FULL_SLIP_TIP_TOL = 1e-8
FULL_SLIP_TENSION_TOL = 1e-7
# A pose that stands still is the previous Newton solution unchanged (residual already below tolerance).
STILL_TIP_TOL = 1e-12
# The hole residual (N times h) meets 1e-10 N m: tensions on the cone bounds to ~6e-9 N.
CONE_TOL = 1e-8
# Frictionless: loading and unloading meet the same equilibria; the loop area is rounding of ~12
# Newton solves, |theta| error ~1e-9 rad times a 1.5 mm drive.
FRICTIONLESS_AREA_TOL = 1e-11
# stick_slip_tensions (sequential clip) vs the elastic chain at fixed geometry: both exact up to the
# Newton tolerance (6e-9 N) and the rounding of EA (1 - m/g) at EA x 1e3 (~3e-10 N; at x 1e4 the
# rounding, 3e-9 N per hole, reaches the Newton tolerance itself).
RIGID_LIMIT_TOL = 1e-7


def _ramp(q_end, n):
    return np.linspace(0.0, 1.0, n + 1)[1:, None] * np.asarray(q_end)


def _pull(q1=1.5e-3, n=6):
    """Cable 1 pulled in, cables 2 and 3 paid out half as much (a planar bend at beta ~ 0)."""
    return _ramp([q1, -0.5 * q1, -0.5 * q1], n)


def _hole_chain(robot, bend):
    """Holes of every cable at the base plate and every disk, (..., 3 n, 1 + n N, 3), from the interval
    bends by chained segment transforms (independent of the library's wrap-angle code)."""
    J = bend.shape[-2]
    T = np.broadcast_to(np.eye(4), (*bend.shape[:-2], 4, 4)).copy()
    poses = [T]
    for j in range(J):
        T = T @ C.segment_transform(bend[..., j, 0], bend[..., j, 1], H)
        poses.append(T)
    P = np.stack(poses, -3)  # (..., 1 + J, 4, 4)
    r, s = robot.hole_radius, robot.hole_angles
    local = np.stack([r * np.cos(s), r * np.sin(s), np.zeros_like(s)], -1)  # (3n, 3)
    return np.einsum("...kab,cb->...cka", P[..., :3, :3], local) + P[..., None, :, :3, 3]


def _wraps(robot, bend):
    holes = _hole_chain(robot, bend)
    b = np.diff(holes, axis=-2)
    b = b / np.linalg.norm(b, axis=-1, keepdims=True)
    prev = np.concatenate([np.broadcast_to([0.0, 0.0, 1.0], b[..., :1, :].shape), b[..., :-1, :]], -2)
    # atan2 of |b x prev| and b . prev: exact at the tiny wraps of a tiny drive, where arccos of a dot
    # product near 1 loses every digit (a 3e-8 rad wrap read as 0).
    return np.arctan2(np.linalg.norm(np.cross(prev, b), axis=-1), np.sum(b * prev, -1))


def _check_cone(robot, h):
    """Every hole of every step: ratio inside the cone; a sliding hole on the bound its slip says."""
    a = robot.friction_array[:, None] * _wraps(robot, h.bend)
    prox = np.concatenate([h.tension[..., None], h.span_tension[..., :-1]], -1)
    dist = h.span_tension
    N = robot.disks_per_segment
    live = np.arange(robot.n_segments * N)[None, :] < (N * (robot.cable_segment + 1))[:, None]
    lo, hi = prox * np.exp(-a), prox * np.exp(a)
    assert np.all((dist >= lo - CONE_TOL)[..., live]) and np.all((dist <= hi + CONE_TOL)[..., live])
    assert np.all(h.state[..., ~live] == 0)
    slide_in, slide_out = (h.state == 1) & live, (h.state == -1) & live
    np.testing.assert_allclose(dist[slide_in], lo[slide_in], atol=CONE_TOL)
    np.testing.assert_allclose(dist[slide_out], hi[slide_out], atol=CONE_TOL)


def test_monotone_loading_is_the_full_slip_equilibrium():
    """(a) Every cable driven monotonically: every hole slides in its drive's direction and the pose
    is the full-slip disk-wise equilibrium disk_equilibrium(drive=q, direction=sign)."""
    q = np.stack([_pull(), _ramp(C.compensated_drive(PAPER, np.array([0.9, 1.0])).q_compensated, 6)], 1)
    h = C.simulate_history(PAPER, q)
    assert np.all(h.valid)
    d = np.sign(q[-1])
    np.testing.assert_array_equal(h.state[1:], np.broadcast_to(d[..., None], h.state[1:].shape))
    for i in range(q.shape[0]):
        eq = C.disk_equilibrium(PAPER, drive=q[i], direction=d)
        assert np.all(eq.converged)
        np.testing.assert_allclose(h.bend[i], eq.bend, atol=FULL_SLIP_ANGLE_TOL)
        np.testing.assert_allclose(h.tip[i], eq.tip, atol=FULL_SLIP_TIP_TOL)
        np.testing.assert_allclose(h.tension[i], eq.tension, atol=FULL_SLIP_TENSION_TOL)
        np.testing.assert_allclose(h.span_tension[i], eq.span_tension, atol=FULL_SLIP_TENSION_TOL)
    _check_cone(PAPER, h)


def test_reversal_dead_band_matches_the_base_hole_cone():
    """(b) After pulling, cable 1 is paid out in 1 um steps (cables 2, 3 held): nothing moves until its
    actuator tension has fallen from T_s0 e^(mu eta_0) to T_s0 e^(-mu eta_0) (T_s0 the first span's
    tension, eta_0 the base-plate wrap computed here from the disk poses); then the tip moves."""
    load = _pull()
    top = load[-1]
    back = top - np.arange(1, 31)[:, None] * np.array([1e-6, 0.0, 0.0])
    h = C.simulate_history(PAPER, np.concatenate([load, back]))
    assert np.all(h.valid)
    n = load.shape[0]
    mu_eta0 = PAPER.friction[0] * _wraps(PAPER, h.bend[n - 1])[0, 0]
    t_rev, t_s0 = h.tension[n - 1, 0], h.span_tension[n - 1, 0, 0]
    np.testing.assert_allclose(t_rev, t_s0 * np.exp(mu_eta0), rtol=1e-9)  # sliding in at the bound
    threshold = t_s0 * np.exp(-mu_eta0)
    moved = np.linalg.norm(h.tip[n:] - h.tip[n - 1], axis=-1)
    inside = h.tension[n:, 0] >= threshold
    assert np.all(moved[inside] < STILL_TIP_TOL)
    assert np.all(h.state[n:][inside] == 0)
    assert np.all(moved[~inside] > 1e-9)
    # the band in drive: only the free length stretches, dq = L_free dT / EA (~11 um at this pose)
    width_q = PAPER.free_length * (t_rev - threshold) / EA
    assert inside.sum() == int(np.floor(width_q / 1e-6 + 1e-9))
    assert inside.sum() >= 5 and not inside[-1]


def _cycle_area(robot, n=6):
    up = _pull(n=n)
    q = np.concatenate([np.zeros((1, 3)), up, up[-2::-1], np.zeros((1, 3))])
    h = C.simulate_history(robot, q)
    assert np.all(h.valid)
    return abs(np.trapezoid(h.psi[:, 0], q[:, 0])), h


def test_loop_area_grows_with_friction_and_vanishes_without():
    """(c) Load-unload cycle: theta(q_1) encloses a loop whose area is 0 without friction and grows
    with mu."""
    mu = np.array(PAPER.friction)
    areas = [_cycle_area(C.ContinuumRobot(friction=tuple(f * mu)))[0] for f in (0.0, 0.5, 1.0)]
    assert areas[0] < FRICTIONLESS_AREA_TOL
    assert areas[1] > 1e-7
    assert areas[2] > 1.3 * areas[1]


def test_held_cable_is_stuck():
    """(d) A cable whose drive stays still keeps its material at every hole while the others move
    (cable 1 pulled in further, cable 3 paid out): its flux is 0, its actuator tension unchanged, its
    span tensions inside the cone (they change elastically with the pose: the material is kept)."""
    load = _pull()
    more = load[-1] + np.arange(1, 4)[:, None] * np.array([2e-6, 0.0, -2e-6])
    h = C.simulate_history(PAPER, np.concatenate([load, more]))
    assert np.all(h.valid)
    n = load.shape[0]
    assert np.all(np.abs(h.slip[n:, 1]) <= C.STUCK_FLUX_TOL) and np.all(h.state[n:, 1] == 0)
    np.testing.assert_allclose(h.tension[n:, 1], h.tension[n - 1, 1], atol=1e-9)
    assert np.all(h.state[n:, 2] == -1)  # the paid-out cable slides out
    assert np.linalg.norm(h.tip[-1] - h.tip[n - 1]) > 1e-5  # measured 79 um
    _check_cone(PAPER, h)
    # the sliding approximation lets the held cable slide (its tension follows the pose)
    hs = C.simulate_history(PAPER, np.concatenate([load, more]), memory="slip")
    assert np.ptp(hs.tension[n - 1 :, 1]) > 1e-3


def test_path_dependence():
    """(e) Two histories ending at the same drive: different poses with friction, the same without."""
    q_end = _pull(n=1)[0] * 0.6
    a = _ramp(q_end, 3)
    b = np.concatenate([_ramp(q_end / 0.6, 4), q_end / 0.6 + _ramp(q_end - q_end / 0.6, 3)])
    for robot, differ in ((PAPER, True), (C.ContinuumRobot(friction=(0.0, 0.0, 0.0)), False)):
        ha, hb = C.simulate_history(robot, a), C.simulate_history(robot, b)
        assert np.all(ha.valid) and np.all(hb.valid)
        gap = np.abs(ha.psi[-1, 0] - hb.psi[-1, 0])
        assert (gap > 1e-3) if differ else (gap < 1e-8)


@pytest.mark.parametrize("stiffer", [1.0, 1e2, 1e3])
def test_fixed_geometry_is_the_rigid_cable_memory(stiffer):
    """(f) At a fixed pose the elastic chain equals stick_slip_tensions' sequential clip for every EA,
    hence in the rigid-cable limit EA -> inf: a stuck piece's tension depends on its material only
    (and the flux needed to change a tension goes to 0 like 1/EA).  A very stiff core makes the
    column shortening (a tension-dependent path length, ~EA u^2 ~ EA / EI) negligible."""
    robot = C.ContinuumRobot(core_modulus=6e19 * stiffer, cable_modulus=PAPER.cable_modulus * stiffer)
    ea = robot.cable_axial_stiffness
    psi = np.array([0.8, 0.3])
    N = robot.disks_per_segment
    k = _disks._uniform_k(robot, psi[0::2], psi[1::2])
    th, be = _disks._k_split(k)
    ell = np.where(_disks._span_active(robot), _disks._interval_spans(robot, th, be)[0], 0.0)
    g = _disks._pieces(robot, ell)
    m = g * (1.0 - 5.0 / ea)  # every piece at 5 N
    targets = [9.0, 12.0, 10.0, 7.5, 11.0, 4.0]  # actuator tensions of cable 0 (N)
    t_act, spans = [], []
    for t in targets:
        t0 = ea * (1.0 - m[0, 0] / g[0, 0])
        dq = np.array([robot.free_length * (t - t0) / ea, 0.0, 0.0])  # the free length's share
        st = _disks._memory_step(robot, k, m, dq, fixed_pose=True)
        assert bool(st.converged)
        m = st.material
        t_act.append(st.piece_tension[:, 0])
        spans.append(st.piece_tension[:, 1:])
    assert N == 5
    ref = C.stick_slip_tensions(
        robot, np.broadcast_to(psi, (len(targets), 2)), np.array(t_act), initial=np.full((3, 5), 5.0)
    )
    np.testing.assert_allclose(np.array(spans), ref.span_tension, atol=RIGID_LIMIT_TOL)
    assert np.ptp(np.array(spans)[:, 0, -1]) > 0.5  # the memory is exercised: the tip span moved


@settings(max_examples=4, deadline=None, database=None)
@given(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=5), st.floats(-np.pi, np.pi))
@example(steps=[0.0, 0.0, 1.2244e-06], beta=0.0)  # a 0.5 nm drive: wraps of ~1e-8 rad
def test_random_histories_stay_in_the_cone(steps, beta):
    """Random drive histories (cable 1 and 2 driven, steps up to 0.4 mm): every hole of every step
    inside the friction cone, sliding holes on the bound their slip says."""
    q = np.cumsum(np.array(steps)[:, None] * np.array([4e-4, -2e-4, 0.0]), 0)
    q = q @ np.array([[np.cos(beta), np.sin(beta), 0], [-np.sin(beta), np.cos(beta), 0], [0, 0, 1]])
    h = C.simulate_history(PAPER, q)
    ok = h.valid
    if np.any(ok):
        sub = type(h)(**{f: getattr(h, f)[ok] for f in h.__dataclass_fields__})
        _check_cone(PAPER, sub)


def test_slack_cables_flagged_per_sample_and_batch_independent():
    """(g) A sample whose cables cannot stay taut is flagged (taut, valid false), the others are
    unchanged by it."""
    good = _pull(n=3)
    bad = np.broadcast_to([-5e-3, -5e-3, -5e-3], good.shape)
    h = C.simulate_history(PAPER, np.stack([good, bad], 1))
    one = C.simulate_history(PAPER, good)
    assert np.all(h.valid[:, 0]) and not np.any(h.taut[:, 1]) and not np.any(h.valid[:, 1])
    np.testing.assert_allclose(h.psi[:, 0], one.psi, atol=1e-12)
    assert np.all(h.tension >= 0.0)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"times": np.array([0.0, 2.0, 1.0])}, "times"),
        ({"times": np.array([0.0, 1.0, 1.0])}, "times"),
        ({"memory": "rigid"}, "memory"),
        ({"model": "arc"}, "model"),
        ({"pulley": C.Pulley()}, "pulley"),
    ],
)
def test_bad_input(kwargs, name):
    """(g) Non-monotone times, an unknown memory, and the combinations the elastic model does not cover."""
    with pytest.raises(ValueError, match=name):
        C.simulate_history(PAPER, _pull(n=3), **kwargs)


@pytest.mark.slow
def test_two_segments():
    """Two segments (80 unknowns per step, cables ending at the middle disk): a monotone drive history
    converges with every hole in the cone.  Not every hole slides in its cable's drive direction here
    (segment coupling: a cable's spans in one segment may shorten while those in the other lengthen),
    so the full-slip equilibrium is not the reference for n >= 2."""
    two = C.ContinuumRobot(n_segments=2, friction=PAPER.friction * 2)
    q_end = C.compensated_drive(two, np.array([0.6, 0.3, 0.5, 2.0])).q_compensated
    h = C.simulate_history(two, _ramp(q_end, 2))
    assert np.all(h.valid)
    _check_cone(two, h)
    assert np.all(h.slip[..., :3, 5:] == 0.0)  # beyond the cables' termination: no cable, no flux
    # sanity only: the segment model's drive on the disk-wise robot with memory lands ~0.05 rad away
    np.testing.assert_allclose(h.psi[-1], [0.6, 0.3, 0.5, 2.0], atol=0.1)


def test_slip_mode_reports_the_implied_flux():
    """memory='slip': the cable crossing every hole follows from the sliding model's own span lengths and
    tensions; on a monotone pull it has the drive's sign at every hole (positive for the pulled cable)."""
    h = C.simulate_history(PAPER, _pull(), memory="slip")
    assert np.all(np.isfinite(h.slip)) and np.all(h.slip[:, 0] > 0.0) and np.all(h.slip[:, 1:] < 0.0)


def test_negative_friction_is_refused():
    with pytest.raises(ValueError, match="friction"):
        C.ContinuumRobot(friction=(0.26, -0.1, 0.28))
