"""The motions of paper 1, Section 6 (shared by the study, the verification and the benchmarks)."""

from __future__ import annotations

import numpy as np

from robomech._validation import as_array, check_choice, check_real
from robomech.trajectory import quintic, sinusoid

__all__ = ["AMPLITUDE", "FREQUENCY", "fig5_motion", "sway"]

# Section 6.1: "amplitude pi/3 and frequency 0.05 Hz" about the X or the Y axis.
AMPLITUDE = np.pi / 3
FREQUENCY = 0.05
# Fig. 5(b): "from beta = pi/3 to pi/6 in 5 s"; the profile is not printed: a rest-to-rest quintic.
FIG5B_TRANSITION = 5.0


def sway(t: object, about: str, beta0: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Section 6.1 sway ``AMPLITUDE sin(2 pi FREQUENCY t)`` about X (alpha; beta = ``beta0``) or Y (beta).

    Parameters
    ----------
    t : array_like, shape (...)
        Times (s).
    about : {"x", "y"}
    beta0 : float, optional
        The constant beta (rad) of a sway about X.

    Returns
    -------
    q, qd, qdd : ndarray, shape (..., 2)
        Platform angles ``(alpha, beta)`` (rad), their rates and accelerations.
    """
    check_choice(about, "about", ("x", "y"))
    beta0 = check_real(beta0, "beta0")
    t = as_array(t, "t")
    p = sinusoid(t, AMPLITUDE, FREQUENCY)
    z = np.zeros_like(t)
    if about == "x":
        return np.stack([p.q, z + beta0], -1), np.stack([p.qd, z], -1), np.stack([p.qdd, z], -1)
    return np.stack([z, p.q], -1), np.stack([z, p.qd], -1), np.stack([z, p.qdd], -1)


def fig5_motion(case: str, t: object) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The motions of Fig. 5 (docs/mechanisms/spherical_leg.md, assumption 7).

    ``"a"``: sway about X at beta = pi/3; ``"b"``: beta pi/3 -> pi/6 in 5 s, then a sway about X from
    alpha = 0; ``"c"``: sway about X at beta = 0 (assumed: the print does not state beta).

    Parameters
    ----------
    case : {"a", "b", "c"}
    t : array_like, shape (...)
        Times (s).

    Returns
    -------
    q, qd, qdd : ndarray, shape (..., 2)
        As :func:`sway`.

    Examples
    --------
    >>> from robomech.mechanisms import spherical_leg as sl
    >>> q, qd, qdd = sl.fig5_motion("b", [0.0, 5.0])
    >>> q.round(6)
    array([[0.      , 1.047198],
           [0.      , 0.523599]])
    """
    check_choice(case, "case", ("a", "b", "c"))
    t = as_array(t, "t")
    if case == "a":
        return sway(t, "x", np.pi / 3)
    if case == "c":
        return sway(t, "x", 0.0)
    tr = quintic(t, FIG5B_TRANSITION, np.pi / 3, np.pi / 6)
    sw = sinusoid(np.clip(t - FIG5B_TRANSITION, 0.0, None), AMPLITUDE, FREQUENCY)
    on = t >= FIG5B_TRANSITION
    return (
        np.stack([np.where(on, sw.q, 0.0), tr.q], -1),
        np.stack([np.where(on, sw.qd, 0.0), tr.qd], -1),
        np.stack([np.where(on, sw.qdd, 0.0), tr.qdd], -1),
    )
