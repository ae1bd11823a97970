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

from robomech._batching import failed_rows, on_rows
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
)
from ._compile import compile_model
from ._mobility import mobility
from ._model import Mechanism

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
    closure : ndarray, shape (...)
        Largest closure row of the input ``q`` (m).
    assembled : ndarray of bool, shape (...)
        ``closure <= CLOSURE_RTOL * L``: where False, ``q`` is off the closure manifold and the
        classification has no meaning.
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
    closure: np.ndarray
    assembled: np.ndarray
    length: float  # the characteristic length used (m)


def _kth(s: np.ndarray, k: int) -> np.ndarray | None:
    """k-th largest singular value (1-based) per sample, 0 where there are fewer than k; None for k <= 0
    (no direction that could be lost: the measure of the best-conditioned matrix, see ``cond``)."""
    if k <= 0:
        return None
    return s[:, k - 1] if s.shape[1] >= k else np.zeros(s.shape[0])


# Rows of the site Jacobian [ω; ṗ] selected by ``output``.
OUTPUTS = {"pose": (0, 1, 2, 3, 4, 5), "orientation": (0, 1, 2), "position": (3, 4, 5)}
# Configurations near the reference at which the output's generic rank is taken (the largest rank
# found): the reference itself may be singular (a straight arm), a random neighbour is not.
GENERIC_SAMPLES = 4
# Amplitude (rad for hinges, L for slides) of the random input offsets of those neighbours.
GENERIC_AMPLITUDE = 0.3


def _rows(output: object) -> tuple[int, ...]:
    if isinstance(output, str):
        if output not in OUTPUTS:
            raise ValueError(f"Expected output in {sorted(OUTPUTS)} or row indices 0..5, got {output!r}.")
        return OUTPUTS[output]
    try:
        rows = tuple(int(r) for r in output)  # type: ignore[attr-defined]
        exact = all(float(r) == int(r) and not isinstance(r, bool) for r in output)  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        raise ValueError(
            f"Expected output to be a name or a sequence of row indices 0..5, got {output!r}."
        ) from None
    if not rows or not exact or len(set(rows)) != len(rows) or min(rows) < 0 or max(rows) > 5:
        raise ValueError(f"Expected output to be distinct row indices 0..5 of [ω; ṗ], got {output!r}.")
    return rows


def _singular_values(mech: Mechanism, qf: np.ndarray, si: int, L: float, rows: tuple[int, ...]) -> tuple:
    """(largest closure row (N,), singular values of the scaled K, K_p and site Jacobian's ``rows``),
    each largest first (``_compiled.singular_block``)."""
    from ._compiled import compiled_singular_values  # numba loads on the first kernel call

    return compiled_singular_values(compile_model(mech), qf, si, L, rows)


def _reference_mobility(mech: Mechanism, ref_q: np.ndarray | None):
    """``mobility(mech, ref_q)``, cached per mechanism and reference (a frozen result)."""
    cache = compile_model(mech).cache.setdefault("_sing_mobility", {})
    key = None if ref_q is None else ref_q.tobytes()
    if key not in cache:
        cache[key] = mobility(mech, ref_q)
    return cache[key]


def _generic_output_rank(
    mech: Mechanism, si: int, L: float, rows: tuple[int, ...], ref_q, rtol: float
) -> int:
    """Rank of the scaled input-output Jacobian's ``rows`` at a generic configuration: the largest over the
    reference and GENERIC_SAMPLES assembled neighbours (fixed seed), cached per mechanism."""
    key = ("_sing_generic_rank", si, float(L), rows, None if ref_q is None else ref_q.tobytes(), float(rtol))
    cache = compile_model(mech).cache.setdefault("_sing_generic_rank", {})
    if key in cache:
        return cache[key]
    tree = mech.tree
    q_ref = mech.q0 if ref_q is None else ref_q
    na = len(tree.act_dof)
    qs = [q_ref[None]]
    if na:
        rng = np.random.default_rng(0)
        amp = np.where(tree.dof_translational[tree.act_dof], L, 1.0) * GENERIC_AMPLITUDE
        qa = q_ref[tree.act_qadr] + amp * rng.uniform(-1.0, 1.0, (GENERIC_SAMPLES, na))
        fk = forward_kinematics(mech, qa, q_ref)
        if np.any(fk.converged):
            qs.append(fk.q[fk.converged])
    s = _singular_values(mech, np.concatenate(qs), si, L, rows)[3]
    r = 0
    if s.shape[-1]:
        r = int(np.max(np.sum(s > rtol * np.maximum(s[:, :1], L), axis=-1)))
    cache[key] = r
    return r


