"""Rigid-body dynamics from body Jacobians (Lagrange's equations in matrix form) and virtual-work statics.

For a mechanism whose bodies b = 1..B have body twists ``V_b = J_b(q) qd`` (``J_b (..., B, 6, n)``,
body frames, ``[w; v]``), Lagrange's equations give

    tau = sum_b J_b^T ( G_b (J_b qdd + Jdot_b qd - g_b) - ad(V_b)^T G_b V_b )

with ``G_b`` the 6x6 spatial inertia in the body frame and ``g_b = [0; R_b^T g]`` gravity expressed
in the body frame.  This is exact for any holonomic mechanism once the closure is solved, i.e. once
``J_b`` maps the independent coordinates q (a parallel mechanism's platform angles, say) to each
body's twist: the constraint forces do no virtual work and drop out.  Actuator forces then follow by
virtual work from the actuator Jacobian (:func:`actuator_forces`).

The same equations about each body's centre of mass, in world axes (:func:`com_inverse_dynamics`,
used by :mod:`robomech.multibody` for any described mechanism): with ``[w_b; c_b'] = J_b qd`` the
angular velocity and the centre-of-mass velocity of body b (MuJoCo's ``mj_jacSite`` quantities at the
centre of mass), ``I_b`` its world-frame rotational inertia about the centre of mass and ``m_b`` its
mass,

    tau = sum_b J_b^T [ I_b wd_b + w_b x I_b w_b ;  m_b (c_b'' - g) ],   [wd_b; c_b''] = J_b qdd + Jdot_b qd,

which is Newton's and Euler's equations of each body projected onto the coordinates (virtual power).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from robomech._validation import as_array, broadcast_batch, check_positive, finite_samples
from robomech.spatial._se3 import ad
from robomech.spatial._so3 import _hat as hat

__all__ = [
    "ACTUATION_RESIDUAL_RTOL",
    "INERTIA_RTOL",
    "ActuatorForces",
    "DynamicsTerms",
    "actuator_forces",
    "com_inverse_dynamics",
    "com_kinetic_energy",
    "inverse_dynamics",
    "kinetic_energy",
    "mass_matrix",
    "spatial_inertia",
    "static_torques",
    "world_inertia",
]


# A rotational inertia is symmetric positive semidefinite (I = Σ m (|r|² 1 - r rᵀ)); both are tested
# relative to the largest entry: 1e-9 admits inertias assembled from rounded CAD values (and the zero
# moment of a thin rod about its axis) and refuses any with a negative principal moment, which no
# mass has (its kinetic energy would be negative).
INERTIA_RTOL = 1e-9


def _check_inertia(Ic: np.ndarray, name: str) -> None:
    """ValueError naming ``name`` unless every ``(3, 3)`` matrix is symmetric positive semidefinite."""
    if Ic.size == 0:
        return
    scale = np.max(np.abs(Ic), axis=(-2, -1), keepdims=True)
    scale = np.where(scale > 0, scale, 1.0)
    asym = np.max(np.abs(Ic - np.swapaxes(Ic, -1, -2)) / scale)
    if asym > INERTIA_RTOL:
        raise ValueError(f"Expected {name} to be symmetric, got an asymmetry of {asym:.3g} (relative).")
    ev = np.linalg.eigvalsh(0.5 * (Ic + np.swapaxes(Ic, -1, -2))) / scale[..., 0]  # (..., 3) ascending
    worst = ev[..., 0].reshape(-1)
    if worst.min() < -INERTIA_RTOL:
        k = int(np.argmin(worst))
        moments = (ev.reshape(-1, 3)[k] * scale.reshape(-1)[k]).tolist()
        raise ValueError(
            f"Expected {name} to be a rotational inertia (symmetric, principal moments >= 0), got "
            f"principal moments {[float(f'{x:.6g}') for x in moments]}."
        )


def spatial_inertia(mass: ArrayLike, com: ArrayLike, inertia_com: ArrayLike) -> np.ndarray:
    """6x6 spatial inertia about a body frame's origin for twists ``[w; v]``.

    ``G = [[I_c - m hat(c)^2, m hat(c)], [-m hat(c), m I]]``, so that the body's kinetic energy is
    ``0.5 V^T G V`` and its momentum ``G V`` (``[angular; linear]``, about the frame origin).

    Parameters
    ----------
    mass : float or array_like, shape (...)
        Mass (kg), ``>= 0``.
    com : array_like, shape (..., 3)
        Centre of mass in the body frame (m).
    inertia_com : array_like, shape (..., 3, 3)
        Rotational inertia about the centre of mass, body axes (kg m^2): symmetric with principal
        moments >= 0 (within ``INERTIA_RTOL``).

    Returns
    -------
    ndarray, shape (..., 6, 6)

    Raises
    ------
    ValueError
        If an array is not finite and real with the stated shape, ``mass`` is negative,
        ``inertia_com`` is not a rotational inertia, or the batch shapes do not broadcast.

    Examples
    --------
    >>> import numpy as np
    >>> G = spatial_inertia(2.0, [0.5, 0.0, 0.0], np.diag([0.01, 0.02, 0.02]))
    >>> float(G[2, 2])          # I_zz about the origin: 0.02 + 2 * 0.5**2 (parallel axes)
    0.52
    """
    m = as_array(mass, "mass")
    c = as_array(com, "com", (3,))
    Ic = as_array(inertia_com, "inertia_com", (3, 3))
    if np.any(m < 0):
        raise ValueError(f"Expected mass >= 0, got {mass!r}.")
    _check_inertia(Ic, "inertia_com")
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


def _bodies(G: ArrayLike, J: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    G = as_array(G, "G", (None, 6, 6))
    J = as_array(J, "J", (None, 6, None))
    broadcast_batch((G, 2, "G"), (J, 2, "J"))
    return G, J


def _rates(x: ArrayLike, name: str, J: np.ndarray) -> np.ndarray:
    """A generalized-coordinate vector (..., n) matching ``J (..., B, 6, n)``; its batch excludes B."""
    a = as_array(x, name, (J.shape[-1],), min_ndim=1)
    broadcast_batch((J, 3, "J"), (a, 1, name))
    return a


def mass_matrix(G: np.ndarray, J: np.ndarray) -> np.ndarray:
    """Joint-space mass matrix ``M = sum_b J_b^T G_b J_b``.

    Parameters
    ----------
    G : array_like, shape (..., B, 6, 6)
        Spatial inertia of each body in its body frame (:func:`spatial_inertia`).
    J : array_like, shape (..., B, 6, n)
        Body Jacobian of each body (body frame, ``[w; v]``), mapping the n independent coordinates.

    Returns
    -------
    ndarray, shape (..., n, n)
        Symmetric, in kg m^2 (revolute) / kg (prismatic) units.

    Examples
    --------
    >>> import numpy as np
    >>> G = spatial_inertia(2.0, [0.5, 0.0, 0.0], np.diag([0.01, 0.02, 0.02]))[None]  # one body (B = 1)
    >>> J = np.zeros((1, 6, 1)); J[0, 2, 0] = 1.0; J[0, 4, 0] = 0.0   # a link spinning about its z axis
    >>> mass_matrix(G, J)
    array([[0.52]])
    """
    G, J = _bodies(G, J)
    return np.einsum("...bia,...bij,...bjc->...ac", J, G, J)


def kinetic_energy(G: np.ndarray, J: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """Kinetic energy ``0.5 qd^T M qd`` of the bodies.

    Parameters
    ----------
    G : array_like, shape (..., B, 6, 6)
        Spatial inertias (body frames).
    J : array_like, shape (..., B, 6, n)
        Body Jacobians.
    qd : array_like, shape (..., n)
        Generalized rates (rad/s or m/s).

    Returns
    -------
    ndarray, shape (...)
        Energy (J).

    Examples
    --------
    >>> import numpy as np
    >>> G = spatial_inertia(2.0, [0.5, 0.0, 0.0], np.diag([0.01, 0.02, 0.02]))[None]  # one body (B = 1)
    >>> J = np.zeros((1, 6, 1)); J[0, 2, 0] = 1.0; J[0, 4, 0] = 0.0   # a link spinning about its z axis
    >>> float(kinetic_energy(G, J, np.array([2.0])))   # 0.5 * 0.52 * 2**2
    1.04
    """
    G, J = _bodies(G, J)
    qd = _rates(qd, "qd", J)
    V = np.einsum("...bij,...j->...bi", J, qd)
    return 0.5 * np.einsum("...bi,...bij,...bj->...", V, G, V)


@dataclass(frozen=True)
class DynamicsTerms:
    """``tau = M qdd + c + g_terms`` split into its parts (each (..., n); M (..., n, n)).

    The result of :func:`inverse_dynamics` and :func:`com_inverse_dynamics`; ``n`` the independent
    coordinates that the Jacobians map.

    Attributes
    ----------
    tau : ndarray, shape (..., n)
        Generalized forces the joints must supply (N m for revolute, N for prismatic coordinates).
    M : ndarray, shape (..., n, n)
        Symmetric mass matrix (kg m^2 / kg).
    velocity_terms : ndarray, shape (..., n)
        Coriolis and centrifugal forces ``c(q, qd)`` (N m or N).
    gravity_terms : ndarray, shape (..., n)
        Gravity forces, including any external wrenches' share (N m or N).
    """

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
    """Generalized forces for the motion ``(q, qd, qdd)`` of bodies with body Jacobians ``J``.

    ``tau = sum_b J_b^T ( G_b (J_b qdd + Jdot_b qd - g_b) - ad(V_b)^T G_b V_b ) - sum_b J_b^T W_b``:
    Lagrange's equations in matrix form (module docstring), exact for any holonomic mechanism once
    ``J`` maps its independent coordinates.

    Parameters
    ----------
    G : array_like, shape (..., B, 6, 6)
        Spatial inertia of each body in its body frame.
    J : array_like, shape (..., B, 6, n)
        Body Jacobians at q (body frames, ``[w; v]``).
    Jdot : array_like, shape (..., B, 6, n)
        Time derivative of ``J`` along ``qd`` (:func:`robomech.kinematics.jacobian_derivative`).
    qd, qdd : array_like, shape (..., n)
        Generalized rates and accelerations.
    gravity_body : array_like, shape (..., B, 3), optional
        Gravity acceleration expressed in each body frame (m/s^2), e.g. ``R_b^T [0, 0, -9.81]``.
    external_wrench_body : array_like, shape (..., B, 6), optional
        Wrench ``[m; f]`` applied to each body about its frame origin (body axes, N m and N); it
        enters with a minus sign: ``tau`` is what the joints must supply.

    Returns
    -------
    DynamicsTerms
        ``tau (..., n)`` and its parts: ``M (..., n, n)``, ``velocity_terms``, ``gravity_terms``
        (the latter includes the external wrenches), with ``tau = M qdd + velocity + gravity``.

    Examples
    --------
    >>> import numpy as np
    >>> G = spatial_inertia(2.0, [0.5, 0.0, 0.0], np.diag([0.01, 0.02, 0.02]))[None]  # one body (B = 1)
    >>> J = np.zeros((1, 6, 1)); J[0, 2, 0] = 1.0; J[0, 4, 0] = 0.0   # a link spinning about its z axis
    >>> Jdot = np.zeros_like(J)
    >>> terms = inverse_dynamics(G, J, Jdot, qd=np.array([0.0]), qdd=np.array([3.0]))
    >>> terms.tau.round(12)      # 0.52 kg m^2 * 3 rad/s^2
    array([1.56])
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


