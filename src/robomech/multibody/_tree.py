"""Batched tree kinematics of a described mechanism (internal; kernels trust their inputs).

Everything here works on flat batches ``q (N, nq)`` / ``qd (N, ..., nv)`` and returns world-frame
quantities:

* :func:`kinematics` -> :class:`TreeState`: every body's pose ``T (N, nb, 4, 4)`` (index 0 is the
  world), every velocity coordinate's space screw ``S (N, nv, 6)`` (``[ω; v]``, v of the point at the
  world origin), so that body b's space twist is ``V_b = sum_k A[b, k] S_k qd_k``;
* :func:`frame_jacobian` -> the ``[ω; ṗ]`` Jacobian ``(N, 6, nv)`` of a point fixed in a body
  (MuJoCo's ``mj_jacSite`` quantities);
* :func:`integrate` -> ``q ⊕ δ``: hinge/slide add, ball/free rotate by ``exp`` of the *local*
  angular increment (MuJoCo's ``mj_integratePos``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._options import QUAT_MIN_NORM as _QUAT_MIN_NORM

__all__ = [
    "Tree",
    "TreeState",
    "body_poses",
    "body_twists",
    "compile_tree",
    "frame_jacobian",
    "integrate",
    "kinematics",
    "normalize_quaternions",
    "quat_to_matrix",
    "space_jacobian",
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


def quat_exp(w: np.ndarray) -> np.ndarray:
    """Unit quaternion of the rotation vector ``w`` (..., 3)."""
    th = np.linalg.norm(w, axis=-1)
    half = 0.5 * th
    # sin(th/2)/th, with its series below 1e-4 rad (error < th^4/3840 ~ 1e-19)
    small = th < 1e-4
    k = np.where(small, 0.5 - th * th / 48.0, np.sin(half) / np.where(small, 1.0, th))
    return np.concatenate([np.cos(half)[..., None], k[..., None] * w], axis=-1)


def axis_angle_matrix(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotation (..., 3, 3) by ``angle (...)`` about the unit ``axis (3,)`` (Rodrigues)."""
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    s, c = np.sin(angle)[..., None, None], np.cos(angle)[..., None, None]
    return np.eye(3) + s * K + (1 - c) * (K @ K)


def normalize_quaternions(tree: Tree, q: np.ndarray) -> np.ndarray:
    """Copy of ``q`` with every ball/free quaternion normalised (MuJoCo normalises them too)."""
    q = np.array(q, dtype=float, copy=True)
    for a in tree.quat_adr:
        qt = q[..., a : a + 4]
        n = np.linalg.norm(qt, axis=-1, keepdims=True)
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


def compile_tree(mech) -> Tree:
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
        L = _default_length(mech, tree)
    object.__setattr__(tree, "length", float(L))
    return tree


def _default_length(mech, tree: Tree) -> float:
    """RMS distance of the body origins, joint anchors and sites from their centroid at q0 (m).

    This is the length that makes a rotation (rad) and a translation (m) commensurate in residuals
    and conditioning; 1 m if the mechanism has no extent (a single point).
    """
    T = body_poses(tree, tree.q0[None])[0]
    pts = [T[1:, :3, 3]]
    for k in range(len(tree.jnt_names)):
        Tb = T[tree.jnt_body[k]]
        pts.append((Tb[:3, :3] @ tree.jnt_pos[k] + Tb[:3, 3])[None])
    for s in range(len(tree.site_names)):
        pts.append((T[tree.site_body[s]] @ tree.T_site[s])[None, :3, 3])
    P = np.concatenate(pts)
    L = float(np.sqrt(np.mean(np.sum((P - P.mean(axis=0)) ** 2, axis=1)))) if len(P) > 1 else 0.0
    return L if L > 1e-9 else 1.0


# ------------------------------------------------------------------ kinematics
@dataclass(frozen=True, eq=False)
class TreeState:
    """World poses ``T (N, nb, 4, 4)`` of all bodies and space screws ``S (N, nv, 6)`` of all coordinates."""

    T: np.ndarray
    S: np.ndarray


