"""Generic inverse dynamics of the OmniLeg description == the analytic Lagrange model (issue 13).

``omnileg.to_multibody(leg)`` carries the analytic model's 22 bodies with their inertias and the
double-Cardan drive; ``robomech.multibody.inverse_dynamics`` (Newton-Euler of the spanning tree
projected through the closure's G) must then give the analytic model's motor torques and each of its
parts: M_a = M, the velocity terms, the gravity terms and the foot-force terms.  The two are
formulated independently (jets of closed-form body poses vs the generic tree and its closure
constraints), so agreement to rounding checks both.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomech import multibody as mb
from robomech.mechanisms import omnileg as ol
from robomech.mechanisms.omnileg._dynamics import _body_list
from robomech.mechanisms.omnileg._multibody import _frame
from robomech.multibody._compile import compile_model
from robomech.multibody._compiled import compiled_body_poses

# Both sides are exact rigid-body models of the same bodies (issue 13's bar: 1e-8 relative; measured
# ~2e-14).
REL_TOL = 1e-8
# Torques are compared relative to max(|analytic|, TORQUE_FLOOR): at rest at α = β = γ = 0 the gravity
# torques vanish; 1e-3 N·m is 1e-3 of the leg's typical gravity torque (~1 N·m), far above rounding.
TORQUE_FLOOR = 1e-3
# Mass matrices relative to max(|M|, MASS_FLOOR): 1e-6 kg m² is ~1e-3 of the smallest diagonal entry.
MASS_FLOOR = 1e-6
# Body poses: pure geometry of two codes (rounding of O(0.3 m) through ~10 transforms).
POSE_TOL = 1e-12

LEG = ol.OmniLeg.paper()
MECH = ol.to_multibody(LEG)
PARTS = (
    ("tau", "tau", TORQUE_FLOOR),
    ("M_a", "M", MASS_FLOOR),
    ("velocity_terms", "velocity_terms", TORQUE_FLOOR),
    ("gravity_terms", "gravity_terms", TORQUE_FLOOR),
    ("external_terms", "foot_terms", TORQUE_FLOOR),
)


def _errors(leg, mech, q, qd, qdd, F, guess=None):
    """Relative max error of each part (generic vs analytic), and the assembled generic q."""
    fk = mb.forward_kinematics(mech, q, guess=guess, steps=1 if guess is not None else 4)
    assert fk.converged.all()
    W = np.zeros((*F.shape[:-1], 6))
    W[..., 3:] = F  # a pure force at the foot point, [m; f]
    gen = mb.inverse_dynamics(mech, fk.q, qd, qdd, wrenches={"foot": W})
    ana = ol.inverse_dynamics(leg, q, qd, qdd, foot_force=F)
    assert gen.valid.all()
    err = {}
    for g, a, floor in PARTS:
        x, y = getattr(gen, g), getattr(ana, a)
        err[g] = float(np.max(np.abs(x - y)) / max(float(np.max(np.abs(y))), floor))
    return err, fk.q


def _eq52(n=61):
    t = np.linspace(0.0, 6.0, n)
    prof = ol.joint_trajectory_eq52(t)
    F = np.where((t <= 1.0)[:, None], [0.0, -20.0, 20.0], 0.0)  # Fig. 11's foot force in 0-1 s
    return t, prof, F


def test_joint_names_and_values_are_the_analytic_tree():
    """The description's qpos is joint_motion's (same names, same zero of every angle)."""
    _, prof, _ = _eq52()
    fk = mb.forward_kinematics(MECH, prof.q, steps=4)
    assert fk.converged.all()
    idx = [MECH.qpos_address(n) for n in ol.TREE_JOINTS]
    assert sorted(idx) == list(range(MECH.nq))
    jm = ol.joint_motion(LEG, prof.q, prof.qd, prof.qdd)
    assert np.max(np.abs(fk.q[:, idx] - jm.q)) < POSE_TOL
    G = mb.influence(MECH, fk.q, second_order=False).G  # (N, nv, 3)
    dof = [MECH.dof_address(n) for n in ol.TREE_JOINTS]
    assert np.max(np.abs(np.einsum("nij,nj->ni", G, prof.qd)[:, dof] - jm.qd)) < POSE_TOL
    assert MECH.actuated == ("theta21", "theta11", "drive_in")


def test_body_frames_and_mass_centres_are_the_analytic_ones():
    rng = np.random.default_rng(3)
    q = np.column_stack(
        [
            rng.uniform(-1, 1, 12) * LEG.alpha_max,
            rng.uniform(-1, 1, 12) * LEG.beta_max,
            rng.uniform(0, 1.4, 12),
        ]
    )
    fk = mb.forward_kinematics(MECH, q, steps=4)
    assert fk.converged.all()
    T = compiled_body_poses(compile_model(MECH), fk.q)
    R_an, p_an = ol.body_poses(LEG, q)
    bodies = {b.name: b for b in MECH.bodies}
    for i, (name, kind) in enumerate(_body_list()):
        bi = MECH.tree.body_index(name)
        R = T[:, bi, :3, :3]
        assert np.max(np.abs(R @ _frame(name) - R_an[:, i])) < POSE_TOL, name
        inertial = bodies[name].inertial
        assert inertial is not None and inertial.mass == LEG.bodies[kind].mass
        com = T[:, bi, :3, 3] + R @ np.asarray(inertial.pos)
        assert np.max(np.abs(com - p_an[:, i])) < POSE_TOL, name


def test_generic_equals_analytic_along_eq52():
    """Eq. (52) over its whole period (γ through 0 at t = 0, 3, 6 s) with Fig. 11's foot force."""
    _, prof, F = _eq52()
    err, _ = _errors(LEG, MECH, prof.q, prof.qd, prof.qdd, F)
    assert max(err.values()) < REL_TOL, err


