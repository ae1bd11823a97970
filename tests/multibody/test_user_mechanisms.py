"""Four mechanisms outside the gallery, built as a new user would (``user_mechanisms.py``): assembly,
mobility, forward kinematics against closed forms, assembly-mode flags, singularities (point outputs
included), inverse/forward dynamics, and ``verify`` against MuJoCo of the exported MJCF."""

from __future__ import annotations

import numpy as np
import pytest

from robomech import multibody as mb

from .user_mechanisms import agile_eye, five_bar_along_x, sarrus, tsai_3upu, tsai_points

FIVE_BAR = five_bar_along_x()
EYE = agile_eye()
SARRUS = sarrus()
TSAI = tsai_3upu()
ALL = {"five_bar": FIVE_BAR, "agile_eye": EYE, "sarrus": SARRUS, "tsai_3upu": TSAI}
# Mobility: planar five-bar 2, spherical wrist 3, Sarrus 1 (Grübler counts 0: overconstrained),
# Tsai 3-UPU 3 translations.
DOF = {"five_bar": 2, "agile_eye": 3, "sarrus": 1, "tsai_3upu": 3}
# Solver tolerance of an assembled configuration and of closed-form comparisons (m, rad): FK
# converges to CONVERGED_RTOL * L ~ 1e-10; the closed forms are exact to round-off.
CLOSED_FORM_TOL = 1e-8
# A regular sample's singular values are O(1e-3..1) m here; a singular one is round-off.
SINGULAR_SIGMA = 1e-7


def _joint_index(mech: mb.Mechanism, name: str) -> int:
    names = [j.name for b in mech.bodies for j in b.joints]
    return names.index(name)


def _q_act(mech: mb.Mechanism, q: np.ndarray) -> np.ndarray:
    return q[..., [_joint_index(mech, a) for a in mech.actuated]]


def _wrap(a):
    return np.angle(np.exp(1j * np.asarray(a)))


@pytest.mark.parametrize("name", sorted(ALL))
def test_assembled_at_the_reference_with_the_expected_mobility(name):
    mech = ALL[name]
    assert np.max(np.abs(mb.constraint_residual(mech, mech.q0))) < CLOSED_FORM_TOL
    assert mb.mobility(mech).dof == DOF[name]


def test_a_five_bar_described_open_is_closed_at_build():
    """All links along x at the reference leave the tips B apart; the Builder assembles the loop."""
    q = FIVE_BAR.q0
    assert np.max(np.abs(q)) > 0.1  # moved away from the described (open) reference
    tip_left = mb.site_pose(FIVE_BAR, q, "tip")[:3, 3]
    # the right leg's tip, by planar forward kinematics of its two links
    a, e = q[_joint_index(FIVE_BAR, "base_right")], q[_joint_index(FIVE_BAR, "elbow_right")]
    right = np.array([0.05, 0, 0]) + 0.2 * np.array([np.cos(a), np.sin(a), 0])
    right += 0.25 * np.array([np.cos(a + e), np.sin(a + e), 0])
    np.testing.assert_allclose(tip_left, right, atol=CLOSED_FORM_TOL)


