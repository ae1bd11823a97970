"""Forward kinematics beyond |α|, |β| = 90° is not mirrored (issue 14, defect 4)."""

from __future__ import annotations

import numpy as np

import robomech.mechanisms.omnileg as ol
from robomech.testing import numerical_hessian, numerical_jacobian

LEG = ol.OmniLeg.paper()
# Closed forms vs the PoE closure solved by Gauss-Newton: both exact to rounding (the closure's own
# tolerance is 1e-12, tests/mechanisms/omnileg/test_omnileg_chains.py).
CLOSURE_TOL = 1e-10
# Central differences (robomech.testing step) of O(0.1) m functions: truncation and rounding ~1e-11.
FD_TOL = 1e-8
# A continuous pose moves by at most |J| Δq per step: |J| <= L1 + 2 L4 < 0.4 m/rad.
LIPSCHITZ = 0.4


def test_fk_beyond_90_degrees_is_the_closure_of_the_three_chains():
    q = np.array([[0.3, 1.9, 0.2], [2.0, -2.5, 0.4], [-1.8, 0.4, 0.1], [2.6, 2.2, 0.0]])
    closure = ol.thigh_closure(LEG, q[:, 0], q[:, 1])
    assert closure.converged.all()
    knee = ol.forward_kinematics(LEG, q) - np.stack(
        [0 * q[:, 2], 0 * q[:, 2], LEG.L5 + 2 * LEG.L4 * np.cos(q[:, 2])], -1
    )
    np.testing.assert_allclose(knee, closure.knee, atol=CLOSURE_TOL)
    np.testing.assert_allclose(ol.thigh_direction(q[:, 0], q[:, 1]) * LEG.L1, closure.knee, atol=CLOSURE_TOL)


def test_fk_of_alpha_2_rad_puts_the_knee_above_the_hip():
    # FK([2, 0, 0]) was the mirror image (knee below the hip, y > 0): the thigh turned 115° about X0
    # points up and to -Y0.
    p = ol.forward_kinematics(LEG, [2.0, 0.0, 0.0]) - np.array([0.0, 0.0, LEG.L5 + 2 * LEG.L4])
    np.testing.assert_allclose(p, LEG.L1 * np.array([0.0, -np.sin(2.0), np.cos(2.0)]), atol=1e-15)


def test_fk_is_continuous_through_90_degrees():
    t = np.linspace(-np.pi, np.pi, 4001)
    for beta in (0.0, 0.7, 2.0):
        q = np.stack([t, np.full_like(t, beta), np.full_like(t, 0.3)], -1)
        step = np.linalg.norm(np.diff(ol.forward_kinematics(LEG, q), axis=0), axis=-1)
        assert step.max() <= LIPSCHITZ * (t[1] - t[0])
        q = np.stack([np.full_like(t, beta), t, np.full_like(t, 0.3)], -1)
        step = np.linalg.norm(np.diff(ol.forward_kinematics(LEG, q), axis=0), axis=-1)
        assert step.max() <= LIPSCHITZ * (t[1] - t[0])


def test_jacobian_and_hessian_beyond_90_degrees_match_central_differences():
    rng = np.random.default_rng(3)
    q = np.stack([rng.uniform(-3, 3, 200), rng.uniform(-3, 3, 200), rng.uniform(-1.4, 1.4, 200)], -1)
    # stay away from α = β = ±90° together (the chains' carried axes parallel, |w| = 0)
    w = np.sqrt(np.cos(q[:, 0]) ** 2 + (np.cos(q[:, 1]) * np.sin(q[:, 0])) ** 2)
    q = q[w > 0.2]
    np.testing.assert_allclose(
        ol.jacobian(LEG, q), numerical_jacobian(lambda x: ol.forward_kinematics(LEG, x), q), atol=FD_TOL
    )
    np.testing.assert_allclose(
        ol.hessian(LEG, q), numerical_hessian(lambda x: ol.jacobian(LEG, x), q), atol=FD_TOL
    )


def test_dynamics_follow_the_unmirrored_pose():
    # the potential energy of the knee plate is -m g z_knee: its gradient is the gravity torque's share,
    # and it must follow the unmirrored knee (z < 0 beyond 90°).
    q = np.array([[2.0, 0.1, 0.3], [0.4, 0.3, 0.3]])
    _, p = ol.body_poses(LEG, q)
    k = ol.BODY_NAMES.index("knee_plate")
    knee = ol.thigh_direction(q[:, 0], q[:, 1]) * LEG.L1
    np.testing.assert_allclose(p[:, k] - knee, [[0, 0, LEG.knee_to_crank / 2]] * 2, atol=1e-15)


def test_passive_angles_beyond_90_degrees_are_the_closure_angles():
    q = np.array([[0.3, 1.9], [2.0, -2.5], [-1.8, 0.4], [2.6, 2.2], [0.4, 0.3]])
    c = ol.thigh_closure(LEG, q[:, 0], q[:, 1])
    assert c.converged.all()
    t12, t22 = ol.passive_angles(LEG, q[:, 0], q[:, 1])

    def wrap(x):  # the closure's angles are unwrapped
        return (x + np.pi) % (2 * np.pi) - np.pi

    np.testing.assert_allclose(wrap(c.theta[:, 0, 1] - t12), 0.0, atol=CLOSURE_TOL)
    np.testing.assert_allclose(wrap(c.theta[:, 1, 1] - t22), 0.0, atol=CLOSURE_TOL)
