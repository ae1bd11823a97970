"""Rigid-body dynamics from body Jacobians (Lagrange's equations in matrix form) and virtual-work statics.

For a mechanism whose bodies b = 1..B have body twists ``V_b = J_b(q) qd`` (``J_b (..., B, 6, n)``,
body frames, ``[w; v]``), Lagrange's equations give

    tau = sum_b J_b^T ( G_b (J_b qdd + Jdot_b qd - g_b) - ad(V_b)^T G_b V_b )

with ``G_b`` the 6x6 spatial inertia in the body frame and ``g_b = [0; R_b^T g]`` gravity expressed
in the body frame.  This is exact for any holonomic mechanism once the closure is solved, i.e. once
``J_b`` maps the independent coordinates q (a parallel mechanism's platform angles, say) to each
body's twist: the constraint forces do no virtual work and drop out.  Actuator forces then follow by
virtual work from the actuator Jacobian (:func:`actuator_forces`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._validation import as_array, broadcast_batch, check_positive, finite_samples
from robomech.spatial._se3 import ad
from robomech.spatial._so3 import _hat as hat

__all__ = [
    "DynamicsTerms",
    "actuator_forces",
    "inverse_dynamics",
    "kinetic_energy",
    "mass_matrix",
    "spatial_inertia",
    "static_torques",
]


def spatial_inertia(mass: object, com: object, inertia_com: object) -> np.ndarray:
    """6x6 spatial inertia about a body frame's origin for twists ``[w; v]``.

    ``com (..., 3)`` is the centre of mass in the body frame and ``inertia_com (..., 3, 3)`` the
    rotational inertia about it, in body axes:
    ``G = [[I_c - m hat(c)^2, m hat(c)], [-m hat(c), m I]]``.
    """
    m = as_array(mass, "mass")
    c = as_array(com, "com", (3,))
    Ic = as_array(inertia_com, "inertia_com", (3, 3))
    if np.any(m < 0):
        raise ValueError(f"Expected mass >= 0, got {mass!r}.")
    broadcast_batch((m, 0, "mass"), (c, 1, "com"), (Ic, 2, "inertia_com"))
    C = hat(c)
    mm = m[..., None, None]
    batch = np.broadcast_shapes(m.shape, c.shape[:-1], Ic.shape[:-2])
    G = np.zeros((*batch, 6, 6))
    G[..., :3, :3] = Ic - mm * (C @ C)
    G[..., :3, 3:] = mm * C
    G[..., 3:, :3] = -mm * C
    G[..., 3:, 3:] = mm * np.eye(3)
    return G


def _bodies(G: object, J: object) -> tuple[np.ndarray, np.ndarray]:
    G = as_array(G, "G", (None, 6, 6))
    J = as_array(J, "J", (None, 6, None))
    broadcast_batch((G, 2, "G"), (J, 2, "J"))
    return G, J


def _rates(x: object, name: str, J: np.ndarray) -> np.ndarray:
    """A generalized-coordinate vector (..., n) matching ``J (..., B, 6, n)``; its batch excludes B."""
    a = as_array(x, name, (J.shape[-1],), min_ndim=1)
    broadcast_batch((J, 3, "J"), (a, 1, name))
    return a


def mass_matrix(G: np.ndarray, J: np.ndarray) -> np.ndarray:
    """``M = sum_b J_b^T G_b J_b`` for ``G (..., B, 6, 6)`` and ``J (..., B, 6, n)``."""
    G, J = _bodies(G, J)
    return np.einsum("...bia,...bij,...bjc->...ac", J, G, J)


def kinetic_energy(G: np.ndarray, J: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """``0.5 qd^T M qd`` (...)."""
    G, J = _bodies(G, J)
    qd = _rates(qd, "qd", J)
    V = np.einsum("...bij,...j->...bi", J, qd)
    return 0.5 * np.einsum("...bi,...bij,...bj->...", V, G, V)


@dataclass(frozen=True)
class DynamicsTerms:
    """``tau = M qdd + c + g_terms`` split into its parts (each (..., n); M (..., n, n))."""

    tau: np.ndarray
    M: np.ndarray
    velocity_terms: np.ndarray
    gravity_terms: np.ndarray


def inverse_dynamics(
    G: np.ndarray,
    J: np.ndarray,
    Jdot: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    gravity_body: np.ndarray | None = None,
    external_wrench_body: np.ndarray | None = None,
) -> DynamicsTerms:
    """Generalized forces for the motion (q, qd, qdd) of bodies with body Jacobians ``J``.

    ``Jdot (..., B, 6, n)`` is the time derivative of ``J`` along ``qd`` (see
    :func:`robomech.kinematics.jacobian_derivative`), ``gravity_body (..., B, 3)`` the gravity
    acceleration vector expressed in each body frame, and ``external_wrench_body (..., B, 6)`` a wrench
    ``[m; f]`` applied to each body about its frame origin (body axes).  The external wrench enters
    with a minus sign: tau is what the joints must supply.
    """
    G, J = _bodies(G, J)
    Jdot = as_array(Jdot, "Jdot", (None, 6, J.shape[-1]))
    broadcast_batch((J, 2, "J"), (Jdot, 2, "Jdot"))
    qd = _rates(qd, "qd", J)
    qdd = _rates(qdd, "qdd", J)
    if gravity_body is not None:
        gravity_body = as_array(gravity_body, "gravity_body", (None, 3))
        broadcast_batch((J, 2, "J"), (gravity_body, 1, "gravity_body"))
    if external_wrench_body is not None:
        external_wrench_body = as_array(external_wrench_body, "external_wrench_body", (None, 6))
        broadcast_batch((J, 2, "J"), (external_wrench_body, 1, "external_wrench_body"))
    V = np.einsum("...bij,...j->...bi", J, qd)
    Jd_qd = np.einsum("...bij,...j->...bi", Jdot, qd)
    GV = np.einsum("...bij,...bj->...bi", G, V)
    bias_w = np.einsum("...bji,...bj->...bi", ad(V), GV)  # ad(V)^T G V
    M = mass_matrix(G, J)
    vel = np.einsum("...bia,...bi->...a", J, np.einsum("...bij,...bj->...bi", G, Jd_qd) - bias_w)
    grav = np.zeros_like(vel)
    if gravity_body is not None:
        g6 = np.concatenate([np.zeros_like(gravity_body), gravity_body], axis=-1)
        grav = -np.einsum("...bia,...bi->...a", J, np.einsum("...bij,...bj->...bi", G, g6))
    if external_wrench_body is not None:
        grav = grav - np.einsum("...bia,...bi->...a", J, external_wrench_body)
    tau = np.einsum("...ij,...j->...i", M, qdd) + vel + grav
    return DynamicsTerms(tau=tau, M=M, velocity_terms=vel, gravity_terms=grav)


def static_torques(J: object, wrench: object) -> np.ndarray:
    """Virtual work: generalized forces balancing ``wrench`` applied where ``J`` maps q-rates to the twist.

    ``tau = J^T w`` for ``J (..., 6, n)``, ``w (..., 6)`` (or any matching m-vector, e.g. a force with a
    3xn translational Jacobian).
    """
    J = as_array(J, "J", (None, None))
    w = as_array(wrench, "wrench", (J.shape[-2],))
    broadcast_batch((J, 2, "J"), (w, 1, "wrench"))
    return np.einsum("...ij,...i->...j", J, w)


def actuator_forces(
    J_act: object, tau_q: object, *, rcond: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Actuator forces ``f`` with ``J_act^T f = tau_q`` of minimum norm, and the residual per sample.

    ``J_act (..., k, n)`` maps generalized rates to the k actuator rates (k >= n; k > n is redundant
    actuation, resolved here by the minimum-norm rule).  Returns ``(f (..., k), residual (...))``; a
    residual well above rounding flags a configuration where the actuators cannot balance ``tau_q``
    (an actuation singularity).  A sample with a non-finite entry gets NaN forces and a NaN residual
    and never reaches LAPACK (an SVD of an inf matrix does not return).
    """
    J_act = as_array(J_act, "J_act", (None, None), finite=False)
    if J_act.shape[-2] < J_act.shape[-1]:
        raise ValueError(f"Expected J_act (..., k, n) with k >= n actuators, got {J_act.shape}.")
    tau_q = as_array(tau_q, "tau_q", (J_act.shape[-1],), finite=False)
    rc = 1e-12 if rcond is None else check_positive(rcond, "rcond")
    batch = broadcast_batch((J_act, 2, "J_act"), (tau_q, 1, "tau_q"))
    k, n = J_act.shape[-2:]
    JT = np.broadcast_to(np.swapaxes(J_act, -1, -2), (*batch, n, k))
    tq = np.broadcast_to(tau_q, (*batch, n))
    good = finite_samples(JT, 2) & finite_samples(tq, 1)
    # Scale each system to unit size first: finite entries of 1e200 would overflow inside the SVD.
    size = np.max(np.abs(np.where(good[..., None, None], JT, 0.0)), axis=(-2, -1), initial=0.0)
    scale = np.where(good, size, 1.0)
    scale = np.where(scale > 0, scale, 1.0)
    f = np.full((*batch, k), np.nan)
    resid = np.full(batch, np.nan)
    if np.any(good):
        JTg = JT[good] / scale[good][:, None, None]
        tg = tq[good] / scale[good][:, None]
        fg = np.einsum("...ij,...j->...i", np.linalg.pinv(JTg, rcond=rc), tg)
        resid[good] = np.linalg.norm(np.einsum("...ij,...j->...i", JTg, fg) - tg, axis=-1) * scale[good]
        f[good] = fg
    return f, resid