def _five_bar_tip(q_act: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The tip by planar forward kinematics of the left leg (independent of the engine's tree)."""
    a, e = q[..., _joint_index(FIVE_BAR, "base_left")], q[..., _joint_index(FIVE_BAR, "elbow_left")]
    x = -0.05 + 0.2 * np.cos(a) + 0.25 * np.cos(a + e)
    y = 0.2 * np.sin(a) + 0.25 * np.sin(a + e)
    return np.stack([x, y], axis=-1)


def test_five_bar_one_step_mode_switches_are_flagged():
    """Solved in ONE step from the reference, large crank moves can land on the other assembly mode
    (tip mirrored across the line of the elbows); continuation in 50 stages is the reference."""
    g = np.linspace(-0.8, 0.8, 17)
    qa = _q_act(FIVE_BAR, FIVE_BAR.q0) + np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    one = mb.forward_kinematics(FIVE_BAR, qa)
    cont = mb.forward_kinematics(FIVE_BAR, qa, steps=50)
    assert cont.converged.all() and not cont.mode_changed.any()
    other = np.max(np.abs(_wrap(one.q - cont.q)), axis=-1) > 1e-3
    assert other.sum() > 0  # the test has switched samples to find
    np.testing.assert_array_equal(one.mode_changed, other)
    assert not one.converged[other].any()
    # both loops close (the other mode is a genuine assembly), so the residual alone cannot tell
    assert np.all(one.residual[other] <= mb.CONVERGED_RTOL * FIVE_BAR.tree.length)
    np.testing.assert_allclose(_q_act(FIVE_BAR, cont.q), qa, atol=CLOSED_FORM_TOL)


def _stretched_left(phi: float) -> np.ndarray:
    """A five-bar configuration with the left leg stretched (elbow 0): a serial (type I) singularity
    of the tip point; the right leg reaches the tip by the law of cosines."""
    tip = np.array([-0.05, 0.0]) + 0.45 * np.array([np.cos(phi), np.sin(phi)])
    d = tip - (0.05, 0.0)
    r = np.hypot(*d)
    e = np.arccos((r**2 - 0.2**2 - 0.25**2) / (2 * 0.2 * 0.25))  # right elbow (one of two)
    a = np.arctan2(d[1], d[0]) - np.arctan2(0.25 * np.sin(e), 0.2 + 0.25 * np.cos(e))
    q = np.zeros(4)
    q[[_joint_index(FIVE_BAR, n) for n in ("base_left", "elbow_left", "base_right", "elbow_right")]] = (
        phi,
        0.0,
        a,
        e,
    )
    return q


def test_five_bar_point_output_singularities():
    q_sing = _stretched_left(np.deg2rad(80.0))
    assert np.max(np.abs(mb.constraint_residual(FIVE_BAR, q_sing))) < CLOSED_FORM_TOL
    s = mb.singularities(FIVE_BAR, np.stack([FIVE_BAR.q0, q_sing]), "tip", output="position")
    assert s.type_I.tolist() == [False, True]  # control: the reference is regular
    assert s.sigma_I[1] < SINGULAR_SIGMA < s.sigma_I[0]
    assert not s.type_II.any()


def test_agile_eye_point_output_has_rank_two_and_a_singular_wrist():
    """The pointer moves on a sphere: its velocity has generic rank 2, which is no type I drop; around
    the orthogonal reference the wrist is far from type II."""
    rng = np.random.default_rng(3)
    qa = _q_act(EYE, EYE.q0) + rng.uniform(-0.3, 0.3, (8, 3))
    fk = mb.forward_kinematics(EYE, qa, steps=5)
    assert fk.converged.all()
    s = mb.singularities(EYE, fk.q, "pointer", output="position")
    assert not s.type_I.any() and not s.type_II.any() and not s.constraint.any()
    # the orthogonal reference: the passive block's smallest singular value is O(L)
    inf = mb.influence(EYE, EYE.q0, second_order=False)
    assert inf.sigma_min > 0.1 * EYE.tree.length


def test_sarrus_top_plate_height_is_the_closed_form():
    """Leg a's lower link leaves the base at elevation beta0 - theta (a hinge about +y lowers it):
    the plate is at z = 2 link sin(beta0 - theta) and stays above the base centre."""
    theta = np.linspace(-0.4, 0.4, 9)[:, None]
    fk = mb.forward_kinematics(SARRUS, _q_act(SARRUS, SARRUS.q0) + theta, steps=5)
    assert fk.converged.all()
    T = mb.site_pose(SARRUS, fk.q, "centre")
    beta0 = np.arctan2(0.06, np.sqrt(0.1**2 - 0.06**2))
    np.testing.assert_allclose(T[:, 2, 3], 2 * 0.1 * np.sin(beta0 - theta[:, 0]), atol=CLOSED_FORM_TOL)
    np.testing.assert_allclose(T[:, :2, 3], 0.0, atol=CLOSED_FORM_TOL)
    np.testing.assert_allclose(T[:, :3, :3], np.broadcast_to(np.eye(3), (9, 3, 3)), atol=CLOSED_FORM_TOL)


# --- Tsai 3-UPU -------------------------------------------------------------------------------------
R_BASE, R_PLATFORM, H = 0.3, 0.1, 0.5
# Each leg's constraint is a couple c_i = t_i x s_i (perpendicular to both U axes); with the platform
# translated by p it points along a_i e_ri + h e_z, a_i = p . e_ri + (R_PLATFORM - R_BASE).  The
# three couples are dependent (a constraint singularity) when the points a_i e_ri are collinear: on
# the x axis at x = +-2 (R_BASE - R_PLATFORM), and by the 3-fold symmetry at radius 2 |R_BASE -
# R_PLATFORM| in every direction tried below: the constraint-singularity cylinder.
CYLINDER = 2 * abs(R_BASE - R_PLATFORM)
# On the cylinder the rotation is fixed only to second order: a closure residual eps leaves a rotation
# of ~sqrt(eps / L) (1e-7 at the solver's 1e-10 m).
SINGULAR_ROT_TOL = 1e-5


def _tsai_inputs(p: np.ndarray) -> np.ndarray:
    """Slide extensions (from the reference) that translate the platform by p (n, 3): closed form."""
    B, P, _ = tsai_points(R_BASE, R_PLATFORM, H)
    return np.linalg.norm(P[None] + p[:, None] - B[None], axis=-1) - np.linalg.norm(P - B, axis=-1)


def _tsai_pose_error(q: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    T = mb.site_pose(TSAI, q, "centre")
    rot = np.linalg.norm(T[..., :3, :3] - np.eye(3), axis=(-2, -1))
    return rot, np.linalg.norm(T[..., :3, 3] - (p + np.array([0.0, 0.0, H])), axis=-1)


def test_tsai_constraint_singularity_cylinder():
    ang = np.deg2rad([0.0, 60.0, 180.0, 300.0])
    for radius, singular in ((0.75 * CYLINDER, False), (CYLINDER, True), (1.25 * CYLINDER, False)):
        p = radius * np.stack([np.cos(ang), np.sin(ang), 0 * ang], axis=-1)
        # straight from the reference, in 30 stages (a guess that crosses nothing before the cylinder)
        fk = mb.forward_kinematics(TSAI, _tsai_inputs(p), steps=30)
        closed = fk.residual <= mb.CONVERGED_RTOL * TSAI.tree.length
        rot, pos = _tsai_pose_error(fk.q, p)
        tol = SINGULAR_ROT_TOL if singular else CLOSED_FORM_TOL
        assert closed.all() and np.all(rot < tol) and np.all(pos < tol), (radius, rot, pos)
        s = mb.singularities(TSAI, fk.q, "centre", output="position")
        if singular:
            assert np.all(s.sigma_C < SINGULAR_SIGMA), s.sigma_C
        else:
            assert np.all(s.sigma_C > 1e-3) and not s.constraint.any(), s.sigma_C


def test_tsai_path_through_the_cylinder_is_never_a_converged_rotation():
    """Across the cylinder the legs also admit rotating assemblies; a sample FK calls converged is on
    the translational mode (R = I, p the commanded translation), a crossing is flagged."""
    x = np.linspace(0.0, 1.5 * CYLINDER, 31)
    p = np.stack([x, np.full_like(x, 0.02), 0 * x], axis=-1)
    qa = _tsai_inputs(p)
    for steps in (1, 20):
        fk = mb.forward_kinematics(TSAI, qa, steps=steps)
        rot, pos = _tsai_pose_error(fk.q, p)
        assert np.all(rot[fk.converged] < CLOSED_FORM_TOL) and np.all(pos[fk.converged] < CLOSED_FORM_TOL)
        assert fk.converged[x < 0.9 * CYLINDER].all()
        np.testing.assert_array_equal(fk.mode_changed, ~fk.converged)
        assert fk.mode_changed[x > 1.1 * CYLINDER].all()  # crossed: flagged
    # control: the same samples solved from a guess beyond the cylinder are converged, translational
    beyond = x > 1.1 * CYLINDER
    guess = np.broadcast_to(fk.q[-1], (int(beyond.sum()), TSAI.nq))
    fk2 = mb.forward_kinematics(TSAI, qa[beyond], guess)
    rot, pos = _tsai_pose_error(fk2.q, p[beyond])
    assert fk2.converged.all() and np.all(rot < CLOSED_FORM_TOL) and np.all(pos < CLOSED_FORM_TOL)


# --- dynamics and verification ------------------------------------------------------------------------
# Inverse then forward dynamics recover the accelerations to the mass matrix's conditioning (~1e-13).
ROUND_TRIP_TOL = 1e-10


@pytest.mark.parametrize("name", sorted(ALL))
def test_inverse_then_forward_dynamics_recover_the_accelerations(name):
    mech = ALL[name]
    rng = np.random.default_rng(5)
    na = len(mech.actuated)
    fk = mb.forward_kinematics(mech, _q_act(mech, mech.q0) + rng.uniform(-0.05, 0.05, (4, na)))
    assert fk.converged.all()
    qd, qdd = rng.normal(size=(4, na)), rng.normal(size=(4, na))
    inv = mb.inverse_dynamics(mech, fk.q, qd, qdd)
    fwd = mb.forward_dynamics(mech, fk.q, qd, inv.tau)
    assert inv.valid.all() and fwd.valid.all()
    np.testing.assert_allclose(fwd.qdd_act, qdd, atol=ROUND_TRIP_TOL)


def test_an_unassembled_description_exports_its_assembled_reference_as_a_keyframe():
    """The five-bar typed open: MuJoCo's qpos0 of the exported file leaves the closure open (as typed),
    its keyframe ``assembled`` starts MuJoCo closed; a description closed at qpos0 gets no keyframe."""
    mujoco = pytest.importorskip("mujoco")
    m = mujoco.MjModel.from_xml_string(mb.to_mjcf(FIVE_BAR))
    d = mujoco.MjData(m)

    def closure_error() -> float:
        mujoco.mj_forward(m, d)
        return float(np.max(np.abs(d.efc_pos[d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY])))

    assert closure_error() > 1e3 * CLOSED_FORM_TOL  # control: typed open at qpos0
    mujoco.mj_resetDataKeyframe(m, d, mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "assembled"))
    np.testing.assert_array_equal(d.qpos, FIVE_BAR.q0)
    assert closure_error() < CLOSED_FORM_TOL
    assert mujoco.MjModel.from_xml_string(mb.to_mjcf(mb.gallery.load("four_bar"))).nkey == 0


@pytest.mark.slow
@pytest.mark.parametrize("name", ["five_bar", "agile_eye", "tsai_3upu"])
def test_verify_of_the_exported_mjcf_passes(name, tmp_path):
    """``robomech verify FILE`` of ``to_mjcf``'s file: every check against MuJoCo passes (5-8 s each)."""
    from robomech.cli import main

    path = tmp_path / f"{name}.xml"
    path.write_text(mb.to_mjcf(ALL[name]))
    assert main(["verify", str(path), "--quiet"]) == 0


# The Sarrus fall's actuated coordinate against MuJoCo's (rad): the engine's soft redundant closure row
# and its step grid leave 2.5e-4 rad after 0.3 s (measured, on either branch of the passive leg).
SARRUS_FALL_TOL = 1e-3


@pytest.mark.slow
def test_sarrus_verify_explains_a_failing_fall_and_takes_duration_and_start(tmp_path, capsys):
    """The Sarrus linkage's 0.3 s passive fall passes close to the folded (type II) pose, where the
    second leg can fold either way and rounding picks the branch: the same fall with other output
    times, or from the file's reference instead of the description's, keeps MuJoCo's branch (every
    coordinate within 2.5e-4 rad, energy drift 9e-11) or flips that leg by 2.2 rad (energy drift 1.8e-7
    to 3.6e-7 against 1e-7).  On either branch the actuated coordinate follows MuJoCo's, and a failing
    drift says why: the constraint singularity it passed.  ``robomech verify`` stops the fall at that
    crossing (t = 0.1414 s from the test trajectory's start) and passes on the interval before it,
    naming it.  A 0.1 s fall passes, and so does a 0.05 s
    fall from another start (``--q0``): compared on the engine's step grid, the one redundant closure
    row (which MuJoCo solves as a soft constraint) leaves the motion within 1e-8 of the rigid model's.
    (~40 s: three verifications.)"""
    from robomech.cli import main
    from robomech.verify import _mujoco
    from robomech.verify._generic import TOL_DRIFT, _sample_times, _why, engine_model

    path = tmp_path / "sarrus.xml"
    path.write_text(mb.to_mjcf(SARRUS))
    rc = main(["verify", str(path)])
    out = capsys.readouterr().out
    assert "forward simulation vs engine (0.3 s, passive)" in out
    assert rc == 0 and "singularity (its closure's Jacobian loses rank) at t = 0.1414 s" in out, out
    t = _sample_times(0.3)
    sim = mb.simulate(SARRUS, SARRUS.q0, t=t, qd0=np.zeros(SARRUS.nv))
    eng = _mujoco.Engine(engine_model(SARRUS, simulation=True))
    eng.set_state(SARRUS.q0, np.zeros(SARRUS.nv))
    Q = np.array(eng.simulate(t, lambda d: d.qpos.copy()))
    act = SARRUS.tree.act_qadr
    assert np.max(np.abs(sim.q[:, act] - Q[:, act])) <= SARRUS_FALL_TOL
    if not sim.energy_drift_rel <= TOL_DRIFT.value:  # the leg flipped at the fold: the singularity is named
        why = _why(SARRUS, t, sim.q, np.zeros(len(t), bool))
        assert "constraint singularity" in why, why
    assert main(["verify", str(path), "--quiet", "--duration", "0.1"]) == 0
    q0 = mb.forward_kinematics(SARRUS, _q_act(SARRUS, SARRUS.q0) - 0.05).q
    rc = main(["verify", str(path), "--duration", "0.05", "--q0", *map(str, q0)])
    out = capsys.readouterr().out
    assert "forward simulation vs engine (0.05 s, passive)" in out
    assert rc == 0, out  # 7.7e-9 against 1e-3


# Same samples, same result at any batch size (the compiled kernels take over from numpy at larger
# batches): the Tsai 3-UPU once differed by 5.7e-11 between batches of 300 and 150.
BATCH_RTOL = 1e-12


@pytest.mark.parametrize("n", [1, 150, 255, 256, 257, 300, 1000])
def test_tsai_results_do_not_depend_on_the_batch_size(n):
    rng = np.random.default_rng(0)
    q = mb.forward_kinematics(TSAI, _q_act(TSAI, TSAI.q0) + rng.uniform(-0.05, 0.05, (7, 3)), steps=3).q
    qq = q[np.arange(n) % 7]
    k = min(n, 7)
    for f in (
        lambda x: mb.site_jacobian(TSAI, x, "centre"),
        lambda x: mb.inverse_dynamics(TSAI, x, np.ones(3), np.ones(3)).tau,
        lambda x: mb.singularities(TSAI, x, "centre").sigma_II,
    ):
        one = np.stack([f(q[i]) for i in range(k)])
        np.testing.assert_allclose(f(qq)[:k], one, rtol=BATCH_RTOL, atol=BATCH_RTOL)
