"""Masks that never lie in the multibody kinematics, and the Builder / MJCF boundary.

Each rule has a control showing it can fail: the old mask (the residual alone) is shown to say
valid where the new one does not, a check that is skipped is shown to let the defect through.
"""

from __future__ import annotations

import numpy as np
import pytest

from robomech import multibody as mb
from robomech.multibody._assembly import MAX_STEPS, assembly_mode_sign

FOUR_BAR = mb.gallery.load("four_bar")
# Cranks over almost a full turn, each solved in ONE step from the reference configuration: the
# Newton path of a large move can end on the other assembly mode (elbow flipped).
CRANKS = np.linspace(-3.0, 3.0, 61)[:, None]
# Continuation in 100 stages of <= 0.03 rad stays on the reference mode (the independent answer).
CONTINUATION = 100
# Two assembly modes of a four-bar at one crank differ by O(1) rad in the passive joints; the same
# mode found twice agrees to the solver's tolerance (~1e-10 rad).
SAME_MODE_TOL = 1e-3


def _wrap(a: np.ndarray) -> np.ndarray:
    return np.angle(np.exp(1j * a))


# --- assembly mode ---------------------------------------------------------------------------------


def test_mode_changed_marks_exactly_the_samples_that_left_the_reference_mode():
    one = mb.forward_kinematics(FOUR_BAR, CRANKS)
    cont = mb.forward_kinematics(FOUR_BAR, CRANKS, steps=CONTINUATION)
    assert cont.converged.all() and not cont.mode_changed.any()
    other_mode = np.max(np.abs(_wrap(one.q - cont.q)), axis=-1) > SAME_MODE_TOL
    assert other_mode.sum() > 0  # the test has switched samples to find
    np.testing.assert_array_equal(one.mode_changed, other_mode)
    assert not one.converged[other_mode].any()
    assert one.converged[~other_mode].all()


def test_control_the_residual_alone_calls_the_switched_samples_converged():
    one = mb.forward_kinematics(FOUR_BAR, CRANKS)
    closed = one.residual <= mb.CONVERGED_RTOL * FOUR_BAR.tree.length
    assert (closed & one.mode_changed).sum() == one.mode_changed.sum() > 0  # the old mask lied here


def test_assembly_mode_sign_separates_the_two_modes_of_a_four_bar():
    qa = mb.forward_kinematics(FOUR_BAR, [0.2]).q
    rng = np.random.default_rng(1)
    guesses = np.repeat(qa[None], 40, axis=0)
    guesses[:, 1:] += rng.uniform(-3.0, 3.0, (40, 2))
    fk = mb.forward_kinematics(FOUR_BAR, np.full((40, 1), 0.2), guesses)
    sol = fk.q[fk.residual <= mb.CONVERGED_RTOL * FOUR_BAR.tree.length]
    same = np.max(np.abs(_wrap(sol - qa)), axis=-1) < SAME_MODE_TOL
    assert same.any() and (~same).any()
    sign = assembly_mode_sign(FOUR_BAR, np.repeat(qa[None], len(sol), axis=0), sol)
    np.testing.assert_array_equal(sign, np.where(same, 1.0, -1.0))
    # control: against itself the sign is +1, undefined (0) for a failed sample
    assert assembly_mode_sign(FOUR_BAR, qa[None], qa[None]).tolist() == [1.0]
    assert assembly_mode_sign(FOUR_BAR, qa[None], np.full((1, 3), np.nan)).tolist() == [0.0]


# --- overflowing inputs and unbounded work -----------------------------------------------------------


def test_an_overflowing_crank_is_masked_and_its_q_is_never_valid():
    fk = mb.forward_kinematics(FOUR_BAR, np.array([[0.2], [1e300], [-1e200]]))
    assert fk.converged.tolist() == [True, False, False]
    assert np.isnan(fk.q[1:]).all()
    mb.site_pose(FOUR_BAR, fk.q, "coupler_point")  # the output chains


def test_q_of_1e300_is_refused_by_the_analysis_functions():
    q = mb.forward_kinematics(FOUR_BAR, [0.2]).q.copy()
    q[1] = 1e300
    for f in (mb.site_pose, mb.site_jacobian, mb.singularities):
        with pytest.raises(ValueError, match="Expected q finite"):
            f(FOUR_BAR, q, "coupler_point")


def test_steps_are_bounded():
    with pytest.raises(ValueError, match="steps"):
        mb.forward_kinematics(FOUR_BAR, [0.2], steps=10**7)
    with pytest.raises(ValueError, match="steps"):
        mb.inverse_kinematics(FOUR_BAR, "coupler_point", np.eye(4), steps=MAX_STEPS + 1)
    assert mb.forward_kinematics(FOUR_BAR, [0.2], steps=3).converged  # control: a fair count runs


