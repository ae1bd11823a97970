"""Every joint of the leg as a spanning tree plus closures (``TREE_JOINTS``, for multibody engines and
animations; the tree: docs/mechanisms/omnileg.md, "Generic description")."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._batching import carries_failed_rows
from robomech._validation import as_array, broadcast_batch, check_params

from . import _jet as jt
from ._params import OmniLeg

__all__ = ["TREE_JOINTS", "JointMotion", "joint_motion"]

TREE_JOINTS = (
    "theta11", "theta12", "theta13", "theta14",
    "theta21", "theta22", "theta23",
    "theta31", "theta32", "theta33",
    "drive_in", "drive_phi1", "drive_phi2", "drive_phi3",
    "drive_out",
    "crank_1", "coupler_1", "crank_2", "coupler_2", "crank_3", "coupler_3",
    "foot",
)  # fmt: skip


@dataclass(frozen=True)
class JointMotion:
    """Angles, rates and accelerations of the tree joints (the result of :func:`joint_motion`).

    Attributes
    ----------
    q, qd, qdd : ndarray, shape (..., 22)
        Joint angles (rad), rates (rad/s) and accelerations (rad/s²), in the order of ``TREE_JOINTS``.
    """

    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray


@carries_failed_rows({"q": 1, "qd": 1, "qdd": 1})
def joint_motion(leg: OmniLeg, q: object, qd: object, qdd: object) -> JointMotion:
    """All tree-joint angles, rates and accelerations for the motion ``(q, q̇, q̈)`` of ``(α, β, γ)`` (the
    formulas: docs/mechanisms/omnileg.md, "Generic description").

    Parameters
    ----------
    leg : OmniLeg
    q, qd, qdd : array_like, shape (..., 3)
        Angles (rad), rates (rad/s) and accelerations (rad/s²) of ``(α, β, γ)``; broadcast together.

    Returns
    -------
    :class:`JointMotion`

    Examples
    --------
    >>> m = joint_motion(OmniLeg.paper(), [0.1, 0.2, 0.8], np.zeros(3), np.zeros(3))
    >>> m.q.shape, float(m.q[TREE_JOINTS.index("crank_1")])
    ((22,), 0.8)
    """
    check_params(leg, OmniLeg, "leg")
    q = as_array(q, "q", (3,))
    qd = as_array(qd, "qd", (3,))
    qdd = as_array(qdd, "qdd", (3,))
    batch = broadcast_batch((q, 1, "q"), (qd, 1, "qd"), (qdd, 1, "qdd"))
    flat = [np.ascontiguousarray(np.broadcast_to(a, (*batch, 3)).reshape(-1, 3)) for a in (q, qd, qdd)]
    alpha, beta, gamma = jt.Jet.variables(*flat)
    ta, tb = jt.tan(alpha), jt.tan(beta)
    ca, cb = jt.cos(alpha), jt.cos(beta)
    one = ca * 0.0 + 1.0
    th12 = jt.atan2(ta * cb, one)
    th22 = -jt.atan2(tb * ca, one)  # paper 2, eq. (12): printed +; the closure gives -
    inv_n = jt.reciprocal(jt.sqrt(ta * ta + tb * tb + 1.0))
    u = jt.stack([tb * inv_n, -ta * inv_n, inv_n])
    cg, sg = jt.cos(gamma), jt.sin(gamma)
    zero = np.zeros(flat[0].shape[0])
    a1 = jt.stack([-sg, cg, zero])
    ex = jt.stack([cg, sg, zero])
    n_vec = jt.cross(a1, u)
    a2 = n_vec * jt.reciprocal(jt.sqrt(jt.dot(n_vec, n_vec))).expand()
    a21 = jt.cross(a2, a1)
    ua2 = jt.cross(u, a2)
    phi1 = jt.atan2(jt.dot(ex, a21), jt.dot(ex, a2))
    phi2 = jt.atan2(jt.dot(a21, ua2), jt.dot(a1, ua2))
    joints = [
        beta, th12, -th12, -beta,
        alpha, th22, -th22,
        -beta, -th12, th12,
        gamma, phi1, phi2, -phi2,
        gamma,
        gamma, gamma * -2.0, gamma, gamma * -2.0, gamma, gamma * -2.0,
        gamma,
    ]  # fmt: skip
    n = len(joints)
    out = [np.stack([getattr(j, k) for j in joints], axis=-1).reshape(*batch, n) for k in ("v", "vd", "vdd")]
    return JointMotion(*out)
