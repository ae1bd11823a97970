"""Rigid transforms, twists ``[w; v]``, wrenches ``[m; f]`` and screw algebra. Batched over ``...``."""

from __future__ import annotations

import numpy as np

from robomech._validation import as_array, broadcast_batch

from ._so3 import SMALL_ANGLE, _exp_so3, _hat, _log_so3, _series_coeffs, _vee, log_so3

__all__ = [
    "ad",
    "adjoint",
    "exp_se3",
    "hat_se3",
    "inverse_transform",
    "lie_bracket",
    "log_se3",
    "reciprocal_product",
    "screw_from_axis",
    "screw_to_axis",
    "transform",
    "vee_se3",
    "virtual_power",
    "wrench_at",
]


def transform(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Homogeneous transform ``T_AB`` from a rotation ``R_AB`` and a translation ``p_AB``.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
        Rotation of frame B in frame A.
    p : array_like, shape (..., 3)
        Origin of B in A (m).  Batch dimensions of ``R`` and ``p`` broadcast.

    Returns
    -------
    ndarray, shape (..., 4, 4)
        ``[[R, p], [0, 1]]``, mapping homogeneous points of B to A.

    Examples
    --------
    >>> import numpy as np
    >>> transform(np.eye(3), [1.0, 2.0, 3.0])[:3, 3]
    array([1., 2., 3.])
    """
    R = as_array(R, "R", (3, 3))
    p = as_array(p, "p", (3,))
    broadcast_batch((R, 2, "R"), (p, 1, "p"))
    return _transform(R, p)


def _transform(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    batch = np.broadcast_shapes(R.shape[:-2], p.shape[:-1])
    T = np.zeros((*batch, 4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = p
    T[..., 3, 3] = 1.0
    return T


def inverse_transform(T: np.ndarray) -> np.ndarray:
    """Inverse ``T_BA`` of a rigid transform ``T_AB``, using its structure: ``[R^T, -R^T p]``.

    Parameters
    ----------
    T : array_like, shape (..., 4, 4)
        Rigid transforms.

    Returns
    -------
    ndarray, shape (..., 4, 4)

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.spatial import rot_z
    >>> T = transform(rot_z(0.3), [1.0, 0.0, 0.5])
    >>> np.allclose(inverse_transform(T) @ T, np.eye(4))
    True
    """
    T = as_array(T, "T", (4, 4))
    Rt = np.swapaxes(T[..., :3, :3], -1, -2)
    return _transform(Rt, -np.einsum("...ij,...j->...i", Rt, T[..., :3, 3]))


def hat_se3(V: np.ndarray) -> np.ndarray:
    """The 4x4 matrix ``[[hat(w), v], [0, 0]]`` of a twist ``V = [w; v]`` (an element of se(3)).

    Parameters
    ----------
    V : array_like, shape (..., 6)
        Twists ``[w; v]`` (rad/s, m/s) or unit screws.

    Returns
    -------
    ndarray, shape (..., 4, 4)

    Examples
    --------
    >>> hat_se3([0.0, 0.0, 1.0, 1.0, 2.0, 0.0])[:3] + 0.0  # + 0.0: no negative zeros
    array([[ 0., -1.,  0.,  1.],
           [ 1.,  0.,  0.,  2.],
           [ 0.,  0.,  0.,  0.]])
    """
    V = as_array(V, "V", (6,))
    out = np.zeros((*V.shape[:-1], 4, 4))
    out[..., :3, :3] = _hat(V[..., :3])
    out[..., :3, 3] = V[..., 3:]
    return out


def vee_se3(X: np.ndarray) -> np.ndarray:
    """Inverse of :func:`hat_se3`: the twist ``[w; v]`` of a 4x4 se(3) matrix.

    Parameters
    ----------
    X : array_like, shape (..., 4, 4)

    Returns
    -------
    ndarray, shape (..., 6)

    Examples
    --------
    >>> vee_se3(hat_se3([0.1, 0.2, 0.3, 1.0, 2.0, 3.0]))
    array([0.1, 0.2, 0.3, 1. , 2. , 3. ])
    """
    X = as_array(X, "X", (4, 4))
    return np.concatenate([_vee(X[..., :3, :3]), X[..., :3, 3]], axis=-1)


def exp_se3(V: np.ndarray) -> np.ndarray:
    """Rigid motion ``exp(hat_se3(V))`` of a twist followed for unit time.

    For a joint screw ``S`` and joint value ``q`` pass ``S * q``.  Accurate at zero rotation (series).

    Parameters
    ----------
    V : array_like, shape (..., 6)
        Twists ``[w; v]`` (``w`` in rad, ``v`` in m for unit time).

    Returns
    -------
    ndarray, shape (..., 4, 4)
        The transform of the motion, expressed in the twist's frame.

    See Also
    --------
    log_se3 : the inverse.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.spatial import screw_from_axis
    >>> S = screw_from_axis([0.0, 0.0, 1.0], [1.0, 0.0, 0.0])  # z axis through (1, 0, 0)
    >>> (exp_se3(S * np.pi) @ [0.0, 0.0, 0.0, 1.0]).round(12)  # the origin turns half around it
    array([2., 0., 0., 1.])
    """
    return _exp_se3(as_array(V, "V", (6,)))


def _exp_se3(V: np.ndarray) -> np.ndarray:
    w, v = V[..., :3], V[..., 3:]
    theta = np.linalg.norm(w, axis=-1)
    _, B, C = _series_coeffs(theta)
    W = _hat(w)
    W2 = W @ W
    G = np.eye(3) + B[..., None, None] * W + C[..., None, None] * W2
    return _transform(_exp_so3(w), np.einsum("...ij,...j->...i", G, v))


def log_se3(T: np.ndarray) -> np.ndarray:
    """Twist ``[w; v]`` with ``exp_se3(log_se3(T)) == T``, rotation angle in [0, pi].

    ``v = G(w)^-1 p`` with ``G^-1 = I - W/2 + D W^2`` and ``D = (1 - (t/2) cot(t/2)) / t^2``, written
    with ``tan`` so that it is finite at ``t = pi`` and replaced by its series near 0.

    Parameters
    ----------
    T : array_like, shape (..., 4, 4)
        Rigid transforms (the rotation part must be a rotation within ``ROTATION_ATOL``).

    Returns
    -------
    ndarray, shape (..., 6)
        ``w`` (rad) and ``v`` (m), the twist that reaches ``T`` in unit time.

    Examples
    --------
    >>> import numpy as np
    >>> V = np.array([0.1, -0.2, 0.3, 1.0, 0.0, -0.5])
    >>> np.allclose(log_se3(exp_se3(V)), V)
    True
    """
    T = as_array(T, "T", (4, 4))
    try:
        log_so3(T[..., :3, :3])
    except ValueError as exc:
        raise ValueError(str(exc).replace("Expected R", "Expected the rotation part of T")) from None
    w = _log_so3(T[..., :3, :3])
    theta = np.linalg.norm(w, axis=-1)
    small = theta < SMALL_ANGLE
    t = np.where(small, 1.0, theta)
    half = 0.5 * t
    D = np.where(
        small,
        1.0 / 12.0 + theta**2 / 720.0 + theta**4 / 30240.0,
        (1.0 - half * np.cos(half) / np.sin(half)) / (t * t),
    )
    W = _hat(w)
    Ginv = np.eye(3) - 0.5 * W + D[..., None, None] * (W @ W)
    v = np.einsum("...ij,...j->...i", Ginv, T[..., :3, 3])
    return np.concatenate([w, v], axis=-1)


def adjoint(T: np.ndarray) -> np.ndarray:
    """The 6x6 adjoint ``Ad(T_AB) = [[R, 0], [hat(p) R, R]]``: maps twists in B to A.

    ``V_A = Ad(T_AB) V_B`` for twists ``[w; v]``; wrenches ``[m; f]`` map with ``Ad(T_AB)^-T``.

    Parameters
    ----------
    T : array_like, shape (..., 4, 4)
        Transforms ``T_AB``.

    Returns
    -------
    ndarray, shape (..., 6, 6)

    Examples
    --------
    >>> import numpy as np
    >>> T = transform(np.eye(3), [1.0, 0.0, 0.0])
    >>> adjoint(T) @ [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]  # spin about z at x = 1, seen from the origin
    array([ 0.,  0.,  1.,  0., -1.,  0.])
    """
    T = as_array(T, "T", (4, 4))
    R, p = T[..., :3, :3], T[..., :3, 3]
    out = np.zeros((*T.shape[:-2], 6, 6))
    out[..., :3, :3] = R
    out[..., 3:, 3:] = R
    out[..., 3:, :3] = _hat(p) @ R
    return out


def ad(V: np.ndarray) -> np.ndarray:
    """The 6x6 Lie-algebra adjoint ``ad(V) = [[hat w, 0], [hat v, hat w]]`` of a twist.

    ``ad(V1) @ V2`` is the Lie bracket ``[V1, V2]`` (:func:`lie_bracket`).

    Parameters
    ----------
    V : array_like, shape (..., 6)
        Twists ``[w; v]``.

    Returns
    -------
    ndarray, shape (..., 6, 6)

    Examples
    --------
    >>> import numpy as np
    >>> V1, V2 = np.array([0, 0, 1.0, 0, 0, 0]), np.array([1.0, 0, 0, 0, 1.0, 0])
    >>> np.allclose(ad(V1) @ V2, lie_bracket(V1, V2))
    True
    """
    V = as_array(V, "V", (6,))
    W = _hat(V[..., :3])
    out = np.zeros((*V.shape[:-1], 6, 6))
    out[..., :3, :3] = W
    out[..., 3:, 3:] = W
    out[..., 3:, :3] = _hat(V[..., 3:])
    return out


def lie_bracket(V1: np.ndarray, V2: np.ndarray) -> np.ndarray:
    """Lie bracket ``[V1, V2] = ad(V1) V2 = [w1 x w2; w1 x v2 - w2 x v1]`` of two twists.

    It is the velocity-product term of screw-based accelerations (``dJ/dt`` of a serial chain).

    Parameters
    ----------
    V1, V2 : array_like, shape (..., 6)
        Twists ``[w; v]`` in the same frame; batch dimensions broadcast.

    Returns
    -------
    ndarray, shape (..., 6)

    Examples
    --------
    >>> lie_bracket([1.0, 0, 0, 0, 0, 0], [0, 1.0, 0, 0, 0, 0])
    array([0., 0., 1., 0., 0., 0.])
    """
    V1 = as_array(V1, "V1", (6,))
    V2 = as_array(V2, "V2", (6,))
    broadcast_batch((V1, 1, "V1"), (V2, 1, "V2"))
    w1, v1, w2, v2 = V1[..., :3], V1[..., 3:], V2[..., :3], V2[..., 3:]
    return np.concatenate([np.cross(w1, w2), np.cross(w1, v2) - np.cross(w2, v1)], axis=-1)


def reciprocal_product(S1: np.ndarray, S2: np.ndarray) -> np.ndarray:
    """Reciprocal product ``w1 . v2 + w2 . v1`` of two screws in axis-moment order ``[s; s0]``.

    A force ``f`` along a line through ``r`` is the screw ``[f; r x f]``; it is reciprocal to a twist
    (product zero) when it does no work on it.  For wrenches in robomech's ``[m; f]`` order use
    :func:`virtual_power`, which is the same product with the wrench's halves swapped.

    Parameters
    ----------
    S1, S2 : array_like, shape (..., 6)
        Screws in the same frame; batch dimensions broadcast.

    Returns
    -------
    ndarray, shape (...)

    Examples
    --------
    >>> from robomech.spatial import screw_from_axis
    >>> s1 = screw_from_axis([0.0, 0.0, 1.0], [0.0, 0.0, 0.0])
    >>> s2 = screw_from_axis([0.0, 0.0, 1.0], [1.0, 0.0, 0.0])  # parallel lines are reciprocal
    >>> float(reciprocal_product(s1, s2))
    0.0
    """
    S1 = as_array(S1, "S1", (6,))
    S2 = as_array(S2, "S2", (6,))
    broadcast_batch((S1, 1, "S1"), (S2, 1, "S2"))
    return np.sum(S1[..., :3] * S2[..., 3:], axis=-1) + np.sum(S2[..., :3] * S1[..., 3:], axis=-1)


def virtual_power(W: np.ndarray, V: np.ndarray) -> np.ndarray:
    """Power ``m . w + f . v`` of a wrench ``W = [m; f]`` on a twist ``V = [w; v]``.

    Parameters
    ----------
    W : array_like, shape (..., 6)
        Wrenches (N m, N), moments about the origin of the frame they are expressed in.
    V : array_like, shape (..., 6)
        Twists (rad/s, m/s) in the same frame; batch dimensions broadcast.

    Returns
    -------
    ndarray, shape (...)
        Power (W).

    Examples
    --------
    >>> float(virtual_power([0, 0, 2.0, 1.0, 0, 0], [0, 0, 3.0, 4.0, 0, 0]))  # 2*3 + 1*4
    10.0
    """
    W = as_array(W, "W", (6,))
    V = as_array(V, "V", (6,))
    broadcast_batch((W, 1, "W"), (V, 1, "V"))
    return np.sum(W * V, axis=-1)


def screw_from_axis(axis: np.ndarray, point: np.ndarray, pitch: np.ndarray | float = 0.0) -> np.ndarray:
    """Unit screw ``[s; r x s + h s]`` of the line through ``point`` along ``axis`` with pitch ``h``.

    ``pitch = inf`` gives the prismatic (pure translation) screw ``[0; s]``.  ``axis`` is normalised.

    Parameters
    ----------
    axis : array_like, shape (..., 3)
        Directions of the lines (nonzero; normalised here).
    point : array_like, shape (..., 3)
        A point of each line (m).
    pitch : float or array_like, shape (...), optional
        Pitch (m/rad); ``inf`` for a prismatic joint.  Default 0 (revolute).

    Returns
    -------
    ndarray, shape (..., 6)
        Joint screws ``[w; v]`` in the frame of ``axis`` and ``point``.

    Examples
    --------
    >>> import numpy as np
    >>> screw_from_axis([0.0, 0.0, 2.0], [1.0, 0.0, 0.0])
    array([ 0.,  0.,  1.,  0., -1.,  0.])
    >>> screw_from_axis([1.0, 0.0, 0.0], [0.0, 0.0, 0.0], np.inf)  # prismatic along x
    array([0., 0., 0., 1., 0., 0.])
    """
    axis = as_array(axis, "axis", (3,))
    point = as_array(point, "point", (3,))
    h = as_array(pitch, "pitch", finite=False)
    if np.any(np.isnan(h)):
        raise ValueError("Expected pitch to be a real number or +-inf (prismatic), got NaN.")
    norm = np.linalg.norm(axis, axis=-1)
    if np.any(norm == 0.0):
        n_zero = int(np.sum(norm == 0.0))
        raise ValueError(f"Expected axis to be nonzero vectors, got {n_zero} zero vector(s).")
    broadcast_batch((axis, 1, "axis"), (point, 1, "point"), (h, 0, "pitch"))
    s = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    infinite = np.isinf(h)[..., None]
    h_f = np.where(np.isinf(h), 0.0, h)[..., None]
    rot = np.concatenate(np.broadcast_arrays(s, np.cross(point, s) + h_f * s), axis=-1)
    trans = np.concatenate([np.zeros_like(s), s], axis=-1)
    return np.where(infinite, trans, rot)


def screw_to_axis(S: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Axis direction (unit), the point of the axis nearest the origin, and the pitch of a screw.

    A screw with zero angular part has pitch ``inf``, its direction from the linear part and point 0.

    Parameters
    ----------
    S : array_like, shape (..., 6)
        Nonzero screws ``[w; v]``.

    Returns
    -------
    direction : ndarray, shape (..., 3)
    point : ndarray, shape (..., 3)
        Nearest point of the axis to the origin (m).
    pitch : ndarray, shape (...)
        Pitch (m/rad), ``inf`` for a pure translation.

    Examples
    --------
    >>> d, p, h = screw_to_axis(screw_from_axis([0.0, 0.0, 1.0], [1.0, 2.0, 5.0], 0.1))
    >>> d, p.round(12) + 0.0, float(h)
    (array([0., 0., 1.]), array([1., 2., 0.]), 0.1)
    """
    S = as_array(S, "S", (6,))
    w, v = S[..., :3], S[..., 3:]
    ww = np.sum(w * w, axis=-1)
    if np.any((ww == 0.0) & (np.sum(v * v, axis=-1) == 0.0)):
        raise ValueError("Expected S to be nonzero screws, got a zero screw (no axis).")
    rot = ww > 0.0
    safe = np.where(rot, ww, 1.0)
    direction = np.where(rot[..., None], w, v)
    direction = direction / np.linalg.norm(direction, axis=-1, keepdims=True)
    point = np.where(rot[..., None], np.cross(w, v) / safe[..., None], 0.0)
    pitch = np.where(rot, np.sum(w * v, axis=-1) / safe, np.inf)
    return direction, point, pitch


def wrench_at(force: np.ndarray, point: np.ndarray, moment: np.ndarray | None = None) -> np.ndarray:
    """Wrench ``[m; f]`` about the origin of a force applied at ``point`` plus a free ``moment``.

    Parameters
    ----------
    force : array_like, shape (..., 3)
        Force (N).
    point : array_like, shape (..., 3)
        Point of application (m), in the same frame.
    moment : array_like, shape (..., 3), optional
        Free moment added (N m), a vector like the force.  Default: none.

    Returns
    -------
    ndarray, shape (..., 6)
        ``[point x force + moment; force]``.

    Raises
    ------
    ValueError
        If an argument is not a finite real array of shape (..., 3) (a scalar moment is not a
        moment), or the batch shapes do not broadcast.

    Examples
    --------
    >>> wrench_at([0.0, 0.0, -10.0], [1.0, 0.0, 0.0]) + 0.0  # 10 N down at x = 1 m
    array([  0.,  10.,   0.,   0.,   0., -10.])
    """
    force = as_array(force, "force", (3,))
    point = as_array(point, "point", (3,))
    items = [(force, 1, "force"), (point, 1, "point")]
    if moment is not None:
        moment = as_array(moment, "moment", (3,))
        items.append((moment, 1, "moment"))
    broadcast_batch(*items)
    m = np.cross(point, force)
    if moment is not None:
        m = m + moment
    return np.concatenate(np.broadcast_arrays(m, force), axis=-1)