def static_torques(J: ArrayLike, wrench: ArrayLike) -> np.ndarray:
    """Virtual work: generalized forces ``tau = J^T w`` that balance a wrench where ``J`` maps q-rates.

    Parameters
    ----------
    J : array_like, shape (..., m, n)
        Jacobian from generalized rates to the twist (m = 6) or velocity (e.g. m = 3) where the wrench
        acts, in the frame of ``wrench``.
    wrench : array_like, shape (..., m)
        Wrench ``[m; f]`` (N m, N), or a force (N) for a 3 x n translational Jacobian.

    Returns
    -------
    ndarray, shape (..., n)
        ``J^T w`` (N m or N), the generalized forces equivalent to ``wrench`` by virtual work.

    Examples
    --------
    >>> import numpy as np
    >>> J = np.array([[0.0], [1.0], [0.0]])     # a 1 m link at q = 0: tip velocity (0, 1, 0) per rad/s
    >>> static_torques(J, np.array([0.0, -10.0, 0.0]))
    array([-10.])
    """
    J = as_array(J, "J", (None, None))
    w = as_array(wrench, "wrench", (J.shape[-2],))
    broadcast_batch((J, 2, "J"), (w, 1, "wrench"))
    return np.einsum("...ij,...i->...j", J, w)


# The actuators balance tau_q when |J_act^T f - tau_q| is at most this fraction of |tau_q| (a zero
# tau_q has the zero solution, residual 0): the minimum-norm solution of a consistent system has
# a residual of rounding (~1e-16 relative, amplified by the conditioning up to 1/rcond = 1e12 only at
# the cut-off); a configuration where tau_q has a component outside the range of J_act^T (an
# actuation singularity) leaves a residual of that component's size.
ACTUATION_RESIDUAL_RTOL = 1e-9


