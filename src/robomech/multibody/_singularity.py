"""Singularity classification (Gosselin–Angeles, with Zlatanov's constraint singularities) and maps.

Everything is measured in metres: rotation rows and hinge columns are multiplied by the
characteristic length ``L`` (``mech.length``, or ``length=``), so that the matrices mix no units and
their singular values are lengths (per unit of scaled rate).  At an assembled ``q``:

* **type I** (serial, input): the output site can no longer move in some direction while the inputs
  still can — the input–output Jacobian ``J = J_site G`` loses rank.  Measure ``sigma_I`` = the
  ``dof``-th singular value of the scaled ``J``.
* **type II** (parallel, output): with every input locked the output can still move — the passive
  block ``K_p`` loses rank beyond its idle motions.  Measure ``sigma_II`` = the
  ``(n_passive - n_idle)``-th singular value of the scaled ``K_p`` (``G`` blows up like 1/sigma_II).
* **constraint**: the closure itself degenerates (the mechanism gains a motion) — ``K`` loses rank
  below its rank at the generic reference configuration.  Measure ``sigma_C`` = the
  ``rank_ref``-th singular value of the scaled ``K``.

The reference counts (``dof``, ``n_idle``, ``rank_ref``) come from :func:`mobility` at a generic
configuration (default ``mech.q0``; pass ``reference=`` if that one is singular).  A sample is
singular of a type when its measure over the largest singular value of the same matrix (or over
``L`` if that is larger: a one-input Jacobian has a single singular value) is below ``rtol``
(default :data:`robomech.analysis.workspace.SINGULAR_RTOL`, 1e-8); ``cond_*`` are those ratios'
inverses (condition numbers, dimensionless).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from robomech._validation import as_array, check_int, check_positive, check_real
from robomech.analysis import workspace

from ._assembly import (
    MAX_STEPS,
    FKResult,
    IKResult,
    check_mechanism,
    check_q,
    forward_kinematics,
    inverse_kinematics,
    on_rows,
)
from ._influence import _influence_flat
from ._mobility import mobility
from ._model import Mechanism
from ._tree import frame_jacobian

__all__ = ["SingularityMapResult", "SingularityResult", "singularities", "singularity_map"]


@dataclass(frozen=True)
class SingularityResult:
    """Per-sample measures (batch shape of ``q``); lengths in metres, conditions dimensionless.

    The result of :func:`singularities`.  Rotations and hinge columns are scaled by the characteristic
    length L so that every singular value is a length; each condition number is the largest singular
    value (or L if larger) over the relevant one, and a type is flagged when it exceeds ``1 / rtol``.

    Attributes
    ----------
    sigma_I : ndarray, shape (...)
        The ``dof``-th singular value of the scaled input-output Jacobian of the site (m): zero at a
        type I (serial, output) singularity.
    sigma_II : ndarray, shape (...)
        The relevant smallest singular value of the passive constraint block (m): zero at a type II
        (parallel, input) singularity.
    sigma_C : ndarray, shape (...)
        The ``rank``-th singular value of the whole constraint Jacobian (m): zero at a constraint
        singularity.
    cond_I, cond_II, cond_C : ndarray, shape (...)
        The corresponding condition numbers (inf where the singular value is zero).
    type_I, type_II, constraint : ndarray of bool, shape (...)
        ``cond_I``, ``cond_II``, ``cond_C`` above ``1 / rtol``.
    singular : ndarray of bool, shape (...)
        Any of the three.
    length : float
        The characteristic length used (m).
    """

    sigma_I: np.ndarray
    sigma_II: np.ndarray
    sigma_C: np.ndarray
    cond_I: np.ndarray
    cond_II: np.ndarray
    cond_C: np.ndarray
    type_I: np.ndarray
    type_II: np.ndarray
    constraint: np.ndarray
    singular: np.ndarray  # any of the three
    length: float  # the characteristic length used (m)


def _kth(s: np.ndarray, k: int) -> np.ndarray:
    """k-th largest singular value (1-based) per sample, 0 where there are fewer than k."""
    if k <= 0:
        return np.full(s.shape[0], np.inf)
    return s[:, k - 1] if s.shape[1] >= k else np.zeros(s.shape[0])


def singularities(
    mech: Mechanism,
    q: ArrayLike,
    site: str,
    *,
    reference: ArrayLike | None = None,
    length: float | None = None,
    rtol: float = workspace.SINGULAR_RTOL,
) -> SingularityResult:
    """Type I / type II / constraint singularity measures of ``site`` at assembled ``q (..., nq)``.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (..., nq)
        Assembled configurations.
    site : str
        The output site.
    reference : array_like, shape (nq,), optional
        Configuration for the characteristic length (default ``mech.q0``).
    length : float, optional
        Characteristic length L (m) that scales rotations and hinge columns (default ``mech.length``).
    rtol : float, optional
        Relative threshold of a singular value below which a type counts as singular.

    Returns
    -------
    SingularityResult
        Per sample: ``sigma_I``, ``sigma_II``, ``sigma_C`` (m), ``cond_*``, the flags ``type_I``,
        ``type_II``, ``constraint``, ``singular`` and the ``length`` used (m).

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> s = mb.singularities(mech, mb.forward_kinematics(mech, np.array([0.2])).q, "coupler_point")
    >>> bool(s.singular), round(float(s.length), 4)            # a regular pose; L in m
    (False, 0.4753)
    """
    mech = check_mechanism(mech)
    tree = mech.tree
    if not isinstance(site, str):
        raise ValueError(f"Expected site to be a site name (str), got {type(site).__name__}.")
    si = tree.site_index(site)
    q = check_q(mech, q, nan_rows=True)  # NaN samples (failed FK samples): NaN measures, flags False
    L = tree.length if length is None else check_positive(length, "length")
    rtol = check_real(rtol, "rtol", low=0.0, high=1.0, low_open=True, high_open=True)
    if reference is not None:
        reference = check_q(mech, reference, "reference")
        if reference.ndim != 1:
            raise ValueError(f"Expected reference to have shape ({mech.nq},), got {reference.shape}.")
    ref = mobility(mech, reference)
    batch = q.shape[:-1]

    def run(qf: np.ndarray) -> tuple:
        state, K, G, _, _, _ = _influence_flat(mech, qf, False)
        col = np.where(tree.dof_translational, 1.0, L)  # hinge columns times L -> metres
        rows = np.array([L, L, L, 1.0, 1.0, 1.0])
        act = tree.act_dof
        pas = np.setdiff1d(np.arange(tree.nv), act)
        Ks = K * col  # K rows are already lengths
        sK = np.linalg.svd(Ks, compute_uv=False) if Ks.shape[1] and Ks.shape[2] else np.zeros((len(qf), 0))
        sP = (
            np.linalg.svd(Ks[..., pas], compute_uv=False)
            if Ks.shape[1] and len(pas)
            else np.zeros((len(qf), 0))
        )
        b = tree.site_body[si]
        p = (state.T[:, b] @ tree.T_site[si])[:, :3, 3]
        Jf = frame_jacobian(tree, state, b, p)
        # input-output Jacobian per scaled input rate: G maps unscaled rates; hinge inputs are per rad
        J = rows[:, None] * (Jf @ G) / col[act]
        sJ = np.linalg.svd(J, compute_uv=False) if len(act) else np.zeros((len(qf), 0))
        idle_locked = ref.locked_dof  # motions of a generic configuration with every input locked
        sigma_I = _kth(sJ, ref.dof)
        sigma_II = _kth(sP, len(pas) - idle_locked)
        sigma_C = _kth(sK, ref.rank)

        def cond(sig: np.ndarray, smax: np.ndarray) -> np.ndarray:
            # reference: the largest singular value, or L if larger (a one-input J has a single value)
            ok = sig > 0
            return np.where(ok, np.maximum(smax, L) / np.where(ok, sig, 1.0), np.inf)

        cI = cond(sigma_I, sJ[:, 0] if sJ.shape[1] else np.ones(len(qf)))
        cII = cond(sigma_II, sP[:, 0] if sP.shape[1] else np.ones(len(qf)))
        cC = cond(sigma_C, sK[:, 0] if sK.shape[1] else np.ones(len(qf)))
        return sigma_I, sigma_II, sigma_C, cI, cII, cC

    _, (sigma_I, sigma_II, sigma_C, cI, cII, cC) = on_rows(mech, q.reshape(-1, mech.nq), run)
    tI, tII, tC = cI > 1 / rtol, cII > 1 / rtol, cC > 1 / rtol

    def sh(x: np.ndarray) -> np.ndarray:
        return x.reshape(batch)

    return SingularityResult(
        sigma_I=sh(sigma_I),
        sigma_II=sh(sigma_II),
        sigma_C=sh(sigma_C),
        cond_I=sh(cI),
        cond_II=sh(cII),
        cond_C=sh(cC),
        type_I=sh(tI),
        type_II=sh(tII),
        constraint=sh(tC),
        singular=sh(tI | tII | tC),
        length=L,
    )


@dataclass(frozen=True)
class SingularityMapResult:
    """Maps over a grid (batch shape of the grid): assembly, singularity types and dexterity.

    ``reachable`` = the sample assembled (FK) or the target was reached (IK); every other field is
    NaN / False where it is false.  ``dexterity`` and ``cond`` are those of
    :func:`robomech.analysis.workspace.singularity_map` on the unit-scaled input–output Jacobian.

    Attributes
    ----------
    q : ndarray, shape (..., nq)
        Assembled configurations (MuJoCo ``qpos``); NaN where not reachable.
    reachable : ndarray of bool, shape (...)
        The closure assembled (FK grid) or the site target was reached (IK grid).
    singularity : SingularityResult
        :func:`singularities` at ``q`` (the same batch shape; NaN / False where not reachable).
    cond : ndarray, shape (...)
        Condition number of the unit-scaled input-output Jacobian.
    dexterity : ndarray, shape (...)
        ``1 / cond`` in ``[0, 1]``.
    singular : ndarray of bool, shape (...)
        The scaled Jacobian is singular (``workspace.singularity_map``) or ``singularity.singular``;
        False where not reachable.
    """

    q: np.ndarray
    reachable: np.ndarray
    singularity: SingularityResult
    cond: np.ndarray
    dexterity: np.ndarray
    singular: np.ndarray


def singularity_map(
    mech: Mechanism,
    site: str,
    *,
    q_act: ArrayLike | None = None,
    T: ArrayLike | None = None,
    guess: ArrayLike | None = None,
    steps: int = 4,
    ik_weights: ArrayLike | None = None,
    length: float | None = None,
) -> SingularityMapResult:
    """Workspace / dexterity / singularity maps over a grid of inputs ``q_act (..., n_act)`` (FK) or
    of site targets ``T (..., 4, 4)`` (IK), e.g. from :func:`robomech.analysis.workspace.grid`.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    site : str
        The output site.
    q_act : array_like, shape (..., n_act), optional
        A grid of inputs (FK); exactly one of ``q_act`` and ``T``.
    T : array_like, shape (..., 4, 4), optional
        A grid of site targets (IK).
    guess : array_like, shape (..., nq), optional
        Start configuration of the solves.
    steps : int, optional
        Continuation stages of each solve.
    ik_weights : array_like, shape (6,), optional
        Error-row weights of the IK solves (:func:`inverse_kinematics`).
    length : float, optional
        Characteristic length (m).

    Returns
    -------
    SingularityMapResult
        ``q``, ``reachable``, ``singularity`` (:class:`SingularityResult`), ``cond``, ``dexterity`` and
        ``singular`` over the grid's batch shape.

    Examples
    --------
    >>> from robomech import multibody as mb
    >>> from robomech.analysis import workspace
    >>> mech = mb.gallery.load("four_bar")
    >>> smap = mb.singularity_map(mech, "coupler_point", q_act=workspace.grid([(-0.5, 0.5)], 5))
    >>> smap.reachable.shape, bool(smap.reachable.all())
    ((5,), True)
    """
    mech = check_mechanism(mech)
    if not isinstance(site, str):
        raise ValueError(f"Expected site to be a site name (str), got {type(site).__name__}.")
    mech.tree.site_index(site)
    steps = check_int(steps, "steps", low=1, high=MAX_STEPS)
    if length is not None:
        check_positive(length, "length")
    if (q_act is None) == (T is None):
        raise ValueError("Expected exactly one of q_act (input grid) or T (output grid).")
    r: FKResult | IKResult
    if q_act is not None:
        qa = as_array(q_act, "q_act", (len(mech.actuated),), finite="mask")  # beyond 1e100: masked like NaN
        r = forward_kinematics(mech, qa, guess, steps=steps)
    else:
        assert T is not None  # exactly one of q_act and T (checked above)
        r = inverse_kinematics(mech, site, T, guess, weights=ik_weights, steps=steps)
    ok = r.converged
    q = np.where(ok[..., None], r.q, mech.tree.q0)
    s = singularities(mech, q, site, length=length)
    tree = mech.tree
    L = s.length
    qf = q.reshape(-1, mech.nq)
    state, _, G, _, _, _ = _influence_flat(mech, qf, False)
    si = tree.site_index(site)
    b = tree.site_body[si]
    p = (state.T[:, b] @ tree.T_site[si])[:, :3, 3]
    col = np.where(tree.dof_translational, 1.0, L)
    J = np.array([L, L, L, 1, 1, 1])[:, None] * (frame_jacobian(tree, state, b, p) @ G) / col[tree.act_dof]
    # keep the rows the output actually uses (rank of the reference), so that a 3-DOF site is not
    # judged singular for the 3 directions it never moves in
    U = np.linalg.svd(J, full_matrices=False)[0]
    J = np.einsum("nij,nik->njk", U, J)[:, : max(1, mobility(mech).dof)]
    wm = workspace.singularity_map(J)
    nan = np.nan

    def mask(x: np.ndarray, fill: float | bool) -> np.ndarray:
        return np.where(ok.reshape(-1), x.reshape(-1), fill).reshape(ok.shape)

    sing = SingularityResult(
        **{
            f: (mask(getattr(s, f), nan) if f.startswith(("sigma", "cond")) else mask(getattr(s, f), False))
            for f in (
                "sigma_I",
                "sigma_II",
                "sigma_C",
                "cond_I",
                "cond_II",
                "cond_C",
                "type_I",
                "type_II",
                "constraint",
                "singular",
            )
        },
        length=L,
    )
    return SingularityMapResult(
        q=np.where(ok[..., None], r.q, nan),
        reachable=ok,
        singularity=sing,
        cond=mask(wm.cond, nan),
        dexterity=mask(wm.dexterity, nan),
        singular=mask(wm.singular | s.singular.reshape(-1), False),
    )
