"""A PUMA-like URDF with what the UR5-like arm of ``test_urdf.py`` lacks — joint axes off the link
axes, ``continuous`` joints (Pinocchio's (cos, sin) coordinates), inertials rotated by ``rpy``, a tool
link *with mass* on a fixed joint and a second fixed link after it — against MuJoCo on an MJCF twin
written here from the same numbers (body ``quat`` from the URDF ``rpy``, ``fullinertia = R I R^T``),
against Pinocchio's own URDF parser, and its link frames against the URDF's transform chain composed
here.  Batches of 1 and 300."""

from __future__ import annotations

import numpy as np
import pytest

from robomech import multibody as mb

from ._helpers import axis_angle as _axis_angle
from ._helpers import urdf_rpy as _rpy

mujoco = pytest.importorskip("mujoco")

TOL_REL = 1e-9  # the acceptance bound for dynamics against MuJoCo / Pinocchio
TOL_POSE = 1e-12  # link frames of a ~1 m arm: products of a dozen 4x4 matrices (m, and rotation entries)
TOL_FD_REL = 1e-9  # forward dynamics: the 6x6 mass matrix's conditioning on top of the forces' rounding
HALF_PI = 1.5707963267948966


def _unit(v):
    v = np.asarray(v, float)
    return tuple(v / np.linalg.norm(v))


# joint, parent, child, origin xyz, rpy, axis, mass, com xyz, com rpy, (ixx iyy izz ixy ixz iyz)
MOVING = [
    ("j1", "base_link", "link1", (0, 0, 0.40), (0, 0, 0.3), _unit((0, 0, 1)), 4.0, (0.01, -0.02, -0.08),
     (0.1, 0.2, 0.3), (0.05, 0.04, 0.03, 0.002, -0.001, 0.003)),
    ("j2", "link1", "link2", (0.05, 0.12, 0.0), (HALF_PI, 0, 0), _unit((0, 0, 1)), 6.0, (0.2, 0.0, 0.03),
     (0, 0.1, -0.2), (0.02, 0.15, 0.14, 0.001, 0.002, -0.0015)),
    ("j3", "link2", "link3", (0.43, 0.0, -0.03), (0, 0, -0.4), _unit((0, 0, 1)), 3.0, (0.02, -0.15, 0.01),
     (0.3, -0.1, 0.0), (0.06, 0.01, 0.055, 0.003, 0.0, 0.001)),
    ("j4", "link3", "link4", (0.0, -0.43, 0.02), (-HALF_PI, 0.2, 0), _unit((0.1, 0.2, 1)), 1.2,
     (0.0, 0.01, -0.05), (0, 0, 0.7), (0.004, 0.0045, 0.002, 0.0002, 0.0001, -0.0003)),
    ("j5", "link4", "link5", (0.0, 0.0, 0.0), (HALF_PI, 0, 0), _unit((0, 0, 1)), 0.8, (0.0, 0.0, 0.02),
     (0.2, 0, 0), (0.0012, 0.0011, 0.0009, 0, 0.0001, 0)),
    ("j6", "link5", "link6", (0.0, -0.06, 0.0), (-HALF_PI, 0, 0.1), _unit((0, -0.3, 1)), 0.3,
     (0.0, 0.0, 0.03), (0, 0, 0), (0.0003, 0.0003, 0.0002, 0, 0, 0)),
]  # fmt: skip
FIXED = [
    ("tool_joint", "link6", "tool0", (0.01, 0.0, 0.09), (0.0, 0.3, HALF_PI), 0.25, (0.0, 0.0, 0.03),
     (0.2, 0.1, 0.0), (0.0004, 0.0005, 0.0003, 0.00001, 0, 0)),
    ("flange_joint", "tool0", "flange", (0.0, 0.02, 0.05), (0.5, 0.0, 0.0), None, None, None, None),
]  # fmt: skip
CONTINUOUS = ("j1", "j6")


