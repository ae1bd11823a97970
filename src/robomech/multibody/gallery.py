"""Textbook mechanisms shipped as MJCF files (``robomech/multibody/gallery/*.xml``).

``four_bar.xml`` is written by hand (it is also the tutorial's example of a user's file); the others
are generated from the builders below by ``python -m robomech.multibody.gallery`` (and a test checks
that the shipped files are what the builders give).  Each file's header comment states the
mechanism, its dimensions, its reference configuration and its known properties, which the tests
check (docs/multibody.md shows them):

* ``bennett``: 4R spatial linkage, opposite links equal (a, α), (b, β) with a/sin α = b/sin β; one DOF
  where Grübler–Kutzbach says -2; ``tan(θ1/2) tan(θ2/2) = sin((β+α)/2) / sin((β-α)/2)``, θ3 = -θ1,
  θ4 = -θ2 (Denavit–Hartenberg angles, which are the joints' qpos here);
* ``planar_3rrr``: 3 DOF (x, y, φ), hinge cut joints (spatially overconstrained, GK -3);
* ``delta``: Clavel's Delta, parallelogram forearms of S–S rods: 3 translational DOF, 6 idle spins;
* ``rps_3``: 3-RPS, 3 DOF (one translation, two rotations), each leg stays in its plane;
* ``stewart``: 6-UPS Gough–Stewart platform, 6 DOF, leg lengths |p + R P_i - B_i|.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._model import Builder, Mechanism, _quat_from_matrix

__all__ = ["BUILDERS", "NAMES", "load", "path", "write"]

_DIR = Path(__file__).resolve().parent / "gallery"


def _rz(t: float) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def _rx(t: float) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    return np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])


def _q(R: np.ndarray) -> tuple[float, ...]:
    return tuple(_quat_from_matrix(R))


def _frame_x(x: np.ndarray, y_hint: np.ndarray) -> np.ndarray:
    """Rotation whose x axis is along ``x`` and y axis as close as possible to ``y_hint``."""
    x = x / np.linalg.norm(x)
    y = y_hint - (y_hint @ x) * x
    y /= np.linalg.norm(y)
    return np.column_stack([x, y, np.cross(x, y)])


# ---------------------------------------------------------------------------------------------- Bennett
BENNETT = {"a": 0.3, "alpha": np.deg2rad(30.0), "beta": np.deg2rad(60.0), "theta1_0": 1.0}


def bennett_theta2(
    theta1: np.ndarray, alpha: float = BENNETT["alpha"], beta: float = BENNETT["beta"]
) -> np.ndarray:
    """Bennett's input-output relation: ``tan(θ1/2) tan(θ2/2) = sin((β+α)/2) / sin((β-α)/2)``."""
    k = np.sin((beta + alpha) / 2) / np.sin((beta - alpha) / 2)
    return 2 * np.arctan(k / np.tan(np.asarray(theta1) / 2))


def build_bennett() -> Mechanism:
    a, al, be = BENNETT["a"], BENNETT["alpha"], BENNETT["beta"]
    b = a * np.sin(be) / np.sin(al)
    t1 = BENNETT["theta1_0"]
    t2 = float(bennett_theta2(t1))
    th = (t1, t2, -t1, -t2)
    bl = Builder("bennett", gravity=(0, 0, -9.81))
    lengths, twists = (a, b, a, b), (al, be, al, be)
    parent, pos, R_in = "world", (0.0, 0.0, 0.0), np.eye(3)
    for i in range(4):
        # Denavit-Hartenberg: link i is Rz(θ_i) Tx(a_i) Rx(α_i); hinge ref = θ_i at qpos0, so qpos = θ_i
        name = f"link{i + 1}"
        bl.body(
            name,
            parent,
            pos=pos,
            quat=_q(R_in @ _rz(th[i])),
            joints=[bl.hinge(f"theta{i + 1}", axis=(0, 0, 1), ref=th[i])],
        )
        parent, pos, R_in = name, (lengths[i], 0.0, 0.0), _rx(twists[i])
    bl.site("coupler", "link2", pos=(b / 2, 0.0, 0.0))
    # the ground link closes the loop: link4's end frame Tx(b) Rx(β) is the world frame
    bl.weld("ground", "link4", "world", relpos=(b, 0.0, 0.0), relquat=_q(_rx(be)))
    bl.actuate("theta1")
    return bl.build()


