"""Rigid-body inverse dynamics of the spherical parallel leg (Kane's equations on q = (alpha, beta)) and
its redundant force distribution ``J^T f = tau``, replacing paper 1, eqs. (19)-(28) (errata, assumptions,
the Cardan spin that ``paper_as_printed=True`` drops: docs/mechanisms/spherical_leg.md)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from robomech._batching import carries_failed_rows
from robomech._validation import (
    as_array,
    broadcast_batch,
    check_bool,
    check_int,
    check_params,
    check_real,
    finite_samples,
)

from ._kinematics import LENGTH_FLOOR, _check_state, _rotation
from ._params import SphericalLeg

__all__ = [
    "ACTUATION_SIGMA_MIN",
    "CARDAN_LOCK_TOL",
    "PAPER_DRIVEN_LEGS",
    "ForceDistribution",
    "InverseDynamicsResult",
    "distribute_forces",
    "generalized_forces",
    "inverse_dynamics",
    "mass_matrix",
    "mechanical_energy",
]

# Paper 1, Section 2.1: the sway (alpha, beta) is driven by motors 7 and 9 through the two RUHU
# chains, legs 1 and 3 (indices 0 and 2); leg 2 (RUPR) carries the wheel lift.
PAPER_DRIVEN_LEGS = (0, 2)
# The actuation is singular where the leg Jacobian (or the driven legs' 2x2 block) loses rank: below
# this ratio sigma_min/sigma_max the 2x2 solve itself loses all accuracy (same threshold as
# robomech.analysis.workspace.SINGULAR_RTOL); the forces are NaN there.
ACTUATION_SINGULAR_RTOL = 1e-8
# Physical bound of the actuation (m/rad): sigma_min is the lever arm through which the legs hold the
# platform.  Below 1 mm/rad every N m needs more than 1 kN of leg force (10x the largest well-conditioned
# force of Fig. 5) and 10 um of leg-length error leaves more than 0.6 deg of platform play; such samples
# are flagged with their finite forces kept (docs/mechanisms/spherical_leg.md, "Actuation bound").
ACTUATION_SIGMA_MIN = 1e-3
# Gimbal lock of a base universal joint (the leg along its fixed axis: 1 - (a . s)^2 = 0, where the spin
# is unbounded): below this value (the leg within 1.8 deg of the axis, spin gain > 1000) a sample is
# flagged and the denominator floored.  The paper's motions stay above 0.036 (Fig. 5(a), leg 3).
CARDAN_LOCK_TOL = 1e-3


@dataclass(frozen=True)
class _Motion:
    """Per-body kinematic quantities (legs stacked on axis -2 of the (..., 3, 3) arrays)."""

    E: np.ndarray  # (..., 3, 2)
    w: np.ndarray  # platform angular velocity (..., 3)
    dw: np.ndarray
    p: np.ndarray  # platform centre (..., 3)
    Rp: np.ndarray  # platform rotation (..., 3, 3)
    s: np.ndarray  # (..., 3, 3) leg unit vectors
    sd: np.ndarray
    sdd: np.ndarray
    l: np.ndarray  # (..., 3)
    ld: np.ndarray
    ldd: np.ndarray
    Jl: np.ndarray  # (..., 3, 2) dl/dq
    Ps: np.ndarray  # (..., 3, 3, 2) d(sdot)/d(qd)
    sig: np.ndarray  # (..., 3) spin of each leg about its axis imposed by the base universal joint
    sigd: np.ndarray  # (..., 3) its rate
    Psig: np.ndarray  # (..., 3, 2) d(sig)/d(qd)
    lock: np.ndarray  # (...,) a base universal joint at or near gimbal lock (CARDAN_LOCK_TOL)


def _cardan_spin(
    a: np.ndarray, s: np.ndarray, sd: np.ndarray, sdd: np.ndarray, Ps: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Spin ``w . s`` of a body on a universal joint with fixed first axis ``a (3 legs, 3)``
    (docs/mechanisms/spherical_leg.md, assumption 3): ``sigma = kappa . sdot``, ``kappa = f(c) (a x s)``,
    ``f(c) = c / (1 - c^2)``, ``c = a . s``.  Returns sigma, its time derivative, its partial velocities
    ``kappa . Ps`` and the gimbal-lock mask (``1 - c^2 < CARDAN_LOCK_TOL``, denominator floored there)."""
    c = np.sum(a * s, -1)
    den = 1.0 - c * c
    lock = den < CARDAN_LOCK_TOL
    den = np.maximum(den, CARDAN_LOCK_TOL)
    f = c / den
    df = (1.0 + c * c) / (den * den)  # f'(c)
    axs = np.cross(a, s)
    kappa = f[..., None] * axs
    kappa_d = (df * np.sum(a * sd, -1))[..., None] * axs + f[..., None] * np.cross(a, sd)
    sig = np.sum(kappa * sd, -1)
    sigd = np.sum(kappa * sdd, -1) + np.sum(kappa_d * sd, -1)
    Psig = np.einsum("...li,...lik->...lk", kappa, Ps)
    return sig, sigd, Psig, np.any(lock, axis=-1)


