"""Dynamics of any described mechanism: closed chains in actuator space, and every other kinematic class.

The spanning tree's rigid-body dynamics (Newton-Euler of every body about its centre of mass,
:func:`robomech.dynamics.com_inverse_dynamics`) over the tree's velocity coordinates ``qd (nv)``,

    M(q) qdd + c(q, qd) + g(q) = E tau + J_s^T W + K^T lambda,

is projected onto the admissible motions ``qd = G qd_act`` (``G`` the first-order influence
coefficients, :func:`~robomech.multibody.influence`; ``qdd = G qdd_act + Gdot qd_act``).  Because
``K G = 0`` the closure forces ``K^T lambda`` drop out, and because the actuated rows of ``G`` are the
identity ``G^T E = I``:

    tau = G^T (M qdd + c + g - J_s^T W) = M_a qdd_act + c_a + g_a + e_a,     M_a = G^T M G.

``W`` are external wrenches ``[m; f]`` (world axes, moment about the site point) applied *to* the
mechanism at sites; ``e_a = -G^T J_s^T W`` is their share.  ``G`` is the minimum-norm choice for idle
motions (a link spinning about its own axis): idle motions are prescribed at rest, as in MuJoCo's
least-squares projection.

Redundant actuation (more actuators than degrees of freedom; paper 1's three legs on a 2-DOF
platform): only rates ``qd_act`` in the consistent subspace ``range(N_c)``, ``N_c = null(K G)``, are
admissible, and virtual work fixes only ``N_c^T tau = N_c^T tau_G``.  The rule that picks ``tau`` is
stated and selectable: ``weights=None`` the minimum-norm forces (``tau = N_c N_c^T tau_G``, no
internal preload), ``weights = w (n_act,) >= 0`` the forces minimising ``sum tau_i^2 / w_i`` (an actuator
with ``w_i = 0`` carries nothing: paper 1's "two legs driven" rule is ``w = (1, 0, 1)``):
``tau = W N_c (N_c^T W N_c)^-1 N_c^T tau_G``, ``W = diag(w)``.

Forward dynamics works on the tree coordinates with the closure as a constraint (idle motions
included, as the engine has them): ``qdd = qdd_p + u``, ``K qdd_p = -Kdot qd`` (minimum norm), ``u`` in
``null(K)`` from ``P (M u - f) = 0`` with ``P = I - K^+ K``.  :func:`simulate` integrates ``(q, qd)`` with
``scipy.integrate.solve_ivp`` and projects back onto the constraint manifold (positions by the
closure Newton iteration, velocities onto ``null(K)``) at every output time, every sample on its own.

Where the actuated rates do not determine the state (fewer actuators than degrees of freedom, none, a
floating base) the functions take every coordinate's rate ``qd (nv)`` instead of ``qd_act``;
inverse dynamics then solves virtual work over an orthonormal basis ``Nb`` of ``null(K)`` in least
squares, ``Nb^T E tau = Nb^T f`` with ``f`` the tree's generalized forces (:mod:`._rnea`), and reports
``Nb (Nb^T f - Nb^T E tau)``, what the unactuated coordinates would need (``_inverse_full_flat``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from robomech._batching import failed_rows, on_rows
from robomech._validation import MAX_MAGNITUDE, as_array, broadcast_batch, check_bool

from ._assembly import check_mechanism, check_q
from ._compile import Bodies, compile_model
from ._model import Mechanism
from ._options import (
    ADMISSIBLE_RTOL,
    CLOSURE_RTOL,
    RANK_RTOL,
    SINGULAR_COND,
)
from ._tree import (
    normalize_quaternions,
    quat_mul,
)

__all__ = [
    "ADMISSIBLE_RTOL",
    "SINGULAR_COND",
    "ForwardDynamicsResult",
    "InverseDynamicsResult",
    "SimulationResult",
    "SiteWrenchResult",
    "StaticsResult",
    "energy",
    "forward_dynamics",
    "inverse_dynamics",
    "simulate",
    "site_wrench",
    "statics",
]

# Samples per block in the batched kernels: bounds the (N, bodies, 6, nv) temporaries to ~100 MB.
CHUNK = 2048


# ----------------------------------------------------------------------------- helpers
def _mv(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Batched matrix-vector product ``A (N, i, j) x (N, j) -> (N, i)`` (matmul, BLAS)."""
    return (A @ x[..., None])[..., 0]


def _bodies(mech: Mechanism) -> Bodies:
    """The bodies with mass or inertia, from the compiled model."""
    return compile_model(mech).bodies


def _reference(mech: Mechanism) -> tuple[int, int]:
    """(passive rank of K at the reference configuration, mobility DOF)."""
    return _reference3(mech)[:2]


def _rank_K(mech: Mechanism) -> int:
    """Generic rank of the full constraint Jacobian K (nv minus every instantaneous motion, idle included)."""
    return _reference3(mech)[2]


def _reference3(mech: Mechanism) -> tuple[int, int, int]:
    """(generic passive rank, mobility DOF, generic rank of K): the compiled model's reference rank."""
    m = compile_model(mech)
    return m.rank0, m.dof, m.rank_K


# ----------------------------------------------------------------------------- validation helpers
def _check_wrenches(mech: Mechanism, wrenches: object) -> dict[int, np.ndarray]:
    if wrenches is None:
        return {}
    if not isinstance(wrenches, Mapping):
        raise ValueError(
            f"Expected wrenches to be a mapping site name -> (..., 6) wrench, got {type(wrenches).__name__}."
        )
    out = {}
    for name, W in wrenches.items():
        if not isinstance(name, str) or name not in mech.tree.site_names:
            raise ValueError(
                f"Expected wrenches keys to be site names among {list(mech.tree.site_names)}, got {name!r}."
            )
        out[mech.tree.site_index(name)] = as_array(W, f"wrenches[{name!r}]", (6,))
    return out


def _check_weights(mech: Mechanism, weights: object) -> np.ndarray | None:
    if weights is None:
        return None
    na = len(mech.actuated)
    w = as_array(weights, "weights", (na,))
    if w.shape != (na,) or np.any(w < 0) or not np.any(w > 0):
        raise ValueError(f"Expected weights to be {na} non-negative numbers, not all zero, got {weights!r}.")
    return w


def _fully_actuated(mech: Mechanism) -> tuple[int, int]:
    rank0, dof = _reference(mech)
    na = len(mech.actuated)
    if na < dof or na == 0:
        raise ValueError(
            f"Expected mech to be actuated in every degree of freedom (dof {dof}), "
            f"got {na} actuated joint(s); inverse dynamics needs the actuators to determine the motion."
        )
    return rank0, dof


# ----------------------------------------------------------------------------- inverse dynamics
@dataclass(frozen=True)
class InverseDynamicsResult:
    """``tau = M_a qdd_act + velocity_terms + gravity_terms + external_terms`` per sample.

    The result of :func:`inverse_dynamics`; ``...`` is the broadcast batch shape of its inputs.

    Attributes
    ----------
    tau : ndarray, shape (..., n_act)
        Generalized force at each actuated joint, in actuator order (N m or N; actuator gear not
        applied).  NaN where not ``valid`` — except, from full rates, where only ``unactuated`` is
        not zero: the least-squares forces are kept there (the closest the actuators come).
    M_a : ndarray, shape (..., n_act, n_act)
        Mass matrix in actuator space, ``G^T M G`` (kg m^2, kg); with redundant actuation the
        distributed ``Pi G^T M G``, ``Pi`` the stated rule's projector.  From full rates ``qd``,
        ``B M B^T`` with ``tau = B f`` the rule applied to the generalized forces ``f``.
    velocity_terms : ndarray, shape (..., n_act)
        Coriolis and centrifugal share of ``tau`` (N m or N).
    gravity_terms : ndarray, shape (..., n_act)
        Gravity share of ``tau`` (N m or N).
    external_terms : ndarray, shape (..., n_act)
        Share of ``tau`` that balances the site wrenches (N m or N).
    qd : ndarray, shape (..., nv)
        Every tree coordinate's rate, ``G qd_act`` (MuJoCo ``qvel`` order; rad/s, m/s).
    qdd : ndarray, shape (..., nv)
        Every tree coordinate's acceleration, ``G qdd_act + Gdot qd_act`` (rad/s^2, m/s^2).
    cond : ndarray, shape (...)
        Condition number of the passive constraint block (grows without bound at a type II /
        parallel singularity; above ``SINGULAR_COND`` the sample is not valid).
    sigma_min : ndarray, shape (...)
        Smallest kept singular value of the passive constraint block (m).
    admissibility : ndarray, shape (...)
        How far the motion is from one the actuators can produce, relative: the closure error of the
        prescribed rates and accelerations and, with fewer actuators than degrees of freedom, the
        size of ``unactuated`` over that of the generalized forces (above ``ADMISSIBLE_RTOL``: not
        valid).
    unactuated : ndarray, shape (..., nv)
        The generalized force (``qvel`` order) the unactuated coordinates would need for the motion
        (a floating base: the base wrench, force in world axes then torque in body axes): the
        minimum-norm force doing the virtual work the actuators cannot, over every admissible motion.
        Zero where the actuators determine the motion.
    closure : ndarray, shape (...)
        Largest closure row of the input ``q`` (m); above ``CLOSURE_RTOL * L`` the sample is not valid.
    valid : ndarray of bool, shape (...)
        False at a singular configuration, an inadmissible motion, an unassembled ``q`` or a
        non-finite input; the forces are NaN there.
    """

    tau: np.ndarray
    M_a: np.ndarray
    velocity_terms: np.ndarray
    gravity_terms: np.ndarray
    external_terms: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    cond: np.ndarray
    sigma_min: np.ndarray
    admissibility: np.ndarray
    unactuated: np.ndarray
    closure: np.ndarray
    valid: np.ndarray


