"""Built-in study ``vectored-thrust-tolerance``: Monte Carlo over manufacturing errors of paper 5's thruster.

Each design is one as-built mechanism: a vector of ten manufacturing errors (zero-mean normal, stated
sigma).  Its controller keeps the nominal model, so commanding inputs q it expects the nominal propeller
axis ``s0_nom(q)`` (``vectored_thrust.forward_kinematics`` of ``VectoredThruster.paper()``); the as-built
mechanism points along ``s0(q)`` of :func:`as_built_axis`.  The pointing error is the angle between them,
over the Table 1 workspace (the nominal reachable set of an input grid over q1 in +-pi/4, q2 in +-pi/6).

The as-built model generalises paper 5's closure (eqs. (5)-(8), (11)) to misaligned axes and imperfect
arcs; with every error zero it is the library's forward kinematics (tested to rounding).
"""

from __future__ import annotations

import math

import numpy as np

from robomech.mechanisms import vectored_thrust as vt

from ._study import DesignStudy, Metric, Variable

__all__ = ["ERRORS", "STUDY", "as_built_axis", "pointing_error", "sensitivity", "workspace"]

# Table 1 workspace: a 41 x 41 input grid over the input ranges, kept where the nominal map is reachable.
WORKSPACE_GRID = 41
# Assumed manufacturing tolerance (the paper states none): sigma = 0.1 deg for every angle (a machined
# bore or arc of ~25 mm radius held to ~0.04 mm), encoder zero offsets sigma = 0.1 deg.
SIGMA_ANGLE = math.radians(0.1)
# Designs evaluated at once within a chunk: (DESIGN_BLOCK x 1399 poses x 3) float64 temporaries of
# ~270 kB, which stay in a core's cache; measured on one core, 1024 designs: 0.84 s at once, 0.59 s in
# blocks of 16-64 (docs/performance.md); 2048 designs as a Dask worker runs them (glibc's
# MALLOC_TRIM_THRESHOLD_=65536, which Dask's nanny sets: every temporary above 128 kB is mapped and
# unmapped): 1.21-1.22 s of CPU in blocks of 2-8, 1.45 s in blocks of 32.
DESIGN_BLOCK = 8
# The as-built s13 needs 1 - |in-plane part|^2 > 0; below this the platform does not assemble.
ASSEMBLY_TOL = 1e-12

