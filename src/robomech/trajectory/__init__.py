"""Time profiles returning position, velocity and acceleration together, batched over time.

Every profile takes ``t (...)`` in seconds and broadcasts its parameters against it.  The normalised
polynomials are those of paper 2: eq. (53) uses the rest-to-rest quintic ``6s^5 - 15s^4 + 10s^3`` and
the swing sextic ``64(-s^6 + 3s^5 - 3s^4 + s^3)`` (0 -> 1 -> 0, peak at mid-period); eq. (51) is the
same pair written out for an unstated period T = 5 s (errata).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._validation import as_array, broadcast_batch, check_positive

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
    if c.shape[-1] == 0:
        raise ValueError("Expected coeffs to have shape (..., K) with K >= 1, got K = 0.")
    broadcast_batch((t, 0, "t"), (c, 1, "coeffs"))
    return _polynomial(t, c)


def _polynomial(t: np.ndarray, c: np.ndarray) -> Profile:
    k = np.arange(c.shape[-1])
    tt = t[..., None]
    pw = lambda e: np.where(e >= 0, tt ** np.maximum(e, 0), 0.0)  # noqa: E731
    q = np.sum(c * pw(k), axis=-1)
    qd = np.sum(c * k * pw(k - 1), axis=-1)
    qdd = np.sum(c * k * (k - 1) * pw(k - 2), axis=-1)
    return Profile(q, qd, qdd)


def _normalised(t: object, duration: float, coeffs: np.ndarray, scale: np.ndarray, name: str) -> Profile:
    T = check_positive(duration, "duration")
    t = as_array(t, "t")
    broadcast_batch((t, 0, "t"), (scale, 0, name))
    s = np.clip(t / T, 0.0, 1.0)
    inside = (t >= 0.0) & (t <= T)
    p = _polynomial(s, coeffs)
    a = scale
    return Profile(a * p.q, a * np.where(inside, p.qd, 0.0) / T, a * np.where(inside, p.qdd, 0.0) / T**2)


_QUINTIC = np.array([0.0, 0.0, 0.0, 10.0, -15.0, 6.0])
_SWING = np.array([0.0, 0.0, 0.0, 64.0, -192.0, 192.0, -64.0])


def quintic(t: object, duration: float, start: object = 0.0, end: object = 1.0) -> Profile:
    """Rest-to-rest quintic from ``start`` to ``end`` over ``duration`` (held constant outside)."""
    start = as_array(start, "start")
    end = as_array(end, "end")
    broadcast_batch((start, 0, "start"), (end, 0, "end"))
    p = _normalised(t, duration, _QUINTIC, end - start, "end")
    return Profile(start + p.q, p.qd, p.qdd)


def swing_sextic(t: object, duration: float, height: object = 1.0) -> Profile:
    """Swing sextic 0 -> ``height`` -> 0 over ``duration`` (paper 2, eq. (53) Z), at rest at both ends."""
    return _normalised(t, duration, _SWING, as_array(height, "height"), "height")


def sinusoid(
    t: object, amplitude: object, frequency: object, phase: object = 0.0, offset: object = 0.0
) -> Profile:
    """``offset + amplitude sin(2 pi f t + phase)`` (frequency in Hz)."""
    t = as_array(t, "t")
    a = as_array(amplitude, "amplitude")
    f = as_array(frequency, "frequency")
    ph = as_array(phase, "phase")
    off = as_array(offset, "offset")
    broadcast_batch(
        (t, 0, "t"), (a, 0, "amplitude"), (f, 0, "frequency"), (ph, 0, "phase"), (off, 0, "offset")
    )
    w = 2.0 * np.pi * f
    arg = w * t + ph
    return Profile(off + a * np.sin(arg), a * w * np.cos(arg), -a * w * w * np.sin(arg))
