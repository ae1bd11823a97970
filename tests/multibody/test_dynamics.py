"""Closed-chain dynamics of described mechanisms: identities that do not use the engine.

(The engine comparison of every gallery mechanism is tests/verify/test_verify_generic.py.)
References: the mechanism's own energy differentiated along a trajectory (power balance), the
virtual-work identity ``tau = -J^T W`` for a wrench at a site, forward/inverse round trips, the
non-redundant four-bar as reference for its redundantly actuated twin, and a toggle configuration
where the passive dyad is collinear (type II singularity).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from robomech import dynamics
from robomech import multibody as mb

from . import _reference as R

# Exact identities of O(1) quantities evaluated in double precision.
IDENTITY_TOL = 1e-10
# Central difference (step 1e-5 s) of the energy along a trajectory: truncation ~h^2 E''' ~ 1e-9.
FD_POWER_TOL = 1e-7

FOUR_BAR = dataclasses.replace(mb.gallery.load("four_bar"), gravity=(0.0, -9.81, 0.0))
RRR = dataclasses.replace(mb.gallery.load("planar_3rrr"), gravity=(0.0, -9.81, 0.0))


def _motion(mech, n=4, seed=0, amp=0.2):
    rng = np.random.default_rng(seed)
    na = len(mech.actuated)
    qa = mech.q0[mech.tree.act_qadr] + amp * rng.uniform(-1, 1, (n, na))
    fk = mb.forward_kinematics(mech, qa, steps=3)
    assert fk.converged.all()
    return fk.q, rng.normal(size=(n, na)), rng.normal(size=(n, na))


@pytest.mark.parametrize("mech", [FOUR_BAR, RRR], ids=["four_bar", "planar_3rrr"])
def test_parts_sum_and_mass_matrix_is_kinetic_energy(mech):
    q, qd, qdd = _motion(mech)
    r = mb.inverse_dynamics(mech, q, qd, qdd)
    assert r.valid.all()
    parts = np.einsum("...ij,...j->...i", r.M_a, qdd) + r.velocity_terms + r.gravity_terms + r.external_terms
    assert np.max(np.abs(parts - r.tau)) < IDENTITY_TOL
    assert np.max(np.abs(r.M_a - r.M_a.swapaxes(-1, -2))) < IDENTITY_TOL
    assert np.all(np.linalg.eigvalsh(r.M_a) > 0)
    T, _ = mb.energy(mech, q, r.qd)
    assert np.max(np.abs(T - 0.5 * np.einsum("ni,nij,nj->n", qd, r.M_a, qd))) < IDENTITY_TOL
    # velocity terms vanish at rest; gravity terms do not depend on the motion
    r0 = mb.inverse_dynamics(mech, q, 0 * qd, qdd)
    assert np.max(np.abs(r0.velocity_terms)) < IDENTITY_TOL
    assert np.max(np.abs(r0.gravity_terms - r.gravity_terms)) < IDENTITY_TOL


def test_power_balance_against_own_energy():
    mech = RRR
    w = np.array([3.0, 4.0, 5.0])

    def state(t):
        qa = mech.q0[mech.tree.act_qadr] + 0.1 * np.sin(w * t)
        return qa, 0.1 * w * np.cos(w * t), -0.1 * w * w * np.sin(w * t)

    h = 1e-5
    for t in (0.1, 0.4):
        qa, qd, qdd = (np.stack(x) for x in zip(*(state(t + k * h) for k in (-1, 0, 1)), strict=True))
        fk = mb.forward_kinematics(mech, qa, steps=3)
        r = mb.inverse_dynamics(mech, fk.q, qd, qdd)
        E = np.sum(mb.energy(mech, fk.q, r.qd), axis=0)
        dE = (E[2] - E[0]) / (2 * h)
        P = r.tau[1] @ qd[1]
        assert abs(P - dE) < FD_POWER_TOL * max(1.0, abs(P))


def test_statics_virtual_work_and_site_wrench_round_trip():
    mech = RRR
    q, _, _ = _motion(mech, n=3)
    J = mb.site_jacobian(mech, q, "platform")
    rng = np.random.default_rng(3)
    W = rng.normal(size=(3, 6))
    s = mb.statics(mech, q, wrenches={"platform": W}, gravity=False)
    assert s.valid.all()
    assert np.max(np.abs(s.tau + np.einsum("nij,ni->nj", J, W))) < IDENTITY_TOL
    # the wrench the mechanism exerts, from the forces that produce it (a wrench in range of J, scaled)
    L = mech.length
    Js = np.concatenate([J[:, :3] * L, J[:, 3:]], axis=1)
    W_out = np.einsum("nij,nj->ni", Js, rng.normal(size=(3, 3)))
    W_out[:, :3] *= L
    tau = np.einsum("nij,ni->nj", J, W_out)
    back = mb.site_wrench(mech, q, "platform", tau, gravity=False)
    assert back.valid.all()
    assert np.max(np.abs(back.wrench - W_out)) < IDENTITY_TOL * max(1.0, np.max(np.abs(W_out)))
    assert np.max(back.residual) < IDENTITY_TOL


@pytest.mark.parametrize("mech", [FOUR_BAR, RRR], ids=["four_bar", "planar_3rrr"])
def test_forward_inverts_inverse(mech):
    q, qd, qdd = _motion(mech, seed=1)
    tau = mb.inverse_dynamics(mech, q, qd, qdd).tau
    f = mb.forward_dynamics(mech, q, qd, tau)
    assert f.valid.all()
    assert np.max(np.abs(f.qdd_act - qdd)) < IDENTITY_TOL


def test_redundant_actuation_rules():
    red = dataclasses.replace(FOUR_BAR, actuated=("theta2", "theta4"))
    q, qd1, qdd1 = _motion(FOUR_BAR, n=3, seed=2)
    ref = mb.inverse_dynamics(FOUR_BAR, q, qd1, qdd1)
    G = mb.influence(FOUR_BAR, q).G  # theta4 rate per unit crank rate (coordinates 0, 1, 2)
    dG = mb.influence(FOUR_BAR, q).dG
    qd = np.concatenate([qd1, G[:, 2] * qd1], axis=-1)
    qdd4 = G[:, 2, 0] * qdd1[:, 0] + dG[:, 2, 0, 0] * qd1[:, 0] ** 2
    qdd = np.concatenate([qdd1, qdd4[:, None]], axis=-1)
    r = mb.inverse_dynamics(red, q, qd, qdd)
    assert r.valid.all()
    # same power as the single actuator, minimum norm among the forces that give it
    assert np.max(np.abs(np.sum(r.tau * qd, -1) - ref.tau[:, 0] * qd1[:, 0])) < IDENTITY_TOL
    c = np.concatenate([np.ones((3, 1)), G[:, 2]], axis=-1)  # the consistent direction
    assert np.max(np.abs(r.tau[:, 0] * c[:, 1] - r.tau[:, 1] * c[:, 0])) < IDENTITY_TOL
    # weights (1, 0): the crank alone carries the load, as the non-redundant model
    r1 = mb.inverse_dynamics(red, q, qd, qdd, weights=[1.0, 0.0])
    assert np.max(np.abs(r1.tau[:, 1])) < IDENTITY_TOL
    assert np.max(np.abs(r1.tau[:, 0] - ref.tau[:, 0])) < IDENTITY_TOL
    # forward dynamics of the redundantly actuated chain undoes either distribution
    for forces in (r.tau, r1.tau):
        f = mb.forward_dynamics(red, q, qd, forces)
        assert f.valid.all() and np.max(np.abs(f.qdd_act - qdd)) < IDENTITY_TOL
    # inconsistent rates are not a motion of the mechanism
    bad = mb.inverse_dynamics(red, q, qd + np.array([0.0, 1.0]), qdd)
    assert not bad.valid.any() and np.all(np.isnan(bad.tau))


def test_type_two_singularity_is_flagged_not_absurd():
    b = mb.Builder("toggle", gravity=(0, -9.81, 0))
    inertial = mb.Inertial(1.0, (0.1, 0.0, 0.0), diaginertia=(0.01,) * 3)
    b.body("crank", joints=[b.hinge("a")], inertial=inertial)
    b.body("coupler", parent="crank", pos=(0, 1, 0), joints=[b.hinge("b")], inertial=inertial)
    b.body("rocker", pos=(2, 0, 0), joints=[b.hinge("c")], inertial=inertial)
    b.connect("C", "coupler", "rocker", anchor1=(1.0, -0.5, 0.0))  # B, C, D collinear at q0
    b.actuate("a")
    mech = b.build()
    q = np.stack([mech.q0, mech.q0])
    fk = mb.forward_kinematics(mech, [-0.05], guess=mech.q0)  # the dyad folds: a regular neighbour
    assert fk.converged
    q[1] = fk.q
    r = mb.inverse_dynamics(mech, q, [[0.0], [0.3]], [[0.0], [0.1]])
    assert not r.valid[0] and np.isnan(r.tau[0]).all()
    assert r.valid[1] and np.isfinite(r.tau[1]).all()
    s = mb.statics(mech, q)
    assert not s.valid[0] and s.valid[1]


def test_nonfinite_sample_is_masked_alone():
    q, qd, qdd = _motion(FOUR_BAR, n=3)
    qd[1, 0] = np.nan
    r = mb.inverse_dynamics(FOUR_BAR, q, qd, qdd)
    assert r.valid.tolist() == [True, False, True]
    good = mb.inverse_dynamics(FOUR_BAR, q[[0, 2]], qd[[0, 2]], qdd[[0, 2]])
    assert np.array_equal(good.tau, r.tau[[0, 2]])


def test_simulation_conserves_energy_and_stays_closed():
    q, qd, _ = _motion(FOUR_BAR, n=2, seed=4)
    sim = mb.simulate(FOUR_BAR, q, qd, np.linspace(0, 0.5, 6))
    assert sim.success.all()
    assert np.max(sim.energy_drift_rel) < 1e-7
    assert np.max(sim.closure) < 1e-10 * FOUR_BAR.length
    # driven: the actuator's work enters the balance
    sim = mb.simulate(FOUR_BAR, q, qd, np.linspace(0, 0.3, 4), tau=[0.5])
    assert sim.success.all() and np.max(sim.energy_drift_rel) < 1e-7 and np.max(np.abs(sim.work)) > 0


def test_com_inverse_dynamics_matches_spatial_form():
    """The centre-of-mass kernel against the body-frame spatial-inertia form of robomech.dynamics."""
    rng = np.random.default_rng(0)
    q, qd, qdd = _motion(RRR, n=2)
    r = mb.inverse_dynamics(RRR, q, qd, qdd)
    # kinetic energy from the com kernel equals the actuator-space quadratic form
    from robomech.multibody import _dynamics as D

    from ._reference import kinematics

    st = kinematics(RRR.tree, q)
    bd = D._bodies(RRR)
    _, J, _ = R._com_jacobians(RRR.tree, st, bd, None, None)
    Rb = st.T[:, bd.idx, :3, :3]
    T = dynamics.com_kinetic_energy(bd.mass, dynamics.world_inertia(Rb, bd.inertia), J, r.qd)
    assert np.max(np.abs(T - 0.5 * np.einsum("ni,nij,nj->n", qd, r.M_a, qd))) < IDENTITY_TOL
    del rng


@pytest.mark.parametrize("name", ["bennett", "delta", "stewart"])
def test_kdot_qd_equals_constraint_jacobian_rate(name):
    """The reference's direct velocity-product closure accelerations against the multibody layer's dK/dt
    (the kernels' are checked against the reference: test_compiled_influence.py)."""
    from ._reference import kinematics

    mech = mb.gallery.load(name)
    q, qd_a, _ = _motion(mech, n=3, seed=6, amp=0.02)
    qd = np.einsum("nij,nj->ni", mb.influence(mech, q, second_order=False).G, qd_a)
    st = kinematics(mech.tree, q)
    ref = np.einsum("nij,nj->ni", mb.constraint_jacobian_rate(mech, q, qd), qd)
    got = R.kdot_qd(mech, st, q, qd, R.screw_rates(mech.tree, st, qd))
    assert np.max(np.abs(got - ref)) < IDENTITY_TOL * max(1.0, np.max(np.abs(ref)))


@pytest.mark.parametrize("name", ["four_bar", "bennett", "delta", "stewart"])
def test_constraint_matrix_equals_multibody_layer(name):
    from ._reference import kinematics

    mech = mb.gallery.load(name)
    q, _, _ = _motion(mech, n=3, seed=7, amp=0.02)
    K = mb.constraint_jacobian(mech, q)
    assert np.max(np.abs(R.constraint_matrix(mech, kinematics(mech.tree, q), q) - K)) < IDENTITY_TOL


def test_screw_rates_flat_equal_screw_rates():
    from ._reference import kinematics

    mech = mb.gallery.load("stewart")
    q, _, _ = _motion(mech, n=3, seed=8, amp=0.02)
    qd = np.random.default_rng(0).normal(size=(3, mech.nv))
    st = kinematics(mech.tree, q)
    diff = R.screw_rates_flat(mech.tree, st, qd) - R.screw_rates(mech.tree, st, qd)
    assert np.max(np.abs(diff)) < IDENTITY_TOL


@settings(max_examples=25, deadline=None)
@given(
    qa=st.floats(-np.pi, np.pi),
    qd=st.floats(-5, 5),
    qdd=st.floats(-20, 20),
    w=st.tuples(st.floats(-2, 2), st.floats(-2, 2), st.floats(-2, 2)),
)
def test_property_four_bar_forward_inverts_inverse_with_site_force(qa, qd, qdd, w):
    """Any crank state and force at the coupler point: forward dynamics undoes inverse dynamics, and the
    actuator power equals the rate of the mechanism's energy minus the power of the external force."""
    fk = mb.forward_kinematics(FOUR_BAR, [qa], steps=4)
    assume(bool(fk.converged))
    W = np.array([0.0, 0.0, 0.0, *w])
    r = mb.inverse_dynamics(FOUR_BAR, fk.q, [qd], [qdd], wrenches={"coupler_point": W})
    assume(bool(r.valid))
    f = mb.forward_dynamics(FOUR_BAR, fk.q, [qd], r.tau, wrenches={"coupler_point": W})
    assert abs(f.qdd_act[0] - qdd) < IDENTITY_TOL * max(1.0, abs(qdd))
    # power: tau qd = dT/dt + dU/dt - W . V_site, with dT/dt + dU/dt = qd_full . (M qdd + c + g) projected
    J = mb.site_jacobian(FOUR_BAR, fk.q, "coupler_point")
    P_ext = W @ (J @ [qd])
    P_int = (r.M_a @ [qdd] + r.velocity_terms + r.gravity_terms) @ [qd]
    assert abs(r.tau @ [qd] - (P_int - P_ext)) < IDENTITY_TOL * max(1.0, abs(P_int), abs(P_ext))


def test_unbatched_calls_return_unbatched_results():
    q = mb.forward_kinematics(FOUR_BAR, [0.2]).q  # (nq,)
    assert mb.inverse_dynamics(FOUR_BAR, q, [1.0], [0.0]).valid.shape == ()
    assert mb.statics(FOUR_BAR, q).tau.shape == (1,)
    assert mb.site_wrench(FOUR_BAR, q, "coupler_point", [0.1]).wrench.shape == (6,)
    assert mb.forward_dynamics(FOUR_BAR, q, [0.1], [0.2]).qdd_act.shape == (1,)
    sim = mb.simulate(FOUR_BAR, q, [1.0], [0.0, 0.01])
    assert sim.q.shape == (2, FOUR_BAR.nq) and sim.success.shape == ()


def test_site_wrench_of_huge_forces_is_flagged_or_right_quietly():
    """Forces of 1e300 either overflow (the sample is flagged, its wrench NaN) or, where the norms do not
    overflow (NumPy >= 2.4 scales its vector norms), the wrench is the unit-force wrench times 1e300 (the
    map tau -> wrench is linear, gravity is negligible beside 1e300): never a wrong value under a True mask,
    and no RuntimeWarning either way."""
    import warnings

    q = mb.forward_kinematics(FOUR_BAR, [[0.2], [0.3]]).q
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = mb.site_wrench(FOUR_BAR, q, "coupler_point", [[1e300], [0.1]])
    unit = mb.site_wrench(FOUR_BAR, q[0], "coupler_point", [1.0], gravity=False).wrench
    assert bool(r.valid[1]) and np.all(np.isfinite(r.wrench[1]))
    if r.valid[0]:
        np.testing.assert_allclose(r.wrench[0] / 1e300, unit, rtol=1e-12, atol=1e-12 * np.abs(unit).max())
    else:
        assert np.all(np.isnan(r.wrench[0]))


# The Delta's round trip below is computed through SVD null-space bases of its 18 x 27 closure
# Jacobian and a 6 x 6 idle mass block; measured <= 1.3e-11 of the largest acceleration (the naive
# round trip misses by ~1e-6 of it).
DELTA_ROUND_TRIP_RTOL = 1e-9
# The actuator-rate inverse's idle torque is ~7e-6 of the generalized forces on the gallery Delta
# (the forearm rods' axial inertia); a thousandth of that is far above rounding and below the effect.
IDLE_TORQUE_FLOOR = 1e-9


def test_delta_round_trip_differs_by_the_idle_torque_alone():
    """On the Delta, ``forward_dynamics(inverse_dynamics(qd_act, qdd_act).tau)`` is not ``qdd_act``:
    the actuator-rate inverse prescribes the idle spins' accelerations (``G qdd_act + Gdot qd_act``,
    minimum norm), which needs a torque ``h = N_i^T f`` on them that no actuator supplies; forward
    dynamics leaves them free.  Shown with the tree's own ``M`` and ``f`` (RNEA/CRBA): forward dynamics
    is the prescribed motion plus the constrained response to ``-h``, and the inverse whose idle spins
    are torque-free (``N_i^T f = 0``) round-trips to rounding."""
    from scipy.linalg import null_space

    mech = mb.gallery.load("delta")
    rng = np.random.default_rng(3)
    na, n = len(mech.actuated), 4
    qa = mech.q0[mech.tree.act_qadr] + 0.2 * rng.uniform(-1, 1, (n, na))
    fk = mb.forward_kinematics(mech, qa)
    assert fk.converged.all()
    q, qd_a, qdd_a = fk.q, rng.normal(size=(n, na)), 3 * rng.normal(size=(n, na))
    inf = mb.influence(mech, q)
    qd = np.einsum("nij,nj->ni", inf.G, qd_a)
    qdd = np.einsum("nij,nj->ni", inf.G, qdd_a) + np.einsum("nijk,nj,nk->ni", inf.dG, qd_a, qd_a)
    r = mb.inverse_dynamics(mech, q, qd_a, qdd_a)
    fd = mb.forward_dynamics(mech, q, qd_a, r.tau)
    assert r.valid.all() and fd.valid.all()
    f = mb.generalized_forces(mech, q, qd, qdd)
    scale = np.abs(fd.qdd).max()
    assert np.max(np.abs(np.einsum("nij,ni->nj", inf.G, f) - r.tau)) < IDENTITY_TOL * np.abs(f).max()
    K, M = mb.constraint_jacobian(mech, q), mb.mass_matrix(mech, q)
    E = np.zeros((mech.nv, na))
    E[mech.tree.act_dof, np.arange(na)] = 1.0
    for i in range(n):
        Ni = null_space(np.vstack([K[i], E.T]))  # the idle motions: admissible, every actuator locked
        assert Ni.shape[1] == mb.mobility(mech).idle_dof == 6
        h = Ni.T @ f[i]
        assert np.abs(h).max() > IDLE_TORQUE_FLOOR * np.abs(f[i]).max()  # the gap is real, not rounding
        Nb = null_space(K[i])
        response = Nb @ np.linalg.solve(Nb.T @ M[i] @ Nb, -Nb.T @ (Ni @ h))
        assert np.abs(qdd[i] + response - fd.qdd[i]).max() < DELTA_ROUND_TRIP_RTOL * scale
        # torque-free idle spins: the physical inverse, which forward dynamics inverts
        qdd_free = qdd[i] - Ni @ np.linalg.solve(Ni.T @ M[i] @ Ni, h)
        f_free = mb.generalized_forces(mech, q[i], qd[i], qdd_free)
        back = mb.forward_dynamics(mech, q[i], qd_a[i], inf.G[i].T @ f_free)
        assert np.abs(back.qdd_act - qdd_a[i]).max() < DELTA_ROUND_TRIP_RTOL * scale


# Round trip through two closed-chain solves at regular states: measured <= 3e-13 relative on the
# gallery mechanisms without idle motions.
ROUND_TRIP_RTOL = 1e-10


@pytest.mark.parametrize(
    "name", [n for n in mb.gallery.NAMES if mb.mobility(mb.gallery.load(n)).idle_dof == 0]
)
def test_gallery_forward_inverts_inverse_without_idle_motions(name):
    mech = mb.gallery.load(name)
    rng = np.random.default_rng(1)
    na = len(mech.actuated)
    scale = np.where(mech.tree.dof_translational[mech.tree.act_dof], mech.length, 1.0)
    fk = mb.forward_kinematics(mech, mech.q0[mech.tree.act_qadr] + 0.05 * scale * rng.uniform(-1, 1, (4, na)))
    assert fk.converged.all()
    qd, qdd = rng.normal(size=(4, na)), rng.normal(size=(4, na))
    r = mb.inverse_dynamics(mech, fk.q, qd, qdd)
    f = mb.forward_dynamics(mech, fk.q, qd, r.tau)
    assert r.valid.all() and f.valid.all()
    assert np.abs(f.qdd_act - qdd).max() < ROUND_TRIP_RTOL * np.abs(qdd).max()
