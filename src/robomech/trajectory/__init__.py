"""Time profiles returning position, velocity and acceleration together, batched over time.

Every profile takes ``t (...)`` in seconds and broadcasts its parameters against it.  The normalised
polynomials are those of paper 2: eq. (53) uses the rest-to-rest quintic ``6s^5 - 15s^4 + 10s^3`` and
the swing sextic ``64(-s^6 + 3s^5 - 3s^4 + s^3)`` (0 -> 1 -> 0, peak at mid-period); eq. (51) is the
same pair written out for an unstated period T = 5 s (errata).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robomech._validation import as_array, broadcast_batch, check_positive

__all__ = ["Profile", "polynomial", "quintic", "sinusoid", "swing_sextic"]


@dataclass(frozen=True)
class Profile:
    """Position, velocity and acceleration of a profile, all of the same shape.

    Attributes
    ----------
    q : ndarray, shape (...)
        Position, in the unit of the profile's amplitude (m or rad, say).
    qd : ndarray, shape (...)
        Its time derivative (unit/s).
    qdd : ndarray, shape (...)
        Its second time derivative (unit/s²).
    """

    q: NDArray[np.float64]
    qd: NDArray[np.float64]
    qdd: NDArray[np.float64]

    def stack(self, *others: Profile) -> Profile:
        """Stack this and further profiles along a new last axis (e.g. one per joint).

        Parameters
        ----------
        *others : Profile
            Profiles of the same shape as this one.

        Returns
        -------
        Profile
            ``q``, ``qd``, ``qdd`` of shape ``(..., 1 + len(others))``.

        Raises
        ------
        ValueError
            If one of ``others`` is not a :class:`Profile` or has another shape.

        Examples
        --------
        >>> import numpy as np
        >>> t = np.linspace(0.0, 2.0, 5)                     # s
        >>> legs = quintic(t, 2.0).stack(swing_sextic(t, 2.0, 0.05))
        >>> legs.q.shape                                     # 5 times, 2 coordinates
        (5, 2)
        """
        ps = (self, *others)
        names = ["self", *(f"others[{i}]" for i in range(len(others)))]
        for name, p in zip(names, ps, strict=True):  # also Profile.stack(a, b) called on the class
            if not isinstance(p, Profile):
                raise ValueError(f"Expected {name} to be a Profile, got {type(p).__name__}.")
            if p.q.shape != self.q.shape:
                raise ValueError(
                    f"Expected {name} to have the shape {self.q.shape} of the first profile (the same "
                    f"times), got {p.q.shape}."
                )
        return Profile(*(np.stack([getattr(p, k) for p in ps], axis=-1) for k in ("q", "qd", "qdd")))


def polynomial(t: ArrayLike, coeffs: ArrayLike) -> Profile:
    """``sum_k c_k t^k`` with ``coeffs (..., K)`` lowest order first, and its two derivatives.

    Parameters
    ----------
    t : array_like, shape (...)
        Times (s).
    coeffs : array_like, shape (..., K)
        Coefficients ``c_0 .. c_{K-1}`` (unit/s^k), lowest order first, ``K >= 1``; the batch part
        broadcasts with ``t``.

    Returns
    -------
    Profile
        ``q = sum_k c_k t^k``, ``qd``, ``qdd`` of the broadcast batch shape.

    Examples
    --------
    >>> import numpy as np
    >>> p = polynomial(np.array([0.0, 1.0, 2.0]), [1.0, 0.0, 3.0])   # 1 + 3 t²
    >>> p.q, p.qd, p.qdd
    (array([ 1.,  4., 13.]), array([ 0.,  6., 12.]), array([6., 6., 6.]))
    """
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


def _normalised(t: ArrayLike, duration: float, coeffs: np.ndarray, scale: np.ndarray, name: str) -> Profile:
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


def quintic(t: ArrayLike, duration: float, start: ArrayLike = 0.0, end: ArrayLike = 1.0) -> Profile:
    """Rest-to-rest quintic from ``start`` to ``end`` over ``duration`` (held constant outside).

    ``q = start + (end - start)(6s^5 - 15s^4 + 10s^3)`` with ``s = t / duration`` (paper 2, eq. (53)):
    zero velocity and acceleration at both ends; before ``t = 0`` it holds ``start``, after
    ``duration`` it holds ``end``.

    Parameters
    ----------
    t : array_like, shape (...)
        Times (s).
    duration : float
        Length of the motion (s), ``> 0``.
    start, end : array_like, shape (...), optional
        End positions (any unit: m, rad); broadcast with ``t``.  Defaults 0 and 1 (the normalised
        profile).

    Returns
    -------
    Profile
        Position, velocity (unit/s) and acceleration (unit/s²) of the broadcast shape.

    Examples
    --------
    >>> import numpy as np
    >>> p = quintic(np.array([0.0, 0.5, 1.0]), 1.0, start=0.0, end=2.0)
    >>> p.q, p.qd                  # peak speed 15/8 (end - start) / duration at mid-time
    (array([0., 1., 2.]), array([0.  , 3.75, 0.  ]))
    """
    start = as_array(start, "start")
    end = as_array(end, "end")
    broadcast_batch((start, 0, "start"), (end, 0, "end"))
    p = _normalised(t, duration, _QUINTIC, end - start, "end")
    return Profile(start + p.q, p.qd, p.qdd)


def swing_sextic(t: ArrayLike, duration: float, height: ArrayLike = 1.0) -> Profile:
    """Swing sextic 0 -> ``height`` -> 0 over ``duration`` (paper 2, eq. (53) Z), at rest at both ends.

    ``q = height * 64(-s^6 + 3s^5 - 3s^4 + s^3)`` with ``s = t / duration``, peak ``height`` at
    ``s = 1/2``; 0 outside ``[0, duration]``.

    Parameters
    ----------
    t : array_like, shape (...)
        Times (s).
    duration : float
        Swing period (s), ``> 0``.
    height : array_like, shape (...), optional
        Peak value (m for a foot lift); broadcasts with ``t``.  Default 1.

    Returns
    -------
    Profile
        Position (m), velocity (m/s) and acceleration (m/s²).

    Examples
    --------
    >>> import numpy as np
    >>> p = swing_sextic(np.array([0.0, 1.0, 2.0]), 2.0, height=0.05)
    >>> p.q, p.qd, p.qdd           # lift 5 cm at mid-swing, where it decelerates at -0.3 m/s²
    (array([0.  , 0.05, 0.  ]), array([0., 0., 0.]), array([ 0. , -0.3,  0. ]))
    """
    return _normalised(t, duration, _SWING, as_array(height, "height"), "height")


def sinusoid(
    t: ArrayLike, amplitude: ArrayLike, frequency: ArrayLike, phase: ArrayLike = 0.0, offset: ArrayLike = 0.0
) -> Profile:
    """``offset + amplitude sin(2 pi f t + phase)`` (frequency in Hz).

    Parameters
    ----------
    t : array_like, shape (...)
        Times (s).
    amplitude : array_like, shape (...)
        Amplitude (any unit: m, rad).
    frequency : array_like, shape (...)
        Frequency ``f`` (Hz, cycles per second, not rad/s).
    phase : array_like, shape (...), optional
        Phase (rad), default 0.
    offset : array_like, shape (...), optional
        Mean value (the amplitude's unit), default 0.

    Returns
    -------
    Profile
        Position, velocity ``2 pi f amplitude cos(...)`` and acceleration; every argument broadcasts
        with ``t``.

    Examples
    --------
    >>> import numpy as np
    >>> p = sinusoid(np.array([0.0, 0.25]), amplitude=0.1, frequency=1.0)
    >>> p.q.round(6), p.qd.round(6)          # a quarter period: at the crest, at rest
    (array([0. , 0.1]), array([0.628319, 0.      ]))
    """
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
