"""Rotations: hat/vee, exponential and logarithm of SO(3), elementary rotations. Batched over ``...``."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from robomech._validation import as_array

__all__ = ["exp_so3", "hat", "log_so3", "rot_x", "rot_y", "rot_z", "sincos", "vee"]

# Below this angle the closed forms sin(t)/t, (1-cos t)/t^2 ... are replaced by their Taylor series:
# the series truncated after the t^4 term has error O(t^6) < 1e-24 at t = 1e-4, while the closed forms
# lose about eps/t^2 ~ 1e-8 relative accuracy there through cancellation.
SMALL_ANGLE = 1e-4
# log_so3 accepts R only if |R^T R - I| and |det R - 1| are below this: a rotation composed from a
# few hundred float64 products stays within ~1e-13, a matrix read from a text file with 6 digits
# within ~1e-6; anything further is not a rotation and its "logarithm" would be meaningless.
ROTATION_ATOL = 1e-5


def hat(w: np.ndarray) -> np.ndarray:
    """Skew-symmetric matrix of a 3-vector, so that ``hat(a) @ b == cross(a, b)``.

    Parameters
    ----------
    w : array_like, shape (..., 3)
        Vectors (any unit; an angular velocity in rad/s gives ``hat(w)`` in rad/s).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        ``[[0, -w3, w2], [w3, 0, -w1], [-w2, w1, 0]]`` for each vector.

    Examples
    --------
    >>> hat([1.0, 2.0, 3.0])
    array([[ 0., -3.,  2.],
           [ 3.,  0., -1.],
           [-2.,  1.,  0.]])
    """
    w = as_array(w, "w", (3,))
    return _hat(w)


def _hat(w: np.ndarray) -> np.ndarray:
    z = np.zeros_like(w[..., 0])
    return np.stack(
        [
            np.stack([z, -w[..., 2], w[..., 1]], -1),
            np.stack([w[..., 2], z, -w[..., 0]], -1),
            np.stack([-w[..., 1], w[..., 0], z], -1),
        ],
        -2,
    )


def vee(W: np.ndarray) -> np.ndarray:
    """Inverse of :func:`hat`: the vector of a skew-symmetric matrix.

    Parameters
    ----------
    W : array_like, shape (..., 3, 3)
        Matrices; only their antisymmetric part ``(W - W^T) / 2`` is used.

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> vee(hat([1.0, 2.0, 3.0]))
    array([1., 2., 3.])
    """
    W = as_array(W, "W", (3, 3))
    return _vee(W)


def _vee(W: np.ndarray) -> np.ndarray:
    return 0.5 * np.stack(
        [W[..., 2, 1] - W[..., 1, 2], W[..., 0, 2] - W[..., 2, 0], W[..., 1, 0] - W[..., 0, 1]], -1
    )


def _series_coeffs(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A = sin t / t, B = (1 - cos t)/t^2, C = (t - sin t)/t^3, accurate for all t >= 0."""
    small = theta < SMALL_ANGLE
    t = np.where(small, 1.0, theta)
    t2 = theta * theta
    A = np.where(small, 1.0 - t2 / 6.0 + t2 * t2 / 120.0, np.sin(t) / t)
    B = np.where(small, 0.5 - t2 / 24.0 + t2 * t2 / 720.0, (1.0 - np.cos(t)) / (t * t))
    C = np.where(small, 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0, (t - np.sin(t)) / (t * t * t))
    return A, B, C


