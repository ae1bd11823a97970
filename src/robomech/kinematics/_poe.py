"""Product of exponentials, Jacobians and second-order influence coefficients (Hessians).

Shapes: ``screws (n, 6)`` (or broadcastable ``(..., n, 6)``), ``q (..., n)``, ``M (4, 4)``;
``J (..., 6, n)``; ``H (..., 6, n, n)`` with ``H[..., i, j, k] = dJ[..., i, j]/dq[..., k]``.
"""

from __future__ import annotations

import numpy as np

from robomech._validation import as_array, broadcast_batch
from robomech.spatial._se3 import _exp_se3, ad, adjoint

__all__ = [
    "hessian_body",
    "hessian_space",
    "jacobian_body",
    "jacobian_derivative",
    "jacobian_space",
    "poe_fk",
]


def _check(screws: object, q: object, name: str = "screws") -> tuple[np.ndarray, np.ndarray]:
    S = as_array(screws, name, (None, 6))
    qa = as_array(q, "q", (None,), min_ndim=1)
    if qa.shape[-1] != S.shape[-2]:
        raise ValueError(f"Expected q to have shape (..., {S.shape[-2]}) to match {name}, got {qa.shape}.")
    broadcast_batch((S, 2, name), (qa, 1, "q"))
    return S, qa


def _joint_exps(S: np.ndarray, q: np.ndarray) -> np.ndarray:
    """exp([S_i] q_i) for every joint: (..., n, 4, 4)."""
    return _exp_se3(S * q[..., None])


def poe_fk(M: object, screws: object, q: object) -> np.ndarray:
    """Space-form product of exponentials ``T = exp([S1]q1) ... exp([Sn]qn) M`` -> (..., 4, 4)."""
    M = as_array(M, "M", (4, 4))
    S, qa = _check(screws, q)
    broadcast_batch((M, 2, "M"), (S, 2, "screws"), (qa, 1, "q"))
    E = _joint_exps(S, qa)
    T = np.broadcast_to(np.eye(4), (*E.shape[:-3], 4, 4))
    for i in range(E.shape[-3]):
        T = T @ E[..., i, :, :]
    return T @ M


def jacobian_space(screws: object, q: object) -> np.ndarray:
    """Space Jacobian ``J_s (..., 6, n)``: column i is ``Ad(exp([S1]q1)...exp([S_{i-1}]q_{i-1})) S_i``."""
    S, qa = _check(screws, q)
    E = _joint_exps(S, qa)
    n = S.shape[-2]
    batch = np.broadcast_shapes(S.shape[:-2], qa.shape[:-1])
    J = np.empty((*batch, 6, n))
    T = np.broadcast_to(np.eye(4), (*batch, 4, 4))
    for i in range(n):
        J[..., :, i] = np.einsum("...ij,...j->...i", adjoint(T), S[..., i, :])
        T = T @ E[..., i, :, :]
    return J


def jacobian_body(body_screws: object, q: object) -> np.ndarray:
    """Body Jacobian ``J_b (..., 6, n)`` from body screw axes ``B (n, 6)`` (``T = M exp([B1]q1)...``).

    Column i is ``Ad(exp(-[Bn]qn)...exp(-[B_{i+1}]q_{i+1})) B_i``.
    """
    B, qa = _check(body_screws, q, "body_screws")
    E = _exp_se3(-B * qa[..., None])
    n = B.shape[-2]
    batch = np.broadcast_shapes(B.shape[:-2], qa.shape[:-1])
    J = np.empty((*batch, 6, n))
    T = np.broadcast_to(np.eye(4), (*batch, 4, 4))
    for i in range(n - 1, -1, -1):
        J[..., :, i] = np.einsum("...ij,...j->...i", adjoint(T), B[..., i, :])
        T = T @ E[..., i, :, :]
    return J


def hessian_space(screws: object, q: object) -> np.ndarray:
    """Second-order influence coefficients of the space Jacobian, ``(..., 6, n, n)``.

    ``dJ_j/dq_k = ad(J_k) J_j`` for ``k < j`` and 0 otherwise (column j moves only with the joints
    before it).
    """
    J = jacobian_space(screws, q)
    n = J.shape[-1]
    H = np.zeros((*J.shape, n))
    Jc = np.swapaxes(J, -1, -2)  # (..., n, 6)
    adJ = ad(Jc)  # (..., n, 6, 6)
    for k in range(n):
        # columns j > k
        H[..., :, k + 1 :, k] = np.swapaxes(
            np.einsum("...ab,...jb->...ja", adJ[..., k, :, :], Jc[..., k + 1 :, :]), -1, -2
        )
    return H


def hessian_body(body_screws: object, q: object) -> np.ndarray:
    """Second-order influence coefficients of the body Jacobian, ``(..., 6, n, n)``.

    ``dJb_j/dq_k = ad(Jb_j) Jb_k`` for ``k > j`` and 0 otherwise (column j moves only with the joints
    after it).
    """
    J = jacobian_body(body_screws, q)
    n = J.shape[-1]
    H = np.zeros((*J.shape, n))
    Jc = np.swapaxes(J, -1, -2)
    adJ = ad(Jc)
    for j in range(n):
        H[..., :, j, j + 1 :] = np.einsum("...ab,...kb->...ak", adJ[..., j, :, :], Jc[..., j + 1 :, :])
    return H


def jacobian_derivative(H: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """Time derivative of a Jacobian along ``qd``: ``dJ/dt = sum_k H[..., k] qd_k``.

    ``H (..., m, n, n)`` and ``qd (..., n)`` broadcast over their batch dimensions; for a stack of
    bodies ``H (..., B, 6, n, n)`` pass ``qd[..., None, :]``.
    """
    H = as_array(H, "H", (None, None, None))
    if H.shape[-1] != H.shape[-2]:
        raise ValueError(f"Expected H to have shape (..., m, n, n), got {H.shape}.")
    qd = as_array(qd, "qd", (H.shape[-1],), min_ndim=1)
    broadcast_batch((H, 3, "H"), (qd, 1, "qd"))
    return np.einsum("...ijk,...k->...ij", H, qd)