ERRORS = (
    ("axis1_tilt_y", "RRR input axis (X) tilted toward Y"),
    ("axis1_tilt_z", "RRR input axis (X) tilted toward Z"),
    ("axis2_tilt_x", "RR input axis (Y) tilted toward X"),
    ("axis2_tilt_z", "RR input axis (Y) tilted toward Z"),
    ("arc_angle", "RRR 45 deg arc angle error (VectoredThruster.arc_angle via dataclasses.replace)"),
    ("rrr_arc2_angle", "RRR 90 deg arc angle error (s12 to s13)"),
    ("rr_arc_angle", "RR 90 deg arc angle error (Y to s22)"),
    ("platform_angle", "fixing-device angle error between s22 and s13 (90 deg)"),
    ("q1_offset", "encoder zero offset of q1"),
    ("q2_offset", "encoder zero offset of q2"),
)
ERROR_NAMES = tuple(n for n, _ in ERRORS)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _rotate(axis: np.ndarray, v: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rodrigues: v rotated about the unit ``axis`` by ``angle`` (all broadcast, (..., 3))."""
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    return v * c + np.cross(axis, v) * s + axis * np.sum(axis * v, -1, keepdims=True) * (1 - c)


def as_built_axis(th: vt.VectoredThruster, errors: dict[str, np.ndarray], q: np.ndarray):
    """Propeller axis (..., 3) of the as-built mechanism at commanded inputs ``q (..., 2)``, and valid (...).

    ``errors`` maps each name of :data:`ERRORS` to an array broadcasting against ``q[..., 0]`` (rad).
    Construction (all axes through O): input axes ``u1 ~ X + e1y Y + e1z Z``, ``u2 ~ Y + e2x X + e2z Z``;
    ``s12 = Rot(u1, q1 + d1) s12_0`` with s12_0 at ``a + da`` from u1 in the plane of u1 and -Z (eq. (7));
    ``s22 = Rot(u2, q2 + d2) s22_0`` with s22_0 at ``pi/2 + d_rr`` from u2 toward -X (eq. (5)); s13 the unit
    vector at ``pi/2 + d_arc2`` from s12 and ``pi/2 + d_p`` from s22 on the side of ``s22 x s12`` (eq. (8)'s
    assembly mode); ``s0 = s22 x s13 / |s22 x s13|`` (eq. (11)).
    """
    e = {k: np.asarray(errors.get(k, 0.0), dtype=float) for k in ERROR_NAMES}
    X, Y, Z = np.eye(3)
    u1 = _unit(X + e["axis1_tilt_y"][..., None] * Y + e["axis1_tilt_z"][..., None] * Z)
    u2 = _unit(Y + e["axis2_tilt_x"][..., None] * X + e["axis2_tilt_z"][..., None] * Z)
    a = th.arc_angle + e["arc_angle"]
    w1 = _unit(-Z - np.sum(-Z * u1, -1, keepdims=True) * u1)
    s12_0 = np.cos(a)[..., None] * u1 + np.sin(a)[..., None] * w1
    w2 = _unit(-X - np.sum(-X * u2, -1, keepdims=True) * u2)
    b = 0.5 * math.pi + e["rr_arc_angle"]
    s22_0 = np.cos(b)[..., None] * u2 + np.sin(b)[..., None] * w2
    s12 = _rotate(u1, s12_0, q[..., 0] + e["q1_offset"])
    s22 = _rotate(u2, s22_0, q[..., 1] + e["q2_offset"])
    c1 = np.cos(0.5 * math.pi + e["rrr_arc2_angle"])  # s13 . s12
    c2 = np.cos(0.5 * math.pi + e["platform_angle"])  # s13 . s22
    c = np.sum(s12 * s22, -1)
    n = np.cross(s22, s12)
    d2 = np.sum(n * n, -1)
    valid = np.sqrt(d2) > vt.SINGULAR_TOL
    den = np.where(valid, d2, 1.0)  # 1 - c^2 = |s22 x s12|^2
    al = (c1 - c2 * c) / den
    be = (c2 - c1 * c) / den
    z2 = 1.0 - (al * al + be * be + 2 * al * be * c)
    valid &= z2 > ASSEMBLY_TOL
    z = np.sqrt(np.where(valid, z2, 1.0))
    s13 = al[..., None] * s12 + be[..., None] * s22 + (z / np.sqrt(den))[..., None] * n
    s0 = _unit(np.cross(s22, s13))
    return np.where(valid[..., None], s0, np.nan), valid


def pointing_error(th: vt.VectoredThruster, errors: dict[str, np.ndarray], q: np.ndarray):
    """Angle (rad) between the as-built and the nominal propeller axis at ``q (..., 2)``, and valid."""
    return _pointing_error(th, errors, q, vt.forward_kinematics(th, q).axis)


def _pointing_error(th: vt.VectoredThruster, errors: dict[str, np.ndarray], q: np.ndarray, nom: np.ndarray):
    """:func:`pointing_error` against the given nominal axes ``nom`` (broadcasting with ``q[..., None]``)."""
    s0, ok = as_built_axis(th, errors, q)
    # atan2(|a x b|, a . b): accurate for the micro-radian angles of a tolerance study (acos is not)
    ang = np.arctan2(np.linalg.norm(np.cross(s0, nom), axis=-1), np.sum(s0 * nom, -1))
    return np.where(ok, ang, np.nan), ok


def workspace(th: vt.VectoredThruster) -> np.ndarray:
    """Input samples (P, 2) of the nominal Table 1 workspace (reachable points of the input grid)."""
    g = vt.input_grid(th, WORKSPACE_GRID).reshape(-1, 2)
    return g[vt.workspace_map(th, g).reachable]


def evaluate(study: DesignStudy, params: list, rows: np.ndarray, seed) -> dict[str, np.ndarray]:
    th = study.nominal()
    q = workspace(th)
    nom = vt.forward_kinematics(th, q).axis  # the nominal axes, once per chunk
    names = study.variable_names
    n = rows.shape[0]
    out = {m.name: np.full(n, np.nan) for m in study.metrics}
    out["assembles"] = np.zeros(n, dtype=bool)
    # the arc-angle error went through the parameter dataclass (DesignStudy.designs_to_params: the
    # as-built thruster is dataclasses.replace(nominal, arc_angle=a + da)); a rejected one is a failed design
    ok_design = np.array([p is not None for p in params], dtype=bool)
    # DESIGN_BLOCK designs at a time (every operation is per design and pose, every reduction per design
    # along the poses, so the blocks change no bit of the result; tested): the (designs, poses, 3)
    # temporaries stay cache-sized instead of 34 MB each for a 1024-design chunk
    for b in range(0, n, DESIGN_BLOCK):
        blk = slice(b, min(b + DESIGN_BLOCK, n))
        errors = {name: rows[blk, i][:, None] for i, name in enumerate(names)}
        err, ok = _pointing_error(th, errors, q[None], nom)
        ok &= ok_design[blk, None]
        out["assembled_fraction"][blk] = ok.mean(axis=1)
        full = ok.all(axis=1)
        out["assembles"][blk] = full
        if full.any():
            ef = err[full]  # finite: a fully assembled design has a valid angle at every pose
            idx = np.arange(blk.start, blk.stop)[full]
            out["rms_error"][idx] = np.sqrt(np.mean(ef * ef, axis=1))
            out["p50_error"][idx] = np.percentile(ef, 50, axis=1)
            out["p95_error"][idx] = np.percentile(ef, 95, axis=1)
            out["max_error"][idx] = ef.max(axis=1)
    return out


def summarize(study: DesignStudy, results) -> list[dict]:
    """Sensitivity ranking (first-order shares) and its check against the Monte Carlo mean square."""
    sig = {v.name: v.sigma for v in study.variables}
    sens = sensitivity(study.nominal(), sig)
    total = sum(sens.values())
    rows = [[k + 1, name, sig[name], c, 100.0 * c / total] for k, (name, c) in enumerate(sens.items())]
    ok = np.asarray(results["chunk_done"]).all()
    rms = np.asarray(results["rms_error"], float)
    fin = rms[np.isfinite(rms)]
    check = []
    if ok and fin.size > 1:
        ms = fin * fin
        se = float(ms.std() / np.sqrt(ms.size))
        check = [
            ["Monte Carlo mean of rms_error^2", float(ms.mean()), se],
            ["sum of contributions", total, 0.0],
        ]
    return [
        {
            "title": "Sensitivity ranking: contribution of each error to the mean squared pointing error",
            "columns": ["rank", "error", "sigma (rad)", "contribution (rad^2)", "share (%)"],
            "rows": rows,
            "note": "First order: mean over the workspace of the squared pointing error with that error "
            "alone at +-sigma (docs/explore.md); the shares add up to the linearised mean square.",
        },
        {
            "title": "Check: linearised prediction vs Monte Carlo",
            "columns": ["quantity", "value (rad^2)", "standard error (rad^2)"],
            "rows": check,
            "note": "The two agree to a few standard errors plus second-order terms.",
        },
    ]


_P = int(workspace(vt.VectoredThruster.paper()).shape[0])  # nominal workspace poses per design

STUDY = DesignStudy(
    name="vectored-thrust-tolerance",
    title="Vectored thruster (paper 5): pointing error from manufacturing errors (Monte Carlo)",
    mechanism="vectored_thrust.VectoredThruster",
    nominal=vt.VectoredThruster.paper,
    variables=tuple(
        Variable(n, unit="rad", kind="normal", sigma=SIGMA_ANGLE, description=d) for n, d in ERRORS
    ),
    metrics=(
        Metric("rms_error", "rad", "RMS pointing error over the Table 1 workspace"),
        Metric("p50_error", "rad", "median pointing error over the workspace"),
        Metric("p95_error", "rad", "95th percentile of the pointing error over the workspace"),
        Metric("max_error", "rad", "worst pointing error over the workspace"),
        Metric(
            "assembled_fraction", "1", "fraction of workspace poses where the as-built mechanism assembles"
        ),
        Metric(
            "assembles", "bool", "the as-built mechanism assembles over the whole workspace", dtype="bool"
        ),
    ),
    evaluate=evaluate,
    parameters={
        "workspace_grid": WORKSPACE_GRID,
        "workspace": "reachable points of the nominal input grid (Table 1 ranges, tilt, interference)",
        "sigma_default_rad": SIGMA_ANGLE,
    },
    poses_per_design=_P,
    default_sampler="random",
    default_chunk=2048,  # ~1.2 s of work per task on one core in DESIGN_BLOCK blocks (docs/performance.md)
    default_designs=4096,
    error_names=ERROR_NAMES,
    summarize=summarize,
)


def sensitivity(th: vt.VectoredThruster, sigmas: dict[str, float]) -> dict[str, float]:
    """First-order share of each error in the mean squared pointing error over the workspace.

    To first order the pointing error is ``|G(q) e|``, so its mean square over the workspace is the
    quadratic form ``e^T M e`` and, for independent zero-mean errors, ``E[e^T M e] = sum_k M_kk sigma_k^2``:
    the contribution of error k is the mean square with that error alone at one sigma (averaged over
    +sigma and -sigma, which cancels the second-order term).  Returns ``{name: contribution (rad^2)}``
    sorted largest first; their sum predicts the Monte Carlo mean of ``rms_error**2``.
    """
    q = workspace(th)
    out = {}
    for name, s in sigmas.items():
        ms = []
        for sign in (1.0, -1.0):
            err, ok = pointing_error(th, {name: np.array(sign * s)}, q)
            ms.append(float(np.mean(err[ok] ** 2)))
        out[name] = 0.5 * (ms[0] + ms[1])
    return dict(sorted(out.items(), key=lambda kv: -kv[1]))