# --- Builder --------------------------------------------------------------------------------------


def _two_links() -> mb.Builder:
    b = mb.Builder("m")
    b.body("a", joints=[b.hinge("j")])
    b.body("c", parent="a", joints=[b.hinge("k")], pos=(1, 0, 0))
    return b


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda b: b.hinge("h", None), "axis"),
        (lambda b: b.slide("h", (0, 0, 1), None), "pos"),
        (lambda b: b.body("z", quat=None), "quat"),
        (lambda b: b.body("z", joints=None), "joints"),
        (lambda b: b.connect("cl", "a", "c", None), "anchor1"),
        (lambda b: b.revolute("cl", "a", "c", (0, 0, 0), None), "axis"),
        (lambda b: b.couple("cp", "j", "k", None), "polycoef"),
        (lambda b: b.helical("h", (0, 0, 1), "abc"), "pitch"),
        (lambda b: b.couple("cp", "j", "j", (0, 1)), "joint2"),
    ],
)
def test_builder_bad_arguments_raise_value_error_naming_them(call, name):
    with pytest.raises(ValueError, match=rf"Expected {name}\b|{name} of coupling"):
        call(_two_links())


def test_control_good_builder_arguments_pass():
    b = _two_links()
    b.couple("cp", "j", "k", (0, 1))
    b.helical("h", (0, 0, 1), 0.01)
    b.hinge("h2", (0, 1, 0), (0, 0, 0.1))


def _closed(anchor2) -> mb.Builder:
    b = _two_links()
    b.body("d", parent="c", joints=[b.hinge("l")], pos=(1, 0, 0))
    b.connect("cl", "world", "d", (1.5, 0.3, 0), anchor2=anchor2)
    b.actuate("j")
    return b


def test_a_typoed_anchor_is_refused_at_build_naming_the_closure():
    with pytest.raises(ValueError, match=r"Expected the description 'm' to assemble.*'cl'"):
        _closed((900.0, 0.0, 0.0)).build()


def test_control_an_unassembled_but_assemblable_anchor_builds():
    mech = _closed((0.5, 0.0, 0.0)).build()  # off the closure at q0, but reachable
    assert mb.forward_kinematics(mech, [0.3], steps=CONTINUATION).converged


# --- MJCF ---------------------------------------------------------------------------------------------


def test_an_mjcf_that_can_never_assemble_is_refused_at_load():
    good = mb.to_mjcf(_closed((0.5, 0.0, 0.0)).build())
    bad = good.replace(
        '<site name="_closure_cl_2" pos="0.5 0.0 0.0" />', '<site name="_closure_cl_2" pos="900 0 0" />'
    )
    assert bad != good
    assert mb.from_mjcf(good).nq == 3  # control: the untouched file loads
    with pytest.raises(ValueError, match=r"to assemble.*'cl'"):
        mb.from_mjcf(bad)


def test_unsupported_mjcf_messages_say_expected_and_name_an_unnamed_site_actuator():
    xml = (
        "<mujoco><worldbody><body><joint name='j' type='hinge'/><geom size='.1'/><site name='s'/></body>"
        "</worldbody><actuator><general site='s'/></actuator></mujoco>"
    )
    with pytest.raises(ValueError, match=r"Expected path_or_xml .*actuator 'number 0 \(unnamed\)'"):
        mb.from_mjcf(xml)
    tendon = (
        "<mujoco><worldbody><body><joint type='hinge'/><geom size='.1'/><site name='s'/></body>"
        "<site name='w'/></worldbody><tendon><spatial><site site='w'/><site site='s'/></spatial></tendon>"
        "</mujoco>"
    )
    with pytest.raises(ValueError, match="Expected path_or_xml without tendons"):
        mb.from_mjcf(tendon)


def test_to_mjcf_refuses_a_comment_it_could_not_read_back():
    with pytest.raises(ValueError, match="comment"):
        mb.to_mjcf(FOUR_BAR, comment="a\x00b")
    back = mb.from_mjcf(mb.to_mjcf(FOUR_BAR, comment="a\tb -- c"))  # control: a fair comment round-trips
    assert back.nq == FOUR_BAR.nq


def test_to_mjcf_refuses_massless_moving_bodies_naming_them():
    b = mb.Builder("m")
    b.body("a", joints=[b.hinge("j")], inertial=mb.Inertial(0.0))
    b.actuate("j")
    with pytest.raises(ValueError, match=r"Expected mech's moving bodies to have mass.*'a'"):
        mb.to_mjcf(b.build())
    b = mb.Builder("m")  # control: with a mass the export is read back by MuJoCo
    b.body("a", joints=[b.hinge("j")], inertial=mb.Inertial(1.0, diaginertia=(0.1, 0.1, 0.1)))
    b.actuate("j")
    assert mb.from_mjcf(mb.to_mjcf(b.build())).nq == 1


