"""The spanning tree's standard dynamics quantities, batched: inverse dynamics (RNEA) and mass matrix (CRBA).

Both run on the compiled tree (``_tree.Tree``) in world coordinates: every body's spatial velocity
``V_b = [ω; v]`` (``v`` the velocity of the body point at the world origin) and acceleration
``A_b = dV_b/dt`` are accumulated from the base outwards (Featherstone's recursive Newton-Euler
algorithm, forward pass),

    V_b = V_parent + sum_k S_k qd_k,     A_b = A_parent + sum_k (S_k qdd_k + (V_carrier(k) x S_k) qd_k),

with the base accelerating at ``[0; -g]`` (gravity), each body's wrench ``F_b = I_b A_b + V_b x* I_b V_b``
(``I_b`` its spatial inertia about the world origin), summed from the leaves inwards (backward pass)
and projected ``tau_k = S_k . F_subtree(k)``.  The mass matrix is the composite-rigid-body algorithm:
``I^c_b`` the inertia of the subtree rooted at b (backward pass), ``M_ij = S_i . I^c_{body(i)} S_j`` for
``j`` a coordinate that moves ``body(i)``.  Loops closures are not applied: these are the tree's
quantities (MuJoCo ``mj_rne`` / ``mj_fullM``, Pinocchio ``rnea`` / ``crba``); the closed-chain
dynamics project them (``_dynamics``).  Each pass loops over the bodies in Python and is vectorised
over the batch.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._validation import MAX_MAGNITUDE, as_array, broadcast_batch, check_bool

from ._compile import compile_model
from ._model import Mechanism
from ._tree import kinematics, normalize_quaternions, quat_to_matrix

__all__ = ["BodyInertias", "body_inertias", "generalized_forces", "mass_matrix"]


@dataclass(frozen=True, eq=False)
class BodyInertias:
    """Mass properties of every tree body (index 0 the world, zero), body frame."""

    mass: np.ndarray  # (nb,) kg
    com: np.ndarray  # (nb, 3) centre of mass in the body frame (m)
    inertia: np.ndarray  # (nb, 3, 3) rotational inertia about the com, body axes (kg m^2)


def body_inertias(mech: Mechanism) -> BodyInertias:
    """The tree's mass properties (bodies without an ``Inertial`` are massless), built once per mechanism."""
    from ._compile import compile_model

    d = compile_model(mech).cache  # the compiled model's, never the frozen description
    out = d.get("_rnea_inertias")
    if out is None:
        nb = len(mech.bodies) + 1
        m, c, inn = np.zeros(nb), np.zeros((nb, 3)), np.zeros((nb, 3, 3))
        for i, b in enumerate(mech.bodies, start=1):
            if b.inertial is None:
                continue
            it = b.inertial
            R = quat_to_matrix(np.asarray(it.quat, float))
            m[i], c[i], inn[i] = it.mass, it.pos, R @ np.diag(it.diaginertia) @ R.T
        out = d["_rnea_inertias"] = BodyInertias(m, c, inn)
    return out


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a x b`` over the last axis (component arithmetic: np.cross is slow on small batches)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def _motion_cross(V: np.ndarray, S: np.ndarray) -> np.ndarray:
    """``V x S`` for spatial motions ``[ω; v]``: ``[ω x ω_s; ω x v_s + v x ω_s]``."""
    w, v = V[..., :3], V[..., 3:]
    ws, vs = S[..., :3], S[..., 3:]
    return np.concatenate([_cross(w, ws), _cross(w, vs) + _cross(v, ws)], axis=-1)


def _world_inertia(bi: BodyInertias, T: np.ndarray):
    """Per body: mass (nb,), world centre of mass ``c (N, nb, 3)``, world inertia about it (N, nb, 3, 3)."""
    R = T[..., :3, :3]
    c = (R @ bi.com[:, :, None])[..., 0] + T[..., :3, 3]
    Ic = R @ bi.inertia @ R.swapaxes(-1, -2)
    return bi.mass, c, Ic