@dataclass(frozen=True)
class ActuatorForces:
    """Actuator forces per sample (the result of :func:`actuator_forces`).

    Attributes
    ----------
    forces : ndarray, shape (..., k)
        Minimum-norm actuator forces (N or N m); NaN for a sample with a non-finite entry.
    residual : ndarray, shape (...)
        ``|J_act^T f - tau_q|`` (the units of ``tau_q``); NaN for a sample with a non-finite entry.
    valid : ndarray of bool, shape (...)
        The sample is finite and the actuators balance ``tau_q``: ``residual`` at most
        ``ACTUATION_RESIDUAL_RTOL`` times ``|tau_q|``.
    """

    forces: np.ndarray
    residual: np.ndarray
    valid: np.ndarray


def actuator_forces(J_act: ArrayLike, tau_q: ArrayLike, *, rcond: float | None = None) -> ActuatorForces:
    """Actuator forces ``f`` with ``J_act^T f = tau_q`` of minimum norm, the residual and a mask per sample.

    ``J_act`` maps generalized rates to the k actuator rates (k >= n; k > n is redundant actuation,
    resolved here by the minimum-norm rule).  A residual above ``ACTUATION_RESIDUAL_RTOL`` flags a
    configuration where the actuators cannot balance ``tau_q`` (an actuation singularity): ``valid``
    False.  A sample with a non-finite entry (or one beyond ``MAX_MAGNITUDE``) gets NaN forces, a NaN
    residual and ``valid`` False, and never reaches LAPACK (an SVD of an inf matrix does not return).

    Parameters
    ----------
    J_act : array_like, shape (..., k, n)
        Actuator Jacobian (actuator rates per generalized rate), k >= n >= 1.
    tau_q : array_like, shape (..., n)
        Generalized forces to balance (N m or N).
    rcond : float, optional
        Relative cut-off of the pseudo-inverse (default 1e-12), after scaling each system to unit size.

    Returns
    -------
    ActuatorForces
        ``forces`` (..., k), ``residual`` (...) and ``valid`` (...).

    Raises
    ------
    ValueError
        If ``J_act`` is not a real array (..., k, n) with k >= n >= 1, ``tau_q`` not a real array
        (..., n), their batch shapes do not broadcast, or ``rcond`` is not a positive real number.

    Examples
    --------
    >>> import numpy as np
    >>> J_act = np.array([[1.0], [1.0]])             # two actuators driving one coordinate
    >>> r = actuator_forces(J_act, np.array([4.0]))
    >>> r.forces.round(12), float(r.residual.round(12)), bool(r.valid)   # shared equally (minimum norm)
    (array([2., 2.]), 0.0, True)
    """
    J_act = as_array(J_act, "J_act", (None, None), finite=False, nonempty=True)
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
    valid = np.zeros(batch, dtype=bool)
    if np.any(good):
        JTg = JT[good] / scale[good][:, None, None]
        tg = tq[good] / scale[good][:, None]
        fg = np.einsum("...ij,...j->...i", np.linalg.pinv(JTg, rcond=rc), tg)
        rg = np.linalg.norm(np.einsum("...ij,...j->...i", JTg, fg) - tg, axis=-1)
        resid[good] = rg * scale[good]
        valid[good] = np.isfinite(rg) & (rg <= ACTUATION_RESIDUAL_RTOL * np.linalg.norm(tg, axis=-1))
        f[good] = fg
    return ActuatorForces(forces=f, residual=resid, valid=valid)


