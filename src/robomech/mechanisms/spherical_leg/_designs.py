"""Many legs at once (private): the closed-form kernels on per-design arrays of R, r, h.

The design studies (``robomech.explore``) evaluate thousands of legs that differ only in ``R``, ``r``,
``h``.  :class:`Designs` carries those (and the home-pose points and universal-joint axes derived from
them) as arrays with a leading design axis, and every other parameter from one :class:`SphericalLeg`;
the kernels of ``_kinematics``, ``_workspace`` and ``_dynamics`` read a leg only through attributes and
broadcast, so they take it unchanged and return ``(D, P, ...)`` arrays for D designs and P poses.  Each
sample goes through the same operations with the same numbers as for its own :class:`SphericalLeg`:
:func:`workspace_designs` and :func:`inverse_dynamics_designs` equal
:func:`~robomech.mechanisms.spherical_leg.workspace_map` and
:func:`~robomech.mechanisms.spherical_leg.inverse_dynamics` design by design (``tests/explore``).
No input validation: the callers pass validated parameter objects and their own poses.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from robomech._validation import finite_samples
from robomech.analysis.workspace import SINGULAR_RTOL, _measures
from robomech.spatial._so3 import _sincos as sincos

from ._dynamics import InverseDynamicsResult, _generalized, _motion, distribute_forces
from ._kinematics import _jacobian_sincos, _squared_length_columns
from ._params import SphericalLeg
from ._workspace import WorkspaceMap, _map

__all__ = ["Designs", "designs", "group_legs", "inverse_dynamics_designs", "workspace_designs"]


@dataclass(frozen=True)
class Designs:
    """The legs ``legs`` (equal but for R, r, h): those three as arrays ``(D, 1)`` (m), the points and
    axes derived from them as ``(D, 1, 3, 3)`` (computed when a kernel first reads them), every other
    parameter the first leg's."""

    legs: tuple[SphericalLeg, ...]
    R: np.ndarray
    r: np.ndarray
    h: np.ndarray

    def __getattr__(self, name: str) -> Any:
        # the shared parameters (limits, masses, bodies, gravity, screw): the first leg's
        return getattr(self.legs[0], name)

    def _per_design(self, name: str) -> np.ndarray:
        return np.stack([getattr(g, name) for g in self.legs])[:, None]

    @functools.cached_property
    def base_points(self) -> np.ndarray:
        return self._per_design("base_points")

    @functools.cached_property
    def platform_points_home(self) -> np.ndarray:
        return self._per_design("platform_points_home")

    @functools.cached_property
    def cardan_axes(self) -> np.ndarray:
        return self._per_design("cardan_axes")


def _shared(leg: SphericalLeg) -> tuple[Any, ...]:
    """The fields of ``leg`` but R, r, h: equal for legs that differ only in those three."""
    return tuple(getattr(leg, f.name) for f in dataclasses.fields(leg) if f.name not in ("R", "r", "h"))


def designs(legs: Sequence[SphericalLeg]) -> Designs:
    """The legs (equal but for R, r, h: :func:`group_legs` splits others) as one :class:`Designs`."""
    R, r, h = (np.array([[getattr(g, f)] for g in legs], dtype=float) for f in ("R", "r", "h"))
    return Designs(tuple(legs), R, r, h)


def group_legs(legs: Sequence[SphericalLeg]) -> list[np.ndarray]:
    """Indices into ``legs`` of each group of legs that differ only in R, r, h (first-seen order)."""
    groups: dict[tuple[Any, ...], list[int]] = {}
    for i, g in enumerate(legs):
        groups.setdefault(_shared(g), []).append(i)
    return [np.array(v, dtype=np.int64) for v in groups.values()]