def singularities(
    mech: Mechanism,
    q: ArrayLike,
    site: str,
    *,
    output: str | tuple[int, ...] = "pose",
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
    output : str or sequence of int, optional
        Which of the site's motions is the output of the type I test: ``"pose"`` (default, all six
        rows ``[ω; ṗ]``), ``"position"`` (the point's velocity, rows 3-5), ``"orientation"`` (rows
        0-2), or distinct row indices 0..5.  Type I is a drop of the selected rows' rank below their
        generic rank (taken at the reference and a few assembled neighbours).
    reference : array_like, shape (nq,), optional
        A generic configuration for the reference counts (default ``mech.q0``).
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
    out_rows = _rows(output)
    ref = _reference_mobility(mech, reference)
    batch = q.shape[:-1]

    def run(qf: np.ndarray) -> tuple:
        # K rows are already lengths; the input-output Jacobian is per scaled input rate
        closure, sK, sP, sJ = _singular_values(mech, qf, si, L, out_rows)
        n_pas = tree.nv - len(tree.act_dof)
        idle_locked = ref.locked_dof  # motions of a generic configuration with every input locked
        # the output can lose no more directions than it has at a generic configuration (a floating robot's
        # trunk site does not move with the legs; a point output has at most 3)
        k_out = min(ref.dof, _generic_output_rank(mech, si, L, out_rows, reference, rtol))
        sigma_I = _kth(sJ, k_out)
        sigma_II = _kth(sP, n_pas - idle_locked)
        sigma_C = _kth(sK, ref.rank)

        def cond(sig: np.ndarray | None, smax: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            # reference: the largest singular value, or L if larger (a one-input J has a single value);
            # nothing to lose (k <= 0: an open chain's empty passive block): sigma L, cond 1
            if sig is None:
                return np.full(len(qf), L), np.ones(len(qf))
            ok = sig > 0
            return sig, np.where(ok, np.maximum(smax, L) / np.where(ok, sig, 1.0), np.inf)

        sigma_I, cI = cond(sigma_I, sJ[:, 0] if sJ.shape[1] else np.ones(len(qf)))
        sigma_II, cII = cond(sigma_II, sP[:, 0] if sP.shape[1] else np.ones(len(qf)))
        sigma_C, cC = cond(sigma_C, sK[:, 0] if sK.shape[1] else np.ones(len(qf)))
        return sigma_I, sigma_II, sigma_C, cI, cII, cC, closure

    from ._dynamics import CLOSURE_RTOL

    qf = q.reshape(-1, mech.nq)
    sigma_I, sigma_II, sigma_C, cI, cII, cC, closure = on_rows(
        failed_rows(qf), run, qf, probe=(mech.tree.q0[None],)
    )
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
        closure=sh(closure),
        assembled=sh(closure <= CLOSURE_RTOL * L),
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
    output: str | tuple[int, ...] = "pose",
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
    output : str or sequence of int, optional
        The output of the type I test, as in :func:`singularities` (default ``"pose"``).

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
    _rows(output)  # checked before any solve
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
    s = singularities(mech, q, site, output=output, length=length)
    tree = mech.tree
    L = s.length
    qf = q.reshape(-1, mech.nq)
    from ._compiled import compiled_site_jacobian  # numba loads on the first kernel call

    si = tree.site_index(site)
    col = np.where(tree.dof_translational, 1.0, L)
    J = np.array([L, L, L, 1, 1, 1])[:, None] * compiled_site_jacobian(mech, qf, si) / col[tree.act_dof]
    # keep the rows the output actually uses (rank of the reference), so that a 3-DOF site is not
    # judged singular for the 3 directions it never moves in
    U = np.linalg.svd(J, full_matrices=False)[0]
    J = np.einsum("nij,nik->njk", U, J)[:, : max(1, _reference_mobility(mech, None).dof)]
    wm = workspace.singularity_map(J)
    nan = np.nan

    def mask(x: np.ndarray, fill: float | bool) -> np.ndarray:
        return np.where(ok.reshape(-1), x.reshape(-1), fill).reshape(ok.shape)

    sing = SingularityResult(
        **{
            f: (
                mask(getattr(s, f), nan)
                if f.startswith(("sigma", "cond", "closure"))
                else mask(getattr(s, f), False)
            )
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
                "closure",
                "assembled",
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
