"""Disk-resolved reference of a cable-driven continuum robot with friction at every hole (paper 3).

Formulated independently of ``robomech.mechanisms.continuum`` (no import of it, its own equations and
code path), so that it can arbitrate that package's constant-curvature, arc/chord, friction and
elongation models.  See ``docs/mechanisms/continuum_cosserat.md``.

Model
-----
* Backbone: an inextensible, unshearable Kirchhoff (Cosserat) rod of bending stiffness EI and torsional
  stiffness GJ, straight and stress free at rest, clamped at the base plate (``p = 0``, ``R = I``).
  With no distributed load its internal force ``n`` is constant between disks and
  ``p' = R e3``, ``R' = R û``, ``u = K⁻¹ Rᵀ m``, ``m' = -p' × n`` (base frame).
* Disks: rigid, thin, glued to the backbone at equal arc-length spacing ``segment_length / N``; a disk
  at ``s_d`` has the backbone pose ``(p_d, R_d)``; hole ``c`` sits at ``h = p_d + R_d r_c``.
* Cables: straight spans between the holes of consecutive disks (the chord geometry follows from the
  rod's computed shape, not from an assumed arc), arriving at the base-plate hole along +z from the
  actuator (straight free length below the base).  A cable passing disk d pulls it with
  ``T_{d+1} a_{d+1} - T_d a_d`` (unit span directions a, span tensions T), its termination disk with
  ``-T_D a_D``; the moment about the backbone point is ``(R_d r_c) × f``.  These point wrenches make the
  rod's internal wrench jump: ``n(s_d⁻) = n(s_d⁺) + f``, ``m(s_d⁻) = m(s_d⁺) + (R_d r_c) × f``.
* Friction: Coulomb friction on the wrap of a cable around a hole edge, the capstan law over the wrap
  angle η_d = ∠(a_d, a_{d+1}) of the actual span directions: ``T_{d+1} = T_d exp(-s μ η_d)`` with
  s = +1 for a cable being pulled in (sliding toward the actuator: the proximal side carries more
  tension), -1 paid out, 0 frictionless.  Holes are points (no hole length, no edge radius).
* Cables are elastic (EA): a cable's stretch is ``(T_act L_free + Σ_d T_d ℓ_d - T0 (L_free + L0)) / EA``
  relative to the straight pose at the pretension T0 (ℓ_d span lengths, L0 the straight length).

Solution: multiple shooting over the disk intervals.  Unknowns per interval: the backbone position,
a rotation increment and the internal wrench (n, m) at its start; each interval is integrated by
classical RK4 (``DISK_RK4_STEPS`` steps); residuals are the base clamp, continuity of the pose and the
wrench jumps at the disks, and the tip wrench.  In drive mode the actuator tensions are unknowns too,
with each cable's length compatibility as residual (a slack cable has zero tension and a gap).
Solved by damped Newton (structured finite-difference Jacobian) from a constant-curvature guess,
with continuation in the load.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from .._validation import as_array, check_positive

__all__ = [
    "DISK_RESIDUAL_TOL",
    "DISK_RK4_STEPS",
    "DiskRobot",
    "DiskSolution",
    "solve_disk_robot",
    "straight_buckling_tension",
    "straight_stability",
]

DISK_RK4_STEPS = 12
"""RK4 steps per disk interval (18 mm on the paper robot).  Between disks the rod is a column under the
cables' compression P (~20 N at the paper's tensions, wave number sqrt(P/EI) ~ 130/m), so the step must
resolve it: measured tip change when the steps are doubled: 4 → 8: 22 µm, 12 → 24: < 1 µm (test), far
below the mm-level differences the reference arbitrates."""
DISK_RESIDUAL_TOL = 1e-10
"""Accepted max |residual| of the shooting equations (nondimensional: lengths / L, forces / (EI/L²)):
~1e-10 of the O(1) scales, far below the µm-level differences the reference arbitrates."""
DISK_NEWTON_STOP = 1e-12
"""Newton stops below this max |residual| (100x under DISK_RESIDUAL_TOL; round-off is ~1e-14)."""
DISK_NEWTON_ITERATIONS = 12
"""Newton iterations per continuation step (quadratic convergence needs 3-6 from the previous step)."""
DISK_NEWTON_BACKTRACKS = 8
"""Step halvings of the Newton line search before the continuation step is declared failed."""
FD_STEP = 1e-6
"""Central-difference step of the Jacobian, relative to the unknowns' scale (~eps^(1/3))."""
DISK_CONTINUATION_FIRST_STEP = 0.5
"""Continuation in the load (see _solve_case): first step 0.5 of the load (the direct full step fails
from the straight guess at the paper's tensions: the cable compression, ~60 % of the Euler load of one
18 mm disk interval, makes the shooting map strongly nonlinear), doubled after success ..."""
DISK_CONTINUATION_MIN_STEP = 1.0 / 64.0
"""... halved after a failure down to 1/64; below it the case is reported not converged with the load
fraction it reached."""
SLACK_SCALE = 1.0
"""Nondimensional slack variable: a negative tension unknown x means tension 0 and a gap of -x·L·EI/(L² EA)
... i.e. the same scale as the stretch; any positive scale gives the same solution."""


