"""Paper 1's forward solution exactly as printed (eqs. (6)-(7), misprints included, in mm), for a report to
put beside the exact solution; the printed formulas: docs/mechanisms/spherical_leg.md, "Findings"."""

from __future__ import annotations

import numpy as np

from ._kinematics import _squared_length_columns

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
        sq = _squared_length_columns(leg, np.sin(alpha), np.cos(alpha), np.sin(beta), np.cos(beta))
        fit = np.sqrt(np.maximum(np.stack(sq, -1), 0.0))
        resid = np.linalg.norm(fit - np.where(ok_in[:, None], L, 0.0), axis=-1)
    nan = np.nan
    return (
        np.where(valid, alpha, nan),
        np.where(valid, beta, nan),
        np.where(valid, resid, nan),
        valid,
    )
