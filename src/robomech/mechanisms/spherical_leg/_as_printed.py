"""Paper 1's forward solution exactly as printed (eqs. (6)-(7)): for showing why its numbers differ.

Nothing here is a model robomech uses: it re-runs the printed pipeline, misprints included, so that a
report can put its output beside the exact solution.  As printed (paper 1, Section 3.2), in mm:

* β = arcsin((l2² - l1²) / (4 R h)) (eq. (6); right);
* the half-angle tangent a = tan(α/2) solves a⁴ + k1 a³ + k2 a² + k3 a + k4 = 0 with A = cos β,
  D = r² + R² + h² + 2Rr - l3², k1 = k3 = 4RhA / D, k4 = (r² + R² + h² - 2Rr - l3²) / D and
  k2 = [(l2² - l1²) / (8R²) + 2r² + 2R² + 2h²A² - 2l3²] / D.  Correct is (l2² - l1²)² / (8R²) (the
  square is lost; with it k2 = 1 + k4 and the quartic is (a² + 1)(a² + k1 a + k4): the exact quadratic);
  the lost square makes the printed k2 depend on the unit, so it is evaluated in mm, the paper's unit;
* Ferrari's method with the resolvent Q = (2k2³ - 9 k2 k3 k4 + 27k3² + 27k1²k4 - 72k2k4) / 54 (correct:
  9 k1 k2 k3), D = sqrt(Q² - P³), P = (k2² - 3k1k3 + 12k4)/9, G = cbrt(Q + D) + P / cbrt(Q + D),
  M = sqrt(k1²/4 - 2k2/3 + G), S = k1²/2 - 4k2/3 - G, T = (-k1³ + 4k1k2 - 8k3) / (4M),
  a = -k1/4 ± M/2 ± sqrt(S ± T)/2 (the sign of T paired with that of M), in complex arithmetic as
  MATLAB evaluates it;
* α = arctan(2a) (correct: 2 arctan(a)), "discarding the solutions outside (-π/2, π/2)".

The print does not say which of the remaining roots it keeps; here: the real one (|Im| below
``REAL_ROOT_TOL``) in (-π/2, π/2) whose α reproduces l3 best.  With all three misprints corrected this
pipeline returns the exact pose (tests), so the misprints alone are what it shows.
"""

from __future__ import annotations

import numpy as np

# A root of the printed quartic counts as real when its imaginary part is below this (relative to
# 1 + |a|): the complex Ferrari arithmetic leaves ~1e-16 imaginary parts on real roots, while the
# complex pairs of this quartic have |Im a| > 0.1 (the factor a² + 1 of the correct quartic, shifted).
REAL_ROOT_TOL = 1e-9
_MM = 1e3


def forward_as_printed(leg, L: np.ndarray, *, fix_square=False, fix_resolvent=False, fix_arctan=False):
    """(alpha, beta, residual (m), valid) from lengths ``L (n, 3)`` (m) by the printed pipeline.

    The ``fix_*`` switches correct one misprint each (used by the tests and the report to attribute
    the error); all three together give the exact solution.
    """
    R, r, h = leg.R * _MM, leg.r * _MM, leg.h * _MM
    with np.errstate(all="ignore"):
        ok_in = np.all(np.isfinite(L), -1) & np.all(L > 0, -1)
        l1, l2, l3 = (np.where(ok_in, L[:, i], 1.0) * _MM for i in range(3))
        sb = (l2**2 - l1**2) / (4 * R * h)  # paper 1, eq. (6)
        ok_b = np.abs(sb) <= 1.0
        beta = np.arcsin(np.clip(sb, -1.0, 1.0))
        A = np.cos(beta)
        D0 = r * r + R * R + h * h + 2 * R * r - l3**2
        k1 = 4 * R * h * A / D0
        d = (l2**2 - l1**2) ** 2 if fix_square else (l2**2 - l1**2)  # paper 1, eq. (7) k2: square lost
        k2 = (d / (8 * R * R) + 2 * r * r + 2 * R * R + 2 * h * h * A * A - 2 * l3**2) / D0
        k3 = k1
        k4 = (r * r + R * R + h * h - 2 * R * r - l3**2) / D0
        nine = 9 * k1 * k2 * k3 if fix_resolvent else 9 * k2 * k3 * k4  # paper 1: printed 9 k2 k3 k4
        Q = (2 * k2**3 - nine + 27 * k3**2 + 27 * k1**2 * k4 - 72 * k2 * k4) / 54 + 0j
        P = (k2**2 - 3 * k1 * k3 + 12 * k4) / 9 + 0j
        Dd = np.sqrt(Q**2 - P**3)
        C = (Q + Dd) ** (1.0 / 3.0)  # principal complex cube root, as MATLAB's (.)^(1/3)
        G = C + P / C
        M = np.sqrt(k1**2 / 4 - 2 * k2 / 3 + G)
        S = k1**2 / 2 - 4 * k2 / 3 - G
        T = (-(k1**3) + 4 * k1 * k2 - 8 * k3) / (4 * M)
        roots = np.stack(
            [-k1 / 4 + sm * M / 2 + sr * np.sqrt(S + sm * T) / 2 for sm in (1, -1) for sr in (1, -1)], -1
        )
        real = np.abs(roots.imag) <= REAL_ROOT_TOL * (1 + np.abs(roots))
        a = roots.real
        alpha = 2 * np.arctan(a) if fix_arctan else np.arctan(2 * a)  # paper 1, eq. (7): arctan(2a)
        admissible = real & (np.abs(alpha) < np.pi / 2) & np.isfinite(alpha)
        K = (R * R + r * r + h * h) / _MM**2
        bq = beta[:, None]
        l3_fit = np.sqrt(
            np.maximum(K - 2 * leg.R * (leg.r * np.cos(alpha) - leg.h * np.cos(bq) * np.sin(alpha)), 0)
        )
        miss = np.where(admissible, np.abs(l3_fit - l3[:, None] / _MM), np.inf)
        pick = np.argmin(miss, axis=-1)
        alpha = np.take_along_axis(alpha, pick[:, None], -1)[:, 0]
        valid = ok_in & ok_b & np.any(admissible, -1)
        sa, ca, sbt, cbt = np.sin(alpha), np.cos(alpha), np.sin(beta), np.cos(beta)
        Lr, rr, hr = leg.R, leg.r, leg.h
        Kr = Lr * Lr + rr * rr + hr * hr
        fit = np.sqrt(
            np.maximum(
                np.stack(
                    [
                        Kr - 2 * Lr * (rr * cbt + hr * sbt),
                        Kr - 2 * Lr * (rr * cbt - hr * sbt),
                        Kr - 2 * Lr * (rr * ca - hr * cbt * sa),
                    ],
                    -1,
                ),
                0.0,
            )
        )
        resid = np.linalg.norm(fit - np.where(ok_in[:, None], L, 0.0), axis=-1)
    nan = np.nan
    return (
        np.where(valid, alpha, nan),
        np.where(valid, beta, nan),
        np.where(valid, resid, nan),
        valid,
    )
