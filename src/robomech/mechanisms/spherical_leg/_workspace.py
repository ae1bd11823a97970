"""Reachable workspace and singularity map of the spherical parallel leg over (alpha, beta): J loses rank
exactly where dl3/dalpha = 0, the boundary of the assembly branches (docs/mechanisms/spherical_leg.md)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._batching import carries_failed_rows
from robomech._validation import check_params, finite_samples
from robomech.analysis.workspace import SINGULAR_RTOL, SingularityMap, _measures, singularity_map
from robomech.spatial._so3 import _sincos as sincos

from ._kinematics import _angles, _jacobian_sincos, _squared_length_columns, inverse_kinematics, jacobian
from ._params import SphericalLeg

__all__ = ["WorkspaceMap", "workspace_map"]

# Poses whose J condition number exceeds this are reported as ill-conditioned: the platform's
# sensitivity to leg-length errors then differs by more than 100x between its two directions (both
# columns of J are in m/rad, so the ratio is unit-free).
ILL_CONDITIONED = 100.0


@dataclass(frozen=True)
class WorkspaceMap:
    """Workspace and singularity measures per pose (the result of :func:`workspace_map`).

    Attributes
    ----------
    lengths : ndarray, shape (..., 3)
        Leg lengths (m).
    reachable : ndarray of bool, shape (...)
        Every leg within ``[length_min, length_max]``.
    sigma_min, sigma_max : ndarray, shape (...)
        Smallest and largest singular value of the leg Jacobian J (m/rad).
    cond : ndarray, shape (...)
        Condition number ``sigma_max / sigma_min`` of J (unit-free).
    singular : ndarray of bool, shape (...)
        ``sigma_min / sigma_max < SINGULAR_RTOL``.
    ill_conditioned : ndarray of bool, shape (...)
        ``cond > ILL_CONDITIONED``.
    dl3_dalpha : ndarray, shape (...)
        ``d l3 / d alpha`` (m/rad), whose sign marks the assembly branch.
    """

    lengths: np.ndarray
    reachable: np.ndarray
    sigma_min: np.ndarray
    sigma_max: np.ndarray
    cond: np.ndarray
    singular: np.ndarray
    ill_conditioned: np.ndarray
    dl3_dalpha: np.ndarray


@carries_failed_rows({"alpha": 0, "beta": 0})
def workspace_map(leg: SphericalLeg, alpha: object, beta: object) -> WorkspaceMap:
    """Workspace and singularity map at poses ``alpha``, ``beta`` (singular values of J by
    :func:`robomech.analysis.workspace.singularity_map`).

    Parameters
    ----------
    leg : SphericalLeg
    alpha, beta : array_like, shape (...)
        Platform angles (rad); broadcast together (e.g. a meshgrid).

    Returns
    -------
    :class:`WorkspaceMap`
    """
    check_params(leg, SphericalLeg, "leg")
    a, b = _angles(alpha, beta)
    return _map(leg, inverse_kinematics(leg, a, b).lengths, jacobian(leg, a, b))


def _map(leg: SphericalLeg, L: np.ndarray, J: np.ndarray, sm: SingularityMap | None = None) -> WorkspaceMap:
    """The map from the leg lengths ``L (..., 3)`` and Jacobians ``J (..., 3, 2)`` (any batch), and their
    singularity map ``sm`` if already known."""
    sm = singularity_map(J, rtol=SINGULAR_RTOL) if sm is None else sm
    # rank <= 1 where sigma_min = 0: then sigma_max is J's Frobenius norm
    frob = np.sqrt(np.einsum("...ij,...ij->...", J, J))
    smax = np.where(sm.dexterity > 0, sm.sigma_min / np.where(sm.dexterity > 0, sm.dexterity, 1.0), frob)
    reach = np.all((L >= leg.length_min) & (L <= leg.length_max), axis=-1)
    return WorkspaceMap(
        L, reach, sm.sigma_min, smax, sm.cond, sm.singular, sm.cond > ILL_CONDITIONED, J[..., 2, 0]
    )


def _map_closed_form(leg: SphericalLeg, alpha: np.ndarray, beta: np.ndarray) -> WorkspaceMap:
    """:func:`workspace_map` at poses ``alpha``, ``beta`` (rad, unvalidated) by :func:`_singular_values`;
    ``leg`` may carry per-design arrays broadcasting against the poses (a design study's legs)."""
    (sa, ca), (sb, cb) = sincos(alpha), sincos(beta)
    L = np.stack(_squared_length_columns(leg, sa, ca, sb, cb), -1)
    np.sqrt(np.maximum(L, 0.0, out=L), out=L)
    J = np.empty((*L.shape[:-1], 3, 2))
    _jacobian_sincos(leg, sa, ca, sb, cb, J)
    finite = finite_samples(J, 2)  # as singularity_map's
    smax, smin = _singular_values(np.where(finite[..., None, None], J, 0.0))
    return _map(leg, L, J, _measures(smax, smin, finite, SINGULAR_RTOL))


def _singular_values(J: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(sigma_max, sigma_min) of leg Jacobians ``J (..., 3, 2)`` in closed form, to a few ulps each: legs 1
    and 2 do not move with alpha (``J[..., 0:2, 0] = 0``), so an orthogonal transform of rows 0, 1 leaves
    ``[[f, g], [0, h]] = [[J20, J21], [0, hypot(J01, J11)]]`` with the same singular values, LAPACK's
    ``dlas2``'s (Demmel and Kahan's formula, high relative accuracy for both; the SVD of
    :func:`~robomech.analysis.workspace.singularity_map` is accurate to rounding of sigma_max in each).
    ~25x faster than that SVD on 3x2 matrices, the study's dominant cost."""
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