def exp_so3(w: np.ndarray) -> np.ndarray:
    """Rotation matrix ``exp(hat(w))`` of a rotation vector (Rodrigues' formula).

    Parameters
    ----------
    w : array_like, shape (..., 3)
        Rotation vectors: unit axis times angle (rad).  Accurate for all angles, including 0 (Taylor
        series below ``SMALL_ANGLE``).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        ``R_AB`` for a frame B rotated by ``w`` (expressed in A) from A.

    See Also
    --------
    log_so3 : the inverse, angle in [0, pi].

    Examples
    --------
    >>> import numpy as np
    >>> exp_so3([0.0, 0.0, np.pi / 2]).round(12)
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    return _exp_so3(as_array(w, "w", (3,)))


def _exp_so3(w: np.ndarray) -> np.ndarray:
    theta = np.linalg.norm(w, axis=-1)
    A, B, _ = _series_coeffs(theta)
    W = _hat(w)
    return np.eye(3) + A[..., None, None] * W + B[..., None, None] * (W @ W)


def log_so3(R: np.ndarray) -> np.ndarray:
    """Rotation vector of a rotation matrix, angle in [0, pi]; accurate near 0 and near pi.

    The angle comes from ``atan2(|axis part|, cos part)``, accurate everywhere.  Near 0 the axis is
    the antisymmetric part scaled by its series; for angles above pi/2 it is read from the symmetric
    part ``(R + R^T)/2 - cos t I = (1 - cos t) u u^T`` (the antisymmetric part vanishes at pi), with
    the sign taken from the antisymmetric part.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
        Rotation matrices (``R^T R = I`` and ``det R = 1`` within ``ROTATION_ATOL``).

    Returns
    -------
    ndarray, shape (..., 3)
        Axis times angle (rad), with ``exp_so3(log_so3(R)) == R``.

    Raises
    ------
    ValueError
        If ``R`` is not a batch of rotation matrices.

    Examples
    --------
    >>> import numpy as np
    >>> log_so3(exp_so3([0.3, -0.2, 0.1])).round(12)
    array([ 0.3, -0.2,  0.1])
    """
    R = as_array(R, "R", (3, 3))
    err = np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max(axis=(-2, -1), initial=0.0)
    det_err = np.abs(np.linalg.det(R) - 1.0) if R.size else np.zeros(R.shape[:-2])
    if np.any(err > ROTATION_ATOL) or np.any(det_err > ROTATION_ATOL):
        worst = float(max(np.max(err, initial=0.0), np.max(det_err, initial=0.0)))
        raise ValueError(
            f"Expected R to be rotation matrices (R^T R = I, det R = 1 within {ROTATION_ATOL}), "
            f"got a deviation of {worst:.3g}."
        )
    return _log_so3(R)


def _log_so3(R: np.ndarray) -> np.ndarray:
    s_vec = _vee(R)  # = sin(t) u
    sin_t = np.linalg.norm(s_vec, axis=-1)
    cos_t = 0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0)
    theta = np.arctan2(sin_t, cos_t)

    # Branch 1 (theta <= pi/2): w = theta / sin(theta) * s_vec.
    small = theta < SMALL_ANGLE
    safe_sin = np.where(small, 1.0, sin_t)
    scale = np.where(small, 1.0 + theta * theta / 6.0 + 7.0 * theta**4 / 360.0, theta / safe_sin)
    w_near = scale[..., None] * s_vec

    # Branch 2 (theta > pi/2): axis from the symmetric part, column with the largest diagonal.
    S = 0.5 * (R + np.swapaxes(R, -1, -2)) - cos_t[..., None, None] * np.eye(3)
    k = np.argmax(np.diagonal(S, axis1=-2, axis2=-1), axis=-1)
    col = np.take_along_axis(S, k[..., None, None].repeat(3, axis=-2), axis=-1)[..., 0]
    u = col / np.maximum(np.linalg.norm(col, axis=-1, keepdims=True), np.finfo(float).tiny)
    sign = np.where(np.sum(u * s_vec, axis=-1) < 0.0, -1.0, 1.0)
    w_far = (sign * theta)[..., None] * u

    return np.where((theta > 0.5 * np.pi)[..., None], w_far, w_near)


def sincos(angle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(sin(angle), cos(angle))`` from one tangent of the half angle, for any real angle.

    ``s = 2t / (1 + t^2)``, ``c = (1 - t^2) / (1 + t^2)`` with ``t = tan(angle / 2)``: absolute error
    within 2.3e-16 of ``np.sin``/``np.cos`` (relative for small angles; tests), and on this project's
    machines about 3.5x faster than the two calls, whose float64 kernels are not vectorised
    (docs/performance.md).  Finite at odd multiples of pi, where ``t`` is ~1e16: ``c = -1``.

    Parameters
    ----------
    angle : array_like, shape (...)
        Angles (rad).

    Returns
    -------
    s, c : ndarray, shape (...)
        Sine and cosine.

    Examples
    --------
    >>> import numpy as np
    >>> s, c = sincos(np.array([0.0, np.pi / 2]))
    >>> s.round(12), c.round(12)
    (array([0., 1.]), array([1., 0.]))
    """
    return _sincos(as_array(angle, "angle"))


def _sincos(angle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    t = np.tan(0.5 * angle)
    t2 = t * t
    d = 1.0 / (1.0 + t2)
    return 2.0 * t * d, (1.0 - t2) * d


def _rot(angle: ArrayLike, i: int, j: int) -> np.ndarray:
    a = as_array(angle, "angle")
    s, c = _sincos(a)
    R = np.zeros((*a.shape, 3, 3))
    k = 3 - i - j
    R[..., k, k] = 1.0
    R[..., i, i] = c
    R[..., j, j] = c
    R[..., i, j] = -s
    R[..., j, i] = s
    return R


def rot_x(angle: ArrayLike) -> np.ndarray:
    """Active right-handed rotation about x.

    Parameters
    ----------
    angle : array_like, shape (...)
        Rotation angles (rad).

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Examples
    --------
    >>> import numpy as np
    >>> (rot_x(np.pi / 2) @ [0.0, 1.0, 0.0]).round(12)
    array([0., 0., 1.])
    """
    return _rot(angle, 1, 2)


def rot_y(angle: ArrayLike) -> np.ndarray:
    """Active right-handed rotation about y.

    Parameters
    ----------
    angle : array_like, shape (...)
        Rotation angles (rad).

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Examples
    --------
    >>> import numpy as np
    >>> (rot_y(np.pi / 2) @ [0.0, 0.0, 1.0]).round(12)
    array([1., 0., 0.])
    """
    return _rot(angle, 2, 0)


def rot_z(angle: ArrayLike) -> np.ndarray:
    """Active right-handed rotation about z.

    Parameters
    ----------
    angle : array_like, shape (...)
        Rotation angles (rad).

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Examples
    --------
    >>> import numpy as np
    >>> rot_z(np.array([0.0, np.pi / 2])).shape
    (2, 3, 3)
    >>> (rot_z(np.pi / 2) @ [1.0, 0.0, 0.0]).round(12)
    array([0., 1., 0.])
    """
    return _rot(angle, 0, 1)
