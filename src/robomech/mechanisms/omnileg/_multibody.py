"""The OmniLeg described generically (``robomech.multibody``), from its parameters.

Nothing is derived by hand here: the generic layer assembles the closures and differentiates them,
and the tests compare the result with the analytic model (eq. (11) FK, the PoE thigh closure, the
foot J and H) to 1e-10.

* Thigh (paper 2, eqs. (1)-(7)): chain k's joints are chain 1's screws (axes y, x at A1 = (0, L3, 0);
  x, y at B1 = (0, L3, L1)) rotated by kR = Rz(-δ), δ = (k-1) π/2, as printed (eq. (5)).  Chain 1's four
  hinges carry the knee plate; chains 2 and 3 keep three hinges in the tree and close on the knee plate
  through their fourth joint (a hinge cut, ``revolute`` closure).  qpos of ``theta{k}{j}`` = θ_kj.
* Shank (eq. (10), Fig. 4e): each chain C_iD_iE_i is a crank (hinge about its radial axis at C_i,
  ``knee_to_crank`` below O0'), a coupler (hinge at D_i) and the foot (hinge at E_i on chain 1, hinge
  cuts on chains 2 and 3).  The three cranks turn together (one motor through bevel gears): cranks 2
  and 3 are coupled to crank 1 (joint couplings).  qpos of ``crank1`` = γ.  The reference
  configuration is γ = 60° (γ = 0 folds every chain straight, a singular configuration).
* The double-Cardan drive shaft inside the thigh is not described: it carries γ to the knee with a
  1:1 ratio (exact, see the analytic model) and changes no position; the dynamics layer may add it.
* Inertias are not attached (the analytic model's body frames differ; see ``_dynamics.py``).

``q_act = (α, β, γ)`` in the analytic model's order (actuators θ21, θ11, crank1); the foot site is
the foot point, whose position is eq. (11).
"""

from __future__ import annotations

import numpy as np

from robomech.multibody import Builder, Mechanism

from ._params import OmniLeg

__all__ = ["REFERENCE_GAMMA", "to_multibody"]

# Reference (qpos0) crank angle: the gait's start FK(0, 0, 60 deg) (docs/mechanisms/omnileg.md).
REFERENCE_GAMMA = np.deg2rad(60.0)


def _kR(k: int) -> np.ndarray:
    d = 0.5 * np.pi * k
    c, s = np.cos(d), np.sin(d)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])  # paper 2, eq. (5): Rz(-δ), as printed


def _quat(R: np.ndarray) -> tuple[float, ...]:
    from robomech.multibody._model import _quat_from_matrix

    return tuple(_quat_from_matrix(R))


def to_multibody(leg: OmniLeg) -> Mechanism:
    """The generic description of ``leg`` (an :class:`OmniLeg`); q_act = (α, β, γ)."""
    if not isinstance(leg, OmniLeg):
        raise ValueError(f"Expected leg to be an OmniLeg, got {type(leg).__name__}.")
    L1, L3, L4 = leg.L1, leg.L3, leg.L4
    b = Builder("omnileg", gravity=leg.gravity)
    w1 = np.array([[0.0, 1, 0], [1, 0, 0], [1, 0, 0], [0, 1, 0]])  # paper 2, eq. (1)
    p1 = np.array([[0.0, L3, 0], [0, L3, 0], [0, L3, L1], [0, L3, L1]])  # eq. (2)
    knee = np.array([0.0, 0.0, L1])  # O0' at the home pose (eq. (3))
    for k in range(3):
        w, p = w1 @ _kR(k).T, p1 @ _kR(k).T  # eqs. (6), (7)
        c = k + 1
        # every body frame is parallel to the hip frame at the home pose, so qpos = the PoE angles
        b.body(f"hip_cross{c}", pos=p[0], joints=[b.hinge(f"theta{c}1", axis=w[0])])
        b.body(f"thigh_rod{c}", f"hip_cross{c}", joints=[b.hinge(f"theta{c}2", axis=w[1])])
        b.body(f"knee_cross{c}", f"thigh_rod{c}", pos=p[2] - p[0], joints=[b.hinge(f"theta{c}3", axis=w[2])])
        if k == 0:
            b.body(
                "knee_plate",
                "knee_cross1",
                pos=knee - p[2],
                joints=[b.hinge("theta14", axis=w[3], pos=p[3] - knee)],
            )
        else:
            b.revolute(f"theta{c}4", f"knee_cross{c}", "knee_plate", anchor1=(0.0, 0.0, 0.0), axis=w[3])
    # shank: chain i in the plane normal to its radial axis x_i (frame S_i = Rz(ψ_i))
    g0 = float(REFERENCE_GAMMA)
    psi = leg.shank_azimuth + 2.0 * np.pi * np.arange(3) / 3.0
    e_plane = leg.knee_to_crank + 2.0 * L4 * np.cos(g0)  # depth of the E plane below O0' (eq. (10))
    for i in range(3):
        c = i + 1
        S = np.array(
            [[np.cos(psi[i]), -np.sin(psi[i]), 0.0], [np.sin(psi[i]), np.cos(psi[i]), 0.0], [0, 0, 1.0]]
        )
        C = S @ np.array([leg.shank_radius, 0.0, leg.knee_to_crank])
        Rc = S @ np.array(
            [[1.0, 0, 0], [0, np.cos(g0), -np.sin(g0)], [0, np.sin(g0), np.cos(g0)]]
        )  # S_i Rx(γ0)
        # crank: z along C_iD_i; coupler: z along D_iE_i at angle -γ, i.e. Rx(-2γ) relative to the crank
        b.body(
            f"crank{c}",
            "knee_plate",
            pos=C,
            quat=_quat(Rc),
            joints=[b.hinge(f"crank{c}", axis=(1, 0, 0), ref=g0)],
        )
        Rrel = np.array(
            [[1.0, 0, 0], [0, np.cos(2 * g0), np.sin(2 * g0)], [0, -np.sin(2 * g0), np.cos(2 * g0)]]
        )
        b.body(
            f"coupler{c}",
            f"crank{c}",
            pos=(0.0, 0.0, L4),
            quat=_quat(Rrel),
            joints=[b.hinge(f"coupler{c}", axis=(1, 0, 0), ref=-2 * g0)],
        )
        E = S @ np.array([leg.shank_radius, 0.0, 0.0])  # E_i relative to the centre of the E plane
        if i == 0:
            Rc_world = Rc @ Rrel  # coupler 1's frame in the knee plate
            foot_origin = np.array([0.0, 0.0, e_plane])
            b.body(
                "foot",
                "coupler1",
                pos=Rc_world.T @ (foot_origin - (C + Rc @ np.array([0.0, 0.0, L4]))),
                quat=_quat(Rc_world.T),
                joints=[b.hinge("foot", axis=S[:, 0], pos=E, ref=0.0)],
            )
        else:
            b.revolute(f"E{c}", f"coupler{c}", "foot", anchor1=(0.0, 0.0, L4), axis=(1.0, 0.0, 0.0))
            b.couple(f"gear{c}", f"crank{c}", "crank1", (0.0, 1.0))
    b.site("foot", "foot", pos=(0.0, 0.0, leg.L5 - leg.knee_to_crank))
    b.actuate("theta21", "theta11", "crank1")
    return b.build()
