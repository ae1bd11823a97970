"""MJCF in (through MuJoCo's own compiler, ``MjSpec``) and out (``xml.etree``, full float precision).

Reading compiles the file with MuJoCo, so defaults classes, ``<frame>``, euler/axis-angle/xyaxes
orientations, ``fromto``, degrees and inertia-from-geoms are MuJoCo's own, and the closure data of
``connect``/``weld`` are taken after MuJoCo has resolved them at ``qpos0`` (``eq_data``).  Writing uses
``xml.etree.ElementTree`` rather than ``MjSpec.to_xml``: the latter (MuJoCo 3.x/4.0) prints six
significant digits and drops explicit inertials, which would break the 1e-10 round trips.
MuJoCo is an optional dependency (``pip install robomech[verify]``): only :func:`from_mjcf` needs it.
"""

from __future__ import annotations

import codecs
import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from ._compile import compile_model
from ._model import (
    ASSEMBLED_RTOL,
    Body,
    Closure,
    Coupling,
    Inertial,
    Joint,
    Mechanism,
    Site,
    _quat_from_matrix,
)
from ._tree import quat_to_matrix

__all__ = ["AUX_SITE_PREFIX", "from_mjcf", "to_mjcf"]

# The keyframe to_mjcf writes with the assembled reference of a description typed unassembled
ASSEMBLED_KEY = "assembled"
# Sites written by to_mjcf to express a point closure whose anchors do not coincide at qpos0
# (MuJoCo's site form of <connect>); from_mjcf does not list them as the mechanism's sites.
AUX_SITE_PREFIX = "_closure_"
_JTYPE = {0: "free", 1: "ball", 2: "slide", 3: "hinge"}


def _import_mujoco():
    try:
        import mujoco
    except ImportError as exc:  # pragma: no cover - exercised only without the optional extra
        raise ImportError(
            "robomech.multibody.from_mjcf needs MuJoCo to read MJCF: "
            "pip install 'robomech[verify]' (mujoco>=3.1)."
        ) from exc
    return mujoco


def _is_xml(text: str) -> bool:
    return text.lstrip().startswith("<")


_XML_DECLARATION = re.compile(rb"""^\s*<\?xml[^>]*?\bencoding\s*=\s*["']([A-Za-z0-9._-]+)["']""")


def _declared_encoding_text(path: Path) -> str | None:
    """The file's text, transcoded, when its XML declaration names an encoding other than UTF-8.

    MuJoCo's parser reads bytes as UTF-8 whatever the declaration says; an XML file may be in any
    encoding its declaration names (XML 1.0, section 4.3.3), so such a file is decoded here and
    handed over as text.  None for a UTF-8 (or undeclared) file, which MuJoCo reads itself.
    """
    with path.open("rb") as fh:
        head = fh.read(200)
    match = _XML_DECLARATION.match(head)
    if match is None:
        return None
    name = match.group(1).decode("ascii")
    try:
        codec = codecs.lookup(name).name
    except LookupError as exc:
        raise ValueError(
            f"Expected path_or_xml to declare an encoding Python knows, got encoding={name!r} "
            f"in {str(path)!r}."
        ) from exc
    if codec in ("utf-8", "ascii"):
        return None
    try:
        text = path.read_bytes().decode(codec)
    except UnicodeDecodeError as exc:
        raise ValueError(
            f"Expected path_or_xml to be {name}-encoded as its XML declaration says, got a byte that is not "
            f"{name} ({exc.reason} at byte {exc.start}) in {str(path)!r}."
        ) from exc
    # the declaration now describes the text handed over, not the file's bytes
    declaration = r"^(\s*<\?xml[^>]*?\bencoding\s*=\s*)([\"'])[A-Za-z0-9._-]+\2"
    return re.sub(declaration, r"\1\2UTF-8\2", text, count=1)


def _compile(mujoco, source: str | os.PathLike):
    try:
        if isinstance(source, str) and _is_xml(source):
            spec = mujoco.MjSpec.from_string(source)
        else:
            path = Path(source)
            if not path.is_file():
                raise ValueError(
                    f"Expected path_or_xml to be MJCF text or an existing file, got {str(source)!r}."
                )
            text = _declared_encoding_text(path)
            if text is None:
                spec = mujoco.MjSpec.from_file(str(path))
            else:
                spec = mujoco.MjSpec.from_string(text)
                spec.modelfiledir = str(path.parent.resolve())  # meshes/textures relative to the file
        return spec.compile()
    except ValueError as exc:
        if "Expected path_or_xml" in str(exc):
            raise
        raise ValueError(f"Expected path_or_xml to be MJCF that MuJoCo compiles; MuJoCo says: {exc}") from exc


