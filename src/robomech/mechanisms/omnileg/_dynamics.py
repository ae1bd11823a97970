"""Rigid-body dynamics of the OmniLeg (paper 2's Lagrange model ``M q̈ + V + G = τ + Jᵀ F``) and the static
force maps: the 22 bodies placed by the solved closure as jets (``_jet.py``), each body's Newton-Euler
equations projected on q (docs/mechanisms/omnileg.md, "Dynamics model")."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._batching import carries_failed_rows, chunked
from robomech._validation import as_array, broadcast_batch, check_bool, check_params
from robomech.analysis.lstsq import _damped_inverse

from . import _jet as jt
from ._chains import _shank_frames
from ._kinematics import jacobian
from ._params import OmniLeg, RigidBody

__all__ = [
    "BODY_NAMES",
    "FOOT_FORCE_CONVENTION",
    "DynamicsResult",
    "FootForceResult",
    "body_poses",
    "energy",
    "foot_force_from_torques",
    "gravity_torques",
    "inverse_dynamics",
    "mass_matrix",
    "static_torques",
]

# The one sign convention of every OmniLeg function taking or returning a foot force (inverse_dynamics,
# static_torques, foot_force_from_torques): F is the force applied TO the foot by its surroundings (the
# ground reaction; a force on the foot body in a multibody engine), hip frame, N.  It enters the motor
# torques as -Jᵀ F.  Paper 2's F_f (eqs. (47)-(50), the force the foot delivers) is -F.
FOOT_FORCE_CONVENTION = "applied to the foot"
# A foot Jacobian with sigma_min / sigma_max below this is treated as singular (γ ≈ 0, the fully
# extended shank): 1e-3 bounds the force amplification by 1e3 relative to the best-conditioned direction.
SINGULAR_RCOND = 1e-3
# Damping of the weak directions of the foot force at flagged samples, relative to sigma_max: equal to
# the singularity threshold, so that no direction is amplified by more than 1 / (2 SINGULAR_RCOND).
DAMPING_RELATIVE = SINGULAR_RCOND


# Samples per chunk of the dynamics kernel: bounds the memory of its temporaries (dozens of (3, N, 3)
# arrays, 2.4 MB each at this size) for huge batches; measured at no cost in speed (27 us/sample in
# chunks of 8k-32k samples vs 24 us/sample for one 1e5-sample block; 40 us/sample at 2k).
DYN_CHUNK = 32768


def _body_list() -> list[tuple[str, str]]:
    """(instance name, parameter key) of the 22 bodies, in a fixed order."""
    thigh = [(f"{b}_{k + 1}", b) for k in range(3) for b in ("hip_cross", "thigh_rod", "knee_cross")]
    drive = ["knee_plate", "drive_shaft_in", "drive_cross_a", "drive_rod", "drive_cross_b", "drive_shaft_out"]
    shank = [(f"{b}_{i + 1}", b) for i in range(3) for b in ("crank", "coupler")]
    return [*thigh, *((n, n.removesuffix("_a").removesuffix("_b")) for n in drive), *shank, ("foot", "foot")]


BODY_NAMES = tuple(name for name, _ in _body_list())


Cols3 = tuple[jt.Jet, jt.Jet, jt.Jet]  # the three columns of R_b
Cols = Cols3 | None  # None: R_b = I, translation only


def _rotate_cols(S: np.ndarray, cols: Cols3) -> Cols3:
    """The columns of ``S R`` for a constant rotation ``S`` and the columns of ``R``."""
    return (jt.rotate_const(S, cols[0]), jt.rotate_const(S, cols[1]), jt.rotate_const(S, cols[2]))


def _half_cross_sum(cols: Cols3, part: str) -> np.ndarray:
    """``½ Σ_j r_j × part(r_j)`` over the columns r_j (``part`` one of "vd", "vdd", "g")."""
    c0, c1, c2 = cols
    return 0.5 * (
        jt.cross3(c0.v, getattr(c0, part))
        + jt.cross3(c1.v, getattr(c1, part))
        + jt.cross3(c2.v, getattr(c2, part))
    )


def _poses(
    leg: OmniLeg, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray
) -> list[tuple[Cols, jt.Jet | np.ndarray]]:
    """(columns of R_b, o_b) of every body as jets, in the order of BODY_NAMES; ``q, qd, qdd (N, 3)``."""
    alpha, beta, gamma = jt.Jet.variables(q, qd, qdd)
    ca, sa, cb, sb = jt.cos(alpha), jt.sin(alpha), jt.cos(beta), jt.sin(beta)
    cg, sg = jt.cos(gamma), jt.sin(gamma)
    # thigh direction, eq. (9) / L1 multiplied through by cos α cos β (not mirrored beyond 90°, _kinematics)
    cbsa, cbca = cb * sa, cb * ca
    inv_n = jt.reciprocal(jt.sqrt(ca * ca + cbsa * cbsa))
    u = jt.stack([sb * ca * inv_n, -cbsa * inv_n, cbca * inv_n])
    knee = u * leg.L1
    zero = np.zeros(q.shape[0])
    one = cg * 0.0 + 1.0  # constant 1 as a jet (jt.stack needs one jet per stacked vector)
    # Second-joint axis x_k of chain k (carried by the crosses and the rod); fixed axis y_k of chain k.
    x1 = jt.stack([cb, zero, -sb])  # Ry(β) e_x
    x2 = jt.stack([zero, -ca, -sa])  # Rx(α) (-e_y)
    x_axes = [x1, x2, -x1]
    y_axes = [np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0]), np.array([0.0, -1.0, 0.0])]
    A_pts = [np.array(a) for a in ((0.0, leg.L3, 0.0), (leg.L3, 0.0, 0.0), (0.0, -leg.L3, 0.0))]  # eq. (7)
    out: list[tuple[Cols, jt.Jet | np.ndarray]] = []
    for k in range(3):
        xk = x_axes[k]
        # cross frame columns (x, y, z): x the carried axis, y the fixed axis, z = x × y
        R_cross = (xk, xk * 0.0 + y_axes[k], jt.cross(xk, y_axes[k]))
        R_rod = (xk, jt.cross(u, xk), u)
        out.append((R_cross, A_pts[k]))
        out.append((R_rod, A_pts[k]))
        out.append((R_cross, knee + A_pts[k]))
    out.append((None, knee))
    a1 = jt.stack([-sg, cg, zero])  # Rz(γ) e_y: input yoke arm of the drive cross
    Rz = (jt.stack([cg, sg, zero]), a1, jt.stack([zero, zero, one]))
    n_vec = jt.cross(a1, u)
    a2 = n_vec * jt.reciprocal(jt.sqrt(jt.dot(n_vec, n_vec))).expand()  # rod-side arm, ⟂ a1 and the rod
    R_dcross = (a2, a1, jt.cross(a2, a1))
    R_drod = (a2, jt.cross(u, a2), u)
    origin = np.zeros(3)
    out += [(Rz, origin), (R_dcross, origin), (R_drod, origin), (R_dcross, knee), (Rz, knee)]
    S = _shank_frames(leg.shank_azimuth)
    crank_dir = jt.stack([zero, -sg, cg])  # Rx(γ) e_z
    Rx_p = (jt.stack([one, zero, zero]), jt.stack([zero, cg, sg]), jt.stack([zero, -sg, cg]))
    Rx_m = (jt.stack([one, zero, zero]), jt.stack([zero, cg, -sg]), jt.stack([zero, sg, cg]))
    for i in range(3):
        C = knee + S[i] @ np.array([leg.shank_radius, 0.0, leg.knee_to_crank])
        D = C + jt.rotate_const(S[i], crank_dir) * leg.L4
        out.append((_rotate_cols(S[i], Rx_p), C))
        out.append((_rotate_cols(S[i], Rx_m), D))
    # the foot's z as a vector jet, so that a per-sample L4 (N, 1) broadcasts (a design study's legs)
    foot_origin = knee + (
        jt.stack([zero, zero, cg]) * (2.0 * leg.L4) + np.array([0.0, 0.0, leg.knee_to_crank])
    )
    out.append((None, foot_origin))
    return out


@dataclass(frozen=True)
class _Terms:
    tau_motion: np.ndarray  # Σ J_vᵀ m a_c + J_ωᵀ (I ω̇ + ω × I ω)   (N, 3)
    tau_gravity: np.ndarray  # -Σ m J_vᵀ g                            (N, 3)
    M: np.ndarray  # (N, 3, 3)
    kinetic: np.ndarray  # (N,)
    potential: np.ndarray  # (N,)
    R: np.ndarray  # (N, B, 3, 3) body rotations (B = 0 unless requested)
    p: np.ndarray  # (N, B, 3) centres of mass (B = 0 unless requested)


# paper 2, eqs. (26)-(31): the simplified Cardan drive.  Each drive body turns like the chain-1 body it
# replaces (cross CS_A4 like CS_A1, rod A4B4 like rod A1B1, cross CS_B4 like CS_B1) plus an independent
# spin γ̇ about the fixed Z0 (r_γ = [0 0 1]), its inertia carried by that body's rotation (eq. (31)).
_PAPER_DRIVE = {"drive_cross_a": "hip_cross_1", "drive_rod": "thigh_rod_1", "drive_cross_b": "knee_cross_1"}


def _terms(
    leg: OmniLeg,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    poses: bool = False,
    paper_drive: bool = False,
) -> _Terms:
    """Newton-Euler sums over the bodies projected on q (Lagrange's equations), ``q, qd, qdd (N, 3)``.

    For body b with centre of mass p_b, rotation R_b and inertia I_b (body axes):
    ``τ = Σ_b m_b (∂p_b/∂q)ᵀ (p̈_b - g) + (∂ω_b/∂q̇)ᵀ (I_s ω̇_b + ω_b × I_s ω_b)``, ``I_s = R_b I_b R_bᵀ``.
    """
    grav = np.asarray(leg.gravity)
    N = q.shape[0]
    tau_m = np.zeros((3, N))
    tau_g = np.zeros((3, N))
    M = np.zeros((3, 3, N))
    kin = np.zeros(N)
    pot = np.zeros(N)
    eye = np.broadcast_to(np.eye(3), (N, 3, 3))
    Rs, ps = [], []
    groups: dict[int, tuple[Cols3, np.ndarray]] = {}
    spun: dict[int, tuple[Cols3, np.ndarray]] = {}  # paper_drive: rotations that also spin by γ about Z0
    by_name: dict[str, Cols3] = {}  # the rotating bodies' columns
    for (cols, o), (name, key) in zip(_poses(leg, q, qd, qdd), _body_list(), strict=True):
        if cols is not None:
            by_name[name] = cols
        body: RigidBody = leg.bodies[key]
        m = body.mass  # a float, or (N,) per sample (a design study's legs)
        c = body.com_vector  # (3,) or (N, 3)
        # mass centre p = o + R c = o + Σ_j c_j r_j
        p = (
            o + c
            if cols is None
            else o
            + sum((cols[j] * c[..., j, None] for j in range(3) if np.any(c[..., j] != 0.0)), start=0.0 * c)
        )
        if isinstance(p, jt.Jet):
            tau_m += np.sum(p.g * (np.asarray(m)[..., None] * p.vdd), axis=-1)
            tau_g -= m * (p.g @ grav)
            M += m * np.sum(p.g[:, None] * p.g[None, :], axis=-1)
            kin += 0.5 * m * np.sum(p.vd * p.vd, axis=-1)
            pot -= m * (p.v @ grav)
            if poses:
                ps.append(p.v)
        else:  # a mass centre fixed in the hip frame (the hip crosses): potential only
            pot -= m * (np.asarray(p) @ grav)
            if poses:
                ps.append(np.broadcast_to(np.asarray(p, dtype=float), (N, 3)))
        if poses:
            Rs.append(eye if cols is None else np.stack([r.v for r in cols], axis=-1))
        if cols is None:
            continue
        if paper_drive and name in _PAPER_DRIVE:
            ref = by_name[_PAPER_DRIVE[name]]
            prev = spun.get(id(ref))
            spun[id(ref)] = (ref, body.inertia_matrix if prev is None else prev[1] + body.inertia_matrix)
            continue
        # bodies turning together (a U-joint's two crosses, the drive's two crosses and two shafts) share
        # one set of columns: their rotational terms are linear in the inertia, so sum the inertias
        prev = groups.get(id(cols))
        groups[id(cols)] = (cols, body.inertia_matrix if prev is None else prev[1] + body.inertia_matrix)
    ez = np.array([0.0, 0.0, 1.0])
    rot = [(c, i, False) for c, i in groups.values()] + [(c, i, True) for c, i in spun.values()]
    for cols, Iner, spin in rot:
        # ω = ½ Σ_j r_j × ṙ_j, ω̇ = ½ Σ_j r_j × r̈_j, ∂ω/∂q̇_k = ½ Σ_j r_j × ∂r_j/∂q_k  (columns r_j of R)
        w = _half_cross_sum(cols, "vd")
        wd = _half_cross_sum(cols, "vdd")
        Jw = _half_cross_sum(cols, "g")  # (3 q, N, 3 xyz)
        if spin:  # paper 2, eqs. (26), (29): ω = ω_chain1 + γ̇ Z0, and ω̇ = ω̇_chain1 + γ̈ Z0 (Z0 fixed)
            w = w + qd[:, 2:3] * ez
            wd = wd + qdd[:, 2:3] * ez
            Jw = Jw + np.stack([0 * ez, 0 * ez, ez])[:, None, :]
        # body-frame components x_b = Rᵀ x; the inertia then acts as a constant 3x3 matrix (BLAS)
        wb = np.stack([np.sum(r.v * w, axis=-1) for r in cols], axis=-1)
        wdb = np.stack([np.sum(r.v * wd, axis=-1) for r in cols], axis=-1)
        Jwb = np.stack([np.sum(r.v * Jw, axis=-1) for r in cols], axis=-1)  # (3 q, N, 3 body)
        Iwb = _inertia_times(Iner, wb)
        hb = _inertia_times(Iner, wdb) + jt.cross3(wb, Iwb)  # I ω̇ + ω × I ω in body axes
        tau_m += np.sum(Jwb * hb, axis=-1)
        M += np.sum(_inertia_times(Iner, Jwb)[:, None] * Jwb[None, :], axis=-1)
        kin += 0.5 * np.sum(wb * Iwb, axis=-1)
    R_all = np.stack(Rs, axis=1) if poses else np.zeros((N, 0, 3, 3))
    p_all = np.stack(ps, axis=1) if poses else np.zeros((N, 0, 3))
    return _Terms(tau_m.T, tau_g.T, np.moveaxis(M, -1, 0), kin, pot, R_all, p_all)


def _inertia_times(inertia: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``I x`` for body-axis vectors ``x (..., N, 3)``: one BLAS product for a constant ``I (3, 3)``, per
    sample for ``I (N, 3, 3)`` (a design study's legs)."""
    if inertia.ndim == 2:
        return x @ inertia.T
    return (
        inertia[..., 0] * x[..., 0, None]
        + inertia[..., 1] * x[..., 1, None]
        + inertia[..., 2] * x[..., 2, None]
    )


def _terms_chunked(
    leg: OmniLeg, q: np.ndarray, qd: np.ndarray | None = None, qdd: np.ndarray | None = None, **options: bool
) -> _Terms:
    """:func:`_terms` over cache-sized chunks of samples (identical results, far fewer cache misses);
    ``qd``, ``qdd`` zero where not given."""
    qd = np.zeros_like(q) if qd is None else qd
    qdd = np.zeros_like(q) if qdd is None else qdd
    return chunked(lambda s: _terms(leg, q[s], qd[s], qdd[s], **options), q.shape[0], DYN_CHUNK)


def _flat(*arrays: np.ndarray) -> tuple[tuple[int, ...], list[np.ndarray]]:
    batch = np.broadcast_shapes(*(a.shape[:-1] for a in arrays))
    return batch, [np.ascontiguousarray(np.broadcast_to(a, (*batch, 3)).reshape(-1, 3)) for a in arrays]


@carries_failed_rows({"q": 1})
def body_poses(leg: OmniLeg, q: object) -> tuple[np.ndarray, np.ndarray]:
    """Body rotations and mass centres (m) in the hip frame, in the order of ``BODY_NAMES``.

    Parameters
    ----------
    leg : OmniLeg
    q : array_like, shape (..., 3)

    Returns
    -------
    R, p : ndarray, shape (..., 22, 3, 3) and (..., 22, 3)
    """
    check_params(leg, OmniLeg, "leg")
    q = as_array(q, "q", (3,))
    batch, (qf,) = _flat(q)
    t = _terms_chunked(leg, qf, poses=True)
    B = len(BODY_NAMES)
    return t.R.reshape(*batch, B, 3, 3), t.p.reshape(*batch, B, 3)


@dataclass(frozen=True)
class DynamicsResult:
    """``tau = M q̈ + velocity_terms + gravity_terms + foot_terms`` (each (..., 3), N·m; M (..., 3, 3)).

    Attributes
    ----------
    tau : ndarray, shape (..., 3)
        Motor torques (N·m), α, β, γ order.
    M : ndarray, shape (..., 3, 3)
        Joint-space inertia matrix (kg m²).
    velocity_terms, gravity_terms, foot_terms : ndarray, shape (..., 3)
        Coriolis and centrifugal ``V(q, q̇)``, gravity ``G(q)`` and foot-force ``-Jᵀ F`` torques (N·m; the
        last zero without a foot force).
    """

    tau: np.ndarray
    M: np.ndarray
    velocity_terms: np.ndarray
    gravity_terms: np.ndarray
    foot_terms: np.ndarray


@carries_failed_rows({"q": 1, "qd": 1, "qdd": 1}, {"foot_force": 1})
def inverse_dynamics(
    leg: OmniLeg,
    q: object,
    qd: object,
    qdd: object,
    foot_force: object | None = None,
    *,
    paper_as_printed: bool = False,
) -> DynamicsResult:
    """Motor torques for the motion (q, q̇, q̈), optionally with a force on the foot.

    Parameters
    ----------
    leg : OmniLeg
    q, qd, qdd : array_like, shape (..., 3)
    foot_force : array_like, shape (..., 3), optional
        Force applied *to* the foot (N, hip frame; ``FOOT_FORCE_CONVENTION``: paper 2's ``F_f`` is -F).
    paper_as_printed : bool, optional
        Use paper 2's simplified Cardan drive (eqs. (26)-(31)) instead of the exact one, for comparison.

    Returns
    -------
    :class:`DynamicsResult`

    Examples
    --------
    >>> leg = OmniLeg.paper()
    >>> r = inverse_dynamics(leg, [[0.1, 0.2, 1.0]] * 4, np.zeros(3), np.zeros(3))
    >>> bool(np.allclose(r.tau, r.gravity_terms))   # at rest only gravity acts
    True
    """
    check_params(leg, OmniLeg, "leg")
    paper_as_printed = check_bool(paper_as_printed, "paper_as_printed")
    q = as_array(q, "q", (3,))
    qd = as_array(qd, "qd", (3,))
    qdd = as_array(qdd, "qdd", (3,))
    F = None if foot_force is None else as_array(foot_force, "foot_force", (3,))
    with_F = [] if F is None else [(F, 1, "foot_force")]
    full = broadcast_batch((q, 1, "q"), (qd, 1, "qd"), (qdd, 1, "qdd"), *with_F)
    q = np.broadcast_to(q, (*full, 3))  # a foot_force batch may extend the motion's
    batch, (qf, qdf, qddf) = _flat(q, qd, qdd)
    t = _terms_chunked(leg, qf, qdf, qddf, paper_drive=bool(paper_as_printed))
    vel = t.tau_motion - np.einsum("nij,nj->ni", t.M, qddf)
    foot = np.zeros_like(t.tau_motion)
    if F is not None:
        F = np.broadcast_to(F, (*batch, 3)).reshape(-1, 3)
        foot = -np.einsum("nij,ni->nj", jacobian(leg, qf), F)
    tau = t.tau_motion + t.tau_gravity + foot
    shp = (*batch, 3)
    return DynamicsResult(
        tau.reshape(shp),
        t.M.reshape(*batch, 3, 3),
        vel.reshape(shp),
        t.tau_gravity.reshape(shp),
        foot.reshape(shp),
    )


@carries_failed_rows({"q": 1})
def mass_matrix(leg: OmniLeg, q: object) -> np.ndarray:
    """Joint-space inertia matrix ``M(q)`` (kg m²; paper 2, eq. (46) with the exact Cardan drive).

    Parameters
    ----------
    leg : OmniLeg
    q : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    check_params(leg, OmniLeg, "leg")
    q = as_array(q, "q", (3,))
    batch, (qf,) = _flat(q)
    return _terms_chunked(leg, qf).M.reshape(*batch, 3, 3)


@carries_failed_rows({"q": 1})
def gravity_torques(leg: OmniLeg, q: object) -> np.ndarray:
    """Gravity torques ``G(q) = ∂V/∂q`` (N·m; eq. (46)): ``gravity_terms`` of :func:`inverse_dynamics`.

    Parameters
    ----------
    leg : OmniLeg
    q : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3)
    """
    check_params(leg, OmniLeg, "leg")
    q = as_array(q, "q", (3,))
    batch, (qf,) = _flat(q)
    return _terms_chunked(leg, qf).tau_gravity.reshape(*batch, 3)


@carries_failed_rows({"q": 1, "qd": 1})
def energy(leg: OmniLeg, q: object, qd: object) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic ``½ q̇ᵀ M q̇`` and potential ``-Σ m_b gᵀ p_b`` energy (J), the hip origin as datum.

    Parameters
    ----------
    leg : OmniLeg
    q, qd : array_like, shape (..., 3)

    Returns
    -------
    kinetic, potential : ndarray, shape (...)
    """
    check_params(leg, OmniLeg, "leg")
    q = as_array(q, "q", (3,))
    qd = as_array(qd, "qd", (3,))
    broadcast_batch((q, 1, "q"), (qd, 1, "qd"))
    batch, (qf, qdf) = _flat(q, qd)
    t = _terms_chunked(leg, qf, qdf)
    return t.kinetic.reshape(batch), t.potential.reshape(batch)


