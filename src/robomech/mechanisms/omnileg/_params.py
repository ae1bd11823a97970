"""Parameters of the OmniLeg (paper 2): geometry of Table 2, joint ranges, and inertial assumptions
(the paper gives none: :func:`default_bodies`); frames and justification: docs/mechanisms/omnileg.md."""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, fields

import numpy as np

from robomech._validation import as_array, check_positive, check_real
from robomech.dynamics import _check_inertia

__all__ = ["BodySet", "OmniLeg", "RigidBody", "default_bodies"]

# Density of 6061 aluminium and of steel, kg/m^3 (handbook values).
RHO_ALUMINIUM = 2700.0
RHO_STEEL = 7850.0
# Standard gravity, m/s^2.
STANDARD_GRAVITY = 9.80665
# Principal moments may violate the triangle inequality by this relative amount (rounding only).
TRIANGLE_RTOL = 1e-9


@dataclass(frozen=True)
class RigidBody:
    """Inertial parameters of one rigid body in its body frame (docs/mechanisms/omnileg.md, "Dynamics model").

    Parameters
    ----------
    mass : float
        Mass (kg), > 0.
    com : array_like, shape (3,)
        Centre of mass (m); stored as a tuple (``com_vector``: as an array).
    inertia : array_like, shape (3, 3)
        Inertia about the centre of mass (kg m²): symmetric, positive semidefinite, principal moments
        obeying the triangle inequality; stored as nested tuples (``inertia_matrix``: as an array).
    """

    mass: float
    com: tuple[float, ...]  # 3 floats once validated
    inertia: tuple[tuple[float, ...], ...]  # 3 x 3 floats once validated

    def __post_init__(self) -> None:
        m = check_positive(self.mass, "RigidBody.mass")
        c = as_array(self.com, "RigidBody.com")
        if c.shape != (3,) or not np.all(np.isfinite(c)):
            raise ValueError(f"Expected RigidBody.com to be 3 finite numbers, got {self.com!r}.")
        inertia = as_array(self.inertia, "RigidBody.inertia")
        if inertia.shape != (3, 3) or not np.all(np.isfinite(inertia)):
            raise ValueError(
                f"Expected RigidBody.inertia to be a finite 3x3 matrix, got shape {inertia.shape}."
            )
        _check_inertia(inertia, "RigidBody.inertia")  # symmetric, positive semidefinite (to rounding)
        ev = np.linalg.eigvalsh(inertia)
        if ev[0] + ev[1] < ev[2] * (1 - TRIANGLE_RTOL):
            raise ValueError(
                f"Expected RigidBody.inertia's principal moments to obey the triangle inequality, got "
                f"{ev.tolist()}."
            )
        object.__setattr__(self, "mass", m)
        object.__setattr__(self, "com", tuple(float(v) for v in c))
        object.__setattr__(self, "inertia", tuple(tuple(float(v) for v in row) for row in inertia))

    @property
    def inertia_matrix(self) -> np.ndarray:
        return np.array(self.inertia)

    @property
    def com_vector(self) -> np.ndarray:
        return np.array(self.com)


def _cylinder(
    mass: float, radius: float, length: float, com=(0, 0, 0), axis=2, inner_radius=0.0
) -> RigidBody:
    """(Hollow) cylinder along body axis ``axis`` about its centre."""
    r2 = radius**2 + inner_radius**2
    i_axial = 0.5 * mass * r2
    i_trans = mass * (3 * r2 + length**2) / 12.0
    d = [i_trans, i_trans, i_trans]
    d[axis] = i_axial
    return RigidBody(
        mass, com, tuple(tuple(float(d[i]) if i == j else 0.0 for j in range(3)) for i in range(3))
    )


def _cross(radius: float, span: float) -> RigidBody:
    """A universal-joint cross: two steel pins of ``radius`` and length ``span`` along body x and y."""
    m_pin = RHO_STEEL * math.pi * radius**2 * span
    a = _cylinder(m_pin, radius, span, axis=0).inertia_matrix
    b = _cylinder(m_pin, radius, span, axis=1).inertia_matrix
    inertia = a + b
    return RigidBody(2 * m_pin, (0.0, 0.0, 0.0), tuple(tuple(float(v) for v in row) for row in inertia))


