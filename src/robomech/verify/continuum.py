"""Verification of the continuum robot (paper 3) against a higher-fidelity Cosserat-rod reference.

DRAFT: these checks verify the Cosserat reference itself (``_cosserat.py``) against classical results
that need no constant-curvature package. Once ``robomech.mechanisms.continuum`` is merged, the lead
adds the comparison of its constant-curvature kinematics and statics with the Cosserat solution (the
error table of ``constant_curvature_error_table`` then uses the library model instead of the helper).
"""

from __future__ import annotations

import math

import numpy as np

from ._core import Check, Tolerance, Verification
from ._cosserat import (
    BVP_TOL,
    TendonRod,
    base_balance_error,
    constant_curvature_transform,
    elastica_cantilever_tip,
    solve_static,
)

__all__ = ["VERIFICATION"]

_NAME = "continuum"

ARC_TOLERANCE = Tolerance(
    1e-9,
    "zero load, straight cables: the exact solution is a circular arc; BVP collocation tolerance 1e-8 "
    "(4th-order collocation on a circle measures ~1e-12 of L)",
    relative=True,
)
ELASTICA_TOLERANCE = Tolerance(
    1e-8,
    "tip force, no cable tension: quadrature elastica (quad/brentq 1e-11) vs BVP at tolerance 1e-8",
    relative=True,
)
BALANCE_TOLERANCE = Tolerance(
    1e-7,
    "global moment balance at the base, relative to EI/L; base curvature from the derivative of the "
    "collocation spline, accurate to about the BVP tolerance",
    relative=True,
)
CONVERGENCE_TOLERANCE = Tolerance(
    1e-8,
    "stated tip accuracy: halving the BVP tolerance moves the tip by less than 1e-8 of the length",
    relative=True,
)

_BEND_DEG = (0.0, 30.0, 60.0, 90.0)
"""Bend angles (paper's planar experiment spans 0-90°) for the zero-load arc check."""
_LOADS_N = (0.1, 0.5, 1.0)
"""Tip loads (N) for the elastica and balance checks: the range of the error table."""


def _arc_check(rigid: TendonRod) -> Check:
    L, ei, r = rigid.length, rigid.bending_stiffness, rigid.tendon_radius[0]
    cases = []
    for deg in _BEND_DEG:
        tau = ei * math.radians(deg) / (L * r)
        cases += [(tau, 0.0, 0.0), (0.0, tau, 0.0), (tau, 0.5 * tau, 0.0)]
    tau = np.array(cases)
    sol = solve_static(rigid, tau)
    u = np.einsum("ba,ai->bi", tau, np.cross([0.0, 0.0, 1.0], rigid.tendon_offsets))[:, :2] / ei
    T = constant_curvature_transform(u, L)
    err = np.max(np.abs(sol.T_tip[..., :3, 3] - T[..., :3, 3]), axis=-1) / L
    err = np.maximum(err, np.max(np.abs(sol.T_tip[..., :3, :3] - T[..., :3, :3]), axis=(-1, -2)))
    err = np.where(sol.converged, err, np.inf)
    return Check(
        _NAME,
        "Cosserat unloaded = CC arc (tip /L)",
        float(np.max(err)),
        ARC_TOLERANCE,
        f"{len(cases)} cable combinations, θ = 0-90°, {sol.seconds:.2f} s",
    )


def _elastica_check(rigid: TendonRod) -> Check:
    L = rigid.length
    F = np.array([[P, 0.0, 0.0] for P in _LOADS_N])
    sol = solve_static(rigid, np.zeros(3), F)
    errs = []
    for i, P in enumerate(_LOADS_N):
        x_l, y_l, _ = elastica_cantilever_tip(rigid.bending_stiffness, L, P)
        e = np.max(np.abs(sol.T_tip[i, :3, 3] - [y_l, 0.0, x_l])) / L
        errs.append(e if sol.converged[i] else math.inf)
    return Check(
        _NAME,
        "Cosserat tip force = elastica (tip /L)",
        float(max(errs)),
        ELASTICA_TOLERANCE,
        f"loads {_LOADS_N} N, no cable tension",
    )


def _balance_check(rod: TendonRod) -> Check:
    rng = np.random.default_rng(8)
    n = 6
    tau = rng.uniform(0.0, 12.0, (n, rod.n_tendons))
    F = rng.uniform(-1.0, 1.0, (n, 3)) * np.asarray(_LOADS_N).max() / math.sqrt(3.0)
    M = rng.uniform(-0.01, 0.01, (n, 3))
    sol = solve_static(rod, tau, F, M)
    err = np.where(sol.converged, base_balance_error(rod, sol), np.inf)
    return Check(
        _NAME,
        "Cosserat base moment balance (/(EI/L))",
        float(np.max(err)),
        BALANCE_TOLERANCE,
        f"{n} random spatial loads with 3 cables, extensible/shearable rod",
    )


def _convergence_check(rod: TendonRod) -> Check:
    L, ei, r = rod.length, rod.bending_stiffness, rod.tendon_radius[0]
    tau = np.array([[ei * math.radians(90.0) / (L * r), 0.0, 0.0]] * 2)
    F = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
    a = solve_static(rod, tau, F, tol=BVP_TOL)
    b = solve_static(rod, tau, F, tol=BVP_TOL / 2)
    err = np.max(np.abs(a.T_tip[..., :3, 3] - b.T_tip[..., :3, 3]), axis=-1) / L
    err = np.where(a.converged & b.converged, err, np.inf)
    return Check(
        _NAME,
        "Cosserat BVP tol halved: tip change (/L)",
        float(np.max(err)),
        CONVERGENCE_TOLERANCE,
        "90° bend with 1 N lateral and 1 N axial tip loads",
    )


def _run() -> list[Check]:
    rod = TendonRod.paper()
    rigid = TendonRod.paper(rigid_axial_shear=True)
    return [_arc_check(rigid), _elastica_check(rigid), _balance_check(rod), _convergence_check(rod)]


VERIFICATION = Verification(
    name=_NAME,
    title="Paper 3 continuum robot: Cosserat-rod reference (Rucker & Webster 2011), draft",
    engine="static Cosserat rod with tendon routing, scipy.integrate.solve_bvp",
    run=_run,
)