def _id_outputs(N: int, na: int, nv: int, extra: tuple[str, ...]) -> dict[str, np.ndarray]:
    """Empty output arrays of an inverse-dynamics kernel: the forces and measures of
    ``InverseDynamicsResult`` (N samples, ``na`` actuators, ``nv`` coordinates), then ``extra`` in the
    kernel's argument order."""
    shapes = {"qd": (N, nv), "qdd": (N, nv), "unactuated": (N, nv), "closure": (N,)}
    out = dict(
        tau=np.empty((N, na)),
        M_a=np.empty((N, na, na)),
        velocity_terms=np.empty((N, na)),
        gravity_terms=np.empty((N, na)),
        external_terms=np.empty((N, na)),
    )
    out.update({k: np.empty(shapes[k]) for k in extra if k in ("qd", "qdd")})
    out.update(cond=np.empty(N), sigma_min=np.empty(N), admissibility=np.empty(N))
    for k in extra:
        if k not in ("qd", "qdd"):
            out[k] = np.empty(N, dtype=np.bool_) if k in ("valid", "_computed") else np.empty(shapes[k])
    return out


def _inverse_compiled(mech, q, qd_a, qdd_a, wr, weights, gravity=True) -> dict[str, np.ndarray]:
    """The closed-chain inverse dynamics in actuator space (the derivation of the module docstring) by
    the compiled per-sample kernel (``_compiled.inv_dyn``), the one implementation at every batch size;
    its numpy formulation is the tests' reference (tests/multibody/_reference.py)."""
    from ._compiled import inv_dyn

    model = compile_model(mech)
    tree, t, d = model.tree, model.tables, model.dyn
    N, nv, na = q.shape[0], tree.nv, len(tree.act_dof)
    W, wsb, wT = _wrench_arrays(tree, wr, N)
    gv = np.asarray(mech.gravity, dtype=float) if gravity else np.zeros(3)
    wts = np.zeros(0) if weights is None else np.ascontiguousarray(weights, dtype=float)
    out = _id_outputs(N, na, nv, ("qd", "qdd", "valid", "closure"))
    f = np.ascontiguousarray
    inv_dyn(
        f(q, dtype=float),
        f(qd_a, dtype=float),
        f(qdd_a, dtype=float),
        W,
        wsb,
        wT,
        gv,
        wts,
        t,
        d,
        *out.values(),
    )
    return out


def _inverse_one(mech, q, qd_a, qdd_a, gravity) -> InverseDynamicsResult | None:
    """One sample given as float64 vectors of the exact shapes, no wrench, no weights: validated here,
    computed by one call of the kernel block (the same per-sample code as every batch).  None — the
    general path then validates, masks and explains — for any other input and for a sample that is
    not valid (non-finite, singular, inadmissible or not assembled)."""
    if not (
        type(mech) is Mechanism
        and type(q) is np.ndarray
        and type(qd_a) is np.ndarray
        and type(qdd_a) is np.ndarray
        and (gravity is True or gravity is False)
    ):
        return None
    model = compile_model(mech)
    tree = model.tree
    na, nv = len(model.act), tree.nv
    if (
        q.shape != (tree.nq,)
        or qd_a.shape != (na,)
        or qdd_a.shape != (na,)
        or q.dtype != np.float64
        or qd_a.dtype != np.float64
        or qdd_a.dtype != np.float64
        or na == 0
        or na < model.dof
        or not (q.flags.c_contiguous and qd_a.flags.c_contiguous and qdd_a.flags.c_contiguous)
    ):
        return None
    if tree.quat_adr:
        q = q.copy()
        for a in tree.quat_adr:
            w, x, y, z = q[a], q[a + 1], q[a + 2], q[a + 3]
            nrm = float(np.sqrt(w * w + x * x + y * y + z * z))
            if not nrm >= 1e-9:  # zero or non-finite: the general path raises or masks
                return None
            q[a : a + 4] /= nrm
    from ._compiled import inv_dyn_one

    o = inv_dyn_one(model, q, qd_a, qdd_a, mech.gravity, gravity)
    if o is None:
        return None
    return InverseDynamicsResult(
        tau=o[0][0],
        M_a=o[1][0],
        velocity_terms=o[2][0],
        gravity_terms=o[3][0],
        external_terms=o[4][0],
        qd=o[5][0],
        qdd=o[6][0],
        cond=o[7].reshape(()),
        sigma_min=o[8].reshape(()),
        admissibility=o[9].reshape(()),
        unactuated=np.zeros(nv),
        closure=o[11].reshape(()),
        valid=o[10].reshape(()),
    )


def _run_chunked(fn, n: int, arrays: list[np.ndarray], **kw) -> dict[str, np.ndarray]:
    # overflow in a sample (inputs of 1e300) is flagged by its mask, not warned about
    with np.errstate(all="ignore"):
        if n == 0:  # an empty batch: evaluate one dummy sample for the result shapes, return none of it
            part = fn(*(np.zeros((1, *a.shape[1:])) for a in arrays), **kw)
            return {k: v[:0] for k, v in part.items()}
        parts = [fn(*(a[i : i + CHUNK] for a in arrays), **kw) for i in range(0, n, CHUNK)]
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def _broadcast(mech, q, others: list[tuple[object, str, int]], qname: str = "q"):
    """Validate ``q`` (non-finite allowed: masked) and the others (..., n); broadcast, flatten."""
    qv = as_array(q, qname, (mech.nq,), finite=False)
    for a in mech.tree.quat_adr:
        n = np.linalg.norm(qv[..., a : a + 4], axis=-1)
        if np.any(np.isfinite(n) & (n < 1e-9)):
            raise ValueError(f"Expected the quaternion {qname}[..., {a}:{a + 4}] to be non-zero.")
    arrs = [as_array(x, name, (n,), finite=False) for x, name, n in others]
    batch = broadcast_batch(
        (qv, 1, qname), *((a, 1, name) for a, (_, name, _) in zip(arrs, others, strict=True))
    )
    n = int(np.prod(batch))  # explicit: reshape(-1, 0) of an empty trailing axis is ambiguous
    flat = [np.broadcast_to(qv, (*batch, mech.nq)).reshape(n, mech.nq)]
    flat += [np.broadcast_to(a, (*batch, a.shape[-1])).reshape(n, a.shape[-1]) for a in arrs]
    return batch, flat


def _site_inputs(mech, q, arrays, wrenches):
    """Validate the per-sample arrays and the site wrenches, broadcast them with ``q`` and sanitize:
    ``(site indices of the wrenches, batch shape, per-sample ok mask, flat arrays)``."""
    wr = _check_wrenches(mech, wrenches)
    names = list(wr)
    batch, flat = _broadcast(
        mech, q, list(arrays) + [(wr[s], f"wrenches[{mech.tree.site_names[s]!r}]", 6) for s in names]
    )
    ok, flat = _sanitize(mech, flat)
    return names, batch, ok, flat


def _sanitize(mech, flat: list[np.ndarray]) -> tuple[np.ndarray, list[np.ndarray]]:
    # a sample with an entry beyond MAX_MAGNITUDE (1e300, say) would overflow in products: masked like NaN
    # (|x| <= MAX_MAGNITUDE is False for NaN and inf too: one pass tests finiteness and magnitude)
    ok = np.ones(flat[0].shape[0], dtype=bool)
    for a in flat:
        ok &= np.all(np.abs(a) <= MAX_MAGNITUDE, axis=-1)
    out = []
    for i, a in enumerate(flat):
        a = np.array(a, dtype=float)
        a[~ok] = mech.tree.q0 if i == 0 else 0.0
        out.append(a)
    out[0] = normalize_quaternions(mech.tree, out[0])
    return ok, out


