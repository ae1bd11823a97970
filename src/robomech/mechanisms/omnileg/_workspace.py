"""Foot workspace and singularity map of the OmniLeg over Table 2's joint ranges (paper 2): the knee's sphere
patch swept by the shank's stroke, singular only where γ = 0, and Section 1's symmetry claim tested per
sample (docs/mechanisms/omnileg.md)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._batching import carries_failed_rows
from robomech._validation import as_array, broadcast_to_batch, check_int, check_params
from robomech.analysis.workspace import grid, singularity_map

from ._dynamics import SINGULAR_RCOND
from ._kinematics import forward_kinematics, inverse_kinematics, jacobian, within_limits
from ._params import OmniLeg

__all__ = [
    "FootWorkspace",
    "SymmetryResult",
    "WorkspaceMap",
    "foot_workspace",
    "joint_grid",
    "singular_surface",
    "workspace_map",
    "workspace_symmetry",
]

# Gauss-Legendre nodes per joint coordinate for the area integral: the integrand is analytic on the
# box, and 48 nodes integrate it to rounding (tested against 96 nodes and the boundary's shoelace area).
AREA_NODES = 48
# Points per box edge of the projected boundary polyline returned by foot_workspace.
BOUNDARY_POINTS = 200


@dataclass(frozen=True)
class WorkspaceMap:
    """Foot position and singularity measures per joint sample (the result of :func:`workspace_map`).

    Attributes
    ----------
    q : ndarray, shape (..., 3)
        The joint samples ``(α, β, γ)`` (rad).
    foot : ndarray, shape (..., 3)
        Foot position in the hip frame (m).
    within_limits : ndarray of bool, shape (...)
        The sample is within Table 2's joint ranges.
    det : ndarray, shape (...)
        Determinant of the foot Jacobian (m³/rad³).
    cond, dexterity, sigma_min, singular : ndarray, shape (...)
        The foot Jacobian's :class:`robomech.analysis.workspace.SingularityMap` (sigma_min in m/rad),
        singular below ``SINGULAR_RCOND`` (the damped solves' threshold; γ ≈ 0).
    """

    q: np.ndarray
    foot: np.ndarray
    within_limits: np.ndarray
    det: np.ndarray
    cond: np.ndarray
    dexterity: np.ndarray
    sigma_min: np.ndarray
    singular: np.ndarray


def joint_grid(leg: OmniLeg, n: int | tuple[int, int, int]) -> np.ndarray:
    """Regular grid of joint samples (rad) over Table 2's joint ranges, the range ends included.

    Parameters
    ----------
    leg : OmniLeg
    n : int or tuple of int
        Samples per joint (each >= 2): one count for all three, or ``(n_α, n_β, n_γ)``.

    Returns
    -------
    ndarray, shape (n_α, n_β, n_γ, 3)
    """
    check_params(leg, OmniLeg, "leg")
    ranges = [(-leg.alpha_max, leg.alpha_max), (-leg.beta_max, leg.beta_max), (leg.gamma_min, leg.gamma_max)]
    return grid(ranges, n)


@carries_failed_rows({"q": 1})
def workspace_map(leg: OmniLeg, q: object) -> WorkspaceMap:
    """Foot position and Jacobian conditioning (paper 2, eqs. (11), (14)) at joint samples ``q``.

    Parameters
    ----------
    leg : OmniLeg
    q : array_like, shape (..., 3)
        Joint samples (rad), e.g. :func:`joint_grid`.

    Returns
    -------
    :class:`WorkspaceMap`

    Examples
    --------
    >>> leg = OmniLeg.paper()
    >>> w = workspace_map(leg, joint_grid(leg, 5))
    >>> w.foot.shape, bool(w.singular[..., 0].all()), bool(w.singular[..., 1:].any())  # γ = 0 singular
    ((5, 5, 5, 3), True, False)
    """
    check_params(leg, OmniLeg, "leg")
    q = as_array(q, "q", (3,))
    J = jacobian(leg, q)
    sm = singularity_map(J, rtol=SINGULAR_RCOND)
    return WorkspaceMap(
        q=q,
        foot=forward_kinematics(leg, q),
        within_limits=within_limits(leg, q),
        det=np.linalg.det(J),
        cond=sm.cond,
        dexterity=sm.dexterity,
        sigma_min=sm.sigma_min,
        singular=sm.singular,
    )


def singular_surface(leg: OmniLeg, alpha: object, beta: object) -> np.ndarray:
    """Foot positions ``FK(α, β, 0)`` (m) on the singular surface γ = 0 (the fully extended shank).

    Parameters
    ----------
    leg : OmniLeg
    alpha, beta : array_like, shape (...)

    Returns
    -------
    ndarray, shape (..., 3)
    """
    check_params(leg, OmniLeg, "leg")
    a = as_array(alpha, "alpha")
    b = as_array(beta, "beta")
    a, b = broadcast_to_batch((a, 0, "alpha"), (b, 0, "beta"))
    return forward_kinematics(leg, np.stack([a, b, np.zeros_like(a)], -1))


@dataclass(frozen=True)
class FootWorkspace:
    """The foot workspace over the joint ranges (the result of :func:`foot_workspace`).

    Attributes
    ----------
    volume, projected_area, stroke : float
        ``projected_area * stroke`` (m³); area of the horizontal section, the knee patch seen from above
        (m²); vertical travel of the shank ``2 L4 (max cos γ - min cos γ)`` (m).
    boundary : ndarray, shape (M, 2)
        Closed horizontal boundary ``(x, y)`` (m, hip frame), ``M = 4 BOUNDARY_POINTS``: the images
        of the edges ``|α| = α_max``, ``|β| = β_max``.
    depth_min, depth_max, radius_max : float
        Shallowest and deepest foot positions along Z0, largest horizontal distance from Z0 (m).
    """

    volume: float
    projected_area: float
    stroke: float
    boundary: np.ndarray
    depth_min: float
    depth_max: float
    radius_max: float


def _projected_jacobian_det(leg: OmniLeg, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|∂(x, y)/∂(α, β)| of the knee (the foot's horizontal position), from the analytic J."""
    J = jacobian(leg, np.stack([a, b, np.zeros_like(a)], -1))
    return np.abs(J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0])


