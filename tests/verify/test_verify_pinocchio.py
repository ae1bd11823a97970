"""``robomech verify --engine pinocchio``: the generic checks against Pinocchio, a second engine."""

from __future__ import annotations

import dataclasses

import pytest

from robomech import multibody as mb
from robomech.cli import main
from robomech.verify import _pinocchio_engine as pe

pytest.importorskip("pinocchio", reason="no Pinocchio (pip install 'robomech[pinocchio]')")


@pytest.mark.parametrize("name", ["four_bar", "bennett", "planar_3rrr", "rps_3"])
def test_gallery_passes_against_pinocchio(name, capsys):
    assert main(["verify", "--engine", "pinocchio", name]) == 0
    assert "6 passed, 0 failed" in capsys.readouterr().out


@pytest.mark.slow
@pytest.mark.parametrize("name", ["delta", "stewart", "spherical-leg", "omnileg", "vectored-thrust"])
def test_large_and_paper_descriptions_pass_against_pinocchio(name, capsys):
    assert main(["verify", "--engine", "pinocchio", name]) == 0


def test_pinocchio_checks_have_teeth(monkeypatch):
    """Pinocchio given a model with one body 1 % heavier: the mass matrix and inverse dynamics checks fail,
    the kinematic ones still pass."""
    mech = mb.gallery.load("four_bar")
    b = mech.bodies[1]
    heavier = dataclasses.replace(b, inertial=dataclasses.replace(b.inertial, mass=1.01 * b.inertial.mass))
    wrong = dataclasses.replace(mech, bodies=(mech.bodies[0], heavier, *mech.bodies[2:]))
    real = mb.to_pinocchio
    monkeypatch.setattr(mb, "to_pinocchio", lambda m: real(wrong))
    checks = {c.quantity: c.passed for c in pe.check_mechanism_pinocchio(mech, "four_bar")}
    assert not checks["mass matrix (crba)"]
    assert not checks["inverse dynamics (rnea through the constraint Jacobian)"]
    assert checks["closure (constraint-model frames)"] and checks["body frames (framesForwardKinematics)"]


def test_a_mechanism_without_description_is_a_usage_error(capsys):
    assert main(["verify", "--engine", "pinocchio", "continuum"]) == 2


def test_an_open_chains_closure_rows_are_not_applicable_against_pinocchio(tmp_path, capsys):
    """A double pendulum has no constraint rows: its closure and admissible-velocity rows are n/a (0 by
    construction), the rest pass and the exit status is 0; the four-bar's are judged (the gallery test)."""
    path = tmp_path / "pendulum.xml"
    path.write_text(
        '<mujoco><worldbody><body name="l1"><joint name="j1" axis="0 1 0"/>'
        '<geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.02" mass="1"/>'
        '<body name="l2" pos="0.5 0 0"><joint name="j2" axis="0 1 0"/>'
        '<geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.02" mass="0.7"/></body></body>'
        "</worldbody></mujoco>"
    )
    assert main(["verify", "--engine", "pinocchio", str(path)]) == 0
    out = capsys.readouterr().out
    assert "4 passed, 0 failed, 2 n/a" in out
    na = [line for line in out.splitlines() if line.rstrip().endswith("n/a") and "passed" not in line]
    assert [("closure" in line, "admissible velocity" in line) for line in na] == [
        (True, False),
        (False, True),
    ]