@dataclass(frozen=True)
class DiskRobot:
    """Disk-resolved robot, SI units (its own parameter object: nothing shared with the CC package).

    segment_lengths (K,) m; disks_per_segment N (the segment's end disk included; the base of segment 1
    is the fixed base plate); bending_stiffness EI and torsional_stiffness GJ (N m²) of the backbone;
    hole_radius, hole_angle (n_c,): hole of cable c at ``r (cos a, sin a, 0)`` in every disk frame;
    cable_segment (n_c,): 0-based segment at whose end disk the cable terminates; friction (n_c,) μ ≥ 0;
    cable_axial_stiffness EA (N); free_length (m) of cable between actuator and base plate; pretension
    T0 (N) of the straight reference pose (elongation and drive are measured from it).
    """

    segment_lengths: tuple[float, ...]
    disks_per_segment: int
    bending_stiffness: float
    torsional_stiffness: float
    hole_radius: tuple[float, ...]
    hole_angle: tuple[float, ...]
    cable_segment: tuple[int, ...]
    friction: tuple[float, ...]
    cable_axial_stiffness: float
    free_length: float
    pretension: float

    def __post_init__(self) -> None:
        lengths = tuple(float(x) for x in np.atleast_1d(self.segment_lengths))
        if not lengths:
            raise ValueError("Expected segment_lengths to hold at least one length, got none.")
        for k, ell in enumerate(lengths):
            check_positive(ell, f"segment_lengths[{k}]")
        object.__setattr__(self, "segment_lengths", lengths)
        if not isinstance(self.disks_per_segment, int | np.integer) or self.disks_per_segment < 1:
            raise ValueError(f"Expected disks_per_segment an integer >= 1, got {self.disks_per_segment!r}.")
        for name in ("bending_stiffness", "torsional_stiffness", "cable_axial_stiffness"):
            check_positive(getattr(self, name), name)
        check_positive(self.free_length, "free_length", allow_zero=True)
        check_positive(self.pretension, "pretension", allow_zero=True)
        n_c = len(np.atleast_1d(self.hole_radius))
        conv = {}
        for name in ("hole_radius", "hole_angle", "friction"):
            vals = tuple(float(x) for x in np.atleast_1d(getattr(self, name)))
            if len(vals) != n_c or not all(math.isfinite(v) for v in vals):
                raise ValueError(f"Expected {name} of {n_c} finite values, got {getattr(self, name)!r}.")
            conv[name] = vals
        if n_c == 0 or any(r <= 0 for r in conv["hole_radius"]):
            raise ValueError(f"Expected hole_radius > 0 for at least one cable, got {self.hole_radius!r}.")
        if any(m < 0 for m in conv["friction"]):
            raise ValueError(f"Expected friction coefficients >= 0, got {self.friction!r}.")
        seg = tuple(np.atleast_1d(self.cable_segment).tolist())
        if len(seg) != n_c or not all(isinstance(k, int) and 0 <= k < len(lengths) for k in seg):
            raise ValueError(f"Expected cable_segment of {n_c} segment indices, got {self.cable_segment!r}.")
        for name, vals in conv.items():
            object.__setattr__(self, name, vals)
        object.__setattr__(self, "cable_segment", seg)

    @property
    def n_cables(self) -> int:
        return len(self.hole_radius)

    @property
    def n_disks(self) -> int:
        """Disks above the base plate (= shooting intervals)."""
        return len(self.segment_lengths) * self.disks_per_segment

    @property
    def length(self) -> float:
        return float(sum(self.segment_lengths))


