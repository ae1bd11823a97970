"""``robomech verify`` of a floating base: tree dynamics, forward dynamics and a free flight vs MuJoCo."""

from __future__ import annotations

import json
import unittest.mock as um

import numpy as np
import pytest

from robomech import multibody as mb
from robomech.cli import main
from robomech.verify import _generic as g

pytest.importorskip("mujoco")

LEG = """<body name="{n}_thigh" pos="{x} {y} 0"><joint name="{n}_hip" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0 0 -0.2" size="0.03" mass="{m1}"/>
  <body name="{n}_shank" pos="0 0 -0.2"><joint name="{n}_knee" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.02 0 -0.2" size="0.02" mass="{m2}"/>
    <site name="{n}_foot" pos="0.02 0 -0.2"/></body></body>"""
CORNERS = (("fl", 0.25, 0.15), ("fr", 0.25, -0.15), ("hl", -0.25, 0.15), ("hr", -0.25, -0.15))


def quadruped(thigh_mass: float = 1.3) -> str:
    """A quadruped-like tree: a torso on a free joint, four two-hinge legs, a motor on every hinge."""
    legs = "".join(
        LEG.format(n=n, x=x, y=y, m1=thigh_mass if n == "fl" else 1.3, m2=0.4) for n, x, y in CORNERS
    )
    motors = "".join(f'<motor joint="{n}_{j}"/>' for n, _, _ in CORNERS for j in ("hip", "knee"))
    return f"""<mujoco model="quadruped"><worldbody><body name="torso" pos="0 0 0.5"><freejoint name="base"/>
  <geom type="box" size="0.3 0.15 0.05" mass="8"/>{legs}</body></worldbody>
  <actuator>{motors}</actuator></mujoco>"""


QUAD = mb.from_mjcf(quadruped())
SHORT = 0.1  # s of free flight: the comparison is the same at any length; the suite keeps it short
ROWS = {
    "generalized forces (vs mj_rne)",
    "mass matrix (vs mj_fullM)",
    "forward dynamics under actuator forces (vs engine qacc)",
    f"free flight vs engine ({SHORT:g} s, passive)",
    "momentum of the free flight",
    "energy drift of the simulation",
}


def test_a_floating_base_is_checked_against_the_engine():
    checks = g.check_mechanism(QUAD, "quadruped", duration=SHORT)
    assert {c.quantity for c in checks} == ROWS
    assert all(c.passed for c in checks), [(c.quantity, c.max_error, c.detail) for c in checks]
    flight = next(c for c in checks if c.quantity.startswith("free flight"))
    moved = float(flight.detail.rsplit("motion of ", 1)[1].split()[0])
    assert moved > 0.1  # the tumbling start moves the bodies: the relative error means something


def test_a_one_percent_mass_error_fails():
    """Teeth: the engine built from the same quadruped with one thigh 1 % heavier."""
    wrong = mb.from_mjcf(quadruped(thigh_mass=1.313))
    real = g.engine_model

    def engine_of_the_wrong_one(mech, **kw):
        return real(wrong, **kw)

    with um.patch.object(g, "engine_model", engine_of_the_wrong_one):
        checks = g.check_mechanism(QUAD, "quadruped", duration=SHORT)
    failed = {c.quantity for c in checks if not c.passed}
    assert {"generalized forces (vs mj_rne)", "mass matrix (vs mj_fullM)"} <= failed
    assert "forward dynamics under actuator forces (vs engine qacc)" in failed
    assert f"free flight vs engine ({SHORT:g} s, passive)" in failed
    assert "energy drift of the simulation" not in failed  # the multibody side alone: unchanged