def default_bodies(L1: float, L3: float, L4: float, L5: float, knee_to_crank: float) -> dict[str, RigidBody]:
    """Plausible inertial parameters from the link geometry (sizes, materials and frames of the 11 body kinds
    of ``BODY_FIELDS``: docs/mechanisms/omnileg.md, "Dynamics model").

    Parameters
    ----------
    L1, L3, L4, L5, knee_to_crank : float
        As in :class:`OmniLeg` (m).

    Returns
    -------
    dict of str to RigidBody
    """
    L1, L3, L4, L5 = (check_positive(v, n) for v, n in ((L1, "L1"), (L3, "L3"), (L4, "L4"), (L5, "L5")))
    knee_to_crank = check_positive(knee_to_crank, "knee_to_crank", allow_zero=True)
    if knee_to_crank >= L5:
        # the foot rod runs from the crank plane down to the foot point: it needs a positive length
        raise ValueError(
            f"Expected knee_to_crank < L5 (the cranks above the foot), got knee_to_crank={knee_to_crank!r}, "
            f"L5={L5!r}."
        )
    cross = _cross(0.0025, 0.024)
    # Thigh rod: tube plus fittings (2 x 20 g) at its ends; com at mid-length by symmetry.
    r_o, r_i = 0.008, 0.006
    m_tube = RHO_ALUMINIUM * math.pi * (r_o**2 - r_i**2) * L1
    tube = _cylinder(m_tube, r_o, L1, inner_radius=r_i).inertia_matrix
    m_fit = 0.020
    # two 20 g fittings at ±L1/2 (point masses) plus their own inertia (~20 g rings of radius ~3 mm:
    # m r² ≈ 2e-7 kg m² about the rod axis, half that across)
    ends = np.diag([2 * m_fit * (L1 / 2) ** 2, 2 * m_fit * (L1 / 2) ** 2, 0.0]) + np.diag([1e-7, 1e-7, 2e-7])
    thigh_rod = RigidBody(m_tube + 2 * m_fit, (0.0, 0.0, L1 / 2), tuple(map(tuple, tube + ends)))
    r_s = 0.003
    drive_rod = _cylinder(RHO_STEEL * math.pi * r_s**2 * L1, r_s, L1, com=(0.0, 0.0, L1 / 2))
    shaft_len = 0.030
    m_shaft = RHO_STEEL * math.pi * r_s**2 * shaft_len
    drive_shaft_in = _cylinder(m_shaft, r_s, shaft_len, com=(0.0, 0.0, -shaft_len / 2))
    gear_m, gear_r, gear_t = 0.040, 0.012, 0.008
    gear = _cylinder(gear_m, gear_r, gear_t).inertia_matrix
    shaft = _cylinder(m_shaft, r_s, shaft_len).inertia_matrix
    # output shaft from the knee point O0' down to the bevel gear at z = knee_to_crank
    z_s, z_g = shaft_len / 2, knee_to_crank
    m_out = m_shaft + gear_m
    z_c = (m_shaft * z_s + gear_m * z_g) / m_out
    par = np.diag([1.0, 1.0, 0.0])
    I_out = shaft + gear + par * (m_shaft * (z_s - z_c) ** 2 + gear_m * (z_g - z_c) ** 2)
    drive_shaft_out = RigidBody(m_out, (0.0, 0.0, z_c), tuple(map(tuple, I_out)))
    plate_r, plate_t = L3 + 0.015, 0.008
    m_plate = RHO_ALUMINIUM * math.pi * plate_r**2 * plate_t
    m_extra = 0.150
    knee_plate = _cylinder(m_plate + m_extra, plate_r, plate_t, com=(0.0, 0.0, knee_to_crank / 2))
    bar_w, bar_t = 0.012, 0.006
    m_bar = RHO_ALUMINIUM * bar_w * bar_t * L4
    box = (bar_w**2 + L4**2, bar_t**2 + L4**2, bar_t**2 + bar_w**2)  # the bar as a box
    bar = np.diag([m_bar * v / 12 for v in box])
    coupler = RigidBody(m_bar, (0.0, 0.0, L4 / 2), tuple(map(tuple, bar)))
    m_cg = 0.025
    z_cr = m_bar * (L4 / 2) / (m_bar + m_cg)
    I_cr = (
        bar
        + np.diag([1.0, 1.0, 0.0]) * (m_bar * (L4 / 2 - z_cr) ** 2 + m_cg * z_cr**2)
        + np.diag([2e-6, 1e-6, 1e-6])  # the 25 g bevel gear (r ≈ 12 mm) about its own axis x: ½ m r²
    )
    crank = RigidBody(m_bar + m_cg, (0.0, 0.0, z_cr), tuple(map(tuple, I_cr)))
    foot_drop = L5 - knee_to_crank
    m_pad = 0.100
    m_frod = RHO_ALUMINIUM * math.pi * 0.005**2 * foot_drop
    z_f = (m_frod * foot_drop / 2 + m_pad * foot_drop) / (m_frod + m_pad)
    I_f = (
        _cylinder(m_frod, 0.005, foot_drop).inertia_matrix
        + _cylinder(m_pad, 0.03, 0.01).inertia_matrix
        + par * (m_frod * (foot_drop / 2 - z_f) ** 2 + m_pad * (foot_drop - z_f) ** 2)
    )
    foot = RigidBody(m_frod + m_pad, (0.0, 0.0, z_f), tuple(map(tuple, I_f)))
    return {
        "hip_cross": cross,
        "thigh_rod": thigh_rod,
        "knee_cross": cross,
        "knee_plate": knee_plate,
        "drive_shaft_in": drive_shaft_in,
        "drive_cross": cross,
        "drive_rod": drive_rod,
        "drive_shaft_out": drive_shaft_out,
        "crank": crank,
        "coupler": coupler,
        "foot": foot,
    }


