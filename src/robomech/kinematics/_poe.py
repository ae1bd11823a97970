"""Product of exponentials, Jacobians and second-order influence coefficients (Hessians).

Shapes: ``screws (n, 6)`` (or broadcastable ``(..., n, 6)``), ``q (..., n)``, ``M (4, 4)``;
``J (..., 6, n)``; ``H (..., 6, n, n)`` with ``H[..., i, j, k] = dJ[..., i, j]/dq[..., k]``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

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


def _check(screws: ArrayLike, q: ArrayLike, name: str = "screws") -> tuple[np.ndarray, np.ndarray]:
    S = as_array(screws, name, (None, 6))
    qa = as_array(q, "q", (None,), min_ndim=1)
    if qa.shape[-1] != S.shape[-2]:
        raise ValueError(f"Expected q to have shape (..., {S.shape[-2]}) to match {name}, got {qa.shape}.")
    broadcast_batch((S, 2, name), (qa, 1, "q"))
    return S, qa


def _joint_exps(S: np.ndarray, q: np.ndarray) -> np.ndarray:
    """exp([S_i] q_i) for every joint: (..., n, 4, 4)."""
    return _exp_se3(S * q[..., None])


def poe_fk(M: ArrayLike, screws: ArrayLike, q: ArrayLike) -> np.ndarray:
    """Forward kinematics by the space-form product of exponentials, ``T = exp([S1]q1) ... exp([Sn]qn) M``.

    Parameters
    ----------
    M : array_like, shape (..., 4, 4)
        Home pose ``T_sb(0)`` of the end frame b in the space frame s (m).
    screws : array_like, shape (..., n, 6)
        Joint screws ``[w; v]`` in the space frame at the home pose (unit ``w`` for revolute joints,
        ``[0; unit v]`` for prismatic ones).
    q : array_like, shape (..., n)
        Joint values (rad or m).  Batch dimensions of ``M``, ``screws`` and ``q`` broadcast.

    Returns
    -------
    ndarray, shape (..., 4, 4)
        ``T_sb(q)``.

    See Also
    --------
    jacobian_space, hessian_space

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.spatial import screw_from_axis
    >>> z = np.array([0.0, 0.0, 1.0])
    >>> screws = screw_from_axis(np.stack([z, z]), np.array([[0.0, 0, 0], [1.0, 0, 0]]))  # planar 2R
    >>> M = np.eye(4); M[0, 3] = 2.0                      # tool at x = 2 m at q = 0
    >>> poe_fk(M, screws, np.array([np.pi / 2, -np.pi / 2]))[:3, 3].round(12)
    array([1., 1., 0.])
    >>> poe_fk(M, screws, np.zeros((5, 2))).shape   # a batch of 5 configurations
    (5, 4, 4)
    """
    M = as_array(M, "M", (4, 4))
    S, qa = _check(screws, q)
    broadcast_batch((M, 2, "M"), (S, 2, "screws"), (qa, 1, "q"))
    E = _joint_exps(S, qa)
    T = np.broadcast_to(np.eye(4), (*E.shape[:-3], 4, 4))
    for i in range(E.shape[-3]):
        T = T @ E[..., i, :, :]
    return T @ M


def jacobian_space(screws: ArrayLike, q: ArrayLike) -> np.ndarray:
    """Space Jacobian ``J_s``: column i is ``Ad(exp([S1]q1)...exp([S_{i-1}]q_{i-1})) S_i``.

    ``J_s(q) @ qd`` is the end frame's space twist ``[w; v]`` (``v``: the velocity of the body point at
    the space origin), for any end frame of the chain.

    Parameters
    ----------
    screws : array_like, shape (..., n, 6)
        Joint screws in the space frame at the home pose.
    q : array_like, shape (..., n)
        Joint values (rad or m); batch dimensions broadcast with those of ``screws``.

    Returns
    -------
    ndarray, shape (..., 6, n)
        ``J[..., :, i]`` is the twist of joint i at ``q`` (rad/s and m/s per unit joint rate).

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.spatial import screw_from_axis
    >>> z = np.array([0.0, 0.0, 1.0])
    >>> screws = screw_from_axis(np.stack([z, z]), np.array([[0.0, 0, 0], [1.0, 0, 0]]))  # planar 2R
    >>> M = np.eye(4); M[0, 3] = 2.0                      # tool at x = 2 m at q = 0
    >>> J = jacobian_space(screws, np.array([np.pi / 2, 0.0]))
    >>> J[[2, 3, 4]].round(12) + 0.0   # rows w_z, v_x, v_y (+ 0.0: no negative zeros)
    array([[1., 1.],
           [0., 1.],
           [0., 0.]])
    """
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


def jacobian_body(body_screws: ArrayLike, q: ArrayLike) -> np.ndarray:
    """Body Jacobian ``J_b`` from body screw axes (``T = M exp([B1]q1)...exp([Bn]qn)``).

    Column i is ``Ad(exp(-[Bn]qn)...exp(-[B_{i+1}]q_{i+1})) B_i``; ``J_b @ qd`` is the end frame's body
    twist, expressed in the end frame.

    Parameters
    ----------
    body_screws : array_like, shape (..., n, 6)
        Joint screws ``[w; v]`` expressed in the end frame at the home pose.
    q : array_like, shape (..., n)
        Joint values (rad or m).

    Returns
    -------
    ndarray, shape (..., 6, n)

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.spatial import adjoint, inverse_transform, screw_from_axis
    >>> from robomech.kinematics import jacobian_space, poe_fk
    >>> z = np.array([0.0, 0.0, 1.0])
    >>> S = screw_from_axis(np.stack([z, z]), np.array([[0.0, 0, 0], [1.0, 0, 0]]))
    >>> M = np.eye(4); M[0, 3] = 2.0
    >>> B = (adjoint(inverse_transform(M)) @ S.T).T   # the same joints in the end frame
    >>> q = np.array([0.3, -0.7])
    >>> T = poe_fk(M, S, q)
    >>> np.allclose(adjoint(T) @ jacobian_body(B, q), jacobian_space(S, q))
    True
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


