"""Workspace, singularity and dexterity maps from batched Jacobians.

These work on any Jacobian stack ``J (..., m, n)``: a mechanism module evaluates its Jacobian on a grid
(:func:`grid`) and these functions turn it into maps.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robomech._validation import as_array, check_int, check_real, finite_samples

__all__ = ["SingularityMap", "condition_number", "grid", "singularity_map"]

# A configuration counts as singular when sigma_min / sigma_max falls below this: at 1e-8 a unit
# error in the inputs maps to 1e8 in the outputs, beyond any physical meaning for these mechanisms.
SINGULAR_RTOL = 1e-8


def grid(ranges: Sequence[tuple[float, float]], n: int | Sequence[int]) -> np.ndarray:
    """Regular grid over ``ranges`` ((lo, hi) per coordinate): ``(n_1, ..., n_d, d)``."""
    r = as_array(ranges, "ranges", (2,))
    if r.ndim != 2 or r.shape[0] == 0:
        raise ValueError(f"Expected ranges to have shape (d, 2) with d >= 1 (lo, hi) pairs, got {r.shape}.")
    if np.any(r[:, 1] <= r[:, 0]):
        raise ValueError(f"Expected ranges with lo < hi in every pair, got {r.tolist()}.")
    if isinstance(n, list | tuple | np.ndarray):
        if len(n) != len(r):
            raise ValueError(f"Expected n to give one count per coordinate ({len(r)}), got {n!r}.")
        counts = [check_int(c, "n", low=2) for c in n]
    else:
        counts = [check_int(n, "n", low=2)] * len(r)
    ranges = r.tolist()
    axes = [np.linspace(lo, hi, c) for (lo, hi), c in zip(ranges, counts, strict=True)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)


def condition_number(J: object) -> np.ndarray:
    """2-norm condition number ``sigma_max / sigma_min`` of each Jacobian (inf where singular).

    A Jacobian with a non-finite entry gets NaN and is kept away from LAPACK (whose SVD raises for
    the whole batch on one NaN)."""
    J = as_array(J, "J", (None, None), finite=False)
    s, finite = _singular_values(J)
    smin = s[..., -1]
    cond = np.where(smin > 0, s[..., 0] / np.where(smin > 0, smin, 1.0), np.inf)
    return np.where(finite, cond, np.nan)


def _singular_values(J: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Singular values of each finite Jacobian (scaled to unit size so 1e200 entries do not overflow),
    zeros for a non-finite one; and the finiteness mask."""
    finite = finite_samples(J, 2)
    Js = np.where(finite[..., None, None], J, 0.0)
    size = np.max(np.abs(Js), axis=(-2, -1), initial=0.0)
    size = np.where(size > 0, size, 1.0)
    s = np.linalg.svd(Js / size[..., None, None], compute_uv=False) * size[..., None]
    return s, finite


@dataclass(frozen=True)
class SingularityMap:
    cond: np.ndarray  # (...,) condition number
    dexterity: np.ndarray  # (...,) 1 / cond in [0, 1]
    singular: np.ndarray  # (...,) bool, cond > 1 / SINGULAR_RTOL
    sigma_min: np.ndarray  # (...,) smallest singular value (in the Jacobian's units)


def singularity_map(J: object, *, rtol: float = SINGULAR_RTOL) -> SingularityMap:
    """Condition, dexterity and a singular mask for each Jacobian; non-finite Jacobians count as singular."""
    J = as_array(J, "J", (None, None), finite=False)
    rtol = check_real(rtol, "rtol", low=0.0, high=1.0, low_open=True)
    s, finite = _singular_values(J)
    smax, smin = s[..., 0], s[..., -1]
    ratio = np.where(smax > 0, smin / np.where(smax > 0, smax, 1.0), 0.0)
    ratio = np.where(finite, ratio, 0.0)
    cond = np.where(ratio > 0, 1.0 / np.where(ratio > 0, ratio, 1.0), np.inf)
    return SingularityMap(
        cond=cond, dexterity=ratio, singular=ratio < rtol, sigma_min=np.where(finite, smin, np.nan)
    )