def test_draw_refuses_an_unknown_colour_naming_it():
    with pytest.raises(ValueError, match="Expected color"):
        mb.draw(FOUR_BAR, color="notacolor")


# --- mobility of long chains -------------------------------------------------------------------------


def _hinge_chain(n: int, close: bool, anchor: tuple[float, float, float] | None = None) -> mb.Mechanism:
    b = mb.Builder("chain")
    parent = "world"
    for i in range(n):
        b.body(
            f"b{i}",
            parent=parent,
            pos=(0.1, 0, 0) if i else (0, 0, 0),
            joints=[b.hinge(f"j{i}", (0, 0, 1) if i % 2 else (0, 1, 0))],
            inertial=mb.Inertial(1.0, diaginertia=(0.1, 0.1, 0.1)),
        )
        parent = f"b{i}"
    if close:
        b.connect("cl", "world", parent, anchor or (0.1 * (n - 1), 0.0, 0.0))
    b.actuate("j0")
    return b.build()


@pytest.mark.parametrize(("anchor", "singular"), [(None, True), ((0.8, 0.3, 0.1), False)])
def test_mobility_with_generic_neighbour_directions_matches_every_direction(monkeypatch, anchor, singular):
    """The neighbour rank check along 6 generic directions agrees with the check along all of them,
    at the stretched (singular) pose of a closed 12-hinge chain and at a generic assembly."""
    from robomech.multibody import _mobility

    mech = _hinge_chain(12, close=True, anchor=anchor)
    few = mb.mobility(mech)
    assert few.singular is singular
    monkeypatch.setattr(_mobility, "NEIGHBOUR_DIRECTIONS", 10**6)  # control: every direction
    every = mb.mobility(mech)
    assert (few.dof, few.rank, few.singular) == (every.dof, every.rank, every.singular)


@pytest.mark.slow
def test_mobility_of_a_long_chain_is_linear_work():
    """1000 hinges: previously one kinematics call per admissible direction (2000 calls); building
    the chain itself takes several seconds, hence slow."""
    m = mb.mobility(_hinge_chain(1000, close=False))
    assert m.dof == 1000


# --- robomech verify: the simulation can be set and a failure says why --------------------------------


@pytest.mark.parametrize(
    ("options", "name"),
    [
        ({"duration": 0.0}, "duration"),
        ({"duration": 100.0}, "duration"),
        ({"duration": "0.3"}, "duration"),
        ({"q0": np.zeros(2)}, "q0"),
        ({"q0": np.array([0.0, 1.0, 1.0])}, "q0"),  # does not assemble
        ({"q0": FOUR_BAR.q0, "qd_act0": np.zeros(3)}, "qd_act0"),
        ({"qd_act0": np.zeros(1)}, "q0"),
    ],
)
def test_verify_simulation_options_are_checked(options, name):
    from robomech.verify._generic import check_mechanism

    with pytest.raises(ValueError, match=rf"Expected {name}\b"):
        check_mechanism(FOUR_BAR, "fb", **options)


def test_verify_simulation_duration_and_start_are_used():
    from robomech.verify._generic import check_mechanism

    q0 = mb.forward_kinematics(FOUR_BAR, [0.5]).q
    checks = check_mechanism(FOUR_BAR, "fb", duration=0.05, q0=q0, qd_act0=[1.0])
    sim = [c for c in checks if c.quantity.startswith("forward simulation")]
    assert sim and sim[0].quantity.endswith("(0.05 s, passive)") and sim[0].passed


def test_a_failing_simulation_check_says_why(monkeypatch):
    """Control: the same comparison under a tolerance it cannot meet fails, and then names when it left
    the engine and how close it came to a constraint singularity (where a passive motion is not
    determined)."""
    from robomech.verify import _generic
    from robomech.verify._core import Tolerance

    monkeypatch.setattr(_generic, "TOL_SIM", Tolerance(1e-30, "impossible: the control", relative=True))
    q0 = mb.forward_kinematics(FOUR_BAR, [0.5]).q
    (sim, _) = _generic._simulation_checks(FOUR_BAR, "fb", q0, np.ones(1), 0.1)
    assert not sim.passed
    assert "diverged from the engine after t =" in sim.detail
    assert "constraint singularity" in sim.detail and "sigma " in sim.detail


def test_verify_cli_takes_duration_and_start(capsys):
    from robomech.cli import main

    assert main(["verify", "four_bar", "--quiet", "--duration", "0.05", "--q0", "0", "0", "0"]) == 0
    assert "forward simulation vs engine (0.05 s, passive)" in capsys.readouterr().out
    assert main(["verify", "four_bar", "--quiet", "--duration", "-1"]) == 2  # control: refused in one line
    assert "duration" in capsys.readouterr().err
