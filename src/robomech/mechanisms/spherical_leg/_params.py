"""Parameters of the 2RUHU-RUPR-RUR spherical parallel leg (paper 1, Tables 1-2), in SI units; geometry,
inertial model and the justification of every value: docs/mechanisms/spherical_leg.md."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from robomech._validation import as_array, check_bool, check_choice, check_positive

__all__ = ["LegBody", "SphericalLeg"]

_MM = 1e-3


def _positive(obj: object, field_name: str, label: str, *, allow_zero: bool = False) -> None:
    """Validate a scalar field and store it as a float (a str, bool or array never stays in a field)."""
    value = check_positive(getattr(obj, field_name), label, allow_zero=allow_zero)
    object.__setattr__(obj, field_name, value)


@dataclass(frozen=True)
class LegBody:
    """One rigid body of a leg, modelled as a uniform prism along the leg axis.

    Parameters
    ----------
    name : str
        Label used in error messages (e.g. ``"screw"``).
    length, width, wall : float
        Length along the leg axis, outer diameter (round) or side (square) of the section, and its wall
        thickness (``>= width / 2``: solid); m, > 0.
    mass : float
        Mass (kg, >= 0).
    shape : {"round", "square"}, optional
        Section shape.
    """

    name: str
    length: float
    width: float
    wall: float
    mass: float
    shape: str = "round"

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise ValueError(f"Expected name to be a str, got {type(self.name).__name__}.")
        _positive(self, "length", f"{self.name}.length")
        _positive(self, "width", f"{self.name}.width")
        _positive(self, "wall", f"{self.name}.wall")
        _positive(self, "mass", f"{self.name}.mass", allow_zero=True)
        check_choice(self.shape, f"{self.name}.shape", ("round", "square"))

    @property
    def axial_inertia(self) -> float:
        """Moment of inertia about the body's own axis through its centre of mass (kg m^2)."""
        o = 0.5 * self.width
        i = max(0.0, o - self.wall)
        if self.shape == "round":
            return 0.5 * self.mass * (o * o + i * i)
        # square tube of outer side 2o, inner side 2i: polar moment per area (a^4 - b^4)/6 / (a^2 - b^2)
        a, b = 2 * o, 2 * i
        return self.mass * (a * a + b * b) / 6.0

    @property
    def transverse_inertia(self) -> float:
        """Moment of inertia about a transverse axis through the centre of mass (kg m^2); both section
        shapes are isotropic, so the body is inertially axisymmetric."""
        return 0.5 * self.axial_inertia + self.mass * self.length**2 / 12.0


