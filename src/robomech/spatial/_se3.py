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
    """Homogeneous transform from rotation (..., 3, 3) and translation (..., 3), broadcast together."""
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
    """``T^-1`` using the rigid structure: ``[R^T, -R^T p]``."""
    T = as_array(T, "T", (4, 4))
    Rt = np.swapaxes(T[..., :3, :3], -1, -2)
    return _transform(Rt, -np.einsum("...ij,...j->...i", Rt, T[..., :3, 3]))


def hat_se3(V: np.ndarray) -> np.ndarray:
    """4x4 matrix of the twist ``V = [w; v]`` (..., 6)."""
    V = as_array(V, "V", (6,))
    out = np.zeros((*V.shape[:-1], 4, 4))
    out[..., :3, :3] = _hat(V[..., :3])
    out[..., :3, 3] = V[..., 3:]
    return out


def vee_se3(X: np.ndarray) -> np.ndarray:
    """Inverse of :func:`hat_se3`."""
    X = as_array(X, "X", (4, 4))
    return np.concatenate([_vee(X[..., :3, :3]), X[..., :3, 3]], axis=-1)


def exp_se3(V: np.ndarray) -> np.ndarray:
    """``exp(hat_se3(V))`` for the twist ``V = [w; v]`` (..., 6) (unit time; scale V by the angle)."""
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
    """Twist ``[w; v]`` (..., 6) with ``exp_se3(log_se3(T)) == T``, rotation angle in [0, pi].

    ``v = G(w)^-1 p`` with ``G^-1 = I - W/2 + D W^2`` and ``D = (1 - (t/2) cot(t/2)) / t^2``, written
    with ``tan`` so that it is finite at ``t = pi`` and replaced by its series near 0.
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
    """6x6 adjoint of ``T_AB``: maps a twist ``[w; v]`` in B to A, ``[[R, 0], [hat(p) R, R]]``."""
    T = as_array(T, "T", (4, 4))
    R, p = T[..., :3, :3], T[..., :3, 3]
    out = np.zeros((*T.shape[:-2], 6, 6))
    out[..., :3, :3] = R
    out[..., 3:, 3:] = R
    out[..., 3:, :3] = _hat(p) @ R
    return out


def ad(V: np.ndarray) -> np.ndarray:
    """6x6 Lie-algebra adjoint of the twist ``V = [w; v]``: ``[[hat w, 0], [hat v, hat w]]``."""
    V = as_array(V, "V", (6,))
    W = _hat(V[..., :3])
    out = np.zeros((*V.shape[:-1], 6, 6))
    out[..., :3, :3] = W
    out[..., 3:, 3:] = W
    out[..., 3:, :3] = _hat(V[..., 3:])
    return out


def lie_bracket(V1: np.ndarray, V2: np.ndarray) -> np.ndarray:
    """``[V1, V2] = ad(V1) V2 = [w1 x w2; w1 x v2 - w2 x v1]`` (the velocity-product term of screws)."""
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
    """
    S1 = as_array(S1, "S1", (6,))
    S2 = as_array(S2, "S2", (6,))
    broadcast_batch((S1, 1, "S1"), (S2, 1, "S2"))
    return np.sum(S1[..., :3] * S2[..., 3:], axis=-1) + np.sum(S2[..., :3] * S1[..., 3:], axis=-1)


def virtual_power(W: np.ndarray, V: np.ndarray) -> np.ndarray:
    """Power ``m . w + f . v`` of the wrench ``W = [m; f]`` on the twist ``V = [w; v]`` (same frame)."""
    W = as_array(W, "W", (6,))
    V = as_array(V, "V", (6,))
    broadcast_batch((W, 1, "W"), (V, 1, "V"))
    return np.sum(W * V, axis=-1)


def screw_from_axis(axis: np.ndarray, point: np.ndarray, pitch: np.ndarray | float = 0.0) -> np.ndarray:
    """Unit screw ``[s; r x s + h s]`` of the line through ``point`` along ``axis`` with pitch ``h``.

    ``pitch = inf`` gives the prismatic (pure translation) screw ``[0; s]``.  ``axis`` is normalised.
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
    """Axis direction (unit), the point of the axis nearest the origin, and the pitch of screw ``S``.

    A screw with zero angular part has pitch ``inf``, its direction from the linear part and point 0.
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


def wrench_at(force: np.ndarray, point: np.ndarray, moment: np.ndarray | float = 0.0) -> np.ndarray:
    """Wrench ``[m; f]`` about the origin of a force applied at ``point`` plus a free ``moment``."""
    force = as_array(force, "force", (3,))
    point = as_array(point, "point", (3,))
    moment = as_array(moment, "moment")
    if moment.ndim and moment.shape[-1] != 3 and moment.size != 1:
        raise ValueError(f"Expected moment to have shape (..., 3) or be a scalar, got {moment.shape}.")
    m = np.cross(point, force) + moment
    return np.concatenate(np.broadcast_arrays(m, force), axis=-1)
