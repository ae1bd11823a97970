"""Pareto fronts of a sweep's objectives (non-dominated sorting from pymoo)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from robomech._validation import as_array

from ._study import Objective

__all__ = ["objective_matrix", "pareto_front"]


def objective_matrix(
    metrics: Mapping[str, np.ndarray], objectives: Sequence[Objective]
) -> tuple[np.ndarray, np.ndarray]:
    """``F (n, k)`` to minimise (``max`` objectives negated) and ``feasible (n,)`` (every value finite)."""
    if not isinstance(metrics, Mapping):
        raise ValueError(f"Expected metrics to be a mapping of metric arrays, got {type(metrics).__name__}.")
    if isinstance(objectives, str) or not isinstance(objectives, Sequence) or not objectives:
        raise ValueError(f"Expected objectives to be a non-empty sequence of Objective, got {objectives!r}.")
    cols = []
    for o in objectives:
        if not isinstance(o, Objective):
            raise ValueError(f"Expected objectives to hold Objective, got {type(o).__name__}.")
        if o.metric not in metrics:
            raise ValueError(f"Expected metrics to hold objective {o.metric!r}, got {sorted(metrics)}.")
        a = as_array(metrics[o.metric], "metrics", finite=False)
        if a.ndim != 1:
            raise ValueError(f"Expected metrics[{o.metric!r}] to have shape (n,), got {a.shape}.")
        cols.append((-1.0 if o.sense == "max" else 1.0) * a)
    if len({c.shape for c in cols}) != 1:
        raise ValueError(f"Expected metrics of equal length, got shapes {[c.shape for c in cols]}.")
    F = np.stack(cols, -1)
    ok = np.all(np.isfinite(F), axis=-1)
    if "design_ok" in metrics:
        d = np.asarray(metrics["design_ok"])
        if d.dtype != bool or d.shape != ok.shape:
            raise ValueError(
                f"Expected metrics['design_ok'] to be bool of shape {ok.shape}, got {d.dtype} {d.shape}."
            )
        ok &= d
    return F, ok


def pareto_front(metrics: Mapping[str, np.ndarray], objectives: Sequence[Objective]) -> np.ndarray:
    """Indices (ascending) of the feasible designs no other feasible design dominates.

    Non-dominated sorting by pymoo on the objectives (``max`` ones negated); a design is feasible where
    every objective value is finite and, if present, ``metrics["design_ok"]`` is True.

    Parameters
    ----------
    metrics : mapping of str to ndarray, shape (n,)
        Per-design metric arrays, e.g. :func:`open_results` of a sweep store.
    objectives : sequence of Objective
        Non-empty; each names a metric of shape ``(n,)``.

    Returns
    -------
    ndarray of int, shape (k,)
        Row indices of the Pareto-optimal designs (empty if none is feasible).

    Raises
    ------
    ValueError
        If ``metrics`` is not a mapping, ``objectives`` is not a non-empty sequence of Objective, an
        objective's metric is missing or not of shape ``(n,)``, the lengths differ, or ``design_ok``
        is not bool of shape ``(n,)``.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.explore import Objective, pareto_front
    >>> m = {"a": np.array([1.0, 2.0, 3.0]), "b": np.array([1.0, 2.0, 0.0])}
    >>> pareto_front(m, [Objective("a", "min"), Objective("b", "min")])
    array([0, 2])
    """
    from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

    F, ok = objective_matrix(metrics, objectives)
    idx = np.flatnonzero(ok)
    if idx.size == 0:
        return idx
    front = NonDominatedSorting().do(F[idx], only_non_dominated_front=True)
    return np.sort(idx[np.asarray(front, dtype=int)])
