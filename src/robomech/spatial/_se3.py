"""Rigid transforms, twists ``[w; v]``, wrenches ``[m; f]`` and screw algebra. Batched over ``...``."""

from __future__ import annotations

import numpy as np

from ._so3 import SMALL_ANGLE, _series_coeffs, exp_so3, hat, log_so3, vee

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
    R = np.asarray(R, dtype=float)
    p = np.asarray(p, dtype=float)
    batch = np.broadcast_shapes(R.shape[:-2], p.shape[:-1])
    T = np.zeros((*batch, 4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = p
    T[..., 3, 3] = 1.0
    return T


def inverse_transform(T: np.ndarray) -> np.ndarray:
    """``T^-1`` using the rigid structure: ``[R^T, -R^T p]``."""
    T = np.asarray(T, dtype=float)
    Rt = np.swapaxes(T[..., :3, :3], -1, -2)
    return transform(Rt, -np.einsum("...ij,...j->...i", Rt, T[..., :3, 3]))


def hat_se3(V: np.ndarray) -> np.ndarray:
    """4x4 matrix of the twist ``V = [w; v]`` (..., 6)."""
    V = np.asarray(V, dtype=float)
    out = np.zeros((*V.shape[:-1], 4, 4))
    out[..., :3, :3] = hat(V[..., :3])
    out[..., :3, 3] = V[..., 3:]
    return out


def vee_se3(X: np.ndarray) -> np.ndarray:
    """Inverse of :func:`hat_se3`."""
    X = np.asarray(X, dtype=float)
    return np.concatenate([vee(X[..., :3, :3]), X[..., :3, 3]], axis=-1)


def exp_se3(V: np.ndarray) -> np.ndarray:
    """``exp(hat_se3(V))`` for the twist ``V = [w; v]`` (..., 6) (unit time; scale V by the angle)."""
    V = np.asarray(V, dtype=float)
    w, v = V[..., :3], V[..., 3:]
    theta = np.linalg.norm(w, axis=-1)
    _, B, C = _series_coeffs(theta)
    W = hat(w)
    W2 = W @ W
    G = np.eye(3) + B[..., None, None] * W + C[..., None, None] * W2
    return transform(exp_so3(w), np.einsum("...ij,...j->...i", G, v))


def log_se3(T: np.ndarray) -> np.ndarray:
    """Twist ``[w; v]`` (..., 6) with ``exp_se3(log_se3(T)) == T``, rotation angle in [0, pi].

    ``v = G(w)^-1 p`` with ``G^-1 = I - W/2 + D W^2`` and ``D = (1 - (t/2) cot(t/2)) / t^2``, written
    with ``tan`` so that it is finite at ``t = pi`` and replaced by its series near 0.
    """
    T = np.asarray(T, dtype=float)
    w = log_so3(T[..., :3, :3])
    theta = np.linalg.norm(w, axis=-1)
    small = theta < SMALL_ANGLE
    t = np.where(small, 1.0, theta)
    half = 0.5 * t
    D = np.where(
        small,
        1.0 / 12.0 + theta**2 / 720.0 + theta**4 / 30240.0,
        (1.0 - half * np.cos(half) / np.sin(half)) / (t * t),
    )
    W = hat(w)
    Ginv = np.eye(3) - 0.5 * W + D[..., None, None] * (W @ W)
    v = np.einsum("...ij,...j->...i", Ginv, T[..., :3, 3])
    return np.concatenate([w, v], axis=-1)


def adjoint(T: np.ndarray) -> np.ndarray:
    """6x6 adjoint of ``T_AB``: maps a twist ``[w; v]`` in B to A, ``[[R, 0], [hat(p) R, R]]``."""
    T = np.asarray(T, dtype=float)
    R, p = T[..., :3, :3], T[..., :3, 3]
    out = np.zeros((*T.shape[:-2], 6, 6))
    out[..., :3, :3] = R
    out[..., 3:, 3:] = R
    out[..., 3:, :3] = hat(p) @ R
    return out


def ad(V: np.ndarray) -> np.ndarray:
    """6x6 Lie-algebra adjoint of the twist ``V = [w; v]``: ``[[hat w, 0], [hat v, hat w]]``."""
    V = np.asarray(V, dtype=float)
    W = hat(V[..., :3])
    out = np.zeros((*V.shape[:-1], 6, 6))
    out[..., :3, :3] = W
    out[..., 3:, 3:] = W
    out[..., 3:, :3] = hat(V[..., 3:])
    return out


def lie_bracket(V1: np.ndarray, V2: np.ndarray) -> np.ndarray:
    """``[V1, V2] = ad(V1) V2 = [w1 x w2; w1 x v2 - w2 x v1]`` (the velocity-product term of screws)."""
    V1 = np.asarray(V1, dtype=float)
    V2 = np.asarray(V2, dtype=float)
    w1, v1, w2, v2 = V1[..., :3], V1[..., 3:], V2[..., :3], V2[..., 3:]
    return np.concatenate([np.cross(w1, w2), np.cross(w1, v2) - np.cross(w2, v1)], axis=-1)


def reciprocal_product(S1: np.ndarray, S2: np.ndarray) -> np.ndarray:
    """Reciprocal product ``w1 . v2 + w2 . v1`` of two screws in axis-moment order ``[s; s0]``.

    A force ``f`` along a line through ``r`` is the screw ``[f; r x f]``; it is reciprocal to a twist
    (product zero) when it does no work on it.  For wrenches in robomech's ``[m; f]`` order use
    :func:`virtual_power`, which is the same product with the wrench's halves swapped.
    """
    S1 = np.asarray(S1, dtype=float)
    S2 = np.asarray(S2, dtype=float)
    return np.sum(S1[..., :3] * S2[..., 3:], axis=-1) + np.sum(S2[..., :3] * S1[..., 3:], axis=-1)


def virtual_power(W: np.ndarray, V: np.ndarray) -> np.ndarray:
    """Power ``m . w + f . v`` of the wrench ``W = [m; f]`` on the twist ``V = [w; v]`` (same frame)."""
    W = np.asarray(W, dtype=float)
    V = np.asarray(V, dtype=float)
    return np.sum(W * V, axis=-1)


def screw_from_axis(axis: np.ndarray, point: np.ndarray, pitch: np.ndarray | float = 0.0) -> np.ndarray:
    """Unit screw ``[s; r x s + h s]`` of the line through ``point`` along ``axis`` with pitch ``h``.

    ``pitch = inf`` gives the prismatic (pure translation) screw ``[0; s]``.  ``axis`` is normalised.
    """
    axis = np.asarray(axis, dtype=float)
    point = np.asarray(point, dtype=float)
    h = np.asarray(pitch, dtype=float)
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
    S = np.asarray(S, dtype=float)
    w, v = S[..., :3], S[..., 3:]
    ww = np.sum(w * w, axis=-1)
    rot = ww > 0.0
    safe = np.where(rot, ww, 1.0)
    direction = np.where(rot[..., None], w, v)
    direction = direction / np.linalg.norm(direction, axis=-1, keepdims=True)
    point = np.where(rot[..., None], np.cross(w, v) / safe[..., None], 0.0)
    pitch = np.where(rot, np.sum(w * v, axis=-1) / safe, np.inf)
    return direction, point, pitch


def wrench_at(force: np.ndarray, point: np.ndarray, moment: np.ndarray | float = 0.0) -> np.ndarray:
    """Wrench ``[m; f]`` about the origin of a force applied at ``point`` plus a free ``moment``."""
    force = np.asarray(force, dtype=float)
    point = np.asarray(point, dtype=float)
    m = np.cross(point, force) + np.asarray(moment, dtype=float)
    return np.concatenate(np.broadcast_arrays(m, force), axis=-1)
