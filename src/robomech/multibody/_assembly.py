"""Assembly (position analysis): forward and inverse kinematics of any described closed chain.

Both solve the closure equations (plus, for IK, the site's pose error) by the Levenberg–Marquardt
iteration on the velocity constraint matrix, in least squares, so that redundant constraints (more
equations than independent ones) and redundant actuation (more inputs than DOF, consistent inputs)
work: the compiled per-sample kernel ``_compiled.lm_solve`` at every batch size (FK through
``_compiled.compiled_fk``, IK through the design-batched driver ``_designs.ik_designs`` on the one
design).  Every sample has its own damping, its own acceptance test and its own stop; a sample that
cannot close stops with ``converged = False`` and does not affect the others.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from robomech._validation import MAX_MAGNITUDE, as_array, broadcast_batch, check_int

from ._compile import compile_model
from ._model import Mechanism
from ._options import CONVERGED_RTOL
from ._tree import normalize_quaternions

__all__ = [
    "CONVERGED_RTOL",
    "FKResult",
    "IKResult",
    "check_mechanism",
    "check_q",
    "forward_kinematics",
    "inverse_kinematics",
]

# (tolerances and iteration limits: _options)


def check_mechanism(mech: object) -> Mechanism:
    if not isinstance(mech, Mechanism):
        raise ValueError(f"Expected mech to be a robomech.multibody.Mechanism, got {type(mech).__name__}.")
    return mech


def check_q(mech: Mechanism, q: object, name: str = "q", *, nan_rows: bool = False) -> np.ndarray:
    """``q (..., nq)`` finite, quaternions non-zero; returns it with quaternions normalised.

    ``nan_rows=True`` is the rule of the batched analysis functions (docs/conventions.md, "Failed
    samples chain"): a sample with a NaN entry is a failed sample of an earlier call (what
    :func:`forward_kinematics` returns where it did not converge); the whole row is set to NaN and
    the caller gives NaN / False for it (:func:`robomech._batching.on_rows`).  ±inf and magnitudes above
    ``MAX_MAGNITUDE`` are refused either way: they are no failed sample but a wrong input.
    """
    q = as_array(q, name, (mech.nq,), nan_rows=nan_rows)
    for a in mech.tree.quat_adr:
        n = np.linalg.norm(q[..., a : a + 4], axis=-1)
        if np.any(n < 1e-9):
            raise ValueError(
                f"Expected the quaternion {name}[..., {a}:{a + 4}] to be non-zero, got norm {np.nanmin(n)}."
            )
    return normalize_quaternions(mech.tree, q)


# Singular values of the passive block below this fraction of the largest are the start's idle or
# redundant directions: left out of the assembly-mode determinant (they carry no mode).
MODE_RANK_RTOL = 1e-8
# Largest number of continuation stages: each stage is a full Newton solve of the batch; a million
# stages of one sample already take minutes, and 10**4 stages of 1e-4 of the move suffice for any
# path the gallery needs.
MAX_STEPS = 10_000


def _passive_block(mech: Mechanism, q: np.ndarray) -> np.ndarray:
    """The passive columns ``K_p (N, m, nv - na)`` of the velocity constraint matrix at ``q (N, nq)``."""
    from ._compiled import compiled_resjac  # numba loads on the first kernel call, not at import

    model = compile_model(mech)
    return compiled_resjac(model, q, True)[1][..., model.pas]


def assembly_mode_sign(mech: Mechanism, q_start: np.ndarray, q_end: np.ndarray) -> np.ndarray:
    """Sign (+1, -1; 0 where undefined) of ``det(U^T K_p(q_end) V)`` with ``K_p(q_start) = U S V^T``.

    ``K_p`` is the passive block of the constraint Jacobian; ``U``, ``V`` its singular vectors at
    ``q_start (N, nq)`` restricted to the non-zero singular values.  At ``q_start`` the determinant is
    the product of those singular values (positive); it vanishes exactly where ``K_p`` loses rank (a
    type II singularity), so a negative sign at ``q_end`` says ``q_end`` is on another assembly mode
    (five-bar elbow flipped, a 3-UPU platform in its rotating mode).  0 where a configuration is not
    finite or the mechanism has no passive block.
    """
    N = q_start.shape[0]
    ok = np.all(np.isfinite(q_start), axis=-1) & np.all(np.isfinite(q_end), axis=-1)
    out = np.zeros(N)
    if not ok.any():
        return out
    K0 = _passive_block(mech, q_start[ok])
    K1 = _passive_block(mech, q_end[ok])
    if K0.shape[1] == 0 or K0.shape[2] == 0:
        return out
    U, sv, Vt = np.linalg.svd(K0, full_matrices=False)
    keep = sv > MODE_RANK_RTOL * sv[:, :1]
    M = U.swapaxes(-1, -2) @ K1 @ Vt.swapaxes(-1, -2)
    both = keep[:, :, None] & keep[:, None, :]
    M = np.where(both, M, np.eye(M.shape[-1]))
    out[ok] = np.where(keep[:, 0], np.sign(np.linalg.det(M)), 0.0)
    return out


@dataclass(frozen=True)
class FKResult:
    """Forward kinematics per sample (batch shape ``...`` of ``q_act``).

    The result of :func:`forward_kinematics`.

    Attributes
    ----------
    q : ndarray, shape (..., nq)
        The assembled configuration (MuJoCo ``qpos``; NaN where the input was not finite).
    residual : ndarray, shape (...)
        The largest closure row (m).
    converged : ndarray of bool, shape (...)
        ``residual <= CONVERGED_RTOL * L``.
    iterations : ndarray of int, shape (...)
        The Levenberg-Marquardt iterations used.
    mode_changed : ndarray of bool, shape (...)
        The solution is on another assembly mode than the start (the guess, or the previous
        continuation stage): the passive block of the constraint Jacobian, written in the start's
        singular vectors, changed the sign of its determinant (``assembly_mode_sign``), so the
        solver crossed a type II singularity.  ``converged`` is False there.
    """

    q: np.ndarray
    residual: np.ndarray
    converged: np.ndarray
    iterations: np.ndarray
    mode_changed: np.ndarray


@dataclass(frozen=True)
class IKResult:
    """Inverse kinematics per sample (batch shape ``...`` of ``T_target``).

    The result of :func:`inverse_kinematics`.

    Attributes
    ----------
    q : ndarray, shape (..., nq)
        The configuration found (MuJoCo ``qpos``).
    q_act : ndarray, shape (..., n_act)
        Its actuated joints' entries, in actuator order (rad or m).
    residual : ndarray, shape (...)
        The largest closure row (m).
    pose_error : ndarray, shape (...)
        The weighted site pose error left (rotation times L, m).
    converged : ndarray of bool, shape (...)
        ``residual`` and ``pose_error`` both below ``CONVERGED_RTOL * L``.
    iterations : ndarray of int, shape (...)
        The Levenberg-Marquardt iterations used.
    """

    q: np.ndarray
    q_act: np.ndarray
    residual: np.ndarray
    pose_error: np.ndarray
    converged: np.ndarray
    iterations: np.ndarray


def _guess(mech: Mechanism, guess: ArrayLike | None, batch: tuple[int, ...]) -> np.ndarray:
    if guess is None:
        return np.broadcast_to(mech.q0, (*batch, mech.nq))  # the assembled reference
    return check_q(mech, guess, "guess", nan_rows=True)  # a failed sample's q: that sample is masked


def floating_base_dofs(mech: Mechanism) -> np.ndarray:
    """Velocity coordinates of the free joints that float a whole sub-mechanism (no closure ties their
    body's subtree to anything outside it): moving them moves the closures rigidly, so assembly holds
    them at the guess (a free joint closed by connects, a Delta's platform, is a passive coordinate)."""
    tree = mech.tree
    out: list[int] = []
    for k in range(len(tree.jnt_names)):
        if tree.jnt_type[k] != 3:
            continue
        d0 = int(tree.jnt_dadr[k])
        sub = {tree.body_names[b] for b in range(len(tree.body_names)) if tree.A[b, d0]}
        if all((c.body1 in sub) == (c.body2 in sub) for c in mech.closures):
            out.extend(range(d0, d0 + 6))
    return np.array(out, dtype=int)


def forward_kinematics(
    mech: Mechanism, q_act: ArrayLike, guess: ArrayLike | None = None, *, steps: int = 1
) -> FKResult:
    """Assemble the mechanism at the actuated coordinates ``q_act (..., n_act)`` (actuator order).

    The passive coordinates start from ``guess (..., nq)`` (default the reference configuration
    ``mech.q0``) and the solution is the assembly branch connected to it.  ``steps > 1`` moves the
    inputs from the guess's values to ``q_act`` in that many equal stages (continuation), which
    keeps the branch over large moves; along a trajectory pass the previous solution as the guess.
    Non-finite ``q_act`` (and magnitudes above 1e100), a NaN row of ``guess`` (a failed sample of an
    earlier call) and a solution on another assembly mode than the start (``mode_changed``) give
    ``converged = False`` for that sample only (NaN ``q`` for the first two).  A free joint that
    floats a whole sub-mechanism (a floating-base robot) is a coordinate like the actuated ones: held
    at the guess, never moved by the assembly.  Without actuators, ``q_act`` has shape ``(..., 0)`` and
    the passive chain is assembled from the guess.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism (:func:`from_mjcf` or :class:`Builder`).
    q_act : array_like, shape (..., n_act)
        Actuated joints' coordinates in actuator order (rad for hinges, m for slides).
    guess : array_like, shape (..., nq), optional
        Start of the passive coordinates (default ``mech.q0``); broadcasts with ``q_act``.
    steps : int, optional
        Continuation stages from the guess's inputs to ``q_act`` (``1 <= steps <= MAX_STEPS``, 10 000).

    Returns
    -------
    FKResult
        ``q (..., nq)`` (MuJoCo qpos), ``residual (...)`` (m), ``converged`` and ``iterations``.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> fk = mb.forward_kinematics(mech, np.array([[0.2], [np.nan]]))   # a bad sample is only flagged
    >>> fk.q[0].round(4), fk.converged
    (array([ 0.2   , -0.196 ,  0.0771]), array([ True, False]))
    """
    mech = check_mechanism(mech)
    tree = mech.tree
    na = len(mech.actuated)
    qa = as_array(q_act, "q_act", (na,), finite=False)
    qa = np.where(np.abs(qa) <= MAX_MAGNITUDE, qa, np.nan)  # inf, 1e300: masked like NaN
    steps = check_int(steps, "steps", low=1, high=MAX_STEPS)
    g0 = _guess(mech, guess, qa.shape[:-1])
    batch = broadcast_batch((qa, 1, "q_act"), (g0, 1, "guess"))
    n = int(np.prod(batch))  # explicit: reshape(-1, 0) is ambiguous for a mechanism without actuators
    qa_f = np.broadcast_to(qa, (*batch, na)).reshape(n, na)
    q = np.array(np.broadcast_to(g0, (*batch, mech.nq)).reshape(n, mech.nq))
    ok = np.all(np.isfinite(qa_f), axis=-1) & np.all(np.isfinite(q), axis=-1)
    q[~ok] = tree.q0
    start = q[:, tree.act_qadr].copy()
    target = np.where(ok[:, None], qa_f, start)
    free = np.setdiff1d(np.arange(tree.nv), np.concatenate([tree.act_dof, floating_base_dofs(mech)]))
    iters = np.zeros(q.shape[0], dtype=int)
    flipped = np.zeros(q.shape[0], dtype=bool)
    from ._compiled import compiled_fk  # numba loads on the first kernel call, not at import

    for s in range(1, steps + 1):
        q_prev = q.copy()
        q[:, tree.act_qadr] = start + (target - start) * (s / steps)
        q, rc, it, _ = compiled_fk(mech, q, free)  # the one implementation, any batch size
        iters += it
        flipped |= assembly_mode_sign(mech, q_prev, q) < 0
    flipped &= ok
    conv = ok & (rc <= CONVERGED_RTOL * tree.length) & ~flipped
    q = np.where(ok[:, None], q, np.nan)
    rc = np.where(ok, rc, np.nan)
    return FKResult(
        q=q.reshape(*batch, mech.nq),
        residual=rc.reshape(batch),
        converged=conv.reshape(batch),
        iterations=iters.reshape(batch),
        mode_changed=flipped.reshape(batch),
    )


def inverse_kinematics(
    mech: Mechanism,
    site: str,
    T_target: ArrayLike,
    guess: ArrayLike | None = None,
    *,
    weights: ArrayLike | None = None,
    steps: int = 1,
) -> IKResult:
    """Configuration(s) that put ``site`` at ``T_target (..., 4, 4)`` (world) with the loops closed.

    ``weights (6,)`` scale the error rows ``[rot_x, rot_y, rot_z, x, y, z]`` (rotation rows in
    length units, times the characteristic length); a zero weight leaves that component free (e.g.
    ``(0, 0, 0, 1, 1, 1)`` for a point target).  All coordinates move, from ``guess`` (default
    ``mech.q0``), in least squares; ``steps > 1`` moves the target from the guess's site pose in
    stages (continuation).  A target the mechanism cannot reach leaves ``converged = False``.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    site : str
        Name of the site to place.
    T_target : array_like, shape (..., 4, 4)
        Target world poses of the site (m).
    guess : array_like, shape (..., nq), optional
        Start configuration (default ``mech.q0``).
    weights : array_like, shape (6,), optional
        Weights of the error rows ``[rot_x, rot_y, rot_z, x, y, z]`` (>= 0; 0 leaves a component free).
    steps : int, optional
        Continuation stages (``>= 1``).

    Returns
    -------
    IKResult
        ``q (..., nq)``, ``q_act (..., n_act)``, ``residual`` (m), ``pose_error`` (m) and ``converged``.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> T = mb.site_pose(mech, mb.forward_kinematics(mech, np.array([0.2])).q, "coupler_point")
    >>> ik = mb.inverse_kinematics(mech, "coupler_point", T)
    >>> ik.q_act.round(10), bool(ik.converged)                          # the crank angle back
    (array([0.2]), True)
    """
    mech = check_mechanism(mech)
    tree = mech.tree
    if not isinstance(site, str):
        raise ValueError(f"Expected site to be a site name (str), got {type(site).__name__}.")
    tree.site_index(site)  # a ValueError naming the site if the mechanism has none of that name
    T = as_array(T_target, "T_target", (4, 4), finite="mask")  # beyond 1e100: masked like NaN
    w = np.ones(6) if weights is None else as_array(weights, "weights", (6,))
    if w.ndim != 1 or np.any(w < 0) or not np.any(w > 0):
        raise ValueError(f"Expected weights to be 6 non-negative numbers, not all zero, got {w!r}.")
    steps = check_int(steps, "steps", low=1, high=MAX_STEPS)
    g0 = _guess(mech, guess, T.shape[:-2])
    batch = broadcast_batch((T, 2, "T_target"), (g0, 1, "guess"))
    Tf = np.array(np.broadcast_to(T, (*batch, 4, 4)).reshape(-1, 4, 4))
    q = np.array(np.broadcast_to(g0, (*batch, mech.nq)).reshape(-1, mech.nq))
    ok = np.all(np.isfinite(Tf), axis=(-1, -2))
    # a target must be a rigid transform: orthonormal rotation, last row (0, 0, 0, 1)
    Rt = np.where(ok[:, None, None], Tf[:, :3, :3], np.eye(3))
    orth = np.max(np.abs(Rt.swapaxes(-1, -2) @ Rt - np.eye(3)), axis=(-1, -2))
    if np.any(ok & ((orth > 1e-6) | (np.max(np.abs(Tf[:, 3] - [0, 0, 0, 1]), axis=-1) > 1e-12))):
        raise ValueError("Expected T_target to hold rigid transforms (orthonormal R, last row 0 0 0 1).")
    from ._designs import ik_designs, single_design  # numba loads on the first kernel call

    # the compiled inverse kinematics of the design-batched drivers, on this one design
    q, conv, rc, pose_err, iters = ik_designs(
        single_design(mech, site), np.zeros(Tf.shape[0], dtype=np.int64), Tf, q, w, steps
    )
    return IKResult(
        q=q.reshape(*batch, mech.nq),
        q_act=q[:, tree.act_qadr].reshape(*batch, len(mech.actuated)),
        residual=rc.reshape(batch),
        pose_error=pose_err.reshape(batch),
        converged=conv.reshape(batch),
        iterations=iters.reshape(batch),
    )


def _interp_pose(T0: np.ndarray, T1: np.ndarray, t: float) -> np.ndarray:
    """Pose ``t`` of the way from T0 to T1 (straight line in position, geodesic in rotation)."""
    from robomech.spatial import exp_so3, log_so3

    R = T0[:, :3, :3] @ exp_so3(t * log_so3(T0[:, :3, :3].swapaxes(-1, -2) @ T1[:, :3, :3]))
    out = np.array(T1, copy=True)
    out[:, :3, :3] = R
    out[:, :3, 3] = (1 - t) * T0[:, :3, 3] + t * T1[:, :3, 3]
    return out
