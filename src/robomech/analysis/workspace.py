"""Workspace, singularity and dexterity maps from batched Jacobians.

These work on any Jacobian stack ``J (..., m, n)``: a mechanism module evaluates its Jacobian on a grid
(:func:`grid`) and these functions turn it into maps.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robomech._validation import as_array, check_int, check_real, finite_samples

__all__ = ["SingularityMap", "condition_number", "grid", "singularity_map"]

# A configuration counts as singular when sigma_min / sigma_max falls below this: at 1e-8 a unit
# error in the inputs maps to 1e8 in the outputs, beyond any physical meaning for these mechanisms.
SINGULAR_RTOL = 1e-8


def grid(ranges: ArrayLike, n: int | Sequence[int]) -> NDArray[np.float64]:
    """Regular grid over ``ranges`` ((lo, hi) per coordinate): ``(n_1, ..., n_d, d)``.

    Parameters
    ----------
    ranges : array_like, shape (d, 2)
        ``(lo, hi)`` per coordinate, ``lo < hi``, in the coordinate's unit (m, rad).
    n : int or sequence of int
        Points per coordinate (``>= 2``, end points included): one count for all or one per coordinate.

    Returns
    -------
    ndarray, shape (n_1, ..., n_d, d)
        The grid points, ``indexing="ij"`` (the first coordinate varies along the first axis); ready
        to be passed as a batch to any model.

    Examples
    --------
    >>> g = grid([(0.0, 1.0), (-1.0, 1.0)], (2, 3))
    >>> g.shape
    (2, 3, 2)
    >>> g[1, 2]                    # last point of both coordinates
    array([1., 1.])
    """
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
    axes = [np.linspace(lo, hi, c) for (lo, hi), c in zip(r, counts, strict=True)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)


def condition_number(J: ArrayLike) -> NDArray[np.float64]:
    """2-norm condition number ``sigma_max / sigma_min`` of each Jacobian (inf where singular).

    ``J`` must be finite: a bare number per sample has no mask to flag a non-finite Jacobian with.
    For a batch that may hold failed samples (NaN Jacobians of unreachable poses) use
    :func:`singularity_map`, whose ``singular`` mask is True there and whose ``cond`` is inf.

    Parameters
    ----------
    J : array_like, shape (..., m, n)
        Jacobians (any frame: the condition number does not depend on it, but it does depend on the
        units of mixed rows, e.g. rad/s and m/s rows of a twist Jacobian).

    Returns
    -------
    ndarray, shape (...)
        ``sigma_max / sigma_min`` (>= 1), ``inf`` where ``sigma_min = 0``.  An exactly singular
        matrix usually gives a large finite value (~1e16) from rounding: use :func:`singularity_map`
        for a singular mask.

    Raises
    ------
    ValueError
        If ``J`` is not a real array of shape (..., m, n) with m, n >= 1, or has a non-finite entry or
        one beyond ``MAX_MAGNITUDE``.

    Examples
    --------
    >>> import numpy as np
    >>> J = np.array([[[2.0, 0.0], [0.0, 1.0]], [[1.0, 0.0], [0.0, 1e-3]]])
    >>> condition_number(J)
    array([   2., 1000.])
    """
    J = as_array(J, "J", (None, None), nonempty=True)
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
    """Per-Jacobian singularity measures (the result of :func:`singularity_map`).

    Attributes
    ----------
    cond : ndarray, shape (...)
        2-norm condition number ``sigma_max / sigma_min`` (inf where singular or non-finite).
    dexterity : ndarray, shape (...)
        ``1 / cond`` in ``[0, 1]`` (0 where singular or non-finite).
    singular : ndarray of bool, shape (...)
        ``dexterity < rtol``: singular, or a non-finite Jacobian.
    sigma_min : ndarray, shape (...)
        Smallest singular value, in the Jacobian's units; NaN for a non-finite Jacobian.
    """

    cond: NDArray[np.float64]
    dexterity: NDArray[np.float64]
    singular: NDArray[np.bool_]
    sigma_min: NDArray[np.float64]


def singularity_map(J: ArrayLike, *, rtol: float = SINGULAR_RTOL) -> SingularityMap:
    """Condition, dexterity and a singular mask for each Jacobian; non-finite Jacobians count as singular.

    Parameters
    ----------
    J : array_like, shape (..., m, n)
        Jacobians, e.g. a model's Jacobian evaluated on a :func:`grid`.
    rtol : float, optional
        A Jacobian is singular when ``sigma_min / sigma_max < rtol`` (``0 < rtol <= 1``); default
        ``SINGULAR_RTOL`` = 1e-8.

    Returns
    -------
    SingularityMap
        ``cond``, ``dexterity``, ``singular`` and ``sigma_min``, each of shape ``(...)``.

    Examples
    --------
    >>> import numpy as np
    >>> J = np.array([[[2.0, 0.0], [0.0, 1.0]], [[1.0, 1.0], [1.0, 1.0]]])   # regular, rank 1
    >>> m = singularity_map(J)
    >>> m.dexterity[0], m.singular
    (np.float64(0.5), array([False,  True]))
    """
    J = as_array(J, "J", (None, None), finite=False, nonempty=True)
    rtol = check_real(rtol, "rtol", low=0.0, high=1.0, low_open=True)
    s, finite = _singular_values(J)
    return _measures(s[..., 0], s[..., -1], finite, rtol)


def _measures(smax: np.ndarray, smin: np.ndarray, finite: np.ndarray, rtol: float) -> SingularityMap:
    """The :class:`SingularityMap` of Jacobians with extreme singular values ``smax``, ``smin`` (0 where
    ``finite`` is False)."""
    ratio = np.where(smax > 0, smin / np.where(smax > 0, smax, 1.0), 0.0)
    ratio = np.where(finite, ratio, 0.0)
    cond = np.where(ratio > 0, 1.0 / np.where(ratio > 0, ratio, 1.0), np.inf)
    return SingularityMap(
        cond=cond, dexterity=ratio, singular=ratio < rtol, sigma_min=np.where(finite, smin, np.nan)
    )
