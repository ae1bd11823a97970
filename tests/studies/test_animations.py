"""The animations of the paper reports show the models' motion ("pictures that move").

For each of the three GIFs: the file has one frame per trajectory sample at the stated rate, is
small, the drawn mechanism changes where the motion changes (and not where it does not), and the
site drawn in the first and last frame (and every frame between) is the trajectory's point as the
analytic model of the paper computes it.  The generic frame-by-frame assembly is checked against a
plain sequential solve, on a path where a batched solve from the reference jumps branch.
"""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from robomech import multibody as mb
from robomech.mechanisms import omnileg as ol
from robomech.mechanisms import spherical_leg as sl
from robomech.mechanisms import vectored_thrust as vt
from robomech.studies import StudyResult, write_study_report
from robomech.studies._animate import CONTINUATION_STEPS, animate, assemble_path, frame_ms
from robomech.studies.omnileg import gait_animation
from robomech.studies.spherical_leg import fig5_animation
from robomech.studies.vectored_thrust import table1_animation
from robomech.verify import vectored_thrust as vv

# The generic assembly closes the loops to CONVERGED_RTOL * L (1e-10 of a ~0.1-0.5 m mechanism) and
# the site follows from the same closed configuration: its distance to the analytic model's point is
# then ~1e-15 m; 1e-9 m leaves room for a loosely converged frame and still fails any wrong frame.
SITE_TOL = 1e-9
# A report GIF must stay small (issue: "<= ~1-2 MB"); the three are 0.1-0.2 MB at 320 x 320 px.
MAX_GIF_BYTES = 1_000_000
# Pixel rows at the bottom holding the time label (it changes every frame), excluded when comparing
# drawings (the label is 8 pt at 2 % of the height: ~11 px tall from row 314 up, of 320).
CLOCK_ROWS = 24
# Two drawings of visibly different poses differ in at least this many pixels (a 320 x 320 frame;
# one 2-px line moved across the picture changes ~500).
MIN_CHANGED_PIXELS = 300


def _frames(path):
    with Image.open(path) as im:
        assert im.format == "GIF"
        frames, durations = [], []
        for k in range(im.n_frames):
            im.seek(k)
            frames.append(np.asarray(im.convert("RGB"), dtype=np.int16)[:-CLOCK_ROWS])
            durations.append(im.info["duration"])
    return frames, durations


def _changed(a, b):
    return int(np.count_nonzero(np.any(a != b, axis=-1)))


def _check_gif(anim, fps):
    assert anim.figure.path.suffix == ".gif" and anim.figure.caption and anim.figure.alt
    assert anim.bytes == anim.figure.path.stat().st_size <= MAX_GIF_BYTES
    frames, durations = _frames(anim.figure.path)
    assert len(frames) == anim.q.shape[0] == anim.t.shape[0] == anim.site.shape[0]
    assert all(d == frame_ms(fps) == 10 * round(100 / fps) for d in durations)
    assert anim.converged.all()
    return frames


@pytest.fixture(scope="module")
def sl_anim(tmp_path_factory):
    leg = sl.SphericalLeg.paper()
    return leg, *fig5_animation(leg, tmp_path_factory.mktemp("sl"))


def test_spherical_leg_animation_is_the_fig5b_motion(sl_anim):
    from robomech.studies.spherical_leg import ANIMATION_DURATION, ANIMATION_FPS, ANIMATION_STEP

    leg, anim, check = sl_anim
    frames = _check_gif(anim, ANIMATION_FPS)
    assert len(frames) == round(ANIMATION_DURATION / ANIMATION_STEP) + 1
    q, _, _ = sl.fig5_motion("b", anim.t[[0, -1]])
    P = sl.platform_rotation(q[:, 0], q[:, 1])[..., :, 2] * leg.h  # eq. (1): P = R(α, β) (0, 0, h)
    np.testing.assert_allclose(anim.site[[0, -1]], P, atol=SITE_TOL)
    # every frame: the assembled leg strokes are the analytic leg lengths, and P is the model's
    assert check["max_leg_length_error_m"] < SITE_TOL and check["max_platform_point_error_m"] < SITE_TOL
    # t = 0 (β = π/3) and t = 5 s (β = π/6) are different poses, drawn differently ...
    k5, k15 = (int(np.argmin(np.abs(anim.t - s))) for s in (5.0, 15.0))
    assert _changed(frames[0], frames[k5]) > MIN_CHANGED_PIXELS
    # ... while t = 5 s and t = 15 s are the same pose (α = sin(π) = 0, β = π/6): the same drawing
    np.testing.assert_allclose(anim.q[k5], anim.q[k15], atol=1e-12)
    assert _changed(frames[k5], frames[k15]) == 0
    assert all(_changed(a, b) > 0 for a, b in zip(frames[k5 + 1 : k15], frames[k5 + 2 : k15], strict=False))


