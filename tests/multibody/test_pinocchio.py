"""The Pinocchio bridge against the engine: a second, independent implementation of the tree's dynamics
(Pinocchio's RNEA / CRBA) and of the closures (its rigid constraint models) on every gallery mechanism and
the three rigid paper descriptions."""

from __future__ import annotations

import numpy as np
import pytest

from robomech import multibody as mb

pin = pytest.importorskip("pinocchio", reason="no Pinocchio (pip install 'robomech[pinocchio]')")

# Two exact implementations of the same rigid-body algorithms: they differ by rounding only
# (measured <= 1e-15 relative on these mechanisms); 1e-10 leaves room for larger trees.
AGREE_RTOL = 1e-10
SPREAD = 0.05  # rad (or times the characteristic length) around the reference: assembles on every one


def _descriptions():
    from robomech.mechanisms import omnileg as ol
    from robomech.mechanisms import spherical_leg as sl
    from robomech.mechanisms import vectored_thrust as vt

    out = {n: (lambda n=n: mb.gallery.load(n)) for n in mb.gallery.NAMES}
    out["spherical-leg"] = lambda: sl.to_multibody(sl.SphericalLeg.paper(), actuate="platform")
    out["omnileg"] = lambda: ol.to_multibody(ol.OmniLeg.paper())
    out["vectored-thrust"] = lambda: vt.to_multibody(vt.VectoredThruster.paper())
    return out


DESCRIPTIONS = _descriptions()


def _state(mech, seed):
    rng = np.random.default_rng(seed)
    scale = np.where(mech.tree.dof_translational[mech.tree.act_dof], mech.length, 1.0)
    qa = mech.q0[mech.tree.act_qadr] + SPREAD * scale * rng.uniform(-1, 1, len(mech.actuated))
    fk = mb.forward_kinematics(mech, qa)
    assert fk.converged
    return fk.q, rng.normal(size=mech.nv), rng.normal(size=mech.nv)


@pytest.mark.parametrize("name", list(DESCRIPTIONS))
def test_pinocchio_model_agrees_with_the_engine(name):
    mech = DESCRIPTIONS[name]()
    P = mb.to_pinocchio(mech)
    model, data = P.model, P.model.createData()
    assert model.nv == mech.nv and len(P.constraints) >= 1
    for seed in range(3):
        q, qd, qdd = _state(mech, seed)
        qp, vp, ap = P.state(q, qd, qdd)
        T = P.velocity_map(q)
        tau = mb.generalized_forces(mech, q, qd, qdd)
        tp = pin.rnea(model, data, qp, vp, ap)
        np.testing.assert_allclose(tp, T.T @ tau, rtol=0, atol=AGREE_RTOL * max(1.0, np.abs(tau).max()))
        M = mb.mass_matrix(mech, q)
        Mp = pin.crba(model, data, qp)
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        np.testing.assert_allclose(Mp, T.T @ M @ T, rtol=0, atol=AGREE_RTOL * np.abs(M).max())
        # every body's frame where the engine puts it
        pin.framesForwardKinematics(model, data, qp)
        from robomech.multibody._compile import compile_model

        from ._reference import kinematics

        Tw = kinematics(compile_model(mech).tree, q[None]).T[0]
        for b, fid in P.body_frames.items():
            k = mech.tree.body_index(b)
            np.testing.assert_allclose(data.oMf[fid].homogeneous, Tw[k], atol=AGREE_RTOL * mech.length)
        # the closures close in Pinocchio at the engine's assembled configuration
        for cm in P.constraints:
            o1 = data.oMi[cm.joint1_id] * cm.joint1_placement
            o2 = data.oMi[cm.joint2_id] * cm.joint2_placement
            assert np.abs(o1.translation - o2.translation).max() < AGREE_RTOL * mech.length


def test_the_check_has_teeth():
    """A 1 % heavier body on the Pinocchio side is far outside the agreement tolerance."""
    mech = mb.gallery.load("delta")
    P = mb.to_pinocchio(mech)
    model = P.model
    body = model.inertias[3]
    model.inertias[3] = pin.Inertia(1.01 * body.mass, body.lever, body.inertia)
    q, qd, qdd = _state(mech, 0)
    qp, vp, ap = P.state(q, qd, qdd)
    tau = mb.generalized_forces(mech, q, qd, qdd)
    err = np.abs(pin.rnea(model, model.createData(), qp, vp, ap) - P.velocity_map(q).T @ tau).max()
    assert err > 1e3 * AGREE_RTOL * np.abs(tau).max()


def test_couplings_are_named_and_foreign_objects_refused():
    from robomech.mechanisms import spherical_leg as sl

    mech = sl.to_multibody(sl.SphericalLeg.paper())
    assert mb.to_pinocchio(mech).couplings == tuple(c.name for c in mech.couplings) != ()
    with pytest.raises(ValueError, match="mech"):
        mb.to_pinocchio("delta")


@pytest.mark.parametrize("name", list(mb.gallery.NAMES))
def test_constrained_forward_dynamics_agrees_with_pinocchio(name):
    """``mb.forward_dynamics`` under random actuator forces at an admissible state = Pinocchio's
    ``constraintDynamics`` with the bridge's constraint models (no Baumgarte terms; an exact KKT solve)."""
    mech = mb.gallery.load(name)
    P = mb.to_pinocchio(mech)
    model, data = P.model, P.model.createData()
    rng = np.random.default_rng(7)
    q, _, _ = _state(mech, 7)
    G = mb.influence(mech, q, second_order=False).G
    qd = G @ rng.normal(size=len(mech.actuated))  # an admissible velocity
    tau_a = rng.normal(size=len(mech.actuated))
    fd = mb.forward_dynamics(mech, q, qd[mech.tree.act_dof], tau_a)
    assert fd.valid
    qp, vp, a_engine = P.state(q, qd, fd.qdd)
    E = np.zeros((mech.nv, len(mech.actuated)))
    E[mech.tree.act_dof, np.arange(len(mech.actuated))] = 1.0
    models, datas = pin.StdVec_RigidConstraintModel(), pin.StdVec_RigidConstraintData()
    for cm in P.constraints:
        models.append(cm)
        datas.append(cm.createData())
    pin.initConstraintDynamics(model, data, models, datas)
    prox = pin.ProximalSettings(1e-14, 1e-12, 100)
    a = pin.constraintDynamics(model, data, qp, vp, P.velocity_map(q).T @ (E @ tau_a), models, datas, prox)
    np.testing.assert_allclose(a, a_engine, rtol=0, atol=AGREE_RTOL * np.abs(a_engine).max())
