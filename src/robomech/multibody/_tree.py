"""The compiled tree of a described mechanism (internal): the arrays the kernels run on.

:func:`compile_tree` builds the :class:`Tree` (bodies indexed from 1, world at 0; joints, their
coordinates and axes; the incidence ``A (nb, nv)`` of the coordinates that move each body; sites and
actuators) once per description.  The tree kinematics, Jacobians and integration run on these arrays
in the compiled kernels (``_compiled.kin``, ``compiled_kinematics``, ``compiled_integrate``); the
numpy formulation of the same algorithms is the tests' reference (tests/multibody/_reference.py).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ._options import QUAT_MIN_NORM as _QUAT_MIN_NORM

__all__ = [
    "Tree",
    "compile_tree",
    "normalize_quaternions",
    "quat_mul",
    "quat_to_matrix",
]

_TYPES = {"hinge": 0, "slide": 1, "ball": 2, "free": 3}


# ------------------------------------------------------------------ small batched SO(3)/quaternion tools
def quat_to_matrix(qt: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of unit quaternions [w, x, y, z] (..., 4)."""
    w, x, y, z = (qt[..., i] for i in range(4))
    R = np.empty((*qt.shape[:-1], 3, 3))
    R[..., 0, 0] = 1 - 2 * (y * y + z * z)
    R[..., 0, 1] = 2 * (x * y - w * z)
    R[..., 0, 2] = 2 * (x * z + w * y)
    R[..., 1, 0] = 2 * (x * y + w * z)
    R[..., 1, 1] = 1 - 2 * (x * x + z * z)
    R[..., 1, 2] = 2 * (y * z - w * x)
    R[..., 2, 0] = 2 * (x * z - w * y)
    R[..., 2, 1] = 2 * (y * z + w * x)
    R[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return R


def quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    aw, ax, ay, az = (a[..., i] for i in range(4))
    bw, bx, by, bz = (b[..., i] for i in range(4))
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def normalize_quaternions(tree: Tree, q: np.ndarray) -> np.ndarray:
    """Copy of ``q`` with every ball/free quaternion normalised (MuJoCo normalises them too)."""
    q = np.array(q, dtype=float, copy=True)
    for a in tree.quat_adr:
        qt = q[..., a : a + 4]
        n = np.sqrt(np.einsum("...i,...i->...", qt, qt))[..., None]
        q[..., a : a + 4] = np.where(
            n > _QUAT_MIN_NORM, qt / np.where(n > _QUAT_MIN_NORM, n, 1.0), [1, 0, 0, 0]
        )
    return q


# ------------------------------------------------------------------ compiled tree
@dataclass(frozen=True, eq=False)
class Tree:
    """Arrays compiled once from a :class:`~robomech.multibody.Mechanism` (bodies indexed from 1)."""

    body_names: tuple[str, ...]  # (nb,) with "world" at 0
    parent: np.ndarray  # (nb,)
    T_off: np.ndarray  # (nb, 4, 4) body pose in its parent
    jnt_names: tuple[str, ...]
    jnt_type: np.ndarray  # (nj,) codes of _TYPES
    jnt_body: np.ndarray
    jnt_qadr: np.ndarray
    jnt_dadr: np.ndarray
    jnt_pos: np.ndarray  # (nj, 3)
    jnt_axis: np.ndarray  # (nj, 3)
    jnt_ref: np.ndarray  # (nj,)
    body_jnts: tuple[tuple[int, ...], ...]
    nq: int
    nv: int
    q0: np.ndarray  # (nq,)
    dof_body: np.ndarray  # (nv,)
    dof_jnt: np.ndarray  # (nv,)
    dof_translational: np.ndarray  # (nv,) bool: slide and free-translation coordinates (metres)
    A: np.ndarray  # (nb, nv) 1.0 where coordinate k moves body b
    C: np.ndarray  # (nv, nv) 1.0 where coordinate j moves the carrier frame of coordinate k
    quat_adr: tuple[int, ...]  # qpos addresses of ball/free quaternions
    site_names: tuple[str, ...]
    site_body: np.ndarray
    T_site: np.ndarray  # (ns, 4, 4) site pose in its body
    act_jnt: np.ndarray  # (na,) joint index of each actuator
    act_dof: np.ndarray  # (na,) velocity coordinate of each actuator
    act_qadr: np.ndarray  # (na,) qpos address of each actuator
    length: float  # characteristic length (m)
    dof_paths: tuple[np.ndarray, ...] = ()  # (nb,) the velocity coordinates that move body b

    def body_index(self, name: str) -> int:
        try:
            return self.body_names.index(name)
        except ValueError:
            raise ValueError(f"Expected a body name among {list(self.body_names)}, got {name!r}.") from None

    def joint_index(self, name: str) -> int:
        try:
            return self.jnt_names.index(name)
        except ValueError:
            raise ValueError(f"Expected a joint name among {list(self.jnt_names)}, got {name!r}.") from None

    def site_index(self, name: str) -> int:
        try:
            return self.site_names.index(name)
        except ValueError:
            raise ValueError(f"Expected a site name among {list(self.site_names)}, got {name!r}.") from None


def _pose(pos, quat) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = quat_to_matrix(np.asarray(quat, float))
    T[:3, 3] = pos
    return T


def compile_tree(mech, default_length: Callable[[Tree], float]) -> Tree:
    """The :class:`Tree` of ``mech``; its characteristic length the description's, else
    ``default_length(tree)`` (the compile step passes one from the body poses at q0)."""
    names = ["world", *(b.name for b in mech.bodies)]
    nb = len(names)
    parent = np.zeros(nb, dtype=int)
    T_off = np.tile(np.eye(4), (nb, 1, 1))
    jn: list[str] = []
    jt: list[int] = []
    jb: list[int] = []
    jq: list[int] = []
    jd: list[int] = []
    jp: list[np.ndarray] = []
    ja: list[np.ndarray] = []
    jr: list[float] = []
    bj: list[list[int]] = [[] for _ in range(nb)]
    q0: list[float] = []
    nq = nv = 0
    dof_body: list[int] = []
    dof_jnt: list[int] = []
    dof_tr: list[bool] = []
    quat_adr = []
    for i, b in enumerate(mech.bodies, start=1):
        parent[i] = names.index(b.parent)
        T_off[i] = _pose(b.pos, b.quat)
        for j in b.joints:
            k = len(jn)
            jn.append(j.name)
            jt.append(_TYPES[j.type])
            jb.append(i)
            jq.append(nq)
            jd.append(nv)
            jp.append(j.pos)
            ja.append(j.axis)
            jr.append(j.ref)
            bj[i].append(k)
            if j.type in ("hinge", "slide"):
                q0.append(j.ref)
            elif j.type == "ball":
                quat_adr.append(nq)
                q0 += [1.0, 0.0, 0.0, 0.0]
            else:
                quat_adr.append(nq + 3)
                q0 += [*b.pos, *b.quat]
            nq += j.nq
            dof_body += [i] * j.nv
            dof_tr += {
                "hinge": [False],
                "slide": [True],
                "ball": [False] * 3,
                "free": [True] * 3 + [False] * 3,
            }[j.type]
            dof_jnt += [k] * j.nv
            nv += j.nv
    A = np.zeros((nb, nv))
    C = np.zeros((nv, nv))
    for i in range(1, nb):
        A[i] = A[parent[i]]
        for k in bj[i]:
            d0, typ = jd[k], jt[k]
            n = {0: 1, 1: 1, 2: 3, 3: 6}[typ]
            if typ in (0, 1):
                C[d0] = A[i]  # the frame before the joint carries its axis
            elif typ == 2:
                C[d0 : d0 + 3] = A[i]
                C[d0 : d0 + 3, d0 : d0 + 3] = 1.0  # a ball's axes turn with it (local angular velocity)
            else:
                C[d0 + 3 : d0 + 6, d0 : d0 + 6] = 1.0  # free: rotation axes are the body's own
            A[i, d0 : d0 + n] = 1.0
    site_names = tuple(s.name for s in mech.sites)
    site_body = np.array([names.index(s.body) for s in mech.sites], dtype=int)
    T_site = np.array([_pose(s.pos, s.quat) for s in mech.sites]).reshape(-1, 4, 4)
    act_jnt = np.array([jn.index(a) for a in mech.actuated], dtype=int)
    jd_arr, jq_arr = np.array(jd, dtype=int), np.array(jq, dtype=int)
    tree = Tree(
        body_names=tuple(names),
        parent=parent,
        T_off=T_off,
        jnt_names=tuple(jn),
        jnt_type=np.array(jt, dtype=int),
        jnt_body=np.array(jb, dtype=int),
        jnt_qadr=jq_arr,
        jnt_dadr=jd_arr,
        jnt_pos=np.array(jp, dtype=float).reshape(-1, 3),
        jnt_axis=np.array(ja, dtype=float).reshape(-1, 3),
        jnt_ref=np.array(jr, dtype=float),
        body_jnts=tuple(tuple(x) for x in bj),
        nq=nq,
        nv=nv,
        q0=np.array(q0, dtype=float),
        dof_body=np.array(dof_body, dtype=int),
        dof_jnt=np.array(dof_jnt, dtype=int),
        dof_translational=np.array(dof_tr, dtype=bool),
        A=A,
        C=C,
        quat_adr=tuple(quat_adr),
        site_names=site_names,
        site_body=site_body,
        T_site=T_site,
        act_jnt=act_jnt,
        act_dof=jd_arr[act_jnt] if len(act_jnt) else np.zeros(0, dtype=int),
        act_qadr=jq_arr[act_jnt] if len(act_jnt) else np.zeros(0, dtype=int),
        length=1.0,
        dof_paths=tuple(np.flatnonzero(A[b]) for b in range(nb)),
    )
    L = mech.characteristic_length
    if L is None:
        L = default_length(tree)
    object.__setattr__(tree, "length", float(L))
    return tree
