"""Built-in study ``omnileg-synthesis``: dimensional synthesis of paper 2's OmniLeg over (L1, L4, L5).

Metrics per design (defined in ``docs/explore.md``):

* ``workspace_volume``: volume (m^3) of the foot workspace, the image of the joint box |alpha| <= alpha_max,
  |beta| <= beta_max, GAMMA_USABLE_MIN <= gamma <= gamma_max under eq. (11), as the integral of |det J|
  over the box (composite Simpson, SIMPSON_POINTS per axis).  eq. (11) is injective on the box (the thigh
  direction is injective in (alpha, beta) and cos gamma is monotonic on [0, pi/2)), so this is the volume.
* ``min_abs_det_j``: min of |det J| (m^3/rad^3) over the same grid (the box's faces included).
* ``peak_torque``: max over the eq. (52) motion (0-6 s) and the three motors of |tau| (N m), and
  ``peak_torque_joint`` the per-motor peaks (alpha, beta, gamma order).

gamma = 0 (the shank stretched straight) is singular for every design (J[2, 2] = -2 L4 sin gamma), so
the minimum of |det J| over Table 2's full range [0, 85 deg] is 0 for every design; the study's usable
workspace starts at GAMMA_USABLE_MIN.  L5 translates the workspace along Z0 and changes neither metric.

``dataclasses.replace`` of an OmniLeg derives the default inertias from the new dimensions (in the
parameter object): the torques use each design's own link inertias
(docs/explore.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from robomech.mechanisms import omnileg as ol
from robomech.mechanisms.omnileg._dynamics import _terms

from ._study import DesignArrays, DesignStudy, Metric, Objective, Variable, design_blocks

__all__ = ["STUDY", "simpson_weights"]

# gamma = 0 is singular for every design: the usable knee range starts here (an assumption, stated).
GAMMA_USABLE_MIN = math.radians(10.0)
# Simpson points per joint axis (odd): the integrand is smooth, 13 points give 6e-5 relative accuracy
# (measured in tests/explore against the projected-area closed form, for every tested design).
SIMPSON_POINTS = 13
# eq. (52) motion: one 6 s period, 0.05 s steps.
EQ52_STEP = 0.05
# Designs in one dynamics call (16 x 121 samples: the jets' temporaries up to (3, N, 3), 140 kB);
# measured on one core, 64 designs, as a Dask worker runs them (glibc's MALLOC_TRIM_THRESHOLD_=65536,
# which Dask's nanny sets: every temporary above 128 kB is mapped and unmapped): 0.50 s of CPU in
# blocks of 1, 0.27 in blocks of 16-32, 0.37 in one block of 64.
DESIGN_BLOCK = 16
# The fields a dynamics call takes per design; legs that differ in any other field are grouped apart.
DESIGN_FIELDS = ("L1", "L4", "L5", "bodies")


class _Bodies(NamedTuple):
    """One body kind per sample."""

    mass: np.ndarray  # (N,)
    com_vector: np.ndarray  # (N, 3)
    inertia_matrix: np.ndarray  # (N, 3, 3)


@dataclass(frozen=True)
class Legs(DesignArrays):
    """Legs equal but for :data:`DESIGN_FIELDS` on ``samples`` poses each, those fields per sample
    (design-major, N = designs x samples: lengths ``(N, 1)``, masses ``(N,)``, centres of mass ``(N, 3)``,
    inertias ``(N, 3, 3)``).  ``_dynamics._terms`` multiplies the inertias per sample here (one BLAS
    product for a single leg): the same products, possibly summed in another order."""

    L1: np.ndarray
    L4: np.ndarray
    L5: np.ndarray
    bodies: dict[str, _Bodies]

    @classmethod
    def of(cls, legs: list[ol.OmniLeg], samples: int) -> Legs:
        def rep(values: list[Any]) -> np.ndarray:
            return np.repeat(np.asarray(values, dtype=float), samples, axis=0)

        bodies = {
            k: _Bodies(*(rep([getattr(g.bodies[k], a) for g in legs]) for a in _Bodies._fields))
            for k in legs[0].bodies
        }
        L1, L4, L5 = (rep([getattr(g, f) for g in legs])[:, None] for f in DESIGN_FIELDS[:3])
        return cls(tuple(legs), L1, L4, L5, bodies)

    @property
    def foot_drop(self) -> np.ndarray:
        """:attr:`OmniLeg.foot_drop` per sample, (N, 1) (m)."""
        return self.L5 - self.designs[0].knee_to_crank


def simpson_weights(lo: float, hi: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of the composite Simpson rule with ``n`` (odd) points on [lo, hi]."""
    x = np.linspace(lo, hi, n)
    w = np.ones(n)
    w[1:-1:2], w[2:-1:2] = 4.0, 2.0
    return x, w * (hi - lo) / (3.0 * (n - 1))