def _apply_inertia(m: np.ndarray, c: np.ndarray, Ic: np.ndarray, X: np.ndarray) -> np.ndarray:
    """``I X`` for spatial inertias (mass ``m``, com ``c``, inertia about the com ``Ic``) and motions X
    ``[ω; v]`` about the world origin: ``f = m (v + ω x c)``, ``n = Ic ω + c x f``."""
    w, v = X[..., :3], X[..., 3:]
    f = m[..., None] * (v + _cross(w, c))
    n = (Ic @ w[..., None])[..., 0] + _cross(c, f)
    return np.concatenate([n, f], axis=-1)


def _rnea_flat(mech: Mechanism, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, g: np.ndarray) -> np.ndarray:
    """Tree inverse dynamics ``(N, nv)`` at normalised ``q (N, nq)``, ``qd``, ``qdd (N, nv)``, gravity ``g (3,)``."""
    tree = mech.tree
    N, nb = q.shape[0], len(tree.body_names)
    st = kinematics(tree, q)
    S = st.S
    V = np.zeros((N, nb, 6))
    A = np.zeros((N, nb, 6))
    A[:, 0, 3:] = -g  # the base accelerates upwards at g: gravity on every body
    for b in range(1, nb):
        p = tree.parent[b]
        v, a = V[:, p].copy(), A[:, p].copy()
        for k in tree.body_jnts[b]:
            typ, da = tree.jnt_type[k], tree.jnt_dadr[k]
            n = (1, 1, 3, 6)[typ]
            Sk = S[:, da : da + n]  # (N, n, 6)
            vj = np.einsum("nkx,nk->nx", Sk, qd[:, da : da + n])
            aj = np.einsum("nkx,nk->nx", Sk, qdd[:, da : da + n])
            if typ <= 1:  # hinge / slide: the axis is carried by the frame before the joint
                aj = aj + _motion_cross(v, Sk[:, 0]) * qd[:, da, None]
            elif typ == 2:  # ball: axes of the frame after it (local angular velocity)
                aj = aj + np.einsum("nkx,nk->nx", _motion_cross((v + vj)[:, None], Sk), qd[:, da : da + 3])
            else:  # free: translation axes fixed in the world, rotation axes the body's own
                aj = aj + np.einsum(
                    "nkx,nk->nx", _motion_cross(vj[:, None], Sk[:, 3:]), qd[:, da + 3 : da + 6]
                )
            v, a = v + vj, a + aj
        V[:, b], A[:, b] = v, a
    m, c, Ic = _world_inertia(body_inertias(mech), st.T)
    F = _apply_inertia(m, c, Ic, A)
    h = _apply_inertia(m, c, Ic, V)
    w, vl = V[..., :3], V[..., 3:]
    F = F + np.concatenate([_cross(w, h[..., :3]) + _cross(vl, h[..., 3:]), _cross(w, h[..., 3:])], axis=-1)
    for b in range(nb - 1, 0, -1):  # backward pass: each subtree's wrench into its parent
        F[:, tree.parent[b]] += F[:, b]
    return np.einsum("nkx,nkx->nk", S, F[:, tree.dof_body])


def _crba_flat(mech: Mechanism, q: np.ndarray) -> np.ndarray:
    """Tree mass matrix ``(N, nv, nv)`` at normalised ``q (N, nq)`` (composite-rigid-body algorithm)."""
    tree = mech.tree
    nb = len(tree.body_names)
    st = kinematics(tree, q)
    m, c, Ic = _world_inertia(body_inertias(mech), st.T)
    # composite inertias as 6 x 6 matrices about the world origin (columns: I applied to unit motions)
    E = np.eye(6)
    I6 = np.stack([_apply_inertia(m, c, Ic, np.broadcast_to(E[j], (*c.shape[:-1], 6))) for j in range(6)], -1)
    for b in range(nb - 1, 0, -1):
        I6[:, tree.parent[b]] += I6[:, b]
    S = st.S
    F = (I6[:, tree.dof_body] @ S[..., None])[..., 0]  # (N, nv, 6): I^c_{body(i)} S_i
    Mf = F @ S.swapaxes(-1, -2)  # Mf[i, j] = S_i . I^c_{body(i)} S_j
    anc = tree.A[tree.dof_body].astype(bool)  # anc[i, j]: coordinate j moves body(i)
    return np.where(anc, Mf, np.where(anc.T, Mf.swapaxes(-1, -2), 0.0))