def test_the_flight_start_is_settable_and_the_cli_checks_a_floating_file(tmp_path, capsys):
    q0 = np.array(QUAD.q0, float)
    qd0 = np.zeros(QUAD.nv)
    qd0[3:6] = (0.0, 0.0, 2.0)  # spinning about the vertical
    checks = g.check_mechanism(QUAD, "quadruped", duration=0.05, q0=q0, qd0=qd0)
    assert all(c.passed for c in checks)
    assert "free flight vs engine (0.05 s, passive)" in {c.quantity for c in checks}
    with pytest.raises(ValueError, match=r"Expected qd0 .*got qd_act0"):
        g.check_mechanism(QUAD, "quadruped", q0=q0, qd_act0=np.zeros(len(QUAD.actuated)))
    path = tmp_path / "quadruped.xml"
    path.write_text(quadruped())
    args = ["verify", str(path), "--quiet", "--json", "--duration", "0.05", "--q0", *map(str, q0)]
    assert main([*args, "--qvel0", *map(str, qd0)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["passed"] and "free flight vs engine (0.05 s, passive)" in {
        c["quantity"] for c in out["checks"]
    }


PENDULUM = """<mujoco><worldbody><body name="l1" pos="0 0 1"><joint name="j1" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.02" mass="1"/>
  <body name="l2" pos="0.5 0 0"><joint name="j2" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.02" mass="0.7"/></body></body>
</worldbody></mujoco>"""


def test_a_passive_fall_starts_where_asked():
    """A passive pendulum released at rest from q0, or with every coordinate's rate qd0 (its actuated
    rates, none, cannot say how it moves)."""
    mech = mb.from_mjcf(PENDULUM)
    for rates in ({}, {"qd0": [1.0, -0.5]}):
        checks = g.check_mechanism(mech, "pendulum", duration=0.2, q0=[0.3, 0.2], **rates)
        assert not any(c.failed for c in checks), [(c.quantity, c.max_error) for c in checks if c.failed]
        assert "forward simulation vs engine (0.2 s, passive)" in {c.quantity for c in checks}
    with pytest.raises(ValueError, match=r"Expected qd0 .*--qvel0"):
        g.check_mechanism(mech, "pendulum", q0=[0.3, 0.2], qd_act0=[1.0, 0.0])


def test_a_floating_base_is_checked_against_pinocchio_with_teeth():
    """``--engine pinocchio``: rnea, crba and aba at the same random states; an engine model with one
    thigh 1 % heavier fails all three."""
    pytest.importorskip("pinocchio")
    from robomech.verify import _pinocchio_engine as pe

    checks = pe.check_mechanism_pinocchio(QUAD, "quadruped")
    assert [c.quantity for c in checks] == [
        "generalized forces (vs rnea)",
        "mass matrix (vs crba)",
        "forward dynamics under actuator forces (vs aba)",
    ]
    assert all(c.passed for c in checks), [(c.quantity, c.max_error) for c in checks]
    wrong = mb.from_mjcf(quadruped(thigh_mass=1.313))
    real = mb.to_pinocchio
    with um.patch.object(mb, "to_pinocchio", lambda mech: real(wrong)):
        assert not any(c.passed for c in pe.check_mechanism_pinocchio(QUAD, "quadruped"))


FLOATING_FOUR_BAR = """<mujoco model="floating_four_bar"><worldbody>
<body name="base" pos="0 0 1"><freejoint name="free"/><geom type="box" size="0.5 0.05 0.05" mass="3"/>
 <body name="crank" pos="0 0 0.05"><joint name="crank" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0 0 0.3" size="0.02" mass="0.4"/>
  <body name="coupler" pos="0 0 0.3"><joint name="elbow" axis="0 1 0"/>
   <geom type="capsule" fromto="0 0 0 0.8 0 0" size="0.02" mass="0.9"/></body></body>
 <body name="rocker" pos="0.8 0 0.05"><joint name="rocker" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0 0 0.3" size="0.02" mass="0.4"/></body></body></worldbody>
<equality><connect body1="coupler" body2="rocker" anchor="0.8 0 0"/></equality>
<actuator><motor joint="crank"/></actuator></mujoco>"""


def test_a_floating_base_with_a_closed_loop_is_checked():
    """A four-bar on a free base: the tree quantities at random (unassembled) states, the free flight
    from the assembled reference (the closure inside the system keeps its momentum); forward dynamics
    is not compared (the engine's closures are soft)."""
    checks = g.check_mechanism(mb.from_mjcf(FLOATING_FOUR_BAR), "floating four-bar", duration=SHORT)
    assert [c.quantity for c in checks] == [
        "generalized forces (vs mj_rne)",
        "mass matrix (vs mj_fullM)",
        f"free flight vs engine ({SHORT:g} s, passive)",
        "momentum of the free flight",
        "energy drift of the simulation",
    ]
    assert all(c.passed for c in checks), [(c.quantity, c.max_error) for c in checks]
