"""The thigh as three UU chains (paper 2, eqs. (1)-(8)) assembled on the engine and checked by the
product of exponentials, and the shank's centred crank-slider (eq. (10), Fig. 4e)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech import multibody as mb
from robomech._batching import carries_failed_rows
from robomech._validation import as_array, broadcast_batch, check_params
from robomech.kinematics import poe_fk
from robomech.spatial import inverse_transform, log_se3, screw_from_axis

from ._multibody import chain_axes, thigh_mechanism
from ._params import OmniLeg

__all__ = [
    "ShankResult",
    "ThighClosure",
    "chain_screws",
    "shank_crank_slider",
    "shank_frames",
    "thigh_closure",
]

# The engine assembles to ~1e-16; 1e-14 (m or rad) is a few ulps of the O(0.1) pose entries, below
# which the product-of-exponentials closure residual is rounding noise.
CLOSURE_TOL = 1e-14
# Continuation stages from the home pose: fewer let the assembly from the home pose reach another branch
# beyond |α|, |β| = 90° (tests/mechanisms/omnileg/test_omnileg_beyond_90.py).
CLOSURE_STAGES = 6
# The knee plate "only translates" when its rotation differs from I by less than this (rad): a
# rounding-level bound for a converged closure.
TRANSLATION_ONLY_TOL = 1e-12


def chain_screws(leg: OmniLeg) -> tuple[np.ndarray, np.ndarray]:
    """Space screws of the three UU chains at the home pose and the knee plate's home pose (eqs. (1)-(7):
    chain 1's screws rotated by ``kR = Rz(-δ)``, δ = (k - 1) π/2, eq. (5) as printed).

    Parameters
    ----------
    leg : OmniLeg

    Returns
    -------
    S : ndarray, shape (3, 4, 6)
        Screw ``[ω; v]`` (space frame O0; v in m) of joint i of chain k as ``S[k, i]``.
    M : ndarray, shape (4, 4)
        Home pose ``T_O0 O0'`` of the knee plate (eq. (3)).
    """
    check_params(leg, OmniLeg, "leg")
    S = screw_from_axis(*chain_axes(leg.L1, leg.L3))
    M = np.eye(4)
    M[2, 3] = leg.L1  # eq. (3)
    return S, M


@dataclass(frozen=True)
class ThighClosure:
    """Closure of the thigh per sample (the result of :func:`thigh_closure`).

    Attributes
    ----------
    theta : ndarray, shape (..., 3, 4)
        Joint angles of the three chains (rad), ``theta[..., k, i] = θ_{k+1, i+1}``.
    T_knee : ndarray, shape (..., 4, 4)
        Knee-plate pose ``T_O0 O0'`` (m), chain 1's product of exponentials.
    residual, rotation_error : ndarray, shape (...)
        Largest component of the closure twists ``log(T_k T_1^-1)`` (rad or m); rotation angle of the knee
        plate (rad), zero for an exact closure.
    converged, translation_only : ndarray of bool, shape (...)
        ``residual <= 10 CLOSURE_TOL``; ``converged & (rotation_error <= TRANSLATION_ONLY_TOL)``.
    iterations : int
        The engine's assembly iterations (largest over the samples).
    knee : ndarray, shape (..., 3)
        Knee point O0' in O0 (m), the translation of ``T_knee``.
    """

    theta: np.ndarray
    T_knee: np.ndarray
    residual: np.ndarray
    converged: np.ndarray
    rotation_error: np.ndarray
    translation_only: np.ndarray
    iterations: int

    @property
    def knee(self) -> np.ndarray:
        return self.T_knee[..., :3, 3]


def _closure_residual(S: np.ndarray, M: np.ndarray, theta: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
    T = [poe_fk(M, S[k], theta[..., k, :]) for k in range(3)]
    T1_inv = inverse_transform(T[0])
    r = np.concatenate([log_se3(T[1] @ T1_inv), log_se3(T[2] @ T1_inv)], axis=-1)
    return r, T


@carries_failed_rows({"alpha": 0, "beta": 0})
def thigh_closure(leg: OmniLeg, alpha: object, beta: object) -> ThighClosure:
    """Solve the closure T1 = T2 = T3 (eq. (8)) for the passive joints, given α = θ21 and β = θ11.

    Assembled by :func:`robomech.multibody.forward_kinematics` from home in ``CLOSURE_STAGES`` stages.

    Parameters
    ----------
    leg : OmniLeg
    alpha, beta : array_like, shape (...)

    Returns
    -------
    :class:`ThighClosure`

    Examples
    --------
    >>> c = thigh_closure(OmniLeg.paper(), 0.3, -0.2)
    >>> bool(c.converged), bool(c.translation_only)
    (True, True)
    """
    check_params(leg, OmniLeg, "leg")
    a = as_array(alpha, "alpha")
    b = as_array(beta, "beta")
    batch = broadcast_batch((a, 0, "alpha"), (b, 0, "beta"))
    mech = thigh_mechanism(leg.L1, leg.L3)
    fk = mb.forward_kinematics(mech, np.stack(np.broadcast_arrays(a, b), -1), steps=CLOSURE_STAGES)
    S, M = chain_screws(leg)
    theta = np.zeros((*batch, 3, 4))
    for k, j in np.ndindex(3, 4):
        if k == 0 or j < 3:
            theta[..., k, j] = fk.q[..., mech.qpos_address(f"theta{k + 1}{j + 1}")]
    R_knee = mb.site_pose(mech, fk.q, "knee")[..., :3, :3]
    for k in (1, 2):  # the cut joint turns chain k's first three joints' rotation into the knee plate's
        R4 = np.swapaxes(poe_fk(np.eye(4), S[k, :3], theta[..., k, :3])[..., :3, :3], -1, -2) @ R_knee
        w = S[k, 3, :3]
        sin = 0.5 * (
            w[0] * (R4[..., 2, 1] - R4[..., 1, 2])
            + w[1] * (R4[..., 0, 2] - R4[..., 2, 0])
            + w[2] * (R4[..., 1, 0] - R4[..., 0, 1])
        )
        theta[..., k, 3] = np.arctan2(sin, 0.5 * (np.trace(R4, axis1=-2, axis2=-1) - 1.0))
    r, T = _closure_residual(S, M, theta)
    res = np.max(np.abs(r), axis=-1)
    R = T[0][..., :3, :3]
    cos_rot = np.clip((np.trace(R, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    # angle from the skew part is accurate for small rotations (arccos is not)
    skew = 0.5 * np.stack(
        [R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], -1
    )
    rot_err = np.arctan2(np.linalg.norm(skew, axis=-1), cos_rot)
    converged = res <= 10 * CLOSURE_TOL
    return ThighClosure(
        theta=theta,
        T_knee=T[0],
        residual=res,
        converged=converged,
        rotation_error=rot_err,
        translation_only=converged & (rot_err <= TRANSLATION_ONLY_TOL),
        iterations=int(np.max(fk.iterations, initial=0)),
    )


@dataclass(frozen=True)
class ShankResult:
    """Shank chains in the knee-plate frame O0' (axes parallel to O0), per sample.

    Attributes
    ----------
    C, D, E : ndarray, shape (..., 3, 3)
        Joint points of chains i = 1..3 as ``C[..., i - 1, :]`` (m, knee-plate frame).
    slider, coupler_angle, delta_L2 : ndarray, shape (...)
        Depth of the E plane below the C plane (m); coupler angle from Z0' (rad, opposite to the crank);
        shank shortening ``2 L4 - slider`` (m, eq. (10)).
    valid : ndarray of bool, shape (...)
        ``|γ| < π/2``; beyond it the chain folds flat and D, E, slider are NaN.
    """

    C: np.ndarray
    D: np.ndarray
    E: np.ndarray
    slider: np.ndarray
    coupler_angle: np.ndarray
    delta_L2: np.ndarray
    valid: np.ndarray


def shank_frames(leg: OmniLeg) -> np.ndarray:
    """Rotations ``S[i - 1]`` of the shank chain frames in the knee-plate frame: x radial along the C_i
    axis, z = Z0', chain i turned by ``shank_azimuth + 2π (i - 1)/3``.

    Parameters
    ----------
    leg : OmniLeg

    Returns
    -------
    ndarray, shape (3, 3, 3)
    """
    check_params(leg, OmniLeg, "leg")
    return _shank_frames(leg.shank_azimuth)


def _shank_frames(azimuth: float) -> np.ndarray:
    psi = azimuth + 2.0 * np.pi * np.arange(3) / 3.0
    c, s = np.cos(psi), np.sin(psi)
    S = np.zeros((3, 3, 3))
    S[:, 0, 0], S[:, 1, 0] = c, s
    S[:, 0, 1], S[:, 1, 1] = -s, c
    S[:, 2, 2] = 1.0
    return S


@carries_failed_rows({"gamma": 0})
def shank_crank_slider(leg: OmniLeg, gamma: object) -> ShankResult:
    """Centred crank-slider of each shank chain: ``s = r cos γ + sqrt(l² - (r sin γ)²)``, r = l = L4,
    i.e. 2 L4 cos γ (eq. (10)).

    Parameters
    ----------
    leg : OmniLeg
    gamma : array_like, shape (...)
        Crank angle γ (rad); samples with ``|γ| >= π/2`` are flagged, not raised.

    Returns
    -------
    :class:`ShankResult`
    """
    check_params(leg, OmniLeg, "leg")
    g_in = as_array(gamma, "gamma")
    valid = np.abs(g_in) < 0.5 * np.pi  # the chain folds flat at |γ| = 90°: outside, flagged and NaN
    g = np.where(valid, g_in, 0.0)
    r = l = leg.L4
    slider = np.where(valid, r * np.cos(g) + np.sqrt(l * l - (r * np.sin(g)) ** 2), np.nan)
    coupler = np.where(valid, -np.arcsin(r * np.sin(g) / l), np.nan)
    S = shank_frames(leg)
    c0 = np.array([leg.shank_radius, 0.0, leg.knee_to_crank])
    C = np.broadcast_to(np.einsum("kij,j->ki", S, c0), (*g.shape, 3, 3))
    crank_dir = np.stack([np.zeros_like(g), -np.sin(g), np.cos(g)], axis=-1)  # Rx(γ) e_z in the chain frame
    D = C + leg.L4 * np.einsum("kij,...j->...ki", S, crank_dir)
    D = np.where(valid[..., None, None], D, np.nan)
    E = C + slider[..., None, None] * np.array([0.0, 0.0, 1.0])
    return ShankResult(
        C=C, D=D, E=E, slider=slider, coupler_angle=coupler, delta_L2=2.0 * leg.L4 - slider, valid=valid
    )