@dataclass(frozen=True)
class DiskSolution:
    """Equilibria of a batch of cases (batch shape ``B``), SI units.

    disk_T (*B, 1 + J, 4, 4): base plate and disk poses; T_tip (*B, 4, 4).  tension (*B, n_c) actuator
    side (below the base plate); span_tension (*B, n_c, J) (0 beyond the cable's end); wrap (*B, n_c, J)
    wrap angle at the hole where each span starts (base plate first); path_length (*B, n_c) chord length
    from the base plate to the termination hole; elongation (*B, n_c) stretch from the straight
    pretensioned pose; taut (*B,) no cable slack; converged (*B,): residual ≤ DISK_RESIDUAL_TOL and
    finite; residual (*B,) max |shooting residual|; load_fraction (*B,) reached by continuation.
    """

    disk_T: np.ndarray
    T_tip: np.ndarray
    tension: np.ndarray
    span_tension: np.ndarray
    wrap: np.ndarray
    path_length: np.ndarray
    elongation: np.ndarray
    taut: np.ndarray
    converged: np.ndarray
    residual: np.ndarray
    load_fraction: np.ndarray
    seconds: float


# ---- nondimensional model ---------------------------------------------------------------------------
_E3 = np.array([0.0, 0.0, 1.0])


def _hat(w: np.ndarray) -> np.ndarray:
    """(..., 3) -> (..., 3, 3)."""
    W = np.zeros((*w.shape, 3))
    W[..., 0, 1], W[..., 0, 2] = -w[..., 2], w[..., 1]
    W[..., 1, 0], W[..., 1, 2] = w[..., 2], -w[..., 0]
    W[..., 2, 0], W[..., 2, 1] = -w[..., 1], w[..., 0]
    return W


def _expm(w: np.ndarray) -> np.ndarray:
    """Rodrigues, (..., 3) -> (..., 3, 3), finite at 0."""
    th = np.linalg.norm(w, axis=-1)[..., None, None]
    W = _hat(w)
    small = th < 1e-8
    a = np.where(small, 1.0 - th**2 / 6.0, np.sin(th) / np.where(small, 1.0, th))
    b = np.where(small, 0.5 - th**2 / 24.0, (1.0 - np.cos(th)) / np.where(small, 1.0, th**2))
    return np.eye(3) + a * W + b * (W @ W)


