"""Forward kinematics along a trajectory of leg lengths that keeps its assembly branch (continuation).

The l3 equation ``sin(α - φ) = s`` has two solutions per sample, ``α0 = φ + asin s`` (branch 0, which
contains α = 0) and ``α1 = φ + π - asin s`` (branch 1).  They meet where ``|s| = 1``, i.e. on the
actuation-singular curve ``∂l3/∂α = 0`` (``h cos β cos α + r sin α = 0``).  A motion that crosses that
curve (paper 1's Fig. 5(a) does, twice per period) passes from one branch to the other: a
forward kinematics that keeps branch 0 then returns the mirror image of the pose about the curve with a
residual of 0, indistinguishable from the right pose by the lengths alone.

:func:`track_branches` solves both branches for every sample and follows the motion: between the
samples where the branches meet the branch cannot change (the two solutions are separated), and at
each meeting it keeps the continuation that best continues the motion so far (quadratic extrapolation
of the three samples before the meeting to the two after it), which separates a crossing of the curve
(α moves on through it) from a touch (α turns back).  The separation of the two solutions is returned
per sample, and the meetings are reported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._validation import as_array, check_int, check_params

from ._kinematics import forward_kinematics
from ._params import SphericalLeg

__all__ = ["BranchTrack", "track_branches"]

# A local minimum of the branch separation counts as a meeting of the branches (a place where the
# motion may change branch) when the separation there is at most this many times the largest step of
# α between neighbouring samples: near the singular curve the separation is 2 |α - α_s| (the two
# solutions are mirror images about α_s), so a crossing between two samples leaves a separation of at
# most 2 steps at the nearer one; 2.5 allows for the curvature of the motion within the step.
MEET_STEP_FACTOR = 2.5


@dataclass(frozen=True)
class BranchTrack:
    """Forward kinematics along a trajectory (the result of :func:`track_branches`).

    Axis -1 of every field is time (N samples); leading axes are independent trajectories.

    Attributes
    ----------
    alpha, beta : ndarray, shape (..., N)
        Platform angles (rad); NaN where not ``valid``.
    residual : ndarray, shape (..., N)
        Length residual (m), as in :func:`forward_kinematics`.
    valid : ndarray of bool, shape (..., N)
        Both closed-form solutions exist (finite positive lengths that assemble).
    branch : ndarray of int8, shape (..., N)
        Which closed-form solution the motion is on (0 or 1); -1 where not valid.
    separation : ndarray, shape (..., N)
        Angle between the two solutions (rad); 0 on the singular curve.
    meeting : ndarray of bool, shape (..., N)
        Samples where the branches meet (within the sampling, see ``MEET_STEP_FACTOR``), i.e. where the
        tracker had to choose.
    switched : ndarray of bool, shape (..., N)
        The meetings where the motion changed branch.
    """

    alpha: np.ndarray
    beta: np.ndarray
    residual: np.ndarray
    valid: np.ndarray
    branch: np.ndarray
    separation: np.ndarray
    meeting: np.ndarray
    switched: np.ndarray


def _wrap(x: np.ndarray) -> np.ndarray:
    return (x + np.pi) % (2.0 * np.pi) - np.pi


def _extrapolate(past_t: np.ndarray, past_a: np.ndarray, at: np.ndarray) -> np.ndarray:
    """The interpolating polynomial of (at most 3) past samples evaluated at ``at`` (sample indices).

    Quadratic: exact for a motion that touches the curve and turns back, where a second difference
    cannot tell the two continuations apart.
    """
    if past_t.size == 1:
        return np.full(at.shape, past_a[0])
    c = np.polyfit(past_t - past_t[-1], past_a, past_t.size - 1)
    return np.polyval(c, at - past_t[-1])


def track_branches(leg: SphericalLeg, lengths: object, *, branch: int = 0) -> BranchTrack:
    """Platform angles along a trajectory of leg lengths ``(..., N, 3)`` (m), starting on ``branch``.

    The time axis is the second-to-last axis of ``lengths`` (N >= 1 samples in order); leading axes are
    independent trajectories.  Samples that do not assemble are flagged (``valid`` False) and bridged:
    the branch carries across them.  Where the two closed-form solutions of :func:`forward_kinematics`
    meet, the tracker keeps the one that continues the motion (a quadratic extrapolation of the
    preceding samples).

    Parameters
    ----------
    leg : SphericalLeg
        The leg's geometry (m).
    lengths : array_like, shape (..., N, 3)
        Leg lengths ``(l1, l2, l3)`` (m) at N >= 1 consecutive samples of each trajectory; non-finite or
        non-positive samples are flagged, not raised.
    branch : {0, 1}, optional
        The assembly branch at the first sample (0: the one containing alpha = 0).

    Returns
    -------
    BranchTrack
        ``alpha``, ``beta`` (rad), ``residual`` (m), ``valid``, ``branch``, ``separation`` (rad),
        ``meeting`` and ``switched``, each of shape ``(..., N)``.

    Raises
    ------
    ValueError
        If ``leg`` is not a :class:`SphericalLeg`, ``lengths`` does not end in a sample axis and an axis
        of 3 or has a non-real dtype, or ``branch`` is not 0 or 1.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.mechanisms import spherical_leg as sl
    >>> leg = sl.SphericalLeg.paper()
    >>> L = sl.inverse_kinematics(leg, np.linspace(0.0, 0.3, 5), 0.1).lengths   # (5, 3), m
    >>> tr = sl.track_branches(leg, L)
    >>> tr.alpha.round(6) + 0.0, tr.branch
    (array([0.   , 0.075, 0.15 , 0.225, 0.3  ]), array([0, 0, 0, 0, 0], dtype=int8))
    """
    check_params(leg, SphericalLeg, "leg")
    branch = check_int(branch, "branch", low=0, high=1)
    L = as_array(lengths, "lengths", (None, 3), finite=False)
    shape = L.shape[:-1]
    n_traj = int(np.prod(shape[:-1], dtype=int))
    Lf = L.reshape(n_traj, shape[-1], 3)  # explicit: -1 is ambiguous for an empty batch
    f0 = forward_kinematics(leg, Lf, branch=0)
    f1 = forward_kinematics(leg, Lf, branch=1)
    a = np.stack([f0.alpha, f1.alpha], -1)  # (B, N, 2)
    valid = f0.valid & f1.valid
    sep = np.abs(_wrap(a[..., 0] - a[..., 1]))
    B, N = valid.shape
    br = np.full((B, N), branch, dtype=np.int8)
    meeting = np.zeros((B, N), dtype=bool)
    switched = np.zeros((B, N), dtype=bool)
    for i in range(B):  # independent trajectories; within one, a loop over its meetings only
        idx = np.flatnonzero(valid[i])
        if idx.size < 3:
            continue
        s = sep[i, idx]
        ai = a[i, idx]  # (M, 2)
        step = np.max(np.abs(_wrap(np.diff(ai, axis=0))), axis=-1)  # (M-1,) largest step of either branch
        local_min = (s[1:-1] <= s[:-2]) & (s[1:-1] <= s[2:])
        scale = np.maximum(step[:-1], step[1:])
        cand = np.flatnonzero(local_min & (s[1:-1] <= MEET_STEP_FACTOR * scale)) + 1
        cur = branch
        seg = np.zeros(idx.size, dtype=np.int8)
        start = 0
        M = idx.size
        cand_list: list[int] = [int(x) for x in cand]
        for k in cand_list:  # positions in idx
            seg[start:k] = cur
            # the motion before the meeting (samples k-3 .. k-1; the meeting sample itself may already
            # lie on the other side) extrapolated to k, k+1, k+2; keep the continuation that fits it
            past = np.arange(max(0, k - 3), k)
            pa = np.unwrap(ai[past, seg[past]])
            ahead = np.arange(k + 1, min(M, k + 3))
            pred = _extrapolate(past.astype(float), pa, np.concatenate([[k], ahead]).astype(float))
            err = [float(np.sum(np.abs(_wrap(ai[ahead, b] - pred[1:])))) for b in (0, 1)]
            new = cur if err[cur] <= err[1 - cur] else 1 - cur
            # the meeting sample itself: the solution nearer the extrapolation
            seg[k] = 0 if abs(_wrap(ai[k, 0] - pred[0])) <= abs(_wrap(ai[k, 1] - pred[0])) else 1
            meeting[i, idx[k]] = True
            switched[i, idx[k]] = new != cur
            cur = new
            start = k + 1
        seg[start:] = cur
        # invalid samples between valid ones carry the branch of the preceding valid sample
        full = np.full(N, branch, dtype=np.int8)
        full[idx] = seg
        carry = np.maximum.accumulate(np.where(valid[i], np.arange(N), -1))
        full = np.where(carry >= 0, full[np.maximum(carry, 0)], branch)
        br[i] = full
    alpha = np.where(br == 0, a[..., 0], a[..., 1])
    resid = np.where(br == 0, f0.residual, f1.residual)
    out = dict(
        alpha=np.where(valid, alpha, np.nan),
        beta=np.where(valid, f0.beta, np.nan),
        residual=np.where(valid, resid, np.nan),
        valid=valid,
        branch=np.where(valid, br, -1).astype(np.int8),
        separation=np.where(valid, sep, np.nan),
        meeting=meeting,
        switched=switched,
    )
    return BranchTrack(**{k: v.reshape(shape) for k, v in out.items()})
