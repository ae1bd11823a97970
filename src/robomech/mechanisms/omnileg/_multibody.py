"""The OmniLeg described generically (``robomech.multibody``): the analytic model's 22 bodies, tree joints,
closures and gear couplings, body by body in docs/mechanisms/omnileg.md, "Generic description"."""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from robomech._validation import check_params
from robomech.multibody import Builder, Inertial, Mechanism
from robomech.multibody._model import _quat_from_matrix
from robomech.spatial import rot_x, rot_z

from ._params import OmniLeg, RigidBody

__all__ = ["REFERENCE_GAMMA", "to_multibody"]

# Reference (qpos0) crank angle: the gait's start FK(0, 0, 60 deg) (docs/mechanisms/omnileg.md).
REFERENCE_GAMMA = float(np.deg2rad(60.0))

Matrix = NDArray[np.float64]


def _kR(k: int) -> Matrix:
    d = 0.5 * np.pi * k
    c, s = np.cos(d), np.sin(d)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])  # paper 2, eq. (5): Rz(-δ), as printed


def _frame(name: str) -> Matrix:
    """The analytic model's body frame of ``name`` in this description's body frame (constant).

    Every body frame here is parallel to the hip frame at α = β = 0 and moves with its body; the
    analytic frames (``_dynamics._poses``) of chain k's crosses and rod are chain 1's rotated by kR
    (their x axis is the carried joint axis x_k, kR e_x); every other analytic frame coincides with
    the body frame here.  ``test_omnileg_generic_dynamics`` checks R_here(q) _frame = R_analytic(q).
    """
    for k in range(3):
        if name in (f"hip_cross_{k + 1}", f"thigh_rod_{k + 1}", f"knee_cross_{k + 1}"):
            return _kR(k)
    return np.eye(3)


def _inertial(body: RigidBody, Q: Matrix) -> Inertial:
    """``body`` (analytic frame) as an :class:`Inertial` of a body whose frame maps the analytic one by Q."""
    inertia = Q @ body.inertia_matrix @ Q.T
    inertia = 0.5 * (inertia + inertia.T)
    d, V = np.linalg.eigh(inertia)
    if np.linalg.det(V) < 0:  # a proper rotation for the quaternion
        V[:, 2] = -V[:, 2]
    return Inertial(
        body.mass,
        pos=tuple(float(v) for v in Q @ body.com_vector),
        quat=tuple(_quat_from_matrix(V)),
        diaginertia=tuple(float(max(v, 0.0)) for v in d),
    )


def chain_axes(L1: float, L3: float) -> tuple[Matrix, Matrix]:
    """Axes ``w`` and points ``p`` (3, 4, 3) of the UU chains' joints at the home pose (eqs. (1)-(7))."""
    w1 = np.array([[0.0, 1, 0], [1, 0, 0], [1, 0, 0], [0, 1, 0]])  # paper 2, eq. (1)
    p1 = np.array([[0.0, L3, 0], [0, L3, 0], [0, L3, L1], [0, L3, L1]])  # eq. (2)
    return np.stack([w1 @ _kR(k).T for k in range(3)]), np.stack(
        [p1 @ _kR(k).T for k in range(3)]
    )  # eqs. (6), (7)


def _add_thigh(
    b: Builder, L1: float, L3: float, inertial: Callable[[str, str], Inertial] | None = None
) -> None:
    """The three UU chains and the knee plate; chains 2 and 3 close on it through their fourth joint."""
    knee = np.array([0.0, 0.0, L1])  # O0' at the home pose (eq. (3))

    def body(name: str, parent: str, kind: str, **kw: Any) -> None:
        b.body(name, parent, inertial=None if inertial is None else inertial(name, kind), **kw)

    for k, (w, p) in enumerate(zip(*chain_axes(L1, L3), strict=True)):
        c = k + 1
        # every body frame is parallel to the hip frame at the home pose, so qpos = the PoE angles
        hc, tr, kc = f"hip_cross_{c}", f"thigh_rod_{c}", f"knee_cross_{c}"
        body(hc, "world", "hip_cross", pos=p[0], joints=[b.hinge(f"theta{c}1", axis=w[0])])
        body(tr, hc, "thigh_rod", joints=[b.hinge(f"theta{c}2", axis=w[1])])
        body(kc, tr, "knee_cross", pos=p[2] - p[0], joints=[b.hinge(f"theta{c}3", axis=w[2])])
        if k == 0:
            hinge = b.hinge("theta14", axis=w[3], pos=p[3] - knee)
            body("knee_plate", kc, "knee_plate", pos=knee - p[2], joints=[hinge])
        else:
            b.revolute(f"theta{c}4", kc, "knee_plate", anchor1=(0.0, 0.0, 0.0), axis=w[3])


@functools.lru_cache(maxsize=8)
def thigh_mechanism(L1: float, L3: float) -> Mechanism:
    """The thigh alone (no inertias): q_act = (α, β) = (θ21, θ11), site ``knee`` at O0'."""
    b = Builder("omnileg_thigh")
    _add_thigh(b, L1, L3)
    b.site("knee", "knee_plate")
    b.actuate("theta21", "theta11")
    return b.build()


