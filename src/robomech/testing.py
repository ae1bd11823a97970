"""Finite-difference references for the tests: every analytic derivative is checked against these.

Central differences have truncation error ``O(h^2 f''')`` and rounding error ``O(eps f / h)``; the
defaults balance the two for functions of order one (error about 1e-10 for first derivatives).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from robomech._validation import as_array, check_positive
from robomech.spatial import inverse_transform, vee_se3

__all__ = ["numerical_hessian", "numerical_jacobian", "numerical_space_jacobian"]

# eps**(1/3) ~ 6e-6 is the optimal central-difference step for an O(1) function.
FD_STEP = 6e-6
# The Hessian differences the analytic Jacobian once, so the same optimal step applies.


def _check_callable(f: object, name: str) -> None:
    if not callable(f):
        raise ValueError(f"Expected {name} to be a callable, got {type(f).__name__}.")


def numerical_jacobian(
    f: Callable[[np.ndarray], np.ndarray], x: np.ndarray, h: float = FD_STEP
) -> np.ndarray:
    """Central-difference derivative of ``f`` at ``x (..., n)``: returns ``(..., *out, n)``.

    ``f`` must be batched: ``f(x (..., n)) -> (..., *out)``.

    Parameters
    ----------
    f : callable
        Batched map ``f(x (..., n)) -> (..., *out)``.
    x : ndarray, shape (..., n)
        Points of evaluation.
    h : float, optional
        Step (in the units of ``x``); the default ~ eps^(1/3) balances truncation and rounding.

    Returns
    -------
    ndarray, shape ``(..., *out, n)``
        ``d f / d x_k`` in the last axis.

    Examples
    --------
    >>> import numpy as np
    >>> f = lambda x: np.stack([x[..., 0] ** 2, x[..., 0] * x[..., 1]], axis=-1)
    >>> numerical_jacobian(f, np.array([1.0, 2.0])).round(8)
    array([[2., 0.],
           [2., 1.]])
    """
    _check_callable(f, "f")
    x = as_array(x, "x", (None,), min_ndim=1, nonempty=True)
    h = check_positive(h, "h")
    n = x.shape[-1]
    cols = []
    for k in range(n):
        e = np.zeros(n)
        e[k] = h
        cols.append((np.asarray(f(x + e)) - np.asarray(f(x - e))) / (2.0 * h))
    return np.stack(cols, axis=-1)


def numerical_hessian(
    jac: Callable[[np.ndarray], np.ndarray], x: np.ndarray, h: float = FD_STEP
) -> np.ndarray:
    """Central differences of an analytic Jacobian ``jac(x) -> (..., m, n)``: ``(..., m, n, n)``.

    Parameters
    ----------
    jac : callable
        Batched analytic Jacobian ``jac(x (..., n)) -> (..., m, n)``.
    x : ndarray, shape (..., n)
        Points of evaluation.
    h : float, optional
        Step (in the units of ``x``).

    Returns
    -------
    ndarray, shape (..., m, n, n)
        ``H[..., i, j, k] = d J_ij / d x_k``.

    Examples
    --------
    >>> import numpy as np
    >>> jac = lambda x: np.array([[2 * x[0], 0.0], [x[1], x[0]]])    # of (x0², x0 x1)
    >>> numerical_hessian(jac, np.array([1.0, 2.0]))[1].round(8)      # d/dx of the second row
    array([[0., 1.],
           [1., 0.]])
    """
    _check_callable(jac, "jac")
    return numerical_jacobian(jac, x, h)


def numerical_space_jacobian(
    fk: Callable[[np.ndarray], np.ndarray], q: np.ndarray, h: float = FD_STEP
) -> np.ndarray:
    """Space Jacobian of a pose map ``fk(q) -> T (..., 4, 4)``: column k is ``vee(dT/dq_k T^-1)``.

    Parameters
    ----------
    fk : callable
        Batched pose map ``fk(q (..., n)) -> T (..., 4, 4)``.
    q : ndarray, shape (..., n)
        Joint coordinates.
    h : float, optional
        Step (rad or m).

    Returns
    -------
    ndarray, shape (..., 6, n)
        Columns ``[ω; v]``: the space twists per unit joint rate.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.kinematics import jacobian_space, poe_fk
    >>> from robomech.spatial import screw_from_axis
    >>> z = np.array([0.0, 0.0, 1.0])
    >>> S = screw_from_axis(np.stack([z, z]), np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]))
    >>> M = np.eye(4)
    >>> M[0, 3] = 1.5
    >>> q = np.array([0.3, 0.4])
    >>> Jn = numerical_space_jacobian(lambda q: poe_fk(M, S, q), q)
    >>> bool(np.abs(Jn - jacobian_space(S, q)).max() < 1e-9)          # the analytic Jacobian agrees
    True
    """
    _check_callable(fk, "fk")
    q = as_array(q, "q", (None,), min_ndim=1, nonempty=True)
    T_inv = inverse_transform(fk(q))
    dT = numerical_jacobian(fk, q, h)  # (..., 4, 4, n)
    return vee_se3(np.einsum("...abk,...bc->...kac", dT, T_inv)).swapaxes(-1, -2)