def workspace_designs(d: Designs, alpha: np.ndarray, beta: np.ndarray) -> WorkspaceMap:
    """:func:`~robomech.mechanisms.spherical_leg.workspace_map` of every design at the poses ``alpha``,
    ``beta`` (rad, shape (P,)): each field ``(D, P, ...)``."""
    (sa, ca), (sb, cb) = sincos(alpha), sincos(beta)
    L = np.stack(_squared_length_columns(d, sa, ca, sb, cb), -1)  # type: ignore[arg-type]
    np.sqrt(np.maximum(L, 0.0, out=L), out=L)
    J = np.empty((*L.shape[:-1], 3, 2))
    _jacobian_sincos(d, sa, ca, sb, cb, J)
    finite = finite_samples(J, 2)  # as singularity_map's
    smax, smin = _singular_values(np.where(finite[..., None, None], J, 0.0))
    return _map(d, L, J, _measures(smax, smin, finite, SINGULAR_RTOL))  # type: ignore[arg-type]


def _singular_values(J: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(sigma_max, sigma_min) of leg Jacobians ``J (..., 3, 2)`` in closed form, to a few ulps each.

    Legs 1 and 2 do not move with alpha (``J[..., 0:2, 0] = 0``), so turning rows 0 and 1 into
    ``(0, hypot(J01, J11))`` and ``(0, 0)`` (an orthogonal transform: the same singular values) leaves
    the upper triangular ``[[f, g], [0, h]] = [[J20, J21], [0, hypot(J01, J11)]]``, whose singular values
    are LAPACK's ``dlas2`` (Demmel and Kahan's formula, high relative accuracy for both; LAPACK's SVD of
    J, in :func:`~robomech.analysis.workspace.singularity_map`, is accurate to rounding of sigma_max in
    each).  ~25x faster than that SVD on 3x2 matrices, the study's dominant cost.
    """
    fa, ga, ha = np.abs(J[..., 2, 0]), np.abs(J[..., 2, 1]), np.hypot(J[..., 0, 1], J[..., 1, 1])
    fhmn, fhmx = np.minimum(fa, ha), np.maximum(fa, ha)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        big, small = np.maximum(fhmx, ga), np.minimum(fhmx, ga)
        smax0 = np.where(big > 0, big * np.sqrt(1.0 + (small / big) ** 2), 0.0)  # fhmn = 0: rank <= 1
        as_, at = 1.0 + fhmn / fhmx, (fhmx - fhmn) / fhmx
        au = (ga / fhmx) ** 2  # ga < fhmx
        c = 2.0 / (np.sqrt(as_ * as_ + au) + np.sqrt(at * at + au))
        smin1, smax1 = fhmn * c, fhmx / c
        au = fhmx / ga  # ga >= fhmx
        c = 1.0 / (np.sqrt(1.0 + (as_ * au) ** 2) + np.sqrt(1.0 + (at * au) ** 2))
        smin2 = np.where(au == 0, (fhmn * fhmx) / ga, 2.0 * ((fhmn * c) * au))
        smax2 = np.where(au == 0, ga, ga / (c + c))
    lo = fhmn == 0
    smax = np.where(lo, smax0, np.where(ga < fhmx, smax1, smax2))
    smin = np.where(lo, 0.0, np.where(ga < fhmx, smin1, smin2))
    return smax, smin


def inverse_dynamics_designs(
    d: Designs, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, driven_legs: tuple[int, int] | None
) -> InverseDynamicsResult:
    """:func:`~robomech.mechanisms.spherical_leg.inverse_dynamics` of every design along one motion
    ``q, qd, qdd (T, 2)``, without an external wrench: each field ``(D, T, ...)``."""
    dd = Designs(d.legs, d.R, d.r, d.h[..., None])  # the platform centre h Rp e_z is (D, T, 3)
    m = _motion(dd, q, qd, qdd)  # type: ignore[arg-type]
    tau = _generalized(dd, m, None)  # type: ignore[arg-type]
    dist = distribute_forces(m.Jl, tau, driven_legs)
    valid = dist.valid & ~m.lock
    return InverseDynamicsResult(tau, dist.forces, dist.residual, valid, dist.sigma_min, dist.rcond)
