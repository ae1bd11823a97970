"""Static Cosserat-rod model of a tendon-driven continuum robot (the higher-fidelity reference of paper 3).

The model is that of Rucker & Webster, "Statics and Dynamics of Continuum Robots With General Tendon
Routing and External Loading", IEEE T-RO 27(6), 2011 (paper 3's ref. [16]), specialised to tendons
routed *parallel to the backbone* (constant offset ``r_i`` in the disk frames, the robot of paper 3),
written here independently and solved as a boundary-value problem with :func:`scipy.integrate.solve_bvp`.

Formulation (see ``docs/mechanisms/continuum_cosserat.md`` for the derivation)
-----------------------------------------------------------------------------
Arc length ``s`` in [0, L]; backbone position ``p(s)`` and orientation ``R(s)`` (body z = tangent);
body-frame strains ``u`` (curvature/torsion) and ``v`` (shear/stretch, ``v = e3`` when rigid):

    p' = R v,        R' = R û.

Instead of the rod's own internal moment, the state carries the internal wrench of the *composite*
(rod + the tendons crossing the section), ``N`` and ``M`` in the base frame.  The tendons are internal
to the composite (they are anchored to the rod at their termination), so with no distributed external
load ``N ≡ F_tip`` and ``M' = -p' × N`` with ``M(L) = L_tip``: the composite is a free Kirchhoff rod.
The rod's own wrench is the composite's minus the tendon pulls crossing the section:

    n_rod = N - Σ_i τ_i t_i,     m_rod = M - Σ_i τ_i (R r_i) × t_i,
    t_i = R (v + u × r_i) / |v + u × r_i|        (unit tangent of tendon i, straight routing r_i' = 0)

and the linear constitutive law ``m_rod = R K_bt u``, ``n_rod = R K_se (v - e3)`` closes the system.
This is exactly Rucker & Webster's model (frictionless tendons, tension constant along a tendon, point
load at the termination) — their distributed tendon load integrates to the same section balance —
but it keeps the ODE free of tendon-path derivatives.  The implicit pair (u, v) is solved at each
collocation point by Newton's method (analytic, always nonsingular 6×6 Jacobian; see ``_strains``).

Segments: tendon ``i`` terminates at the distal end of segment ``tendon_segment[i]``.  The composite
wrench is continuous there (the anchor load is internal); the set of active tendons changes, so each
segment is its own collocation interval (states stacked, continuity as boundary conditions).

Assumptions (stated, also in the docs): static equilibrium; no gravity or other distributed load;
frictionless tendons; the discrete disks are ignored (tendons follow the backbone continuously at
constant offset, no chord between disks); straight, stress-free reference rod (``u* = 0``); linear
elastic constitutive law; tip force and moment constant in the base frame (dead loads).
Base frame: ``p(0) = 0``, ``R(0) = I``, the undeformed rod along +z; tendon ``i`` at
``r_i = r (cos α_i, sin α_i, 0)`` in every disk frame.

The constant-curvature (CC) functions at the end of this file are an independent comparison helper for
the reference's own tests and its error table; the library's model ``robomech.mechanisms.continuum`` is
compared with this reference in ``robomech.verify.continuum``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import quad, solve_bvp
from scipy.optimize import brentq

from .._validation import as_array, check_positive

__all__ = [
    "BVP_TOL",
    "CCSolution",
    "CosseratSolution",
    "ErrorTable",
    "TendonRod",
    "base_balance_error",
    "constant_curvature_error_table",
    "constant_curvature_statics",
    "constant_curvature_transform",
    "elastica_cantilever_tip",
    "solve_static",
]

# ----------------------------------------------------------------------------------------------------
# Named numerical constants
# ----------------------------------------------------------------------------------------------------
BVP_TOL = 1e-8
"""solve_bvp ``tol``: relative collocation residual (nondimensional states are O(1)); gives tip
positions accurate to ~1e-9 L (measured by halving it, see tests), far below the CC errors studied."""
TABLE_BVP_TOL = 1e-6
"""BVP tolerance of the error table: tip positions differ by < 1e-8 L (measured 7.9e-9 L = 0.7 nm over
the default table) from BVP_TOL, negligible against the ≥ µm CC errors tabulated, at half the time."""
BVP_BC_TOL = 1e-10
"""solve_bvp ``bc_tol``: boundary conditions are linear in the states, so they are met to round-off."""
BVP_MAX_NODES_PER_SEGMENT = 3000
"""Mesh-size cap per segment for solve_bvp. A 90 mm segment needs < 600 nodes at BVP_TOL up to 1 N,
except just past the Euler load (1 N axial at a 15° bend: 1700 nodes); a diverging direct solve stops
here and the load continuation takes over."""
INITIAL_NODES_PER_SEGMENT = 21
"""Initial mesh per segment (refined by solve_bvp); the CC arc guess is already close."""
STRAIN_NEWTON_ITERATIONS = 12
"""Newton iterations of the implicit (u, v) solve per collocation point (analytic 6×6 Jacobian, always
nonsingular); from the straight-tendon start it reaches round-off in <= 6 iterations over the paper's
range (measured up to Σ τ r² / EI = 8: 9 cables at 15 N on the 0.8 mm core)."""
STRAIN_NEWTON_STOP = 1e-14
"""Newton step (nondimensional strain) below which the implicit solve stops: round-off of O(1) strains."""
CONTINUATION_FIRST_STEP = 0.25
"""If the direct solve fails, the load factor λ (tensions and tip wrench together) is ramped from 0 in
steps starting at 0.25 ..."""
CONTINUATION_GROWTH = 1.5
"""... grown by 1.5 after a converged step (natural continuation) ..."""
CONTINUATION_MIN_STEP = 1.0 / 256.0
"""... and halved after a failed one, down to 1/256 of the load; below it the case is reported as not
converged with the load fraction it reached (``load_fraction``)."""
CONSTITUTIVE_RESIDUAL_FACTOR = 10.0
"""Accepted mismatch between the shape curvature (spline derivative) and the constitutive curvature at
the output points, nondimensional (curvature · L), as a multiple of the BVP tolerance: the collocation
residual bounds the derivative error relative to (1 + |f|), measured ≤ 3e-3 tol at tol = 1e-8."""
CC_NEWTON_MAX_ITER = 60
"""Newton iterations of the CC statics (2 unknowns per segment); converges in < 10 from the unloaded arc."""
CC_NEWTON_TOL = 1e-8
"""Nondimensional virtual-work residual accepted by the CC statics Newton solve (round-off level)."""
CC_FD_STEP = 1e-6
"""Central-difference step (nondimensional curvature) for the CC tip Jacobian inside Newton; the
residual itself is exact, so the step only affects the convergence rate."""
CC_MAX_STEP = 0.5
"""Largest Newton step (nondimensional curvature, ≈ 29° of bend) in the CC statics; prevents overshoot."""


# ----------------------------------------------------------------------------------------------------
# Parameters
# ----------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class TendonRod:
    """Tendon-driven continuum robot as a Cosserat rod, in SI units.

    segment_lengths: (K,) m. bending_stiffness EI (N m²), torsional_stiffness GJ (N m²).
    axial_stiffness EA (N) or None (inextensible); shear_stiffness κGA (N) or None (unshearable).
    tendon_radius (n_t,) m, tendon_angle (n_t,) rad: hole at ``r (cos α, sin α, 0)`` in every disk frame.
    tendon_segment (n_t,): 0-based index of the segment at whose distal end the tendon terminates.
    """

    segment_lengths: tuple[float, ...]
    bending_stiffness: float
    torsional_stiffness: float
    axial_stiffness: float | None
    shear_stiffness: float | None
    tendon_radius: tuple[float, ...]
    tendon_angle: tuple[float, ...]
    tendon_segment: tuple[int, ...]

    def __post_init__(self) -> None:
        lengths = tuple(float(x) for x in np.atleast_1d(self.segment_lengths))
        if len(lengths) == 0:
            raise ValueError("Expected segment_lengths to hold at least one length, got none.")
        for k, ell in enumerate(lengths):
            check_positive(ell, f"segment_lengths[{k}]")
        object.__setattr__(self, "segment_lengths", lengths)
        check_positive(self.bending_stiffness, "bending_stiffness")
        check_positive(self.torsional_stiffness, "torsional_stiffness")
        if self.axial_stiffness is not None:
            check_positive(self.axial_stiffness, "axial_stiffness")
        if self.shear_stiffness is not None:
            check_positive(self.shear_stiffness, "shear_stiffness")
        radius = tuple(float(x) for x in np.atleast_1d(self.tendon_radius))
        angle = tuple(float(x) for x in np.atleast_1d(self.tendon_angle))
        seg = tuple(np.atleast_1d(self.tendon_segment).tolist())
        if not (len(radius) == len(angle) == len(seg)) or len(radius) == 0:
            raise ValueError(
                "Expected tendon_radius, tendon_angle and tendon_segment of one common length >= 1, got "
                f"{len(radius)}, {len(angle)}, {len(seg)}."
            )
        for i, r in enumerate(radius):
            check_positive(r, f"tendon_radius[{i}]")
        for i, a in enumerate(angle):
            if not math.isfinite(a):
                raise ValueError(f"Expected tendon_angle[{i}] finite, got {a!r}.")
        for i, k in enumerate(seg):
            if not (isinstance(k, int) and 0 <= k < len(lengths)):
                raise ValueError(
                    f"Expected tendon_segment[{i}] an integer in [0, {len(lengths) - 1}], got {k!r}."
                )
        object.__setattr__(self, "tendon_radius", radius)
        object.__setattr__(self, "tendon_angle", angle)
        object.__setattr__(self, "tendon_segment", seg)

    @property
    def n_segments(self) -> int:
        return len(self.segment_lengths)

    @property
    def n_tendons(self) -> int:
        return len(self.tendon_radius)

    @property
    def length(self) -> float:
        """Total backbone length (m)."""
        return float(sum(self.segment_lengths))

    @property
    def tendon_offsets(self) -> np.ndarray:
        """(n_t, 3) hole positions ``r_i`` in the disk frames (m)."""
        r = np.asarray(self.tendon_radius)
        a = np.asarray(self.tendon_angle)
        return np.stack([r * np.cos(a), r * np.sin(a), np.zeros_like(r)], axis=-1)

    @classmethod
    def from_round_rod(
        cls,
        *,
        segment_lengths: tuple[float, ...],
        rod_diameter: float,
        youngs_modulus: float,
        poisson_ratio: float,
        tendon_radius: tuple[float, ...],
        tendon_angle: tuple[float, ...],
        tendon_segment: tuple[int, ...],
        rigid_axial_shear: bool = False,
    ) -> TendonRod:
        """Stiffnesses of a solid round core rod.

        EI = E π d⁴/64, GJ = G π d⁴/32, EA = E π d²/4, κGA with κ = 6(1+ν)/(7+6ν) (solid circle).
        """
        d = check_positive(rod_diameter, "rod_diameter")
        e = check_positive(youngs_modulus, "youngs_modulus")
        nu = float(poisson_ratio)
        if not (math.isfinite(nu) and -1.0 < nu < 0.5):
            raise ValueError(f"Expected poisson_ratio in (-1, 0.5), got {poisson_ratio!r}.")
        g = e / (2.0 * (1.0 + nu))
        area = math.pi * d**2 / 4.0
        inertia = math.pi * d**4 / 64.0
        shear_coefficient = 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu)  # Timoshenko/Cowper, solid circle
        return cls(
            segment_lengths=segment_lengths,
            bending_stiffness=e * inertia,
            torsional_stiffness=g * 2.0 * inertia,
            axial_stiffness=None if rigid_axial_shear else e * area,
            shear_stiffness=None if rigid_axial_shear else shear_coefficient * g * area,
            tendon_radius=tendon_radius,
            tendon_angle=tendon_angle,
            tendon_segment=tendon_segment,
        )

    @classmethod
    def paper(
        cls,
        *,
        rod_diameter: float = 1.0e-3,
        youngs_modulus: float = 60e9,
        poisson_ratio: float = 0.33,
        hole_radius: float = 4.0e-3,
        rigid_axial_shear: bool = False,
    ) -> TendonRod:
        """Paper 3's robot: one 90 mm segment, 3 cables at 0°, 120°, 240° (eq. 4), NiTi core rod.

        The one "paper robot" of robomech: the same unprinted values as
        ``robomech.mechanisms.continuum.ContinuumRobot.paper()`` (a test checks it): core diameter
        1.0 mm, NiTi austenite E = 60 GPa (EI = 2.9e-3 N m²), ν = 0.33, cable-hole radius 4 mm.
        (A 0.8 mm core buckles between the disks at 12 N pretension, inside
        the paper's operating range; see ``ContinuumRobot.core_diameter``.)
        """
        return cls.from_round_rod(
            segment_lengths=(0.090,),
            rod_diameter=rod_diameter,
            youngs_modulus=youngs_modulus,
            poisson_ratio=poisson_ratio,
            tendon_radius=(hole_radius,) * 3,
            tendon_angle=(0.0, 2.0 * math.pi / 3.0, 4.0 * math.pi / 3.0),
            tendon_segment=(0, 0, 0),
            rigid_axial_shear=rigid_axial_shear,
        )


# ----------------------------------------------------------------------------------------------------
# Result
# ----------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class CosseratSolution:
    """Static Cosserat solution for a batch of load cases (batch shape ``B``).

    s: (n_s,) arc length (m) of the output points (segment ends included, once).
    position: (*B, n_s, 3) m; rotation: (*B, n_s, 3, 3) ``R_base_disk(s)``.
    curvature: (*B, n_s, 3) body-frame ``u`` (1/m) from the constitutive law (piecewise continuous;
    at a segment joint the proximal value). curvature_shape: (*B, n_s, 3) ``vee(Rᵀ R')`` from the
    collocation spline, i.e. the curvature the computed shape actually has.
    rod_moment: (*B, n_s, 3) rod internal moment ``m_rod`` (N m, base frame).
    T_tip: (*B, 4, 4) tip pose ``T_base_tip`` (rotation projected onto SO(3)).
    converged: (*B,) solve_bvp success and all residuals within tolerance.
    residual: (*B,) max relative collocation residual (solve_bvp's rms_residuals).
    bc_residual: (*B,) max abs boundary-condition residual (nondimensional).
    constitutive_residual: (*B,) max |curvature_shape - curvature| · L (nondimensional).
    contraction: (*B,) ``Σ τ r² / min(EI, GJ)``, the tendon-to-rod stiffness ratio (a diagnostic: the
    implicit strain solve is Newton and converges at any value).
    n_nodes: (*B,) final mesh size; seconds: wall time of the whole batch.
    load_fraction: (*B,) fraction λ of the load (tensions and tip wrench) that was solved: 1 where
    converged; where the continuation stalled, the outputs are the finite solution at that fraction
    (``converged`` False), never NaN.
    """

    s: np.ndarray
    position: np.ndarray
    rotation: np.ndarray
    curvature: np.ndarray
    curvature_shape: np.ndarray
    rod_moment: np.ndarray
    T_tip: np.ndarray
    converged: np.ndarray
    residual: np.ndarray
    bc_residual: np.ndarray
    constitutive_residual: np.ndarray
    contraction: np.ndarray
    n_nodes: np.ndarray
    load_fraction: np.ndarray
    seconds: float
    tensions: np.ndarray = field(repr=False)
    tip_force: np.ndarray = field(repr=False)
    tip_moment: np.ndarray = field(repr=False)


# ----------------------------------------------------------------------------------------------------
# Kernels (nondimensional: lengths / L, moments / (EI/L), forces / (EI/L²))
# ----------------------------------------------------------------------------------------------------
_E3 = np.array([0.0, 0.0, 1.0])


def _hat(u: np.ndarray) -> np.ndarray:
    """(3, m) -> (3, 3, m) skew matrices."""
    z = np.zeros_like(u[0])
    return np.array([[z, -u[2], u[1]], [u[2], z, -u[0]], [-u[1], u[0], z]])


@dataclass(frozen=True)
class _Nondim:
    ell: np.ndarray  # (K,) segment lengths / L
    kbt: np.ndarray  # (3,) bending/torsion stiffness / EI
    kse_inv: np.ndarray  # (3,) EI / (L² K_se), 0 where rigid
    r: np.ndarray  # (n_t, 3) offsets / L
    seg: np.ndarray  # (n_t,) termination segment


def _nondim(rod: TendonRod) -> _Nondim:
    L = rod.length
    ei = rod.bending_stiffness
    kbt = np.array([1.0, 1.0, rod.torsional_stiffness / ei])
    inv = [
        0.0 if k is None else ei / (L**2 * k)
        for k in (rod.shear_stiffness, rod.shear_stiffness, rod.axial_stiffness)
    ]
    return _Nondim(
        ell=np.asarray(rod.segment_lengths) / L,
        kbt=kbt,
        kse_inv=np.asarray(inv),
        r=rod.tendon_offsets / L,
        seg=np.asarray(rod.tendon_segment),
    )


def _strains(
    nd: _Nondim, k: int, tau: np.ndarray, R: np.ndarray, M: np.ndarray, F: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Solve the implicit constitutive relations in segment ``k`` at m points.

    R (3, 3, m), M (3, m), F (3,) nondimensional. Returns u (3, m), v (3, m), m_rod_body (3, m) and the
    unit tendon tangents in the body frame (n_a, 3, m) of the tendons active in segment k.

    Unknowns x = (u, v) per point; residual in compliance form

        g_u = u - K_bt⁻¹ (Rᵀ M - Σ τ r × t),   g_v = v - e3 - K_se⁻¹ (Rᵀ F - Σ τ t),

    t = b/|b|, b = v + u × r, solved by Newton with the analytic Jacobian I + C H,
    C = diag(K_bt⁻¹, K_se⁻¹), H = Σ (τ/|b|) Bᵀ (I - t tᵀ) B, B = db/dx = [-[r]×, I].  H is positive
    semidefinite, so I + C H is nonsingular at every tension: the fixed point u ← K⁻¹(...) used before
    contracts only while Σ τ r² < min(EI, GJ) (it failed for two segments at 5 N), Newton does not need it.
    """
    active = nd.seg >= k
    r = nd.r[active]  # (n_a, 3)
    t = tau[active]  # (n_a,)
    mb0 = np.einsum("jim,jm->im", R, M)  # Rᵀ M
    nb0 = np.einsum("jim,j->im", R, F)  # Rᵀ F
    m = R.shape[-1]
    n_a = len(t)
    C = np.concatenate([1.0 / nd.kbt, nd.kse_inv])[:, None]  # (6, 1)
    # start: every tendon along the body z axis (t = e3), exact for the straight rod
    pull_m0 = np.sum(t[:, None] * np.cross(r, _E3), axis=0)  # Σ τ r × e3
    u = (mb0 - pull_m0[:, None]) * C[:3]
    v = _E3[:, None] + (nb0 - np.sum(t) * _E3[:, None]) * C[3:]
    if n_a == 0:
        return u, v, u * nd.kbt[:, None], np.zeros((0, 3, m))
    rx = np.zeros((n_a, 3, 3))  # [r]× per tendon
    rx[:, 0, 1], rx[:, 0, 2] = -r[:, 2], r[:, 1]
    rx[:, 1, 0], rx[:, 1, 2] = r[:, 2], -r[:, 0]
    rx[:, 2, 0], rx[:, 2, 1] = -r[:, 1], r[:, 0]
    B = np.concatenate([-rx, np.broadcast_to(np.eye(3), rx.shape)], axis=-1)  # (n_a, 3, 6)
    eye6 = np.eye(6)

    def tangents(u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        b = v[None] - np.einsum("aij,jm->aim", rx, u)  # v + u × r = v - [r]× u, (n_a, 3, m)
        nb = np.sqrt(np.sum(b * b, axis=1))
        return b / nb[:, None], nb

    for _ in range(STRAIN_NEWTON_ITERATIONS):
        that, nb = tangents(u, v)
        pull_m = np.einsum("a,aij,ajm->im", t, rx, that)  # Σ τ r × t
        pull_f = np.einsum("a,aim->im", t, that)
        g = np.concatenate([u - (mb0 - pull_m) * C[:3], v - _E3[:, None] - (nb0 - pull_f) * C[3:]])
        P = np.eye(3)[None, :, :, None] - that[:, :, None, :] * that[:, None, :, :]  # (n_a, 3, 3, m)
        PB = np.einsum("aijm,ajk->aikm", P, B)
        H = np.einsum("am,aji,ajkm->mik", t[:, None] / nb, B, PB)  # (m, 6, 6)
        J = eye6 + C[None, :, :] * H
        dx = np.linalg.solve(J, -g.T[..., None])[..., 0].T  # (6, m)
        u, v = u + dx[:3], v + dx[3:]
        if np.max(np.abs(dx), initial=0.0) <= STRAIN_NEWTON_STOP:
            break
    that, _ = tangents(u, v)
    return u, v, u * nd.kbt[:, None], that


def _rhs_segment(nd: _Nondim, k: int, tau: np.ndarray, F: np.ndarray, y: np.ndarray) -> np.ndarray:
    """d/dσ of one segment's 15 states (p, R row-major, M) at m points; s = s_k + σ ℓ_k."""
    m = y.shape[-1]
    R = y[3:12].reshape(3, 3, m)
    M = y[12:15]
    u, v, _, _ = _strains(nd, k, tau, R, M, F)
    ell = nd.ell[k]
    dp = np.einsum("ijm,jm->im", R, v)
    dR = np.einsum("ikm,kjm->ijm", R, _hat(u))
    dM = -np.cross(dp, F[:, None], axis=0)
    return ell * np.concatenate([dp, dR.reshape(9, m), dM], axis=0)


def _cc_guess(nd: _Nondim, tau: np.ndarray, F: np.ndarray, Lm: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """Stacked initial guess: piecewise CC arcs of the unloaded robot, M from the global balance."""
    K = len(nd.ell)
    ys = []
    T = np.eye(4)
    u_xy = _cc_unloaded_curvature(nd, tau)  # (K, 2)
    poses = []
    for k in range(K):
        Ts = T @ _cc_transform_kernel(u_xy[k][None, :], nd.ell[k] * sigma)  # (m, 4, 4)
        poses.append(Ts)
        T = Ts[-1]
    p_tip = T[:3, 3]
    for k in range(K):
        Ts = poses[k]
        p = Ts[:, :3, 3].T
        R = Ts[:, :3, :3].reshape(-1, 9).T
        M = Lm[:, None] + np.cross(p_tip[:, None] - p, F[:, None], axis=0)
        ys.append(np.concatenate([p, R, M], axis=0))
    return np.concatenate(ys, axis=0)


def _solve_one(nd: _Nondim, tau: np.ndarray, F: np.ndarray, Lm: np.ndarray, tol: float):
    """One load case: direct solve from the CC arc; if that fails, natural continuation in a load factor
    λ that scales the tensions and the tip wrench together, from the straight unloaded rod (λ = 0, exact)
    to λ = 1, with adaptive steps (halved on failure, grown after success).  Returns the last solve, the
    (fun, bc) of the full load and the load fraction λ reached (1.0 when the full load was solved)."""
    K = len(nd.ell)

    def make(load: float):
        Fl, Ll, tl = load * F, load * Lm, load * tau

        def fun(x: np.ndarray, y: np.ndarray) -> np.ndarray:
            return np.concatenate([_rhs_segment(nd, k, tl, Fl, y[15 * k : 15 * k + 15]) for k in range(K)])

        def bc(ya: np.ndarray, yb: np.ndarray) -> np.ndarray:
            res = [ya[0:3], ya[3:12] - np.eye(3).ravel()]
            for k in range(K - 1):
                res.append(yb[15 * k : 15 * k + 15] - ya[15 * (k + 1) : 15 * (k + 1) + 15])
            res.append(yb[15 * (K - 1) + 12 : 15 * K] - Ll)
            return np.concatenate(res)

        return fun, bc

    def attempt(load: float, x: np.ndarray, y: np.ndarray):
        fun, bc = make(load)
        with np.errstate(all="ignore"):  # a diverging trial may overflow; it is then rejected
            s = solve_bvp(fun, bc, x, y, tol=tol, bc_tol=BVP_BC_TOL, max_nodes=BVP_MAX_NODES_PER_SEGMENT * K)
        ok = s.status == 0 and bool(np.all(np.isfinite(s.y)))
        return s, ok

    x0 = np.linspace(0.0, 1.0, INITIAL_NODES_PER_SEGMENT)
    sol, ok = attempt(1.0, x0, _cc_guess(nd, tau, F, Lm, x0))
    if ok:
        return sol, make(1.0), 1.0
    reached, step = 0.0, CONTINUATION_FIRST_STEP
    guess_x, guess_y = x0, _cc_guess(nd, 0.0 * tau, 0.0 * F, 0.0 * Lm, x0)
    best = None
    while reached < 1.0 and step >= CONTINUATION_MIN_STEP:
        target = min(1.0, reached + step)
        trial, ok = attempt(target, guess_x, guess_y)
        if ok:
            reached, best = target, trial
            guess_x, guess_y = trial.x, trial.y
            step *= CONTINUATION_GROWTH
        else:
            step *= 0.5
    if best is None:
        return sol, make(1.0), 0.0
    return best, make(1.0), reached


def _project_so3(R: np.ndarray) -> np.ndarray:
    U, _, Vt = np.linalg.svd(R)
    D = np.ones(R.shape[:-1])
    D[..., -1] = np.sign(np.linalg.det(U @ Vt))
    return (U * D[..., None, :]) @ Vt


def _loads(
    rod: TendonRod, tensions: object, tip_force: object, tip_moment: object
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Validated load case: tensions (*B, n_t) >= 0, tip force and moment (*B, 3), zero when None."""
    tau = as_array(tensions, "tensions", (rod.n_tendons,))
    if np.any(tau < 0.0):
        raise ValueError(f"Expected tensions >= 0 (a tendon cannot push), got min {tau.min()!r}.")
    F = as_array(np.zeros(3) if tip_force is None else tip_force, "tip_force", (3,))
    Lm = as_array(np.zeros(3) if tip_moment is None else tip_moment, "tip_moment", (3,))
    return tau, F, Lm


def solve_static(
    rod: TendonRod,
    tensions: object,
    tip_force: object = None,
    tip_moment: object = None,
    *,
    points_per_segment: int = 31,
    tol: float = BVP_TOL,
) -> CosseratSolution:
    """Solve the static Cosserat BVP for each load case of a batch.

    tensions (*B, n_t) N (>= 0: a tendon cannot push); tip_force, tip_moment (*B, 3) N, N m in the base
    frame (dead loads at the tip, default zero). Batch shapes broadcast. The batch is a Python loop over
    load cases (each a BVP); this is a reference model, its time is reported in ``seconds``.
    """
    n_t = rod.n_tendons
    tau, F, Lm = _loads(rod, tensions, tip_force, tip_moment)
    if not (isinstance(points_per_segment, int) and points_per_segment >= 2):
        raise ValueError(f"Expected points_per_segment an integer >= 2, got {points_per_segment!r}.")
    tol = check_positive(tol, "tol")
    batch = np.broadcast_shapes(tau.shape[:-1], F.shape[:-1], Lm.shape[:-1])
    tau_b = np.broadcast_to(tau, (*batch, n_t)).reshape(-1, n_t)
    F_b = np.broadcast_to(F, (*batch, 3)).reshape(-1, 3)
    L_b = np.broadcast_to(Lm, (*batch, 3)).reshape(-1, 3)

    nd = _nondim(rod)
    L, ei = rod.length, rod.bending_stiffness
    K = rod.n_segments
    sig = np.linspace(0.0, 1.0, points_per_segment)
    s_bounds = np.concatenate([[0.0], np.cumsum(rod.segment_lengths)])
    s_parts, sig_parts, seg_parts = [], [], []
    for k in range(K):
        keep = sig if k == 0 else sig[1:]
        s_parts.append(s_bounds[k] + keep * rod.segment_lengths[k])
        sig_parts.append(keep)
        seg_parts.append(np.full(keep.shape, k))
    s_out = np.concatenate(s_parts)
    n_s = s_out.size
    nb = tau_b.shape[0]
    pos = np.full((nb, n_s, 3), np.nan)
    rot = np.full((nb, n_s, 3, 3), np.nan)
    curv = np.full((nb, n_s, 3), np.nan)
    curv_shape = np.full((nb, n_s, 3), np.nan)
    mrod = np.full((nb, n_s, 3), np.nan)
    T_tip = np.full((nb, 4, 4), np.nan)
    conv = np.zeros(nb, bool)
    res = np.full(nb, np.inf)
    bcres = np.full(nb, np.inf)
    cres = np.full(nb, np.inf)
    contraction = np.sum(tau_b * np.asarray(rod.tendon_radius) ** 2, axis=-1) / min(
        ei, rod.torsional_stiffness
    )
    nodes = np.zeros(nb, int)
    fraction = np.zeros(nb)
    t0 = time.perf_counter()
    for b in range(nb):
        sol, (_fun, bc), fraction[b] = _solve_one(
            nd, tau_b[b] * L**2 / ei, F_b[b] * L**2 / ei, L_b[b] * L / ei, tol
        )
        # the outputs describe the load actually solved (fraction[b] of it; 1 when converged)
        taun = fraction[b] * tau_b[b] * L**2 / ei
        Fn = fraction[b] * F_b[b] * L**2 / ei
        nodes[b] = sol.x.size
        res[b] = float(np.max(sol.rms_residuals)) if sol.rms_residuals.size else np.inf
        bcres[b] = float(np.max(np.abs(bc(sol.y[:, 0], sol.y[:, -1]))))
        for k in range(K):
            sel = np.concatenate(seg_parts) == k
            sg = np.concatenate(sig_parts)[sel]
            y = sol.sol(sg)[15 * k : 15 * k + 15]
            dy = sol.sol(sg, 1)[15 * k : 15 * k + 15] / nd.ell[k]
            m = sg.size
            R = y[3:12].reshape(3, 3, m)
            u, _, mb, _ = _strains(nd, k, taun, R, y[12:15], Fn)
            dR = dy[3:12].reshape(3, 3, m)
            W = np.einsum("jim,jkm->ikm", R, dR)  # Rᵀ R' = û
            us = 0.5 * np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]])
            pos[b, sel] = (y[0:3] * L).T
            rot[b, sel] = np.moveaxis(R, -1, 0)
            curv[b, sel] = (u / L).T
            curv_shape[b, sel] = (us / L).T
            mrod[b, sel] = (np.einsum("ijm,jm->im", R, mb) * ei / L).T
        cres[b] = float(np.max(np.abs(curv_shape[b] - curv[b]))) * L
        T_tip[b] = np.eye(4)
        T_tip[b, :3, :3] = _project_so3(rot[b, -1])
        T_tip[b, :3, 3] = pos[b, -1]
        conv[b] = (
            sol.status == 0
            and res[b] <= tol
            and bcres[b] <= 10 * BVP_BC_TOL
            and fraction[b] == 1.0
            and cres[b] <= CONSTITUTIVE_RESIDUAL_FACTOR * tol
            and bool(np.all(np.isfinite(pos[b])))
        )
    seconds = time.perf_counter() - t0
    shp = batch
    return CosseratSolution(
        s=s_out,
        position=pos.reshape(*shp, n_s, 3),
        rotation=rot.reshape(*shp, n_s, 3, 3),
        curvature=curv.reshape(*shp, n_s, 3),
        curvature_shape=curv_shape.reshape(*shp, n_s, 3),
        rod_moment=mrod.reshape(*shp, n_s, 3),
        T_tip=T_tip.reshape(*shp, 4, 4),
        converged=conv.reshape(shp),
        residual=res.reshape(shp),
        bc_residual=bcres.reshape(shp),
        constitutive_residual=cres.reshape(shp),
        contraction=contraction.reshape(shp),
        n_nodes=nodes.reshape(shp),
        load_fraction=fraction.reshape(shp),
        seconds=seconds,
        tensions=np.broadcast_to(tau, (*batch, n_t)).copy(),
        tip_force=np.broadcast_to(F, (*batch, 3)).copy(),
        tip_moment=np.broadcast_to(Lm, (*batch, 3)).copy(),
    )


def base_balance_error(rod: TendonRod, sol: CosseratSolution) -> np.ndarray:
    """Global static balance at the base, (*B,) relative error.

    Free body: everything distal of the base section (rod + tendons). Its loads are the tip wrench, the
    rod's base moment ``m_rod(0) = R(0) K u_shape(0)`` (from the *shape* of the solution, the spline
    derivative, not from the ODE's moment state) and the tendon pulls ``τ_i t_i(0)`` applied at the holes
    ``R(0) r_i``. Moment balance about the base origin:

        m_rod(0) + Σ_i (R(0) r_i) × (τ_i t_i(0)) = L_tip + p(L) × F_tip.

    Returned as |lhs - rhs| / (EI / L).
    """
    R0 = sol.rotation[..., 0, :, :]
    u0 = sol.curvature_shape[..., 0, :]
    kbt = np.array([rod.bending_stiffness, rod.bending_stiffness, rod.torsional_stiffness])
    m0 = np.einsum("...ij,...j->...i", R0, kbt * u0)
    r = rod.tendon_offsets  # (n_t, 3)
    # tendon tangents at s = 0 in the body frame: (v + u × r)/|.|, v from the constitutive law
    kse_inv = np.array(
        [
            0.0 if k is None else 1.0 / k
            for k in (rod.shear_stiffness, rod.shear_stiffness, rod.axial_stiffness)
        ]
    )
    tb = np.broadcast_to(_E3, u0.shape)[..., None, :] + np.cross(u0[..., None, :], r)
    that = tb / np.linalg.norm(tb, axis=-1, keepdims=True)
    nb = np.einsum("...ji,...j->...i", R0, sol.tip_force) - np.einsum("...a,...ai->...i", sol.tensions, that)
    v0 = _E3 + nb * kse_inv
    tb = v0[..., None, :] + np.cross(u0[..., None, :], r)
    that = tb / np.linalg.norm(tb, axis=-1, keepdims=True)
    arm = np.einsum("...ij,aj->...ai", R0, r)
    pull = np.einsum("...a,...ij,...aj->...ai", sol.tensions, R0, that)
    lhs = m0 + np.sum(np.cross(arm, pull), axis=-2)
    rhs = sol.tip_moment + np.cross(sol.position[..., -1, :], sol.tip_force)
    return np.linalg.norm(lhs - rhs, axis=-1) / (rod.bending_stiffness / rod.length)


# ----------------------------------------------------------------------------------------------------
# Independent reference: the Euler elastica cantilever (quadrature, no ODE solver)
# ----------------------------------------------------------------------------------------------------
ELASTICA_QUAD_TOL = 1e-11
"""Absolute/relative quad tolerance of the elastica integrals (1/sqrt endpoint handled by weight='alg')."""


def elastica_cantilever_tip(
    bending_stiffness: float, length: float, load: float
) -> tuple[float, float, float]:
    """Tip of an inextensible cantilever (clamped along +x) under a dead transverse tip load ``load`` (+y).

    Classical elastica by quadrature: with θ the tangent angle, EI θ'²/2 = P (sin θ_L - sin θ), so
    L = sqrt(EI/2P) ∫₀^θ_L dθ / sqrt(sin θ_L - sin θ), x_L = sqrt(2 EI sin θ_L / P),
    y_L = sqrt(EI/2P) ∫₀^θ_L sin θ dθ / sqrt(sin θ_L - sin θ). Returns (x_L, y_L, θ_L) in m, m, rad.
    """
    ei = check_positive(bending_stiffness, "bending_stiffness")
    ell = check_positive(length, "length")
    P = check_positive(load, "load")
    c = math.sqrt(ei / (2.0 * P))

    def integral(theta_l: float, numerator) -> float:
        # (sin θ_L - sin θ) = (θ_L - θ) g(θ), g > 0 for θ_L < π/2; weight (θ_L - θ)^(-1/2)
        def f(th: float) -> float:
            # sin θ_L - sin θ = 2 cos((θ_L+θ)/2) sin(d/2), d = θ_L - θ: no cancellation near θ = θ_L
            d = theta_l - th
            g = math.cos(0.5 * (theta_l + th)) * (math.sin(0.5 * d) / (0.5 * d) if d > 0 else 1.0)
            return numerator(th) / math.sqrt(g)

        val, _ = quad(
            f,
            0.0,
            theta_l,
            weight="alg",
            wvar=(0.0, -0.5),
            epsabs=ELASTICA_QUAD_TOL,
            epsrel=ELASTICA_QUAD_TOL,
        )
        return val

    theta_l = brentq(
        lambda th: c * integral(th, lambda t: 1.0) - ell, 1e-9, math.pi / 2 - 1e-6, xtol=1e-15, rtol=1e-15
    )
    x_l = math.sqrt(2.0 * ei * math.sin(theta_l) / P)
    y_l = c * integral(theta_l, math.sin)
    return x_l, y_l, theta_l


# ----------------------------------------------------------------------------------------------------
# Constant-curvature comparison helper (tests and error table only; the library model,
# robomech.mechanisms.continuum, is compared in robomech.verify.continuum)
# ----------------------------------------------------------------------------------------------------
def _cc_transform_kernel(u_xy: np.ndarray, ell: np.ndarray) -> np.ndarray:
    """Arc of constant body curvature (u_x, u_y, 0) over length ell: (..., 4, 4), finite at u = 0."""
    u_xy, ell = np.broadcast_arrays(u_xy, np.asarray(ell)[..., None])
    ell = ell[..., 0]
    w = np.concatenate([u_xy * ell[..., None], np.zeros_like(ell)[..., None]], axis=-1)  # rotation vector
    theta = np.linalg.norm(w, axis=-1)
    W = np.zeros((*w.shape[:-1], 3, 3))
    W[..., 0, 1], W[..., 0, 2], W[..., 1, 2] = -w[..., 2], w[..., 1], -w[..., 0]
    W = W - np.swapaxes(W, -1, -2)
    sinc = np.sinc(theta / np.pi)
    half = np.sinc(theta / (2 * np.pi))
    R = np.eye(3) + sinc[..., None, None] * W + 0.5 * (half**2)[..., None, None] * (W @ W)
    # p = ∫₀^ℓ R(s) e3 ds = ℓ [sin θ/θ e3 + (1 - cos θ)/θ² (w × e3)], (1 - cos θ)/θ² = ½ sinc²(θ/2)
    wxe3 = np.stack([w[..., 1], -w[..., 0], np.zeros_like(theta)], axis=-1)
    p = ell[..., None] * (sinc[..., None] * _E3 + 0.5 * (half**2)[..., None] * wxe3)
    T = np.zeros((*theta.shape, 4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = p
    T[..., 3, 3] = 1.0
    return T


def constant_curvature_transform(curvature_xy: object, length: object) -> np.ndarray:
    """CC arc pose (..., 4, 4) for body curvature (u_x, u_y) (..., 2) in 1/m over ``length`` (...,) m.

    Equals Rz(β) Ry(θ) Rz(-β) with θ = ℓ|u|, bending direction (cos β, sin β) = (u_y, -u_x)/|u|.
    """
    u = as_array(curvature_xy, "curvature_xy", (2,))
    ell = as_array(length, "length")
    if np.any(ell < 0):
        raise ValueError("Expected length >= 0.")
    return _cc_transform_kernel(u, ell)


def _cc_unloaded_curvature(nd: _Nondim, tau: np.ndarray) -> np.ndarray:
    """(K, 2) body curvature of each segment for tensions tau (consistent units): EI u = Σ τ e3 × r."""
    K = len(nd.ell)
    out = np.zeros((K, 2))
    for k in range(K):
        active = nd.seg >= k
        m = np.sum(tau[active, None] * np.cross(_E3, nd.r[active]), axis=0)
        out[k] = m[:2] / nd.kbt[:2]
    return out


@dataclass(frozen=True)
class CCSolution:
    """CC statics result: curvature (*B, K, 2) 1/m, T_tip (*B, 4, 4), converged (*B,), residual (*B,)."""

    curvature: np.ndarray
    T_tip: np.ndarray
    converged: np.ndarray
    residual: np.ndarray


def _cc_tip(nd: _Nondim, u: np.ndarray) -> np.ndarray:
    """u (..., K, 2) nondim -> tip pose (..., 4, 4) nondim."""
    T = np.broadcast_to(np.eye(4), (*u.shape[:-2], 4, 4))
    for k in range(len(nd.ell)):
        T = T @ _cc_transform_kernel(u[..., k, :], np.full(u.shape[:-2], nd.ell[k]))
    return T


def constant_curvature_statics(
    rod: TendonRod, tensions: object, tip_force: object = None, tip_moment: object = None
) -> CCSolution:
    """Constant-curvature statics by virtual work (each segment an arc, no torsion, no axial strain).

    Unknowns: body curvature (u_x, u_y) per segment. Balance per segment k:
    ℓ_k (EI u_k - Σ_{i through k} τ_i (e3 × r_i)_xy) - J_k(u)ᵀ F - J_ωk(u)ᵀ L = 0, with J the tip
    linear/angular velocity Jacobians of the chained arcs (central differences) — the generalized force of
    the dead tip wrench. Batched Newton from the unloaded arcs. tensions (*B, n_t), loads (*B, 3).
    """
    n_t = rod.n_tendons
    tau, F, Lm = _loads(rod, tensions, tip_force, tip_moment)
    batch = np.broadcast_shapes(tau.shape[:-1], F.shape[:-1], Lm.shape[:-1])
    L, ei = rod.length, rod.bending_stiffness
    nd = _nondim(rod)
    K = rod.n_segments
    taun = np.broadcast_to(tau, (*batch, n_t)) * L**2 / ei
    Fn = np.broadcast_to(F, (*batch, 3)) * L**2 / ei
    Ln = np.broadcast_to(Lm, (*batch, 3)) * L / ei
    # tendon moment per segment (nondim), (*B, K, 2)
    act = (nd.seg[None, :] >= np.arange(K)[:, None]).astype(float)  # (K, n_t)
    exr = np.cross(_E3, nd.r)[:, :2]  # (n_t, 2)
    m_t = np.einsum("kt,...t,ti->...ki", act, taun, exr)
    u = m_t / nd.kbt[:2]
    ell = nd.ell[:, None]

    def resid(u: np.ndarray) -> np.ndarray:
        T0 = _cc_tip(nd, u)
        g = ell * (u * nd.kbt[:2] - m_t)
        for k in range(K):
            for j in range(2):
                du = np.zeros_like(u)
                du[..., k, j] = CC_FD_STEP
                Tp, Tm = _cc_tip(nd, u + du), _cc_tip(nd, u - du)
                dp = (Tp[..., :3, 3] - Tm[..., :3, 3]) / (2 * CC_FD_STEP)
                dR = (Tp[..., :3, :3] - Tm[..., :3, :3]) / (2 * CC_FD_STEP)
                Om = dR @ np.swapaxes(T0[..., :3, :3], -1, -2)
                om = 0.5 * np.stack(
                    [
                        Om[..., 2, 1] - Om[..., 1, 2],
                        Om[..., 0, 2] - Om[..., 2, 0],
                        Om[..., 1, 0] - Om[..., 0, 1],
                    ],
                    axis=-1,
                )
                g[..., k, j] -= np.sum(dp * Fn, axis=-1) + np.sum(om * Ln, axis=-1)
        return g

    n = 2 * K
    for _ in range(CC_NEWTON_MAX_ITER):
        g = resid(u)
        if np.all(np.max(np.abs(g), axis=(-1, -2)) <= CC_NEWTON_TOL):
            break
        J = np.zeros((*batch, n, n))
        for c in range(n):
            du = np.zeros_like(u)
            du[..., c // 2, c % 2] = CC_FD_STEP
            J[..., :, c] = ((resid(u + du) - resid(u - du)) / (2 * CC_FD_STEP)).reshape(*batch, n)
        step = -np.linalg.solve(J, g.reshape(*batch, n, 1))[..., 0]
        norm = np.linalg.norm(step, axis=-1, keepdims=True)
        step = step * np.minimum(1.0, CC_MAX_STEP / np.maximum(norm, 1e-300))
        u = u + step.reshape(u.shape)
    g = resid(u)
    residual = np.max(np.abs(g), axis=(-1, -2))
    T = _cc_tip(nd, u)
    T[..., :3, 3] *= L
    return CCSolution(curvature=u / L, T_tip=T, converged=residual <= CC_NEWTON_TOL, residual=residual)


# ----------------------------------------------------------------------------------------------------
# Error table (paper 3)
# ----------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ErrorTable:
    """CC-vs-Cosserat tip errors. Axes: direction (n_d,), load (n_l,) N, bend angle (n_a,) rad.

    position_error, orientation_error (n_d, n_l, n_a): CC statics (same tensions and tip load) vs
    Cosserat, m and rad. arc_position_error: the CC arc having the Cosserat tip's own bend angle and
    plane vs the Cosserat tip position (pure kinematic error of the arc assumption), m.
    converged: both solvers converged. cosserat_tip, cc_tip: (n_d, n_l, n_a, 3) m.
    """

    directions: tuple[str, ...]
    load: np.ndarray
    bend_angle: np.ndarray
    tension: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    arc_position_error: np.ndarray
    converged: np.ndarray
    cosserat_tip: np.ndarray
    cc_tip: np.ndarray
    seconds: float

    def markdown(self) -> str:
        head = (
            "| load | θ₀ (deg) | tension (N) | CC statics tip error (mm) | CC orientation error (deg) "
            "| arc-fit tip error (mm) |"
        )
        lines = [head, "|---|---|---|---|---|---|"]
        for d, name in enumerate(self.directions):
            for j, f in enumerate(self.load):
                for a, th in enumerate(self.bend_angle):
                    ok = "" if self.converged[d, j, a] else " (not converged)"
                    label = "none" if f == 0 else f"{f:g} N {name}"
                    if f == 0 and d > 0:
                        continue
                    pos_mm = 1e3 * self.position_error[d, j, a]
                    ori_deg = math.degrees(self.orientation_error[d, j, a])
                    arc_mm = 1e3 * self.arc_position_error[d, j, a]
                    lines.append(
                        f"| {label} | {math.degrees(th):.0f} | {self.tension[a]:.2f} | {pos_mm:.3f}{ok} | "
                        f"{ori_deg:.2f} | {arc_mm:.3f} |"
                    )
        return "\n".join(lines)


DIRECTIONS = {"lateral": np.array([1.0, 0.0, 0.0]), "axial": np.array([0.0, 0.0, -1.0])}
"""Tip-load directions in the base frame: lateral = +x (in the bending plane, towards the bend),
axial = -z (along the base axis, compressing the straight robot, e.g. a payload's weight with the base up)."""


def constant_curvature_error_table(
    rod: TendonRod | None = None,
    bend_angles_deg: object = (0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0),
    loads_n: object = (0.0, 0.05, 0.1, 0.2),
    directions: tuple[str, ...] = ("lateral", "axial"),
    *,
    tendon: int = 0,
    tol: float = TABLE_BVP_TOL,
) -> ErrorTable:
    """CC tip error vs bend angle and tip load, against the Cosserat reference (single segment).

    For each nominal bend angle θ₀ the single tendon ``tendon`` gets the tension that bends the unloaded
    robot by θ₀ (τ = EI θ₀ / (L r)); then a tip force of each magnitude and direction is applied, and
    the CC statics and the Cosserat BVP are solved with the same tensions and load.
    """
    rod = TendonRod.paper() if rod is None else rod
    if rod.n_segments != 1:
        raise ValueError(f"Expected a single-segment rod for the error table, got {rod.n_segments} segments.")
    if not (isinstance(tendon, int) and 0 <= tendon < rod.n_tendons):
        raise ValueError(f"Expected tendon an index in [0, {rod.n_tendons - 1}], got {tendon!r}.")
    ang = np.deg2rad(as_array(bend_angles_deg, "bend_angles_deg", (None,)))
    if ang.ndim != 1 or np.any(ang < 0) or np.any(ang >= np.pi):
        raise ValueError("Expected bend_angles_deg a 1-D sequence in [0, 180).")
    loads = as_array(loads_n, "loads_n", (None,))
    if loads.ndim != 1 or np.any(loads < 0):
        raise ValueError("Expected loads_n a 1-D sequence of magnitudes >= 0.")
    for d in directions:
        if d not in DIRECTIONS:
            raise ValueError(f"Expected directions from {sorted(DIRECTIONS)}, got {d!r}.")
    t0 = time.perf_counter()
    tension_1 = rod.bending_stiffness * ang / (rod.length * rod.tendon_radius[tendon])
    tau = np.zeros((ang.size, rod.n_tendons))
    tau[:, tendon] = tension_1
    F = np.stack([loads[:, None] * DIRECTIONS[d] for d in directions])  # (n_d, n_l, 3)
    tau_full = np.broadcast_to(tau, (len(directions), loads.size, ang.size, rod.n_tendons))
    F_full = np.broadcast_to(F[:, :, None, :], (len(directions), loads.size, ang.size, 3))
    cos = solve_static(rod, tau_full, F_full, tol=tol)
    cc = constant_curvature_statics(rod, tau_full, F_full)
    pe = np.linalg.norm(cc.T_tip[..., :3, 3] - cos.T_tip[..., :3, 3], axis=-1)
    Rerr = np.swapaxes(cc.T_tip[..., :3, :3], -1, -2) @ cos.T_tip[..., :3, :3]
    oe = np.arccos(np.clip((np.trace(Rerr, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0))
    # arc through the Cosserat tip's tangent: θ, β from R e3, tip of that arc with the rod length
    z = cos.T_tip[..., :3, 2]
    theta = np.arccos(np.clip(z[..., 2], -1.0, 1.0))
    rho_xy = np.linalg.norm(z[..., :2], axis=-1)
    dir_xy = np.where(rho_xy[..., None] > 0, z[..., :2] / np.maximum(rho_xy, 1e-300)[..., None], 0.0)
    ell = rod.length
    # ℓ (1 - cos θ)/θ = ℓ (θ/2) sinc²(θ/2) along the bending direction, ℓ sin θ / θ along z
    lateral = ell * (theta / 2) * np.sinc(theta / (2 * np.pi)) ** 2
    arc_tip = np.concatenate(
        [lateral[..., None] * dir_xy, (ell * np.sinc(theta / np.pi))[..., None]], axis=-1
    )
    ape = np.linalg.norm(arc_tip - cos.T_tip[..., :3, 3], axis=-1)
    return ErrorTable(
        directions=tuple(directions),
        load=loads,
        bend_angle=ang,
        tension=tension_1,
        position_error=pe,
        orientation_error=oe,
        arc_position_error=ape,
        converged=cos.converged & cc.converged,
        cosserat_tip=cos.T_tip[..., :3, 3],
        cc_tip=cc.T_tip[..., :3, 3],
        seconds=time.perf_counter() - t0,
    )
