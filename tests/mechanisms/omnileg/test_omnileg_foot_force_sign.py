"""One foot-force sign convention across the OmniLeg's dynamics and statics (issue 14, defect 2)."""

from __future__ import annotations

import dataclasses

import numpy as np

import robomech.mechanisms.omnileg as ol

LEG = ol.OmniLeg.paper()
WEIGHTLESS = dataclasses.replace(LEG, gravity=(0.0, 0.0, 0.0))
Q = np.array([[0.3, -0.2, 0.6], [-0.5, 0.4, 1.2], [0.1, 0.6, 0.3]])
F = np.array([[0.0, -20.0, 20.0], [5.0, 1.0, -30.0], [-3.0, 2.0, 10.0]])
# Exact linear maps of the same J: rounding only.
TOL = 1e-12


def test_static_torques_are_the_foot_terms_of_inverse_dynamics():
    z = np.zeros_like(Q)
    still = ol.inverse_dynamics(WEIGHTLESS, Q, z, z, foot_force=F).tau
    np.testing.assert_allclose(ol.static_torques(LEG, Q, F), still, atol=TOL)
    assert ol.FOOT_FORCE_CONVENTION == "applied to the foot"


def test_foot_force_from_torques_inverts_the_foot_terms():
    z = np.zeros_like(Q)
    tau = ol.inverse_dynamics(LEG, Q, z, z, foot_force=F).foot_terms
    r = ol.foot_force_from_torques(LEG, Q, tau)
    assert not r.singular.any()
    np.testing.assert_allclose(r.force, F, atol=1e-9)
    np.testing.assert_allclose(r.residual, 0.0, atol=1e-9)


def test_a_ground_reaction_pushing_the_foot_up_needs_a_shank_torque_that_resists_it():
    # a ground reaction along -Z0 (toward the hip) does positive work on increasing γ (dp_z/dγ =
    # -2 L4 sin γ < 0 lifts the foot): the motor holding the pose must push back, τ_γ < 0.
    q = np.array([0.0, 0.0, 0.8])
    tau = ol.static_torques(LEG, q, [0.0, 0.0, -30.0])
    np.testing.assert_allclose(tau[2], -2 * LEG.L4 * np.sin(0.8) * 30.0, rtol=1e-12)
