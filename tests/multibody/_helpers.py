"""Shared helpers for the multibody tests: finite-difference references through assembly, MuJoCo closure."""

from __future__ import annotations

import numpy as np

from robomech import multibody as mb
from robomech.testing import numerical_jacobian


def fd_site_jacobian(mech, q, site):
    """Central differences of the site pose through forward kinematics (rows [ω; ṗ])."""
    qa = q[..., mech.tree.act_qadr]

    def pose(x):
        return mb.site_pose(mech, mb.forward_kinematics(mech, x, guess=q).q, site)

    T = pose(qa)
    dT = numerical_jacobian(pose, qa)  # (..., 4, 4, n)
    R = T[..., :3, :3]
    W = np.einsum("...abk,...cb->...kac", dT[..., :3, :3, :], R)  # dR R^T
    w = np.stack([W[..., 2, 1], W[..., 0, 2], W[..., 1, 0]], axis=-1)  # (..., n, 3)
    v = np.moveaxis(dT[..., :3, 3, :], -1, -2)
    return np.concatenate([w, v], axis=-1).swapaxes(-1, -2)


def fd_site_hessian(mech, q, site):
    qa = q[..., mech.tree.act_qadr]

    def jac(x):
        return mb.site_jacobian(mech, mb.forward_kinematics(mech, x, guess=q).q, site)

    return numerical_jacobian(jac, qa)


def mujoco_closure(mech_or_xml, qs):
    """Largest |efc_pos| over MuJoCo's equality rows for each configuration (MuJoCo's own residual)."""
    import mujoco

    xml = mech_or_xml if isinstance(mech_or_xml, str) else mb.to_mjcf(mech_or_xml)
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    out = []
    for q in np.reshape(qs, (-1, m.nq)):
        d.qpos[:] = q
        mujoco.mj_forward(m, d)
        eq = d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        out.append(np.max(np.abs(d.efc_pos[eq])) if np.any(eq) else 0.0)
    return np.array(out)


def urdf_rpy(r, p, y):
    """URDF ``rpy``: fixed-axis roll, pitch, yaw, ``R = Rz(y) Ry(p) Rx(r)``."""
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    Rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    Rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def axis_angle(a, t):
    """Rotation by ``t`` about the axis ``a`` (Rodrigues; ``a`` need not be a unit vector)."""
    a = np.asarray(a, float) / np.linalg.norm(a)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(t) * K + (1 - np.cos(t)) * K @ K