def from_mjcf(path_or_xml: str | os.PathLike) -> Mechanism:
    """Read an MJCF file (path) or MJCF text into a :class:`Mechanism`.

    Bodies, joints (hinge, slide, ball, free), sites, inertials, ``<equality>`` ``connect`` (body and
    site forms), ``weld`` (body and site forms) and ``joint`` couplings, ``<actuator>`` joint
    transmissions (their order is ``mech.actuated``) and ``<option gravity>``.  Elements that would
    change the mechanism and are not supported — tendons, flexes, mocap bodies, tendon/flex/distance
    equalities, actuators on tendons, sites or bodies — raise ``ValueError`` naming them.  Inactive
    equalities (``active="false"``) are not constraints of the mechanism and are left out.
    Simulation settings (timestep, solver, contacts, limits, visuals) are ignored.

    Parameters
    ----------
    path_or_xml : str or os.PathLike
        A path to an MJCF file, or MJCF text (a string starting with ``<``).

    Returns
    -------
    Mechanism
        The frozen, validated description (``q`` is MuJoCo's ``qpos``; lengths in m, angles in rad).

    Examples
    --------
    >>> from robomech import multibody as mb
    >>> mech = mb.from_mjcf(mb.gallery.path("four_bar"))
    >>> mech.actuated, mech.nq, [b.name for b in mech.bodies]
    (('theta2',), 3, ['crank', 'coupler', 'rocker'])
    """
    try:
        mech = _read(path_or_xml)
    except UnicodeDecodeError as exc:  # MuJoCo hands names over as UTF-8 bytes
        raise ValueError(
            "Expected path_or_xml to be UTF-8 encoded MJCF (MuJoCo reads names as UTF-8), got a name "
            f"that is not UTF-8 ({exc.reason} at byte {exc.start}): save the file as UTF-8."
        ) from exc
    return mech


def _read(path_or_xml: str | os.PathLike) -> Mechanism:
    if not isinstance(path_or_xml, str | os.PathLike):
        raise ValueError(f"Expected path_or_xml to be a path or MJCF text, got {type(path_or_xml).__name__}.")
    _refuse_urdf(path_or_xml)
    mujoco = _import_mujoco()
    return mechanism_from_model(mujoco, _compile(mujoco, path_or_xml))


def _refuse_urdf(source: str | os.PathLike) -> None:
    """ValueError if ``source`` is URDF (root ``<robot>``): MuJoCo would read it without actuators."""
    try:
        if isinstance(source, str) and _is_xml(source):
            root = ET.fromstring(source)
        elif Path(source).is_file():
            root = ET.parse(Path(source)).getroot()
        else:
            return
    except (ET.ParseError, LookupError):  # malformed XML, an encoding Python does not know
        return  # reported by _compile
    if root.tag == "robot":
        raise ValueError(
            "Expected path_or_xml to be MJCF (root <mujoco>), got URDF (root <robot>): "
            "this is URDF; use robomech.multibody.from_urdf."
        )