def world_inertia(R: ArrayLike, inertia: ArrayLike) -> np.ndarray:
    """Rotational inertia in world axes ``R I R^T`` of a body at orientation ``R (..., 3, 3)``.

    ``inertia (..., 3, 3)`` is the inertia about the centre of mass in body axes (a principal
    inertia ``diag(d)`` in a frame ``R_i`` of the body is ``R_i diag(d) R_i^T``).

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
        Body orientations (rotation matrices, body to world).
    inertia : array_like, shape (..., 3, 3)
        Inertia about the centre of mass in body axes (kg m²).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Inertia about the centre of mass in world axes (kg m²).

    Examples
    --------
    >>> import numpy as np
    >>> Rz90 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    >>> np.diag(world_inertia(Rz90, np.diag([1.0, 2.0, 3.0])))    # x and y swap
    array([2., 1., 3.])
    """
    R = as_array(R, "R", (3, 3))
    Ic = as_array(inertia, "inertia", (3, 3))
    broadcast_batch((R, 2, "R"), (Ic, 2, "inertia"))
    return R @ Ic @ np.swapaxes(R, -1, -2)


def com_inverse_dynamics(
    mass: ArrayLike,
    inertia: ArrayLike,
    J: ArrayLike,
    Jdot_qd: ArrayLike,
    qd: ArrayLike,
    qdd: ArrayLike,
    gravity: ArrayLike = (0.0, 0.0, -9.81),
) -> DynamicsTerms:
    """Generalized forces from centre-of-mass Jacobians in world axes (Newton-Euler per body, projected).

    ``mass (..., B)``; ``inertia (..., B, 3, 3)`` world-axes inertia about each centre of mass
    (:func:`world_inertia`); ``J (..., B, 6, n)`` maps ``qd`` to ``[w; c']`` of each body (angular
    velocity, centre-of-mass velocity, world axes); ``Jdot_qd (..., B, 6)`` is ``Jdot qd`` (the
    velocity-product accelerations ``[wd; c'']`` at ``qdd = 0``); ``gravity (..., 3)`` the gravity
    acceleration (m/s^2).  Returns ``tau = M qdd + velocity_terms + gravity_terms`` with
    ``M = sum_b J_b^T diag(I_b, m_b 1) J_b``.

    Parameters
    ----------
    mass : array_like, shape (..., B)
        Body masses (kg).
    inertia : array_like, shape (..., B, 3, 3)
        World-axes inertia about each centre of mass (kg m²).
    J : array_like, shape (..., B, 6, n)
        ``[w; c']`` of each body per unit ``qd`` (rad/s, m/s; world axes).
    Jdot_qd : array_like, shape (..., B, 6)
        ``Jdot qd``: velocity-product accelerations (rad/s², m/s²).
    qd, qdd : array_like, shape (..., n)
        Generalized velocities and accelerations.
    gravity : array_like, shape (..., 3), optional
        Gravity acceleration (m/s²), default ``(0, 0, -9.81)``.

    Returns
    -------
    DynamicsTerms
        ``tau``, ``velocity_terms``, ``gravity_terms`` ``(..., n)`` (N or N m) and ``M (..., n, n)``.

    Examples
    --------
    >>> import numpy as np
    >>> J = np.zeros((1, 6, 1))
    >>> J[0, 5, 0] = 1.0                                  # one 2 kg body on a vertical slide
    >>> r = com_inverse_dynamics(np.array([2.0]), np.zeros((1, 3, 3)), J, np.zeros((1, 6)),
    ...                          np.array([0.0]), np.array([1.0]))
    >>> r.tau.round(12), r.gravity_terms.round(12)        # m (qdd + g): 2 (1 + 9.81) N
    (array([21.62]), array([19.62]))
    """
    m = as_array(mass, "mass", (None,))
    B = m.shape[-1]
    qd = as_array(qd, "qd", (None,))
    n = qd.shape[-1]
    # shapes are checked against mass (B bodies) and qd (n coordinates): a mismatch names both
    I = as_array(inertia, "inertia (B from mass)", (B, 3, 3))
    J = as_array(J, "J (B from mass, n from qd)", (B, 6, n))
    a0 = as_array(Jdot_qd, "Jdot_qd (B from mass)", (B, 6))
    qdd = as_array(qdd, "qdd (n from qd)", (n,))
    g = as_array(gravity, "gravity", (3,))
    broadcast_batch(
        (m, 1, "mass"),
        (I, 3, "inertia"),
        (J, 3, "J"),
        (a0, 2, "Jdot_qd"),
        (qd, 1, "qd"),
        (qdd, 1, "qdd"),
        (g, 1, "gravity"),
    )
    if np.any(m < 0):
        raise ValueError(f"Expected mass >= 0, got min {float(np.min(m))}.")
    return _com_terms(m, I, J, a0, qd, qdd, g)


