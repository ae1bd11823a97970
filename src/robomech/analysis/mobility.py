"""Screw-theory mobility of a platform connected to the base by serial chains (as paper 5 does by hand).

For chain i with unit joint screws ``S_i (n_i, 6)`` expressed in one frame at one configuration:

* its twist system is ``span(S_i)``;
* its constraint system is every wrench ``W = [m; f]`` that does no work on any of them:
  ``W . S = m . w + f . v = 0`` (the reciprocal product of the wrench's screw ``[f; m]`` with ``S``);
* the platform's constraint system is the union (span of all chains' constraints), and its twist
  system is the reciprocal of that union; ``dof = 6 - rank(union)``.

Numerical ranks use the SVD with a relative tolerance ``RANK_RTOL``; screws mix angular (1) and
length units, so express them in a length unit in which the mechanism's size is of order one, or
pass ``length_scale``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from robomech._validation import as_array, check_real

__all__ = [
    "RANK_RTOL",
    "UNIT_SCREW_ATOL",
    "ChainScrews", "MobilityResult", "analyze", "constraint_wrenches", "reciprocal_basis",
]

# Singular values below RANK_RTOL * max(1, sigma_max) count as zero.  Unit screws of a mechanism of
# size ~1 have entries of order one; rounding in their construction leaves ~1e-15, while a
# genuinely independent direction of a non-degenerate mechanism is far above 1e-9.
RANK_RTOL = 1e-9

# analyze() takes *unit* joint screws: |w| = 1 (revolute/helical) or w = 0 and |v| = 1 (prismatic, in
# units of length_scale),
# within this tolerance (screws built in float64 are unit to ~1e-15; a value read with 6 digits to
# ~1e-6).  The check also catches a chain passed transposed, (6, n) instead of (n, 6), whose rows are
# then not unit screws.
UNIT_SCREW_ATOL = 1e-5

_DELTA = np.block([[np.zeros((3, 3)), np.eye(3)], [np.eye(3), np.zeros((3, 3))]])


def _row_basis(X: np.ndarray, tol: float) -> np.ndarray:
    """Orthonormal basis (k, 6) of the row space of X."""
    if X.size == 0:
        return np.zeros((0, 6))
    _, s, Vt = np.linalg.svd(X)
    cutoff = tol * max(1.0, s[0] if s.size else 0.0)
    return Vt[: int(np.sum(s > cutoff))]


def _null_basis(X: np.ndarray, tol: float) -> np.ndarray:
    """Orthonormal basis (k, 6) of ``{y : X y = 0}``."""
    if X.shape[0] == 0:
        return np.eye(6)
    _, s, Vt = np.linalg.svd(X)
    cutoff = tol * max(1.0, s[0] if s.size else 0.0)
    r = int(np.sum(s > cutoff))
    return Vt[r:]


def _check_tol(tol: object) -> float:
    # A relative rank tolerance: NaN would make every singular value "zero" (DOF 6 for anything).
    return check_real(tol, "tol", low=0.0, high=1.0, low_open=True, high_open=True)


def reciprocal_basis(screws: ArrayLike, *, tol: float = RANK_RTOL) -> np.ndarray:
    """Basis of the screws (axis-moment order ``[s; s0]``) reciprocal to every row of ``screws``.

    Parameters
    ----------
    screws : array_like, shape (m, 6)
        Screws ``[s; s0]`` (e.g. joint twists), moments of order one (scale lengths first).
    tol : float, optional
        Relative rank tolerance on the singular values (default ``RANK_RTOL``).

    Returns
    -------
    ndarray, shape (k, 6)
        Orthonormal rows ``r`` with ``reciprocal_product(r, s) = 0`` for every row ``s``;
        ``k = 6 - rank(screws)``.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.spatial import reciprocal_product
    >>> S = np.array([[0.0, 0, 1, 0, 0, 0]])            # a revolute joint on the z axis
    >>> R = reciprocal_basis(S)
    >>> R.shape, bool(np.allclose(reciprocal_product(R, S), 0.0))
    ((5, 6), True)
    """
    S = as_array(screws, "screws", (None, 6))
    tol = _check_tol(tol)
    if S.ndim != 2:
        raise ValueError(f"Expected screws to have shape (m, 6), got {S.shape}.")
    return _null_basis(S @ _DELTA, tol) if S.shape[0] else np.eye(6)


def constraint_wrenches(twists: ArrayLike, *, tol: float = RANK_RTOL) -> np.ndarray:
    """Basis of the wrenches ``[m; f]`` that do no work on any row of ``twists``.

    Parameters
    ----------
    twists : array_like, shape (m, 6)
        Twists ``[w; v]`` a chain allows its end (its joint screws), moments of order one.
    tol : float, optional
        Relative rank tolerance (default ``RANK_RTOL``).

    Returns
    -------
    ndarray, shape (k, 6)
        Wrenches ``W`` with ``virtual_power(W, V) = 0`` for every allowed twist ``V``.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.spatial import virtual_power
    >>> V = np.array([[0.0, 0, 1, 0, 0, 0]])            # spin about z
    >>> W = constraint_wrenches(V)
    >>> W.shape, bool(np.allclose(virtual_power(W, V), 0.0))
    ((5, 6), True)
    """
    S = as_array(twists, "twists", (None, 6))
    tol = _check_tol(tol)
    if S.ndim != 2:
        raise ValueError(f"Expected twists to have shape (m, 6), got {S.shape}.")
    return _null_basis(S, tol) if S.shape[0] else np.eye(6)


@dataclass(frozen=True)
class ChainScrews:
    """The screw systems of one chain (part of :class:`MobilityResult`).

    Attributes
    ----------
    twists : ndarray, shape (r_i, 6)
        Orthonormal basis of the chain's twist system ``[w; v]`` (moments divided by
        ``length_scale``).
    constraints : ndarray, shape (c_i, 6)
        Basis of its constraint wrenches ``[m; f]`` (same scaled coordinates), ``c_i = 6 - r_i``.
    """

    twists: np.ndarray  # (r_i, 6) basis of the chain's twist system
    constraints: np.ndarray  # (c_i, 6) basis of its constraint wrenches [m; f] (scaled coordinates)


@dataclass(frozen=True)
class MobilityResult:
    """Mobility of the platform and the counts that explain it: the result of :func:`analyze`.

    Moments and linear parts are in the scaled coordinates (divided by ``length_scale``).

    Attributes
    ----------
    dof : int
        Degrees of freedom of the platform, ``6 - rank`` of the union of the constraints.
    platform_twists : ndarray, shape (dof, 6)
        Orthonormal basis of the platform twist system ``[w; v]``.
    constraint_wrenches : ndarray, shape (6 - dof, 6)
        Wrenches ``[m; f]`` spanning the union of the chains' constraints.
    chains : tuple of ChainScrews
        Each chain's twist and constraint systems, in the order given.
    rotational_dof : int
        Rank of the angular parts of the platform twists.
    translational_dof : int
        Dimension of the pure translations the platform can make.
    common_constraints : int
        ``lambda``: dimension of the constraints shared by every chain.
    redundant_constraints : int
        ``nu``: constraints beyond the common ones that repeat others.
    gruebler_kutzbach : int
        The spatial count ``6 (n - g - 1) + sum f``.
    modified_gruebler_kutzbach : int
        ``(6 - lambda)(n - g - 1) + sum f + nu``.
    singular : bool
        The screw-theory DOF disagrees with the modified count: the rank of the constraint system is
        not locally constant, and ``dof`` holds at this instant only.
    warning : str
        Why ``singular`` is set; empty otherwise.
    """

    dof: int
    platform_twists: np.ndarray  # (dof, 6) orthonormal basis of the platform twist system
    constraint_wrenches: np.ndarray  # (6 - dof, 6) wrenches [m; f] spanning the union of the constraints
    chains: tuple[ChainScrews, ...]
    rotational_dof: int  # rank of the angular parts of the platform twists
    translational_dof: int  # dimension of the pure translations the platform can make
    common_constraints: int  # lambda: dimension of the constraints shared by every chain
    redundant_constraints: int  # nu: constraints beyond the common ones that repeat others
    gruebler_kutzbach: int  # 6(n - g - 1) + sum f, the spatial count
    modified_gruebler_kutzbach: int  # (6 - lambda)(n - g - 1) + sum f + nu
    # True when the screw-theory DOF disagrees with the modified Grübler–Kutzbach count computed from
    # the same constraint systems: the configuration is singular (the rank of the constraint system
    # is not locally constant, e.g. the vectored thruster on its rank-1 curve), and ``dof`` holds only
    # at this instant, not in a neighbourhood.
    singular: bool = False
    warning: str = ""  # why ``singular`` is set, empty otherwise

    def summary(self) -> str:
        """One line: DOF (rotational / translational), constraint counts, both mobility counts."""
        return (
            f"DOF {self.dof} ({self.rotational_dof}R{self.translational_dof}T); "
            f"constraints {self.constraint_wrenches.shape[0]} independent, "
            f"common {self.common_constraints}, redundant {self.redundant_constraints}; "
            f"Gruebler-Kutzbach {self.gruebler_kutzbach}, modified {self.modified_gruebler_kutzbach}"
        )


def _intersection_dim(bases: Sequence[np.ndarray], tol: float) -> int:
    """Dimension of the intersection of subspaces given by row bases."""
    # The intersection is the reciprocal-free complement: orthogonal complement of the sum of complements.
    complements = [_null_basis(B, tol) for B in bases]
    stacked = np.vstack(complements) if complements else np.zeros((0, 6))
    return 6 - _row_basis(stacked, tol).shape[0]


def analyze(chains: Sequence[object], *, length_scale: float = 1.0, tol: float = RANK_RTOL) -> MobilityResult:
    """Platform mobility from each chain's unit joint screws (``[w; v]``; ``[0; d]`` for prismatic).

    The constraint wrenches of each chain are the wrenches reciprocal to its joint screws; the
    platform's twists are those reciprocal to the union of all chains' constraints.  ``length_scale``
    divides the moment parts so that the screws are of order one (e.g. the mechanism's radius in the
    units used).  The Grübler–Kutzbach counts assume each chain is a serial chain of one-DOF joints from
    base to platform (a universal joint is two screws, a spherical three).

    Parameters
    ----------
    chains : sequence of array_like, each shape (n_i, 6)
        Joint screws of each chain from base to platform, in one frame, at one configuration.
    length_scale : float, optional
        Length unit of the moment parts (same unit as the screws' points); default 1.
    tol : float, optional
        Relative rank tolerance of the screw systems (default ``RANK_RTOL``).

    Returns
    -------
    MobilityResult
        ``dof``; ``platform_twists (dof, 6)`` and ``constraint_wrenches (k, 6)`` bases;
        ``rotational_dof``/``translational_dof``; common and redundant constraint counts; the
        Grübler–Kutzbach and modified Grübler–Kutzbach counts for comparison; ``singular`` (with a
        ``warning`` text) where the screw-theory DOF and the modified count disagree, i.e. a singular
        configuration where ``dof`` holds at this instant only.

    Raises
    ------
    ValueError
        If a chain is not an ``(n_i, 6)`` array of unit screws (e.g. passed transposed), or
        ``length_scale`` / ``tol`` are out of range.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech.spatial import screw_from_axis
    >>> z = np.array([0.0, 0.0, 1.0])
    >>> four_bar = [
    ...     screw_from_axis(np.stack([z, z]), np.array([[0.0, 0, 0], [0.3, 1.0, 0]])),
    ...     screw_from_axis(np.stack([z, z]), np.array([[2.0, 0, 0], [1.6, 1.2, 0]])),
    ... ]
    >>> m = analyze(four_bar)
    >>> m.dof, m.gruebler_kutzbach, m.modified_gruebler_kutzbach   # G-K fails: planar is over-constrained
    (1, -2, 1)
    >>> m.singular
    False
    """
    if isinstance(chains, np.ndarray) or not isinstance(chains, Sequence) or isinstance(chains, str):
        raise ValueError(
            "Expected chains to be a sequence (list or tuple) of (n_i, 6) arrays of joint screws, "
            f"got {type(chains).__name__}."
        )
    if len(chains) == 0:
        raise ValueError("Expected chains to hold at least one (n_i, 6) array of joint screws, got none.")
    length_scale = check_real(length_scale, "length_scale", low=0.0, low_open=True)
    tol = _check_tol(tol)
    scale = np.array([1, 1, 1, 1 / length_scale, 1 / length_scale, 1 / length_scale])
    per_chain = []
    for i, c in enumerate(chains):
        S = as_array(c, f"chains[{i}]", (None, 6))
        if S.ndim != 2 or S.shape[0] == 0:
            raise ValueError(f"Expected chains[{i}] to have shape (n_i, 6) with n_i >= 1, got {S.shape}.")
        S = S * scale
        w = np.linalg.norm(S[:, :3], axis=1)
        v = np.linalg.norm(S[:, 3:], axis=1)
        unit = np.where(w > UNIT_SCREW_ATOL, np.abs(w - 1.0), np.abs(v - 1.0)) <= UNIT_SCREW_ATOL
        if not np.all(unit):
            raise ValueError(
                f"Expected chains[{i}] to hold unit joint screws as rows, shape (n_i, 6) "
                f"(|w| = 1, or w = 0 and |v| = length_scale), got rows "
                f"{np.flatnonzero(~unit).tolist()} of shape "
                f"{S.shape} that are not (a chain passed transposed?)."
            )
        twists = _row_basis(S, tol)
        constraints = _null_basis(S, tol)
        per_chain.append(ChainScrews(twists=twists, constraints=constraints))

    all_constraints = np.vstack([c.constraints for c in per_chain])
    union = _row_basis(all_constraints, tol)
    platform = _null_basis(union, tol) if union.shape[0] else np.eye(6)
    dof = platform.shape[0]

    rot = _row_basis(platform[:, :3], tol).shape[0] if dof else 0
    lam = _intersection_dim([c.constraints for c in per_chain], tol)
    nu = sum(c.constraints.shape[0] - lam for c in per_chain) - (union.shape[0] - lam)

    n_joints = sum(np.asarray(c).shape[0] for c in chains)
    n_links = 2 + sum(np.asarray(c).shape[0] - 1 for c in chains)
    loops = n_links - n_joints - 1
    modified = (6 - lam) * loops + n_joints + nu
    singular = dof != modified
    warning = (
        f"singular configuration: the screw-theory DOF {dof} differs from the modified "
        f"Grübler–Kutzbach count {modified}; the rank of the constraint system is not locally "
        "constant here, so the DOF holds at this instant only"
        if singular
        else ""
    )
    return MobilityResult(
        dof=dof,
        platform_twists=platform / scale,
        constraint_wrenches=union / scale[[3, 4, 5, 0, 1, 2]],  # wrench [m; f]: m carries length
        chains=tuple(per_chain),
        rotational_dof=rot,
        translational_dof=dof - rot,
        common_constraints=lam,
        redundant_constraints=nu,
        gruebler_kutzbach=6 * loops + n_joints,
        modified_gruebler_kutzbach=modified,
        singular=singular,
        warning=warning,
    )
