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
dynamics project them (``_dynamics``).  The passes run per sample in compiled kernels
(``_rnea_kernels``), large batches in parallel blocks.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._validation import MAX_MAGNITUDE, as_array, broadcast_batch, check_bool

from ._compile import compile_model
from ._model import Mechanism
from ._tree import normalize_quaternions, quat_to_matrix

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


def _rnea_flat(mech: Mechanism, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, g: np.ndarray) -> np.ndarray:
    """Tree inverse dynamics ``(N, nv)`` at normalised ``q (N, nq)``, ``qd``, ``qdd (N, nv)``, gravity g
    (the compiled kernel ``_compiled.rnea_block``, per sample)."""
    from ._compiled import compiled_rnea

    c = np.ascontiguousarray
    return compiled_rnea(
        compile_model(mech), c(q, dtype=float), c(qd, dtype=float), c(qdd, dtype=float), c(g, dtype=float)
    )


def _crba_flat(mech: Mechanism, q: np.ndarray) -> np.ndarray:
    """Tree mass matrix ``(N, nv, nv)`` at normalised ``q (N, nq)`` (``_rnea_kernels.crba_block``)."""
    from ._compile import compile_model
    from ._rnea_kernels import crba_batch

    return crba_batch(compile_model(mech), q)


def _flat_inputs(mech: Mechanism, q: object, others: list[tuple[object, str]]):
    """Validate ``q (..., nq)`` and ``(..., nv)`` arrays; a sample with a non-finite entry or one beyond
    ``MAX_MAGNITUDE`` is computed at the reference and returned NaN (``ok`` False)."""
    tree = mech.tree
    nq, nv = tree.nq, tree.nv
    qv = as_array(q, "q", (nq,), finite=False)
    for a in tree.quat_adr:
        nrm = np.linalg.norm(qv[..., a : a + 4], axis=-1)
        if np.any(np.isfinite(nrm) & (nrm < 1e-9)):
            raise ValueError(
                f"Expected the quaternion q[..., {a}:{a + 4}] to be non-zero, got norm {nrm.min()}."
            )
    arrs = [as_array(x, name, (nv,), finite=False) for x, name in others]
    if all(a.shape == (*qv.shape[:-1], nv) for a in arrs):
        batch = qv.shape[:-1]  # the common case: nothing to broadcast
    else:
        batch = broadcast_batch(
            (qv, 1, "q"), *((a, 1, name) for a, (_, name) in zip(arrs, others, strict=True))
        )
    n = int(np.prod(batch))
    flat = [np.broadcast_to(qv, (*batch, nq)).reshape(n, nq)]
    flat += [np.broadcast_to(a, (*batch, nv)).reshape(n, nv) for a in arrs]
    ok = np.ones(n, dtype=bool)
    with np.errstate(invalid="ignore"):
        for a in flat:
            ok &= np.all(np.abs(a) <= MAX_MAGNITUDE, axis=-1)  # False for NaN and inf too
    if not ok.all():
        flat = [np.where(ok[:, None], a, 0.0) for a in flat]
        flat[0] = np.where(ok[:, None], flat[0], tree.q0)
    if tree.quat_adr:
        flat[0] = normalize_quaternions(tree, flat[0])
    return batch, ok, flat