def _quat(R):
    """[w, x, y, z] of a rotation matrix (Shepperd's branch on the largest diagonal term)."""
    t = np.trace(R)
    if t > 0:
        s = 2 * np.sqrt(1 + t)
        return np.array([s / 4, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s])
    i = int(np.argmax(np.diag(R)))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2 * np.sqrt(1 + R[i, i] - R[j, j] - R[k, k])
    q = np.empty(4)
    q[0], q[1 + i] = (R[k, j] - R[j, k]) / s, s / 4
    q[1 + j], q[1 + k] = (R[j, i] + R[i, j]) / s, (R[k, i] + R[i, k]) / s
    return q


def _f(v):
    return " ".join(repr(float(x)) for x in v)


def _tensor(I):
    ixx, iyy, izz, ixy, ixz, iyz = I
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])


def _urdf() -> str:
    def inertial(m, com, crpy, I):
        if m is None:
            return ""
        ixx, iyy, izz, ixy, ixz, iyz = I
        return (
            f'<inertial><origin xyz="{_f(com)}" rpy="{_f(crpy)}"/><mass value="{m!r}"/><inertia '
            f'ixx="{ixx!r}" iyy="{iyy!r}" izz="{izz!r}" ixy="{ixy!r}" ixz="{ixz!r}" iyz="{iyz!r}"/>'
            "</inertial>"
        )

    out = ['<robot name="puma_like">', '<link name="base_link"/>']
    out += [f'<link name="{e[2]}">{inertial(*e[6:])}</link>' for e in MOVING]
    out += [f'<link name="{e[2]}">{inertial(*e[5:])}</link>' for e in FIXED]
    for n, p, c, xyz, rpy, ax, *_ in MOVING:
        kind = "continuous" if n in CONTINUOUS else "revolute"
        limit = "" if n in CONTINUOUS else '<limit lower="-3" upper="3" effort="100" velocity="3"/>'
        out.append(
            f'<joint name="{n}" type="{kind}"><parent link="{p}"/><child link="{c}"/>'
            f'<origin xyz="{_f(xyz)}" rpy="{_f(rpy)}"/><axis xyz="{_f(ax)}"/>{limit}</joint>'
        )
    for n, p, c, xyz, rpy, *_ in FIXED:
        out.append(
            f'<joint name="{n}" type="fixed"><parent link="{p}"/><child link="{c}"/>'
            f'<origin xyz="{_f(xyz)}" rpy="{_f(rpy)}"/></joint>'
        )
    return "\n".join([*out, "</robot>"])


def _mjcf_twin() -> str:
    """The same arm in MJCF, converted here: body pos/quat = joint origin, inertia rotated to the body."""
    children: dict[str, list] = {}
    for e in MOVING:
        children.setdefault(e[1], []).append((e[0], e[2], e[3], e[4], e[5], *e[6:]))
    for e in FIXED:
        children.setdefault(e[1], []).append((None, e[2], e[3], e[4], None, *e[5:]))

    def body(joint, name, xyz, rpy, axis, m, com, crpy, I):
        s = f'<body name="{name}" pos="{_f(xyz)}" quat="{_f(_quat(_rpy(*rpy)))}">'
        if m is not None:
            R = _rpy(*crpy)
            Ib = R @ _tensor(I) @ R.T
            full = [*np.diag(Ib), Ib[0, 1], Ib[0, 2], Ib[1, 2]]
            s += f'<inertial pos="{_f(com)}" mass="{m!r}" fullinertia="{_f(full)}"/>'
        if joint is not None:
            s += f'<joint name="{joint}" type="hinge" axis="{_f(axis)}"/>'
        return s + "".join(body(*ch) for ch in children.get(name, [])) + "</body>"

    motors = "".join(f'<motor joint="{e[0]}"/>' for e in MOVING)
    return (
        f'<mujoco model="puma_like_twin"><option gravity="0 0 -9.81"/><worldbody>'
        f"{''.join(body(*ch) for ch in children['base_link'])}</worldbody>"
        f"<actuator>{motors}</actuator></mujoco>"
    )


def _chain(q, link):
    """World pose of ``link``: each joint's origin (xyz, rpy) then its rotation about its axis."""
    T = {"base_link": np.eye(4)}
    for k, (_, p, c, xyz, rpy, ax, *_) in enumerate(MOVING):
        A, B = np.eye(4), np.eye(4)
        A[:3, :3], A[:3, 3] = _rpy(*rpy), xyz
        B[:3, :3] = _axis_angle(ax, q[k])
        T[c] = T[p] @ A @ B
    for _, p, c, xyz, rpy, *_ in FIXED:
        A = np.eye(4)
        A[:3, :3], A[:3, 3] = _rpy(*rpy), xyz
        T[c] = T[p] @ A
    return T[link]