@settings(max_examples=30, deadline=None)
@given(
    a=st.floats(-1.0, 1.0),
    b=st.floats(-1.0, 1.0),
    g=st.floats(0.0, 1.0),
    rates=st.lists(st.floats(-5.0, 5.0), min_size=6, max_size=6),
    force=st.lists(st.floats(-50.0, 50.0), min_size=3, max_size=3),
)
def test_generic_equals_analytic_random_states(a, b, g, rates, force):
    """Random admissible states: any pose in Table 2's ranges, any rates, accelerations, foot force."""
    q = np.array([[a * LEG.alpha_max, b * LEG.beta_max, LEG.gamma_min + g * (LEG.gamma_max - LEG.gamma_min)]])
    r = np.asarray(rates)
    err, _ = _errors(LEG, MECH, q, r[None, :3], r[None, 3:], np.asarray(force)[None])
    assert max(err.values()) < REL_TOL, err


def test_generic_equals_analytic_for_other_parameters():
    """Other dimensions, inertias (an off-diagonal foot inertia and an offset mass centre) and gravity."""
    foot = LEG.bodies["foot"]
    c, s = np.cos(0.4), np.sin(0.4)
    R = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]) @ np.array(
        [[c, -s, 0.0], [s, c, 0.0], [0, 0, 1]]
    )
    I = R @ np.array(foot.inertia) @ R.T  # a full (non-diagonal) inertia tensor
    leg = dataclasses.replace(
        LEG,
        L1=0.18,
        L4=0.11,
        shank_azimuth=0.3,
        gravity=(1.0, -2.0, 9.0),
        bodies={"foot": dataclasses.replace(foot, inertia=I, com=(0.004, -0.002, foot.com[2]))},
    )
    _, prof, F = _eq52(21)
    err, _ = _errors(leg, ol.to_multibody(leg), prof.q, prof.qd, prof.qdd, F)
    assert max(err.values()) < REL_TOL, err


def test_the_comparison_has_teeth():
    """A 2 % heavier crank in the description only: the generic torques move far beyond REL_TOL."""
    crank = LEG.bodies["crank"]
    heavy = dataclasses.replace(LEG, bodies={"crank": dataclasses.replace(crank, mass=1.02 * crank.mass)})
    _, prof, F = _eq52(13)
    err, _ = _errors(LEG, ol.to_multibody(heavy), prof.q, prof.qd, prof.qdd, F)
    assert err["tau"] > 1e3 * REL_TOL and err["M_a"] > 1e3 * REL_TOL


def test_paper_drive_is_not_the_described_drive():
    """paper 2, eqs. (26)-(31): the simplified drive differs from the exact double Cardan described."""
    _, prof, _ = _eq52(13)
    fk = mb.forward_kinematics(MECH, prof.q, steps=4)
    gen = mb.inverse_dynamics(MECH, fk.q, prof.qd, prof.qdd)
    pp = ol.inverse_dynamics(LEG, prof.q, prof.qd, prof.qdd, paper_as_printed=True)
    assert np.max(np.abs(gen.tau - pp.tau)) / np.max(np.abs(pp.tau)) > 10 * REL_TOL


def test_to_multibody_rejects_other_objects():
    with pytest.raises(ValueError, match="leg"):
        ol.to_multibody("paper")  # type: ignore[arg-type]
