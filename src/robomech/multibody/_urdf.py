"""URDF in, through MuJoCo's own URDF compiler (``MjSpec``), into a :class:`Mechanism`.

The URDF text is read with ``xml.etree`` first, for what MuJoCo's compiler does not keep:

* ``<mimic>`` elements (older MuJoCo versions drop them) become :class:`Coupling` s
  ``q_follower = multiplier * q_leader + offset``;
* every link is kept as a body (``<compiler fusestatic="false">``: MuJoCo would otherwise merge a link
  attached by a fixed joint into its parent) and gets a site of the same name at its frame, so
  ``site_pose(mech, q, "tool0")`` is the URDF frame of ``tool0``;
* mesh geometry whose file cannot be found (``package://`` paths, missing files) is dropped with a
  warning: the mechanism needs the ``<inertial>`` elements, not the meshes; visuals are discarded.

The compiled ``MjModel`` is turned into the description by the MJCF reader's own code
(:func:`robomech.multibody._mjcf.mechanism_from_model`).
"""

from __future__ import annotations

import dataclasses
import os
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

from ._mjcf import _import_mujoco, _is_xml, from_mjcf, mechanism_from_model, to_mjcf
from ._model import Closure, Coupling, Mechanism, Site

__all__ = ["from_urdf"]

_MOVING = ("revolute", "continuous", "prismatic", "floating")
_TYPES = (*_MOVING, "fixed", "planar")


def _read(path_or_text: str | os.PathLike) -> tuple[ET.Element, Path | None]:
    if not isinstance(path_or_text, str | os.PathLike):
        raise ValueError(
            f"Expected path_or_text to be a path or URDF text, got {type(path_or_text).__name__}."
        )
    try:
        if isinstance(path_or_text, str) and _is_xml(path_or_text):
            return ET.fromstring(path_or_text), None
        path = Path(path_or_text)
        if not path.is_file():
            raise ValueError(f"Expected path_or_text to be URDF text or an existing file, got {str(path)!r}.")
        return ET.parse(path).getroot(), path.parent
    except ET.ParseError as exc:
        raise ValueError(
            f"Expected path_or_text to be well-formed URDF XML; the XML parser says: {exc}"
        ) from exc
    except LookupError as exc:  # an encoding declaration Python does not know
        raise ValueError(f"Expected path_or_text to declare an encoding Python knows; {exc}.") from exc


def _drop_missing_meshes(root: ET.Element, folder: Path | None) -> None:
    """Remove visual/collision elements whose mesh file cannot be found (warning naming them)."""
    dropped = []
    for link in root.iter("link"):
        for kind in ("visual", "collision"):
            for el in list(link.findall(kind)):
                mesh = el.find("geometry/mesh")
                if mesh is None:
                    continue
                fname = mesh.get("filename", "")
                p = Path(fname)
                if not p.is_absolute() and folder is not None:
                    p = folder / p
                if fname.startswith("package://") or not p.is_file():
                    link.remove(el)
                    dropped.append(fname)
    if dropped:
        warnings.warn(
            f"from_urdf: {len(dropped)} mesh geometr{'y' if len(dropped) == 1 else 'ies'} with a file that "
            f"cannot be found left out (e.g. {dropped[0]!r}); inertias come from the <inertial> elements.",
            stacklevel=3,
        )


def _compile(mujoco, root: ET.Element, folder: Path | None):
    ext = root.find("mujoco")
    if ext is None:
        ext = ET.SubElement(root, "mujoco")
    comp = ext.find("compiler")
    if comp is None:
        comp = ET.SubElement(ext, "compiler")
    comp.set("fusestatic", "false")  # keep fixed-joint links (tool0, flanges) as bodies
    comp.set("discardvisual", "true")
    if folder is not None:
        comp.set("meshdir", str(folder))
    try:
        spec = mujoco.MjSpec.from_string(ET.tostring(root, encoding="unicode"))
        return spec.compile()
    except ValueError as exc:
        raise ValueError(
            f"Expected path_or_text to be URDF that MuJoCo compiles; MuJoCo says: {exc}"
        ) from exc


def _closures_from_snippet(mech: Mechanism, snippet: str) -> Mechanism:
    """``mech`` with the closures/couplings of an MJCF ``<equality>`` snippet (names are link/joint names)."""
    try:
        eq = ET.fromstring(snippet)
    except ET.ParseError as exc:
        raise ValueError(
            f"Expected closures to be an MJCF <equality> snippet; the XML parser says: {exc}"
        ) from exc
    if eq.tag != "equality":
        raise ValueError(
            f"Expected closures to be an MJCF <equality>...</equality> snippet, got root <{eq.tag}>."
        )
    root = ET.fromstring(to_mjcf(mech))
    old = root.find("equality")
    if old is not None:
        root.remove(old)
        for child in old:
            eq.append(child)
    # <equality> goes before <actuator> (MJCF section order does not matter to MuJoCo, but keep it tidy)
    root.append(eq)
    try:
        return from_mjcf(ET.tostring(root, encoding="unicode"))
    except ValueError as exc:  # an error in the snippet, not in the document it was merged into
        raise ValueError(
            f"Expected closures to be an <equality> snippet naming the URDF's links and joints; "
            f"loading it with the URDF failed: {exc}"
        ) from exc


def _iterable(x: object) -> bool:
    try:
        iter(x)  # type: ignore[call-overload]
    except TypeError:
        return False
    return True


