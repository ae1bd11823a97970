"""mb.animate writes the motion with matplotlib's writers; notebook display of mechanisms and results.

The GIF is read back with Pillow: one frame per configuration, the delay of `frame_ms`, and the
drawing changes between frames exactly where the configuration changes.  An .mp4 is written where
ffmpeg exists and is a clear ValueError where it does not.
"""

from __future__ import annotations

import dataclasses
import shutil

import numpy as np
import pytest
from PIL import Image

from robomech import multibody as mb
from robomech.multibody._animate import frame_ms

MECH = mb.gallery.load("four_bar")
# Crank angles (rad) of a short motion, with a repeated pose (frames 2 and 3 are the same).
CRANK = np.array([0.2, 0.5, 0.8, 0.8, 1.1])
# Pixel rows at the bottom holding the frame label (changes every frame), excluded when comparing.
LABEL_ROWS = 16
# Two drawings of different poses differ in many pixels (one 2-px line moved: hundreds).
MIN_CHANGED_PIXELS = 100


def _frames(path):
    im = Image.open(path)
    out = []
    for k in range(im.n_frames):
        im.seek(k)
        out.append((np.asarray(im.convert("RGB")), im.info.get("duration")))
    return out


def test_gif_has_one_frame_per_configuration_and_moves_with_it(tmp_path):
    q = mb.forward_kinematics(MECH, CRANK[:, None]).q
    path = mb.animate(MECH, q, tmp_path / "m.gif", fps=10, dpi=40, site="coupler_point")
    frames = _frames(path)
    assert len(frames) == len(CRANK)
    assert all(d == frame_ms(10) for _, d in frames)
    body = [f[:-LABEL_ROWS] for f, _ in frames]
    changed = [int(np.sum(np.any(body[k] != body[k + 1], axis=-1))) for k in range(len(body) - 1)]
    assert changed[2] == 0  # frames 3 and 4 show the same pose
    assert min(changed[:2] + changed[3:]) > MIN_CHANGED_PIXELS


def test_mp4_needs_ffmpeg_and_other_suffixes_are_refused(tmp_path):
    q = mb.forward_kinematics(MECH, CRANK[:, None]).q
    if shutil.which("ffmpeg") is None:
        with pytest.raises(ValueError, match="ffmpeg"):
            mb.animate(MECH, q, tmp_path / "m.mp4")
    else:
        assert mb.animate(MECH, q, tmp_path / "m.mp4", dpi=40).stat().st_size > 0
    with pytest.raises(ValueError, match="path"):
        mb.animate(MECH, q, tmp_path / "m.png")


def test_results_print_compactly_and_stay_dataclasses():
    qa = np.linspace(-3, 3, 200)[:, None]
    fk = mb.forward_kinematics(MECH, qa)
    text = repr(fk)
    assert text.startswith("FKResult(q=float64(200, 3)")
    assert f"converged={int(fk.converged.sum())}/200 True" in text
    assert len(text) < 300 and "\n" not in text
    assert dataclasses.replace(fk, iterations=fk.iterations).q is fk.q  # still a dataclass
    assert [f.name for f in dataclasses.fields(fk)] == ["q", "residual", "converged", "iterations"]
    s = mb.singularities(MECH, fk.q[fk.converged][:5], "coupler_point")
    assert repr(s).startswith("SingularityResult(sigma_I=float64(5,)")


def test_a_mechanism_shows_a_small_picture_without_touching_pyplot():
    import matplotlib.pyplot as plt

    before = plt.get_fignums()
    png = MECH._repr_png_()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    w, h = int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")
    assert (w, h) == (240, 240)  # 3 in at 80 dpi
    assert plt.get_fignums() == before
