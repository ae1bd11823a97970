"""Time profiles returning position, velocity and acceleration together, batched over time.

Every profile takes ``t (...)`` in seconds and broadcasts its parameters against it.  The normalised
polynomials are those of paper 2: eq. (53) uses the rest-to-rest quintic ``6s^5 - 15s^4 + 10s^3`` and
the swing sextic ``64(-s^6 + 3s^5 - 3s^4 + s^3)`` (0 -> 1 -> 0, peak at mid-period); eq. (51) is the
same pair written out for an unstated period T = 5 s (errata).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._validation import as_array, check_positive

__all__ = ["Profile", "polynomial", "quintic", "sinusoid", "swing_sextic"]


@dataclass(frozen=True)
class Profile:
    """Position, velocity and acceleration of a profile, all of the same shape."""

    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray

    def stack(self, *others: Profile) -> Profile:
        """Stack this and further profiles along a new last axis (e.g. one per joint)."""
        ps = (self, *others)
        return Profile(*(np.stack([getattr(p, k) for p in ps], axis=-1) for k in ("q", "qd", "qdd")))


def polynomial(t: object, coeffs: object) -> Profile:
    """``sum_k c_k t^k`` with ``coeffs (..., K)`` lowest order first, and its two derivatives."""
    t = as_array(t, "t")
    c = as_array(coeffs, "coeffs", (None,))
    k = np.arange(c.shape[-1])
    tt = t[..., None]
    pw = lambda e: np.where(e >= 0, tt ** np.maximum(e, 0), 0.0)  # noqa: E731
    q = np.sum(c * pw(k), axis=-1)
    qd = np.sum(c * k * pw(k - 1), axis=-1)
    qdd = np.sum(c * k * (k - 1) * pw(k - 2), axis=-1)
    return Profile(q, qd, qdd)


def _normalised(t: object, duration: float, coeffs: np.ndarray, scale: object) -> Profile:
    T = check_positive(duration, "duration")
    t = as_array(t, "t")
    s = np.clip(t / T, 0.0, 1.0)
    inside = (t >= 0.0) & (t <= T)
    p = polynomial(s, coeffs)
    a = np.asarray(scale, dtype=float)
    return Profile(a * p.q, a * np.where(inside, p.qd, 0.0) / T, a * np.where(inside, p.qdd, 0.0) / T**2)


_QUINTIC = np.array([0.0, 0.0, 0.0, 10.0, -15.0, 6.0])
_SWING = np.array([0.0, 0.0, 0.0, 64.0, -192.0, 192.0, -64.0])


def quintic(t: object, duration: float, start: object = 0.0, end: object = 1.0) -> Profile:
    """Rest-to-rest quintic from ``start`` to ``end`` over ``duration`` (held constant outside)."""
    start = np.asarray(start, dtype=float)
    p = _normalised(t, duration, _QUINTIC, np.asarray(end, dtype=float) - start)
    return Profile(start + p.q, p.qd, p.qdd)


def swing_sextic(t: object, duration: float, height: object = 1.0) -> Profile:
    """Swing sextic 0 -> ``height`` -> 0 over ``duration`` (paper 2, eq. (53) Z), at rest at both ends."""
    return _normalised(t, duration, _SWING, height)


def sinusoid(
    t: object, amplitude: object, frequency: object, phase: object = 0.0, offset: object = 0.0
) -> Profile:
    """``offset + amplitude sin(2 pi f t + phase)`` (frequency in Hz)."""
    t = as_array(t, "t")
    w = 2.0 * np.pi * np.asarray(frequency, dtype=float)
    arg = w * t + np.asarray(phase, dtype=float)
    a = np.asarray(amplitude, dtype=float)
    return Profile(
        np.asarray(offset, dtype=float) + a * np.sin(arg), a * w * np.cos(arg), -a * w * w * np.sin(arg)
    )
