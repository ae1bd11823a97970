"""The generic engine verification (verify/_generic.py): gallery, teeth, ``robomech verify FILE``."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from robomech import multibody as mb
from robomech.cli import main
from robomech.verify import _generic as g
from robomech.verify._core import Tolerance
from robomech.verify._mujoco import assemble_along

FAST = ["four_bar", "bennett", "planar_3rrr", "rps_3"]


@pytest.mark.slow
@pytest.mark.parametrize("name", ["spherical-leg", "omnileg", "vectored-thrust"])
def test_paper_descriptions_agree_with_engine(name):
    """The papers' multibody descriptions exported to MuJoCo (redundant actuation driven consistently;
    bodies without inertia take the exported geoms' on both sides); the 0.3 s simulation is left out."""
    checks = g.check_mechanism(g.describe(name), name, simulate=False)
    assert all(c.passed for c in checks), [(c.quantity, c.max_error) for c in checks if not c.passed]


@pytest.mark.parametrize("name", FAST)
def test_gallery_mechanism_agrees_with_engine(name):
    checks = g.check_mechanism(mb.gallery.load(name), name)
    failed = [(c.quantity, c.max_error) for c in checks if not c.passed]
    assert not failed
    assert any("inverse dynamics" in c.quantity for c in checks)
    assert any("forward simulation" in c.quantity for c in checks)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["stewart", "delta"])
def test_large_gallery_mechanism_agrees_with_engine(name):
    # the Delta's passive simulation (27 coordinates, 6 idle forearm spins) takes ~20 s: recorded in
    # docs/dynamics.md, checked here without it
    checks = g.check_mechanism(mb.gallery.load(name), name, simulate=name != "delta")
    assert all(c.passed for c in checks), [(c.quantity, c.max_error) for c in checks if not c.passed]


def test_inverse_dynamics_check_has_teeth():
    """A 1% mass error on one body, or a wrong gravity sign, is far outside the torque tolerance."""
    mech = dataclasses.replace(mb.gallery.load("four_bar"), gravity=(0.0, -9.81, 0.0))
    t, at = g.trajectory(mech)
    qa, qd, qdd = at(t[:4])
    fk = assemble_along(mech, qa)
    q, conv = fk.q, fk.converged
    assert conv.all()
    import mujoco

    m = g.engine_model(mech)
    d = mujoco.MjData(m)
    r = mb.inverse_dynamics(mech, q, qd, qdd)
    eng = np.array([g.engine_inverse_dynamics(m, d, mech, q[i], r.qd[i], r.qdd[i]) for i in range(4)])
    scale = np.max(np.abs(eng))
    assert np.max(np.abs(r.tau - eng)) / scale < g.TOL_TORQUE.value
    b = mech.bodies[1]
    heavier = dataclasses.replace(b, inertial=dataclasses.replace(b.inertial, mass=1.01 * b.inertial.mass))
    wrong = dataclasses.replace(mech, bodies=(mech.bodies[0], heavier, *mech.bodies[2:]))
    rw = mb.inverse_dynamics(wrong, q, qd, qdd)
    assert np.max(np.abs(rw.tau - eng)) / scale > 1e3 * g.TOL_TORQUE.value
    up = mb.inverse_dynamics(dataclasses.replace(mech, gravity=(0.0, 9.81, 0.0)), q, qd, qdd)
    assert np.max(np.abs(up.tau - eng)) / scale > 1e3 * g.TOL_TORQUE.value


def test_cli_verifies_a_users_file(capsys, monkeypatch):
    path = str(mb.gallery.path("four_bar"))
    assert main(["verify", path, "--json"]) == 0
    out = json.loads(capsys.readouterr().out, parse_constant=lambda c: pytest.fail(f"non-strict JSON {c}"))
    assert out["passed"] and len(out["checks"]) >= 8
    monkeypatch.setattr(g, "TOL_TORQUE", Tolerance(1e-300, "impossible: forces a failure"))
    assert main(["verify", path]) == 1
    assert "FAIL" in capsys.readouterr().out  # the table, with the failed check
    assert main(["verify", "no_such_mechanism"]) == 2
    monkeypatch.undo()
    assert main(["verify", "bennett"]) == 0  # a gallery name: the generic checks
    assert "bennett (generic)" in capsys.readouterr().out
    assert main(["verify", "missing.xml"]) == 2


