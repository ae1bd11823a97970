"""Closed chains typed in MJCF as a user would (``connect`` between two sites, a five-bar open at its
``qpos0``, an Agile-Eye-type spherical wrist, a Sarrus linkage typed slightly off its closure): kinematics
against closed forms written here, and inverse and forward dynamics against a reference built from
MuJoCo alone — its site Jacobians (``mj_jacSite``) and their rates (``mj_jacDot``) give the closure
Jacobian ``K`` and ``Kdot qd``, its ``mj_rne`` the tree's generalized forces ``f``, and

    G = [I; -K_p^+ K_a],   qd = G qd_act,   qdd_p = -K_p^+ (K_a qdd_act + Kdot qd),   tau = G^T f,

the virtual-work projection of the tree's forces onto the actuated joints (no robomech quantity in it).
Batches of 1 and 300, and the batch of 300 equal to its samples one at a time."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robomech import multibody as mb

mujoco = pytest.importorskip("mujoco")

# Independent double-precision formulations of ~1 m, ~1 kg linkages: a few ulps of the largest term.
TOL_REL = 1e-9  # the acceptance bound against MuJoCo
# Closed-form positions and angles against the assembled configurations (m, rad).
TOL_CLOSED_FORM = 1e-12
# Forward dynamics under the reference torques: the constrained mass matrix's conditioning (~1e3) on top.
TOL_FD_REL = 1e-9

D, L1, L2, L3, L4 = 0.5, 0.4, 0.55, 0.35, 0.5

# every link along +x at qpos0: the tips P and Q are 1.8 - 0.5 - 0.95 = 0.35 m apart there
FIVE_BAR = f"""<mujoco model="five_bar_typed_along_x">
  <option gravity="0 -9.81 0"/>
  <worldbody>
    <body name="p1"><joint name="t1" axis="0 0 1"/>
      <inertial pos="{L1 / 2} 0.01 0" mass="0.8" diaginertia="0.001 0.012 0.012"/>
      <body name="d1" pos="{L1} 0 0"><joint name="t2" axis="0 0 1"/>
        <inertial pos="{L2 / 2} -0.01 0" mass="0.6" diaginertia="0.001 0.015 0.015"/>
        <site name="P" pos="{L2} 0 0"/></body></body>
    <body name="p2" pos="{D} 0 0"><joint name="t3" axis="0 0 1"/>
      <inertial pos="{L3 / 2} 0 0" mass="0.7" diaginertia="0.001 0.008 0.008"/>
      <body name="d2" pos="{L3} 0 0"><joint name="t4" axis="0 0 1"/>
        <inertial pos="{L4 / 2} 0 0" mass="0.5" diaginertia="0.001 0.01 0.01"/>
        <site name="Q" pos="{L4} 0 0"/></body></body>
  </worldbody>
  <equality><connect site1="P" site2="Q"/></equality>
  <actuator><motor joint="t1"/><motor joint="t3"/></actuator>