def test_omnileg_animation_is_the_gait(tmp_path):
    from robomech.studies.omnileg import ANIMATION_FPS, ANIMATION_FRAMES

    leg = ol.OmniLeg.paper()
    anim, check = gait_animation(leg, tmp_path)
    frames = _check_gif(anim, ANIMATION_FPS)
    assert len(frames) == ANIMATION_FRAMES
    gait = ol.gait_eq53(leg, anim.t)
    np.testing.assert_allclose(anim.site[[0, -1]], gait.foot.q[[0, -1]], atol=SITE_TOL)
    assert check["max_foot_error_m"] < SITE_TOL and check["ik_reachable"] == 1.0
    # the foot moves 0.1 m along the stride: the drawing changes between swing start and its middle
    mid = len(frames) // 4
    assert np.linalg.norm(anim.site[mid] - anim.site[0]) > 0.03
    assert _changed(frames[0], frames[mid]) > MIN_CHANGED_PIXELS


def test_thruster_animation_is_the_table1_trajectory(tmp_path):
    from robomech.studies.vectored_thrust import ANIMATION_FPS, ANIMATION_FRAMES

    th = vt.VectoredThruster.paper()
    anim, check = table1_animation(th, tmp_path)
    frames = _check_gif(anim, ANIMATION_FPS)
    assert len(frames) == ANIMATION_FRAMES
    q, _, _ = vv.table1_trajectory(anim.t[[0, -1]])
    np.testing.assert_allclose(anim.site[[0, -1]], vt.forward_kinematics(th, q).tip, atol=SITE_TOL)
    assert check["max_tip_error_m"] < SITE_TOL
    # the period starts and ends upright (q = 0): same drawing; a quarter period in, tilted 45°+
    np.testing.assert_allclose(anim.site[0], [0.0, 0.0, th.propeller_arm], atol=SITE_TOL)
    assert _changed(frames[0], frames[-1]) == 0
    assert _changed(frames[0], frames[len(frames) // 4]) > MIN_CHANGED_PIXELS


def test_animation_in_the_report_has_alt_text_and_caption(sl_anim, tmp_path):
    _, anim, _ = sl_anim
    res = StudyResult("x", "X", "src", figures=[anim.figure])
    paths = write_study_report(res, anim.figure.path.parent)
    md, html = paths["md"].read_text(), paths["html"].read_text()
    assert f"![{anim.figure.alt}]({anim.figure.path.name})" in md
    assert anim.figure.caption in md
    assert f'<img alt="{anim.figure.alt}" src="{anim.figure.path.name}"' in html


def test_assemble_path_follows_the_branch_where_a_batch_jumps():
    mech = mb.gallery.load("four_bar")
    q0 = mech.q0[mech.tree.act_qadr]
    qa = q0 + np.linspace(0.0, 6.3, 40)[:, None]  # a full turn of the crank
    seq = [mb.forward_kinematics(mech, qa[0], steps=10)]
    for row in qa[1:]:
        seq.append(mb.forward_kinematics(mech, row, seq[-1].q))
    q_seq = np.stack([r.q for r in seq])
    # a batch from the reference lands on the other assembly branch for part of the turn ...
    assert np.abs(mb.forward_kinematics(mech, qa, steps=CONTINUATION_STEPS).q - q_seq).max() > 1.0
    # ... assemble_path detects it and gives the frame-by-frame solution
    fk = assemble_path(mech, qa)
    assert fk.converged.all()
    np.testing.assert_allclose(fk.q, q_seq, atol=1e-9)


def test_animate_rejects_bad_input(tmp_path):
    mech = mb.gallery.load("four_bar")
    q = mb.forward_kinematics(mech, [[0.3], [0.4]]).q
    for kw, name in (
        ({"site": "no_such_site"}, "site"),
        ({"times": [0.0]}, "times"),
        ({"view": (1.0,)}, "view"),
        ({"view": (np.nan, 0.0)}, "view"),
        ({"fps": 0.0}, "fps"),
        ({"dpi": 5}, "dpi"),
        ({"invert_z": 1}, "invert_z"),
        ({"title": 3}, "title"),
    ):
        with pytest.raises(ValueError, match=name):
            animate(mech, q, tmp_path / "x.gif", **kw)
    with pytest.raises(ValueError, match="q_act"):
        assemble_path(mech, np.zeros((3, 2)))
    with pytest.raises(ValueError, match="mech"):
        assemble_path("four_bar", np.zeros((3, 1)))
