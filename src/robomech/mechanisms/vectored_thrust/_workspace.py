"""Workspace, singularity and dexterity maps of the vectored thruster over its inputs (paper 5, Section 4);
paper 5, eq. (35)'s "no singularity" tests the wrong matrix (docs/mechanisms/vectored_thrust.md,
"Departures")."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._batching import carries_failed_rows
from robomech._validation import as_array, check_params
from robomech.analysis.workspace import SINGULAR_RTOL, grid

from ._kinematics import _chunked, _fk, _interference, _jacobian, _q
from ._params import VectoredThruster

__all__ = [
    "DEXTERITY_TOL",
    "WorkspaceMap",
    "dexterity",
    "idle_input_curve",
    "input_grid",
    "singular_points",
    "workspace_map",
]

# sigma_min / sigma_max of J below which an input configuration counts as singular in the maps, applied
# to the closed form: the shared threshold.
DEXTERITY_TOL = SINGULAR_RTOL


@dataclass(frozen=True)
class WorkspaceMap:
    """Section 4 of paper 5 per input sample (:func:`workspace_map`).

    Attributes
    ----------
    q : ndarray, shape (..., 2)
        The input samples (rad).
    tip, tilt, in_range, tilt_ok : ndarray
        As in :class:`FKResult`.
    clearance, distance, dexterity : ndarray, shape (...)
        Angular clearance of the 45° arc from the fixing device (rad); ``|s22 x s12|`` (0 where the passive
        axes are parallel); ``1 / cond(J)`` in [0, 1], 0 where singular.
    singular, clear, reachable : ndarray of bool, shape (...)
        ``dexterity < DEXTERITY_TOL`` or passive axes parallel; ``clearance >= interference_clearance``;
        ``in_range & tilt_ok & clear`` and not singular.
    """

    q: np.ndarray
    tip: np.ndarray
    tilt: np.ndarray
    clearance: np.ndarray
    distance: np.ndarray
    dexterity: np.ndarray
    singular: np.ndarray
    in_range: np.ndarray
    tilt_ok: np.ndarray
    clear: np.ndarray
    reachable: np.ndarray


def _dexterity(J: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """1/cond of each (..., 3, 2) J from the eigenvalues of the 2x2 J^T J in closed form by component-wise
    sums (no SVD, no (..., 3, 2) temporaries); J is NaN where not ``ok``, masked at the end."""
    with np.errstate(invalid="ignore", divide="ignore"):
        j00, j10, j20 = J[..., 0, 0], J[..., 1, 0], J[..., 2, 0]
        j01, j11, j21 = J[..., 0, 1], J[..., 1, 1], J[..., 2, 1]
        a = j00 * j00 + j10 * j10 + j20 * j20
        b = j00 * j01 + j10 * j11 + j20 * j21
        c = j01 * j01 + j11 * j11 + j21 * j21
        half_tr = 0.5 * (a + c)
        root = np.sqrt(np.maximum(0.25 * (a - c) ** 2 + b * b, 0.0))
        lmax = half_tr + root
        pos = lmax > 0
        inv_lmax = 1.0 / np.where(pos, lmax, 1.0)
        lmin = np.maximum((a * c - b * b) * inv_lmax, 0.0)  # det / lmax: no cancellation
        ratio = np.sqrt(lmin * inv_lmax)
        return np.where(ok & pos, ratio, 0.0)


@carries_failed_rows({"q": 1})
def dexterity(th: VectoredThruster, q: object) -> np.ndarray:
    """Dexterity ``1/cond(J) = sigma_min / sigma_max`` of the platform Jacobian, in [0, 1] (0 where singular).

    Parameters
    ----------
    th : VectoredThruster
    q : array_like, shape (..., 2)

    Returns
    -------
    ndarray, shape (...)
    """
    check_params(th, VectoredThruster, "th")
    jr = _jacobian(th, _q(q))
    return _dexterity(jr.J, jr.valid)


@carries_failed_rows({"q": 1})
def workspace_map(th: VectoredThruster, q: object) -> WorkspaceMap:
    """Section 4 at each input sample ``q``: tip, limits, singularity, dexterity.

    Parameters
    ----------
    th : VectoredThruster
    q : array_like, shape (..., 2)
        Inputs (rad), e.g. :func:`input_grid`.

    Returns
    -------
    WorkspaceMap
    """
    check_params(th, VectoredThruster, "th")
    return _chunked(_workspace_map, th, _q(q))


def _workspace_map(th: VectoredThruster, q: np.ndarray) -> WorkspaceMap:
    fk = _fk(th, q)
    jr = _jacobian(th, q)
    dex = _dexterity(jr.J, jr.valid)
    clearance = _interference(th, q)
    singular = ~jr.valid | (dex < DEXTERITY_TOL)
    with np.errstate(invalid="ignore"):
        clear = jr.valid & (clearance >= th.interference_clearance)
    return WorkspaceMap(
        q=q,
        tip=fk.tip,
        tilt=fk.tilt,
        clearance=clearance,
        distance=jr.distance,
        dexterity=dex,
        singular=singular,
        in_range=fk.in_range,
        tilt_ok=fk.tilt_ok,
        clear=clear,
        reachable=fk.in_range & fk.tilt_ok & clear & ~singular,
    )


def input_grid(th: VectoredThruster, n: int | tuple[int, int], limits: object = None) -> np.ndarray:
    """Regular grid of inputs (rad), the ends included.

    Parameters
    ----------
    th : VectoredThruster
    n : int or tuple of int
        Samples per input (each >= 2): one count for both, or ``(n1, n2)``.
    limits : array_like, shape (2, 2), optional
        ``[[lo1, hi1], [lo2, hi2]]`` (rad), lo < hi; default ``q1_limits``, ``q2_limits``.

    Returns
    -------
    ndarray, shape (n1, n2, 2)
    """
    check_params(th, VectoredThruster, "th")
    lim = np.array([th.q1_limits, th.q2_limits]) if limits is None else as_array(limits, "limits", (2, 2))
    if lim.shape != (2, 2) or np.any(lim[:, 1] <= lim[:, 0]):
        raise ValueError(f"Expected limits of shape (2, 2) with lo < hi per input, got {lim.tolist()}.")
    return grid(lim, n)


def singular_points(th: VectoredThruster) -> np.ndarray:
    """The passive-axes-parallel singular inputs ``(0, a), (pi, -a)`` (rad), a = ``th.arc_angle``.

    Parameters
    ----------
    th : VectoredThruster

    Returns
    -------
    ndarray, shape (2, 2)
    """
    check_params(th, VectoredThruster, "th")
    a = th.arc_angle
    return np.array([[0.0, a], [np.pi, -a]])


@carries_failed_rows({"q1": 0})
def idle_input_curve(th: VectoredThruster, q1: object) -> np.ndarray:
    """q2 (rad) on the curve ``tan q2 = tan a / cos q1`` where input 1 is idle (X, s12, s13 coplanar) and
    J loses rank, for |q1| < pi/2.

    Parameters
    ----------
    th : VectoredThruster
    q1 : array_like, shape (...)
        Input 1 angles (rad).

    Returns
    -------
    ndarray, shape (...)

    Examples
    --------
    >>> th = VectoredThruster.paper()
    >>> q2 = idle_input_curve(th, 0.3)
    >>> float(dexterity(th, [0.3, float(q2)])) < 1e-8
    True
    """
    check_params(th, VectoredThruster, "th")
    q1 = as_array(q1, "q1")
    return np.arctan2(np.tan(th.arc_angle), np.cos(q1))