</mujoco>"""

# Agile-Eye type: every axis through the origin; leg i: base axis e_i, elbow e_(i+1), platform e_(i+2)
AGILE_EYE = (Path(__file__).parent / "data" / "agile_eye.xml").read_text()  # robomech verify reads it too


def _sarrus(a: float = 0.3, b: float = 0.25, alpha: float = np.deg2rad(40)) -> str:
    """Leg A (hinges about x, links a) carries the top plate; leg B (hinges about y, links b) meets it
    in a revolute closure (two connects on its axis).  Leg B's angle is typed to two decimals, so the
    description is 1e-3 m off its closure at qpos0."""
    beta = round(float(np.arccos(a * np.cos(alpha) / b)), 2)
    sa, ca, sb, cb = np.sin(alpha), np.cos(alpha), np.sin(beta), np.cos(beta)
    return f"""<mujoco model="sarrus"><worldbody>
    <body name="A1"><joint name="pa" axis="1 0 0"/>
      <inertial pos="0 {a * sa / 2} {a * ca / 2}" mass="0.4" diaginertia="0.003 0.003 0.0002"/>
      <body name="A2" pos="0 {a * sa} {a * ca}"><joint name="ka" axis="1 0 0"/>
        <inertial pos="0 {-a * sa / 2} {a * ca / 2}" mass="0.4" diaginertia="0.003 0.003 0.0002"/>
        <body name="top" pos="0 {-a * sa} {a * ca}"><joint name="ta" axis="1 0 0"/>
          <inertial pos="0.15 0 0.02" mass="1.5" diaginertia="0.01 0.02 0.025"/>
          <site name="centre" pos="0.15 0 0.05"/>
          <site name="t1" pos="0.3 0.05 0"/><site name="t2" pos="0.3 -0.05 0"/>
        </body></body></body>
    <body name="B1" pos="0.3 0 0"><joint name="pb" axis="0 1 0"/>
      <inertial pos="{b * sb / 2} 0 {b * cb / 2}" mass="0.3" diaginertia="0.002 0.002 0.0001"/>
      <body name="B2" pos="{b * sb} 0 {b * cb}"><joint name="kb" axis="0 1 0"/>
        <inertial pos="{-b * sb / 2} 0 {b * cb / 2}" mass="0.3" diaginertia="0.002 0.002 0.0001"/>
        <site name="b1" pos="{-b * sb} 0.05 {b * cb}"/><site name="b2" pos="{-b * sb} -0.05 {b * cb}"/>
      </body></body>
  </worldbody>
  <equality><connect site1="b1" site2="t1"/><connect site1="b2" site2="t2"/></equality>
  <actuator><motor joint="pa"/></actuator>
</mujoco>"""


def _wrap(x):
    return (x + np.pi) % (2 * np.pi) - np.pi


def _rel(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - b)) / np.max(np.abs(b)))


# --- the MuJoCo-only reference ------------------------------------------------------------------------
def _closure_rows(m, d, qd):
    """``K`` (3 rows per site connect) and ``Kdot qd`` from MuJoCo's site Jacobians and their rates."""
    K, kdq = [], []
    for e in range(m.neq):
        assert m.eq_objtype[e] == mujoco.mjtObj.mjOBJ_SITE
        J, Jd = [], []
        for s in (m.eq_obj1id[e], m.eq_obj2id[e]):
            jp, jdp = np.zeros((3, m.nv)), np.zeros((3, m.nv))
            mujoco.mj_jacSite(m, d, jp, None, s)
            mujoco.mj_jacDot(m, d, jdp, None, d.site_xpos[s], m.site_bodyid[s])
            J.append(jp)
            Jd.append(jdp)
        K.append(J[0] - J[1])
        kdq.append((Jd[0] - Jd[1]) @ qd)
    return np.vstack(K), np.concatenate(kdq)


def _reference(m, q, qd_act, qdd_act):
    """(tau, qd, qdd) of one sample from MuJoCo alone (module docstring)."""
    act = [int(m.jnt_dofadr[m.actuator_trnid[k, 0]]) for k in range(m.nu)]
    pas = [i for i in range(m.nv) if i not in act]
    d = mujoco.MjData(m)
    d.qpos[:] = q
    mujoco.mj_fwdPosition(m, d)
    K, _ = _closure_rows(m, d, np.zeros(m.nv))
    G = np.zeros((m.nv, m.nu))
    G[act] = np.eye(m.nu)
    G[pas] = -np.linalg.lstsq(K[:, pas], K[:, act], rcond=None)[0]
    qd = G @ qd_act
    d.qvel[:] = qd
    mujoco.mj_fwdVelocity(m, d)
    _, kdq = _closure_rows(m, d, qd)
    qdd = np.zeros(m.nv)
    qdd[act] = qdd_act
    qdd[pas] = -np.linalg.lstsq(K[:, pas], K[:, act] @ qdd_act + kdq, rcond=None)[0]
    d.qacc[:] = qdd
    f = np.zeros(m.nv)
    mujoco.mj_rne(m, d, 1, f)
    return G.T @ f, qd, qdd