# ---------------------------------------------------------------------------------------------- 3-RRR
RRR = {"base_radius": 0.5, "platform_radius": 0.15, "l1": 0.35, "l2": 0.35}


def build_planar_3rrr() -> Mechanism:
    Rb, rp, l1, l2 = RRR["base_radius"], RRR["platform_radius"], RRR["l1"], RRR["l2"]
    bl = Builder("planar_3rrr", gravity=(0, 0, -9.81))
    gam = np.pi / 2 + 2 * np.pi / 3 * np.arange(3)
    for i, g in enumerate(gam):
        A = Rb * np.array([np.cos(g), np.sin(g), 0.0])
        C = rp * np.array([np.cos(g), np.sin(g), 0.0])  # platform vertex, platform at the origin
        d = C - A
        D = np.linalg.norm(d)
        # elbow B: |B - A| = l1, |C - B| = l2, on the left of A -> C
        x = (l1**2 - l2**2 + D**2) / (2 * D)
        y = np.sqrt(l1**2 - x**2)
        e = d / D
        B = A + x * e + y * np.array([-e[1], e[0], 0.0])
        phi = float(np.arctan2(*(B - A)[1::-1]))
        psi = float(np.arctan2(*(C - B)[1::-1]))
        # qpos of the base hinge = absolute angle of the proximal link; of the elbow = relative angle
        bl.body(f"proximal{i + 1}", pos=A, quat=_q(_rz(phi)), joints=[bl.hinge(f"base{i + 1}", ref=phi)])
        bl.body(
            f"distal{i + 1}",
            f"proximal{i + 1}",
            pos=(l1, 0, 0),
            quat=_q(_rz(psi - phi)),
            joints=[bl.hinge(f"elbow{i + 1}", ref=psi - phi)],
        )
        if i == 0:
            # platform frame at its centre, world-aligned at qpos0; its hinge sits at vertex C_1
            bl.body(
                "platform",
                "distal1",
                pos=_rz(-psi) @ (-B),
                quat=_q(_rz(-psi)),
                joints=[bl.hinge("wrist1", pos=C, ref=0.0)],
            )
        else:
            bl.revolute(f"wrist{i + 1}", f"distal{i + 1}", "platform", anchor1=(l2, 0, 0), axis=(0, 0, 1))
    bl.site("platform", "platform")
    bl.actuate("base1", "base2", "base3")
    return bl.build()


# ---------------------------------------------------------------------------------------------- Delta
DELTA = {
    "base_radius": 0.2,
    "arm": 0.25,
    "rod": 0.6,
    "platform_radius": 0.05,
    "half_width": 0.03,
    "theta_0": np.deg2rad(30.0),
}


def delta_height(theta: float = DELTA["theta_0"]) -> float:
    """Depth z0 of the platform below the base at equal arm angles θ (closed form)."""
    R, La, Lb, r = DELTA["base_radius"], DELTA["arm"], DELTA["rod"], DELTA["platform_radius"]
    return La * np.sin(theta) + np.sqrt(Lb**2 - (R + La * np.cos(theta) - r) ** 2)


def build_delta() -> Mechanism:
    R, La, Lb, r, w, th0 = (
        DELTA[k] for k in ("base_radius", "arm", "rod", "platform_radius", "half_width", "theta_0")
    )
    p = np.array([0.0, 0.0, -delta_height(th0)])
    bl = Builder("delta", gravity=(0, 0, -9.81))
    bl.body("platform", pos=p, joints=[bl.free("platform")])
    for i in range(3):
        g = 2 * np.pi / 3 * i
        er, t, ez = (
            np.array([np.cos(g), np.sin(g), 0.0]),
            np.array([-np.sin(g), np.cos(g), 0.0]),
            np.eye(3)[2],
        )
        B = R * er
        R_arm = np.column_stack([er, t, ez]) @ np.array(
            [[np.cos(th0), 0, np.sin(th0)], [0, 1, 0], [-np.sin(th0), 0, np.cos(th0)]]
        )  # x along the arm, pointing θ0 below the horizontal; the hinge axis is y = t
        arm = f"arm{i + 1}"
        bl.body(arm, pos=B, quat=_q(R_arm), joints=[bl.hinge(f"theta{i + 1}", axis=(0, 1, 0), ref=th0)])
        J = B + La * R_arm[:, 0]
        E = p + r * er
        for side, s in (("a", 1.0), ("b", -1.0)):
            top, bot = J + s * w * t, E + s * w * t
            R_rod = _frame_x(bot - top, t)
            rod = f"rod{i + 1}{side}"
            bl.body(
                rod,
                arm,
                pos=(La, s * w, 0.0),
                quat=_q(R_arm.T @ R_rod),
                joints=[bl.ball(f"upper{i + 1}{side}")],
            )
            bl.connect(f"lower{i + 1}{side}", rod, "platform", anchor1=(Lb, 0.0, 0.0), anchor2=bot - p)
    bl.site("tcp", "platform")
    bl.actuate("theta1", "theta2", "theta3")
    return bl.build()


