"""Reachable workspace and singularity map of the spherical parallel leg over (alpha, beta): J loses rank
exactly where dl3/dalpha = 0, the boundary of the assembly branches (docs/mechanisms/spherical_leg.md)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._batching import carries_failed_rows
from robomech._validation import check_params
from robomech.analysis.workspace import SINGULAR_RTOL, SingularityMap, singularity_map

from ._kinematics import _angles, inverse_kinematics, jacobian
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