BODY_FIELDS = (
    "hip_cross", "thigh_rod", "knee_cross", "knee_plate", "drive_shaft_in", "drive_cross", "drive_rod",
    "drive_shaft_out", "crank", "coupler", "foot",
)  # fmt: skip


class BodySet(Mapping):
    """The 11 body parameter sets of an :class:`OmniLeg`, a read-only mapping body kind -> RigidBody; the
    kinds not ``explicit`` are :func:`default_bodies` (docs/mechanisms/omnileg.md, "Derived inertias").

    Parameters
    ----------
    bodies : Mapping
        Body kind -> :class:`RigidBody` for all 11 kinds.
    explicit : frozenset of str
        The kinds given explicitly by the user (not derived from the dimensions).
    """

    __slots__ = ("_bodies", "_explicit")

    def __init__(self, bodies: Mapping[str, RigidBody], explicit: frozenset[str]) -> None:
        self._bodies = dict(bodies)
        self._explicit = frozenset(explicit)

    @property
    def explicit(self) -> frozenset[str]:
        """Body kinds given explicitly (not derived from the dimensions)."""
        return self._explicit

    def overrides(self) -> dict[str, RigidBody]:
        """The explicitly given bodies only."""
        return {k: self._bodies[k] for k in self._explicit}

    def __getitem__(self, key: str) -> RigidBody:
        return self._bodies[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._bodies)

    def __len__(self) -> int:
        return len(self._bodies)

    def __repr__(self) -> str:
        return f"BodySet(explicit={sorted(self._explicit)})"


_PAPER = {"L1": 0.15, "L3": 0.075, "L4": 0.095, "L5": 0.160}  # paper 2, Table 2 (m)
_KNEE_TO_CRANK = 0.030
_SHANK_RADIUS = 0.025