def from_urdf(
    path_or_text: str | os.PathLike,
    *,
    actuated: Sequence[str] | None = None,
    closures: Sequence[Closure] | str | None = None,
) -> Mechanism:
    """Read a URDF file (path) or URDF text into a :class:`Mechanism`, through MuJoCo's URDF compiler.

    Links become bodies (fixed-joint links included: they are kept, not merged into their parent),
    ``revolute``/``continuous`` joints hinges, ``prismatic`` joints slides, ``floating`` joints free
    joints; inertias are the links' ``<inertial>``.  Every link is also a site of the same name at the
    link frame.  ``<mimic joint= multiplier= offset=>`` becomes a :class:`Coupling`
    ``q = multiplier * q_leader + offset``.  Joint limits, dynamics, transmissions and visuals are
    ignored; mesh files that cannot be found are left out with a warning.

    Parameters
    ----------
    path_or_text : str or os.PathLike
        A path to a URDF file, or URDF text (a string starting with ``<``).
    actuated : sequence of str, optional
        The actuated joint names, in actuator order.  Default: every non-fixed joint that is not a
        mimic joint, in file order.
    closures : sequence of Closure, or str, optional
        Loop closures a URDF cannot hold: :class:`Closure` objects naming links as bodies, or an MJCF
        ``<equality>`` snippet (``connect``, ``weld``, ``joint`` elements naming links and joints).

    Returns
    -------
    Mechanism
        The frozen, validated description (``q`` is MuJoCo's ``qpos`` of the URDF model).

    Raises
    ------
    ValueError
        If the text is not URDF, MuJoCo does not compile it, a named joint does not exist or is fixed,
        or a closure is not a :class:`Closure` / ``<equality>`` snippet.

    Examples
    --------
    >>> from robomech import multibody as mb
    >>> urdf = '''<robot name="r"><link name="a"/>
    ...   <link name="b"><inertial><mass value="1"/>
    ...     <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
    ...   <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    ...     <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'''
    >>> mech = mb.from_urdf(urdf)
    >>> mech.actuated, [s.name for s in mech.sites]
    (('j',), ['a', 'b'])
    """
    root, folder = _read(path_or_text)
    if root.tag != "robot":
        raise ValueError(f"Expected path_or_text to be URDF (root <robot>), got root <{root.tag}>.")
    if actuated is not None and (
        isinstance(actuated, str) or not _iterable(actuated) or not all(isinstance(a, str) for a in actuated)
    ):
        raise ValueError(f"Expected actuated to be None or a sequence of joint names, got {actuated!r}.")
    if closures is not None and not isinstance(closures, str):
        if not _iterable(closures) or not all(isinstance(c, Closure) for c in closures):
            raise ValueError(
                "Expected closures to be None, an MJCF <equality> snippet or a sequence of Closure, "
                f"got {closures!r}."
            )
    joints = root.findall("joint")
    for j in joints:
        if j.get("type") not in _TYPES:
            raise ValueError(
                f"Expected path_or_text to be URDF with joint types among {_TYPES}, "
                f"got {j.get('type')!r} (joint {j.get('name')!r})."
            )
    moving = [j.get("name", "") for j in joints if j.get("type") in _MOVING]
    fixed = {j.get("name", "") for j in joints if j.get("type") not in _MOVING}
    floating = {j.get("name", "") for j in joints if j.get("type") == "floating"}  # a free base
    couplings = []
    for j in joints:
        mimic = j.find("mimic")
        if mimic is not None:
            mult = float(mimic.get("multiplier", "1"))
            off = float(mimic.get("offset", "0"))
            couplings.append(
                Coupling(
                    f"mimic_{j.get('name')}",
                    j.get("name", ""),
                    mimic.get("joint"),
                    (off, mult, 0.0, 0.0, 0.0),
                )
            )
    followers = {c.joint1 for c in couplings}
    if actuated is None:
        act = tuple(n for n in moving if n not in followers and n not in floating)
    else:
        act = tuple(actuated)
        for a in act:
            if a in fixed:
                raise ValueError(f"Expected actuated to name non-fixed joints, got the fixed joint {a!r}.")
            if a in floating:
                raise ValueError(
                    f"Expected actuated to name revolute, continuous or prismatic joints, got the floating "
                    f"joint {a!r} (a free base)."
                )
            if a not in moving:
                raise ValueError(f"Expected actuated to name joints of the URDF (among {moving}), got {a!r}.")
    link_names = [lk.get("name", "") for lk in root.findall("link")]
    _drop_missing_meshes(root, folder)
    mujoco = _import_mujoco()
    m = _compile(mujoco, root, folder)
    mech = mechanism_from_model(mujoco, m, actuated=act)
    bodies = {b.name for b in mech.bodies}
    link_sites = tuple(Site(n, n if n in bodies else "world") for n in link_names)
    # MuJoCo >= 3.2 keeps a mimic as a joint equality, older versions drop it: add only the missing ones
    kept = {c.joint1 for c in mech.couplings}
    mech = dataclasses.replace(
        mech,
        sites=(*link_sites, *mech.sites),
        couplings=(*mech.couplings, *(c for c in couplings if c.joint1 not in kept)),
        name=root.get("name") or mech.name,
    )
    if isinstance(closures, str):
        mech = _closures_from_snippet(mech, closures)
    elif closures:
        mech = dataclasses.replace(mech, closures=(*mech.closures, *closures))
    return mech
