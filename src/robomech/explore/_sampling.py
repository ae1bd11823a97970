"""Design matrices: scrambled Sobol, Latin hypercube (``scipy.stats.qmc``), a full grid, or Monte Carlo.

Every sampler draws points in the open unit cube and maps them through each variable
(:meth:`Variable.from_unit`: uniform over the range, or normal with the variable's sigma).  ``sobol``,
``lhs`` and ``grid`` depend only on ``seed`` and ``n``; ``random`` draws chunk ``k`` from its own stream
``SeedSequence([seed, k])`` (:func:`chunk_seed`), so a longer Monte Carlo run extends a shorter one.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence

import numpy as np

from robomech._validation import check_choice, check_int

from ._study import Variable, check_variables

__all__ = ["SAMPLERS", "chunk_seed", "design_matrix", "grid_size"]

SAMPLERS = ("sobol", "lhs", "grid", "random")
# Unit-cube samples are kept this far inside (0, 1): a normal variable maps 0 and 1 to -inf and +inf
# (a scrambled Sobol point can be exactly 0).  1e-12 caps a normal draw at 7 sigma.
UNIT_MARGIN = 1e-12
# Largest design matrix built (rows): 10^7 rows of 8 variables are 640 MB of float64, beyond any sweep
# this machine finishes in a day; more is a typo, refused before memory is allocated.
MAX_DESIGNS = 10**7


def chunk_seed(seed: int, chunk: int) -> np.random.SeedSequence:
    """The independent random stream of chunk ``chunk`` of a sweep with ``seed``.

    Parameters
    ----------
    seed : int
        The sweep's seed, >= 0.
    chunk : int
        Chunk index, >= 0.

    Returns
    -------
    numpy.random.SeedSequence
        ``SeedSequence([seed, chunk])``.

    Raises
    ------
    ValueError
        If ``seed`` or ``chunk`` is not a non-negative int.

    Examples
    --------
    >>> chunk_seed(0, 3).entropy
    [0, 3]
    """
    return np.random.SeedSequence([check_int(seed, "seed", low=0), check_int(chunk, "chunk", low=0)])


def grid_size(n: int, d: int) -> int:
    """Points per axis of the grid sampler: the largest m with m**d <= n (at least 2)."""
    m = max(2, math.floor(n ** (1.0 / d) + 1e-9))
    while (m + 1) ** d <= n:
        m += 1
    return m


def design_matrix(variables: Sequence[Variable], n: int, sampler: str, seed: int, chunk: int) -> np.ndarray:
    """``(n', len(variables))`` design rows; ``n' = n`` except for ``grid`` (``grid_size(n, d)**d``).

    Parameters
    ----------
    variables : sequence of Variable
        The design variables (at least one): one column each.
    n : int
        Number of designs asked for (>= 1).
    sampler : str
        ``"sobol"`` (scrambled), ``"lhs"``, ``"grid"`` or ``"random"`` (module docstring).
    seed : int
        Seed (>= 0); the design matrix depends only on it (and on ``chunk`` for ``random``).
    chunk : int
        Chunk size (>= 1): ``random`` draws each chunk from :func:`chunk_seed`.

    Returns
    -------
    ndarray, shape (n', len(variables))
        Each variable's values in its SI units (uniform over its range, or normal errors).

    Raises
    ------
    ValueError
        If ``variables`` is not a non-empty sequence of Variable (or names a variable twice),
        ``sampler`` is unknown, or ``n`` (1 to ``MAX_DESIGNS``), ``seed``, ``chunk`` are not ints in
        range.

    Examples
    --------
    >>> from robomech.explore import Variable, design_matrix
    >>> design_matrix([Variable("a", 0.0, 1.0)], 4, "grid", 0, 2).ravel().round(3)
    array([0.   , 0.333, 0.667, 1.   ])
    """
    variables = check_variables(variables)
    check_choice(sampler, "sampler", SAMPLERS)
    n = check_int(n, "n", low=1, high=MAX_DESIGNS)
    seed = check_int(seed, "seed", low=0)
    chunk = check_int(chunk, "chunk", low=1)
    d = len(variables)
    names = [v.name for v in variables]
    if len(set(names)) != d:
        dup = sorted({x for x in names if names.count(x) > 1})
        raise ValueError(f"Expected variables with distinct names, got {', '.join(dup)} more than once.")
    if d == 0:
        raise ValueError("Expected variables to hold at least one design variable, got none.")
    if sampler == "sobol":
        from scipy.stats import qmc

        with warnings.catch_warnings():  # the balance warning for n not a power of 2: a documented choice
            warnings.simplefilter("ignore", UserWarning)
            u = qmc.Sobol(d, scramble=True, seed=np.random.default_rng(seed)).random(n)
    elif sampler == "lhs":
        from scipy.stats import qmc

        u = qmc.LatinHypercube(d, seed=np.random.default_rng(seed)).random(n)
    elif sampler == "grid":
        m = grid_size(n, d)
        axis = (
            (np.arange(m) + 0.5) / m if any(v.kind == "normal" for v in variables) else np.linspace(0, 1, m)
        )
        u = np.stack(np.meshgrid(*([axis] * d), indexing="ij"), -1).reshape(-1, d)
    else:
        blocks = []
        for k in range(-(-n // chunk)):
            rows = min(chunk, n - k * chunk)
            blocks.append(np.random.default_rng(chunk_seed(seed, k)).random((rows, d)))
        u = np.concatenate(blocks)
    u = np.clip(u, UNIT_MARGIN, 1.0 - UNIT_MARGIN) if any(v.kind == "normal" for v in variables) else u
    return np.stack([v.from_unit(u[:, i]) for i, v in enumerate(variables)], axis=-1)