def to_multibody(leg: OmniLeg) -> Mechanism:
    """The generic description of ``leg`` with its inertias: q_act = (α, β, γ) (actuators ``theta21``,
    ``theta11``, ``drive_in``), site ``foot`` at the foot point, reference γ = ``REFERENCE_GAMMA``.

    Parameters
    ----------
    leg : OmniLeg

    Returns
    -------
    Mechanism
    """
    check_params(leg, OmniLeg, "leg")
    L1, L4 = leg.L1, leg.L4
    bodies = leg.bodies

    def inertial(name: str, kind: str) -> Inertial:
        return _inertial(bodies[kind], _frame(name))

    b = Builder("omnileg", gravity=leg.gravity)
    _add_thigh(b, leg.L1, leg.L3, inertial)
    g0 = REFERENCE_GAMMA
    # drive (paper 2, Fig. 7): input shaft about Z0 turned by γ, U joint A4 at O0, rod A4B4, U joint B4
    # at O0', output shaft about Z0' in the knee plate; every frame is Rz(γ) at α = β = 0.
    # paper 2, eqs. (26)-(31): the paper decouples the drive's spin from the thigh motion; here the
    # closure solves the double Cardan exactly (as the analytic model does, docs departure 9).
    Rg0 = _quat_from_matrix(rot_z(g0))
    b.body(
        "drive_shaft_in",
        quat=Rg0,
        joints=[b.hinge("drive_in", axis=(0, 0, 1), ref=g0)],
        inertial=inertial("drive_shaft_in", "drive_shaft_in"),
    )
    b.body(
        "drive_cross_a",
        "drive_shaft_in",
        joints=[b.hinge("drive_phi1", axis=(0, 1, 0))],  # about the shaft's yoke arm a1 = Rz(γ) e_y
        inertial=inertial("drive_cross_a", "drive_cross"),
    )
    b.body(
        "drive_rod",
        "drive_cross_a",
        joints=[b.hinge("drive_phi2", axis=(1, 0, 0))],  # about the rod's yoke arm a2
        inertial=inertial("drive_rod", "drive_rod"),
    )
    b.body(
        "drive_cross_b",
        "drive_rod",
        pos=(0.0, 0.0, L1),
        joints=[b.hinge("drive_phi3", axis=(1, 0, 0))],  # in-phase yokes: the rod's arm at B4 is a2 too
        inertial=inertial("drive_cross_b", "drive_cross"),
    )
    b.body(
        "drive_shaft_out",
        "knee_plate",
        quat=Rg0,
        joints=[b.hinge("drive_out", axis=(0, 0, 1), ref=g0)],
        inertial=inertial("drive_shaft_out", "drive_shaft_out"),
    )
    b.revolute("drive_B4", "drive_cross_b", "drive_shaft_out", anchor1=(0.0, 0.0, 0.0), axis=(0, 1, 0))
    # shank: chain i in the plane normal to its radial axis x_i (frame S_i = Rz(ψ_i))
    psi = leg.shank_azimuth + 2.0 * np.pi * np.arange(3) / 3.0
    e_plane = leg.knee_to_crank + 2.0 * L4 * np.cos(g0)  # depth of the E plane below O0' (eq. (10))
    for i in range(3):
        c = i + 1
        S = rot_z(float(psi[i]))
        C = S @ np.array([leg.shank_radius, 0.0, leg.knee_to_crank])
        Rc = S @ rot_x(g0)
        # crank: z along C_iD_i; coupler: z along D_iE_i at angle -γ, i.e. Rx(-2γ) relative to the crank
        b.body(
            f"crank_{c}",
            "knee_plate",
            pos=C,
            quat=_quat_from_matrix(Rc),
            joints=[b.hinge(f"crank_{c}", axis=(1, 0, 0), ref=g0)],
            inertial=inertial(f"crank_{c}", "crank"),
        )
        Rrel = rot_x(-2.0 * g0)
        b.body(
            f"coupler_{c}",
            f"crank_{c}",
            pos=(0.0, 0.0, L4),
            quat=_quat_from_matrix(Rrel),
            joints=[b.hinge(f"coupler_{c}", axis=(1, 0, 0), ref=-2 * g0)],
            inertial=inertial(f"coupler_{c}", "coupler"),
        )
        E = S @ np.array([leg.shank_radius, 0.0, 0.0])  # E_i relative to the centre of the E plane
        if i == 0:
            Rc_world = Rc @ Rrel  # coupler 1's frame in the knee plate
            foot_origin = np.array([0.0, 0.0, e_plane])
            b.body(
                "foot",
                "coupler_1",
                pos=Rc_world.T @ (foot_origin - (C + Rc @ np.array([0.0, 0.0, L4]))),
                quat=_quat_from_matrix(Rc_world.T),
                # the foot turns by γ relative to coupler 1 (qpos = γ, as joint_motion)
                joints=[b.hinge("foot", axis=tuple(S[:, 0]), pos=tuple(E), ref=g0)],
                inertial=inertial("foot", "foot"),
            )
        else:
            b.revolute(f"E{c}", f"coupler_{c}", "foot", anchor1=(0.0, 0.0, L4), axis=(1.0, 0.0, 0.0))
        b.couple(f"gear_{c}", f"crank_{c}", "drive_out", (0.0, 1.0))  # 1:1 bevel gear
    b.site("foot", "foot", pos=(0.0, 0.0, leg.L5 - leg.knee_to_crank))
    b.actuate("theta21", "theta11", "drive_in")
    return b.build()
