"""Forward kinematics along a trajectory of leg lengths that keeps its assembly branch: where the two
closed-form branches meet, a crossing and a touch are fitted to the signed distance from the singular
curve and the better fit decides (docs/mechanisms/spherical_leg.md, "Branch tracking")."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from robomech._validation import as_array, check_int, check_params

from ._kinematics import forward_kinematics
from ._params import SphericalLeg

__all__ = ["BranchTrack", "track_branches"]

# A local minimum of the branch separation counts as a meeting of the branches when it is at most this
# many times the motion's step (per sample, within MEET_WINDOW samples): near the curve the separation
# is 2 |α - α_s|, so a crossing between two samples leaves at most 2 steps at the nearer one, and noise
# moves the samples next to the curve by about a step, hence 4 (a local minimum that is no crossing
# costs only a fit).
MEET_STEP_FACTOR = 4.0
# Candidate meetings closer than this many samples are one meeting (noise makes the separation wiggle
# next to the curve); two real passages stay two meetings if a sample separates them.
MEET_MERGE = 1
# Samples on either side of a meeting that the crossing / touch models are fitted to, and the degree
# of their polynomial: 32 samples average the noise nearest the curve (with 8, 30 nm of noise left most
# Fig. 5(a) meetings ambiguous); a quadratic misfits a sway passing the curve near its turning point on
# a 0.5 s grid, a cubic does not (measured: docs/mechanisms/spherical_leg.md).
MEET_WINDOW = 16
# Where MEET_WINDOW leaves a meeting ambiguous, shorter windows are tried (on a coarse grid 16 samples
# span seconds, over which no cubic follows the motion); their answer is taken only if every one decides
# and all agree (a lone short window decided wrongly once in 40 runs at 0.1 um of noise on 2001 samples;
# per grid: docs/mechanisms/spherical_leg.md).
MEET_WINDOWS = (MEET_WINDOW, 6, 4)
MEET_FIT_DEGREE = 3
# The crossing model places the passage through the curve within this many samples of the sample
# nearest it (noise of the order of a step moves that sample to either side).
MEET_SPLIT = 2
# At most this many meetings are decided together (every combination of crossing and touch is fitted).
MEET_CLUSTER_MAX = 3
# A meeting is decided when the weighted residual of the better model is below this fraction of the
# best fit that leaves the motion on the other branch.  On exact lengths the right model's residual
# is only the cubic's misfit of the motion (ratio far below 0.5); near 1 the two explain the samples
# equally well and the branch after the meeting is not known.
AMBIGUITY_RATIO = 0.5


@dataclass(frozen=True)
class BranchTrack:
    """Forward kinematics along a trajectory (the result of :func:`track_branches`).

    Axis -1 of every field is time (N samples); leading axes are independent trajectories.

    Attributes
    ----------
    alpha, beta : ndarray, shape (..., N)
        Platform angles (rad); NaN where not ``valid``.
    residual : ndarray, shape (..., N)
        Length residual (m), as in :func:`forward_kinematics`; the same on both branches, so it does
        not show which branch a sample is on.
    valid : ndarray of bool, shape (..., N)
        Both closed-form solutions exist (finite positive lengths that assemble) and the branch is
        known: False from the first ``ambiguous`` meeting on.
    branch : ndarray of int8, shape (..., N)
        Which closed-form solution the motion is on (0 or 1); -1 where not valid.
    separation : ndarray, shape (..., N)
        Angle between the two solutions (rad); 0 on the singular curve.
    meeting, switched, ambiguous : ndarray of bool, shape (..., N)
        Samples where the branches meet (within the sampling, ``MEET_STEP_FACTOR``) and the tracker had to
        choose; those where the motion changed branch; those where the samples do not tell a crossing from
        a touch (``AMBIGUITY_RATIO``).
    """

    alpha: np.ndarray
    beta: np.ndarray
    residual: np.ndarray
    valid: np.ndarray
    branch: np.ndarray
    separation: np.ndarray
    meeting: np.ndarray
    switched: np.ndarray
    ambiguous: np.ndarray


def _wrap(x: np.ndarray) -> np.ndarray:
    return (x + np.pi) % (2.0 * np.pi) - np.pi


def _fit_residual(t: np.ndarray, y: np.ndarray, w: np.ndarray) -> float:
    """Weighted residual norm of the least-squares quadratic through ``(t, y)``."""
    c = np.polynomial.polynomial.polyfit(t, y, min(MEET_FIT_DEGREE, t.size - 2), w=w)
    return float(np.linalg.norm(w * (np.polynomial.polynomial.polyval(t, c) - y)))


def _decide(t: np.ndarray, d: np.ndarray, ks: list[int]) -> tuple[list[int | None], bool]:
    """Crossing or touch at each meeting ``ks`` of a cluster: ``(splits, ambiguous)``.

    ``t``: the window's sample indices, ``d``: distances from the curve (rad).  ``splits[j]`` is the
    first sample beyond meeting j if the motion crosses there, ``None`` for a touch.  Every combination
    is fitted (the sign of σ flips at each crossing); ambiguous when the best fit with the other parity
    (the other branch after the cluster) fits almost as well.
    """
    n = t.size
    bounds = [0, *ks[1:], n]  # meeting j may place its crossing in (ks[j-1], ks[j+1]]
    options: list[list[int | None]] = []
    for j, k in enumerate(ks):
        lo_j = max(bounds[j] + (1 if j else 2), k - MEET_SPLIT)
        hi_j = min(bounds[j + 1] if j + 1 < len(ks) else n - 2, k + MEET_SPLIT + 1)
        options.append([None, *range(lo_j, hi_j + 1)])
    w = np.maximum(d, np.finfo(float).tiny)
    tc = t - t[ks[0]]  # centred: a well-conditioned Vandermonde matrix
    idx = np.arange(n)
    best: dict[int, tuple[float, list[int | None]]] = {}
    for combo in itertools.product(*options):
        flips = np.zeros(n, dtype=int)
        for p in combo:
            if p is not None:
                flips += idx >= p
        r = _fit_residual(tc, np.where(flips % 2 == 0, d, -d), w)
        parity = sum(p is not None for p in combo) % 2
        if parity not in best or r < best[parity][0]:
            best[parity] = (r, list(combo))
    if n < 5 or len(best) < 2:  # too few samples to fit either model
        return [None] * len(ks), True
    (r_win, splits), (r_other, _) = sorted(best.values(), key=lambda x: x[0])
    # where exactly each crossing lies (before or after the sample nearest the curve) matters only for
    # that sample, which the window fit weights least: the quadratic through the three samples before
    # it (signed by the decision so far) extrapolated to it puts it on its side of the curve
    sign, prev = 1.0, 0
    for j, (k, p) in enumerate(zip(ks, splits, strict=True)):
        if p is None:
            continue
        past = np.arange(max(prev, k - 3), k)
        if past.size >= 2 and abs(p - k) <= 1:
            sig = sign * d[past]
            pred = np.polyval(np.polyfit(t[past] - t[k], sig, past.size - 1), 0.0)
            splits[j] = k + 1 if pred * sign > 0 else k
        here = splits[j]
        sign, prev = -sign, (p if here is None else here)
    return splits, bool(r_win > AMBIGUITY_RATIO * r_other)


def _short_windows_agree(tries: list[tuple[list[int | None], bool, int]]) -> bool:
    """Every shorter window decided, and all call the same meetings crossings (see MEET_WINDOWS)."""
    if not tries or any(amb for _, amb, _ in tries):
        return False
    kinds = {tuple(sp is None for sp in splits) for splits, _, _ in tries}
    return len(kinds) == 1


def track_branches(leg: SphericalLeg, lengths: object, *, branch: int = 0) -> BranchTrack:
    """Platform angles along trajectories of leg lengths, starting on ``branch``.

    Samples that do not assemble are flagged (``valid`` False) and bridged: the branch carries across
    them.  A meeting of the branches neither fit explains clearly better is flagged ``ambiguous`` and
    the samples after it not ``valid``.

    Parameters
    ----------
    leg : SphericalLeg
    lengths : array_like, shape (..., N, 3)
        Leg lengths (m) at N >= 1 consecutive samples (axis -2 is time; leading axes are independent
        trajectories); non-finite or non-positive samples are flagged, not raised.
    branch : {0, 1}, optional
        The assembly branch at the first sample (0: the one containing alpha = 0).

    Returns
    -------
    :class:`BranchTrack`

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
    ambiguous = np.zeros((B, N), dtype=bool)
    known = np.ones((B, N), dtype=bool)
    for i in range(B):  # independent trajectories; within one, a loop over its meetings only
        idx = np.flatnonzero(valid[i])
        if idx.size < 3:
            continue
        s = sep[i, idx]
        ai = a[i, idx]  # (M, 2)
        gap = np.diff(idx).astype(float)  # samples between neighbouring valid samples (> 1 across a gap)
        step = np.max(np.abs(_wrap(np.diff(ai, axis=0))), axis=-1)  # (M-1,) largest step of either branch
        # the motion's step per sample around each sample: either branch folds back at the curve, so
        # its own step there is small, while the separation keeps changing at twice the motion's rate;
        # the largest over the neighbouring MEET_WINDOW steps is the motion's
        rate = np.maximum(step, 0.5 * np.abs(np.diff(s))) / gap
        padded = np.pad(rate, MEET_WINDOW, mode="edge")
        rate = np.lib.stride_tricks.sliding_window_view(padded, 2 * MEET_WINDOW + 1).max(-1)
        local_min = (s[1:-1] <= s[:-2]) & (s[1:-1] <= s[2:])
        scale = np.maximum(rate[:-1], rate[1:]) * np.maximum(gap[:-1], gap[1:])
        cand = np.flatnonzero(local_min & (s[1:-1] <= MEET_STEP_FACTOR * scale)) + 1
        # one meeting per cluster of candidates: the one nearest the curve
        groups = np.split(cand, np.flatnonzero(np.diff(cand) > MEET_MERGE) + 1) if cand.size else []
        meets = [int(g[np.argmin(s[g])]) for g in groups]
        M = idx.size
        seg = np.zeros(M, dtype=np.int8)
        cur = branch
        start = 0
        tpos = idx.astype(float)
        # meetings closer than a window are decided together (their windows would overlap)
        clusters: list[list[int]] = []
        for k in meets:
            if clusters and k - clusters[-1][-1] <= 2 * MEET_WINDOW and len(clusters[-1]) < MEET_CLUSTER_MAX:
                clusters[-1].append(k)
            else:
                clusters.append([k])
        for c, ks in enumerate(clusters):
            lo = max(clusters[c - 1][-1] + 1 if c else 0, ks[0] - MEET_WINDOW)
            hi = min(clusters[c + 1][0] if c + 1 < len(clusters) else M, ks[-1] + MEET_WINDOW + 1)
            tries = []  # (splits, ambiguous, window start) per window of MEET_WINDOWS
            for window in MEET_WINDOWS:
                lo_w, hi_w = max(lo, ks[0] - window), min(hi, ks[-1] + window + 1)
                tries.append((*_decide(tpos[lo_w:hi_w], 0.5 * s[lo_w:hi_w], [k - lo_w for k in ks]), lo_w))
                if len(tries) == 1 and not tries[0][1]:
                    break
            splits, amb, lo = tries[0]
            if amb and _short_windows_agree(tries[1:]):
                splits, amb, lo = tries[-1]
            for k, sp in zip(ks, splits, strict=True):
                meeting[i, idx[k]] = True
                if sp is None:
                    continue
                split = max(sp + lo, start)
                seg[start:split] = cur
                switched[i, idx[k]] = True
                cur = 1 - cur
                start = split
            if amb:
                ambiguous[i, idx[ks[0]]] = True
                known[i, idx[ks[0]] :] = False
        seg[start:] = cur
        # invalid samples between valid ones carry the branch of the preceding valid sample
        full = np.full(N, branch, dtype=np.int8)
        full[idx] = seg
        carry = np.maximum.accumulate(np.where(valid[i], np.arange(N), -1))
        full = np.where(carry >= 0, full[np.maximum(carry, 0)], branch)
        br[i] = full
    alpha = np.where(br == 0, a[..., 0], a[..., 1])
    resid = np.where(br == 0, f0.residual, f1.residual)
    ok = valid & known
    out = dict(
        alpha=np.where(ok, alpha, np.nan),
        beta=np.where(ok, f0.beta, np.nan),
        residual=np.where(ok, resid, np.nan),
        valid=ok,
        branch=np.where(ok, br, -1).astype(np.int8),
        separation=np.where(valid, sep, np.nan),
        meeting=meeting,
        switched=switched,
        ambiguous=ambiguous,
    )
    return BranchTrack(**{k: v.reshape(shape) for k, v in out.items()})