def _motion(
    leg: SphericalLeg, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, cardan: bool = True
) -> _Motion:
    a, b = q[..., 0], q[..., 1]
    sa, ca, sb, cb = np.sin(a), np.cos(a), np.sin(b), np.cos(b)
    Rp = _rotation(sa, ca, sb, cb)
    E = np.zeros((*a.shape, 3, 2))
    E[..., 0, 0] = 1.0
    E[..., 1, 1] = ca
    E[..., 2, 1] = sa
    w = np.einsum("...ij,...j->...i", E, qd)
    # d/dt of E qd: the second column (0, cos a, sin a) turns with alpha
    Ed_qd = np.stack([np.zeros_like(a), -sa, ca], -1) * (qd[..., 0] * qd[..., 1])[..., None]
    dw = np.einsum("...ij,...j->...i", E, qdd) + Ed_qd
    # paper 1, eq. (21): printed lever arm h_p (the platform thickness); the centre P is at OP = h
    p = leg.h * Rp[..., :, 2]
    B = np.einsum("...ij,...kj->...ki", Rp, leg.platform_points_home)  # (..., 3 legs, 3)
    u = B - leg.base_points
    wl = w[..., None, :]
    ud = np.cross(wl, B)
    udd = np.cross(dw[..., None, :], B) + np.cross(wl, ud)
    l = np.maximum(np.linalg.norm(u, axis=-1), LENGTH_FLOOR)
    s = u / l[..., None]
    ld = np.sum(s * ud, -1)
    sd = (ud - s * ld[..., None]) / l[..., None]
    ldd = np.sum(s * udd, -1) + l * np.sum(sd * sd, -1)
    sdd = (udd - s * ldd[..., None] - 2 * sd * ld[..., None]) / l[..., None]
    # partial velocities: d(udot)/d(qd_k) = E_k x B_i
    U = np.cross(np.swapaxes(E, -1, -2)[..., None, :, :], B[..., :, None, :])  # (..., legs, k, 3)
    U = np.swapaxes(U, -1, -2)  # (..., legs, 3, k)
    Jl = np.einsum("...li,...lik->...lk", s, U)
    Ps = (U - s[..., :, None] * Jl[..., None, :]) / l[..., None, None]
    if cardan:
        sig, sigd, Psig, lock = _cardan_spin(leg.cardan_axes, s, sd, sdd, Ps)
    else:
        # paper 1, eq. (23): the leg's energy has only its swing (no spin about the leg axis); a base
        # universal joint imposes the spin sigma (_cardan_spin) -- kept here only for paper_as_printed
        sig, sigd, Psig, lock = np.zeros_like(l), np.zeros_like(l), np.zeros_like(Jl), np.zeros(a.shape, bool)
    return _Motion(E, w, dw, p, Rp, s, sd, sdd, l, ld, ldd, Jl, Ps, sig, sigd, Psig, lock)


def _driven_motion(
    leg: SphericalLeg, q: object, qd: object, qdd: object, platform_wrench: object, paper_as_printed: bool
) -> tuple[_Motion, np.ndarray | None]:
    """The validated boundary of the force functions: the motion and the platform wrench (or None)."""
    check_params(leg, SphericalLeg, "leg")
    qa, qda, qdda = _check_state(q, qd, qdd)
    w = None if platform_wrench is None else as_array(platform_wrench, "platform_wrench", (6,))
    if w is not None:
        broadcast_batch((qa, 1, "q, qd, qdd"), (w, 1, "platform_wrench"))
    cardan = not check_bool(paper_as_printed, "paper_as_printed")
    return _motion(leg, qa, qda, qdda, cardan), w