class _Model:
    """Nondimensional geometry and the shooting residual (lengths / L, forces / (EI/L²))."""

    def __init__(self, robot: DiskRobot) -> None:
        L, ei = robot.length, robot.bending_stiffness
        self.L, self.ei = L, ei
        N, K = robot.disks_per_segment, len(robot.segment_lengths)
        self.J = N * K
        self.h = np.repeat(np.asarray(robot.segment_lengths) / (N * L), N)  # (J,) interval lengths
        self.kinv = np.array([1.0, 1.0, ei / robot.torsional_stiffness])
        r = np.asarray(robot.hole_radius) / L
        a = np.asarray(robot.hole_angle)
        self.r = np.stack([r * np.cos(a), r * np.sin(a), np.zeros_like(r)], -1)  # (n_c, 3)
        self.n_c = robot.n_cables
        self.end = (np.asarray(robot.cable_segment) + 1) * N  # termination disk index (1..J)
        self.active = np.arange(1, self.J + 1)[None, :] <= self.end[:, None]  # (n_c, J): span d+1 exists
        self.mu = np.asarray(robot.friction)
        self.ea = robot.cable_axial_stiffness / (ei / L**2)
        self.lf = robot.free_length / L
        self.t0 = robot.pretension / (ei / L**2)
        self.L0 = np.cumsum(self.h)[self.end - 1]  # straight length of every cable (n_c,)

    # -- rod integration over all intervals at once
    def _rhs(self, R, m, n):
        # components written out: np.cross and a batched @ with û dominated the cost
        c0, c1, c2 = R[..., 0], R[..., 1], R[..., 2]  # columns of R, (..., J, 3)
        k = self.kinv
        u1 = (np.sum(c0 * m, -1) * k[0])[..., None]  # u = K⁻¹ Rᵀ m
        u2 = (np.sum(c1 * m, -1) * k[1])[..., None]
        u3 = (np.sum(c2 * m, -1) * k[2])[..., None]
        dR = np.empty_like(R)  # R û, column by column
        dR[..., 0] = u3 * c1 - u2 * c2
        dR[..., 1] = u1 * c2 - u3 * c0
        dR[..., 2] = u2 * c0 - u1 * c1
        dp = c2
        dm = np.empty_like(m)  # -dp × n
        dm[..., 0] = dp[..., 2] * n[..., 1] - dp[..., 1] * n[..., 2]
        dm[..., 1] = dp[..., 0] * n[..., 2] - dp[..., 2] * n[..., 0]
        dm[..., 2] = dp[..., 1] * n[..., 0] - dp[..., 0] * n[..., 1]
        return dp, dR, dm

    def integrate(self, p, R, m, n, steps: int):
        h = (self.h / steps)[:, None]
        hh = h[..., None]
        for _ in range(steps):
            k1 = self._rhs(R, m, n)
            k2 = self._rhs(R + 0.5 * hh * k1[1], m + 0.5 * h * k1[2], n)
            k3 = self._rhs(R + 0.5 * hh * k2[1], m + 0.5 * h * k2[2], n)
            k4 = self._rhs(R + hh * k3[1], m + h * k3[2], n)
            p = p + h / 6.0 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
            R = R + hh / 6.0 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
            m = m + h / 6.0 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2])
        return p, R, m

    # -- cables (every function below takes leading batch dimensions: the Jacobian assembles all its
    # perturbed columns in one call)
    def cables(self, P, Rd, t_act, direction):
        """Disk poses P (..., J+1, 3), Rd (..., J+1, 3, 3) incl. the base plate -> span geometry and
        tensions (..., n_c, J)."""
        holes = P[..., None, :, :] + np.einsum("...dab,cb->...cda", Rd, self.r)  # (..., n_c, J+1, 3)
        e = np.diff(holes, axis=-2)  # (..., n_c, J, 3) span vectors
        ell = np.linalg.norm(e, axis=-1)
        a = e / ell[..., None]
        incoming = np.concatenate([np.broadcast_to(_E3, (*a.shape[:-2], 1, 3)), a[..., :-1, :]], axis=-2)
        # wrap angle at the hole where span d starts: angle between the incoming and outgoing directions
        eta = 2.0 * np.arctan2(np.linalg.norm(a - incoming, axis=-1), np.linalg.norm(a + incoming, axis=-1))
        eta = np.where(self.active, eta, 0.0)
        factor = np.exp(-np.cumsum(direction[..., :, None] * self.mu[:, None] * eta, axis=-1))
        T = np.where(self.active, t_act[..., :, None] * factor, 0.0)  # (..., n_c, J) span tensions
        return holes, a, ell, eta, T

    def disk_wrenches(self, Rd, a, T):
        """Force and moment (about the backbone point) of all cables on disks 1..J, (..., J, 3) each."""
        zero = np.zeros((*T.shape[:-1], 1, 3))
        pull_out = np.concatenate([T[..., 1:, None] * a[..., 1:, :], zero], axis=-2)
        f_c = pull_out - T[..., None] * a  # (..., n_c, J, 3): on disk d+1 (index d)
        f_c = np.where(self.active[..., None], f_c, 0.0)
        arm = np.einsum("...dab,cb->...cda", Rd[..., 1:, :, :], self.r)
        return f_c.sum(-3), np.cross(arm, f_c).sum(-3)


def _unpack(model: _Model, x: np.ndarray, Rbar: np.ndarray):
    J = model.J
    X = x[..., : 12 * J].reshape(*x.shape[:-1], J, 12)
    p, w, n, m = X[..., 0:3], X[..., 3:6], X[..., 6:9], X[..., 9:12]
    R = Rbar @ _expm(w)
    return p, R, n, m, x[..., 12 * J :]