# ---------------------------------------------------------------------------------------------- 3-RPS
RPS = {"base_radius": 0.3, "platform_radius": 0.15, "height": 0.4}


def build_rps_3() -> Mechanism:
    Rb, rp, h = RPS["base_radius"], RPS["platform_radius"], RPS["height"]
    p = np.array([0.0, 0.0, h])
    bl = Builder("rps_3", gravity=(0, 0, -9.81))
    for i in range(3):
        g = 2 * np.pi / 3 * i
        er, t = np.array([np.cos(g), np.sin(g), 0.0]), np.array([-np.sin(g), np.cos(g), 0.0])
        B, P = Rb * er, p + rp * er
        v = P - B
        l0 = float(np.linalg.norm(v))
        R_leg = _frame_x(v, t)  # x along the leg, y = the revolute axis (tangent to the base circle)
        bl.body(f"leg{i + 1}", pos=B, quat=_q(R_leg), joints=[bl.hinge(f"r{i + 1}", axis=(0, 1, 0))])
        bl.body(f"piston{i + 1}", f"leg{i + 1}", joints=[bl.slide(f"p{i + 1}", axis=(1, 0, 0))])
        if i == 0:
            bl.body(
                "platform",
                "piston1",
                pos=(l0, 0, 0) - R_leg.T @ (rp * er),
                quat=_q(R_leg.T),
                joints=[bl.ball("s1", pos=rp * er)],
            )
        else:
            bl.connect(f"s{i + 1}", f"piston{i + 1}", "platform", anchor1=(l0, 0, 0), anchor2=rp * er)
    bl.site("platform", "platform")
    bl.actuate("p1", "p2", "p3")
    return bl.build()


# ---------------------------------------------------------------------------------------------- Stewart
STEWART = {
    "base_radius": 0.5,
    "platform_radius": 0.3,
    "height": 0.6,
    "base_half_angle": np.deg2rad(15.0),
    "platform_half_angle": np.deg2rad(45.0),
}


def stewart_points() -> tuple[np.ndarray, np.ndarray]:
    """Base joint centres B_i (world) and platform joint centres P_i (platform frame), (6, 3) each."""
    Rb, rp, hb, hp = (
        STEWART[k] for k in ("base_radius", "platform_radius", "base_half_angle", "platform_half_angle")
    )
    B, P = [], []
    for k in range(3):
        c = 2 * np.pi / 3 * k
        for s in (-1, 1):
            # leg from base point c -+ 15 deg to platform point c -+ 45 deg: neighbouring legs cross
            gb, gp = c + s * hb, c + s * hp
            B.append(Rb * np.array([np.cos(gb), np.sin(gb), 0.0]))
            P.append(rp * np.array([np.cos(gp), np.sin(gp), 0.0]))
    return np.array(B), np.array(P)


def build_stewart() -> Mechanism:
    B, P = stewart_points()
    p = np.array([0.0, 0.0, STEWART["height"]])
    bl = Builder("stewart", gravity=(0, 0, -9.81))
    bl.body("platform", pos=p, joints=[bl.free("platform")])
    for i in range(6):
        v = p + P[i] - B[i]
        l0 = float(np.linalg.norm(v))
        R_leg = _frame_x(v, np.cross(np.eye(3)[2], v) if abs(v[2]) < np.linalg.norm(v) else np.eye(3)[1])
        bl.body(f"cardan{i + 1}", pos=B[i], quat=_q(R_leg), joints=[bl.hinge(f"u{i + 1}a", axis=(0, 1, 0))])
        bl.body(f"cylinder{i + 1}", f"cardan{i + 1}", joints=[bl.hinge(f"u{i + 1}b", axis=(0, 0, 1))])
        bl.body(f"rod{i + 1}", f"cylinder{i + 1}", joints=[bl.slide(f"leg{i + 1}", axis=(1, 0, 0))])
        bl.connect(f"s{i + 1}", f"rod{i + 1}", "platform", anchor1=(l0, 0, 0), anchor2=P[i])
    bl.site("platform", "platform")
    bl.actuate(*(f"leg{i + 1}" for i in range(6)))
    return bl.build()