def _flat_inputs(mech: Mechanism, q: object, others: list[tuple[object, str]]):
    """Validate ``q (..., nq)`` and ``(..., nv)`` arrays; beyond-finite samples become NaN rows."""
    qv = as_array(q, "q", (mech.nq,), finite="mask")
    for a in mech.tree.quat_adr:
        nrm = np.linalg.norm(qv[..., a : a + 4], axis=-1)
        if np.any(np.isfinite(nrm) & (nrm < 1e-9)):
            raise ValueError(
                f"Expected the quaternion q[..., {a}:{a + 4}] to be non-zero, got norm {nrm.min()}."
            )
    arrs = [as_array(x, name, (mech.nv,), finite="mask") for x, name in others]
    batch = broadcast_batch((qv, 1, "q"), *((a, 1, name) for a, (_, name) in zip(arrs, others, strict=True)))
    flat = [np.broadcast_to(qv, (*batch, mech.nq)).reshape(-1, mech.nq)]
    flat += [np.broadcast_to(a, (*batch, mech.nv)).reshape(-1, mech.nv) for a in arrs]
    ok = np.ones(flat[0].shape[0], dtype=bool)
    for a in flat:
        ok &= np.all(np.isfinite(a), axis=-1)
    clean = [np.where(ok[:, None], a, 0.0) for a in flat]
    clean[0] = normalize_quaternions(mech.tree, np.where(ok[:, None], flat[0], mech.tree.q0))
    return batch, ok, clean


def _rnea_one(mech, q, qd, qdd, gravity) -> np.ndarray | None:
    """One sample given as C-contiguous float64 vectors of the exact shapes, entries within
    ``MAX_MAGNITUDE`` (robomech._validation's masking rule): the kernel's forces; None (the general
    path validates and masks) otherwise."""
    if not (
        type(mech) is Mechanism
        and type(q) is np.ndarray
        and type(qd) is np.ndarray
        and type(qdd) is np.ndarray
        and (gravity is True or gravity is False)
    ):
        return None
    model = compile_model(mech)
    tree = model.tree
    nq, nv = tree.nq, tree.nv
    if (
        q.shape != (nq,)
        or qd.shape != (nv,)
        or qdd.shape != (nv,)
        or q.dtype != np.float64
        or qd.dtype != np.float64
        or qdd.dtype != np.float64
        or not (q.flags.c_contiguous and qd.flags.c_contiguous and qdd.flags.c_contiguous)
    ):
        return None
    # sum of squares (three dot products, the cheapest full scan): NaN and inf propagate through it, and
    # below MAX_MAGNITUDE^2 every entry is within MAX_MAGNITUDE; beyond, the general path masks or computes
    if not q @ q + qd @ qd + qdd @ qdd <= MAX_MAGNITUDE * MAX_MAGNITUDE:
        return None
    if tree.quat_adr:
        q = q.copy()
        for a in tree.quat_adr:
            w, x, y, z = q[a], q[a + 1], q[a + 2], q[a + 3]
            nrm = float(np.sqrt(w * w + x * x + y * y + z * z))
            if not nrm >= 1e-9:
                return None
            q[a : a + 4] /= nrm
    gv = model.cache.get("gravity_vector")
    if gv is None:
        gv = model.cache["gravity_vector"] = np.array(mech.gravity, dtype=float)
    from ._compiled import compiled_rnea

    return compiled_rnea(
        model, q.reshape(1, nq), qd.reshape(1, nv), qdd.reshape(1, nv), gv if gravity else np.zeros(3)
    )[0]