def _cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.cross`` of ``(N, 3)`` arrays, the same products and differences in the same order (so the
    same bits) without its axis handling, which dominated the kinematics of a single configuration."""
    out = np.empty(a.shape)
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def _kin(tree: Tree, q: np.ndarray, screws: bool) -> TreeState:
    N = q.shape[0]
    nb = len(tree.body_names)
    T = np.empty((N, nb, 4, 4))
    T[:, 0] = np.eye(4)
    # Without screws S is an empty (N, 0, 6) placeholder that is never written (only poses wanted).
    S = np.zeros((N, tree.nv if screws else 0, 6))
    for b in range(1, nb):
        Tb = T[:, tree.parent[b]] @ tree.T_off[b]
        for k in tree.body_jnts[b]:
            typ, qa, da = tree.jnt_type[k], tree.jnt_qadr[k], tree.jnt_dadr[k]
            pos, axis = tree.jnt_pos[k], tree.jnt_axis[k]
            R, p = Tb[:, :3, :3], Tb[:, :3, 3]
            if typ == 0 or typ == 2:
                anchor = p + R @ pos
                Rj = (
                    axis_angle_matrix(axis, q[:, qa] - tree.jnt_ref[k])
                    if typ == 0
                    else quat_to_matrix(q[:, qa : qa + 4])
                )
                Rn = R @ Rj
                Tb = Tb.copy()
                Tb[:, :3, :3] = Rn
                Tb[:, :3, 3] = anchor - Rn @ pos
                if screws:
                    if typ == 0:
                        w = R @ axis
                        S[:, da, :3] = w
                        S[:, da, 3:] = _cross3(anchor, w)
                    else:
                        for c in range(3):
                            w = Rn[:, :, c]
                            S[:, da + c, :3] = w
                            S[:, da + c, 3:] = _cross3(anchor, w)
            elif typ == 1:
                w = R @ axis
                Tb = Tb.copy()
                Tb[:, :3, 3] = p + w * (q[:, qa] - tree.jnt_ref[k])[:, None]
                if screws:
                    S[:, da, 3:] = w
            else:
                Tb = np.tile(np.eye(4), (N, 1, 1))
                Rn = quat_to_matrix(q[:, qa + 3 : qa + 7])
                Tb[:, :3, :3] = Rn
                Tb[:, :3, 3] = q[:, qa : qa + 3]
                if screws:
                    for c in range(3):
                        S[:, da + c, 3 + c] = 1.0
                        w = Rn[:, :, c]
                        S[:, da + 3 + c, :3] = w
                        S[:, da + 3 + c, 3:] = _cross3(q[:, qa : qa + 3], w)
        T[:, b] = Tb
    return TreeState(T=T, S=S)


def body_poses(tree: Tree, q: np.ndarray) -> np.ndarray:
    """World pose of every body, ``(N, nb, 4, 4)`` (body 0 is the world).  ``q`` normalised quaternions."""
    return _kin(tree, q, screws=False).T


def kinematics(tree: Tree, q: np.ndarray) -> TreeState:
    """Body poses and coordinate space screws at ``q (N, nq)`` (quaternions already normalised)."""
    return _kin(tree, q, screws=True)


def integrate(tree: Tree, q: np.ndarray, dv: np.ndarray) -> np.ndarray:
    """``q ⊕ dv``: the configuration reached from ``q`` by the velocity increment ``dv (N, nv)``."""
    out = np.array(q, copy=True)
    for k in range(len(tree.jnt_names)):
        typ, qa, da = tree.jnt_type[k], tree.jnt_qadr[k], tree.jnt_dadr[k]
        if typ <= 1:
            out[:, qa] += dv[:, da]
        elif typ == 2:
            out[:, qa : qa + 4] = quat_mul(q[:, qa : qa + 4], quat_exp(dv[:, da : da + 3]))
        else:
            out[:, qa : qa + 3] += dv[:, da : da + 3]
            out[:, qa + 3 : qa + 7] = quat_mul(q[:, qa + 3 : qa + 7], quat_exp(dv[:, da + 3 : da + 6]))
    return normalize_quaternions(tree, out) if tree.quat_adr else out


def space_jacobian(tree: Tree, state: TreeState, body: int) -> np.ndarray:
    """Space-twist Jacobian of ``body`` (N, 6, nv): ``V_b = J qd`` (``[ω; v]``, v at the world origin)."""
    return (state.S * tree.A[body][:, None]).swapaxes(-1, -2)


def body_twists(tree: Tree, state: TreeState, qd: np.ndarray) -> np.ndarray:
    """Space twists of all bodies (N, ..., nb, 6) for ``qd (N, ..., nv)``."""
    S = state.S.reshape(state.S.shape[0], *(1,) * (qd.ndim - 2), *state.S.shape[1:])
    return np.einsum("bk,...kx,...k->...bx", tree.A, S, qd)


def frame_jacobian(tree: Tree, state: TreeState, body: int, point: np.ndarray) -> np.ndarray:
    """``[ω; ṗ] = J qd`` for the point ``point (N, 3)`` (world) fixed in ``body``: (N, 6, nv)."""
    S = state.S
    mask = tree.A[body][None, :, None]
    w = S[..., :3] * mask
    v = (S[..., 3:] + np.cross(S[..., :3], point[:, None, :])) * mask
    return np.concatenate([w, v], axis=-1).swapaxes(-1, -2)