@carries_failed_rows({"q": 1}, {"force": 1})
def static_torques(leg: OmniLeg, q: object, force: object) -> np.ndarray:
    """Motor torques ``τ = -Jᵀ F`` (N·m) holding the leg against a foot force, gravity aside: the
    ``foot_terms`` of :func:`inverse_dynamics` (paper 2, eq. (50): τ = Jᵀ F_f, F_f = -F).

    Parameters
    ----------
    leg : OmniLeg
    q : array_like, shape (..., 3)
    force : array_like, shape (..., 3)
        Force applied to the foot (N, hip frame; ``FOOT_FORCE_CONVENTION``); broadcasts with ``q``.

    Returns
    -------
    ndarray, shape (..., 3)
    """
    check_params(leg, OmniLeg, "leg")
    q = as_array(q, "q", (3,))
    F = as_array(force, "force", (3,))
    broadcast_batch((q, 1, "q"), (F, 1, "force"))
    return -np.einsum("...ij,...i->...j", jacobian(leg, q), F)  # paper 2, eq. (50): +Jᵀ F_f, F_f = -F


@dataclass(frozen=True)
class FootForceResult:
    """Foot force from motor torques (the result of :func:`foot_force_from_torques`).

    Attributes
    ----------
    force : ndarray, shape (..., 3)
        Force applied to the foot (N, hip frame; ``FOOT_FORCE_CONVENTION``).
    singular : ndarray of bool, shape (...)
        ``rcond < SINGULAR_RCOND`` (γ ≈ 0): the force is the damped least-squares estimate there and
        ``residual`` is no longer zero.
    rcond : ndarray, shape (...)
        ``sigma_min / sigma_max`` of the foot Jacobian (dimensionless).
    residual : ndarray, shape (...)
        ``|-Jᵀ F - τ|`` (N·m).
    """

    force: np.ndarray
    singular: np.ndarray
    rcond: np.ndarray
    residual: np.ndarray


