"""Four mechanisms outside the gallery, described with the Builder as a new user would.

- ``five_bar_along_x``: a planar five-bar (RRRRR) whose links all lie along x at the reference, so the
  loop is open there (the tips are ``B`` apart) and the Builder assembles it at build;
- ``agile_eye``: a spherical 3-RRR wrist of the Agile-Eye type (Gosselin & Hamel 1994): every axis
  through one centre, base axes u_i, intermediate axes w_i and platform axes v_i mutually orthogonal
  at the reference (u_i = e_i, w_i = e_{i+1}, v_i = e_{i+2});
- ``sarrus``: a Sarrus linkage, two planar RRR legs with orthogonal hinge axes between a fixed base
  and a top plate that can only translate vertically (one DOF though Grübler counts none);
- ``tsai_3upu``: Tsai's translational 3-UPU (Tsai 1996): U joints whose intermediate axes are
  parallel and whose outer axes are tangent to base and platform circles, prismatic legs actuated.

Every body frame is at the world origin at the reference (body ``pos`` zero), so joint positions and
axes are written in world coordinates of the reference.
"""

from __future__ import annotations

import numpy as np

from robomech.multibody import Builder, Inertial, Mechanism

# Link masses and rods' inertias: any positive values give a regular mass matrix (kg, kg m^2).
LINK_MASS = 0.2


def _rod(a, b, mass: float = LINK_MASS) -> Inertial:
    """A thin rod from a to b (world points of the reference): centre of mass midway, inertia of a rod
    about its centre (m L^2 / 12) about every axis (a thin rod's third moment, made isotropic so that
    no frame rotation is needed; any positive inertia serves these tests)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    length = float(np.linalg.norm(b - a))
    i = mass * length**2 / 12 + 1e-6
    return Inertial(mass, tuple((a + b) / 2), diaginertia=(i, i, i))


def five_bar_along_x(
    L1: float = 0.2, L2: float = 0.25, B: float = 0.1, gravity=(0.0, -9.81, 0.0)
) -> Mechanism:
    """Planar five-bar in the x-y plane, every hinge about z, every link along +x at the reference."""
    b = Builder("five_bar_x", gravity=gravity)
    for side, x0 in (("left", -B / 2), ("right", B / 2)):
        A = np.array([x0, 0.0, 0.0])
        b.body(
            f"proximal_{side}",
            joints=[b.hinge(f"base_{side}", pos=A)],
            inertial=_rod(A, A + np.array([L1, 0.0, 0.0])),
        )
        E = A + np.array([L1, 0.0, 0.0])
        b.body(
            f"distal_{side}",
            f"proximal_{side}",
            joints=[b.hinge(f"elbow_{side}", pos=E)],
            inertial=_rod(E, E + np.array([L2, 0.0, 0.0])),
        )
    b.site("tip", "distal_left", pos=(-B / 2 + L1 + L2, 0, 0))
    # the tips are B apart at the reference: the loop is closed at build
    b.revolute(
        "tip_joint",
        "distal_left",
        "distal_right",
        anchor1=(-B / 2 + L1 + L2, 0, 0),
        anchor2=(B / 2 + L1 + L2, 0, 0),
        axis=(0, 0, 1),
    )
    b.actuate("base_left", "base_right")
    return b.build()


E3 = np.eye(3)


def agile_eye(radius: float = 0.1) -> Mechanism:
    """Spherical 3-RRR about the origin; the site ``pointer`` on the platform at ``radius`` along x+y+z."""
    b = Builder("agile_eye", gravity=(0.0, 0.0, -9.81))
    for i in range(3):
        u, w, v = E3[i], E3[(i + 1) % 3], E3[(i + 2) % 3]
        prox, dist = radius * (u + w) / np.sqrt(2), radius * (w + v) / np.sqrt(2)
        b.body(f"proximal{i}", joints=[b.hinge(f"base{i}", axis=u)], inertial=_rod(radius * u, prox))
        b.body(
            f"distal{i}", f"proximal{i}", joints=[b.hinge(f"middle{i}", axis=w)], inertial=_rod(prox, dist)
        )
    b.body(
        "platform",
        "distal0",
        joints=[b.hinge("top0", axis=E3[2])],
        inertial=Inertial(0.5, tuple(radius * np.ones(3) / 3), diaginertia=(1e-3, 1e-3, 1e-3)),
    )
    b.site("pointer", "platform", pos=tuple(radius * np.ones(3) / np.sqrt(3)))
    for i in (1, 2):
        b.revolute(f"top{i}", f"distal{i}", "platform", anchor1=(0, 0, 0), axis=E3[(i + 2) % 3])
    b.actuate("base0", "base1", "base2")
    return b.build()


def sarrus(d: float = 0.1, link: float = 0.1, h: float = 0.12, plate_mass: float = 1.0) -> Mechanism:
    """Sarrus linkage: base at z=0, top plate at z=h; leg a in the x-z plane (hinges about y), leg b in
    the y-z plane (hinges about x); each leg two links of length ``link``, knees pointing outwards."""
    b = Builder("sarrus", gravity=(0.0, 0.0, -9.81))
    out = np.sqrt(link**2 - (h / 2) ** 2)
    for leg, e, axis in (("a", E3[0], E3[1]), ("b", E3[1], E3[0])):
        foot, knee, head = d * e, (d + out) * e + (0, 0, h / 2), d * e + (0, 0, h)
        b.body(f"{leg}1", joints=[b.hinge(f"{leg}_base", axis=axis, pos=foot)], inertial=_rod(foot, knee))
        b.body(
            f"{leg}2",
            f"{leg}1",
            joints=[b.hinge(f"{leg}_knee", axis=axis, pos=knee)],
            inertial=_rod(knee, head),
        )
    b.body(
        "top",
        "a2",
        joints=[b.hinge("a_head", axis=E3[1], pos=d * E3[0] + (0, 0, h))],
        inertial=Inertial(plate_mass, (0, 0, h), diaginertia=(1e-3, 1e-3, 2e-3)),
    )
    b.site("centre", "top", pos=(0, 0, h))
    b.revolute("b_head", "b2", "top", anchor1=d * E3[1] + (0, 0, h), axis=E3[0])
    b.actuate("a_base")
    return b.build()


def tsai_points(r_base: float, r_platform: float, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Base joint centres B_i, platform joint centres P_i at the reference (platform at (0, 0, h)) and
    the circles' tangents t_i (3, 3) each; legs at 0, 120, 240 degrees."""
    th = np.deg2rad([0.0, 120.0, 240.0])
    radial = np.stack([np.cos(th), np.sin(th), np.zeros(3)], axis=-1)
    tangent = np.stack([-np.sin(th), np.cos(th), np.zeros(3)], axis=-1)
    return r_base * radial, r_platform * radial + (0, 0, h), tangent