def hessian_space(screws: ArrayLike, q: ArrayLike) -> np.ndarray:
    """Second-order influence coefficients of the space Jacobian, ``H[..., i, j, k] = dJ[i, j]/dq_k``.

    ``dJ_j/dq_k = ad(J_k) J_j`` for ``k < j`` and 0 otherwise (column j moves only with the joints
    before it).

    Parameters
    ----------
    screws : array_like, shape (..., n, 6)
        Joint screws in the space frame at the home pose.
    q : array_like, shape (..., n)
        Joint values (rad or m).

    Returns
    -------
    ndarray, shape (..., 6, n, n)

    See Also
    --------
    jacobian_derivative : ``dJ/dt`` along joint rates from ``H``.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.spatial import screw_from_axis
    >>> z = np.array([0.0, 0.0, 1.0])
    >>> screws = screw_from_axis(np.stack([z, z]), np.array([[0.0, 0, 0], [1.0, 0, 0]]))  # planar 2R
    >>> M = np.eye(4); M[0, 3] = 2.0                      # tool at x = 2 m at q = 0
    >>> H = hessian_space(screws, np.zeros(2))
    >>> H.shape, float(H[3, 1, 0]), float(H[3, 0, 1])   # ad(S1) S2 = [0; 1, 0, 0]; column 0 is fixed
    ((6, 2, 2), 1.0, 0.0)
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


def hessian_body(body_screws: ArrayLike, q: ArrayLike) -> np.ndarray:
    """Second-order influence coefficients of the body Jacobian, ``H[..., i, j, k] = dJb[i, j]/dq_k``.

    ``dJb_j/dq_k = ad(Jb_j) Jb_k`` for ``k > j`` and 0 otherwise (column j moves only with the joints
    after it).

    Parameters
    ----------
    body_screws : array_like, shape (..., n, 6)
        Joint screws in the end frame at the home pose.
    q : array_like, shape (..., n)
        Joint values (rad or m).

    Returns
    -------
    ndarray, shape (..., 6, n, n)

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.spatial import screw_from_axis
    >>> z = np.array([0.0, 0.0, 1.0])
    >>> B = screw_from_axis(np.stack([z, z]), np.array([[-2.0, 0, 0], [-1.0, 0, 0]]))
    >>> H = hessian_body(B, np.zeros(2))
    >>> H.shape, bool(np.all(H[:, 1, :] == 0.0))   # the last column never moves
    ((6, 2, 2), True)
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
    """Time derivative of a Jacobian along joint rates: ``dJ/dt = sum_k H[..., k] qd_k``.

    Parameters
    ----------
    H : array_like, shape (..., m, n, n)
        Influence coefficients ``dJ[i, j]/dq_k`` (from :func:`hessian_space` or :func:`hessian_body`).
    qd : array_like, shape (..., n)
        Joint rates (rad/s or m/s); batch dimensions broadcast.  For a stack of bodies
        ``H (..., B, 6, n, n)`` pass ``qd[..., None, :]``.

    Returns
    -------
    ndarray, shape (..., m, n)
        ``dJ/dt``; ``dJ/dt @ qd`` is the velocity-product term of the acceleration.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.spatial import screw_from_axis
    >>> z = np.array([0.0, 0.0, 1.0])
    >>> screws = screw_from_axis(np.stack([z, z]), np.array([[0.0, 0, 0], [1.0, 0, 0]]))  # planar 2R
    >>> M = np.eye(4); M[0, 3] = 2.0                      # tool at x = 2 m at q = 0
    >>> q, qd = np.zeros(2), np.array([1.0, 0.0])
    >>> Jd = jacobian_derivative(hessian_space(screws, q), qd)
    >>> Jd.shape, float(Jd[3, 1])      # joint 2's screw changes along v_x at 1 (m/s)/s per rad/s
    ((6, 2), 1.0)
    """
    H = as_array(H, "H", (None, None, None))
    if H.shape[-1] != H.shape[-2]:
        raise ValueError(f"Expected H to have shape (..., m, n, n), got {H.shape}.")
    qd = as_array(qd, "qd", (H.shape[-1],), min_ndim=1)
    broadcast_batch((H, 3, "H"), (qd, 1, "qd"))
    return np.einsum("...ijk,...k->...ij", H, qd)