def _assemble(model, x, Rbar, ends, F_tip, L_tip, direction, mode, load):
    """Shooting residual (..., n_x) from the unknowns ``x (..., n_x)`` and the integrated interval ends
    ``(pe, Re, me)``.  mode 'tension': the actuator tensions are given (``load``); mode 'drive': ``load``
    is the drive q (nondimensional) and the tensions are the trailing unknowns."""
    p, R, n, m, xt = _unpack(model, x, Rbar)
    batch = x.shape[:-1]
    pe, Re, me = ends
    P = np.concatenate([np.zeros((*batch, 1, 3)), pe], -2)  # disk positions from the end of each interval
    Rd = np.concatenate([np.broadcast_to(np.eye(3), (*batch, 1, 3, 3)), Re], -3)
    t_act = load if mode == "tension" else np.maximum(xt, 0.0)
    _, a, ell, _, T = model.cables(P, Rd, t_act, direction)
    f, mo = model.disk_wrenches(Rd, a, T)
    R0 = R[..., 0, :, :] - np.eye(3)
    res = [p[..., 0, :], R0[..., [2, 0, 1], [1, 2, 0]]]  # base clamp (rotation: skew part)
    # continuity at the interior disks: start of interval d = end of interval d-1
    res.append(pe[..., :-1, :] - p[..., 1:, :])
    dR = np.einsum("...jba,...jbc->...jac", R[..., 1:, :, :], Re[..., :-1, :, :])  # R_startᵀ R_end = I
    res.append(
        0.5
        * np.stack(
            [dR[..., 2, 1] - dR[..., 1, 2], dR[..., 0, 2] - dR[..., 2, 0], dR[..., 1, 0] - dR[..., 0, 1]], -1
        )
    )
    # wrench jumps at disks 1..J: n(s⁻) = n(s⁺) + f; beyond the tip, n(s⁺) = F_tip, m(s⁺) = L_tip
    n_plus = np.concatenate([n[..., 1:, :], np.broadcast_to(F_tip, (*batch, 1, 3))], -2)
    m_plus = np.concatenate([m[..., 1:, :], np.broadcast_to(L_tip, (*batch, 1, 3))], -2)
    res.append(n - (n_plus + f))  # no distributed load: n is constant over an interval
    res.append(me - (m_plus + mo))
    if mode == "drive":
        path = np.sum(ell * model.active, axis=-1)
        stretch = (t_act * model.lf + np.sum(T * ell, axis=-1) - model.t0 * (model.lf + model.L0)) / model.ea
        gap = np.minimum(xt, 0.0) * SLACK_SCALE / model.ea  # slack cable: tension 0, path shorter
        # scaled by EA (a force, like the other residuals): unscaled, this stiff equation (~1e-3 of L
        # for a tension change of ~30 EI/L²) misled the Newton line search's merit function
        res.append(model.ea * (path - model.L0 + load - stretch - gap))
    return np.concatenate([r.reshape(*batch, -1) for r in res], -1)


def _ends(model, x, Rbar, steps):
    p, R, n, m, _ = _unpack(model, x, Rbar)
    return model.integrate(p, R, m, n, steps)


def _jacobian(model, x, Rbar, steps, assemble):
    """Central-difference Jacobian exploiting the structure: the end of interval j depends only on
    interval j's 12 unknowns, so perturbing component c of every interval at once gives all their
    columns from one pair of integrations, and the 24 perturbed states plus the base state are
    integrated together in one batched call; the cheap cable/assembly part is then evaluated for all
    perturbed columns in one batched call (it was 24 J calls, 80 % of the time on 2-3 segments)."""
    J = model.J
    n_rod = 12 * J
    hcs = np.array([FD_STEP * max(1.0, float(np.max(np.abs(x[c:n_rod:12])))) for c in range(12)])
    xs = [x]
    for c in range(12):
        dx = np.zeros_like(x)
        dx[c:n_rod:12] = hcs[c]
        xs += [x + dx, x - dx]
    parts = [_unpack(model, z, Rbar) for z in xs]
    p, R, n, m = (np.stack([q[i] for q in parts]) for i in range(4))
    ends = model.integrate(p, R, m, n, steps)  # (25, J, ...)
    cols = np.arange(n_rod)
    j_of, c_of = cols // 12, cols % 12
    h = np.concatenate([np.tile(hcs, J), FD_STEP * np.maximum(1.0, np.abs(x[n_rod:]))])
    E = np.diag(h)  # (n_x, n_x): column i perturbed by h_i

    def perturbed(offset):
        out = []
        for e in ends:
            b = np.broadcast_to(e[0], (x.size, *e[0].shape)).copy()
            b[cols, j_of] = e[offset + 2 * c_of, j_of]  # rod columns: interval j's end moved
            out.append(b)
        return tuple(out)

    # row i of each: the residual with unknown i perturbed (the tension unknowns of drive mode involve
    # no integration: their rows keep the base ends)
    f_plus = assemble(x + E, perturbed(1))
    f_minus = assemble(x - E, perturbed(2))
    return ((f_plus - f_minus) / (2.0 * h[:, None])).T