def _rnea_one(mech, q, qd, qdd, gravity) -> np.ndarray | None:
    """One sample given as C-contiguous float64 vectors of the exact shapes: the kernel checks the
    entries (within ``MAX_MAGNITUDE``, robomech._validation's masking rule; quaternions non-zero) and
    returns the forces in the same call; None (the general path validates and masks) otherwise."""
    if not (
        type(mech) is Mechanism
        and type(q) is np.ndarray
        and type(qd) is np.ndarray
        and type(qdd) is np.ndarray
        and (gravity is True or gravity is False)
    ):
        return None
    model = compile_model(mech)
    one = model.cache.get("rnea_one_call")
    if one is None:
        one = model.cache["rnea_one_call"] = _one_call(model, mech)
    fn, sq, sv, gv, tables = one
    if (
        q.shape != sq
        or qd.shape != sv
        or qdd.shape != sv
        or q.dtype is not _F64
        or qd.dtype is not _F64
        or qdd.dtype is not _F64
        or not (q.flags.c_contiguous and qd.flags.c_contiguous and qdd.flags.c_contiguous)
    ):
        return None
    tau = np.empty(sv)
    if fn is None:
        from ._compiled import entry, rnea_one

        args = (q, qd, qdd, gv if gravity else _ZERO3, tables, np.empty(sq), tau)
        if entry(model, rnea_one, "rnea_one", args):
            return None
        model.cache["rnea_one_call"] = (model.cache["rnea_one"], *one[1:])
        return tau
    if fn(q, qd, qdd, gv if gravity else _ZERO3, tables, np.empty(sq), tau):
        return None
    return tau


def _one_call(model, mech) -> tuple:
    """What a single-sample call reads, in one tuple: (kernel entry point or None before the first
    call, the shapes of ``q`` and of the rates, the gravity vector, the kernel tables)."""
    return (
        model.cache.get("rnea_one"),
        (model.tree.nq,),
        (model.tree.nv,),
        np.array(mech.gravity, dtype=float),
        model.rnea,
    )


_ZERO3 = np.zeros(3)
_F64 = np.dtype(np.float64)


def _crba_one(mech, q) -> np.ndarray | None:
    """One sample as a C-contiguous float64 vector of shape ``(nq,)``: checked and computed in one
    kernel call (as :func:`_rnea_one`); None (the general path) otherwise."""
    if not (type(mech) is Mechanism and type(q) is np.ndarray):
        return None
    model = compile_model(mech)
    if q.shape != (model.tree.nq,) or q.dtype is not _F64 or not q.flags.c_contiguous:
        return None
    from ._compiled import entry as entry_call
    from ._rnea_kernels import crba_one

    nv = model.rnea.nv
    M = np.empty((nv, nv))
    if entry_call(model, crba_one, "crba_one", (q, model.rnea, np.empty(q.shape[0]), M)):
        return None
    return M


def generalized_forces(
    mech: Mechanism, q: object, qd: object, qdd: object, *, gravity: bool = True
) -> np.ndarray:
    """The spanning tree's inverse dynamics ``M(q) qdd + c(q, qd) + g(q)``, every coordinate: ``(..., nv)``.

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
    one = _rnea_one(mech, q, qd, qdd, gravity)
    if one is not None:  # one sample as float64 vectors: straight into the kernel
        return one
    from ._assembly import check_mechanism
    from ._compiled import compiled_rnea

    mech = check_mechanism(mech)
    gravity = check_bool(gravity, "gravity")
    batch, ok, (qf, qdf, qddf) = _flat_inputs(mech, q, [(qd, "qd"), (qdd, "qdd")])
    g = np.asarray(mech.gravity, float) if gravity else np.zeros(3)
    c = np.ascontiguousarray
    with np.errstate(all="ignore"):  # the one implementation (compiled), any batch size
        tau = compiled_rnea(
            compile_model(mech), c(qf, dtype=float), c(qdf, dtype=float), c(qddf, dtype=float), g
        )
    if not ok.all():
        tau = np.where(ok[:, None], tau, np.nan)
    return tau.reshape(*batch, tau.shape[-1])


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

    one = _crba_one(mech, q)
    if one is not None:  # one sample as a float64 vector: straight into the kernel
        return one
    mech = check_mechanism(mech)
    batch, ok, (qf,) = _flat_inputs(mech, q, [])
    with np.errstate(all="ignore"):
        M = _crba_flat(mech, qf)
    if not ok.all():
        M = np.where(ok[:, None, None], M, np.nan)
    return M.reshape(*batch, *M.shape[1:])