def _com_terms(m, I, J, a0, qd, qdd, g) -> DynamicsTerms:
    """Kernel of :func:`com_inverse_dynamics` (inputs trusted, broadcast as documented).

    Products over the bodies are one matmul per sample on the stacked ``(3B, n)`` Jacobians; the 3x3
    products per body are written out elementwise (batched matmul of many tiny matrices is slow).
    """
    batch = np.broadcast_shapes(m.shape[:-1], I.shape[:-3], J.shape[:-3], a0.shape[:-2], qd.shape[:-1])
    B, n = J.shape[-3], J.shape[-1]
    J = np.broadcast_to(J, (*batch, B, 6, n))
    I = np.broadcast_to(I, (*batch, B, 3, 3))
    m = np.broadcast_to(m, (*batch, B))
    Jw, Jv = J[..., :3, :], J[..., 3:, :]

    def i_times(x):  # I_b x_b for x (..., B, 3, k)
        return (
            I[..., :, 0, None] * x[..., 0:1, :]
            + I[..., :, 1, None] * x[..., 1:2, :]
            + I[..., :, 2, None] * x[..., 2:3, :]
        )

    def stack(x):  # (..., B, 3, k) -> (..., 3B, k)
        return x.reshape(*x.shape[:-3], 3 * B, x.shape[-1])

    Jws, Jvs = stack(Jw), stack(Jv)
    w = (Jws @ qd[..., :, None]).reshape(*batch, B, 3)
    Iw = np.sum(I * w[..., None, :], axis=-1)
    mom = np.sum(I * a0[..., None, :3], axis=-1) + np.cross(w, Iw)
    frc = m[..., None] * a0[..., 3:]
    rhs = np.concatenate([mom, frc], axis=-1)  # (..., B, 6)
    vel = (np.swapaxes(J.reshape(*batch, 6 * B, n), -1, -2) @ rhs.reshape(*batch, 6 * B, 1))[..., 0]
    M = np.swapaxes(Jws, -1, -2) @ stack(i_times(Jw)) + np.swapaxes(Jvs, -1, -2) @ stack(
        m[..., None, None] * Jv
    )
    grav = -np.sum(m[..., None, None] * Jv, axis=-3).swapaxes(-1, -2) @ g[..., :, None]
    grav = grav[..., 0]
    tau = (M @ qdd[..., None])[..., 0] + vel + grav
    return DynamicsTerms(tau=tau, M=M, velocity_terms=vel, gravity_terms=grav)