def _rel(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - b)) / np.max(np.abs(b)))


@pytest.fixture(scope="module")
def arm():
    return mb.from_urdf(_urdf())


@pytest.fixture(scope="module")
def states():
    rng = np.random.default_rng(24)
    n = 300
    return (
        rng.uniform(-np.pi, np.pi, (n, 6)),
        rng.normal(0, 2, (n, 6)),
        rng.normal(0, 5, (n, 6)),
        rng.normal(0, 20, (n, 6)),
    )


def test_every_link_frame_is_the_urdf_chain(arm, states):
    q = states[0]
    assert arm.actuated == tuple(e[0] for e in MOVING)
    for link in ("link2", "link6", "tool0", "flange"):
        T = mb.site_pose(arm, q, link)
        expected = np.array([_chain(qi, link) for qi in q])
        assert np.abs(T - expected).max() < TOL_POSE, link


@pytest.mark.parametrize("n", [1, 300])
def test_dynamics_equal_mujoco_on_the_mjcf_twin(arm, states, n):
    q, qd, qdd, tau = (s[:n] for s in states)
    m = mujoco.MjModel.from_xml_string(_mjcf_twin())
    d = mujoco.MjData(m)
    rne, M, acc = np.zeros((n, 6)), np.zeros((n, 6, 6)), np.zeros((n, 6))
    for i in range(n):
        d.qpos[:], d.qvel[:], d.qacc[:] = q[i], qd[i], qdd[i]
        mujoco.mj_fwdPosition(m, d)
        mujoco.mj_fwdVelocity(m, d)
        mujoco.mj_rne(m, d, 1, rne[i])
        mujoco.mj_fullM(m, d, M[i])
        d.ctrl[:] = tau[i]
        mujoco.mj_forward(m, d)
        acc[i] = d.qacc
    assert _rel(mb.generalized_forces(arm, q, qd, qdd), rne) < TOL_REL
    assert _rel(mb.mass_matrix(arm, q), M) < TOL_REL
    inv = mb.inverse_dynamics(arm, q, qd, qdd)
    assert inv.valid.all() and _rel(inv.tau, rne) < TOL_REL
    fwd = mb.forward_dynamics(arm, q, qd, tau)
    assert fwd.valid.all() and _rel(fwd.qdd_act, acc) < TOL_FD_REL
    # the batch of n equals its last sample alone, bit for bit
    last = mb.generalized_forces(arm, q[-1:], qd[-1:], qdd[-1:])
    np.testing.assert_array_equal(last[0], mb.generalized_forces(arm, q, qd, qdd)[-1])


def test_dynamics_and_frames_equal_pinocchio(arm, states):
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromXML(_urdf())
    data = model.createData()
    q, qd, qdd, _ = states

    def pin_q(qi):  # continuous joints are (cos, sin) in Pinocchio
        out = []
        for j in range(1, model.njoints):
            out += [np.cos(qi[j - 1]), np.sin(qi[j - 1])] if model.joints[j].nq == 2 else [qi[j - 1]]
        return np.array(out)

    assert model.nq == 8  # two continuous joints
    tau = np.array([pin.rnea(model, data, pin_q(q[i]), qd[i], qdd[i]) for i in range(len(q))])
    M = np.array([pin.crba(model, data, pin_q(q[i])) for i in range(len(q))])
    M = np.triu(M) + np.swapaxes(np.triu(M, 1), -1, -2)  # crba fills the upper triangle
    assert _rel(mb.generalized_forces(arm, q, qd, qdd), tau) < TOL_REL
    assert _rel(mb.mass_matrix(arm, q), M) < TOL_REL
    for i in range(0, len(q), 50):
        pin.framesForwardKinematics(model, data, pin_q(q[i]))
        for link in ("tool0", "flange"):
            T = data.oMf[model.getFrameId(link)].homogeneous
            assert np.abs(mb.site_pose(arm, q[i : i + 1], link)[0] - T).max() < TOL_POSE