def _check_dynamics(xml: str, q: np.ndarray, seed: int) -> None:
    mech, m = mb.from_mjcf(xml), mujoco.MjModel.from_xml_string(xml)
    rng = np.random.default_rng(seed)
    n = len(q)
    qd_act, qdd_act = rng.normal(0, 1, (n, m.nu)), rng.normal(0, 2, (n, m.nu))
    ref = [_reference(m, q[i], qd_act[i], qdd_act[i]) for i in range(n)]
    tau, qd, qdd = (np.array([r[k] for r in ref]) for k in range(3))
    inv = mb.inverse_dynamics(mech, q, qd_act, qdd_act)
    assert inv.valid.all()
    assert _rel(inv.tau, tau) < TOL_REL
    assert _rel(inv.qd, qd) < TOL_REL and _rel(inv.qdd, qdd) < TOL_REL
    full = mb.inverse_dynamics(mech, q, qd=qd, qdd=qdd)  # every coordinate's rates: the same forces
    assert full.valid.all() and _rel(full.tau, tau) < TOL_REL
    fwd = mb.forward_dynamics(mech, q, qd_act, tau)  # MuJoCo's forces give the accelerations back
    assert fwd.valid.all() and _rel(fwd.qdd_act, qdd_act) < TOL_FD_REL
    one = [
        mb.inverse_dynamics(mech, q[i : i + 1], qd_act[i : i + 1], qdd_act[i : i + 1]).tau[0]
        for i in (0, n - 1)
    ]
    np.testing.assert_array_equal(np.array(one), inv.tau[[0, n - 1]])


# --- the five-bar typed along x -----------------------------------------------------------------------
def _five_bar_closed_form(t1: float, t3: float, mode: int) -> np.ndarray:
    """qpos (t1, t2, t3, t4) with the tip at one of the two circle intersections."""
    B1 = L1 * np.array([np.cos(t1), np.sin(t1)])
    B2 = np.array([D, 0.0]) + L3 * np.array([np.cos(t3), np.sin(t3)])
    e = B2 - B1
    d = np.linalg.norm(e)
    a = (L2**2 - L4**2 + d**2) / (2 * d)
    P = B1 + a * e / d + mode * np.sqrt(L2**2 - a**2) * np.array([-e[1], e[0]]) / d
    return np.array(
        [t1, _wrap(np.arctan2(*(P - B1)[::-1]) - t1), t3, _wrap(np.arctan2(*(P - B2)[::-1]) - t3)]
    )


@pytest.fixture(scope="module")
def five_bar():
    mech = mb.from_mjcf(FIVE_BAR)
    modes = [
        m for m in (1, -1) if np.allclose(_five_bar_closed_form(*mech.q0[[0, 2]], m), mech.q0, atol=1e-9)
    ]
    assert len(modes) == 1  # the assembled reference is one of the closed form's two modes
    rng = np.random.default_rng(4)
    q_act = mech.q0[[0, 2]] + rng.uniform(-0.15, 0.15, (300, 2))
    fk = mb.forward_kinematics(mech, q_act)
    assert fk.converged.all()
    return mech, modes[0], q_act, fk.q


def test_five_bar_typed_open_is_assembled_and_follows_its_closed_form(five_bar):
    mech, mode, q_act, q = five_bar
    assert np.abs(mech.q0).max() > 0.1  # the typed qpos0 (all zeros) was not closed: it moved
    expected = np.array([_five_bar_closed_form(a, b, mode) for a, b in q_act])
    assert np.abs(_wrap(q - expected)).max() < TOL_CLOSED_FORM
    tips = mb.site_pose(mech, q, "P")[:, :3, 3] - mb.site_pose(mech, q, "Q")[:, :3, 3]
    assert np.abs(tips).max() < TOL_CLOSED_FORM
    assert mb.mobility(mech).dof == 2 and not mb.mobility(mech).singular


@pytest.mark.parametrize("n", [1, 300])
def test_five_bar_dynamics_equal_mujoco(five_bar, n):
    _check_dynamics(FIVE_BAR, five_bar[3][:n], seed=n)