def _guess(model: _Model, t_act: np.ndarray, F_tip: np.ndarray, L_tip: np.ndarray):
    """Constant-curvature guess (own computation): each segment an arc bent by its cables' moments."""
    J = model.J
    u = np.zeros((J, 3))
    for d in range(J):
        act = model.end > d
        u[d] = np.sum(t_act[act, None] * np.cross(model.r[act], _E3), axis=0) * -1.0
        u[d] *= model.kinv
    # poses along the chained arcs
    p = np.zeros((J, 3))
    R = np.zeros((J, 3, 3))
    pc, Rc = np.zeros(3), np.eye(3)
    for d in range(J):
        p[d], R[d] = pc, Rc
        w = u[d] * model.h[d]
        th = np.linalg.norm(w)
        Rl = _expm(w)
        if th < 1e-12:
            pl = model.h[d] * _E3
        else:
            W = _hat(w)
            pl = (
                model.h[d]
                * (np.eye(3) + (1 - math.cos(th)) / th**2 * W + (th - math.sin(th)) / th**3 * W @ W)
                @ _E3
            )
        pc, Rc = pc + Rc @ pl, Rc @ Rl
    # internal forces consistent with the cable forces on the guessed disks: n_j = F_tip + Σ_{d > j} f_d
    P = np.concatenate([np.zeros((1, 3)), p[1:], [pc]], 0)
    Rd = np.concatenate([np.eye(3)[None], R[1:], Rc[None]], 0)
    _, a, _, _, T = model.cables(P, Rd, t_act, np.zeros(model.n_c))
    f, _ = model.disk_wrenches(Rd, a, T)
    n = F_tip + np.cumsum(f[::-1], axis=0)[::-1]
    m = np.einsum("jab,jb->ja", R, u / model.kinv)
    return p, R, n, m


def _newton(fun, jac, x: np.ndarray) -> tuple[np.ndarray, float]:
    """Damped Newton on the square shooting system: full steps with the structured central-difference
    Jacobian, halved (up to ``DISK_NEWTON_BACKTRACKS`` times) while they do not lower |F|².  Returns
    the last iterate and its max |residual| (inf if a trial became non-finite or singular).

    Newton rather than MINPACK ``hybr``: with its xtol at round-off, hybr spent its 100 evaluations per
    continuation step on rank-one updates and failed half the steps; Newton with the exact-structure
    Jacobian converges quadratically in 3-6 iterations per step (9x fewer integrations, measured)."""
    with np.errstate(all="ignore"):
        f = fun(x)
        r = float(np.max(np.abs(f)))
        merit = float(f @ f)
        for _ in range(DISK_NEWTON_ITERATIONS):
            if not math.isfinite(r):
                return x, math.inf
            if r <= DISK_NEWTON_STOP:
                break
            try:
                dx = np.linalg.solve(jac(x), f)
            except np.linalg.LinAlgError:
                return x, math.inf
            scale = 1.0
            for _ in range(DISK_NEWTON_BACKTRACKS):
                xn = x - scale * dx
                fn = fun(xn)
                rn, mn = float(np.max(np.abs(fn))), float(fn @ fn)
                if math.isfinite(mn) and mn < merit:
                    break
                scale *= 0.5
            else:
                return x, r  # no descent: this continuation step failed
            stalled = r <= DISK_RESIDUAL_TOL and rn > 0.1 * r  # at round-off: more steps do not help
            x, f, r, merit = xn, fn, rn, mn
            if stalled:
                break
    return x, r


def _solve_case(model, t_act, q, F_tip, L_tip, direction, mode, steps):
    """Continuation from the straight rod: in tension mode the tensions go from their common part
    (min over the cables: the straight rod under uniform pretension is an exact equilibrium) to the
    given ones, in drive mode the drive from 0; the tip wrench is ramped along.  Each step is solved by
    damped Newton (:func:`_newton`) from the previous one; a failed step is halved."""
    if mode == "tension":
        base_t = np.full(model.n_c, float(np.min(t_act)))
        t_guess = base_t
    else:
        base_t = None
        t_guess = np.full(model.n_c, model.t0)
    p, Rbar, n, m = _guess(model, t_guess, 0.0 * F_tip, 0.0 * L_tip)
    x = np.concatenate(
        [np.concatenate([p, np.zeros_like(p), n, m], 1).ravel(), [] if mode == "tension" else t_guess]
    )

    def run(x, frac):
        load = base_t + frac * (t_act - base_t) if mode == "tension" else frac * q

        def assemble(z, ends):
            return _assemble(model, z, Rbar, ends, frac * F_tip, frac * L_tip, direction, mode, load)

        def fun(z):
            return assemble(z, _ends(model, z, Rbar, steps))

        return _newton(fun, lambda z: _jacobian(model, z, Rbar, steps, assemble), x)

    frac, step, r = 0.0, DISK_CONTINUATION_FIRST_STEP, np.inf
    while frac < 1.0 and step >= DISK_CONTINUATION_MIN_STEP:
        target = min(1.0, frac + step)
        xn, rn = run(x, target)
        if rn <= DISK_RESIDUAL_TOL:
            x, frac, r = xn, target, rn
            step *= 2.0
        else:
            step *= 0.5
    if frac < 1.0:
        _, r = run(x, 1.0)  # residual of the full load at the last converged state
    return x, r, frac, Rbar