def _shape(d: dict, batch, ok: np.ndarray, nan_keys) -> dict:
    """Reshape the flat results to ``batch``.  ``ok``: the input rows were finite.  A sample with any
    non-finite result (inputs of 1e300 overflowing, say; a massless motion's acceleration) is not valid;
    ``nan_keys`` (the forces or accelerations) are NaN where not valid, the other fields (measures such
    as an infinite condition number) keep their values but for non-finite input rows (NaN)."""
    # "_computed" (optional): where the forces are the right answer to a question that has one even if
    # the sample is not valid (an underactuated motion: the least-squares forces); elsewhere "valid"
    computed = d.pop("_computed", d["valid"])
    fin = ok.copy()
    for k, v in d.items():
        v = np.asarray(v)
        if k != "valid" and v.dtype.kind == "f" and v.shape[:1] == ok.shape:
            fin &= np.all(np.isfinite(v.reshape(v.shape[0], int(np.prod(v.shape[1:])))), axis=-1)
    keep = np.asarray(computed) & ok
    for k in nan_keys:  # a computed, finite force stays even where a measure is not finite
        v = np.asarray(d[k])
        keep &= np.all(np.isfinite(v.reshape(v.shape[0], int(np.prod(v.shape[1:])))), axis=-1)
    res = {}
    all_ok, all_kept = bool(ok.all()), bool(keep.all())
    for k, v in d.items():  # every branch returns a new array (no result aliases an input or a cache)
        v = np.asarray(v)
        if k == "valid":
            v = v & fin
        elif k in nan_keys and not all_kept:
            v = np.where(keep.reshape(-1, *(1,) * (v.ndim - 1)), v, np.nan)
        elif v.dtype.kind == "f" and k not in nan_keys and not all_ok:
            v = np.where(ok.reshape(-1, *(1,) * (v.ndim - 1)), v, np.nan)
        else:  # nothing to mask (np.where would only copy, at twice the cost)
            v = v.copy()
        res[k] = np.reshape(v, (*batch, *v.shape[1:]))
    return res


_FORCE_KEYS = ("tau", "M_a", "velocity_terms", "gravity_terms", "external_terms")


def _inverse_full_flat(mech, q, qd, qdd, wr, weights, gravity=True):
    """Inverse dynamics from every coordinate's rates and accelerations (any kinematic class).

    With ``Nb`` an orthonormal basis of the admissible velocities and ``f = M qdd + c + g - J_s^T W`` the
    tree's generalized forces (:mod:`._rnea`), virtual work over every admissible motion asks
    ``Nb^T E tau = Nb^T f``; ``tau = B f`` is its least-squares solution (minimum norm, or minimum
    ``sum tau_i^2 / w_i``), and what no actuator force can do, ``Nb (Nb^T f - Nb^T E tau)``, is the
    force the unactuated coordinates would need.  Where the actuators determine the motion this is
    ``G^T f`` of :func:`_inverse_compiled`.  Computed per sample by the compiled kernel
    (``_rnea_kernels.inv_full_block``), the one implementation at every batch size; its numpy
    formulation is the tests' reference (tests/multibody/_reference.py)."""
    from ._rnea_kernels import inverse_full

    model = compile_model(mech)
    N = q.shape[0]
    gv = np.asarray(mech.gravity, float) if gravity else np.zeros(3)
    out = _id_outputs(N, len(model.act), model.tree.nv, ("unactuated", "closure", "_computed", "valid"))
    return inverse_full(model, q, qd, qdd, *_wrench_arrays(model.tree, wr, N), gv, weights, out)


def _finish_inverse(mech: Mechanism, q: np.ndarray, d: dict, actuated_mode: bool) -> dict:
    """The checks common to both inverse-dynamics forms (actuated and full rates): the closure of the
    input ``q`` (reported by the kernels); in actuator mode a zero
    ``unactuated`` force, the empty passive block's measures and, where a sample is not valid, the
    rank measures against the generic rank (``_rnea_kernels.rank_measures``: a type II singularity has
    cond inf)."""
    tree = mech.tree
    N = q.shape[0]
    if actuated_mode:
        d["unactuated"] = np.zeros((N, tree.nv))
        pas = np.setdiff1d(np.arange(tree.nv), tree.act_dof)
        if mech.constraints.m == 0 or len(pas) == 0:
            d["sigma_min"], d["cond"] = np.full(N, tree.length), np.ones(N)
        else:
            bad = np.flatnonzero(~d["valid"])
            if bad.size:
                from ._rnea_kernels import passive_rank_measures

                d["sigma_min"][bad], d["cond"][bad] = passive_rank_measures(compile_model(mech), q[bad])
    assembled = d["closure"] <= CLOSURE_RTOL * tree.length
    d["valid"] = d["valid"] & assembled
    if "_computed" in d:
        d["_computed"] = d["_computed"] & assembled
    return d


def _determined(mech: Mechanism) -> bool:
    """The actuated rates determine every coordinate's rate (at least one actuator per degree of freedom)."""
    _, dof = _reference(mech)
    na = len(mech.actuated)
    return na > 0 and na >= dof


def _rates_mode(mech: Mechanism, fn: str, act: tuple[str, object], full: tuple[str, object]) -> bool:
    """True: the actuated-rates form (``act``), False: the full-velocity form (``full``); checks that
    exactly one is given and that the actuated form is only used where the actuators determine the motion."""
    (an, av), (fname, fv) = act, full
    if (av is None) == (fv is None):
        raise ValueError(
            f"Expected exactly one of {an} (..., n_act) and {fname}= (..., nv) in {fn}, got "
            f"{'both' if av is not None else 'neither'}."
        )
    if av is not None and not _determined(mech):
        _, dof = _reference(mech)
        raise ValueError(
            f"Expected {fname}= (every coordinate's rate, (..., {mech.nv})) for this mechanism: its "
            f"{len(mech.actuated)} actuated joint(s) do not determine its {dof} degree(s) of freedom, "
            f"so {an} cannot give the state."
        )
    return av is not None


