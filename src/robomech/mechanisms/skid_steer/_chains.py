"""Wheel chains of the robot: contact frames (Sheth–Uicker) and their Jacobians, batched.  Configuration
``config (..., 8)`` = ``[θ1, θ01_1, θ02_1, s1, θ2, θ01_2, θ02_2, s2]`` (side 1 right, side 2 left; the
joints and contact frames: ``docs/mechanisms/skid_steer.md``, "Frames and sign conventions")."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from robomech._batching import carries_failed_rows, chunked
from robomech._validation import as_array, check_params

from ._params import ExplorationRobot

__all__ = [
    "CONFIG_SIZE",
    "N_WHEELS",
    "SIDE_JOINTS",
    "WHEELS",
    "WHEEL_SIDE",
    "contact_frames",
    "wheel_jacobians",
]

CONFIG_SIZE = 8
N_WHEELS = 6
# Wheel order of the paper's measured vector (eq. (5)): right front road wheel A_F1, right rear road
# wheel A_H1, right rear wheel P1, then the same on the left side.
WHEELS = (
    "front_road_right",
    "rear_road_right",
    "rear_right",
    "front_road_left",
    "rear_road_left",
    "rear_left",
)
WHEEL_SIDE = (0, 0, 0, 1, 1, 1)
SIDE_JOINTS = ("rocker", "bogie", "side_link", "rear_slide")
# Samples per block for the batched kernels: a block's outputs (~1 kB per sample) stay in the 2 MB L2
# cache while the kernel writes them element by element; measured ~2x faster than one pass at 1e6.
CHUNK = 2048
# Lateral sign of each side's wheel plane: side 1 (right) at y = -b, side 2 (left) at y = +b.
_SIDE_SIGN = (-1.0, 1.0)


def _rot_xz(c: np.ndarray, s: np.ndarray, x: np.ndarray | float, z: np.ndarray | float):
    """``rot_y(a) @ (x, 0, z)`` with ``c = cos a``, ``s = sin a``: returns the (x, z) parts."""
    return c * x + s * z, -s * x + c * z


def side_points(robot: ExplorationRobot, q: np.ndarray) -> dict[str, np.ndarray]:
    """Planar (x, z) geometry ``(..., 2)`` of one side at ``q (..., 4)`` = ``(θ, θ01, θ02, s)``: points ``R``,
    ``H``, ``LF``, ``LH``, contacts ``AF``, ``AH``, ``P``; the angles ``alpha_road``, ``alpha_rear``."""
    check_params(robot, ExplorationRobot, "robot")
    th, t1, t2, s = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    c0, s0 = np.cos(th), np.sin(th)
    a1 = th + t1
    c1, s1 = np.cos(a1), np.sin(a1)
    a2 = a1 + t2
    c2, s2 = np.cos(a2), np.sin(a2)
    zero = np.zeros_like(th)
    # Rear wheel: rocker frame offset (-rear_arm, 0, -(s + r_w)).
    px, pz = _rot_xz(c0, s0, -robot.rear_arm_length, -(s + robot.rear_wheel_radius))
    hx, hz = _rot_xz(c0, s0, robot.bogie_hinge_x, -robot.bogie_hinge_drop)
    lfx, lfz = _rot_xz(c1, s1, robot.side_link_hinge_offset, 0.0)
    # Rear side-link hinge: assumed symmetric to the front one (the paper prints only L^H_{LF1}).
    lhx, lhz = -lfx, -lfz
    lfx, lfz, lhx, lhz = hx + lfx, hz + lfz, hx + lhx, hz + lhz
    dx, dz = _rot_xz(
        c2,
        s2,
        -robot.side_link_length * np.sin(robot.side_link_rake),
        -robot.side_link_length * np.cos(robot.side_link_rake) - robot.road_wheel_radius,
    )
    st = lambda x, z: np.stack([x + zero, z + zero], axis=-1)  # noqa: E731
    return {
        "R": st(0.0, 0.0),
        "H": st(hx, hz),
        "LF": st(lfx, lfz),
        "LH": st(lhx, lhz),
        "AF": st(lfx + dx, lfz + dz),
        "AH": st(lhx + dx, lhz + dz),
        "P": st(px, pz),
        "alpha_road": a2,
        "alpha_rear": th + zero,
    }


def _check_config(config: ArrayLike) -> np.ndarray:
    return as_array(config, "config", (CONFIG_SIZE,))


def _blocked(kernel, q: np.ndarray, tail: tuple[int, ...]) -> np.ndarray:
    """Apply ``kernel (n, 8) -> (n, *tail)`` block by block over the flattened batch of ``q``."""
    qf = q.reshape(-1, CONFIG_SIZE)
    return chunked(lambda s: kernel(qf[s]), qf.shape[0], CHUNK).reshape(*q.shape[:-1], *tail)


@carries_failed_rows({"config": 1})
def contact_frames(robot: ExplorationRobot, config: ArrayLike) -> np.ndarray:
    """Poses ``T_BP (..., 6, 4, 4)`` of the six contact frames in the body frame, order ``WHEELS``.

    Parameters
    ----------
    robot : ExplorationRobot
    config : array_like, shape (..., 8)
        Joint configuration: per side ``SIDE_JOINTS`` (rad, m); the same argument in every function of
        the package.
    """
    check_params(robot, ExplorationRobot, "robot")
    q = _check_config(config)
    return _blocked(lambda qc: _contact_frames(robot, qc), q, (N_WHEELS, 4, 4))


def _contact_frames(robot: ExplorationRobot, q: np.ndarray) -> np.ndarray:
    T = np.zeros((*q.shape[:-1], N_WHEELS, 4, 4))
    for side in range(2):
        g = side_points(robot, q[..., 4 * side : 4 * side + 4])
        y = _SIDE_SIGN[side] * robot.rocker_lateral_offset
        for k, (pt, al) in enumerate((("AF", "alpha_road"), ("AH", "alpha_road"), ("P", "alpha_rear"))):
            w = 3 * side + k
            c, s = np.cos(g[al]), np.sin(g[al])
            T[..., w, 0, 0] = c
            T[..., w, 0, 2] = s
            T[..., w, 2, 0] = -s
            T[..., w, 2, 2] = c
            T[..., w, 1, 1] = 1.0
            T[..., w, 0, 3] = g[pt][..., 0]
            T[..., w, 1, 3] = y
            T[..., w, 2, 3] = g[pt][..., 1]
            T[..., w, 3, 3] = 1.0
    return T


def _linear_columns(robot: ExplorationRobot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Contact positions ``p (..., 6, 3)``, contact angles ``alpha (..., 6)`` and the chain's (x, z)
    velocity columns ``G (..., 6, 2, 4)``: the velocity of contact w relative to B due to its side's
    joint rates ``(θ̇, θ̇01, θ̇02, ṡ)`` is ``(G[w, 0] @ q̇, 0, G[w, 1] @ q̇)`` (a revolute joint about y
    through ``o`` moves ``p`` at ``y × (p - o) = (p_z - o_z, 0, -(p_x - o_x))``)."""
    batch = q.shape[:-1]
    p = np.zeros((*batch, N_WHEELS, 3))
    alpha = np.zeros((*batch, N_WHEELS))
    G = np.zeros((*batch, N_WHEELS, 2, 4))
    for side in range(2):
        qs = q[..., 4 * side : 4 * side + 4]
        g = side_points(robot, qs)
        y = _SIDE_SIGN[side] * robot.rocker_lateral_offset
        for k, (pt, hinge) in enumerate((("AF", "LF"), ("AH", "LH"), ("P", None))):
            w = 3 * side + k
            c = g[pt]
            p[..., w, 0], p[..., w, 1], p[..., w, 2] = c[..., 0], y, c[..., 1]
            # rocker (θ): axis through R = (0, 0) in the side plane
            G[..., w, 0, 0] = c[..., 1]
            G[..., w, 1, 0] = -c[..., 0]
            if hinge is None:
                alpha[..., w] = g["alpha_rear"]
                # rear slide: along the rocker's -z, i.e. -(sin θ, 0, cos θ)
                G[..., w, 0, 3] = -np.sin(qs[..., 0])
                G[..., w, 1, 3] = -np.cos(qs[..., 0])
            else:
                alpha[..., w] = g["alpha_road"]
                d = c - g["H"]
                G[..., w, 0, 1] = d[..., 1]
                G[..., w, 1, 1] = -d[..., 0]
                d = c - g[hinge]
                G[..., w, 0, 2] = d[..., 1]
                G[..., w, 1, 2] = -d[..., 0]
    return p, alpha, G