def straight_stability(robot: DiskRobot, tension: object, *, steps: int = DISK_RK4_STEPS) -> np.ndarray:
    """Smallest singular value of the shooting Jacobian (nondimensional) at the straight equilibrium
    under equal tensions ``tension (*B,)`` (N) in every cable, frictionless.

    The straight rod under equal tensions is an exact equilibrium at every tension; where this value
    falls to 0 that equilibrium bifurcates (the robot buckles: a double zero, one per bending plane, so
    the determinant touches 0 without changing sign).  With a 0.8 mm core
    the zero sits at 12.25 N per cable, = the Euler load pi² EI / h² of one disk interval under the
    three cables' compression 3 T, inside the paper's 3-11 N range plus margin; see
    ``docs/mechanisms/continuum_cosserat.md``."""
    t = as_array(tension, "tension", ())
    if np.any(t < 0):
        raise ValueError(f"Expected tension >= 0, got min {t.min()!r}.")
    if not (isinstance(steps, int) and steps >= 1):
        raise ValueError(f"Expected steps an integer >= 1, got {steps!r}.")
    model = _Model(robot)
    fs = model.ei / model.L**2
    zero = np.zeros(3)
    out = np.empty(t.size)
    for b, tb in enumerate(t.ravel()):
        t_act = np.full(model.n_c, float(tb) / fs)
        p, Rbar, n, m = _guess(model, t_act, zero, zero)
        x = np.concatenate([p, np.zeros_like(p), n, m], 1).ravel()

        def assemble(z, ends, t_act=t_act, Rbar=Rbar):
            return _assemble(model, z, Rbar, ends, zero, zero, np.zeros(model.n_c), "tension", t_act)

        jac = _jacobian(model, x, Rbar, steps, assemble)
        out[b] = np.linalg.svd(jac, compute_uv=False)[-1]
    return out.reshape(t.shape)


BUCKLING_XTOL = 0.01
"""Tension resolution (N) of :func:`straight_buckling_tension` (the minimum of σ_min is sharp: at the
located tension it is ~1e-9, against ~1e-4 at 3 N)."""


def straight_buckling_tension(robot: DiskRobot, low: float, high: float) -> float:
    """The tension per cable (N) in ``[low, high]`` where :func:`straight_stability` has its minimum,
    i.e. where the straight robot under equal tensions buckles (scipy ``minimize_scalar``, bounded, to
    ``BUCKLING_XTOL``).  The bracket must hold one minimum (e.g. 0.8-1.2 × the Euler load of one disk
    interval, π² EI / (3 n h²) per cable for n segments)."""
    from scipy.optimize import minimize_scalar

    lo, hi = check_positive(low, "low"), check_positive(high, "high")
    if not hi > lo:
        raise ValueError(f"Expected high > low, got low={lo!r}, high={hi!r}.")
    res = minimize_scalar(
        lambda t: float(straight_stability(robot, t)),
        bounds=(lo, hi),
        method="bounded",
        options={"xatol": BUCKLING_XTOL},
    )
    return float(res.x)


def _as_direction(direction, n_c, batch):
    if direction is None:
        return np.zeros((*batch, n_c))
    d = as_array(direction, "direction", (n_c,))
    if np.any((d != -1.0) & (d != 0.0) & (d != 1.0)):
        raise ValueError("Expected direction entries in {-1, 0, +1} (paid out, frictionless, pulled in).")
    return d


