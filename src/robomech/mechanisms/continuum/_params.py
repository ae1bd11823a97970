"""Frozen parameters of an n-segment cable-driven continuum robot (paper 3), SI units."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robomech._validation import as_array, coerce_float_fields, coerce_int_fields

__all__ = ["ContinuumRobot"]

CABLES_PER_SEGMENT = 3  # paper 3, Fig. 3: three cables 120 degrees apart drive every segment


@dataclass(frozen=True)
class ContinuumRobot:
    """Parameters of a cable-driven constant-curvature continuum robot: n segments of ``disks_per_segment``
    evenly spaced disks on a NiTi core, three cables per segment at hole angles ``(0, 2 pi/3, 4 pi/3) + i *
    cable_offset`` (layout and the source of every default: ``docs/mechanisms/continuum.md``, Parameters).

    Parameters
    ----------
    n_segments, disks_per_segment : int
        Number of segments n and of disks N per segment (chord spans, >= 1); paper: 1 and 5.
    segment_length : float
        Arc length of every segment (m); paper: 90 mm.
    hole_radius : float
        Distance r of the cable holes from the core axis (m); not printed, default 4 mm; below
        ``segment_length / n_segments`` and ``>= (core_diameter + cable_diameter) / 2``.
    core_modulus, core_diameter : float
        Young's modulus (Pa) and diameter (m) of the NiTi core; not printed (60 GPa, 1.0 mm).
    cable_modulus, cable_diameter : float
        Young's modulus (Pa) and diameter (m) of the Dyneema cable; paper: 4.96 GPa, 0.8 mm.
    friction : tuple of float
        Coulomb friction coefficient per cable (3 n entries, >= 0); paper Table 1 (0.26, 0.31, 0.28).
    pretension : float
        Cable pretension T0 (N, >= 0); not printed, default 10 N (inside Fig. 6's 3-11 N range).
    free_length : float
        Cable length between the actuator and the base plate (m, >= 0); not printed, default 0.1 m.
    cable_offset : float
        Angular offset of the holes of successive segments (rad).
    """

    n_segments: int = 1
    segment_length: float = 0.090
    disks_per_segment: int = 5
    hole_radius: float = 0.004
    core_modulus: float = 60e9
    # paper 3 prints no core diameter: 1.0 mm keeps the column between two disks from buckling below
    # 29.9 N per cable, twice the 15 N working range (docs/mechanisms/continuum.md, Parameters).
    core_diameter: float = 1.0e-3
    cable_modulus: float = 4.96e9
    cable_diameter: float = 0.8e-3
    friction: tuple[float, ...] = (0.26, 0.31, 0.28)
    pretension: float = 10.0
    free_length: float = 0.1
    cable_offset: float = math.pi / 3.0

    def __post_init__(self) -> None:
        # integers stay integers (bool rejected) and every real field is stored as a float
        coerce_int_fields(self, ("n_segments", "disks_per_segment"), low=1)
        lengths = ("segment_length", "hole_radius", "core_diameter", "cable_diameter")
        coerce_float_fields(self, (*lengths, "core_modulus", "cable_modulus"), positive=True)
        coerce_float_fields(self, ("pretension", "free_length"), positive=True, allow_zero=True)
        coerce_float_fields(self, ("cable_offset",))
        if self.hole_radius * self.n_segments >= self.segment_length:
            raise ValueError(
                f"Expected hole_radius well below segment_length, got {self.hole_radius!r} m vs "
                f"{self.segment_length!r} m."
            )
        # a cable runs in a hole beside the core, not through it: the hole's centre must clear the core
        # and the cable's own radius
        clear = 0.5 * (self.core_diameter + self.cable_diameter)
        if self.hole_radius < clear:
            raise ValueError(
                f"Expected hole_radius >= (core_diameter + cable_diameter) / 2 = {clear!r} m (the cable "
                f"beside the core, not inside it), got {self.hole_radius!r} m."
            )
        mu_a = as_array(self.friction, "friction", (None,))
        if mu_a.ndim != 1:
            raise ValueError(f"Expected friction to be a flat sequence of numbers, got shape {mu_a.shape}.")
        mu = tuple(float(m) for m in mu_a)
        n_cables = CABLES_PER_SEGMENT * self.n_segments
        if len(mu) != n_cables:
            raise ValueError(f"Expected friction to have {n_cables} entries (3 per segment), got {len(mu)}.")
        if not all(math.isfinite(m) and m >= 0.0 for m in mu):
            raise ValueError(f"Expected friction coefficients >= 0 and finite, got {mu!r}.")
        object.__setattr__(self, "friction", mu)

    @classmethod
    def paper(cls) -> ContinuumRobot:
        """The prototype of paper 3, Section 5: one 90 mm segment, 5 disks, 0.8 mm Dyneema, Table 1 mu."""
        return cls()

    # ---- derived quantities -------------------------------------------------------------------
    @property
    def n_cables(self) -> int:
        return CABLES_PER_SEGMENT * self.n_segments

    @property
    def bending_stiffness(self) -> float:
        """Core bending stiffness E I (N m^2) of a solid round rod, I = pi d^4 / 64."""
        return self.core_modulus * math.pi * self.core_diameter**4 / 64.0

    @property
    def cable_axial_stiffness(self) -> float:
        """E A of one cable (N)."""
        return self.cable_modulus * math.pi * self.cable_diameter**2 / 4.0

    @property
    def hole_angles(self) -> np.ndarray:
        """Hole angle sigma of every cable (3 n,), cable index 3 i + j for segment i, cable j."""
        base = np.array([0.0, 2.0 * math.pi / 3.0, 4.0 * math.pi / 3.0])  # paper 3, eqs. (4) and (20)
        return np.concatenate([base + i * self.cable_offset for i in range(self.n_segments)])

    @property
    def cable_segment(self) -> np.ndarray:
        """Index of the segment where every cable terminates (3 n,)."""
        return np.repeat(np.arange(self.n_segments), CABLES_PER_SEGMENT)

    @property
    def friction_array(self) -> np.ndarray:
        return np.asarray(self.friction, dtype=float)