@carries_failed_rows({"q": 1}, {"tau": 1})
def foot_force_from_torques(leg: OmniLeg, q: object, tau: object) -> FootForceResult:
    """Solve ``-Jᵀ F = τ`` (the torques of :func:`static_torques`) for the force F applied to the foot
    (paper 2, eq. (47)) by SVD; the weak directions of samples with ``rcond < SINGULAR_RCOND`` are damped
    (``λ = DAMPING_RELATIVE σ_max``, selectively damped least squares).

    Parameters
    ----------
    leg : OmniLeg
    q : array_like, shape (..., 3)
    tau : array_like, shape (..., 3)
        Motor torques (N·m); broadcasts with ``q``.

    Returns
    -------
    :class:`FootForceResult`
    """
    check_params(leg, OmniLeg, "leg")
    q = as_array(q, "q", (3,))
    tau = as_array(tau, "tau", (3,))
    batch = broadcast_batch((q, 1, "q"), (tau, 1, "tau"))
    J = jacobian(leg, q)
    # Jᵀ = V Σ Uᵀ: only the directions with σ_i < SINGULAR_RCOND σ_max are damped
    s, solve = _damped_inverse(np.swapaxes(J, -1, -2), rtol=SINGULAR_RCOND, damping=DAMPING_RELATIVE)
    rcond = s[..., -1] / s[..., 0]
    singular = rcond < SINGULAR_RCOND
    # paper 2, eq. (47): F_f = (Jᵀ)⁻¹ τ for the force the foot delivers; the force applied to it is -F_f
    F_f, resid = solve(tau)  # |-Jᵀ F - τ|
    F = -F_f
    # the per-sample fields have the batch of every argument (q may be one configuration for many tau)
    return FootForceResult(
        force=F,
        singular=np.broadcast_to(singular, batch),
        rcond=np.broadcast_to(rcond, batch),
        residual=resid,
    )