def inverse_dynamics(
    mech: Mechanism,
    q: object,
    qd_act: object = None,
    qdd_act: object = None,
    *,
    qd: object = None,
    qdd: object = None,
    wrenches: Mapping[str, object] | None = None,
    weights: object = None,
    gravity: bool = True,
) -> InverseDynamicsResult:
    """Actuator forces for the motion ``(q, qd_act, qdd_act)`` or ``(q, qd, qdd)`` of any described mechanism.

    ``q (..., nq)`` an assembled configuration (from :func:`forward_kinematics` /
    :func:`inverse_kinematics`), ``qd_act``, ``qdd_act (..., n_act)`` the actuated joints' rates and
    accelerations in actuator order — where the actuators determine the motion (closed chains actuated
    in every degree of freedom, open chains and trees actuated at every joint); for any mechanism,
    every coordinate's rates and accelerations ``qd=``, ``qdd= (..., nv)`` instead (fewer actuators
    than degrees of freedom, none, a floating base).  ``wrenches`` maps site names to wrenches
    ``[m; f] (..., 6)`` applied *to* the mechanism at the site (world axes, moment about the site
    point); gravity from ``mech.gravity`` (MJCF ``<option gravity>``) unless ``gravity=False``.
    ``weights (n_act,)``: the redundant-actuation rule (module docstring; default minimum norm).
    Actuator ``gear`` is not applied: ``tau`` is the generalized force at each actuated joint.  With
    fewer actuators than degrees of freedom ``tau`` is the least-squares best and ``unactuated`` what
    the unactuated coordinates would need (a floating base: the base wrench); the sample is valid only
    where that is zero.  Batched over any leading shape; non-finite samples, unassembled ``q`` and
    singular configurations give ``valid = False`` and NaN forces.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (..., nq)
        Assembled configurations (MuJoCo ``qpos``): the closure residual must be below
        ``CLOSURE_RTOL * L``.
    qd_act : array_like, shape (..., n_act), optional
        Actuated joints' rates in actuator order (rad/s or m/s); must be admissible (with redundant
        actuation, in the consistent subspace), else ``valid`` is False.  Exactly one of ``qd_act``
        (with ``qdd_act``) and ``qd`` (with ``qdd``).
    qdd_act : array_like, shape (..., n_act), optional
        Actuated joints' accelerations (rad/s^2 or m/s^2).
    qd : array_like, shape (..., nv), optional
        Every coordinate's rate (MuJoCo ``qvel``; rad/s, m/s), admissible (``K qd = 0``).
    qdd : array_like, shape (..., nv), optional
        Every coordinate's acceleration (``qacc``; rad/s^2, m/s^2), admissible.
    wrenches : mapping of str to array_like, shape (..., 6), optional
        Site name -> wrench ``[m; f]`` applied *to* the mechanism at that site (world axes, moment
        about the site point; N m, N).  Default None: no external wrench.
    weights : array_like, shape (n_act,), optional
        Redundant-actuation rule: minimise ``sum tau_i^2 / w_i`` (``w_i = 0``: actuator i carries
        nothing).  Default None: minimum-norm forces.  Irrelevant without redundant actuation.
    gravity : bool, optional
        Apply ``mech.gravity`` (MJCF ``<option gravity>``, m/s^2); default True.

    Returns
    -------
    InverseDynamicsResult
        ``tau``, ``M_a``, ``velocity_terms``, ``gravity_terms``, ``external_terms``, every coordinate's
        ``qd`` and ``qdd``, the per-sample ``cond``, ``sigma_min``, ``admissibility``, ``unactuated``,
        ``closure`` and ``valid``.

    Raises
    ------
    ValueError
        If ``mech`` is not a Mechanism, not exactly one of ``qd_act`` / ``qd`` is given (with its
        acceleration), ``qd_act`` is given for a mechanism whose actuators do not determine its
        motion, an array is not real of the stated shape (non-finite values are allowed and masked),
        a quaternion in ``q`` is zero, the batch shapes do not broadcast, ``wrenches`` is not a mapping
        of site names, ``weights`` is not ``n_act`` non-negative numbers (not all zero), or ``gravity``
        is not a bool.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> q = mb.forward_kinematics(mech, np.array([0.2])).q
    >>> r = mb.inverse_dynamics(mech, q, [1.0], [0.5])
    >>> r.tau.shape, r.M_a.shape, bool(r.valid)
    ((1,), (1, 1), True)
    """
    if qd is None and qdd is None and wrenches is None and weights is None:
        one = _inverse_one(mech, q, qd_act, qdd_act, gravity)
        if one is not None:  # one valid sample: straight into the kernel (the general path otherwise)
            return one
    mech = check_mechanism(mech)
    gravity = check_bool(gravity, "gravity")
    act_mode = _rates_mode(mech, "inverse_dynamics", ("qd_act", qd_act), ("qd", qd))
    if act_mode and qdd_act is None:
        raise ValueError("Expected qdd_act (..., n_act) with qd_act, got None.")
    if not act_mode and qdd is None:
        raise ValueError("Expected qdd= (..., nv) with qd=, got None.")
    if (act_mode and qdd is not None) or (not act_mode and qdd_act is not None):
        raise ValueError("Expected qdd_act with qd_act, or qdd= with qd=, not a mix of the two forms.")
    w = _check_weights(mech, weights)
    na, nv = len(mech.actuated), mech.nv
    if act_mode:
        arrays = [(qd_act, "qd_act", na), (qdd_act, "qdd_act", na)]
    else:
        arrays = [(qd, "qd", nv), (qdd, "qdd", nv)]
    names, batch, ok, flat = _site_inputs(mech, q, arrays, wrenches)
    n = flat[0].shape[0]
    if not act_mode:

        def fn_full(qf, qdf, qddf, *ws):
            d = _inverse_full_flat(mech, qf, qdf, qddf, dict(zip(names, ws, strict=True)), w, gravity)
            return _finish_inverse(mech, qf, d, False)

        d = _run_chunked(fn_full, n, flat)
    else:  # the one implementation, compiled per sample (_compiled.inv_dyn), any batch size
        with np.errstate(all="ignore"):
            d = _inverse_compiled(
                mech, flat[0], flat[1], flat[2], dict(zip(names, flat[3:], strict=True)), w, gravity
            )
            d = _finish_inverse(mech, flat[0], d, True)
    return InverseDynamicsResult(**_shape(d, batch, ok, _FORCE_KEYS))


# ----------------------------------------------------------------------------- statics
@dataclass(frozen=True)
class StaticsResult:
    """Actuator forces holding the mechanism at rest against the site wrenches and gravity.

    The result of :func:`statics` (virtual work: ``tau = -G^T (J_s^T W - g)``).

    Attributes
    ----------
    tau : ndarray, shape (..., n_act)
        Actuator forces, ``gravity_terms + external_terms`` (N m or N); NaN where not ``valid``.
    gravity_terms : ndarray, shape (..., n_act)
        Share that holds the weight (N m or N).
    external_terms : ndarray, shape (..., n_act)
        Share that balances the site wrenches (N m or N).
    cond : ndarray, shape (...)
        Condition number of the passive constraint block.
    unactuated : ndarray, shape (..., nv)
        With fewer actuators than degrees of freedom: the generalized force the unactuated
        coordinates would need to hold the mechanism at rest (a floating base: the base wrench), as
        ``InverseDynamicsResult.unactuated``; zero where the actuators determine the motion.
    valid : ndarray of bool, shape (...)
        False at a singular configuration, an unassembled ``q``, a non-finite input, or where the
        actuators cannot hold the mechanism (``unactuated`` not zero).
    """

    tau: np.ndarray
    gravity_terms: np.ndarray
    external_terms: np.ndarray
    cond: np.ndarray
    unactuated: np.ndarray
    valid: np.ndarray


def statics(
    mech: Mechanism,
    q: object,
    *,
    wrenches: Mapping[str, object] | None = None,
    weights: object = None,
    gravity: bool = True,
) -> StaticsResult:
    """Actuator forces balancing ``wrenches`` (applied to the mechanism at sites) and gravity at rest.

    The same virtual-work projection as :func:`inverse_dynamics` at ``qd = qdd = 0``:
    ``tau = -G^T (J_s^T W - g)``; with fewer actuators than degrees of freedom its full-rate form
    (least-squares forces, ``unactuated`` the rest).

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (..., nq)
        Assembled configurations (MuJoCo ``qpos``).
    wrenches : mapping of str to array_like, shape (..., 6), optional
        Site name -> wrench ``[m; f]`` applied *to* the mechanism at that site (world axes, moment
        about the site point; N m, N).  Default None: no external wrench.
    weights : array_like, shape (n_act,), optional
        Redundant-actuation rule, as in :func:`inverse_dynamics` (default None: minimum norm).
    gravity : bool, optional
        Apply ``mech.gravity`` (MJCF ``<option gravity>``, m/s^2); default True.

    Returns
    -------
    StaticsResult
        ``tau``, ``gravity_terms``, ``external_terms`` (..., n_act) (N m or N), ``cond`` and ``valid``.

    Raises
    ------
    ValueError
        If ``mech`` is not a Mechanism, an array is not
        real of the stated shape (non-finite values are allowed and masked), a quaternion in ``q`` is
        zero, the batch shapes do not broadcast, ``wrenches`` is not a mapping of site names,
        ``weights`` is not ``n_act`` non-negative numbers (not all zero), or ``gravity`` is not a bool.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> q = mb.forward_kinematics(mech, np.array([0.2])).q
    >>> st = mb.statics(mech, q, gravity=False)
    >>> bool(np.abs(st.tau).max() < 1e-12), bool(st.valid)
    (True, True)
    """
    mech = check_mechanism(mech)
    q = as_array(q, "q", (mech.nq,), finite=False)
    if _determined(mech):
        z = np.zeros(len(mech.actuated))
        r = inverse_dynamics(mech, q, z, z, wrenches=wrenches, weights=weights, gravity=gravity)
    else:  # the least-squares forces and what the unactuated coordinates would need, at rest
        z = np.zeros(mech.nv)
        r = inverse_dynamics(mech, q, qd=z, qdd=z, wrenches=wrenches, weights=weights, gravity=gravity)
    return StaticsResult(r.tau, r.gravity_terms, r.external_terms, r.cond, r.unactuated, r.valid)


@dataclass(frozen=True)
class SiteWrenchResult:
    """The wrench the mechanism exerts on its environment at a site under actuator forces (at rest).

    The result of :func:`site_wrench`: the least-squares solution of ``J^T W = tau - g_a`` (rotation rows
    scaled by the characteristic length, so that N m and N are compared as N).  With ``n_act < 6`` the
    wrench components the structure carries (``null(J^T)``) are not determined by the actuators and
    are returned as zero (minimum norm).

    Attributes
    ----------
    wrench : ndarray, shape (..., 6)
        ``[m; f]`` in world axes, moment about the site point (N m, N); NaN where not ``valid``.
    residual : ndarray, shape (...)
        Norm of the part of ``tau`` the site cannot transmit (N m or N; non-zero when the actuators
        preload internally or n_act > 6).
    sigma_min : ndarray, shape (...)
        Smallest singular value of ``J`` with its rotation rows times L (m); zero at an output
        singularity where the site cannot resist some wrench.
    cond : ndarray, shape (...)
        Condition number of that scaled ``J`` (above ``SINGULAR_COND``: not valid).
    valid : ndarray of bool, shape (...)
        False at a singular configuration, a non-finite input or a non-finite wrench.
    """

    wrench: np.ndarray
    residual: np.ndarray
    sigma_min: np.ndarray
    cond: np.ndarray
    valid: np.ndarray