def foot_workspace(leg: OmniLeg, *, nodes: int = AREA_NODES) -> FootWorkspace:
    """Volume, horizontal section, boundary and extent of the foot workspace over Table 2's ranges (the
    area: a Gauss-Legendre double integral over (α, β) of the knee's projected Jacobian determinant).

    Parameters
    ----------
    leg : OmniLeg
    nodes : int, optional
        Gauss-Legendre nodes per joint coordinate (>= 2).

    Returns
    -------
    :class:`FootWorkspace`
    """
    check_params(leg, OmniLeg, "leg")
    nodes = check_int(nodes, "nodes", low=2)
    x, w = np.polynomial.legendre.leggauss(nodes)
    A, B = leg.alpha_max, leg.beta_max
    a, b = np.meshgrid(A * x, B * x, indexing="ij")
    area = float(A * B * np.sum(np.outer(w, w) * _projected_jacobian_det(leg, a, b)))
    # cos γ over [γ_min, γ_max] ⊂ (-90°, 90°): smallest at an end, largest at 0 if the range holds it
    ends = (float(np.cos(leg.gamma_min)), float(np.cos(leg.gamma_max)))
    c_lo = min(ends)
    c_hi = 1.0 if leg.gamma_min <= 0.0 <= leg.gamma_max else max(ends)
    stroke = 2.0 * leg.L4 * (c_hi - c_lo)
    t = np.linspace(-1.0, 1.0, BOUNDARY_POINTS)
    one = np.ones_like(t)
    edges = [
        np.stack([A * one, B * t], -1),
        np.stack([-A * t, B * one], -1),
        np.stack([-A * one, -B * t], -1),
        np.stack([A * t, -B * one], -1),
    ]
    ab = np.concatenate(edges)
    knee = forward_kinematics(leg, np.concatenate([ab, np.zeros((len(ab), 1))], -1))
    boundary = knee[:, :2]
    # depths: the knee is shallowest at the box's corners and deepest at α = β = 0
    corner = forward_kinematics(leg, [A, B, 0.0])[2] - (leg.L5 + 2 * leg.L4)
    return FootWorkspace(
        volume=area * stroke,
        projected_area=area,
        stroke=stroke,
        boundary=boundary,
        depth_min=float(corner + leg.L5 + 2 * leg.L4 * c_lo),
        depth_max=float(leg.L1 + leg.L5 + 2 * leg.L4 * c_hi),
        radius_max=float(np.max(np.linalg.norm(boundary, axis=-1))),
    )


@dataclass(frozen=True)
class SymmetryResult:
    """Per foot sample: is it reachable, and does each symmetry's image agree (:func:`workspace_symmetry`).

    Attributes
    ----------
    reachable : ndarray of bool, shape (...)
        The foot sample is reachable within Table 2's ranges.
    mirror_x, mirror_y, swap : ndarray of bool, shape (...)
        The image under x -> -x, y -> -y, (x, y) -> (-y, -x) (the α <-> β exchange) has the same reachability.
    holds : ndarray of bool, shape (...)
        ``mirror_x & mirror_y & swap``.
    """

    reachable: np.ndarray
    mirror_x: np.ndarray
    mirror_y: np.ndarray
    swap: np.ndarray
    holds: np.ndarray


def workspace_symmetry(leg: OmniLeg, p_foot: object) -> SymmetryResult:
    """Test paper 2's claim that the foot workspace is symmetric (the reflections x -> -x, y -> -y and,
    for α_max = β_max, the swap (x, y) -> (-y, -x): a square's symmetry about Z0) at foot positions.

    Parameters
    ----------
    leg : OmniLeg
    p_foot : array_like, shape (..., 3)
        Foot positions in the hip frame (m); non-finite samples are unreachable, as are their images.

    Returns
    -------
    :class:`SymmetryResult`
    """
    check_params(leg, OmniLeg, "leg")
    p = as_array(p_foot, "p_foot", (3,), finite=False)
    images = np.stack(
        [
            p,
            p * np.array([-1.0, 1.0, 1.0]),
            p * np.array([1.0, -1.0, 1.0]),
            np.stack([-p[..., 1], -p[..., 0], p[..., 2]], -1),
        ],
        axis=-2,
    )
    r = inverse_kinematics(leg, images).reachable
    base = r[..., 0]
    mx, my, sw = (r[..., k] == base for k in (1, 2, 3))
    return SymmetryResult(reachable=base, mirror_x=mx, mirror_y=my, swap=sw, holds=mx & my & sw)