def _grid(leg: ol.OmniLeg) -> tuple[np.ndarray, np.ndarray]:
    g_lo = max(leg.gamma_min, GAMMA_USABLE_MIN)
    axes = [
        simpson_weights(-leg.alpha_max, leg.alpha_max, SIMPSON_POINTS),
        simpson_weights(-leg.beta_max, leg.beta_max, SIMPSON_POINTS),
        simpson_weights(g_lo, leg.gamma_max, SIMPSON_POINTS),
    ]
    q = np.stack(np.meshgrid(*[a[0] for a in axes], indexing="ij"), -1).reshape(-1, 3)
    w = np.einsum("i,j,k->ijk", *[a[1] for a in axes]).ravel()
    return q, w


def evaluate(study: DesignStudy, params: list, rows: np.ndarray, seed) -> dict[str, np.ndarray]:
    n = len(params)
    out = {m.name: np.full((n, *m.shape), np.nan) for m in study.metrics}
    t = np.arange(0.0, 6.0 + 1e-9, EQ52_STEP)
    motion = ol.joint_trajectory_eq52(t)
    # legs that differ only in L1, L4, L5 (and the bodies derived from them) share one dynamics call
    for idx in design_blocks(params, DESIGN_FIELDS, DESIGN_BLOCK):
        legs = [params[i] for i in idx]
        for i, leg in zip(idx, legs, strict=True):
            q, w = _grid(leg)
            det = np.abs(np.linalg.det(ol.jacobian(leg, q)))
            out["workspace_volume"][i] = np.dot(w, det)
            out["min_abs_det_j"][i] = det.min()
        D, T = len(legs), motion.q.shape[0]
        qs = (np.tile(x, (D, 1)) for x in (motion.q, motion.qd, motion.qdd))
        terms = _terms(Legs.of(legs, T), *qs)  # type: ignore[arg-type]
        peaks = np.abs((terms.tau_motion + terms.tau_gravity).reshape(D, T, 3)).max(axis=1)
        out["peak_torque_joint"][idx] = peaks
        out["peak_torque"][idx] = peaks.max(axis=1)
    return out


STUDY = DesignStudy(
    name="omnileg-synthesis",
    title="OmniLeg (paper 2): dimensional synthesis over L1, L4, L5",
    mechanism="omnileg.OmniLeg",
    nominal=ol.OmniLeg.paper,
    variables=(
        Variable("L1", 0.10, 0.20, "m", description="thigh rod length A_iB_i"),
        Variable("L4", 0.06, 0.12, "m", description="shank link length C_iD_i = D_iE_i"),
        Variable("L5", 0.12, 0.20, "m", description="knee height below O0'"),
    ),
    metrics=(
        Metric("workspace_volume", "m^3", "foot workspace volume (integral of |det J| over the joint box)"),
        Metric("min_abs_det_j", "m^3", "min |det J| over the usable joint box"),
        Metric("peak_torque", "N m", "max |tau| over the eq. (52) motion and the three motors"),
        Metric("peak_torque_joint", "N m", "per-motor max |tau| along eq. (52) (alpha, beta, gamma)", (3,)),
    ),
    evaluate=evaluate,
    parameters={
        "gamma_usable_min_rad": GAMMA_USABLE_MIN,
        "simpson_points": SIMPSON_POINTS,
        "eq52_step_s": EQ52_STEP,
        "inertias": "default bodies derived from each design's dimensions (OmniLeg.bodies, docs/explore.md)",
    },
    objectives=(
        Objective("workspace_volume", "max"),
        Objective("min_abs_det_j", "max"),
        Objective("peak_torque", "min"),
    ),
    poses_per_design=SIMPSON_POINTS**3 + round(6.0 / EQ52_STEP) + 1,
    default_sampler="sobol",
    default_chunk=64,  # ~1.3 s of work per task on one core (docs/performance.md)
    default_designs=256,
)