def com_kinetic_energy(mass: ArrayLike, inertia: ArrayLike, J: ArrayLike, qd: ArrayLike) -> np.ndarray:
    """``0.5 sum_b (w_b . I_b w_b + m_b |c'_b|^2)`` with ``[w_b; c'_b] = J_b qd`` (...).

    Parameters
    ----------
    mass : array_like, shape (..., B)
        Body masses (kg).
    inertia : array_like, shape (..., B, 3, 3)
        World-axes inertia about each centre of mass (kg m²).
    J : array_like, shape (..., B, 6, n)
        ``[w; c']`` of each body per unit ``qd`` (world axes).
    qd : array_like, shape (..., n)
        Generalized velocities.

    Returns
    -------
    ndarray, shape (...)
        Kinetic energy (J).

    Examples
    --------
    >>> import numpy as np
    >>> J = np.zeros((1, 6, 1))
    >>> J[0, 5, 0] = 1.0
    >>> float(com_kinetic_energy(np.array([2.0]), np.zeros((1, 3, 3)), J, np.array([3.0])))  # m v² / 2
    9.0
    """
    m = as_array(mass, "mass", (None,))
    B = m.shape[-1]
    qd = as_array(qd, "qd", (None,))
    I = as_array(inertia, "inertia (B from mass)", (B, 3, 3))
    J = as_array(J, "J (B from mass, n from qd)", (B, 6, qd.shape[-1]))
    broadcast_batch((m, 1, "mass"), (I, 3, "inertia"), (J, 3, "J"), (qd, 1, "qd"))
    if np.any(m < 0):
        raise ValueError(f"Expected mass >= 0, got min {float(np.min(m))}.")
    V = np.einsum("...bin,...n->...bi", J, qd)
    w, v = V[..., :3], V[..., 3:]
    return 0.5 * (np.einsum("...bi,...bij,...bj->...", w, I, w) + np.einsum("...b,...bi,...bi->...", m, v, v))
