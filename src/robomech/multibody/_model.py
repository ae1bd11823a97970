"""The description of a mechanism: frozen dataclasses, MuJoCo's model semantics, and a builder.

A mechanism is a spanning tree of bodies (each body's pose in its parent, then its joints applied in
order, exactly as MuJoCo's ``mj_kinematics``), loop closures (cut joints), joint couplings, actuated
joints, sites and inertias.  Every vector is stored as a tuple of floats so that descriptions compare
and hash by value.  Quaternions are MuJoCo's ``[w, x, y, z]``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from robomech._validation import MAX_MAGNITUDE, as_array, check_real

from ._options import ASSEMBLED_RTOL, MIN_NORM, ROTATION_TOL  # noqa: F401 (ASSEMBLED_RTOL re-exported)

__all__ = [
    "JOINT_TYPES",
    "Body",
    "Builder",
    "Closure",
    "Coupling",
    "Inertial",
    "Joint",
    "Mechanism",
    "Site",
]

JOINT_TYPES = ("hinge", "slide", "ball", "free")
CLOSURE_KINDS = ("point", "rigid", "revolute")
# tolerances: _options (MIN_NORM for a direction; ASSEMBLED_RTOL and ROTATION_TOL re-exported here)
_MIN_NORM = MIN_NORM

# A point, axis or quaternion given to the Builder: a sequence of floats or a float64 array.
Vector = Sequence[float] | NDArray[np.float64]


def _vec(x: object, n: int, name: str) -> tuple[float, ...]:
    # the common case without an array: n real numbers (not bool), finite, |v| <= MAX_MAGNITUDE (what
    # as_array accepts); anything else takes as_array's path and its errors
    if (
        type(x) in (tuple, list)
        and len(x) == n  # type: ignore[arg-type]
        and all(
            isinstance(v, float | int) and not isinstance(v, bool) and abs(v) <= MAX_MAGNITUDE
            for v in x  # type: ignore[attr-defined]
        )
    ):
        return tuple(float(v) for v in x)  # type: ignore[attr-defined]
    a = as_array(x, name)
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise ValueError(f"Expected {name} to be {n} finite real numbers, got {x!r}.")
    return tuple(float(v) for v in a)


def _unit(x: object, n: int, name: str) -> tuple[float, ...]:
    v = np.array(_vec(x, n, name))
    nrm = np.linalg.norm(v)
    if nrm < _MIN_NORM:
        raise ValueError(f"Expected {name} to be a non-zero {n}-vector, got {x!r}.")
    return tuple(float(c) for c in v / nrm)


def _name(x: object, what: str) -> str:
    if not isinstance(x, str) or not x:
        raise ValueError(f"Expected {what} to be a non-empty string, got {x!r}.")
    return x


@dataclass(frozen=True)
class Joint:
    """One joint of a body (MuJoCo semantics, in the body's frame after the joints before it).

    ``hinge``: rotation by ``q - ref`` about ``axis`` through ``pos``; ``slide``: translation by
    ``q - ref`` along ``axis``; ``ball``: rotation by the unit quaternion ``q`` (4 entries) about
    ``pos``; ``free``: the body's world pose ``(x, y, z, qw, qx, qy, qz)`` (top-level bodies only).
    Velocity coordinates (and the columns of every Jacobian over all coordinates) follow MuJoCo's
    ``qvel``: 1 for hinge and slide, the local angular velocity (3) for a ball, world linear velocity
    of the body origin then local angular velocity (6) for a free joint.

    Parameters
    ----------
    name : str
        Unique, non-empty joint name.
    type : str, optional
        One of ``"hinge"`` (default), ``"slide"``, ``"ball"``, ``"free"``.
    axis : tuple of float, shape (3,), optional
        Hinge / slide axis in the body frame (normalised on construction); default ``+z``.  Unused
        for ball and free joints.
    pos : tuple of float, shape (3,), optional
        Point of the axis (hinge) or centre (ball) in the body frame (m); default the body origin.
    ref : float, optional
        Joint value (rad or m) at which the joint is in its reference pose (MuJoCo ``ref``); default 0.

    Raises
    ------
    ValueError
        If ``name`` is empty, ``type`` is unknown, ``axis`` is not a non-zero 3-vector, or ``pos`` /
        ``ref`` are not finite reals.
    """

    name: str
    type: str = "hinge"
    axis: tuple[float, ...] = (0.0, 0.0, 1.0)
    pos: tuple[float, ...] = (0.0, 0.0, 0.0)
    ref: float = 0.0

    def __post_init__(self) -> None:
        _name(self.name, "name (of a Joint)")
        if not isinstance(self.type, str) or self.type not in JOINT_TYPES:
            raise ValueError(f"Expected type in {JOINT_TYPES}, got {self.type!r} (joint {self.name!r}).")
        object.__setattr__(self, "axis", _unit(self.axis, 3, f"axis of joint {self.name!r}"))
        object.__setattr__(self, "pos", _vec(self.pos, 3, f"pos of joint {self.name!r}"))
        object.__setattr__(self, "ref", check_real(self.ref, f"ref of joint {self.name!r}"))

    @property
    def nq(self) -> int:
        return {"hinge": 1, "slide": 1, "ball": 4, "free": 7}[self.type]

    @property
    def nv(self) -> int:
        return {"hinge": 1, "slide": 1, "ball": 3, "free": 6}[self.type]


@dataclass(frozen=True)
class Inertial:
    """Mass, centre of mass ``pos`` and principal inertia ``diaginertia`` in the frame ``quat`` (body).

    Parameters
    ----------
    mass : float
        Mass (kg), >= 0.
    pos : tuple of float, shape (3,), optional
        Centre of mass in the body frame (m); default the body origin.
    quat : tuple of float, shape (4,), optional
        Orientation ``[w, x, y, z]`` of the principal axes in the body frame (normalised); default
        the identity.
    diaginertia : tuple of float, shape (3,), optional
        Principal moments of inertia about the centre of mass (kg m^2), each >= 0; default zero (a
        point mass).

    Raises
    ------
    ValueError
        If ``mass`` or a moment is negative or not finite, or ``quat`` is zero.
    """

    mass: float
    pos: tuple[float, ...] = (0.0, 0.0, 0.0)
    quat: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0)
    diaginertia: tuple[float, ...] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        object.__setattr__(self, "mass", check_real(self.mass, "mass", low=0.0))
        object.__setattr__(self, "pos", _vec(self.pos, 3, "pos (of an Inertial)"))
        object.__setattr__(self, "quat", _unit(self.quat, 4, "quat (of an Inertial)"))
        d = _vec(self.diaginertia, 3, "diaginertia")
        if min(d) < 0:
            raise ValueError(f"Expected diaginertia >= 0, got {d}.")
        object.__setattr__(self, "diaginertia", d)


@dataclass(frozen=True)
class Body:
    """A body: its pose ``(pos, quat)`` in ``parent`` ("world" for the base) and its joints, in order.

    Parameters
    ----------
    name : str
        Unique, non-empty body name other than ``"world"``.
    parent : str, optional
        Name of the parent body; default ``"world"`` (the fixed base).
    pos : tuple of float, shape (3,), optional
        Origin of the body frame in the parent frame at zero joint motion (m).
    quat : tuple of float, shape (4,), optional
        Orientation ``[w, x, y, z]`` of the body frame in the parent frame (normalised).
    joints : tuple of Joint, optional
        The joints between parent and body, applied in order; empty: welded to the parent.  A free
        joint must be the only joint of a top-level body.
    inertial : Inertial, optional
        Mass properties; None (default) leaves them to the MJCF export (derived from geoms).

    Raises
    ------
    ValueError
        If a name is empty or ``"world"``, a vector is not finite of the stated length, ``joints``
        holds something other than Joint objects, a free joint is misplaced, or ``inertial`` is not an
        Inertial.
    """

    name: str
    parent: str = "world"
    pos: tuple[float, ...] = (0.0, 0.0, 0.0)
    quat: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0)
    joints: tuple[Joint, ...] = ()
    inertial: Inertial | None = None

    def __post_init__(self) -> None:
        _name(self.name, "name (of a Body)")
        if self.name == "world":
            raise ValueError("Expected name other than 'world' for a Body (the fixed base is implicit).")
        _name(self.parent, f"parent of body {self.name!r}")
        object.__setattr__(self, "pos", _vec(self.pos, 3, f"pos of body {self.name!r}"))
        object.__setattr__(self, "quat", _unit(self.quat, 4, f"quat of body {self.name!r}"))
        if not isinstance(self.joints, tuple | list):
            raise ValueError(
                f"Expected joints of body {self.name!r} to be a tuple of Joint, got {self.joints!r}."
            )
        joints = tuple(self.joints)
        if not all(isinstance(j, Joint) for j in joints):
            raise ValueError(f"Expected joints of body {self.name!r} to be Joint objects, got {joints!r}.")
        if any(j.type == "free" for j in joints) and (len(joints) != 1 or self.parent != "world"):
            raise ValueError(
                f"Expected a free joint to be the only joint of a top-level body, got body {self.name!r}."
            )
        object.__setattr__(self, "joints", joints)
        if self.inertial is not None and not isinstance(self.inertial, Inertial):
            raise ValueError(
                f"Expected inertial of body {self.name!r} to be an Inertial, got {self.inertial!r}."
            )


@dataclass(frozen=True)
class Site:
    """A named frame fixed in ``body`` at ``(pos, quat)``: an output of the kinematics.

    Parameters
    ----------
    name : str
        Unique, non-empty site name (the ``site`` argument of :func:`site_pose` and friends).
    body : str
        Name of the body that carries the site.
    pos : tuple of float, shape (3,), optional
        Site origin in the body frame (m).
    quat : tuple of float, shape (4,), optional
        Site orientation ``[w, x, y, z]`` in the body frame (normalised).

    Raises
    ------
    ValueError
        If a name is empty, ``pos`` is not 3 finite reals, or ``quat`` is not a non-zero 4-vector.
    """

    name: str
    body: str
    pos: tuple[float, ...] = (0.0, 0.0, 0.0)
    quat: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        _name(self.name, "name (of a Site)")
        _name(self.body, f"body of site {self.name!r}")
        object.__setattr__(self, "pos", _vec(self.pos, 3, f"pos of site {self.name!r}"))
        object.__setattr__(self, "quat", _unit(self.quat, 4, f"quat of site {self.name!r}"))


@dataclass(frozen=True)
class Closure:
    """A loop closure (cut joint) between ``body1`` and ``body2`` ("world" allowed).

    * ``point`` (MuJoCo ``connect``): point ``anchor1`` of body1 coincides with ``anchor2`` of body2
      (3 equations; a spherical joint).
    * ``rigid`` (MuJoCo ``weld``): body2's pose in body1 is ``(relpos, relquat)``; its position rows
      are measured at ``anchor2`` (body2 frame) as MuJoCo does (6 equations).
    * ``revolute``: as ``point`` and, in addition, ``axis`` (body1 frame) stays aligned with ``axis2``
      (body2 frame): a hinge cut joint; 6 equations of rank 5, written as two point closures one
      characteristic length apart along the axis, which is how MJCF expresses it.

    Parameters
    ----------
    name : str
        Unique, non-empty closure name.
    kind : str
        ``"point"``, ``"rigid"`` or ``"revolute"``.
    body1, body2 : str
        The two bodies joined (different; ``"world"`` allowed).
    anchor1 : tuple of float, shape (3,), optional
        Point of body1, in the body1 frame (m); point and revolute closures.
    anchor2 : tuple of float, shape (3,), optional
        Point of body2, in the body2 frame (m); for a rigid closure the point where the position
        rows are measured.
    relpos : tuple of float, shape (3,), optional
        Rigid closure: body2's origin in the body1 frame (m).
    relquat : tuple of float, shape (4,), optional
        Rigid closure: body2's orientation ``[w, x, y, z]`` in the body1 frame (normalised).
    axis : tuple of float, shape (3,), optional
        Revolute closure: hinge axis in the body1 frame (normalised).
    axis2 : tuple of float, shape (3,), optional
        Revolute closure: the same axis in the body2 frame (normalised).

    Raises
    ------
    ValueError
        If a name is empty, ``kind`` is unknown, ``body1 == body2``, or a vector is not finite of the
        stated length (or zero, for a quaternion or axis).
    """

    name: str
    kind: str
    body1: str
    body2: str
    anchor1: tuple[float, ...] = (0.0, 0.0, 0.0)
    anchor2: tuple[float, ...] = (0.0, 0.0, 0.0)
    relpos: tuple[float, ...] = (0.0, 0.0, 0.0)
    relquat: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0)
    axis: tuple[float, ...] = (0.0, 0.0, 1.0)
    axis2: tuple[float, ...] = (0.0, 0.0, 1.0)

    def __post_init__(self) -> None:
        _name(self.name, "name (of a Closure)")
        if not isinstance(self.kind, str) or self.kind not in CLOSURE_KINDS:
            raise ValueError(f"Expected kind in {CLOSURE_KINDS}, got {self.kind!r} ({self.name!r}).")
        _name(self.body1, f"body1 of closure {self.name!r}")
        _name(self.body2, f"body2 of closure {self.name!r}")
        if self.body1 == self.body2:
            raise ValueError(
                f"Expected body2 of closure {self.name!r} to differ from body1, got {self.body1!r} twice."
            )
        for f in ("anchor1", "anchor2", "relpos"):
            object.__setattr__(self, f, _vec(getattr(self, f), 3, f"{f} of closure {self.name!r}"))
        object.__setattr__(self, "relquat", _unit(self.relquat, 4, f"relquat of closure {self.name!r}"))
        object.__setattr__(self, "axis", _unit(self.axis, 3, f"axis of closure {self.name!r}"))
        object.__setattr__(self, "axis2", _unit(self.axis2, 3, f"axis2 of closure {self.name!r}"))


@dataclass(frozen=True)
class Coupling:
    """MuJoCo's joint equality: ``q1 - ref1 = c0 + c1 x + c2 x^2 + c3 x^3 + c4 x^4`` with ``x = q2 - ref2``.

    ``joint2 = None`` fixes ``joint1`` at ``ref1 + c0``.  Both joints are hinges or slides.

    Parameters
    ----------
    name : str
        Unique, non-empty coupling name.
    joint1 : str
        The driven joint.
    joint2 : str, optional
        The driving joint; None (default) fixes ``joint1``.
    polycoef : tuple of float, shape (5,), optional
        ``(c0, c1, c2, c3, c4)`` in the joints' units (rad, m); default ``(0, 1, 0, 0, 0)``:
        ``q1 - ref1 = q2 - ref2``.

    Raises
    ------
    ValueError
        If a name is empty or ``polycoef`` is not 5 finite reals.
    """

    name: str
    joint1: str
    joint2: str | None = None
    polycoef: tuple[float, ...] = (0.0, 1.0, 0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        _name(self.name, "name (of a Coupling)")
        _name(self.joint1, f"joint1 of coupling {self.name!r}")
        if self.joint2 is not None:
            _name(self.joint2, f"joint2 of coupling {self.name!r}")
            if self.joint2 == self.joint1:
                raise ValueError(
                    f"Expected joint2 of coupling {self.name!r} to differ from joint1, "
                    f"got {self.joint2!r} twice (a joint coupled to itself)."
                )
        object.__setattr__(self, "polycoef", _vec(self.polycoef, 5, f"polycoef of coupling {self.name!r}"))


@dataclass(frozen=True)
class Mechanism:
    """A closed-chain mechanism: bodies (parents before children), closures, couplings, sites, actuators.

    The bodies are kept in MuJoCo's depth-first order (each body followed by its subtree), whatever
    the order given, so that ``q`` is exactly the qpos of :func:`to_mjcf`'s model.

    ``actuated`` names hinge or slide joints in actuator order; ``q_act`` are their ``qpos`` entries.
    The reference configuration ``q0`` is MuJoCo's ``qpos0`` (hinge/slide ``ref``, identity
    quaternions, a free body's own pose).  Usually made by :class:`Builder` or :func:`from_mjcf`.
    ``nq``, ``nv`` (sizes of ``qpos`` and ``qvel``), ``q0`` and ``length`` are derived properties.

    Parameters
    ----------
    bodies : tuple of Body
        At least one body; parents before children (reordered depth-first on construction).
    closures : tuple of Closure, optional
        Loop closures (cut joints) between named bodies.
    couplings : tuple of Coupling, optional
        Joint equalities between hinge / slide joints.
    sites : tuple of Site, optional
        Named output frames.
    actuated : tuple of str, optional
        Actuated hinge or slide joints, each once, in actuator order.
    gravity : tuple of float, shape (3,), optional
        Gravitational acceleration in the world frame (m/s^2); default ``(0, 0, -9.81)``.
    name : str, optional
        Non-empty mechanism name.
    characteristic_length : float, optional
        Length (m) that makes rotations and translations commensurate (residual scaling,
        conditioning); None (default): computed from the geometry.

    Raises
    ------
    ValueError
        If a field has the wrong type, names are not unique, a parent, closure body, coupled joint,
        site body or actuated joint is unknown, an actuated or coupled joint is not a hinge or slide,
        or ``characteristic_length`` is not positive.
    """

    bodies: tuple[Body, ...]
    closures: tuple[Closure, ...] = ()
    couplings: tuple[Coupling, ...] = ()
    sites: tuple[Site, ...] = ()
    actuated: tuple[str, ...] = ()
    gravity: tuple[float, ...] = (0.0, 0.0, -9.81)
    name: str = "mechanism"
    # Informative: the units of the quantities the user passes are SI; this is the length used to make
    # rotations and translations commensurate (residual scaling, conditioning); None: computed.
    characteristic_length: float | None = field(default=None)

    def __post_init__(self) -> None:
        for f, typ in (("bodies", Body), ("closures", Closure), ("couplings", Coupling), ("sites", Site)):
            raw = getattr(self, f)
            if not isinstance(raw, tuple | list) or not all(isinstance(v, typ) for v in raw):
                raise ValueError(f"Expected {f} to be a tuple of {typ.__name__} objects, got {raw!r}.")
            object.__setattr__(self, f, tuple(raw))
        if not isinstance(self.actuated, tuple | list) or not all(isinstance(a, str) for a in self.actuated):
            raise ValueError(f"Expected actuated to be a tuple of joint names, got {self.actuated!r}.")
        object.__setattr__(self, "actuated", tuple(self.actuated))
        object.__setattr__(self, "gravity", _vec(self.gravity, 3, "gravity"))
        _name(self.name, "name (of a Mechanism)")
        if len(self.bodies) == 0:
            raise ValueError("Expected bodies to hold at least one Body, got none.")
        object.__setattr__(self, "bodies", _depth_first(self.bodies))
        seen = {"world"}
        joints: dict[str, Joint] = {}
        for b in self.bodies:
            if b.name in seen:
                raise ValueError(f"Expected unique body names, got {b.name!r} twice.")
            if b.parent not in seen:
                raise ValueError(
                    f"Expected the parent {b.parent!r} of body {b.name!r} to be 'world' or an earlier body."
                )
            seen.add(b.name)
            for j in b.joints:
                if j.name in joints:
                    raise ValueError(f"Expected unique joint names, got {j.name!r} twice.")
                joints[j.name] = j
        names: set[str] = set()
        for cname in (*(c.name for c in self.closures), *(cp.name for cp in self.couplings)):
            if cname in names:
                raise ValueError(f"Expected unique closure/coupling names, got {cname!r} twice.")
            names.add(cname)
        for c in self.closures:
            for bn in (c.body1, c.body2):
                if bn not in seen:
                    raise ValueError(f"Closure {c.name!r} names unknown body {bn!r}.")
        for cp in self.couplings:
            for jn in (cp.joint1, cp.joint2):
                if jn is None:
                    continue
                if jn not in joints:
                    raise ValueError(f"Coupling {cp.name!r} names unknown joint {jn!r}.")
                if joints[jn].type not in ("hinge", "slide"):
                    raise ValueError(f"Expected coupling {cp.name!r} to join hinge/slide joints, got {jn!r}.")
        site_names = set()
        for s in self.sites:
            if s.name in site_names:
                raise ValueError(f"Expected unique site names, got {s.name!r} twice.")
            site_names.add(s.name)
            if s.body not in seen:
                raise ValueError(f"Site {s.name!r} is on unknown body {s.body!r}.")
        if len(set(self.actuated)) != len(self.actuated):
            raise ValueError(f"Expected each actuated joint once, got {self.actuated!r}.")
        for a in self.actuated:
            if a not in joints:
                raise ValueError(f"Expected actuated joints among the joints, got unknown {a!r}.")
            if joints[a].type not in ("hinge", "slide"):
                raise ValueError(
                    f"Expected actuated joint {a!r} to be a hinge or slide, got {joints[a].type!r}."
                )
        if self.characteristic_length is not None:
            from robomech._validation import check_positive

            L = check_positive(self.characteristic_length, "characteristic_length")
            object.__setattr__(self, "characteristic_length", L)

    # -- derived: the compiled model (``_compile.compile_model``, built once, kept outside the description)
    @property
    def tree(self):
        """The compiled spanning tree (``_tree.Tree``) of ``_compile.compile_model``."""
        from ._compile import compile_model

        return compile_model(self).tree

    @property
    def constraints(self):
        """The compiled closure rows (``_constraints.Constraints``) of ``_compile.compile_model``."""
        from ._compile import compile_model

        return compile_model(self).constraints

    @property
    def joints(self) -> tuple[Joint, ...]:
        return tuple(j for b in self.bodies for j in b.joints)

    @property
    def nq(self) -> int:
        return self.tree.nq

    @property
    def nv(self) -> int:
        return self.tree.nv

    @property
    def q0(self) -> np.ndarray:
        """Reference configuration, (nq,): MuJoCo's qpos0 if it satisfies the closures, else the
        assembly nearest to it (``_reference``, in the compile step; a description that cannot assemble
        raises ValueError)."""
        from ._compile import compile_model

        return compile_model(self).q_ref.copy()

    @property
    def length(self) -> float:
        """The characteristic length (m) that makes rotations and translations commensurate."""
        return self.tree.length

    def _repr_png_(self) -> bytes:
        """Jupyter's picture of the mechanism: its wireframe at ``q0`` (Agg canvas, no pyplot)."""
        from ._repr import mechanism_png

        return mechanism_png(self)

    def site(self, name: str) -> Site:
        for s in self.sites:
            if s.name == name:
                return s
        raise ValueError(f"Expected a site name among {[s.name for s in self.sites]}, got {name!r}.")

    def joint(self, name: str) -> Joint:
        for j in self.joints:
            if j.name == name:
                return j
        raise ValueError(f"Expected a joint name among {[j.name for j in self.joints]}, got {name!r}.")

    def qpos_address(self, joint: str) -> int:
        """Index of the first ``qpos`` entry of ``joint``."""
        return int(self.tree.jnt_qadr[self.tree.joint_index(joint)])

    def dof_address(self, joint: str) -> int:
        """Index of the first velocity coordinate (``qvel`` entry) of ``joint``."""
        return int(self.tree.jnt_dadr[self.tree.joint_index(joint)])


def _depth_first(bodies: tuple[Body, ...]) -> tuple[Body, ...]:
    """Bodies in MuJoCo's order (depth-first, children in the order given), so that ``q`` is its qpos.

    Parents must come before their children in the input (checked afterwards); any body whose parent
    is unknown is left at the end for that check to name.
    """
    children: dict[str, list[Body]] = {}
    for b in bodies:
        children.setdefault(b.parent, []).append(b)
    out: list[Body] = []
    stack = list(reversed(children.get("world", [])))
    while stack:
        b = stack.pop()
        out.append(b)
        stack.extend(reversed(children.get(b.name, [])))
    placed = {id(b) for b in out}
    return tuple(out) + tuple(b for b in bodies if id(b) not in placed)


class Builder:
    """Assemble a :class:`Mechanism` in Python (no XML), MuJoCo semantics throughout.

    The builder only collects descriptions; ``Builder.build()`` returns the frozen, validated mechanism.
    A closure anchor not given on the second body is computed at the reference configuration
    (MuJoCo's qpos0 semantics for ``connect`` and ``weld``).  Joints come from the static makers
    :meth:`hinge`, :meth:`slide`, :meth:`ball`, :meth:`free`, :meth:`universal`; :meth:`helical` also
    records its coupling.

    Parameters
    ----------
    name : str, optional
        Non-empty mechanism name.
    gravity : array_like, shape (3,), optional
        Gravitational acceleration in the world frame (m/s^2); default ``(0, 0, -9.81)``.

    Raises
    ------
    ValueError
        If ``name`` is empty or ``gravity`` is not 3 finite reals (the element methods and
        :meth:`build` raise as the dataclasses they make do).

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> b = mb.Builder("pendulum")
    >>> b.body("link", joints=[b.hinge("a", axis=(0, 1, 0))], inertial=mb.Inertial(1.0, pos=(0.5, 0, 0)))
    'link'
    >>> b.site("tip", "link", pos=(1.0, 0, 0))
    'tip'
    >>> b.actuate("a")
    >>> mech = b.build()
    >>> mech.nq, mech.actuated
    (1, ('a',))
    >>> np.round(mb.site_pose(mech, [np.pi / 2], "tip")[:3, 3], 6) + 0.0
    array([ 0.,  0., -1.])
    """

    def __init__(self, name: str = "mechanism", gravity: Vector = (0.0, 0.0, -9.81)) -> None:
        self.name = _name(name, "name (of the mechanism)")
        self.gravity = _vec(gravity, 3, "gravity")
        self._bodies: list[Body] = []
        self._sites: list[Site] = []
        self._closures: list[tuple] = []
        self._couplings: list[Coupling] = []
        self._actuated: list[str] = []

    # joints
    @staticmethod
    def hinge(name: str, axis: Vector = (0, 0, 1), pos: Vector = (0, 0, 0), ref: float = 0.0) -> Joint:
        """A hinge ``Joint`` about ``axis`` (body frame) through ``pos`` (m), zero at ``ref`` (rad)."""
        return Joint(name, "hinge", _vec(axis, 3, "axis"), _vec(pos, 3, "pos"), ref)

    @staticmethod
    def slide(name: str, axis: Vector = (0, 0, 1), pos: Vector = (0, 0, 0), ref: float = 0.0) -> Joint:
        """A slide ``Joint`` along ``axis`` (body frame), zero at ``ref`` (m)."""
        return Joint(name, "slide", _vec(axis, 3, "axis"), _vec(pos, 3, "pos"), ref)

    @staticmethod
    def ball(name: str, pos: Vector = (0, 0, 0)) -> Joint:
        """A ball ``Joint`` centred at ``pos`` (body frame, m): 4 ``qpos`` (quaternion), 3 ``qvel``."""
        return Joint(name, "ball", (0.0, 0.0, 1.0), _vec(pos, 3, "pos"))

    @staticmethod
    def free(name: str) -> Joint:
        """A free ``Joint`` (top-level bodies only): 7 ``qpos`` ``(x, y, z, qw, qx, qy, qz)``, 6 ``qvel``."""
        return Joint(name, "free")

    @staticmethod
    def universal(name: str, axis1: Vector, axis2: Vector, pos: Vector = (0, 0, 0)) -> tuple[Joint, Joint]:
        """A universal joint as two hinges through one point (``name_1`` then ``name_2``)."""
        return (
            Joint(f"{name}_1", "hinge", _vec(axis1, 3, "axis1"), _vec(pos, 3, "pos")),
            Joint(f"{name}_2", "hinge", _vec(axis2, 3, "axis2"), _vec(pos, 3, "pos")),
        )

    def helical(self, name: str, axis: Vector, pitch: float, pos: Vector = (0, 0, 0)) -> tuple[Joint, Joint]:
        """A helical joint: hinge ``name_r`` and slide ``name_p`` coupled by ``p = pitch * theta`` (m/rad)."""
        pitch = check_real(pitch, "pitch")
        axis, pos = _vec(axis, 3, "axis"), _vec(pos, 3, "pos")
        r = Joint(f"{name}_r", "hinge", axis, pos)
        p = Joint(f"{name}_p", "slide", axis, pos)
        self._couplings.append(Coupling(name, p.name, r.name, (0.0, pitch, 0.0, 0.0, 0.0)))
        return r, p

    # elements
    def body(
        self,
        name: str,
        parent: str = "world",
        pos: Vector = (0, 0, 0),
        quat: Vector = (1, 0, 0, 0),
        joints: Sequence[Joint | tuple[Joint, ...]] = (),
        inertial: Inertial | None = None,
    ) -> str:
        """Add a body (parents before children); ``inertial=None`` lets MJCF export derive it from geoms."""
        if joints is None or isinstance(joints, str | bytes) or not isinstance(joints, Sequence):
            raise ValueError(f"Expected joints to be a sequence of Joint, got {type(joints).__name__}.")
        flat: list[Joint] = []
        for j in joints:
            flat.extend(j if isinstance(j, tuple) else (j,))
        self._bodies.append(
            Body(name, parent, _vec(pos, 3, "pos"), _vec(quat, 4, "quat"), tuple(flat), inertial)
        )
        return name

    def site(self, name: str, body: str, pos: Vector = (0, 0, 0), quat: Vector = (1, 0, 0, 0)) -> str:
        """Add a site on ``body`` at ``pos`` (m), ``quat`` ``[w, x, y, z]`` (body frame); returns the name."""
        self._sites.append(Site(name, body, _vec(pos, 3, "pos"), _vec(quat, 4, "quat")))
        return name

    def connect(
        self,
        name: str,
        body1: str,
        body2: str,
        anchor1: Vector,
        anchor2: Vector | None = None,
    ) -> None:
        """Point closure (MuJoCo ``connect``): ``anchor2`` defaults to the coincident point at q0."""
        a2 = None if anchor2 is None else _vec(anchor2, 3, "anchor2")
        self._closures.append(("point", name, body1, body2, _vec(anchor1, 3, "anchor1"), a2, None))

    def revolute(
        self,
        name: str,
        body1: str,
        body2: str,
        anchor1: Vector,
        axis: Vector,
        anchor2: Vector | None = None,
    ) -> None:
        """Hinge closure: as :meth:`connect`, and ``axis`` (body1 frame) fixed in body2."""
        a2 = None if anchor2 is None else _vec(anchor2, 3, "anchor2")
        a1, ax = _vec(anchor1, 3, "anchor1"), _vec(axis, 3, "axis")
        self._closures.append(("revolute", name, body1, body2, a1, a2, ax))

    def weld(
        self,
        name: str,
        body1: str,
        body2: str,
        relpos: Vector | None = None,
        relquat: Vector | None = None,
        anchor2: Vector = (0, 0, 0),
    ) -> None:
        """Rigid closure (MuJoCo ``weld``): body2's pose in body1; default: the pose at q0."""
        rel = (
            None
            if relpos is None
            else (
                _vec(relpos, 3, "relpos"),
                _vec(relquat if relquat is not None else (1, 0, 0, 0), 4, "relquat"),
            )
        )
        self._closures.append(("rigid", name, body1, body2, _vec(anchor2, 3, "anchor2"), rel, None))

    def couple(self, name: str, joint1: str, joint2: str | None, polycoef: Vector) -> None:
        """Add a :class:`Coupling` (``polycoef`` padded with zeros to 5 coefficients)."""
        pc = as_array(polycoef, "polycoef", (None,))
        if pc.ndim != 1 or not 1 <= pc.shape[0] <= 5:
            raise ValueError(f"Expected polycoef to have 1 to 5 coefficients, got shape {pc.shape}.")
        c = tuple(float(v) for v in pc) + (0.0,) * (5 - pc.shape[0])
        self._couplings.append(Coupling(name, joint1, joint2, c))

    def actuate(self, *joints: str) -> None:
        """Mark hinge / slide ``joints`` as actuated, appended in actuator order."""
        self._actuated.extend(joints)

    def build(self) -> Mechanism:
        """The frozen, validated :class:`Mechanism` (closure anchors / poses not given: those at q0)."""
        # First the tree (no closures) to evaluate reference poses for MuJoCo's qpos0 defaults.
        tree_only = Mechanism(
            tuple(self._bodies),
            (),
            tuple(self._couplings),
            tuple(self._sites),
            tuple(self._actuated),
            self.gravity,
            self.name,
        )
        # Its tree and assembled reference only (the compile step's q_ref), not its whole compiled model:
        # the mechanism is compiled once, below.
        from ._compile import _tables, build_tree
        from ._compiled import compiled_body_poses
        from ._constraints import compile_constraints
        from ._reference import assembled_reference

        tree0 = build_tree(tree_only)
        cs0 = compile_constraints(tree_only, tree0)
        tables0 = _tables(tree0, cs0)
        q_ref0 = assembled_reference(tree_only, tree0, cs0, tables0)
        T0 = compiled_body_poses(tables0, q_ref0[None])[0]

        def pose(body: str) -> np.ndarray:
            return T0[tree0.body_index(body)]

        closures = []
        for kind, name, b1, b2, a, other, axis in self._closures:
            T1, T2 = pose(b1), pose(b2)
            if kind in ("point", "revolute"):
                a1 = np.asarray(a, float)
                if other is None:
                    p = T1[:3, :3] @ a1 + T1[:3, 3]
                    a2 = T2[:3, :3].T @ (p - T2[:3, 3])
                else:
                    a2 = np.asarray(other, float)
                ax1 = np.asarray(axis if axis is not None else (0.0, 0.0, 1.0), float)
                ax2 = T2[:3, :3].T @ (T1[:3, :3] @ ax1)
                closures.append(
                    Closure(name, kind, b1, b2, tuple(a1), tuple(a2), axis=tuple(ax1), axis2=tuple(ax2))
                )
            else:
                if other is None:
                    T12 = np.linalg.solve(T1, T2)
                    relpos, relquat = T12[:3, 3], _quat_from_matrix(T12[:3, :3])
                else:
                    relpos, relquat = other
                closures.append(
                    Closure(
                        name, "rigid", b1, b2, anchor2=tuple(a), relpos=tuple(relpos), relquat=tuple(relquat)
                    )
                )
        mech = Mechanism(
            tuple(self._bodies),
            tuple(closures),
            tuple(self._couplings),
            tuple(self._sites),
            tuple(self._actuated),
            self.gravity,
            self.name,
        )
        from ._compile import compile_model

        # assemble the reference now (a description that cannot assemble raises here), on the tree
        # compiled above: the closures are not part of the tree
        compile_model(mech, _tree=tree0)
        return mech


def _quat_from_matrix(R: np.ndarray) -> np.ndarray:
    """Unit quaternion [w, x, y, z] (w >= 0) of a rotation matrix (Shepperd's method).

    Raises ``ValueError`` when ``R`` is not a proper rotation (a silently projected non-orthogonal
    frame once gave a joint undocumented axes).
    """
    R = np.asarray(R, float)
    if R.shape != (3, 3) or not np.all(np.isfinite(R)):
        raise ValueError(f"rotation matrix: expected a finite (3, 3) array, got shape {R.shape}")
    orth = float(np.max(np.abs(R.T @ R - np.eye(3))))
    det = float(np.linalg.det(R))
    if orth > ROTATION_TOL or abs(det - 1.0) > ROTATION_TOL:
        raise ValueError(
            f"rotation matrix: expected a proper rotation (R^T R = I within {ROTATION_TOL:g}, det R = +1), "
            f"got max |R^T R - I| = {orth:.3g}, det R = {det:.6g}"
        )
    tr = np.trace(R)
    if tr > 0:
        s = 2.0 * np.sqrt(1.0 + tr)
        q = np.array([0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s])
    else:
        i = int(np.argmax(np.diag(R)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * np.sqrt(1.0 + R[i, i] - R[j, j] - R[k, k])
        q = np.empty(4)
        q[0] = (R[k, j] - R[j, k]) / s
        q[1 + i] = 0.25 * s
        q[1 + j] = (R[j, i] + R[i, j]) / s
        q[1 + k] = (R[k, i] + R[i, k]) / s
    q = q / np.linalg.norm(q)
    return q if q[0] >= 0 else -q
