"""Pareto fronts of a sweep's objectives (non-dominated sorting from pymoo)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ._study import Objective

__all__ = ["objective_matrix", "pareto_front"]


def objective_matrix(
    metrics: Mapping[str, np.ndarray], objectives: Sequence[Objective]
) -> tuple[np.ndarray, np.ndarray]:
    """``F (n, k)`` to minimise (``max`` objectives negated) and ``feasible (n,)`` (every value finite)."""
    F = np.stack(
        [(-1.0 if o.sense == "max" else 1.0) * np.asarray(metrics[o.metric], float) for o in objectives], -1
    )
    ok = np.all(np.isfinite(F), axis=-1)
    if "design_ok" in metrics:
        ok &= np.asarray(metrics["design_ok"], bool)
    return F, ok


def pareto_front(metrics: Mapping[str, np.ndarray], objectives: Sequence[Objective]) -> np.ndarray:
    """Indices (ascending) of the feasible designs no other feasible design dominates."""
    from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

    F, ok = objective_matrix(metrics, objectives)
    idx = np.flatnonzero(ok)
    if idx.size == 0:
        return idx
    front = NonDominatedSorting().do(F[idx], only_non_dominated_front=True)
    return np.sort(idx[np.asarray(front, dtype=int)])
