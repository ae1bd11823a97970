"""What the viewer draws, in each body's own frame (numpy only; the server places the bodies).

A body is drawn as the links joining the points it carries, all fixed in its frame: where it hangs
on its parent (its first joint's anchor), where its children hang on it, its closure anchors and its
sites; each becomes a cylinder from the body's root to the point (the star of
:func:`robomech.multibody.body_segments`). A link whose two ends coincide at the centre of a
spherical linkage (a point where ``SPHERICAL_HINGES`` or more hinge axes meet) is drawn instead
between points on the two hinges' axes, at ``ARC_RADIUS_FRACTION`` of the characteristic length from
the centre, so such a body is a visible rod joining its two axes; other coincident ends (the two
hinges of a cardan joint, a slider's zero stroke) are not links and are not drawn. Joints are drawn
as spheres at their anchors with their axes as short segments; sites and body frames as small
triads.

A child's anchor in its parent's frame is ``T_off @ pos`` (the child's frame at zero joint
coordinates, times its first joint's anchor): a hinge or ball turns about that point and a slide
starts there, so for a body with one joint (or joints about one point) the point is fixed in the
parent and a slider is drawn from the fixed end of its stroke, as ``studies/_animate`` does; a body
that stacks a slide on rotations in one body is drawn with its anchor at zero stroke.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from robomech.multibody._compile import compile_model
from robomech.multibody._model import Mechanism

# A link shorter than this fraction of the characteristic length has coincident ends: it is drawn
# between its joints' axes instead (a spherical linkage), or not at all when neither end has an axis.
COINCIDENT_FRACTION = 1e-6
# Hinges whose anchors coincide at one point: from this many on, the point is a spherical linkage's
# centre (a cardan joint has two; a spherical 3-R chain or a vectored-thrust gimbal three or more).
SPHERICAL_HINGES = 3
# Distance from the anchor, along the joint axis, of the ends of a spherical link, as a fraction of
# the characteristic length (a rod well inside the mechanism's extent, clear of the joint spheres).
ARC_RADIUS_FRACTION = 0.5
# Cylinder radius of a link, joint-sphere radius and joint-axis length, as fractions of the
# characteristic length: thin enough that the links of a Delta's parallelograms stay apart.
LINK_RADIUS_FRACTION = 0.012
JOINT_RADIUS_FRACTION = 0.025
AXIS_LENGTH_FRACTION = 0.25
# Side of a site's or a body frame's triad, as a fraction of the characteristic length.
TRIAD_FRACTION = 0.12


@dataclass(frozen=True)
class Link:
    """A cylinder from ``a`` to ``b`` (m) in the frame of body ``body`` (index into the tree)."""

    body: int
    a: NDArray[np.float64]
    b: NDArray[np.float64]


@dataclass(frozen=True)
class JointMark:
    """A joint drawn on its child body ``body``: anchor ``pos`` and unit ``axis`` (None: a ball)."""

    body: int
    name: str
    type: str
    pos: NDArray[np.float64]
    axis: NDArray[np.float64] | None
    actuated: bool


@dataclass(frozen=True)
class SiteMark:
    """A site ``name`` on body ``body`` at ``T (4, 4)`` in the body frame."""

    body: int
    name: str
    T: NDArray[np.float64]


@dataclass(frozen=True)
class Scene:
    """The drawing of a mechanism in body frames; ``colour[b]`` the RGB of body ``b``'s chain."""

    body_names: tuple[str, ...]
    links: tuple[Link, ...]
    joints: tuple[JointMark, ...]
    sites: tuple[SiteMark, ...]
    colour: tuple[tuple[int, int, int], ...]
    length: float

    @property
    def link_radius(self) -> float:
        return LINK_RADIUS_FRACTION * self.length

    @property
    def joint_radius(self) -> float:
        return JOINT_RADIUS_FRACTION * self.length


# matplotlib's tab10 (the wireframe's chain colours), as RGB bytes.
PALETTE = (
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
)
GROUND_COLOUR = (60, 60, 60)


def _chain_colours(mech: Mechanism) -> tuple[tuple[int, int, int], ...]:
    """Per tree body (index 0 the world): the colour of its chain, i.e. of its root ancestor."""
    parent = {b.name: b.parent for b in mech.bodies}
    roots: list[str] = []
    out = [GROUND_COLOUR]
    for b in mech.bodies:
        root = b.name
        while parent[root] != "world":
            root = parent[root]
        if root not in roots:
            roots.append(root)
        out.append(PALETTE[roots.index(root) % len(PALETTE)])
    return tuple(out)