@carries_failed_rows({"config": 1})
def wheel_jacobians(robot: ExplorationRobot, config: ArrayLike) -> np.ndarray:
    """Space Jacobians ``(..., 6, 6, 4)`` of the contact frames relative to the body at ``config (..., 8)``.

    ``J[..., w, :, j]`` is the twist ``[ω; v]`` (in B, ``v`` the velocity of the point at B's origin)
    of contact frame ``w`` (``WHEELS`` order) relative to the body per unit rate of joint ``j`` of its
    side (``SIDE_JOINTS``); joints outside the wheel's chain give zero columns.

    Returns
    -------
    ndarray, shape (..., 6, 6, 4)
    """
    check_params(robot, ExplorationRobot, "robot")
    q = _check_config(config)
    return _blocked(lambda qc: _wheel_jacobians(robot, qc), q, (N_WHEELS, 6, 4))


def _wheel_jacobians(robot: ExplorationRobot, q: np.ndarray) -> np.ndarray:
    p, _, G = _linear_columns(robot, q)
    J = np.zeros((*q.shape[:-1], N_WHEELS, 6, 4))
    # Angular part: every revolute joint of the chain turns about y.
    for w in range(N_WHEELS):
        joints = (0, 3) if w % 3 == 2 else (0, 1, 2)
        for j in joints:
            if j != 3:
                J[..., w, 1, j] = 1.0
    # Velocity of the point at B's origin = velocity of the contact point minus ω × p.
    vx, vz = G[..., 0, :], G[..., 1, :]
    wy = J[..., 1, :]
    px, py, pz = p[..., 0:1], p[..., 1:2], p[..., 2:3]
    # (0, wy, 0) × (px, py, pz) = (wy pz, 0, -wy px)
    J[..., 3, :] = vx - wy * pz
    J[..., 4, :] = 0.0 * py
    J[..., 5, :] = vz + wy * px
    return J