def site_wrench(
    mech: Mechanism, q: object, site: str, tau: object, *, gravity: bool = True
) -> SiteWrenchResult:
    """Inverse static map: the site wrench produced by actuator forces ``tau (..., n_act)`` at ``q``.

    The least-squares solution of ``J^T W = tau - g_a`` at rest (``J`` the :func:`site_jacobian`), with
    the rotation rows scaled by the characteristic length; see :class:`SiteWrenchResult`.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism, actuated in every degree of freedom.
    q : array_like, shape (..., nq)
        Assembled configurations (MuJoCo ``qpos``).
    site : str
        Name of the site where the mechanism acts on its environment.
    tau : array_like, shape (..., n_act)
        Actuator forces in actuator order (N m or N).  Batch dimensions broadcast with ``q``.
    gravity : bool, optional
        Apply ``mech.gravity`` (MJCF ``<option gravity>``, m/s^2); default True.

    Returns
    -------
    SiteWrenchResult
        ``wrench [m; f] (..., 6)`` exerted *by* the mechanism (world axes, moment about the site point;
        N m, N), ``residual`` (N m or N), ``sigma_min`` (m), ``cond`` and ``valid`` per sample.

    Raises
    ------
    ValueError
        If ``mech`` is not a Mechanism or has fewer actuators than degrees of freedom, ``site`` is not a
        site name, ``q`` or ``tau`` is not real of the stated shape (non-finite values are masked),
        the batch shapes do not broadcast, or ``gravity`` is not a bool.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> q = mb.forward_kinematics(mech, np.array([0.2])).q
    >>> w = mb.site_wrench(mech, q, "coupler_point", [0.0], gravity=False)
    >>> w.wrench.shape, bool(np.abs(w.wrench).max() < 1e-12)
    ((6,), True)
    """
    from ._compiled import compiled_site_jacobian  # numba loads on the first kernel call

    mech = check_mechanism(mech)
    if not isinstance(site, str):
        raise ValueError(f"Expected site to be a site name (str), got {type(site).__name__}.")
    si = mech.tree.site_index(site)
    gravity = check_bool(gravity, "gravity")
    _fully_actuated(mech)
    na = len(mech.actuated)
    batch, flat = _broadcast(mech, q, [(tau, "tau", na)])
    ok, (qf, tf) = _sanitize(mech, flat)
    tree = mech.tree
    L = tree.length
    out: dict[str, list[np.ndarray]] = {k: [] for k in ("wrench", "residual", "sigma_min", "cond", "valid")}
    empty = qf.shape[0] == 0
    if empty:  # one dummy sample for the result shapes (sliced away below)
        qf, tf = tree.q0[None], np.zeros((1, na))
    # forces of 1e300 overflow in the products and norms: such a sample is flagged (not finite -> not
    # valid, in _shape), quietly, as in inverse_dynamics
    with np.errstate(all="ignore"):
        for i in range(0, qf.shape[0], CHUNK):
            qc, tc = qf[i : i + CHUNK], tf[i : i + CHUNK]
            n = qc.shape[0]
            z = np.zeros((n, na))
            st = _inverse_compiled(mech, qc, z, z, {}, None, gravity)
            J = compiled_site_jacobian(mech, qc, si)  # (n, 6, na)
            Js = np.concatenate([J[:, :3] * L, J[:, 3:]], axis=1)
            U, s, Vt = np.linalg.svd(Js, full_matrices=False)
            smax = s[:, :1]
            keep = s > RANK_RTOL * np.maximum(smax, 1e-300)
            sinv = np.where(keep, 1.0 / np.where(keep, s, 1.0), 0.0)
            rhs = tc - st["gravity_terms"]
            Ws = np.einsum("nik,nk,nkj,nj->ni", U, sinv, Vt, rhs)  # (J_s^T)^+ rhs
            W = np.concatenate([Ws[:, :3] * L, Ws[:, 3:]], axis=1)
            res = np.linalg.norm(np.einsum("nik,ni->nk", J, W) - rhs, axis=-1)
            smin = s[:, -1] if na <= 6 else s[:, 5]
            cond = smax[:, 0] / np.maximum(smin, 1e-300)
            assembled = st["closure"] <= CLOSURE_RTOL * L
            valid = st["valid"] & assembled & (cond <= SINGULAR_COND) & np.all(np.isfinite(W), axis=-1)
            for k, v in zip(out, (W, res, smin, cond, valid), strict=True):
                out[k].append(v)
    d = {k: np.concatenate(v)[: 0 if empty else None] for k, v in out.items()}
    d = _shape(d, batch, ok, ("wrench",))
    return SiteWrenchResult(**d)