def tsai_3upu(r_base: float = 0.3, r_platform: float = 0.1, h: float = 0.5) -> Mechanism:
    """Tsai's 3-UPU: base U (tangent t_i, then s_i ⊥ t_i and the leg), a slide along the leg, platform
    U (s_i, then t_i): intermediate axes parallel, outer axes parallel, so the platform only translates
    away from constraint singularities.  The slides are actuated; ``centre`` is the platform centre."""
    Bp, Pp, t = tsai_points(r_base, r_platform, h)
    b = Builder("tsai_3upu", gravity=(0.0, 0.0, -9.81))
    for i in range(3):
        leg = Pp[i] - Bp[i]
        d = leg / np.linalg.norm(leg)
        s = np.cross(t[i], d)
        ua, ub = b.universal(f"base{i}", t[i], s, pos=Bp[i])
        b.body(f"cylinder{i}", joints=[(ua, ub)], inertial=_rod(Bp[i], Bp[i] + 0.4 * leg))
        b.body(
            f"rod{i}",
            f"cylinder{i}",
            joints=[b.slide(f"leg{i}", axis=d)],
            inertial=_rod(Pp[i] - 0.4 * leg, Pp[i]),
        )
        b.body(
            f"cross{i}",
            f"rod{i}",
            joints=[b.hinge(f"upper{i}", axis=s, pos=Pp[i])],
            inertial=_rod(Pp[i], Pp[i], 0.01),
        )
        if i == 0:
            b.body(
                "platform",
                "cross0",
                joints=[b.hinge("platform0", axis=t[0], pos=Pp[0])],
                inertial=Inertial(1.0, (0, 0, h), diaginertia=(1e-2, 1e-2, 2e-2)),
            )
        else:
            b.revolute(f"platform{i}", f"cross{i}", "platform", anchor1=Pp[i], axis=t[i])
    b.site("centre", "platform", pos=(0, 0, h))
    b.actuate("leg0", "leg1", "leg2")
    return b.build()
