"""``robomech export`` (paper, gallery and file targets load in MuJoCo and read back) and the GIF writer."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from PIL import Image

from robomech import multibody as mb
from robomech.cli import main
from robomech.studies._animate import animate


@pytest.mark.parametrize("target", ["spherical-leg", "omnileg", "vectored-thrust", "delta"])
def test_export_loads_in_mujoco_and_reads_back(target, tmp_path):
    out = tmp_path / "m.xml"
    assert main(["export", target, "--mjcf", str(out)]) == 0
    m = mujoco.MjModel.from_xml_path(str(out))
    mech = mb.from_mjcf(out)
    assert m.nq == mech.nq and m.ngeom > 0  # visible geometry
    masses = [b.inertial.mass for b in mech.bodies if b.inertial is not None]
    assert sum(masses) > 0
    # a user's file goes through the same description
    again = tmp_path / "again.xml"
    assert main(["export", str(out), "--mjcf", str(again)]) == 0
    assert mb.from_mjcf(again) == mech


def test_export_unknown_target_fails_cleanly():
    assert main(["export", "no_such_mechanism"]) == 2


def test_animation_of_a_simulated_motion(tmp_path):
    mech = mb.gallery.load("four_bar")
    fk = mb.forward_kinematics(mech, [[0.3]])
    sim = mb.simulate(mech, fk.q, [[2.0]], np.linspace(0, 0.2, 4))
    path = animate(mech, sim.q[0], tmp_path / "four_bar.gif", fps=10)
    with Image.open(path) as im:
        assert im.format == "GIF" and im.n_frames == 4
    with pytest.raises(ValueError, match="q"):
        animate(mech, np.zeros((2, 5)), tmp_path / "x.gif")