def solve_disk_robot(
    robot: DiskRobot,
    *,
    tension: object | None = None,
    drive: object | None = None,
    direction: object | None = None,
    tip_force: object | None = None,
    tip_moment: object | None = None,
    steps: int = DISK_RK4_STEPS,
) -> DiskSolution:
    """Equilibrium of the disk-resolved robot for a batch of cases.

    Exactly one of ``tension (*B, n_c)`` (actuator-side tensions, N, >= 0) and ``drive (*B, n_c)``
    (cable pulled in by each actuator since the straight pretensioned pose, m) is given.
    ``direction (*B, n_c)`` in {-1, 0, +1}: sliding direction of each cable (+1 pulled in), 0 or None
    frictionless.  ``tip_force``, ``tip_moment (*B, 3)``: dead loads at the tip in the base frame.
    """
    if (tension is None) == (drive is None):
        raise ValueError("Expected exactly one of tension and drive, got both or neither.")
    n_c = robot.n_cables
    if tension is not None:
        load = as_array(tension, "tension", (n_c,))
        if np.any(load < 0):
            raise ValueError(f"Expected tension >= 0 (a cable cannot push), got min {load.min()!r}.")
        mode = "tension"
    else:
        load = as_array(drive, "drive", (n_c,))
        mode = "drive"
    F = as_array(np.zeros(3) if tip_force is None else tip_force, "tip_force", (3,))
    M = as_array(np.zeros(3) if tip_moment is None else tip_moment, "tip_moment", (3,))
    if not (isinstance(steps, int) and steps >= 1):
        raise ValueError(f"Expected steps an integer >= 1, got {steps!r}.")
    batch0 = np.broadcast_shapes(load.shape[:-1], F.shape[:-1], M.shape[:-1])
    d = _as_direction(direction, n_c, batch0)
    batch = np.broadcast_shapes(batch0, d.shape[:-1])
    model = _Model(robot)
    L, ei = model.L, model.ei
    fs, ms = ei / L**2, ei / L
    lb = np.broadcast_to(load, (*batch, n_c)).reshape(-1, n_c)
    Fb = np.broadcast_to(F, (*batch, 3)).reshape(-1, 3) / fs
    Mb = np.broadcast_to(M, (*batch, 3)).reshape(-1, 3) / ms
    db = np.broadcast_to(d, (*batch, n_c)).reshape(-1, n_c)
    nb, J = lb.shape[0], model.J
    out_T = np.zeros((nb, J + 1, 4, 4))
    out_t = np.zeros((nb, n_c))
    out_span = np.zeros((nb, n_c, J))
    out_wrap = np.zeros((nb, n_c, J))
    out_path = np.zeros((nb, n_c))
    out_el = np.zeros((nb, n_c))
    taut = np.zeros(nb, bool)
    conv = np.zeros(nb, bool)
    res = np.full(nb, np.inf)
    frac = np.zeros(nb)
    t0 = time.perf_counter()
    for b in range(nb):
        t_act = lb[b] / fs if mode == "tension" else None
        q = lb[b] / L if mode == "drive" else None
        x, r, frac[b], Rbar = _solve_case(model, t_act, q, Fb[b], Mb[b], db[b], mode, steps)
        res[b] = r
        p, R, n, m, xt = _unpack(model, x, Rbar)
        pe, Re, _ = model.integrate(p, R, m, n, steps)
        P = np.concatenate([np.zeros((1, 3)), pe], 0)
        Rd = np.concatenate([np.eye(3)[None], Re], 0)
        ta = frac[b] * t_act if mode == "tension" else np.maximum(xt, 0.0)
        _, _, ell, eta, T = model.cables(P, Rd, ta, db[b])
        out_T[b, :, :3, :3] = Rd
        out_T[b, :, :3, 3] = P * L
        out_T[b, :, 3, 3] = 1.0
        out_t[b] = ta * fs
        out_span[b] = T * fs
        out_wrap[b] = eta
        out_path[b] = np.sum(ell * model.active, axis=1) * L
        out_el[b] = (
            (ta * model.lf + np.sum(T * ell, axis=1) - model.t0 * (model.lf + model.L0)) / model.ea * L
        )
        taut[b] = mode == "tension" or bool(np.all(xt >= 0.0))
        conv[b] = bool(r <= DISK_RESIDUAL_TOL) and frac[b] == 1.0 and bool(np.all(np.isfinite(x)))
    shp = batch
    return DiskSolution(
        disk_T=out_T.reshape(*shp, J + 1, 4, 4),
        T_tip=out_T[:, -1].reshape(*shp, 4, 4),
        tension=out_t.reshape(*shp, n_c),
        span_tension=out_span.reshape(*shp, n_c, J),
        wrap=out_wrap.reshape(*shp, n_c, J),
        path_length=out_path.reshape(*shp, n_c),
        elongation=out_el.reshape(*shp, n_c),
        taut=taut.reshape(shp),
        converged=conv.reshape(shp),
        residual=res.reshape(shp),
        load_fraction=frac.reshape(shp),
        seconds=time.perf_counter() - t0,
    )