# ----------------------------------------------------------------------------- forward dynamics
def _wrench_arrays(tree, wr: dict[int, np.ndarray], N: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Site wrenches packed for the kernels: ``W (N, ns, 6)``, the sites' bodies ``(ns,)`` and frames
    ``(ns, 4, 4)``."""
    sites = list(wr)
    W = np.zeros((N, len(sites), 6))
    for i, si in enumerate(sites):
        W[:, i] = wr[si]
    wsb = np.array([tree.site_body[si] for si in sites], dtype=np.int64)
    wT = np.ascontiguousarray(np.array([tree.T_site[si] for si in sites], dtype=float).reshape(-1, 4, 4))
    return W, wsb, wT


def _forward_compiled(mech, q, rates, tau_a, wr, gravity, act_mode: bool) -> tuple:
    """Forward dynamics of normalised ``q (N, nq)`` under actuator forces ``tau_a (N, n_act)`` and site
    wrenches ``wr``, the closure a constraint on the tree accelerations (module docstring), by the
    compiled per-sample kernel (``_rnea_kernels.fd_block``), the one implementation at every batch
    size.  ``rates``: ``qd_act (N, n_act)`` (``act_mode``) or every rate ``qd (N, nv)``.  Returns
    ``(qd, qdd, cond, admissibility, closure, regular)``; the numpy formulation is the tests'
    reference (tests/multibody/_reference.py)."""
    from ._rnea_kernels import forward

    model = compile_model(mech)
    tree = model.tree
    N = q.shape[0]
    F = np.zeros((N, tree.nv))
    F[:, tree.act_dof] = tau_a
    W, wsb, wT = _wrench_arrays(tree, wr, N)
    gv = np.asarray(mech.gravity, dtype=float) if gravity else np.zeros(3)
    return forward(model, q, rates, F, W, wsb, wT, gv, act_mode)


_F64 = np.dtype(np.float64)


def _plain_one(mech, q, rates, tau, gravity) -> bool:
    """The arguments of a one-sample fast path are of the plain types (arrays, a bool, no subclass)."""
    return (
        type(mech) is Mechanism
        and type(q) is np.ndarray
        and type(rates) is np.ndarray
        and (tau is None or type(tau) is np.ndarray)
        and (gravity is True or gravity is False)
    )


def _forward_one(mech, q, qd_act, tau, gravity) -> ForwardDynamicsResult | None:
    """One sample in the actuated-rates form (closed chains included), given as C-contiguous float64
    vectors of the exact shapes, no wrench: checked here (every entry within ``MAX_MAGNITUDE``,
    quaternions non-zero and normalised), then one call of the kernel block (``_rnea_kernels.fd_block``,
    the same per-sample code as every batch) with the general path's flags; None (the general path
    validates, masks and explains) for any other input and for a sample that is not valid."""
    if not _plain_one(mech, q, qd_act, tau, gravity):
        return None
    model = compile_model(mech)
    tree = model.tree
    na = len(model.act)
    if na == 0 or na < model.dof:
        return None
    for x, shape in ((q, (tree.nq,)), (qd_act, (na,)), (tau, (na,))):
        if x is not None and (x.shape != shape or x.dtype is not _F64 or not x.flags.c_contiguous):
            return None
    with np.errstate(invalid="ignore"):
        if not (np.abs(q).max() <= MAX_MAGNITUDE and np.abs(qd_act).max() <= MAX_MAGNITUDE):
            return None
        if tau is not None and not np.abs(tau).max() <= MAX_MAGNITUDE:
            return None
    if tree.quat_adr:
        q = q.copy()
        for a in tree.quat_adr:
            nrm = float(np.sqrt(q[a] ** 2 + q[a + 1] ** 2 + q[a + 2] ** 2 + q[a + 3] ** 2))
            if not nrm >= 1e-9:
                return None
            q[a : a + 4] /= nrm
    from ._rnea_kernels import forward

    F = np.zeros((1, tree.nv))
    if tau is not None:
        F[0, tree.act_dof] = tau
    gv = model.cache.get("gravity_vector")
    if gv is None:
        gv = model.cache["gravity_vector"] = np.array(mech.gravity, dtype=float)
    qd, qdd, cond, adm, closure, reg = forward(
        model, q[None], qd_act[None], F, *_NO_WRENCH, gv if gravity else _ZERO3, True
    )
    L = tree.length
    c, a, cl = cond[0], adm[0], closure[0]
    if not (
        reg[0]
        and c < 1.0 / RANK_RTOL
        and a <= ADMISSIBLE_RTOL
        and cl <= CLOSURE_RTOL * L
        and np.all(np.isfinite(qdd))
    ):
        return None
    return ForwardDynamicsResult(
        qdd_act=qdd[0, tree.act_dof],
        qdd=qdd[0],
        qd=qd[0],
        cond=np.array(c),
        admissibility=np.array(a),
        closure=np.array(cl),
        valid=np.array(True),
    )


_NO_WRENCH = (np.zeros((1, 0, 6)), np.zeros(0, dtype=np.int64), np.zeros((0, 4, 4)))


def _forward_tree_one(mech, q, tau, qd, gravity) -> ForwardDynamicsResult | None:
    """One sample of an open tree (no closure rows) in the full-rate form, given as C-contiguous float64
    vectors of the exact shapes: the kernel checks the entries (within ``MAX_MAGNITUDE``; quaternions
    non-zero) and computes ``qdd`` and ``cond`` in one call, with the general path's flags (no closure:
    admissibility and closure 0, valid where ``cond < 1 / RANK_RTOL`` and every value is finite);
    None (the general path validates and masks) otherwise."""
    if not _plain_one(mech, q, qd, tau, gravity):
        return None
    model = compile_model(mech)
    tree = model.tree
    nv = tree.nv
    if model.tables.m or not nv:
        return None
    na = len(model.act)
    for x, shape in ((q, (tree.nq,)), (qd, (nv,)), (tau, (na,))):
        if x is not None and (x.shape != shape or x.dtype is not _F64 or not x.flags.c_contiguous):
            return None
    from ._compiled import entry
    from ._rnea_kernels import fd_tree_one

    F = np.zeros(nv)
    if tau is not None:
        F[tree.act_dof] = tau
    gv = model.cache.get("gravity_vector")
    if gv is None:
        gv = model.cache["gravity_vector"] = np.array(mech.gravity, dtype=float)
    qdd, cond = np.empty(nv), np.empty(1)
    if entry(
        model,
        fd_tree_one,
        "fd_tree_one",
        (q, qd, F, gv if gravity else _ZERO3, model.rnea, np.empty(tree.nq), qdd, cond),
    ):
        return None
    c = cond[0]
    fin = bool(np.isfinite(c)) and bool(np.all(np.isfinite(qdd)))
    valid = fin and c < 1.0 / RANK_RTOL
    if not valid:
        qdd = np.full(nv, np.nan)
    return ForwardDynamicsResult(
        qdd_act=qdd[tree.act_dof],
        qdd=qdd,
        qd=qd.copy(),
        cond=np.array(c),
        admissibility=np.array(0.0),
        closure=np.array(0.0),
        valid=np.array(valid),
    )


_ZERO3 = np.zeros(3)


@dataclass(frozen=True)
class ForwardDynamicsResult:
    """Accelerations under actuator forces: the result of :func:`forward_dynamics`.

    Attributes
    ----------
    qdd_act : ndarray, shape (..., n_act)
        Actuated joints' accelerations in actuator order (rad/s^2 or m/s^2); NaN where not ``valid``.
    qdd : ndarray, shape (..., nv)
        Every tree coordinate's acceleration (MuJoCo ``qvel`` order), idle motions included (free, no
        force on them); NaN where not ``valid``.
    qd : ndarray, shape (..., nv)
        Every tree coordinate's rate, ``G qd_act`` or the given ``qd`` (rad/s, m/s).
    cond : ndarray, shape (...)
        Condition number of the constrained mass matrix (large: a nearly massless motion; inf: a
        massless one), or of the passive constraint block if larger (``qd_act`` form).
    admissibility : ndarray, shape (...)
        Closure error of the given rates ``|K qd|`` and of the resulting acceleration
        ``|K qdd + Kdot qd|``, relative.
    closure : ndarray, shape (...)
        Largest closure row of the input ``q`` (m); above ``CLOSURE_RTOL * L`` the sample is not valid.
    valid : ndarray of bool, shape (...)
        False at a singular configuration, a singular (e.g. massless) mass matrix, an inadmissible
        result, an unassembled ``q`` or a non-finite input.
    """

    qdd_act: np.ndarray
    qdd: np.ndarray
    qd: np.ndarray
    cond: np.ndarray
    admissibility: np.ndarray
    closure: np.ndarray
    valid: np.ndarray


def forward_dynamics(
    mech: Mechanism,
    q: object,
    qd_act: object = None,
    tau: object = None,
    *,
    qd: object = None,
    wrenches: Mapping[str, object] | None = None,
    gravity: bool = True,
) -> ForwardDynamicsResult:
    """Accelerations under actuator forces ``tau (..., n_act)`` at ``(q, qd_act)`` or ``(q, qd)``.

    The inverse of :func:`inverse_dynamics`: ``forward_dynamics(mech, q, qd, inverse_dynamics(mech, q,
    qd, qdd).tau).qdd_act == qdd`` wherever both are valid and the mechanism has no idle motions.  Idle
    motions (a Delta forearm spinning about its axis) are free here: no force acts on them and they
    accelerate as the tree's dynamics say, whereas the actuator-rate inverse prescribes their
    acceleration (minimum norm), which needs a small torque on them that no actuator supplies; through
    the inertia coupling the round trip then misses by that torque's effect (1e-6 to 1e-5 relative on the
    gallery Delta; ``docs/dynamics.md``).  The full-rate form round-trips exactly.  Where the
    actuators determine the motion, the state is ``(q, qd_act)`` and the passive coordinates' rates are
    ``qd = G qd_act`` (idle motions at rest); for any mechanism — and necessarily where the actuators
    do not determine it (fewer actuators than degrees of freedom, none, a floating base) — every
    coordinate's rate ``qd= (..., nv)`` instead.  The closure is a constraint on the tree
    accelerations (``K qdd = -Kdot qd``, module docstring).

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (..., nq)
        Assembled configurations (MuJoCo ``qpos``; closure residual below ``CLOSURE_RTOL * L``).
    qd_act : array_like, shape (..., n_act), optional
        Actuated joints' rates in actuator order (rad/s or m/s).  Exactly one of ``qd_act`` and ``qd``.
    tau : array_like, shape (..., n_act), optional
        Generalized forces at the actuated joints (N m or N; actuator ``gear`` not applied); default
        None: no actuator force.
    qd : array_like, shape (..., nv), optional
        Every coordinate's rate (MuJoCo ``qvel``; rad/s, m/s), admissible (``K qd = 0``).
    wrenches : mapping of str to array_like, shape (..., 6), optional
        Site name -> wrench ``[m; f]`` applied *to* the mechanism at that site (world axes, moment
        about the site point; N m, N).  Default None: no external wrench.
    gravity : bool, optional
        Apply ``mech.gravity`` (MJCF ``<option gravity>``, m/s^2); default True.

    Returns
    -------
    ForwardDynamicsResult
        ``qdd_act (..., n_act)``, every coordinate's ``qdd`` and ``qd (..., nv)``, and per sample
        ``cond``, ``admissibility``, ``closure`` and ``valid`` (accelerations NaN where not valid).

    Raises
    ------
    ValueError
        If ``mech`` is not a Mechanism, not exactly one of ``qd_act`` and ``qd`` is given,
        ``qd_act`` is given for a mechanism whose actuators do not determine its motion, an array is
        not real of the stated shape (non-finite values are masked), a quaternion in ``q`` is zero, the
        batch shapes do not broadcast, ``wrenches`` is not a mapping of site names, or ``gravity`` is
        not a bool.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> q = mb.forward_kinematics(mech, np.array([0.2])).q
    >>> tau = mb.inverse_dynamics(mech, q, [1.0], [0.5]).tau
    >>> fd = mb.forward_dynamics(mech, q, [1.0], tau)
    >>> bool(np.allclose(fd.qdd_act, 0.5)), bool(fd.valid)
    (True, True)
    """
    if wrenches is None:  # one sample as float64 vectors: one kernel call
        one = (
            _forward_tree_one(mech, q, tau, qd, gravity)
            if qd_act is None
            else _forward_one(mech, q, qd_act, tau, gravity)
            if qd is None
            else None
        )
        if one is not None:
            return one
    mech = check_mechanism(mech)
    gravity = check_bool(gravity, "gravity")
    act_mode = _rates_mode(mech, "forward_dynamics", ("qd_act", qd_act), ("qd", qd))
    na, nv = len(mech.actuated), mech.nv
    rates = (qd_act, "qd_act", na) if act_mode else (qd, "qd", nv)
    tau_in = np.zeros(na) if tau is None else tau
    names, batch, ok, flat = _site_inputs(mech, q, [rates, (tau_in, "tau", na)], wrenches)
    tree = mech.tree
    L = tree.length

    def fn(qf, rf, tf, *ws):
        qd_f, qdd, cond, adm, closure, reg = _forward_compiled(
            mech, qf, rf, tf, dict(zip(names, ws, strict=True)), gravity, act_mode
        )
        valid = (
            reg
            & (cond < 1.0 / RANK_RTOL)
            & (adm <= ADMISSIBLE_RTOL)
            & (closure <= CLOSURE_RTOL * L)
            & np.all(np.isfinite(qdd), axis=-1)
        )
        return dict(
            qdd_act=qdd[:, tree.act_dof],
            qdd=qdd,
            qd=qd_f,
            cond=cond,
            admissibility=adm,
            closure=closure,
            valid=valid,
        )

    d = _run_chunked(fn, flat[0].shape[0], flat)
    return ForwardDynamicsResult(**_shape(d, batch, ok, ("qdd_act", "qdd")))


# ----------------------------------------------------------------------------- energy
def energy(mech: Mechanism, q: object, qd: object) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and potential energy ``(T, U) (...)`` (J) at ``q (..., nq)`` with every coordinate's rate
    ``qd (..., nv)`` (``U = -sum m g . c``, zero at the world origin).

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (..., nq)
        Configurations (MuJoCo ``qpos``).
    qd : array_like, shape (..., nv)
        Rate of every velocity coordinate (``qvel``; rad/s, m/s), e.g. ``influence(mech, q).G @
        qd_act``.  Batch dimensions broadcast with ``q``.

    Returns
    -------
    T : ndarray, shape (...)
        Kinetic energy of every body (J).
    U : ndarray, shape (...)
        Gravitational potential energy ``-sum m g . c`` with ``g = mech.gravity`` and ``c`` each body's
        centre of mass in the world frame (J).

    Raises
    ------
    ValueError
        If ``mech`` is not a Mechanism, ``q`` or ``qd`` is not finite real of the stated shape, or the
        batch shapes do not broadcast.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> q = mb.forward_kinematics(mech, np.array([0.2])).q
    >>> T, U = mb.energy(mech, q, np.zeros(mech.nv))
    >>> T.shape, float(T)
    ((), 0.0)
    """
    mech = check_mechanism(mech)
    q = check_q(mech, q, nan_rows=True)  # a failed sample (NaN row) gives NaN energies
    qd = as_array(qd, "qd", (mech.nv,))
    batch = broadcast_batch((q, 1, "q"), (qd, 1, "qd"))
    qf = np.broadcast_to(q, (*batch, mech.nq)).reshape(-1, mech.nq)
    qdf = np.broadcast_to(qd, (*batch, mech.nv)).reshape(-1, mech.nv)

    from ._compiled import compiled_energy  # numba loads on the first kernel call

    model = compile_model(mech)
    gv = np.asarray(mech.gravity, dtype=float)

    def energies(qs: np.ndarray, qds: np.ndarray) -> tuple:
        return compiled_energy(model, qs, qds, gv)

    (T, U) = on_rows(failed_rows(qf), energies, qf, qdf, probe=(mech.tree.q0[None], qdf[:1]))
    return np.reshape(T, batch), np.reshape(U, batch)