def test_five_bar_that_cannot_close_is_refused_with_its_gap():
    """Legs of 0.95 m and 0.85 m cannot meet across 1.9 m: the residual left is the 0.1 m gap."""
    with pytest.raises(ValueError, match=r"leaves residual 0\.1 m"):
        mb.from_mjcf(FIVE_BAR.replace(f'name="p2" pos="{D} 0 0"', 'name="p2" pos="1.9 0 0"'))


# --- the Agile-Eye-type wrist -------------------------------------------------------------------------
def _agile_eye_ik(R: np.ndarray, near: np.ndarray) -> np.ndarray:
    """Base angles for the platform orientation R: each elbow axis w_i is perpendicular to the base axis
    u_i and to the platform axis v_i = R v_i0 (90-degree links), so w_i = +-(u_i x v_i)/|u_i x v_i|;
    the base angle turns w_i0 into w_i about u_i (the sign nearest ``near``)."""
    U, W0, V0 = np.eye(3), np.eye(3)[[1, 2, 0]], np.eye(3)[[2, 0, 1]]
    out = []
    for i in range(3):
        w = np.cross(U[i], R @ V0[i])
        w /= np.linalg.norm(w)
        angles = [np.arctan2(np.cross(W0[i], s * w) @ U[i], W0[i] @ (s * w)) for s in (1, -1)]
        out.append(min(angles, key=lambda a: abs(_wrap(a - near[i]))))
    return np.array(out)


@pytest.fixture(scope="module")
def agile_eye():
    mech = mb.from_mjcf(AGILE_EYE)
    q_act = np.random.default_rng(9).uniform(-0.4, 0.4, (300, 3))
    fk = mb.forward_kinematics(mech, q_act, steps=4)
    assert fk.converged.all()
    return mech, q_act, fk.q


def test_agile_eye_forward_kinematics_inverts_its_closed_form(agile_eye):
    mech, q_act, q = agile_eye
    T = mb.site_pose(mech, q, "camera")
    back = np.array([_agile_eye_ik(T[i, :3, :3], q_act[i]) for i in range(len(q))])
    assert np.abs(_wrap(back - q_act)).max() < TOL_CLOSED_FORM
    # a pure rotation about the centre: the camera stays on its sphere
    radius = np.linalg.norm(T[:, :3, 3], axis=1)
    assert np.ptp(radius) < TOL_CLOSED_FORM
    m = mb.mobility(mech)
    assert (m.dof, m.platform_dof, m.platform_rotational_dof) == (3, 3, 3)


@pytest.mark.parametrize("n", [1, 300])
def test_agile_eye_dynamics_equal_mujoco(agile_eye, n):
    _check_dynamics(AGILE_EYE, agile_eye[2][:n], seed=10 + n)


# --- the Sarrus linkage -------------------------------------------------------------------------------
def test_sarrus_typed_off_its_closure_moves_straight_up_and_its_dynamics_equal_mujoco():
    xml = _sarrus()
    mech = mb.from_mjcf(xml)
    assert mb.mobility(mech).dof == 1
    # leg B (links 0.25 m) reaches 0.5 m: the plate can rise to z = 0.5, leg A's lower link tilt
    # acos(0.5 / 0.6) from vertical; stay below it
    theta = mech.q0[0] + np.linspace(-0.3, 0.08, 300)[:, None]
    fk = mb.forward_kinematics(mech, theta, steps=3)
    assert fk.converged.all()
    T = mb.site_pose(mech, fk.q, "centre")
    tilt = np.deg2rad(40) - fk.q[:, 0]  # a hinge about +x turns the link (0, sin, cos) towards -y
    assert np.abs(T[:, 2, 3] - (0.6 * np.cos(tilt) + 0.05)).max() < TOL_CLOSED_FORM
    assert np.abs(T[:, :2, 3] - [0.15, 0.0]).max() < TOL_CLOSED_FORM
    assert np.abs(T[:, :3, :3] - np.eye(3)).max() < TOL_CLOSED_FORM
    _check_dynamics(xml, fk.q, seed=3)