def test_an_error_in_one_of_several_files_names_that_file(tmp_path, capsys, monkeypatch):
    """``robomech verify a.xml b.xml``: an input error found while checking one file says which."""
    a, b = tmp_path / "first.xml", tmp_path / "second.xml"
    a.write_text(mb.gallery.path("four_bar").read_text())
    b.write_text(mb.gallery.path("four_bar").read_text())
    real = g.check_mechanism

    def check(mech, label, **kw):
        if label == "second":
            raise ValueError("Expected something else, got this.")
        return real(mech, label, **kw)

    monkeypatch.setattr(g, "check_mechanism", check)
    assert main(["verify", str(a), str(b), "--quiet"]) == 2
    assert "second.xml: Expected something else" in capsys.readouterr().err


PENDULUM = """<mujoco model="double_pendulum"><worldbody>
  <body name="l1" pos="0 0 1"><joint name="j1" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.02" mass="1"/>
    <body name="l2" pos="0.5 0 0"><joint name="j2" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.02" mass="0.7"/>
      <site name="tip" pos="0.4 0 0"/></body></body>
</worldbody></mujoco>"""


@pytest.mark.parametrize("case", ["passive double pendulum", "passive four-bar", "underactuated stewart"])
def test_passive_and_underactuated_descriptions_are_verified(case):
    """Without actuators (or with too few to determine the state) the checks follow a motion driven through
    virtual actuators on the first free hinges; the passive simulation applies no force, so the description
    is verified as it is.  Every check passes, and the virtual actuators are named."""
    if case == "passive double pendulum":
        mech = mb.from_mjcf(PENDULUM)
        expect = ("j1", "j2")
    elif case == "passive four-bar":
        mech = dataclasses.replace(mb.gallery.load("four_bar"), actuated=())
        expect = ("theta2",)
    else:
        full = mb.gallery.load("stewart")
        mech = dataclasses.replace(full, actuated=full.actuated[:3])
        expect = None
    assert mech.actuated != expect
    driven, added = g._virtually_actuated(mech)
    assert added and len(driven.actuated) == mb.mobility(mech).dof
    if expect is not None:
        assert added == expect
    checks = g.check_mechanism(mech, case, simulate=case != "underactuated stewart")
    assert all(c.passed for c in checks), [(c.quantity, c.max_error) for c in checks if not c.passed]
    assert "virtual actuators on " + ", ".join(added) in checks[0].detail


# Three links hanging straight down (the reference): there the tip's twist has rank 2 over the three
# swings, so a rule watching the tip alone would count 2 DOF + 1 idle; each swing moves a joint anchor or
# a centre of mass, so the passive description counts 3 DOF and all three joints need an actuator.
TRIPLE_PENDULUM = (Path(__file__).parents[1] / "multibody" / "data" / "triple_pendulum.xml").read_text()


def test_a_passive_chain_straight_at_its_reference_gets_enough_virtual_actuators():
    """The virtual actuators are added until they determine the motion of the mechanism they drive, not
    only until their number reaches a reference DOF (straight, the tip alone loses a rank)."""
    mech = mb.from_mjcf(TRIPLE_PENDULUM)
    _, added = g._virtually_actuated(mech)
    assert added == ("a1", "a2", "a3")
    checks = g.check_mechanism(mech, "triple pendulum", simulate=False)
    assert all(c.passed for c in checks), [(c.quantity, c.max_error) for c in checks if not c.passed]