def build_scene(mech: Mechanism) -> Scene:
    """The links, joints and sites of ``mech`` in body frames (constant over every configuration)."""
    tree = mech.tree
    L = float(mech.length)
    nb = len(tree.body_names)
    # per body: (point, axis or None) in the body frame; the first entry is the body's root
    pts: dict[int, list[tuple[np.ndarray, np.ndarray | None]]] = {i: [] for i in range(nb)}
    joints = []
    for i, body in enumerate(mech.bodies, start=1):
        j0 = body.joints[0] if body.joints else None
        if j0 is None or j0.type == "free":
            pts[i].insert(0, (np.zeros(3), None))
        else:
            axis = np.asarray(j0.axis, float) if j0.type == "hinge" else None
            pts[i].insert(0, (np.asarray(j0.pos, float), axis))
            held = np.asarray(tree.T_off[i])  # the child's frame in the parent's at zero coordinate
            p_parent = held[:3, :3] @ np.asarray(j0.pos, float) + held[:3, 3]
            a_parent = None if axis is None else held[:3, :3] @ axis
            pts[int(tree.parent[i])].append((p_parent, a_parent))
        for j in body.joints:
            if j.type == "free":
                continue
            ax = np.asarray(j.axis, float) if j.type in ("hinge", "slide") else None
            joints.append(JointMark(i, j.name, j.type, np.asarray(j.pos, float), ax, j.name in mech.actuated))
    for c in mech.closures:
        b1, b2 = tree.body_index(c.body1), tree.body_index(c.body2)
        pts[b1].append((np.asarray(c.anchor1 if c.kind != "rigid" else c.relpos, float), None))
        pts[b2].append((np.asarray(c.anchor2, float), None))
    sites = []
    for s, name in enumerate(tree.site_names):
        b = int(tree.site_body[s])
        T = np.asarray(tree.T_site[s], float)
        pts[b].append((T[:3, 3], None))
        sites.append(SiteMark(b, name, T))
    centres = _spherical_centres(mech)
    T0 = poses(mech, np.asarray(mech.q0, float))
    links = []
    for i in range(1, nb):
        if len(pts[i]) < 2:
            continue
        (root, root_axis), rest = pts[i][0], pts[i][1:]
        for p, axis in rest:
            end_a, end_b = root, p
            if np.linalg.norm(end_b - end_a) < COINCIDENT_FRACTION * L:
                at = T0[i, :3, :3] @ root + T0[i, :3, 3]
                central = any(np.linalg.norm(at - c) < COINCIDENT_FRACTION * L for c in centres)
                if not central or (root_axis is None and axis is None):
                    continue
                r = ARC_RADIUS_FRACTION * L
                end_a = root + r * root_axis if root_axis is not None else root
                end_b = p + r * axis if axis is not None else p
                if np.linalg.norm(end_b - end_a) < COINCIDENT_FRACTION * L:
                    continue
            links.append(Link(i, end_a, end_b))
    return Scene(
        body_names=tuple(tree.body_names),
        links=tuple(links),
        joints=tuple(joints),
        sites=tuple(sites),
        colour=_chain_colours(mech),
        length=L,
    )


def _spherical_centres(mech: Mechanism) -> list[NDArray[np.float64]]:
    """World points (at ``q0``) where ``SPHERICAL_HINGES`` or more hinge anchors coincide."""
    T = poses(mech, np.asarray(mech.q0, float))
    pts = [
        T[i, :3, :3] @ np.asarray(j.pos, float) + T[i, :3, 3]
        for i, body in enumerate(mech.bodies, start=1)
        for j in body.joints
        if j.type == "hinge"
    ]
    tol = COINCIDENT_FRACTION * float(mech.length)
    return [p for p in pts if sum(np.linalg.norm(p - o) < tol for o in pts) >= SPHERICAL_HINGES]


def poses(mech: Mechanism, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """World pose ``(nb, 4, 4)`` of every tree body (index 0 the world) at one configuration."""
    from robomech.multibody._compiled import compiled_body_poses  # numba loads at the first kernel call

    return np.asarray(compiled_body_poses(compile_model(mech), np.asarray(q, float)[None])[0])


def cylinder_pose(a: NDArray[np.float64], b: NDArray[np.float64]) -> tuple[np.ndarray, np.ndarray, float]:
    """``(wxyz, centre, height)`` of a cylinder along its local z from ``a`` to ``b``."""
    d = np.asarray(b, float) - np.asarray(a, float)
    h = float(np.linalg.norm(d))
    return quat_z_to(d / h if h > 0 else np.array([0.0, 0.0, 1.0])), (np.asarray(a) + np.asarray(b)) / 2, h


def quat_z_to(u: NDArray[np.float64]) -> np.ndarray:
    """Unit quaternion ``[w, x, y, z]`` of the shortest rotation taking ``e_z`` to the unit ``u``."""
    z = np.array([0.0, 0.0, 1.0])
    c = float(np.dot(z, u))
    if c < -1.0 + 1e-12:  # opposite: half a turn about x
        return np.array([0.0, 1.0, 0.0, 0.0])
    v = np.cross(z, u)
    q = np.array([1.0 + c, *v])
    return q / np.linalg.norm(q)


def matrix_to_wxyz(R: NDArray[np.float64]) -> np.ndarray:
    """Unit quaternion ``[w, x, y, z]`` of a rotation matrix (Shepperd's method, w >= 0)."""
    from robomech.multibody._model import _quat_from_matrix

    return np.asarray(_quat_from_matrix(np.asarray(R, float)), float)
