"""Reachable workspace and singularity map of the spherical parallel leg over (alpha, beta).

J = dl/d(alpha, beta) has rows (0, dl1/db), (0, dl2/db), (dl3/da, dl3/db): dl1/db and dl2/db never
vanish together, so J loses rank exactly where dl3/da = 0, i.e. ``h cos b cos a + r sin a = 0``: the
boundary between the two assembly branches of the l3 equation, where alpha is no longer controlled.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._validation import check_params

# the unvalidated kernel: inputs are validated once at this module's public boundary
from robomech.spatial._so3 import _sincos as sincos

from ._kinematics import LENGTH_FLOOR, _angles, _chunked, _squared_length_columns
from ._params import SphericalLeg

__all__ = ["WorkspaceMap", "workspace_map"]

# A pose counts as singular when sigma_min/sigma_max of J falls below this (as
# robomech.analysis.workspace.SINGULAR_RTOL: a 1e8 amplification has no physical meaning here).
SINGULAR_RTOL = 1e-8
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


def workspace_map(leg: SphericalLeg, alpha: object, beta: object) -> WorkspaceMap:
    """Workspace and singularity map at poses ``alpha``, ``beta`` (rad, broadcast) in closed form.

    The singular values of the 3x2 J come from the eigenvalues of the 2x2 Gram matrix J^T J.

    Parameters
    ----------
    leg : SphericalLeg
        The leg's geometry (m) and stroke (``length_min``, ``length_max``).
    alpha, beta : array_like, shape (...)
        Platform angles (rad); broadcast together (e.g. a meshgrid).

    Returns
    -------
    WorkspaceMap
        ``lengths (..., 3)`` (m), ``reachable``, ``sigma_min``, ``sigma_max`` (m/rad), ``cond``,
        ``singular``, ``ill_conditioned`` and ``dl3_dalpha`` (m/rad), each of shape ``(...)``.

    Raises
    ------
    ValueError
        If ``leg`` is not a :class:`SphericalLeg`, or an angle is not real and finite, or the angles do
        not broadcast.

    Examples
    --------
    >>> from robomech.mechanisms import spherical_leg as sl
    >>> ws = sl.workspace_map(sl.SphericalLeg.paper(), [0.0, 0.1], 0.05)
    >>> ws.lengths.shape, ws.singular
    ((2, 3), array([False, False]))
    """
    check_params(leg, SphericalLeg, "leg")
    a, b = _angles(alpha, beta)
    n = a.size
    outs = (np.empty((n, 3)), np.empty(n, dtype=bool), np.empty(n), np.empty(n), np.empty(n), np.empty(n))
    _chunked(lambda *x: _kernel(leg, *x), (a.reshape(-1), b.reshape(-1)), outs)
    L, reach, smin, smax, cond, j3a = (o.reshape((*a.shape, *o.shape[1:])) for o in outs)
    ratio = smin / smax
    return WorkspaceMap(L, reach, smin, smax, cond, ratio < SINGULAR_RTOL, cond > ILL_CONDITIONED, j3a)


def _kernel(leg: SphericalLeg, a, b, L_out, reach_out, smin_out, smax_out, cond_out, j3a_out) -> None:
    (sa, ca), (sb, cb) = sincos(a), sincos(b)
    R, r, h = leg.R, leg.r, leg.h
    # column by column: numpy's reductions over a length-3 last axis cost ~15 ms per 10^6 rows here
    lengths = []
    for k, qk in enumerate(_squared_length_columns(leg, sa, ca, sb, cb)):
        lk = np.sqrt(np.maximum(qk, 0.0, out=qk), out=qk)
        L_out[:, k] = lk
        lengths.append(lk)
    l1, l2, l3 = lengths
    reach_out[:] = (
        (l1 >= leg.length_min)
        & (l1 <= leg.length_max)
        & (l2 >= leg.length_min)
        & (l2 <= leg.length_max)
        & (l3 >= leg.length_min)
        & (l3 <= leg.length_max)
    )
    hcb = h * cb
    rsb = r * sb
    j1b = R * (rsb - hcb) / np.maximum(l1, LENGTH_FLOOR)
    j2b = R * (rsb + hcb) / np.maximum(l2, LENGTH_FLOOR)
    k3 = R / np.maximum(l3, LENGTH_FLOOR)
    j3a = (r * sa + hcb * ca) * k3
    j3b = -(h * sb * sa) * k3
    g11 = j3a * j3a
    g22 = j1b * j1b + j2b * j2b + j3b * j3b
    g12 = j3a * j3b
    half_tr = 0.5 * (g11 + g22)
    dg = 0.5 * (g11 - g22)
    disc = np.sqrt(dg * dg + g12 * g12)
    lam_max = half_tr + disc
    # det / lam_max avoids the cancellation of half_tr - disc
    lam_min = np.maximum(g11 * g22 - g12 * g12, 0.0) / lam_max
    np.sqrt(lam_max, out=smax_out)
    np.sqrt(lam_min, out=smin_out)
    ratio = smin_out / smax_out
    np.divide(1.0, ratio, out=cond_out, where=ratio > 0)
    cond_out[~(ratio > 0)] = np.inf
    j3a_out[:] = j3a
