"""Screw-theory mobility of the vectored thruster (paper 5, Section 2): the chains' joint screws at a
configuration, analysed by :func:`robomech.analysis.mobility.analyze`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._validation import as_array, check_params
from robomech.analysis import mobility
from robomech.spatial import screw_from_axis

from ._kinematics import _axes
from ._params import VectoredThruster

__all__ = ["MechanismMobility", "chain_screws", "mechanism_mobility", "platform_mobility"]

# Screws in metres: offsets of millimetres give moment parts ~1e-3, far above the SVD rank tolerance (1e-9).
CORE_LENGTH_SCALE = 1.0

_JOINTS = ("s11", "s12", "s13", "s21", "s22")


def chain_screws(
    th: VectoredThruster, q: object, offsets: dict[str, object] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Unit joint screws ``[s; r x s]`` (m) of the RRR chain (s11, s12, s13) and the RR chain (s21, s22).

    Parameters
    ----------
    th : VectoredThruster
    q : array_like, shape (2,)
        One input configuration (rad).
    offsets : dict of str to array_like, optional
        Axis name (``"s11"``, ``"s12"``, ``"s13"``, ``"s21"``, ``"s22"``) -> point (3,) (m, base frame)
        the axis is moved to pass through; ``None`` (default): every axis through O.

    Returns
    -------
    rrr, rr : ndarray, shape (3, 6) and (2, 6)

    Raises
    ------
    ValueError
        A singular ``q``.
    """
    check_params(th, VectoredThruster, "th")
    qa = as_array(q, "q", (2,))
    if qa.ndim != 1:
        raise ValueError(f"Expected q to have shape (2,), got {qa.shape}.")
    ax = _axes(th, qa)
    if not ax.valid:
        raise ValueError(f"Expected q away from the singularity (|s22 x s12| > 0), got q = {qa.tolist()}.")
    if offsets is not None and not isinstance(offsets, dict):
        raise ValueError(f"Expected offsets to be a dict of axis name -> point, got {type(offsets).__name__}")
    offsets = dict(offsets or {})
    for k in offsets:
        if k not in _JOINTS:
            raise ValueError(f"Expected offsets keys among {_JOINTS}, got {k!r}.")
    pts = {k: as_array(offsets.get(k, np.zeros(3)), f"offsets[{k!r}]", (3,)) for k in _JOINTS}
    S = {k: screw_from_axis(getattr(ax, k), pts[k]) for k in _JOINTS}
    return np.stack([S["s11"], S["s12"], S["s13"]]), np.stack([S["s21"], S["s22"]])


def platform_mobility(
    th: VectoredThruster, q: object = (0.0, 0.0), offsets: dict[str, object] | None = None
) -> mobility.MobilityResult:
    """Mobility of the RRR-RR platform (the fixing device) at ``q``: paper 5, eqs. (4)-(10).

    Parameters
    ----------
    th : VectoredThruster
    q : array_like, shape (2,), optional
    offsets : dict of str to array_like, optional
        As in :func:`chain_screws`.

    Returns
    -------
    MobilityResult
    """
    check_params(th, VectoredThruster, "th")
    rrr, rr = chain_screws(th, q, offsets)
    return mobility.analyze([rrr, rr], length_scale=CORE_LENGTH_SCALE)


@dataclass(frozen=True)
class MechanismMobility:
    """Mobility of the platform and of the propeller body (:func:`mechanism_mobility`).

    Attributes
    ----------
    platform : MobilityResult
        The RRR-RR platform (2R expected).
    propeller : MobilityResult
        The propeller body: the central chain (motor about Z, universal joint at ``ujoint_centre``)
        closed with the platform's twists and the shaft bearing about s0.
    """

    platform: mobility.MobilityResult
    propeller: mobility.MobilityResult


def mechanism_mobility(
    th: VectoredThruster,
    q: object = (0.0, 0.0),
    offsets: dict[str, object] | None = None,
    ujoint_centre: object = (0.0, 0.0, 0.0),
) -> MechanismMobility:
    """Mobility of the whole vectored thruster with the central universal-joint chain (Section 2, Fig. 2).

    Parameters
    ----------
    th : VectoredThruster
    q : array_like, shape (2,), optional
    offsets : dict of str to array_like, optional
        As in :func:`chain_screws`.
    ujoint_centre : array_like, shape (3,), optional
        Centre of the central universal joint (m, base frame); default O.

    Returns
    -------
    MechanismMobility

    Examples
    --------
    >>> mm = mechanism_mobility(VectoredThruster.paper(), (0.1, 0.2))
    >>> mm.platform.dof, mm.propeller.dof
    (2, 3)
    """
    check_params(th, VectoredThruster, "th")
    plat = platform_mobility(th, q, offsets)
    qa = as_array(q, "q", (2,))
    c = as_array(ujoint_centre, "ujoint_centre", (3,))
    if c.ndim != 1:
        raise ValueError(f"Expected ujoint_centre to have shape (3,), got {c.shape}.")
    s0 = _axes(th, qa).s0
    # The universal-joint cross: first axis fixed to the motor shaft (X at the current motor angle 0),
    # second axis perpendicular to it and to the propeller shaft.
    u1 = np.array([1.0, 0.0, 0.0])
    u2 = np.cross(s0, u1)
    u2 = u2 / np.linalg.norm(u2)
    central = np.stack(
        [
            screw_from_axis(np.array([0.0, 0.0, 1.0]), np.zeros(3)),  # motor shaft, fixed along Z through O
            screw_from_axis(u1, c),
            screw_from_axis(u2, c),
        ]
    )
    via_platform = np.vstack([plat.platform_twists, screw_from_axis(s0, np.zeros(3))])
    prop = mobility.analyze([central, via_platform], length_scale=CORE_LENGTH_SCALE)
    return MechanismMobility(platform=plat, propeller=prop)