@dataclass(frozen=True)
class SphericalLeg:
    """Frozen parameters of the spherical parallel leg (SI units, radians); defaults and their sources (the
    leg stroke is not printed): docs/mechanisms/spherical_leg.md, "Parameters".

    Parameters
    ----------
    R, r, h : float
        Radii OA_i, PB_i of the base and platform joint circles and distance OP at the home pose (m).
    platform_side, platform_thickness, platform_mass : float
        The box-shaped platform's side and thickness (m) and mass (kg, >= 0).
    lower, upper : tuple of LegBody
        The lower (starting at A_i) and upper (ending at B_i) body of legs 1, 2, 3.
    screw_lead : float
        Lead of the helical joints of legs 1 and 3 (m per turn).
    screw_spin : bool
        Whether the screw (lower body of legs 1, 3) spins relative to the sleeve at 2 pi ldot / screw_lead.
    length_min, length_max : float
        Leg stroke limits (m), ``length_max > length_min >= 0``.
    gravity : tuple of float
        Gravitational acceleration in the base frame (m/s^2).
    """

    R: float = 75 * _MM
    r: float = 30 * _MM
    h: float = 100 * _MM
    platform_side: float = 60 * _MM
    platform_thickness: float = 20 * _MM
    platform_mass: float = 5.0
    lower: tuple[LegBody, LegBody, LegBody] = field(
        default_factory=lambda: (
            LegBody("screw", 110 * _MM, 30 * _MM, 15 * _MM, 2.0),
            LegBody("cylinder", 70 * _MM, 40 * _MM, 10 * _MM, 1.0, "square"),
            LegBody("screw", 110 * _MM, 30 * _MM, 15 * _MM, 2.0),
        )
    )
    upper: tuple[LegBody, LegBody, LegBody] = field(
        default_factory=lambda: (
            LegBody("sleeve", 70 * _MM, 20 * _MM, 10 * _MM, 1.5),
            LegBody("piston", 110 * _MM, 30 * _MM, 15 * _MM, 1.0, "square"),
            LegBody("sleeve", 70 * _MM, 20 * _MM, 10 * _MM, 1.5),
        )
    )
    screw_lead: float = 10 * _MM
    screw_spin: bool = True
    length_min: float = 30 * _MM
    length_max: float = 170 * _MM
    gravity: tuple[float, float, float] = (0.0, 0.0, -10.0)

    def __post_init__(self) -> None:
        for name in ("R", "r", "h", "platform_side", "platform_thickness", "screw_lead"):
            _positive(self, name, name)
        _positive(self, "platform_mass", "platform_mass", allow_zero=True)
        _positive(self, "length_min", "length_min", allow_zero=True)
        _positive(self, "length_max", "length_max")
        object.__setattr__(self, "screw_spin", check_bool(self.screw_spin, "screw_spin"))
        if self.length_max <= self.length_min:
            raise ValueError(
                f"Expected length_max > length_min, got length_max={self.length_max!r}, "
                f"length_min={self.length_min!r}."
            )
        for name in ("lower", "upper"):
            bodies = getattr(self, name)
            if (
                not isinstance(bodies, tuple | list)
                or len(bodies) != 3
                or not all(isinstance(b, LegBody) for b in bodies)
            ):
                raise ValueError(f"Expected {name} to be a tuple of 3 LegBody, got {bodies!r}.")
            object.__setattr__(self, name, tuple(bodies))
        g = as_array(self.gravity, "gravity", (3,))
        flags = any(isinstance(x, bool | np.bool_) for x in np.asarray(self.gravity, dtype=object).ravel())
        if g.ndim != 1 or flags:
            raise ValueError(f"Expected gravity to be 3 finite numbers, got {self.gravity!r}.")
        object.__setattr__(self, "gravity", tuple(float(x) for x in g))

    @classmethod
    def paper(cls) -> SphericalLeg:
        """The paper's values (Tables 1-2, Section 6.1) converted to SI."""
        return cls()

    # --- derived geometry (cheap properties, no state) -------------------------------------------------
    @property
    def base_points(self) -> np.ndarray:
        """A_i in the base frame, (3, 3) rows = legs 1..3 (paper 1, Section 3.1)."""
        return np.array([[self.R, 0.0, 0.0], [-self.R, 0.0, 0.0], [0.0, self.R, 0.0]])

    @property
    def platform_points_home(self) -> np.ndarray:
        """B_i at the home pose (alpha = beta = 0), relative to O, (3, 3) rows = legs 1..3."""
        return np.array([[self.r, 0.0, self.h], [-self.r, 0.0, self.h], [0.0, self.r, self.h]])

    @property
    def platform_inertia(self) -> np.ndarray:
        """Platform rotational inertia about P in platform axes (uniform box), (3, 3) kg m^2."""
        a, t, m = self.platform_side, self.platform_thickness, self.platform_mass
        return np.diag([m * (a * a + t * t) / 12.0, m * (a * a + t * t) / 12.0, m * (2 * a * a) / 12.0])

    @property
    def cardan_axes(self) -> np.ndarray:
        """First (base-fixed) axis ``a_i = Z x s_i(0)`` (normalised) of the universal joint at A_i, (3, 3)
        rows = legs 1..3: an assumption (docs/mechanisms/spherical_leg.md, assumption 3)."""
        u = self.platform_points_home - self.base_points
        x = u / np.linalg.norm(u, axis=-1, keepdims=True)
        out = np.empty((3, 3))
        for i in range(3):
            y = np.cross((0.0, 0.0, 1.0), x[i])
            if np.linalg.norm(y) < 0.1:  # nearly vertical leg: the horizontal direction is ill-defined
                y = np.array([0.0, 1.0, 0.0]) - x[i, 1] * x[i]
            out[i] = y / np.linalg.norm(y)
        return out

    @property
    def spin_ratio(self) -> np.ndarray:
        """Screw spin rate per unit leg rate (rad/m) per leg: 2 pi / lead for legs 1, 3; 0 for leg 2."""
        k = 2.0 * math.pi / self.screw_lead if self.screw_spin else 0.0
        return np.array([k, 0.0, k])
