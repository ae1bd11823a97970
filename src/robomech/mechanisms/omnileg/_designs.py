"""Many legs at once (private): the Lagrange model's kernel on per-design lengths and bodies.

The design studies (``robomech.explore``) evaluate thousands of legs that differ in ``L1``, ``L4``,
``L5`` and the bodies derived from them.  :class:`Designs` carries those per sample (each design's
values repeated over its poses: lengths ``(N, 1)``, masses ``(N,)``, centres of mass ``(N, 3)``,
inertias ``(N, 3, 3)``) and every other parameter from one :class:`OmniLeg`; ``_dynamics._terms`` reads a
leg only through attributes and broadcasts, so it takes it unchanged.  Every operation is the one of a
single leg with that design's numbers except the inertia products (per sample here, one BLAS product
for a single leg): :func:`inverse_dynamics_designs` equals
:func:`~robomech.mechanisms.omnileg.inverse_dynamics` design by design to rounding (``tests/explore``).
No input validation: the callers pass validated parameter objects and their own motions.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from ._dynamics import _terms
from ._params import OmniLeg

__all__ = ["Designs", "designs", "group_legs", "inverse_dynamics_designs"]

# The fields a Designs batch carries per design; every other field is shared.
DESIGN_FIELDS = ("L1", "L4", "L5", "bodies")


class _Bodies(NamedTuple):
    """One body kind per sample."""

    mass: np.ndarray  # (N,)
    com_vector: np.ndarray  # (N, 3)
    inertia_matrix: np.ndarray  # (N, 3, 3)


@dataclass(frozen=True)
class Designs:
    """``legs`` (equal but for :data:`DESIGN_FIELDS`) on ``samples`` poses each: the per-design fields per
    sample (design-major, N = len(legs) * samples), every other parameter the first leg's."""

    legs: tuple[OmniLeg, ...]
    samples: int
    L1: np.ndarray
    L4: np.ndarray
    L5: np.ndarray
    bodies: dict[str, _Bodies]

    def __getattr__(self, name: str) -> Any:
        # the shared parameters (L3, shank geometry, ranges, gravity): the first leg's
        return getattr(self.legs[0], name)

    @property
    def foot_drop(self) -> np.ndarray:
        """:attr:`OmniLeg.foot_drop` per sample, (N, 1) (m)."""
        return self.L5 - self.legs[0].knee_to_crank


def designs(legs: Sequence[OmniLeg], samples: int) -> Designs:
    """The legs as one :class:`Designs` of ``samples`` poses per design."""

    def rep(values: list[Any]) -> np.ndarray:
        return np.repeat(np.asarray(values, dtype=float), samples, axis=0)

    bodies = {
        k: _Bodies(
            rep([g.bodies[k].mass for g in legs]),
            rep([g.bodies[k].com_vector for g in legs]),
            rep([g.bodies[k].inertia_matrix for g in legs]),
        )
        for k in legs[0].bodies
    }
    lengths = (
        rep([g.L1 for g in legs])[:, None],
        rep([g.L4 for g in legs])[:, None],
        rep([g.L5 for g in legs])[:, None],
    )
    return Designs(tuple(legs), samples, *lengths, bodies)


def group_legs(legs: Sequence[OmniLeg]) -> list[np.ndarray]:
    """Indices into ``legs`` of each group of legs that differ only in :data:`DESIGN_FIELDS`."""
    groups: dict[tuple[Any, ...], list[int]] = {}
    for i, g in enumerate(legs):
        key = tuple(getattr(g, f.name) for f in dataclasses.fields(g) if f.name not in DESIGN_FIELDS)
        groups.setdefault(key, []).append(i)
    return [np.array(v, dtype=np.int64) for v in groups.values()]


def inverse_dynamics_designs(
    legs: Sequence[OmniLeg], q: np.ndarray, qd: np.ndarray, qdd: np.ndarray
) -> np.ndarray:
    """Motor torques ``(D, T, 3)`` (N m) of every leg along one motion ``q, qd, qdd (T, 3)``, no foot force:
    :func:`~robomech.mechanisms.omnileg.inverse_dynamics` ``.tau`` of each."""
    D, T = len(legs), q.shape[0]
    t = _terms(designs(legs, T), *(np.tile(x, (D, 1)) for x in (q, qd, qdd)))  # type: ignore[arg-type]
    return (t.tau_motion + t.tau_gravity).reshape(D, T, 3)