def mechanism_from_model(mujoco, m, *, actuated: tuple[str, ...] | None = None) -> Mechanism:
    """The :class:`Mechanism` of a compiled ``MjModel`` ``m`` (shared by the MJCF and URDF readers).

    ``actuated`` (joint names) replaces the model's actuators when given.
    """
    unsupported = [
        ("tendon", m.ntendon),
        ("flex", m.nflex),
        ("mocap body", m.nmocap),
    ]
    for what, n in unsupported:
        if n:
            raise ValueError(
                f"Expected path_or_xml without {what}s (robomech.multibody does not support them: they "
                f"change the mechanism), got {n} {what}(s)."
            )

    def nm(obj, prefix: str, i: int) -> str:
        return obj.name if obj.name else f"{prefix}{i}"

    body_names = ["world"] + [nm(m.body(i), "body", i) for i in range(1, m.nbody)]
    jnt_names = [nm(m.joint(j), "joint", j) for j in range(m.njnt)]
    bodies = []
    for i in range(1, m.nbody):
        joints = []
        for j in range(m.body_jntadr[i], m.body_jntadr[i] + m.body_jntnum[i]):
            typ = _JTYPE[int(m.jnt_type[j])]
            ref = float(m.qpos0[m.jnt_qposadr[j]]) if typ in ("hinge", "slide") else 0.0
            axis = m.jnt_axis[j] if typ in ("hinge", "slide") else (0.0, 0.0, 1.0)
            joints.append(Joint(jnt_names[j], typ, tuple(axis), tuple(m.jnt_pos[j]), ref))
        inertial = Inertial(
            float(m.body_mass[i]), tuple(m.body_ipos[i]), tuple(m.body_iquat[i]), tuple(m.body_inertia[i])
        )
        bodies.append(
            Body(
                body_names[i],
                body_names[m.body_parentid[i]],
                tuple(m.body_pos[i]),
                tuple(m.body_quat[i]),
                tuple(joints),
                inertial,
            )
        )
    site_names = [nm(m.site(s), "site", s) for s in range(m.nsite)]
    sites = [
        Site(site_names[s], body_names[m.site_bodyid[s]], tuple(m.site_pos[s]), tuple(m.site_quat[s]))
        for s in range(m.nsite)
        if not site_names[s].startswith(AUX_SITE_PREFIX)
    ]
    closures, couplings = [], []
    eq = mujoco.mjtEq
    site_t = int(mujoco.mjtObj.mjOBJ_SITE)
    for e in range(m.neq):
        if not m.eq_active0[e]:
            continue
        eq_typ, o1, o2 = int(m.eq_type[e]), int(m.eq_obj1id[e]), int(m.eq_obj2id[e])
        d = np.array(m.eq_data[e])
        name = m.eq(e).name or f"equality{e}"
        sites_form = int(m.eq_objtype[e]) == site_t
        if eq_typ == int(eq.mjEQ_CONNECT):
            if sites_form:
                closures.append(
                    Closure(
                        name,
                        "point",
                        body_names[m.site_bodyid[o1]],
                        body_names[m.site_bodyid[o2]],
                        tuple(m.site_pos[o1]),
                        tuple(m.site_pos[o2]),
                    )
                )
            else:
                closures.append(
                    Closure(name, "point", body_names[o1], body_names[o2], tuple(d[0:3]), tuple(d[3:6]))
                )
        elif eq_typ == int(eq.mjEQ_WELD):
            if sites_form:
                # MuJoCo's site weld: the two site frames coincide.
                T1 = np.eye(4)
                T1[:3, :3], T1[:3, 3] = quat_to_matrix(np.array(m.site_quat[o1])), m.site_pos[o1]
                T2 = np.eye(4)
                T2[:3, :3], T2[:3, 3] = quat_to_matrix(np.array(m.site_quat[o2])), m.site_pos[o2]
                T12 = T1 @ np.linalg.inv(T2)
                closures.append(
                    Closure(
                        name,
                        "rigid",
                        body_names[m.site_bodyid[o1]],
                        body_names[m.site_bodyid[o2]],
                        anchor2=tuple(m.site_pos[o2]),
                        relpos=tuple(T12[:3, 3]),
                        relquat=tuple(_quat_from_matrix(T12[:3, :3])),
                    )
                )
            else:
                # eq_data: anchor (body2 frame), the anchor in body1's frame, the relative quaternion.
                Rrel = quat_to_matrix(d[6:10] / np.linalg.norm(d[6:10]))
                relpos = d[3:6] - Rrel @ d[0:3]
                closures.append(
                    Closure(
                        name,
                        "rigid",
                        body_names[o1],
                        body_names[o2],
                        anchor2=tuple(d[0:3]),
                        relpos=tuple(relpos),
                        relquat=tuple(d[6:10]),
                    )
                )
        elif eq_typ == int(eq.mjEQ_JOINT):
            couplings.append(Coupling(name, jnt_names[o1], jnt_names[o2] if o2 >= 0 else None, tuple(d[0:5])))
        else:
            kind = {int(getattr(eq, k)): k for k in dir(eq) if k.startswith("mjEQ_")}.get(eq_typ, str(eq_typ))
            raise ValueError(
                "Expected path_or_xml with connect, weld and joint equalities only (robomech.multibody "
                f"supports those), got equality {name!r} of type {kind}."
            )
    actuated_given = actuated
    motors: list[str] = []
    for a in range(m.nu):
        if int(m.actuator_trntype[a]) != int(mujoco.mjtTrn.mjTRN_JOINT):
            raise ValueError(
                f"Expected path_or_xml with joint actuators only (robomech.multibody supports joint "
                f"transmissions), got actuator {m.actuator(a).name or f'number {a} (unnamed)'!r} with a "
                f"{mujoco.mjtTrn(int(m.actuator_trntype[a])).name} transmission."
            )
        motors.append(jnt_names[m.actuator_trnid[a, 0]])
    if actuated_given is not None:
        motors = list(actuated_given)
    name = m.names[: m.names.index(b"\0")].decode() if m.names else "mechanism"
    mech = Mechanism(
        tuple(bodies),
        tuple(closures),
        tuple(couplings),
        tuple(sites),
        tuple(motors),
        tuple(m.opt.gravity),
        name or "mechanism",
    )
    mech.q0  # noqa: B018 - assemble the reference now: a file that can never assemble raises at load
    return mech