def test_a_failing_simulation_is_explained_once(monkeypatch):
    """When both the simulation and its energy drift fail, the explanation (which re-simulates the motion
    around each approach to a singularity: minutes near one) is computed once and given to both."""
    mech = mb.from_mjcf(PENDULUM)
    monkeypatch.setattr(g, "TOL_SIM", Tolerance(1e-300, "impossible: forces a failure", relative=True))
    monkeypatch.setattr(g, "TOL_DRIFT", Tolerance(1e-300, "impossible: forces a failure", relative=True))
    calls = []
    real = g._why
    monkeypatch.setattr(g, "_why", lambda *a, **k: calls.append(1) or real(*a, **k))
    driven, _ = g._virtually_actuated(mech)  # as check_mechanism calls it
    checks = g._simulation_checks(driven, "pendulum", mech.q0, qd0=np.array([0.5, -0.3]))
    assert [c.passed for c in checks] == [False, False]
    assert len(calls) == 1


def test_passive_verification_has_teeth():
    """The same passive pendulum with a 1 % heavier link on the engine side fails the dynamics checks."""
    mech = mb.from_mjcf(PENDULUM)
    wrong = mb.from_mjcf(PENDULUM.replace('mass="0.7"', 'mass="0.707"'))
    real = g.engine_model

    def engine_of_the_wrong_one(m):
        return real(wrong)

    import unittest.mock as um

    with um.patch.object(g, "engine_model", engine_of_the_wrong_one):
        checks = g.check_mechanism(mech, "pendulum", simulate=False)
    failed = {c.quantity for c in checks if not c.passed}
    assert "inverse dynamics (mj_rne through efc_J)" in failed


# A parallelogram four-bar (crank = rocker = 0.5 m, coupler = ground = 1 m), passive, falling from 1 rad:
# each time the crank passes horizontal every link is collinear (a change point, where the
# anti-parallelogram branch meets this one): the multibody motion switches branch at the second pass.
PARALLELOGRAM = """<mujoco model="parallelogram"><compiler angle="radian"/><option gravity="0 0 -9.81"/>
<default><geom contype="0" conaffinity="0" density="1000"/></default><worldbody>
 <body name="crank"><joint name="crank" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0 0 0.5" size="0.02"/>
  <body name="coupler" pos="0 0 0.5"><joint name="elbow" axis="0 1 0"/>
   <geom type="capsule" fromto="0 0 0 1 0 0" size="0.02"/></body></body>
 <body name="rocker" pos="1 0 0"><joint name="rocker" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0 0 0.5" size="0.02"/></body></worldbody>
<equality><connect body1="coupler" body2="rocker" anchor="1 0 0"/></equality></mujoco>"""


@pytest.mark.slow
def test_a_passive_fall_through_a_singular_pose_says_where_it_crossed():
    """The fall leaves the engine after the second change point (crank at 3 pi / 2, t ~ 0.694 s, between
    two samples 33 ms apart); the failed check names the crossing, resolved between the samples."""
    mech = mb.from_mjcf(PARALLELOGRAM)
    checks = g.check_mechanism(mech, "parallelogram", duration=1.0, q0=[1.0, -1.0, 1.0])
    sim = next(c for c in checks if c.quantity.startswith("forward simulation"))
    assert not sim.passed
    assert "crossed a type II singularity near t = 0.69" in sim.detail, sim.detail
    sigma = float(sim.detail.rsplit("sigma_min ", 1)[1].split()[0])
    assert sigma < g.SINGULAR_SIGMA_RTOL * mech.tree.length
    # The rest of the description is right.  The energy drift of a fall through a type II singularity sits
    # at the integrator's tolerance (2e-7 relative against 1e-7 with the compiled forward dynamics, 9e-8
    # with the former numpy path, whose accelerations agree to 1e-13): where it fails, it must name the same
    # crossing.
    drift = next(c for c in checks if c.quantity.startswith("energy drift"))
    assert drift.passed or "crossed a type II singularity near t = 0.69" in drift.detail, drift.detail
    assert all(c.passed for c in checks if c is not sim and c is not drift)