BUILDERS = {
    "bennett": build_bennett,
    "planar_3rrr": build_planar_3rrr,
    "delta": build_delta,
    "rps_3": build_rps_3,
    "stewart": build_stewart,
}
_COMMENTS = {
    "bennett": (
        "Bennett linkage (4R, spatial, overconstrained). a = 0.3 m, alpha = 30 deg, b = a "
        "sin(beta)/sin(alpha), beta = 60 deg. qpos = Denavit-Hartenberg angles. Known: 1 DOF while "
        "Gruebler-Kutzbach gives -2; tan(t1/2) tan(t2/2) = sin((beta+alpha)/2)/sin((beta-alpha)/2), t3 = "
        "-t1, t4 = -t2. Generated by robomech.multibody.gallery (build_bennett)."
    ),
    "planar_3rrr": (
        "Planar 3-RRR parallel manipulator, base radius 0.5 m, platform radius 0.15 m, links 0.35 m; "
        "hinge cut joints at wrists 2 and 3 (two <connect> each). Known: 3 DOF (x, y, phi); spatial "
        "Gruebler-Kutzbach -3. qpos of base hinges = absolute link angles. Generated by "
        "robomech.multibody.gallery."
    ),
    "delta": (
        "Delta robot (Clavel) with parallelogram forearms of S-S rods. Base radius 0.2 m, arms 0.25 m, "
        "rods 0.6 m, platform radius 0.05 m, parallelogram half width 0.03 m; arms 30 deg below "
        "horizontal at qpos0. Known: 3 translational DOF, 6 idle rod spins (Gruebler-Kutzbach 9), "
        "platform orientation constant. Generated by robomech.multibody.gallery."
    ),
    "rps_3": (
        "3-RPS parallel manipulator, base radius 0.3 m, platform radius 0.15 m, height 0.4 m at qpos0. "
        "Known: 3 DOF = 1 translation + 2 rotations; each leg stays in the plane normal to its revolute "
        "axis. qpos of the slides = leg extension from qpos0. Generated by robomech.multibody.gallery."
    ),
    "stewart": (
        "6-UPS Gough-Stewart platform, base radius 0.5 m, platform radius 0.3 m, height 0.6 m at qpos0. "
        "Known: 6 DOF; leg length = |p + R P_i - B_i| = l0_i + qpos(leg_i). Generated by "
        "robomech.multibody.gallery."
    ),
}

NAMES = ("four_bar", *BUILDERS)


def path(name: str) -> Path:
    """Path of the gallery MJCF file ``name`` (one of :data:`NAMES`)."""
    if not isinstance(name, str) or name not in NAMES:
        raise ValueError(f"Expected name to be a gallery name among {list(NAMES)}, got {name!r}.")
    return _DIR / f"{name}.xml"


def load(name: str) -> Mechanism:
    """The gallery mechanism ``name`` read with :func:`~robomech.multibody.from_mjcf` (needs MuJoCo)."""
    from ._mjcf import from_mjcf

    return from_mjcf(path(name))


def mjcf(name: str) -> str:
    """The MJCF text the builder of ``name`` gives (what ``write`` stores in the package)."""
    from ._mjcf import to_mjcf

    if not isinstance(name, str) or name not in BUILDERS:
        raise ValueError(
            f"Expected name to be a generated gallery name among {list(BUILDERS)}, got {name!r}."
        )
    return to_mjcf(BUILDERS[name](), comment=_COMMENTS[name]) + "\n"


def write(directory: Path = _DIR) -> list[Path]:
    """Write the generated gallery files into ``directory`` (the package's gallery by default)."""
    if not isinstance(directory, str | Path) or not Path(directory).is_dir():
        raise ValueError(f"Expected directory to be an existing directory, got {directory!r}.")
    out = []
    for name in BUILDERS:
        f = Path(directory) / f"{name}.xml"
        f.write_text(mjcf(name))
        out.append(f)
    return out


if __name__ == "__main__":  # python -m robomech.multibody.gallery
    for f in write():
        print(f)