def _f(x) -> str:
    return " ".join(repr(float(v)) for v in np.atleast_1d(np.asarray(x, dtype=float)))


def to_mjcf(mech: Mechanism, *, comment: str | None = None) -> str:
    """MJCF text of ``mech`` that MuJoCo loads and :func:`from_mjcf` reads back to the same mechanism.

    Angles in radians, every float at full precision, visual capsules (no contacts) from each body's
    origin to its children, joint anchors, closure anchors and sites so the model is visible in
    MuJoCo's viewer.  Bodies without an :class:`Inertial` get MuJoCo's inertia from these geoms.
    A ``revolute`` closure is written as two ``connect`` elements ``name`` and ``name/axis`` one
    characteristic length apart along the axis (MJCF has no hinge equality).  ``comment`` is written
    as an XML comment at the top of the model.  A description whose closures are not closed at
    ``qpos0`` (assembled at load, :attr:`Mechanism.q0`) also gets a keyframe ``assembled`` holding the
    assembled reference, from which MuJoCo starts closed (``mj_resetDataKeyframe``).

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    comment : str, optional
        An XML comment written at the top of the model.

    Returns
    -------
    str
        MJCF text (radians, full-precision floats).

    Examples
    --------
    >>> from robomech import multibody as mb
    >>> xml = mb.to_mjcf(mb.gallery.load("four_bar"))
    >>> xml.splitlines()[0], mb.from_mjcf(xml).actuated
    ('<mujoco model="four_bar">', ('theta2',))
    """
    if not isinstance(mech, Mechanism):
        raise ValueError(f"Expected mech to be a robomech.multibody.Mechanism, got {type(mech).__name__}.")
    if comment is not None and not isinstance(comment, str):
        raise ValueError(f"Expected comment to be None or a string, got {comment!r}.")
    bad = sorted({c for c in comment or "" if (ord(c) < 32 and c not in "\t\n\r") or c in "\ufffe\uffff"})
    if bad:  # XML 1.0 has no such characters: the file could not be read back
        raise ValueError(f"Expected comment to hold no control characters (XML cannot), got {bad!r}.")
    tree = mech.tree
    L = tree.length
    radius = 0.02 * L
    from ._compiled import compiled_body_poses  # numba loads on the first kernel call, not at import

    T0 = compiled_body_poses(compile_model(mech), tree.q0[None])[0]
    root = ET.Element("mujoco", model=mech.name)
    if comment:
        root.append(ET.Comment(" " + comment.replace("--", "- -").strip() + " "))
    ET.SubElement(root, "compiler", angle="radian", autolimits="true")
    ET.SubElement(root, "option", gravity=_f(mech.gravity))
    default = ET.SubElement(root, "default")
    ET.SubElement(default, "geom", contype="0", conaffinity="0", rgba="0.3 0.5 0.8 1")
    world = ET.SubElement(root, "worldbody")
    elems = {"world": world}
    # points of each body to draw to (body frame)
    targets: dict[str, list[np.ndarray]] = {b.name: [] for b in mech.bodies}
    targets["world"] = []
    for b in mech.bodies:
        targets[b.parent].append(np.asarray(b.pos))
        for j in b.joints:
            targets[b.name].append(np.asarray(j.pos))
    for s in mech.sites:
        targets[s.body].append(np.asarray(s.pos))
    for c in mech.closures:
        targets[c.body1].append(np.asarray(c.anchor1 if c.kind != "rigid" else c.relpos))
        targets[c.body2].append(np.asarray(c.anchor2))
    aux_sites: dict[str, list[tuple[str, np.ndarray]]] = {}
    equality = ET.Element("equality")
    for c in mech.closures:
        b1, b2 = tree.body_index(c.body1), tree.body_index(c.body2)
        if c.kind in ("point", "revolute"):
            pairs = [(c.name, np.asarray(c.anchor1), np.asarray(c.anchor2))]
            if c.kind == "revolute":
                pairs.append(
                    (
                        f"{c.name}/axis",
                        np.asarray(c.anchor1) + L * np.asarray(c.axis),
                        np.asarray(c.anchor2) + L * np.asarray(c.axis2),
                    )
                )
            for name, a1, a2 in pairs:
                p1 = T0[b1, :3, :3] @ a1 + T0[b1, :3, 3]
                p2 = T0[b2, :3, :3] @ a2 + T0[b2, :3, 3]
                if np.linalg.norm(p1 - p2) <= ASSEMBLED_RTOL * L:
                    ET.SubElement(equality, "connect", name=name, body1=c.body1, body2=c.body2, anchor=_f(a1))
                else:  # anchors apart at qpos0: MuJoCo's site form keeps both anchors exactly
                    s1, s2 = f"{AUX_SITE_PREFIX}{name}_1", f"{AUX_SITE_PREFIX}{name}_2"
                    aux_sites.setdefault(c.body1, []).append((s1, a1))
                    aux_sites.setdefault(c.body2, []).append((s2, a2))
                    ET.SubElement(equality, "connect", name=name, site1=s1, site2=s2)
        else:
            # MuJoCo's engine uses relpose's position as body2's *anchor* seen from body1 (eq_data[3:6]),
            # which is body2's origin only for a zero anchor.
            p1 = np.asarray(c.relpos) + quat_to_matrix(np.asarray(c.relquat)) @ np.asarray(c.anchor2)
            ET.SubElement(
                equality,
                "weld",
                name=c.name,
                body1=c.body1,
                body2=c.body2,
                relpose=_f([*p1, *c.relquat]),
                anchor=_f(c.anchor2),
            )
    for cp in mech.couplings:
        attrs = {"name": cp.name, "joint1": cp.joint1, "polycoef": _f(cp.polycoef)}
        if cp.joint2 is not None:
            attrs["joint2"] = cp.joint2
        ET.SubElement(equality, "joint", attrs)

    def add_geoms(el: ET.Element, name: str) -> None:
        pts = [p for p in targets[name] if np.linalg.norm(p) > 1e-9 * L]
        if name != "world":
            ET.SubElement(el, "geom", type="sphere", size=_f(1.5 * radius))
        for p in pts:
            ET.SubElement(el, "geom", type="capsule", fromto=_f([0, 0, 0, *p]), size=_f(radius))

    add_geoms(world, "world")
    for sname, p in aux_sites.get("world", []):
        ET.SubElement(world, "site", name=sname, pos=_f(p))
    for b in mech.bodies:
        el = ET.SubElement(elems[b.parent], "body", name=b.name, pos=_f(b.pos), quat=_f(b.quat))
        elems[b.name] = el
        if b.inertial is not None:
            i = b.inertial
            ET.SubElement(
                el, "inertial", pos=_f(i.pos), quat=_f(i.quat), mass=_f(i.mass), diaginertia=_f(i.diaginertia)
            )
        for j in b.joints:
            attrs = {"name": j.name, "type": j.type}
            if j.type in ("hinge", "slide"):
                attrs.update(axis=_f(j.axis), pos=_f(j.pos), ref=_f(j.ref))
            elif j.type == "ball":
                attrs.update(pos=_f(j.pos))
            ET.SubElement(el, "joint", attrs)
        add_geoms(el, b.name)
        for sname, p in aux_sites.get(b.name, []):
            ET.SubElement(el, "site", name=sname, pos=_f(p))
    for s in mech.sites:
        ET.SubElement(elems[s.body], "site", name=s.name, pos=_f(s.pos), quat=_f(s.quat))
    if len(equality):
        root.append(equality)
    if mech.actuated:
        act = ET.SubElement(root, "actuator")
        for a in mech.actuated:
            ET.SubElement(act, "general", name=f"act_{a}", joint=a)
    q_ref = np.asarray(mech.q0, dtype=float)
    if not np.array_equal(q_ref, tree.q0):  # typed unassembled: MuJoCo's qpos0 leaves the closures open
        key = ET.SubElement(root, "keyframe")
        ET.SubElement(key, "key", name=ASSEMBLED_KEY, qpos=_f(q_ref))
    ET.indent(root)
    xml = ET.tostring(root, encoding="unicode")
    _check_mujoco_accepts(mech, xml)
    return xml


def _check_mujoco_accepts(mech: Mechanism, xml: str) -> None:
    """Refuse to export MJCF that MuJoCo would reject for a massless moving body (checked by MuJoCo
    itself where it is installed: its rule depends on the subtree, not on one body)."""
    try:
        import mujoco
    except ImportError:  # pragma: no cover - without the optional extra nothing can check the file
        return
    try:
        mujoco.MjModel.from_xml_string(xml)
    except ValueError as exc:
        msg = str(exc)
        if "mass and inertia" not in msg:
            raise
        found = re.search(r"Element name '([^']*)'", msg)
        body = found.group(1) if found else "?"
        raise ValueError(
            f"Expected mech's moving bodies to have mass and inertia (MuJoCo rejects the exported "
            f"file otherwise), got body {body!r} without: give it an Inertial(mass, diaginertia=...)."
        ) from exc