# ----------------------------------------------------------------------------- simulation
# Integrator tolerances for solve_ivp (DOP853): relative 1e-10 and absolute 1e-12 (rad, m, rad/s) keep the
# local error far below the closure tolerance between two projections.
SIM_RTOL = 1e-10
# Largest |entry| of an initial state (rad, m, rad/s, m/s) accepted by simulate: far beyond any
# mechanism, far below overflow of the squares in the energy (1e300 overflows).
MAX_STATE = 1e100
SIM_ATOL = 1e-12


def _qpos_rate(tree, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """``dq/dt (N, nq)`` from the velocity coordinates (quaternion rates from local angular velocity)."""
    out = np.zeros_like(q)
    for k in range(len(tree.jnt_names)):
        typ, qa, da = tree.jnt_type[k], tree.jnt_qadr[k], tree.jnt_dadr[k]
        if typ <= 1:
            out[:, qa] = qd[:, da]
        elif typ == 2:
            w = np.concatenate([np.zeros((q.shape[0], 1)), qd[:, da : da + 3]], axis=-1)
            out[:, qa : qa + 4] = 0.5 * quat_mul(q[:, qa : qa + 4], w)
        else:
            out[:, qa : qa + 3] = qd[:, da : da + 3]
            w = np.concatenate([np.zeros((q.shape[0], 1)), qd[:, da + 3 : da + 6]], axis=-1)
            out[:, qa + 3 : qa + 7] = 0.5 * quat_mul(q[:, qa + 3 : qa + 7], w)
    return out


@dataclass(frozen=True)
class SimulationResult:
    """A simulated motion, batch ``...`` of initial conditions, ``nt`` output times.

    The result of :func:`simulate`.

    Attributes
    ----------
    t : ndarray, shape (nt,)
        Output times (s).
    q : ndarray, shape (..., nt, nq)
        Configurations (MuJoCo ``qpos``) after projection onto the closure; NaN after a failure.
    qd : ndarray, shape (..., nt, nv)
        Every tree coordinate's rate (``qvel``; rad/s, m/s).
    q_act : ndarray, shape (..., nt, n_act)
        Actuated joints' positions in actuator order (rad or m).
    qd_act : ndarray, shape (..., nt, n_act)
        Actuated joints' rates (rad/s or m/s).
    kinetic : ndarray, shape (..., nt)
        Kinetic energy ``T`` (J).
    potential : ndarray, shape (..., nt)
        Gravitational potential energy ``U`` (J).
    work : ndarray, shape (..., nt)
        The actuators' work since ``t[0]`` (J).
    energy_drift : ndarray, shape (...)
        Max over t of ``|T + U - W - (T + U)(t0)|`` (J); NaN where not ``success``.
    energy_drift_rel : ndarray, shape (...)
        ``energy_drift`` divided by the largest of ``T``, ``|U - U(t0)|`` and ``W`` over the motion.
    closure : ndarray, shape (..., nt)
        Closure residual after projection (m).
    success : ndarray of bool, shape (...)
        The integration succeeded, every state is finite and every closure is below
        ``CONVERGED_RTOL * L``.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    q_act: np.ndarray
    qd_act: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    work: np.ndarray
    energy_drift: np.ndarray
    energy_drift_rel: np.ndarray
    closure: np.ndarray
    success: np.ndarray


def _project(mech, q, qd):
    """Back onto the manifold: positions by the closure Newton iteration (all coordinates), velocities
    onto ``null(K)`` (minimum-norm correction), both by the compiled kernels."""
    from ._compiled import compiled_fk, compiled_project  # numba loads on the first kernel call

    q, rc, _, _ = compiled_fk(mech, q, np.arange(mech.tree.nv))
    return q, compiled_project(compile_model(mech), q, qd), rc


class _SampleFailed(Exception):
    """A sample's integration cannot go on (non-finite state, force or acceleration)."""


def _callback_forces(tau_fn, tt, q, qd, na: int) -> np.ndarray:
    """Call ``tau_fn(t, q (1, nq), qd (1, nv))``; check its return: ``(n_act,)`` or ``(1, n_act)`` reals."""
    out = tau_fn(tt, q, qd)
    try:
        a = np.asarray(out, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"Expected the tau callback to return {na} real force(s) per sample, shape (1, {na}), "
            f"got {type(out).__name__}."
        ) from exc
    if a.shape not in ((na,), (1, na)) and not (na == 0 and a.size == 0):
        raise ValueError(
            f"Expected the tau callback to return shape (1, {na}) (or ({na},)) for the one sample it "
            f"is given, got shape {a.shape}."
        )
    return a.reshape(1, na)


def _simulate_one(mech, q0, qd0, t, tau_fn, gravity):
    """One sample's trajectory (its own ``solve_ivp`` run: step sizes and error control are its own, so
    no other sample can change it).  Returns ``Q (nt, nq), QD (nt, nv), W (nt,), RC (nt,), ok``."""
    from scipy.integrate import solve_ivp

    tree = mech.tree
    nq, nv = tree.nq, tree.nv
    na = len(tree.act_dof)

    def rhs(tt, y):
        q, qd = y[None, :nq], y[None, nq : nq + nv]
        qn = normalize_quaternions(tree, q) if tree.quat_adr else q
        tau = np.zeros((1, na)) if tau_fn is None else tau_fn(tt, qn, qd)
        if not np.all(np.isfinite(tau)):
            raise _SampleFailed
        try:
            qdd = _forward_compiled(mech, qn, qd, tau, {}, gravity, False)[1]
        except np.linalg.LinAlgError as exc:  # a non-finite state reached an SVD
            raise _SampleFailed from exc
        if not np.all(np.isfinite(qdd)):  # a singular (massless) motion: no acceleration exists
            raise _SampleFailed
        power = np.sum(tau * qd[:, tree.act_dof], axis=-1)
        return np.concatenate([_qpos_rate(tree, qn, qd)[0], qdd[0], power])

    nt = len(t)
    Q = np.full((nt, nq), np.nan)
    QD = np.full((nt, nv), np.nan)
    W = np.full(nt, np.nan)
    RC = np.full(nt, np.inf)
    q, qd, rc = _project(mech, q0[None], qd0[None])
    Q[0], QD[0], W[0], RC[0] = q[0], qd[0], 0.0, rc[0]
    with np.errstate(all="ignore"):
        for i in range(1, nt):
            y0 = np.concatenate([Q[i - 1], QD[i - 1], W[i - 1 : i]])
            try:
                sol = solve_ivp(rhs, (t[i - 1], t[i]), y0, method="DOP853", rtol=SIM_RTOL, atol=SIM_ATOL)
            except _SampleFailed:
                return Q, QD, W, RC, False
            if not sol.success or not np.all(np.isfinite(sol.y[:, -1])):
                return Q, QD, W, RC, False
            y = sol.y[:, -1]
            try:
                q, qd, rc = _project(mech, normalize_quaternions(tree, y[None, :nq]), y[None, nq : nq + nv])
            except np.linalg.LinAlgError:
                return Q, QD, W, RC, False
            Q[i], QD[i], W[i], RC[i] = q[0], qd[0], y[-1], rc[0]
    return Q, QD, W, RC, True


def simulate(
    mech: Mechanism,
    q0: object,
    qd_act0: object = None,
    t: object = None,
    *,
    qd0: object = None,
    tau: object = None,
    gravity: bool = True,
) -> SimulationResult:
    """Integrate the mechanism from ``(q0, qd_act0)`` (or ``(q0, qd0)``) to the output times ``t``.

    The initial rates: ``qd_act0 (..., n_act)`` where the actuators determine the motion (the other
    coordinates start at ``qd = G qd_act0``), or every coordinate's rate ``qd0= (..., nv)`` for any
    mechanism (necessarily where the actuators do not determine the motion: fewer actuators than
    degrees of freedom, none, a floating base).  ``tau`` the actuator forces: None (passive motion),
    an array ``(..., n_act)`` held constant, or a callable ``tau(t, q (1, nq), qd (1, nv)) -> (1, n_act)``
    called for one sample at a time.  The state is every tree coordinate (idle motions included),
    integrated by ``scipy.integrate.solve_ivp`` (DOP853, ``SIM_RTOL = 1e-10``, ``SIM_ATOL = 1e-12``)
    between consecutive output times and projected back onto the constraint manifold at each of them.
    Every sample is integrated on its own (its own steps and error control): one sample's state
    never changes another's, and a sample that fails (a massless motion without acceleration, a
    non-finite force from the callback) stops alone with ``success = False``.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q0 : array_like, shape (..., nq)
        Initial configurations (MuJoCo ``qpos``); projected onto the closure before the start.
    qd_act0 : array_like, shape (..., n_act), optional
        Initial actuated rates (rad/s or m/s).  Exactly one of ``qd_act0`` and ``qd0``.
    t : array_like, shape (nt,)
        Strictly increasing output times (s), at least two; the first is the start time.  Required.
    qd0 : array_like, shape (..., nv), optional
        Every coordinate's initial rate (``qvel``; rad/s, m/s), projected onto the admissible ones.
    tau : None, array_like of shape (..., n_act), or callable, optional
        Actuator forces (N m or N): None (default, no actuator force), constant forces, or
        ``tau(t, q (1, nq), qd (1, nv)) -> (1, n_act)`` (or ``(n_act,)``) for the sample it is given.
    gravity : bool, optional
        Apply ``mech.gravity`` (MJCF ``<option gravity>``, m/s^2); default True.

    Returns
    -------
    SimulationResult
        ``t``, the trajectories ``q``, ``qd``, ``q_act``, ``qd_act`` ``(..., nt, ·)``, the energies and
        actuator work ``(..., nt)`` (J), ``energy_drift``, ``energy_drift_rel``, ``closure`` and
        ``success``.

    Raises
    ------
    ValueError
        If ``mech`` is not a Mechanism, not exactly one of ``qd_act0`` and ``qd0`` is given,
        ``qd_act0`` is given for a mechanism whose actuators do not determine its motion, ``t`` is not
        at least two increasing times, an array is not real of the stated shape, ``q0`` or the initial
        rates are not finite or exceed ``MAX_STATE``, ``gravity`` is not a bool, or the ``tau``
        callback returns something other than ``(1, n_act)`` real forces.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> q = mb.forward_kinematics(mech, np.array([0.2])).q
    >>> sim = mb.simulate(mech, q, [1.0], [0.0, 0.01, 0.02])
    >>> sim.q.shape, sim.qd_act.shape, bool(sim.success)
    ((3, 3), (3, 1), True)
    """
    mech = check_mechanism(mech)
    gravity = check_bool(gravity, "gravity")
    act_mode = _rates_mode(mech, "simulate", ("qd_act0", qd_act0), ("qd0", qd0))
    tree = mech.tree
    na = len(mech.actuated)
    if t is None:
        raise ValueError("Expected t to be increasing output times (at least 2), got None.")
    t = as_array(t, "t", (None,))
    if t.ndim != 1 or t.shape[0] < 2 or np.any(np.diff(t) <= 0):
        raise ValueError(f"Expected t to be increasing output times (at least 2), got shape {t.shape}.")
    tau_arr = None
    if tau is not None and not callable(tau):
        tau_arr = as_array(tau, "tau", (na,))
    rates = (qd_act0, "qd_act0", na) if act_mode else (qd0, "qd0", tree.nv)
    batch, flat = _broadcast(
        mech,
        q0,
        [rates] + ([(tau_arr, "tau", na)] if tau_arr is not None else []),
        qname="q0",
    )
    q0f, r0 = flat[0], flat[1]
    for x, nm in ((q0f, "q0"), (r0, rates[1])):
        # an initial state is simulated, not masked: it must be finite and of physical size
        if not np.all(np.isfinite(x)) or np.any(np.abs(x) > MAX_STATE):
            raise ValueError(f"Expected {nm} finite with |value| <= {MAX_STATE:g}, got NaN, inf or more.")
    q0f = normalize_quaternions(tree, q0f)
    N = q0f.shape[0]
    if act_mode:  # the initial rates of every coordinate: qd = G qd_act0 (idle motions at rest)
        from ._compiled import compiled_influence  # numba loads on the first kernel call

        qd0f = _mv(compiled_influence(compile_model(mech), q0f, False)[0], r0)
    else:
        qd0f = np.array(r0)
    nt = len(t)
    Q = np.empty((N, nt, tree.nq))
    QD = np.empty((N, nt, tree.nv))
    W = np.empty((N, nt))
    RC = np.empty((N, nt))
    success = np.zeros(N, dtype=bool)
    for i in range(N):
        fn_i: Callable[..., np.ndarray] | None = None
        if tau_arr is not None:
            held = flat[2][i : i + 1]
            fn_i = lambda tt, q, qd, v=held: v  # noqa: E731
        elif callable(tau):
            fn_i = lambda tt, q, qd: _callback_forces(tau, tt, q, qd, na)  # noqa: E731
        Q[i], QD[i], W[i], RC[i], success[i] = _simulate_one(mech, q0f[i], qd0f[i], t, fn_i, gravity)
    from ._assembly import CONVERGED_RTOL
    from ._compiled import compiled_energy

    Tk, U = compiled_energy(
        compile_model(mech),
        np.nan_to_num(Q.reshape(-1, tree.nq)),
        np.nan_to_num(QD.reshape(-1, tree.nv)),
        np.asarray(mech.gravity, dtype=float),
    )
    Tk, U = Tk.reshape(N, nt), U.reshape(N, nt)
    E = Tk + U - W
    with np.errstate(all="ignore"):
        drift = np.max(np.abs(E - E[:, :1]), axis=-1)
        scale = np.maximum.reduce([np.max(Tk, -1), np.max(np.abs(U - U[:, :1]), -1), np.max(np.abs(W), -1)])
        rel = drift / np.maximum(scale, 1e-300)
    success &= np.all(np.isfinite(Q), axis=(-1, -2)) & np.all(RC <= CONVERGED_RTOL * tree.length, axis=-1)
    bad = ~success
    drift = np.where(bad, np.nan, drift)
    rel = np.where(bad, np.nan, rel)
    Tk = np.where(np.isfinite(Q).all(-1), Tk, np.nan)
    U = np.where(np.isfinite(Q).all(-1), U, np.nan)

    def rs(x, *tail):
        return np.reshape(x, (*batch, *tail))

    return SimulationResult(
        t=t.copy(),
        q=rs(Q, nt, tree.nq),
        qd=rs(QD, nt, tree.nv),
        q_act=rs(Q[..., tree.act_qadr], nt, na),
        qd_act=rs(QD[..., tree.act_dof], nt, na),
        kinetic=rs(Tk, nt),
        potential=rs(U, nt),
        work=rs(W, nt),
        energy_drift=rs(drift),
        energy_drift_rel=rs(rel),
        closure=rs(RC, nt),
        success=rs(success),
    )