def _cross_cols(s: np.ndarray, P: np.ndarray) -> np.ndarray:
    """s (..., 3) x each column of P (..., 3, k) -> (..., 3, k)."""
    return np.swapaxes(np.cross(s[..., None, :], np.swapaxes(P, -1, -2)), -1, -2)


def _generalized(leg: SphericalLeg, m: _Motion, wrench: np.ndarray | None) -> np.ndarray:
    g = np.asarray(leg.gravity)
    # platform: partial velocity of p is -hat(p) E, so Pv^T F = E^T (p x F)
    mp = leg.platform_mass
    ap = np.cross(m.dw, m.p) + np.cross(m.w, np.cross(m.w, m.p))
    Fp = mp * (ap - g)
    Iw = m.Rp @ leg.platform_inertia @ np.swapaxes(m.Rp, -1, -2)
    Iww = np.einsum("...ij,...j->...i", Iw, m.w)
    n_p = np.einsum("...ij,...j->...i", Iw, m.dw) + np.cross(m.w, Iww)
    moment = n_p + np.cross(m.p, Fp)
    if wrench is not None:
        moment = moment - wrench[..., :3]  # the platform's twist about O is [w; 0]: only m_O works
    tau = np.einsum("...ik,...i->...k", m.E, moment)
    # legs (loop over the two bodies of every leg; legs are vectorised on axis -2)
    dwL = np.cross(m.s, m.sdd)
    PwL = _cross_cols(m.s, m.Ps)  # (..., legs, 3, 2)
    sJ = m.s[..., :, None] * m.Jl[..., None, :]  # (..., legs, 3, 2): s (dl/dq)
    k = leg.spin_ratio
    for pos, bodies in (("lower", leg.lower), ("upper", leg.upper)):
        mass = np.array([bd.mass for bd in bodies])
        It = np.array([bd.transverse_inertia for bd in bodies])
        if pos == "lower":
            d = np.array([0.5 * bd.length for bd in bodies])
            acc = d[:, None] * m.sdd
            Pv = d[:, None, None] * m.Ps
            # spin about s: the Cardan's sigma plus, on legs 1 and 3, the screw's own 2 pi ldot / lead
            sig, sigd, Psig = m.sig + k * m.ld, m.sigd + k * m.ldd, m.Psig + k[:, None] * m.Jl
        else:
            d = m.l - np.array([0.5 * bd.length for bd in bodies])
            acc = m.ldd[..., None] * m.s + 2 * m.ld[..., None] * m.sd + d[..., None] * m.sdd
            Pv = sJ + d[..., None, None] * m.Ps
            sig, sigd, Psig = m.sig, m.sigd, m.Psig  # the Cardan's spin only
        Ia = np.array([bd.axial_inertia for bd in bodies])
        # w = s x sdot + sig s; axisymmetric body: n = d/dt(It s x sdot + Ia sig s)
        #   = It s x sddot + Ia (dsig s + sig sdot)   (its gyroscopic part w x I w is inside)
        n = It[:, None] * dwL + Ia[:, None] * (sigd[..., None] * m.s + sig[..., None] * m.sd)
        Pw = PwL + m.s[..., :, None] * Psig[..., None, :]
        F = mass[:, None] * (acc - g)
        tau = tau + np.einsum("...lik,...li->...k", Pv, F) + np.einsum("...lik,...li->...k", Pw, n)
    return tau


@carries_failed_rows({"q": 1, "qd": 1, "qdd": 1}, {"platform_wrench": 1})
def generalized_forces(
    leg: SphericalLeg,
    q: object,
    qd: object,
    qdd: object,
    *,
    platform_wrench: object | None = None,
    paper_as_printed: bool = False,
) -> NDArray[np.float64]:
    """Generalized forces ``tau`` (..., 2) on (alpha, beta) (N m) the actuators supply for (q, qd, qdd).

    Near a gimbal lock of a base universal joint the values are finite but meaningless:
    :func:`inverse_dynamics` flags them (``CARDAN_LOCK_TOL``).

    Parameters
    ----------
    leg : SphericalLeg
    q, qd, qdd : array_like, shape (..., 2)
        Platform angles ``(alpha, beta)`` (rad), their rates and accelerations; broadcast together.
    platform_wrench : array_like, shape (..., 6), optional
        External wrench ``[m_O; f]`` (N m, N) on the platform, base frame, moment about O.
    paper_as_printed : bool, optional

    Returns
    -------
    ndarray, shape (..., 2)
    """
    return _generalized(leg, *_driven_motion(leg, q, qd, qdd, platform_wrench, paper_as_printed))