def generalized_forces(
    mech: Mechanism, q: object, qd: object, qdd: object, *, gravity: bool = True
) -> np.ndarray:
    """The spanning tree's inverse dynamics ``M(q) qdd + c(q, qd) + g(q)`` over every coordinate: ``(..., nv)``.

    The generalized forces (MuJoCo ``qfrc``, ``qvel`` order) that produce the accelerations ``qdd`` at
    ``(q, qd)`` with the loop closures *not* applied (no constraint forces; MuJoCo ``mj_rne`` with
    ``flg_acc=1``, Pinocchio ``rnea``).  Recursive Newton-Euler over the tree (module docstring),
    batched over any leading shape.  A sample with a non-finite (or beyond 1e100) entry gives NaN.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism (bodies without an ``Inertial`` are massless).
    q : array_like, shape (..., nq)
        Configurations (MuJoCo ``qpos``; ball / free quaternions normalised here).
    qd : array_like, shape (..., nv)
        Rate of every velocity coordinate (``qvel``; rad/s, m/s; free joints: world linear velocity
        of the body origin, then local angular velocity).
    qdd : array_like, shape (..., nv)
        Acceleration of every velocity coordinate (``qacc``; rad/s^2, m/s^2).
    gravity : bool, optional
        Include ``mech.gravity`` (MJCF ``<option gravity>``, m/s^2); default True.

    Returns
    -------
    ndarray, shape (..., nv)
        Generalized forces (N m for hinges and rotations, N for slides and translations; a free
        joint's rotational entries are the torque about the body origin in body axes).

    Raises
    ------
    ValueError
        If ``mech`` is not a Mechanism, an array is not real of the stated shape, a quaternion in
        ``q`` is zero, the batch shapes do not broadcast, or ``gravity`` is not a bool.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> b = mb.Builder("pendulum")
    >>> b.body("rod", joints=[b.hinge("a", axis=(0, 1, 0))], inertial=mb.Inertial(2.0, pos=(0.5, 0, 0)))
    'rod'
    >>> mech = b.build()
    >>> float(mb.generalized_forces(mech, [0.0], [0.0], [1.0], gravity=False)[0])   # m l^2 qdd
    0.5
    """
    from ._assembly import check_mechanism
    from ._compiled import compiled_rnea

    one = _rnea_one(mech, q, qd, qdd, gravity)
    if one is not None:  # one sample as float64 vectors: straight into the kernel
        return one
    mech = check_mechanism(mech)
    gravity = check_bool(gravity, "gravity")
    batch, ok, (qf, qdf, qddf) = _flat_inputs(mech, q, [(qd, "qd"), (qdd, "qdd")])
    g = np.asarray(mech.gravity, float) if gravity else np.zeros(3)
    c = np.ascontiguousarray
    with np.errstate(all="ignore"):  # the one implementation (compiled), any batch size
        tau = compiled_rnea(
            compile_model(mech), c(qf, dtype=float), c(qdf, dtype=float), c(qddf, dtype=float), g
        )
    tau = np.where(ok[:, None], tau, np.nan)
    return tau.reshape(*batch, mech.nv)


def mass_matrix(mech: Mechanism, q: object) -> np.ndarray:
    """The spanning tree's joint-space mass matrix ``M(q)`` over every coordinate: ``(..., nv, nv)``.

    Symmetric positive semi-definite (definite when every motion moves mass); MuJoCo ``mj_fullM``,
    Pinocchio ``crba``; the loop closures are not applied.  Composite-rigid-body algorithm over the
    tree (module docstring), batched.  A sample with a non-finite (or beyond 1e100) entry gives NaN.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism (bodies without an ``Inertial`` are massless).
    q : array_like, shape (..., nq)
        Configurations (MuJoCo ``qpos``).

    Returns
    -------
    ndarray, shape (..., nv, nv)
        ``M`` in ``qvel`` order (kg m^2, kg m, kg), ``T = qd . M qd / 2`` the kinetic energy.

    Raises
    ------
    ValueError
        If ``mech`` is not a Mechanism, ``q`` is not real of shape ``(..., nq)`` or a quaternion in it
        is zero.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> b = mb.Builder("pendulum")
    >>> b.body("rod", joints=[b.hinge("a", axis=(0, 1, 0))], inertial=mb.Inertial(2.0, pos=(0.5, 0, 0)))
    'rod'
    >>> mb.mass_matrix(b.build(), [[0.0], [1.0]]).round(12)
    array([[[0.5]],
    <BLANKLINE>
           [[0.5]]])
    """
    from ._assembly import check_mechanism

    mech = check_mechanism(mech)
    batch, ok, (qf,) = _flat_inputs(mech, q, [])
    with np.errstate(all="ignore"):
        M = _crba_flat(mech, qf)
    M = np.where(ok[:, None, None], M, np.nan)
    return M.reshape(*batch, mech.nv, mech.nv)
