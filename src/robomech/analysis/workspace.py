"""Workspace, singularity and dexterity maps from batched Jacobians.

These work on any Jacobian stack ``J (..., m, n)``: a mechanism module evaluates its Jacobian on a grid
(:func:`grid`) and these functions turn it into maps.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robomech._validation import as_array

__all__ = ["SingularityMap", "condition_number", "grid", "singularity_map"]

# A configuration counts as singular when sigma_min / sigma_max falls below this: at 1e-8 a unit
# error in the inputs maps to 1e8 in the outputs, beyond any physical meaning for these mechanisms.
SINGULAR_RTOL = 1e-8


def grid(ranges: Sequence[tuple[float, float]], n: int | Sequence[int]) -> np.ndarray:
    """Regular grid over ``ranges`` ((lo, hi) per coordinate): ``(n_1, ..., n_d, d)``."""
    if len(ranges) == 0:
        raise ValueError("Expected ranges to hold at least one (lo, hi) pair, got none.")
    counts = [n] * len(ranges) if isinstance(n, int) else list(n)
    if len(counts) != len(ranges) or any(c < 2 for c in counts):
        raise ValueError(f"Expected n >= 2 per coordinate ({len(ranges)} coordinates), got {n!r}.")
    axes = [np.linspace(lo, hi, c) for (lo, hi), c in zip(ranges, counts, strict=True)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)


def condition_number(J: object) -> np.ndarray:
    """2-norm condition number ``sigma_max / sigma_min`` of each Jacobian (inf where singular)."""
    J = as_array(J, "J", (None, None), finite=False)
    s = np.linalg.svd(J, compute_uv=False)
    smin = s[..., -1]
    return np.where(smin > 0, s[..., 0] / np.where(smin > 0, smin, 1.0), np.inf)


@dataclass(frozen=True)
class SingularityMap:
    cond: np.ndarray  # (...,) condition number
    dexterity: np.ndarray  # (...,) 1 / cond in [0, 1]
    singular: np.ndarray  # (...,) bool, cond > 1 / SINGULAR_RTOL
    sigma_min: np.ndarray  # (...,) smallest singular value (in the Jacobian's units)


def singularity_map(J: object, *, rtol: float = SINGULAR_RTOL) -> SingularityMap:
    """Condition, dexterity and a singular mask for each Jacobian; non-finite Jacobians count as singular."""
    J = as_array(J, "J", (None, None), finite=False)
    finite = np.all(np.isfinite(J), axis=(-1, -2))
    s = np.linalg.svd(np.where(finite[..., None, None], J, 0.0), compute_uv=False)
    smax, smin = s[..., 0], s[..., -1]
    ratio = np.where(smax > 0, smin / np.where(smax > 0, smax, 1.0), 0.0)
    ratio = np.where(finite, ratio, 0.0)
    cond = np.where(ratio > 0, 1.0 / np.where(ratio > 0, ratio, 1.0), np.inf)
    return SingularityMap(
        cond=cond, dexterity=ratio, singular=ratio < rtol, sigma_min=np.where(finite, smin, np.nan)
    )
