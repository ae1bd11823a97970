"""A described mechanism as a Pinocchio model: its spanning tree and its loop closures.

Pinocchio (``pip install "robomech[pinocchio]"``) is imported inside :func:`to_pinocchio` only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ._model import Mechanism

__all__ = ["PinocchioModel", "to_pinocchio"]

_HINGE, _SLIDE, _BALL, _FREE = 0, 1, 2, 3


@dataclass(frozen=True)
class PinocchioModel:
    """A mechanism in Pinocchio's terms (made by :func:`to_pinocchio`).

    Attributes
    ----------
    model : pinocchio.Model
        The spanning tree: one Pinocchio joint per description joint (hinge -> revolute about its axis,
        slide -> prismatic, ball -> spherical, free -> free-flyer), the bodies' inertias, gravity.
    constraints : list of pinocchio.RigidConstraintModel
        The loop closures: ``CONTACT_3D`` per point (a revolute closure is two points, as in the
        engine's rows), ``CONTACT_6D`` per rigid closure, between frames on the two bodies.
    body_frames : dict of str to int
        Every body's frame (``model.frames`` index), at the description's body frame.
    couplings : tuple of str
        The description's joint couplings (gears, lead screws), which have no Pinocchio constraint
        model: the tree and the closures are exact, these are left to the caller.
    """

    model: Any
    constraints: list
    body_frames: dict[str, int]
    couplings: tuple[str, ...]
    _joints: tuple  # per tree joint: (type, qpos address, dof address, ref, Pinocchio idx_q, idx_v)

    def state(self, q: object, qd: object = None, qdd: object = None) -> tuple[np.ndarray, ...]:
        """MuJoCo ``(qpos, qvel, qacc)`` of one sample -> Pinocchio ``(q, v, a)``.

        Hinge and slide angles are measured from the joint's reference; quaternions ``(w, x, y, z)``
        become ``(x, y, z, w)``; a free joint's world linear velocity and acceleration become body-frame
        ones (``a`` the time derivative of ``v``).  ``qd`` and ``qdd`` default to zero.  Returns
        ``(q, v, a)`` in Pinocchio's coordinates.
        """
        import pinocchio as pin

        q = self._one(q, "q", self._nq)
        qd = np.zeros(self.model.nv) if qd is None else self._one(qd, "qd", self.model.nv)
        qdd = np.zeros(self.model.nv) if qdd is None else self._one(qdd, "qdd", self.model.nv)
        qp, vp, ap = np.zeros(self.model.nq), np.zeros(self.model.nv), np.zeros(self.model.nv)
        for typ, qa, da, ref, iq, iv in self._joints:
            if typ in (_HINGE, _SLIDE):
                qp[iq], vp[iv], ap[iv] = q[qa] - ref, qd[da], qdd[da]
            elif typ == _BALL:
                w, x, y, z = q[qa : qa + 4]
                qp[iq : iq + 4] = (x, y, z, w)
                vp[iv : iv + 3], ap[iv : iv + 3] = qd[da : da + 3], qdd[da : da + 3]
            else:
                w, x, y, z = q[qa + 3 : qa + 7]
                qp[iq : iq + 3] = q[qa : qa + 3]
                qp[iq + 3 : iq + 7] = (x, y, z, w)
                R = pin.Quaternion(w, x, y, z).toRotationMatrix()
                om = qd[da + 3 : da + 6]
                vl = R.T @ qd[da : da + 3]
                vp[iv : iv + 3], vp[iv + 3 : iv + 6] = vl, om
                ap[iv : iv + 3] = R.T @ qdd[da : da + 3] - np.cross(om, vl)
                ap[iv + 3 : iv + 6] = qdd[da + 3 : da + 6]
        return qp, vp, ap

    @property
    def _nq(self) -> int:
        typ_nq = {_HINGE: 1, _SLIDE: 1, _BALL: 4, _FREE: 7}
        return sum(typ_nq[j[0]] for j in self._joints)

    @staticmethod
    def _one(x: object, name: str, n: int) -> np.ndarray:
        from robomech._validation import as_array

        a = as_array(x, name, (n,))
        if a.shape != (n,):
            raise ValueError(f"Expected {name} to be one sample of shape ({n},), got shape {a.shape}.")
        return a

    def velocity_map(self, q: object) -> np.ndarray:
        """``T (nv, model.nv)`` at one MuJoCo ``qpos`` with ``qvel = T @ v``: a permutation for hinge,
        slide and ball joints, the base rotation on a free joint's linear part (world in MuJoCo, body
        axes in Pinocchio).  Generalized forces and mass matrices follow as ``tau_pin = T.T @ tau`` and
        ``M_pin = T.T @ M @ T``."""
        import pinocchio as pin

        q = self._one(q, "q", self._nq)
        T = np.zeros((self.model.nv, self.model.nv))
        for typ, qa, da, _ref, _iq, iv in self._joints:
            if typ == _FREE:
                T[da : da + 3, iv : iv + 3] = pin.Quaternion(*q[qa + 3 : qa + 7]).toRotationMatrix()
                T[da + 3 : da + 6, iv + 3 : iv + 6] = np.eye(3)
            else:
                n = 3 if typ == _BALL else 1
                T[da : da + n, iv : iv + n] = np.eye(n)
        return T


def to_pinocchio(mech: Mechanism) -> PinocchioModel:
    """The description as a Pinocchio model with its loop-closure constraint models.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism (closures of every kind; joint couplings have no Pinocchio constraint
        model and are listed in ``couplings``).

    Returns
    -------
    PinocchioModel
        The tree (``pin.Model``), the closures (``pin.RigidConstraintModel``) and the coordinate map.

    Raises
    ------
    ValueError
        ``mech`` is not a Mechanism.
    ImportError
        Pinocchio is not installed (``pip install "robomech[pinocchio]"``).
    """
    if not isinstance(mech, Mechanism):
        raise ValueError(f"Expected mech to be a robomech.multibody.Mechanism, got {type(mech).__name__}.")
    try:
        import pinocchio as pin
    except ImportError as exc:  # pragma: no cover - the extra is installed where this is tested
        raise ImportError('to_pinocchio needs Pinocchio: pip install "robomech[pinocchio]"') from exc

    t = mech.tree
    model = pin.Model()
    model.gravity = pin.Motion(np.array(mech.gravity, float), np.zeros(3))
    jid = {0: 0}  # tree body -> Pinocchio joint it moves with
    frame_in_joint = {0: pin.SE3.Identity()}  # tree body frame in that joint's frame
    joints = []
    for b in range(1, len(t.body_names)):
        parent = int(t.parent[b])
        Toff = np.array(t.T_off[b], float)
        M = frame_in_joint[parent] * pin.SE3(Toff[:3, :3], Toff[:3, 3])  # body frame at q = ref
        j_parent, last_pos = jid[parent], None
        for k in t.body_jnts[b]:
            typ, p = int(t.jnt_type[k]), np.asarray(t.jnt_pos[k], float)
            if typ == _FREE:
                place, jm, p = pin.SE3.Identity(), pin.JointModelFreeFlyer(), np.zeros(3)
            else:
                axis = np.asarray(t.jnt_axis[k], float)
                if last_pos is None:  # the axis through p, in the body frame at its reference
                    place = M * pin.SE3(np.eye(3), p)
                else:  # a body's later joints act in the frame after the earlier ones
                    place = pin.SE3(np.eye(3), p - last_pos)
                if typ == _HINGE:
                    jm = pin.JointModelRevoluteUnaligned(axis)
                elif typ == _SLIDE:
                    jm = pin.JointModelPrismaticUnaligned(axis)
                else:
                    jm = pin.JointModelSpherical()
            j_parent = model.addJoint(j_parent, jm, place, str(t.jnt_names[k]))
            last_pos = p
            idx = model.joints[j_parent]
            joints.append(
                (typ, int(t.jnt_qadr[k]), int(t.jnt_dadr[k]), float(t.jnt_ref[k]), idx.idx_q, idx.idx_v)
            )
        if last_pos is None:  # welded to its parent
            jid[b], frame_in_joint[b] = jid[parent], M
        else:
            jid[b], frame_in_joint[b] = j_parent, pin.SE3(np.eye(3), -last_pos)
    body_frames = {}
    for b in range(1, len(t.body_names)):
        name = str(t.body_names[b])
        body_frames[name] = model.addFrame(
            pin.Frame(name, jid[b], frame_in_joint[b], pin.FrameType.BODY)
        )
    for body in mech.bodies:
        b = t.body_index(body.name)
        if body.inertial is not None:
            it = body.inertial
            Rq = pin.Quaternion(*it.quat).toRotationMatrix()  # (w, x, y, z)
            inertia = pin.Inertia(it.mass, np.asarray(it.pos, float), Rq @ np.diag(it.diaginertia) @ Rq.T)
            model.appendBodyToJoint(jid[b], inertia, frame_in_joint[b])
    constraints = []
    for c in mech.closures:
        b1, b2 = t.body_index(c.body1), t.body_index(c.body2)

        def contact(kind, R1, x1, x2, _b1=b1, _b2=b2):
            return pin.RigidConstraintModel(
                kind,
                model,
                jid[_b1],
                frame_in_joint[_b1] * pin.SE3(R1, np.asarray(x1, float)),
                jid[_b2],
                frame_in_joint[_b2] * pin.SE3(np.eye(3), np.asarray(x2, float)),
                pin.ReferenceFrame.LOCAL,
            )

        if c.kind == "point":
            constraints.append(contact(pin.ContactType.CONTACT_3D, np.eye(3), c.anchor1, c.anchor2))
        elif c.kind == "revolute":
            L = t.length
            constraints.append(contact(pin.ContactType.CONTACT_3D, np.eye(3), c.anchor1, c.anchor2))
            a1 = np.asarray(c.anchor1) + L * np.asarray(c.axis)
            a2 = np.asarray(c.anchor2) + L * np.asarray(c.axis2)
            constraints.append(contact(pin.ContactType.CONTACT_3D, np.eye(3), a1, a2))
        else:
            Rrel = pin.Quaternion(*c.relquat).toRotationMatrix()
            p1 = np.asarray(c.relpos) + Rrel @ np.asarray(c.anchor2)
            constraints.append(contact(pin.ContactType.CONTACT_6D, Rrel, p1, c.anchor2))
    couplings = tuple(c.name for c in mech.couplings)
    return PinocchioModel(model, constraints, body_frames, couplings, tuple(joints))