@dataclass(frozen=True)
class OmniLeg:
    """The OmniLeg: thigh 3-UU double-parallel mechanism + 3-RRR (crank-slider) shank.

    Defaults and their sources: docs/mechanisms/omnileg.md, "Parameters and their justification".

    Parameters
    ----------
    L1, L3, L4, L5 : float
        Thigh rod A_iB_i, U-joint offset from O0 and O0', shank link C_iD_i = D_iE_i, knee height (m), > 0.
    alpha_max, beta_max : float, optional
        Joint range magnitudes of α and β (rad), in (0, π/2).
    gamma_min, gamma_max : float, optional
        Range of the crank angle γ (rad), ``-π/2 < gamma_min < gamma_max < π/2``.
    knee_to_crank, shank_radius, shank_azimuth : float, optional
        Depth of the C_i below O0' (m, in [0, L5)), radius of the C_i/E_i circles (m), angle of chain
        C1D1E1 from X0 (rad).
    gravity : array_like, shape (3,), optional
        Gravity acceleration in the hip frame (m/s²; Z0 points down).
    bodies : Mapping, optional
        :class:`RigidBody` overrides by body kind (``BODY_FIELDS``); the others are :func:`default_bodies`
        (stored as a :class:`BodySet`).
    """

    L1: float
    L3: float
    L4: float
    L5: float
    alpha_max: float = math.radians(65.0)
    beta_max: float = math.radians(65.0)
    gamma_min: float = 0.0
    gamma_max: float = math.radians(85.0)
    knee_to_crank: float = _KNEE_TO_CRANK
    shank_radius: float = _SHANK_RADIUS
    shank_azimuth: float = math.pi / 2
    gravity: tuple[float, float, float] = (0.0, 0.0, STANDARD_GRAVITY)
    # compare=True: two legs are equal only if every body is (hash=False: a mapping is unhashable; equal
    # legs still hash equal since the hash covers the other fields).
    bodies: Mapping[str, RigidBody] = field(default_factory=dict, hash=False)

    def __post_init__(self) -> None:
        for name in ("L1", "L3", "L4", "L5", "shank_radius"):
            object.__setattr__(self, name, check_positive(getattr(self, name), f"OmniLeg.{name}"))
        h = check_positive(self.knee_to_crank, "OmniLeg.knee_to_crank", allow_zero=True)
        if h >= self.L5:  # the foot rod below the cranks needs a length
            raise ValueError(
                f"Expected OmniLeg.knee_to_crank in [0, L5 = {self.L5}), got {self.knee_to_crank!r}."
            )
        object.__setattr__(self, "knee_to_crank", h)
        for name in ("alpha_max", "beta_max"):
            v = check_positive(getattr(self, name), f"OmniLeg.{name}")
            if v >= math.pi / 2:  # tan(α), tan(β) enter eq. (11): |α|, |β| must stay below 90°.
                raise ValueError(f"Expected OmniLeg.{name} in (0, pi/2) rad, got {getattr(self, name)!r}.")
            object.__setattr__(self, name, v)
        gmin = check_real(self.gamma_min, "OmniLeg.gamma_min")
        gmax = check_real(self.gamma_max, "OmniLeg.gamma_max")
        # The crank-slider of the shank folds flat at γ = ±90°: the range must lie strictly inside.
        if not (-math.pi / 2 < gmin < gmax < math.pi / 2):
            raise ValueError(
                "Expected -pi/2 < OmniLeg.gamma_min < OmniLeg.gamma_max < pi/2, "
                f"got {self.gamma_min!r}, {self.gamma_max!r}."
            )
        object.__setattr__(self, "gamma_min", gmin)
        object.__setattr__(self, "gamma_max", gmax)
        object.__setattr__(self, "shank_azimuth", check_real(self.shank_azimuth, "OmniLeg.shank_azimuth"))
        g = as_array(self.gravity, "OmniLeg.gravity")
        if g.shape != (3,) or not np.all(np.isfinite(g)):
            raise ValueError(f"Expected OmniLeg.gravity to be 3 finite numbers, got {self.gravity!r}.")
        object.__setattr__(self, "gravity", tuple(float(v) for v in g))
        # A BodySet (e.g. passed back by dataclasses.replace) contributes only its explicit entries: the
        # defaults follow the (possibly new) dimensions.
        if isinstance(self.bodies, BodySet):
            bodies = self.bodies.overrides()
        elif isinstance(self.bodies, Mapping):
            bodies = dict(self.bodies)
        elif self.bodies is None:
            bodies = {}
        else:
            raise ValueError(
                "Expected OmniLeg.bodies to be a mapping of body kind to RigidBody, "
                f"got {type(self.bodies).__name__}."
            )
        explicit = frozenset(bodies)
        defaults = default_bodies(self.L1, self.L3, self.L4, self.L5, self.knee_to_crank)
        unknown = set(bodies) - set(BODY_FIELDS)
        if unknown:
            raise ValueError(
                f"Expected OmniLeg.bodies keys among {BODY_FIELDS}, got unknown {sorted(map(repr, unknown))}."
            )
        for k in BODY_FIELDS:
            b = bodies.get(k, defaults[k])
            if not isinstance(b, RigidBody):
                raise ValueError(f"Expected OmniLeg.bodies[{k!r}] to be a RigidBody, got {type(b).__name__}.")
            bodies[k] = b
        object.__setattr__(self, "bodies", BodySet({k: bodies[k] for k in BODY_FIELDS}, explicit))

    @classmethod
    def paper(cls) -> OmniLeg:
        """Table 2 of paper 2 (converted to SI), joint ranges read as magnitudes, default inertias."""
        return cls(L1=_PAPER["L1"], L3=_PAPER["L3"], L4=_PAPER["L4"], L5=_PAPER["L5"])

    @property
    def foot_drop(self) -> float:
        """Depth of the foot point below the E_i plane (m)."""
        return self.L5 - self.knee_to_crank

    def describe(self) -> dict[str, float]:
        """Scalar parameters (SI) for reports."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name not in ("bodies", "gravity")}