@carries_failed_rows({"q": 1})
def mass_matrix(leg: SphericalLeg, q: object, *, paper_as_printed: bool = False) -> NDArray[np.float64]:
    """Mass matrix M(q) (kg m^2, symmetric positive definite): tau = M qdd + c(q, qd) + g(q).

    Parameters
    ----------
    leg : SphericalLeg
    q : array_like, shape (..., 2)
    paper_as_printed : bool, optional

    Returns
    -------
    ndarray, shape (..., 2, 2)
    """
    check_params(leg, SphericalLeg, "leg")
    qa = as_array(q, "q", (2,))
    cardan = not check_bool(paper_as_printed, "paper_as_printed")
    zero_g = replace(leg, gravity=(0.0, 0.0, 0.0))
    cols = []
    for j in range(2):
        mo = _motion(zero_g, qa, np.zeros_like(qa), np.broadcast_to(np.eye(2)[j], qa.shape), cardan)
        cols.append(_generalized(zero_g, mo, None))
    return np.stack(cols, -1)


@carries_failed_rows({"q": 1, "qd": 1})
def mechanical_energy(
    leg: SphericalLeg, q: object, qd: object, *, paper_as_printed: bool = False
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Kinetic and potential energy of platform and legs.

    Parameters
    ----------
    leg : SphericalLeg
    q, qd : array_like, shape (..., 2)
    paper_as_printed : bool, optional

    Returns
    -------
    T, V : ndarray, shape (...)
        Kinetic and gravitational potential energy (J), V zero with every centre of mass at O.
    """
    check_params(leg, SphericalLeg, "leg")
    qa, qda = _check_state(q, qd)
    cardan = not check_bool(paper_as_printed, "paper_as_printed")
    m = _motion(leg, qa, qda, np.zeros_like(qa), cardan)
    g = np.asarray(leg.gravity)
    vp = np.cross(m.w, m.p)
    Iw = m.Rp @ leg.platform_inertia @ np.swapaxes(m.Rp, -1, -2)
    T = 0.5 * leg.platform_mass * np.sum(vp * vp, -1) + 0.5 * np.einsum("...i,...ij,...j->...", m.w, Iw, m.w)
    V = -leg.platform_mass * (m.p @ g)
    wL2 = np.sum(np.cross(m.s, m.sd) ** 2, -1)  # (..., legs)
    A = leg.base_points
    for pos, bodies in (("lower", leg.lower), ("upper", leg.upper)):
        mass = np.array([bd.mass for bd in bodies])
        It = np.array([bd.transverse_inertia for bd in bodies])
        Ia = np.array([bd.axial_inertia for bd in bodies])
        if pos == "lower":
            d = np.array([0.5 * bd.length for bd in bodies])
            v = d[:, None] * m.sd
            sig = m.sig + leg.spin_ratio * m.ld  # Cardan spin + the screw's own
        else:
            d = m.l - np.array([0.5 * bd.length for bd in bodies])
            v = m.ld[..., None] * m.s + d[..., None] * m.sd
            sig = m.sig
        c = A + d[..., None] * m.s
        T = T + 0.5 * np.sum(mass * np.sum(v * v, -1) + It * wL2 + Ia * sig * sig, -1)
        V = V - np.sum(mass * (c @ g), -1)
    return T, V


@dataclass(frozen=True)
class ForceDistribution:
    """Leg forces f with J^T f = tau (the result of :func:`distribute_forces`).

    Attributes
    ----------
    forces : ndarray, shape (..., 3)
        Leg forces (N, positive extends the leg); NaN where the solve is numerically singular
        (``rcond`` below ``ACTUATION_SINGULAR_RTOL``) or the input is not finite.
    residual : ndarray, shape (...)
        ``|J^T f - tau|`` (N m), rounding level where the solve is regular.
    valid : ndarray of bool, shape (...)
        False where ``sigma_min < sigma_min_bound`` (default ``ACTUATION_SIGMA_MIN``: an actuation
        singularity or its neighbourhood; f is then the exact but physically meaningless value) or the
        forces are NaN.
    sigma_min : ndarray, shape (...)
        Smallest singular value of J (minimum-norm rule) or of the driven legs' 2x2 block (m/rad): the
        lever arm through which the legs act; 0 where singular or non-finite.
    rcond : ndarray, shape (...)
        ``sigma_min`` over the largest singular value (unit-free).
    """

    forces: np.ndarray
    residual: np.ndarray
    valid: np.ndarray
    sigma_min: np.ndarray
    rcond: np.ndarray


def distribute_forces(
    J: object,
    tau: object,
    driven_legs: tuple[int, int] | None = None,
    *,
    sigma_min_bound: float = ACTUATION_SIGMA_MIN,
) -> ForceDistribution:
    """Leg forces balancing the generalized forces ``tau`` through ``J``: ``J^T f = tau``.

    ``driven_legs=None``: minimum-norm forces ``f = J (J^T J)^-1 tau`` (no internal preload);
    ``driven_legs=(i, j)``: only those two legs act (paper 1: ``PAPER_DRIVEN_LEGS``), the third carries none.

    Parameters
    ----------
    J : array_like, shape (..., 3, 2)
        Leg Jacobian (m/rad), e.g. from :func:`jacobian`; non-finite samples are flagged, not raised.
    tau : array_like, shape (..., 2)
        Generalized forces (N m); broadcast with ``J``; non-finite samples are flagged.
    driven_legs : tuple of int, optional
        Two different leg indices in 0..2.
    sigma_min_bound : float, optional
        Smallest acceptable lever arm (m/rad, >= 0) of a ``valid`` sample.

    Returns
    -------
    :class:`ForceDistribution`
    """
    J = as_array(J, "J", (3, 2), finite=False)
    t = as_array(tau, "tau", (2,), finite=False)
    broadcast_batch((J, 2, "J"), (t, 1, "tau"))
    bound = check_real(sigma_min_bound, "sigma_min_bound", low=0.0)  # m/rad
    # non-finite samples: zeroed before any arithmetic (then flagged by ok below), never propagated
    good = finite_samples(J, 2)[..., None] & finite_samples(t, 1)[..., None]
    J, t = np.where(good[..., None], J, 0.0), np.where(good, t, 0.0)
    if driven_legs is None:
        A = np.einsum("...ki,...kj->...ij", J, J)
        det = A[..., 0, 0] * A[..., 1, 1] - A[..., 0, 1] * A[..., 1, 0]
        tr = A[..., 0, 0] + A[..., 1, 1]
        # sigma_min^2 / sigma_max^2 of J from the 2x2 Gram matrix; cond ratio test on sigma
        ok = np.isfinite(det) & (det > (ACTUATION_SINGULAR_RTOL**2) * tr * tr)
        dsafe = np.where(ok, det, 1.0)
        inv = np.stack(
            [np.stack([A[..., 1, 1], -A[..., 0, 1]], -1), np.stack([-A[..., 1, 0], A[..., 0, 0]], -1)], -2
        )
        x = np.einsum("...ij,...j->...i", inv, t) / dsafe[..., None]
        f = np.einsum("...ij,...j->...i", J, x)
        smin, smax = _singular_values_2x2_gram(A)
    else:
        pair = tuple(driven_legs) if isinstance(driven_legs, tuple | list) else ()
        pair = tuple(check_int(x, "driven_legs", low=0, high=2) for x in pair)
        if len(pair) != 2 or pair[0] == pair[1]:
            raise ValueError(
                f"Expected driven_legs to be two different leg indices in 0..2, got {driven_legs!r}."
            )
        i, j = (int(x) for x in pair)
        Js = J[..., [i, j], :]  # (..., 2, 2)
        det = Js[..., 0, 0] * Js[..., 1, 1] - Js[..., 0, 1] * Js[..., 1, 0]
        scale = np.sum(Js * Js, axis=(-1, -2))
        ok = np.isfinite(det) & (np.abs(det) > ACTUATION_SINGULAR_RTOL * scale)
        dsafe = np.where(ok, det, 1.0)
        # solve Js^T fs = tau
        f0 = (Js[..., 1, 1] * t[..., 0] - Js[..., 1, 0] * t[..., 1]) / dsafe
        f1 = (-Js[..., 0, 1] * t[..., 0] + Js[..., 0, 0] * t[..., 1]) / dsafe
        f = np.zeros((*det.shape, 3))
        f[..., i] = f0
        f[..., j] = f1
        smin, smax = _singular_values_2x2_gram(np.einsum("...ki,...kj->...ij", Js, Js))
    ok = ok & good[..., 0]
    f = np.where(ok[..., None], f, np.nan)
    resid = np.linalg.norm(
        np.einsum("...ki,...k->...i", J, np.where(ok[..., None], f, 0.0)) - np.where(ok[..., None], t, 0.0),
        axis=-1,
    )
    finite = good[..., 0]  # a non-finite J (zeroed above) has no conditioning: 0
    smin = np.where(finite & np.isfinite(smin), smin, 0.0)
    smax = np.where(finite & np.isfinite(smax), smax, 0.0)
    rcond = np.where(smax > 0, smin / np.where(smax > 0, smax, 1.0), 0.0)
    valid = ok & (smin >= bound)
    return ForceDistribution(
        forces=f, residual=np.where(ok, resid, np.nan), valid=valid, sigma_min=smin, rcond=rcond
    )


def _singular_values_2x2_gram(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(sigma_min, sigma_max) of a matrix from its 2x2 Gram matrix ``A (..., 2, 2)`` (closed form)."""
    with np.errstate(invalid="ignore", over="ignore"):
        a, b, c = A[..., 0, 0], A[..., 0, 1], A[..., 1, 1]
        half_tr = 0.5 * (a + c)
        root = np.sqrt(np.maximum(0.25 * (a - c) ** 2 + b * b, 0.0))
        lmax = half_tr + root
        lmin = np.maximum(a * c - b * b, 0.0) / np.where(lmax > 0, lmax, 1.0)  # det / lmax: no cancellation
        return np.sqrt(lmin), np.sqrt(np.maximum(lmax, 0.0))


@dataclass(frozen=True)
class InverseDynamicsResult:
    """Generalized and leg forces of a platform motion (the result of :func:`inverse_dynamics`).

    Attributes
    ----------
    generalized_forces : ndarray, shape (..., 2)
        ``tau`` on (alpha, beta) (N m).
    leg_forces, residual, sigma_min, rcond : ndarray
        As ``forces``, ``residual``, ``sigma_min``, ``rcond`` of :class:`ForceDistribution`.
    valid : ndarray of bool, shape (...)
        As in :class:`ForceDistribution`, and False near a gimbal lock (``CARDAN_LOCK_TOL``).
    """

    generalized_forces: np.ndarray
    leg_forces: np.ndarray
    residual: np.ndarray
    valid: np.ndarray
    sigma_min: np.ndarray
    rcond: np.ndarray


@carries_failed_rows({"q": 1, "qd": 1, "qdd": 1}, {"platform_wrench": 1})
def inverse_dynamics(
    leg: SphericalLeg,
    q: object,
    qd: object,
    qdd: object,
    *,
    platform_wrench: object | None = None,
    driven_legs: tuple[int, int] | None = None,
    paper_as_printed: bool = False,
) -> InverseDynamicsResult:
    """Generalized forces and leg actuator forces for the platform motion (q, qd, qdd).

    :func:`generalized_forces` distributed by :func:`distribute_forces`; ``valid`` is also False near a
    gimbal lock of a base universal joint (``CARDAN_LOCK_TOL``).  With ``paper_as_printed`` the
    lead-screw spin still follows ``leg.screw_spin``.

    Parameters
    ----------
    leg : SphericalLeg
    q, qd, qdd : array_like, shape (..., 2)
        As in :func:`generalized_forces`.
    platform_wrench : array_like, shape (..., 6), optional
    driven_legs : tuple of int, optional
        As in :func:`distribute_forces`.
    paper_as_printed : bool, optional

    Returns
    -------
    :class:`InverseDynamicsResult`

    Examples
    --------
    >>> from robomech.mechanisms import spherical_leg as sl
    >>> q, qd, qdd = sl.fig5_motion("a", [0.0, 1.0])
    >>> res = sl.inverse_dynamics(sl.SphericalLeg.paper(), q, qd, qdd, driven_legs=(0, 2))
    >>> res.leg_forces.shape, res.valid
    ((2, 3), array([ True,  True]))
    """
    m, w = _driven_motion(leg, q, qd, qdd, platform_wrench, paper_as_printed)
    return _forces(leg, m, w, driven_legs)


def _forces(
    leg: SphericalLeg, m: _Motion, w: np.ndarray | None, driven_legs: tuple[int, int] | None
) -> InverseDynamicsResult:
    """:func:`inverse_dynamics` of the motion ``m`` (unvalidated; ``leg`` as :func:`_motion` takes it)."""
    tau = _generalized(leg, m, w)
    dist = distribute_forces(m.Jl, tau, driven_legs)
    valid = dist.valid & ~m.lock
    return InverseDynamicsResult(tau, dist.forces, dist.residual, valid, dist.sigma_min, dist.rcond)
