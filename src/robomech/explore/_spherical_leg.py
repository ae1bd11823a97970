"""Built-in study ``spherical-leg-synthesis``: dimensional synthesis of paper 1's leg over (R, r, h).

Metrics per design (defined in ``docs/explore.md``):

* ``workspace_fraction``: fraction of the task grid |alpha|, |beta| <= pi/3 (paper 1, Section 6.1: the
  sway amplitude) where every leg length is within [length_min, length_max] and J is not singular;
* ``min_dexterity``, ``mean_dexterity``: sigma_min / sigma_max of J = dl/d(alpha, beta) (1 / cond) over
  those reachable poses (NaN, under ``has_workspace`` False, when there are none);
* ``peak_force``: max over the Fig. 5(b) motion (0-25 s) of max_i |f_i| under paper 1's force rule
  (legs 1 and 3 drive), N; NaN under ``fig5b_ok`` False when the motion leaves the stroke limits, meets
  an actuation singularity, or crosses one between samples (a sign change of dl3/dalpha).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from robomech.mechanisms import spherical_leg as sl
from robomech.mechanisms.spherical_leg._dynamics import _forces, _motion
from robomech.mechanisms.spherical_leg._workspace import _map_closed_form

from ._study import DesignArrays, DesignStudy, Metric, Objective, Variable, design_blocks

__all__ = ["STUDY"]

_MM = 1e-3
# Task grid: paper 1, Section 6.1 sways alpha or beta with amplitude pi/3.
TASK_HALF_RANGE = math.pi / 3
TASK_GRID = 41  # per axis: 1681 poses, a 3 deg step
# Fig. 5(b): beta pi/3 -> pi/6 in 5 s, then one 20 s sway period about X; sampled as the study's plots.
FIG5B_DURATION = 25.0
FIG5B_STEP = 0.1
# Designs evaluated in one kernel call: (DESIGN_BLOCK x 1932 poses) float64 temporaries of ~120 kB
# (x 6 for J); measured on one core, 1024 designs, as a Dask worker runs them (glibc's
# MALLOC_TRIM_THRESHOLD_=65536, which Dask's nanny sets: every temporary above 128 kB is mapped and
# unmapped): 1.27 s of CPU in blocks of 1, 0.99 in blocks of 4-8, 1.25-1.27 in blocks of 16-32
# (0.71 s in blocks of 8 without that setting). The block size changes no bit (every operation is per
# design and pose; tested).
DESIGN_BLOCK = 8
# The fields a kernel call takes per design; legs that differ in any other field are grouped apart.
DESIGN_FIELDS = ("R", "r", "h")


@dataclass(frozen=True)
class Legs(DesignArrays):
    """Legs equal but for R, r, h: those three as arrays ``(D, 1)`` (m; ``h`` ``(D, 1, 1)`` for the
    dynamics, whose platform centre ``h Rp e_z`` is ``(D, T, 3)``), the points and axes derived from them
    ``(D, 1, 3, 3)`` (computed when a kernel first reads them)."""

    R: np.ndarray
    r: np.ndarray
    h: np.ndarray

    @classmethod
    def of(cls, legs: list[sl.SphericalLeg], h_axes: int = 1) -> Legs:
        R, r, h = (np.array([getattr(g, f) for g in legs], dtype=float) for f in DESIGN_FIELDS)
        return cls(tuple(legs), R[:, None], r[:, None], h.reshape(-1, *(1,) * h_axes))

    def _per_design(self, name: str) -> np.ndarray:
        return np.stack([getattr(g, name) for g in self.designs])[:, None]

    @functools.cached_property
    def base_points(self) -> np.ndarray:
        return self._per_design("base_points")

    @functools.cached_property
    def platform_points_home(self) -> np.ndarray:
        return self._per_design("platform_points_home")

    @functools.cached_property
    def cardan_axes(self) -> np.ndarray:
        return self._per_design("cardan_axes")


def _task_grid() -> tuple[np.ndarray, np.ndarray]:
    a = np.linspace(-TASK_HALF_RANGE, TASK_HALF_RANGE, TASK_GRID)
    g = np.meshgrid(a, a, indexing="ij")
    return g[0].ravel(), g[1].ravel()


def _fig5b() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = np.arange(0.0, FIG5B_DURATION + 1e-9, FIG5B_STEP)
    return sl.fig5_motion("b", t)


def evaluate(study: DesignStudy, params: list, rows: np.ndarray, seed) -> dict[str, np.ndarray]:
    n = len(params)
    out = {m.name: np.full(n, np.nan) for m in study.metrics}
    for k in ("has_workspace", "fig5b_ok"):
        out[k] = np.zeros(n, dtype=bool)
    # legs that differ only in R, r, h share one kernel call (any other varied field: one group each)
    for idx in design_blocks(params, DESIGN_FIELDS, DESIGN_BLOCK):
        _block(out, [params[i] for i in idx], idx)
    return out


def _block(out: dict[str, np.ndarray], legs: list[sl.SphericalLeg], idx: np.ndarray) -> None:
    """The metrics of the designs ``legs`` (rows ``idx`` of ``out``), each kernel called once for all."""
    a, b = _task_grid()
    q, qd, qdd = _fig5b()
    # the task grid and the Fig. 5(b) path in one map (the map is per pose, so this changes no bit)
    m = a.size
    pa, pb = np.concatenate([a, q[:, 0]]), np.concatenate([b, q[:, 1]])
    both = _map_closed_form(Legs.of(legs), pa, pb)  # type: ignore[arg-type]
    reach = both.reachable[:, :m] & ~both.singular[:, :m]  # (designs, task poses)
    dex = both.sigma_min[:, :m] / both.sigma_max[:, :m]
    out["workspace_fraction"][idx] = reach.mean(axis=1)
    has = reach.any(axis=1)
    out["has_workspace"][idx] = has
    for k in np.flatnonzero(has):
        d = dex[k, reach[k]]  # design by design: the mean sums these values in this order
        out["min_dexterity"][idx[k]] = d.min()
        out["mean_dexterity"][idx[k]] = d.mean()
    sign = np.sign(both.dl3_dalpha[:, m:])
    feasible = both.reachable[:, m:].all(axis=1) & np.all(sign == sign[:, :1], axis=1) & (sign[:, 0] != 0)
    # the inverse dynamics (~80 % of a design's work) only for the designs whose Fig. 5(b) motion is
    # kinematically feasible (a quarter of the default box): the others' force is NaN anyway
    f = np.flatnonzero(feasible)
    if f.size:
        fl = Legs.of([legs[k] for k in f], h_axes=2)
        dyn = _forces(fl, _motion(fl, q, qd, qdd), None, sl.PAPER_DRIVEN_LEGS)  # type: ignore[arg-type]
        valid = dyn.valid.all(axis=1)
        out["fig5b_ok"][idx[f]] = valid
        out["peak_force"][idx[f[valid]]] = np.max(np.abs(dyn.leg_forces[valid]), axis=(1, 2))


STUDY = DesignStudy(
    name="spherical-leg-synthesis",
    title="Spherical parallel leg (paper 1): dimensional synthesis over R, r, h",
    mechanism="spherical_leg.SphericalLeg",
    nominal=sl.SphericalLeg.paper,
    variables=(
        Variable("R", 50 * _MM, 100 * _MM, "m", description="base joint circle radius OA_i"),
        Variable("r", 20 * _MM, 45 * _MM, "m", description="platform joint circle radius PB_i"),
        Variable("h", 70 * _MM, 140 * _MM, "m", description="height OP of the platform centre"),
    ),
    metrics=(
        Metric("workspace_fraction", "1", "reachable, non-singular fraction of |alpha|, |beta| <= pi/3"),
        Metric("min_dexterity", "1", "min of 1/cond(J) over the reachable task poses"),
        Metric("mean_dexterity", "1", "mean of 1/cond(J) over the reachable task poses"),
        Metric("has_workspace", "bool", "at least one reachable task pose", dtype="bool"),
        Metric("peak_force", "N", "max |f_i| along Fig. 5(b), legs 1 and 3 driving (paper 1's rule)"),
        Metric("fig5b_ok", "bool", "Fig. 5(b) within stroke limits and free of singularities", dtype="bool"),
    ),
    evaluate=evaluate,
    parameters={
        "task_half_range_rad": TASK_HALF_RANGE,
        "task_grid": TASK_GRID,
        "fig5b_duration_s": FIG5B_DURATION,
        "fig5b_step_s": FIG5B_STEP,
        "force_rule": "paper 1: legs 1 and 3 drive",
    },
    objectives=(
        Objective("workspace_fraction", "max"),
        Objective("min_dexterity", "max"),
        Objective("peak_force", "min"),
    ),
    poses_per_design=TASK_GRID**2 + round(FIG5B_DURATION / FIG5B_STEP) + 1,
    default_sampler="sobol",
    default_chunk=1024,  # ~1.2 s of work per task on one core (docs/performance.md)
    default_designs=2048,
)
