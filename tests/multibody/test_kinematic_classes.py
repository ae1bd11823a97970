"""Every kinematic class in the one code path: open chains, trees, floating bases, passive systems.

References: MuJoCo (``mj_rne``, ``mj_fullM``, ``qacc`` of ``mj_forward`` under motor controls) and
Pinocchio (``rnea``, ``crba``) on the same MJCF, an ODE of the compound pendulum written here, and the
per-sample result of each batched call (batches of 1, 10 and 300: one sample, one block and several
parallel blocks of the compiled kernels).
"""

from __future__ import annotations

import dataclasses
import os
import tempfile

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomech import multibody as mb
from robomech.multibody import _assembly, _compiled, _dynamics
from robomech.multibody._options import SINGULAR_COND

mujoco = pytest.importorskip("mujoco")

# Engine comparisons (MuJoCo's recursive algorithms and ours, the same physics in double precision):
# rounding of O(10) sums leaves ~1e-14 relative; the acceptance bound is 1e-9.
ENGINE_RTOL = 1e-9
# The same sample evaluated in a batch and alone: only the order of BLAS reductions may differ.
BATCH_RTOL = 1e-12
# The pendulum's simulation against solve_ivp of its ODE at rtol 1e-12: both integrate to ~1e-10.
ODE_TOL = 1e-8
# Batch sizes: one sample, one block and several parallel blocks of the compiled kernels (_compiled.BLOCK)
BATCHES = (1, 10, 300)
assert max(BATCHES) > 2 * _compiled.BLOCK

ARM6 = """
<mujoco model="arm6">
  <worldbody>
    <body name="l1" pos="0 0 0.1">
      <joint name="j1" axis="0 0 1"/>
      <inertial pos="0 0 0.05" mass="2.0" diaginertia="0.01 0.012 0.008"/>
      <body name="l2" pos="0 0 0.1" quat="0.9238795 0.3826834 0 0">
        <joint name="j2" axis="0 1 0"/>
        <inertial pos="0.15 0 0" quat="0.9 0.1 0.2 0.3" mass="1.5" diaginertia="0.004 0.02 0.021"/>
        <body name="l3" pos="0.3 0 0">
          <joint name="j3" axis="0 1 0"/>
          <inertial pos="0.12 0.01 0" mass="1.0" diaginertia="0.002 0.011 0.012"/>
          <body name="l4" pos="0.25 0 0">
            <joint name="j4" axis="1 0 0"/>
            <inertial pos="0.03 0 0.01" mass="0.5" diaginertia="0.001 0.0012 0.0011"/>
            <body name="l5" pos="0.06 0 0">
              <joint name="j5" axis="0 1 0" pos="0.01 0 0"/>
              <inertial pos="0.02 0 0" mass="0.4" diaginertia="0.0005 0.0006 0.0007"/>
              <body name="l6" pos="0.05 0 0">
                <joint name="j6" axis="1 0 0"/>
                <inertial pos="0.02 0.005 0" mass="0.2" diaginertia="0.0002 0.0003 0.00025"/>
                <site name="tool" pos="0.05 0 0"/>
              </body>
            </body>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor joint="j3"/><motor joint="j1"/><motor joint="j2"/>
    <motor joint="j4"/><motor joint="j5"/><motor joint="j6"/>
  </actuator>
</mujoco>
"""


def _leg(i: int, x: float, y: float) -> str:
    return f"""
      <body name="hip{i}" pos="{x} {y} 0">
        <joint name="hx{i}" axis="1 0 0"/>
        <inertial pos="0 0 -0.02" mass="0.3" diaginertia="0.001 0.001 0.0008"/>
        <body name="thigh{i}" pos="0 0 -0.04">
          <joint name="hy{i}" axis="0 1 0"/>
          <inertial pos="0 0 -0.1" mass="0.6" diaginertia="0.004 0.004 0.0005"/>
          <body name="shin{i}" pos="0 0 -0.2">
            <joint name="kn{i}" axis="0 1 0"/>
            <inertial pos="0 0 -0.1" mass="0.2" diaginertia="0.0015 0.0015 0.0001"/>
            <site name="foot{i}" pos="0 0 -0.2"/>
          </body>
        </body>
      </body>"""


QUAD = f"""
<mujoco model="quadruped">
  <worldbody>
    <body name="trunk" pos="0.1 -0.2 0.45" quat="0.98 0.1 0.05 0.1">
      <freejoint name="base"/>
      <inertial pos="0.01 0 0" mass="8.0" diaginertia="0.05 0.12 0.14"/>
      <site name="imu"/>
      {_leg(0, 0.25, 0.1)}{_leg(1, 0.25, -0.1)}{_leg(2, -0.25, 0.1)}{_leg(3, -0.25, -0.1)}
    </body>
  </worldbody>
  <actuator>
    {"".join(f'<motor joint="{j}{i}"/>' for i in range(4) for j in ("hx", "hy", "kn"))}
  </actuator>
</mujoco>
"""

# A compound pendulum: a rod pivoting about y at 1 m height, centre of mass 0.4 m below the pivot.
PEND_MASS, PEND_D, PEND_IYY = 1.3, 0.4, 0.07
PENDULUM = f"""
<mujoco model="compound_pendulum">
  <worldbody>
    <body name="rod" pos="0 0 1">
      <joint name="pivot" axis="0 1 0"/>
      <inertial pos="0 0 -{PEND_D}" mass="{PEND_MASS}" diaginertia="{PEND_IYY} {PEND_IYY} 0.001"/>
      <site name="tip" pos="0 0 -0.8"/>
    </body>
  </worldbody>
</mujoco>
"""

CART = """
<mujoco model="cart">
  <worldbody>
    <body name="cart" pos="0 0 0.2">
      <joint name="x" type="slide" axis="1 0 0"/>
      <inertial pos="0 0 0" mass="2.5" diaginertia="0.01 0.02 0.02"/>
      <site name="top" pos="0 0 0.1"/>
    </body>
  </worldbody>
  <actuator><motor joint="x"/></actuator>
</mujoco>
"""

XML = {"arm6": ARM6, "quadruped": QUAD, "pendulum": PENDULUM, "cart": CART}
MECH = {k: mb.from_mjcf(v) for k, v in XML.items()}


def _states(mech, n: int, seed: int = 0):
    """n random states (q normalised, qd, qdd) and actuator forces."""
    rng = np.random.default_rng(seed)
    q = mech.q0 + 0.6 * rng.standard_normal((n, mech.nq))
    q = mb._tree.normalize_quaternions(mech.tree, q)
    qd = rng.standard_normal((n, mech.nv))
    qdd = rng.standard_normal((n, mech.nv))
    tau = rng.standard_normal((n, len(mech.actuated)))
    return q, qd, qdd, tau


def _mujoco(name: str, q, qd, qdd, tau):
    """Per sample: mj_rne (M qdd + bias), mj_fullM, and qacc of mj_forward with ctrl = tau (gear 1)."""
    m = mujoco.MjModel.from_xml_string(XML[name])
    d = mujoco.MjData(m)
    rne, M, acc = [], [], []
    for i in range(q.shape[0]):
        d.qpos[:], d.qvel[:], d.ctrl[:] = q[i], qd[i], tau[i]
        mujoco.mj_forward(m, d)
        acc.append(d.qacc.copy())
        d.qacc[:] = qdd[i]
        r = np.zeros(m.nv)
        mujoco.mj_rne(m, d, 1, r)
        rne.append(r)
        Mi = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, Mi)
        M.append(Mi)
    return np.array(rne), np.array(M), np.array(acc)


def _rel(a, b) -> float:
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


def _act_order(mech):
    """Actuated velocity coordinates in actuator order (the arm's actuators are not in qvel order)."""
    return mech.tree.act_dof


@pytest.mark.parametrize("name", list(XML))
@pytest.mark.parametrize("n", BATCHES)
def test_tree_quantities_equal_mujoco(name, n):
    mech = MECH[name]
    q, qd, qdd, tau = _states(mech, n, seed=n)
    rne, M, _ = _mujoco(name, q, qd, qdd, tau)
    f = mb.generalized_forces(mech, q, qd, qdd)
    Mm = mb.mass_matrix(mech, q)
    assert f.shape == (n, mech.nv) and Mm.shape == (n, mech.nv, mech.nv)
    assert _rel(f, rne) < ENGINE_RTOL
    assert _rel(Mm, M) < ENGINE_RTOL
    # batched = per sample
    for i in (0, n - 1):
        assert _rel(f[i], mb.generalized_forces(mech, q[i], qd[i], qdd[i])) < BATCH_RTOL
        assert _rel(Mm[i], mb.mass_matrix(mech, q[i])) < BATCH_RTOL
    # gravity=False is the same pass without the base acceleration
    g0 = mb.generalized_forces(mech, q, qd, qdd, gravity=False)
    grav = mb.generalized_forces(mech, q, 0 * qd, 0 * qdd)
    assert _rel(g0 + grav, f) < ENGINE_RTOL


@pytest.mark.parametrize("name", list(XML))
@pytest.mark.parametrize("n", BATCHES)
def test_forward_dynamics_equals_mujoco_qacc(name, n):
    mech = MECH[name]
    q, qd, _, tau = _states(mech, n, seed=10 + n)
    _, _, acc = _mujoco(name, q, qd, np.zeros((n, mech.nv)), tau)
    fd = mb.forward_dynamics(mech, q, tau=tau, qd=qd)
    assert fd.valid.all() and _rel(fd.qdd, acc) < ENGINE_RTOL
    assert _rel(fd.qdd[0], mb.forward_dynamics(mech, q[0], tau=tau[0], qd=qd[0]).qdd) < BATCH_RTOL
    if name in ("arm6", "cart"):  # the actuators determine the motion: the actuated-rate form agrees
        fa = mb.forward_dynamics(mech, q, qd[:, _act_order(mech)], tau)
        assert fa.valid.all() and _rel(fa.qdd, acc) < ENGINE_RTOL


@pytest.mark.parametrize("name", ["arm6", "cart"])
@pytest.mark.parametrize("n", BATCHES)
def test_inverse_dynamics_of_open_chains_equals_mj_rne(name, n):
    mech = MECH[name]
    q, qd, qdd, tau = _states(mech, n, seed=20 + n)
    rne, _, _ = _mujoco(name, q, qd, qdd, tau)
    a = _act_order(mech)
    r = mb.inverse_dynamics(mech, q, qd[:, a], qdd[:, a])
    assert r.valid.all() and np.all(np.isfinite(r.cond)) and np.all(np.isfinite(r.sigma_min))
    assert _rel(r.tau, rne[:, a]) < ENGINE_RTOL
    full = mb.inverse_dynamics(mech, q, qd=qd, qdd=qdd)
    assert full.valid.all() and _rel(full.tau, rne[:, a]) < ENGINE_RTOL
    assert np.max(np.abs(full.unactuated)) == 0.0  # every coordinate actuated
    one = mb.inverse_dynamics(mech, q[-1], qd[-1, a], qdd[-1, a])
    assert _rel(r.tau[-1], one.tau) < BATCH_RTOL and r.cond[-1] == one.cond
    inf = mb.influence(mech, q)
    assert np.all(np.isfinite(inf.sigma_min)) and np.all(inf.cond == 1.0)
    assert np.allclose(inf.G[:, a], np.eye(len(a)))  # G is the identity on the actuated coordinates


@pytest.mark.parametrize("name", ["quadruped", "pendulum"])
@pytest.mark.parametrize("n", BATCHES)
def test_inverse_dynamics_of_underactuated_systems(name, n):
    """A random motion needs a base wrench / pivot torque (mj_rne's unactuated rows): flagged; the motion
    MuJoCo produces under the same actuator forces needs none: valid, and the forces come back."""
    mech = MECH[name]
    q, qd, qdd, tau = _states(mech, n, seed=30 + n)
    rne, _, acc = _mujoco(name, q, qd, qdd, tau)
    a = _act_order(mech)
    un = np.setdiff1d(np.arange(mech.nv), a)
    r = mb.inverse_dynamics(mech, q, qd=qd, qdd=qdd)
    assert not r.valid.any() and np.all(r.admissibility > _dynamics.ADMISSIBLE_RTOL)
    assert _rel(r.tau, rne[:, a]) < ENGINE_RTOL if len(a) else r.tau.shape == (n, 0)
    assert _rel(r.unactuated[:, un], rne[:, un]) < ENGINE_RTOL  # the base wrench / pivot torque
    assert np.all(r.unactuated[:, a] == 0.0)
    ok = mb.inverse_dynamics(mech, q, qd=qd, qdd=acc)
    assert ok.valid.all()
    scale = max(1.0, np.max(np.abs(tau), initial=0.0))
    assert np.max(np.abs(ok.tau - tau), initial=0.0) < ENGINE_RTOL * scale
    one = mb.inverse_dynamics(mech, q[0], qd=qd[0], qdd=acc[0])
    assert np.max(np.abs(one.tau - ok.tau[0]), initial=0.0) <= BATCH_RTOL * scale
    assert np.max(np.abs(one.unactuated - ok.unactuated[0])) <= BATCH_RTOL * scale


def test_statics_of_a_floating_robot_is_the_base_wrench_of_its_weight():
    mech = MECH["quadruped"]
    q, _, _, _ = _states(mech, 3, seed=50)
    z = np.zeros((3, mech.nv))
    rne, _, _ = _mujoco("quadruped", q, z, z, np.zeros((3, 12)))
    st = mb.statics(mech, q)
    assert not st.valid.any()  # nothing holds the trunk up
    assert _rel(st.tau, rne[:, _act_order(mech)]) < ENGINE_RTOL
    assert _rel(st.unactuated[:, :6], rne[:, :6]) < ENGINE_RTOL
    total = sum(b.inertial.mass for b in mech.bodies)
    assert abs(st.unactuated[0, 2] - total * 9.81) < 1e-9 * total * 9.81  # the base carries the weight


def test_rates_form_is_checked():
    with pytest.raises(ValueError, match="qd="):
        mb.inverse_dynamics(MECH["quadruped"], MECH["quadruped"].q0, np.zeros(12), np.zeros(12))
    with pytest.raises(ValueError, match="qd="):
        mb.forward_dynamics(MECH["pendulum"], [0.1], np.zeros(0))
    with pytest.raises(ValueError, match="exactly one"):
        mb.forward_dynamics(MECH["cart"], [0.1], [0.0], [0.0], qd=[0.0])
    with pytest.raises(ValueError, match="qd0"):
        mb.simulate(MECH["pendulum"], [0.1], np.zeros(0), [0.0, 0.1])


def test_pinocchio_rnea_and_crba():
    pin = pytest.importorskip("pinocchio")
    for name in ("arm6", "pendulum", "quadruped"):
        with tempfile.NamedTemporaryFile("w", suffix=".xml", delete=False) as f:
            f.write(XML[name])
        try:
            model = pin.buildModelFromMJCF(f.name)
        finally:
            os.unlink(f.name)
        data = model.createData()
        mech = MECH[name]
        q, qd, qdd, _ = _states(mech, 5, seed=40)
        for i in range(5):
            if name == "quadruped":
                # Pinocchio's free flyer: q = [p, qx qy qz qw], v = [R^T v, w]; v_mujoco = T v_pin with
                # T = diag(R, I, I), so M_pin = T^T M T and the static forces g_pin = T^T g
                qp = np.concatenate([q[i, :3], q[i, 4:7], q[i, 3:4], q[i, 7:]])
                T = np.eye(mech.nv)
                T[:3, :3] = mb._tree.quat_to_matrix(q[i, 3:7])
                Mp = pin.crba(model, data, qp)
                Mp = np.triu(Mp) + np.triu(Mp, 1).T
                assert _rel(Mp, T.T @ mb.mass_matrix(mech, q[i]) @ T) < ENGINE_RTOL
                z = np.zeros(mech.nv)
                gp = pin.rnea(model, data, qp, z, z)
                assert _rel(gp, T.T @ mb.generalized_forces(mech, q[i], z, z)) < ENGINE_RTOL
                continue
            tp = pin.rnea(model, data, q[i], qd[i], qdd[i])
            Mp = pin.crba(model, data, q[i])
            Mp = np.triu(Mp) + np.triu(Mp, 1).T
            assert _rel(mb.generalized_forces(mech, q[i], qd[i], qdd[i]), tp) < ENGINE_RTOL
            assert _rel(mb.mass_matrix(mech, q[i]), Mp) < ENGINE_RTOL


def _pendulum_ode(th0, w0, t):
    """theta'' = -m g d sin(theta) / (I_yy + m d^2): the pivot torque of gravity on the centre of mass
    ``R_y(theta) (0, 0, -d)`` is ``-m g d sin(theta)`` about +y."""
    from scipy.integrate import solve_ivp

    k = PEND_MASS * 9.81 * PEND_D / (PEND_IYY + PEND_MASS * PEND_D**2)
    sol = solve_ivp(
        lambda _, y: [y[1], -k * np.sin(y[0])], (t[0], t[-1]), [th0, w0], t_eval=t, rtol=1e-12, atol=1e-14
    )
    return sol.y[0], sol.y[1]


@pytest.mark.parametrize("n", [1, 10])
def test_pendulum_simulation_equals_its_ode(n):
    mech = MECH["pendulum"]
    rng = np.random.default_rng(5)
    th0 = rng.uniform(-2.5, 2.5, (n, 1))
    w0 = rng.uniform(-2.0, 2.0, (n, 1))
    t = np.linspace(0.0, 1.0, 6)
    sim = mb.simulate(mech, th0, t=t, qd0=w0)
    assert sim.success.all() and sim.q.shape == (n, 6, 1)
    for i in range(n):
        th, w = _pendulum_ode(th0[i, 0], w0[i, 0], t)
        assert np.max(np.abs(sim.q[i, :, 0] - th)) < ODE_TOL
        assert np.max(np.abs(sim.qd[i, :, 0] - w)) < ODE_TOL
    assert np.max(sim.energy_drift_rel) < 1e-8
    # each sample is integrated alone: the batch result is the single-sample result
    alone = mb.simulate(mech, th0[-1], t=t, qd0=w0[-1])
    assert np.array_equal(alone.q, sim.q[-1])


@pytest.mark.slow
def test_pendulum_simulation_batch_above_threshold():
    mech = MECH["pendulum"]
    rng = np.random.default_rng(6)
    th0, w0 = rng.uniform(-1, 1, (300, 1)), rng.uniform(-1, 1, (300, 1))
    t = np.array([0.0, 0.2])
    sim = mb.simulate(mech, th0, t=t, qd0=w0)
    assert sim.success.all()
    th, _ = _pendulum_ode(th0[7, 0], w0[7, 0], t)
    assert np.max(np.abs(sim.q[7, :, 0] - th)) < ODE_TOL


def _massless_pendulum():
    b = mb.Builder("massless")
    b.body("rod", joints=[b.hinge("a", axis=(0, 1, 0))], inertial=mb.Inertial(0.0))
    b.actuate("a")
    return b.build()


def test_massless_motion_is_never_valid():
    mech = _massless_pendulum()
    fd = mb.forward_dynamics(mech, [0.3], [0.0], [0.5])
    assert not fd.valid and np.isinf(fd.cond) and np.isnan(fd.qdd_act).all()
    sim = mb.simulate(mech, [0.3], [0.0], [0.0, 0.1], tau=[0.5])
    assert not sim.success


def _tip_mass_2r():
    """A planar 2R arm with a point mass at the tip only: M = m J^T J is singular with the arm straight."""
    b = mb.Builder("tip_mass", gravity=(0, -9.81, 0))
    b.body("l1", joints=[b.hinge("a")])
    b.body(
        "l2", parent="l1", pos=(1.0, 0, 0), joints=[b.hinge("b")], inertial=mb.Inertial(1.0, pos=(1.0, 0, 0))
    )
    b.actuate("a", "b")
    return b.build()


def test_singular_mass_matrix_and_nan_sample_stay_alone():
    mech = _tip_mass_2r()
    q = np.array([[0.3, 0.8], [0.1, 0.0], [np.nan, 0.2]])  # regular, straight (singular M), NaN
    qd, tau = np.array([0.2, -0.1]), np.array([0.3, 0.1])
    fd = mb.forward_dynamics(mech, q, qd, tau)
    assert fd.valid.tolist() == [True, False, False]
    # the straight arm's M is singular: its condition number is inf or the rounding of one (~1e17,
    # depending on the LAPACK path); either is far above the singular threshold
    assert np.isnan(fd.qdd[1:]).all() and fd.cond[1] > SINGULAR_COND
    alone = mb.forward_dynamics(mech, q[0], qd, tau)
    assert np.array_equal(alone.qdd, fd.qdd[0])
    r = mb.inverse_dynamics(mech, q, qd, [0.1, 0.2])
    assert r.valid.tolist() == [True, True, False]  # inverse dynamics needs no inverse of M


def test_simulated_samples_are_independent():
    mech = dataclasses.replace(mb.gallery.load("four_bar"), gravity=(0.0, -9.81, 0.0))
    q = mb.forward_kinematics(mech, [[0.2], [0.3], [0.1]]).q
    qd = np.array([[1.0], [-2.0], [0.5]])
    t = np.linspace(0.0, 0.2, 3)
    sim = mb.simulate(mech, q, qd, t)
    for i in range(3):
        one = mb.simulate(mech, q[i], qd[i], t)
        assert np.array_equal(one.q, sim.q[i])

    def tau(tt, qq, qqd):  # NaN for the sample starting with a negative rate
        return np.where(qqd[:, :1] < 0, np.nan, 0.1)

    s2 = mb.simulate(mech, q, qd, t, tau=tau)
    assert s2.success.tolist() == [True, False, True]
    held = mb.simulate(mech, q[[0, 2]], qd[[0, 2]], t, tau=[0.1])
    assert np.array_equal(held.q, s2.q[[0, 2]])
    with pytest.raises(ValueError, match="tau callback"):
        mb.simulate(mech, q, qd, t, tau=lambda tt, qq, qqd: np.zeros((2, 2)))


def test_unassembled_input_is_flagged():
    mech = mb.gallery.load("four_bar")
    q = mb.forward_kinematics(mech, [[0.2], [0.2]]).q
    pas = np.setdiff1d(np.arange(mech.nv), mech.tree.act_dof)[0]
    q[1, mech.tree.jnt_qadr[mech.tree.dof_jnt[pas]]] += 0.5  # a passive joint moved by hand
    r = mb.inverse_dynamics(mech, q, [1.0], [0.5])
    assert r.valid.tolist() == [True, False]
    assert r.closure[0] < _dynamics.CLOSURE_RTOL * mech.length < r.closure[1]
    fd = mb.forward_dynamics(mech, q, [1.0], [0.5])
    assert fd.valid.tolist() == [True, False]
    s = mb.singularities(mech, q, "coupler_point")
    assert s.assembled.tolist() == [True, False]


def test_type_two_singularity_reports_infinite_condition():
    b = mb.Builder("toggle", gravity=(0, -9.81, 0))
    inertial = mb.Inertial(1.0, (0.1, 0.0, 0.0), diaginertia=(0.01,) * 3)
    b.body("crank", joints=[b.hinge("a")], inertial=inertial)
    b.body("coupler", parent="crank", pos=(0, 1, 0), joints=[b.hinge("b")], inertial=inertial)
    b.body("rocker", pos=(2, 0, 0), joints=[b.hinge("c")], inertial=inertial)
    b.connect("C", "coupler", "rocker", anchor1=(1.0, -0.5, 0.0))  # B, C, D collinear at q0
    b.actuate("a")
    mech = b.build()
    for n in (1, 300):  # one block and several parallel blocks
        r = mb.inverse_dynamics(mech, np.tile(mech.q0, (n, 1)), np.zeros((n, 1)), np.zeros((n, 1)))
        assert not r.valid.any() and np.all(r.cond > _dynamics.SINGULAR_COND)


def test_floating_base_is_not_moved_and_not_type_one():
    mech = MECH["quadruped"]
    rng = np.random.default_rng(3)
    guess = mech.q0.copy()
    qa = 0.4 * rng.standard_normal((3, 12))
    fk = mb.forward_kinematics(mech, qa, guess)
    assert fk.converged.all() and np.array_equal(fk.q[:, :7], np.broadcast_to(guess[:7], (3, 7)))
    for site in ("imu", "foot0"):
        s = mb.singularities(mech, fk.q, site)
        assert not s.type_I.any() and not s.singular.any()


def test_floating_closed_chain_keeps_its_base():
    """A four-bar on a floating base, not closed at the guess: assembly closes the loop, the base stays."""
    b = mb.Builder("floating_four_bar")
    b.body(
        "base",
        pos=(0.1, 0.2, 0.3),
        joints=[b.free("root")],
        inertial=mb.Inertial(1.0, diaginertia=(0.1,) * 3),
    )
    b.body("crank", parent="base", joints=[b.hinge("a")], inertial=mb.Inertial(0.1, pos=(0.05, 0, 0)))
    b.body("coupler", parent="crank", pos=(0.1, 0, 0), joints=[b.hinge("b")], inertial=mb.Inertial(0.1))
    b.body("rocker", parent="base", pos=(0.3, 0, 0), joints=[b.hinge("c")], inertial=mb.Inertial(0.1))
    b.connect("C", "coupler", "rocker", anchor1=(0.25, 0.1, 0.0))
    b.actuate("a")
    mech = b.build()
    guess = mech.q0.copy()
    fk = mb.forward_kinematics(mech, [[0.3]], guess, steps=3)
    assert fk.converged.all() and np.array_equal(fk.q[0, :7], guess[:7])
    assert np.max(np.abs(mb.constraint_residual(mech, fk.q))) < 1e-10 * mech.length


def test_passive_mechanism_assembles_and_moves():
    four_bar = dataclasses.replace(mb.gallery.load("four_bar"), actuated=(), gravity=(0.0, -9.81, 0.0))
    q0 = four_bar.q0
    guess = q0 + np.array([0.05, -0.03, 0.02])
    fk = mb.forward_kinematics(four_bar, np.zeros((1, 0)), guess)
    assert fk.converged.all()
    # gravity moves it: a valid acceleration from the full velocity, and a successful simulation
    fd = mb.forward_dynamics(four_bar, fk.q, qd=np.zeros((1, four_bar.nv)))
    assert fd.valid.all() and np.max(np.abs(fd.qdd)) > 0
    sim = mb.simulate(four_bar, fk.q[0], t=[0.0, 0.05], qd0=np.zeros(four_bar.nv))
    assert sim.success and np.max(sim.closure) < 1e-10 * four_bar.length


def _five_bar_leg_straight():
    """A five-bar (proximal 0.4 m, distal 0.6 m) assembled with its left leg straight, 60 deg up."""
    a, bl = 0.4, 0.6
    A0, B0 = np.array([-0.5, 0.0]), np.array([0.4, 0.0])
    u = np.array([np.cos(np.pi / 3), np.sin(np.pi / 3)])
    P, E = A0 + (a + bl) * u, A0 + a * u
    # the right elbow F: |F - B0| = a, |P - F| = bl (the intersection above the base line)
    dvec = P - B0
    dd = np.linalg.norm(dvec)
    x = (a**2 - bl**2 + dd**2) / (2 * dd)
    F = B0 + x * dvec / dd + np.sqrt(a**2 - x**2) * np.array([-dvec[1], dvec[0]]) / dd
    b = mb.Builder("five_bar")
    b.body("l1", pos=(*A0, 0), joints=[b.hinge("t1")])
    b.body("l2", parent="l1", pos=(*(E - A0), 0), joints=[b.hinge("p1")])
    b.body("r1", pos=(*B0, 0), joints=[b.hinge("t2")])
    b.body("r2", parent="r1", pos=(*(F - B0), 0), joints=[b.hinge("p2")])
    b.site("tip", "l2", pos=(*(P - E), 0))
    b.connect("P", "l2", "r2", anchor1=(*(P - E), 0))
    b.actuate("t1", "t2")
    return b.build()


def test_point_output_type_one_singularity():
    mech = _five_bar_leg_straight()
    q = np.stack([mech.q0, mb.forward_kinematics(mech, [[0.3, 0.0]]).q[0]])
    pos = mb.singularities(mech, q, "tip", output="position")
    assert pos.type_I.tolist() == [True, False]
    assert mb.singularities(mech, q, "tip", output=(3, 4)).type_I.tolist() == [True, False]
    assert not mb.singularities(mech, q[1], "tip", output="orientation").type_I
    with pytest.raises(ValueError, match="output"):
        mb.singularities(mech, q, "tip", output="speed")
    with pytest.raises(ValueError, match="output"):
        mb.singularities(mech, q, "tip", output=(3, 3))


def _five_bar_by_lengths(base: float):
    """A five-bar typed by link lengths (proximal 0.4 m, distal 0.6 m) with every link along x: the
    closure anchors (both given) are ``base + 0.9`` m apart at the description's own pose."""
    b = mb.Builder("five_bar_by_lengths")
    inertial = mb.Inertial(0.2, pos=(0.2, 0, 0), diaginertia=(1e-3,) * 3)
    b.body("l1", joints=[b.hinge("t1")], inertial=inertial)
    b.body("l2", parent="l1", pos=(0.4, 0, 0), joints=[b.hinge("p1")], inertial=inertial)
    b.body("r1", pos=(base, 0, 0), joints=[b.hinge("t2")], inertial=inertial)
    b.body("r2", parent="r1", pos=(0.4, 0, 0), joints=[b.hinge("p2")], inertial=inertial)
    b.site("tip", "l2", pos=(0.6, 0, 0))
    b.connect("P", "l2", "r2", anchor1=(0.6, 0, 0), anchor2=(0.6, 0, 0))
    b.actuate("t1", "t2")
    return b


def test_unassembled_description_is_assembled_at_load():
    mech = _five_bar_by_lengths(0.5).build()
    tree = mech.tree
    assert not np.allclose(mech.q0, tree.q0)  # the description's own pose is not closed ...
    res = mb.constraint_residual(mech, mech.q0)
    assert np.max(np.abs(res)) < _assembly.CONVERGED_RTOL * mech.length  # ... its reference is
    m = mb.mobility(mech)
    assert m.dof == 2 and not m.singular
    s = mb.singularities(mech, mech.q0, "tip")
    assert not s.singular and s.assembled
    fk = mb.forward_kinematics(mech, mech.q0[tree.act_qadr] + 0.05)
    assert fk.converged
    r = mb.inverse_dynamics(mech, fk.q, [0.1, -0.2], [0.3, 0.0])
    assert r.valid
    # the assembly nearest to the typed pose: the elbow-up/down branch the LM reaches first, every
    # coordinate within the 0.5 rad-capped path from the sketch (a few radians at most)
    assert np.max(np.abs(mech.q0 - tree.q0)) < np.pi


def test_description_that_cannot_assemble_is_refused_at_load():
    with pytest.raises(ValueError, match=r"assemble.*residual"):
        _five_bar_by_lengths(3.0).build()  # legs of 1 m cannot meet across 3 m
    xml = mb.to_mjcf(dataclasses.replace(_five_bar_by_lengths(0.5).build(), closures=()))
    xml = xml.replace(
        "</mujoco>",
        '<equality><connect body1="l2" body2="r2" anchor="0.6 0 0"/></equality></mujoco>',
    )
    mech = mb.from_mjcf(xml)  # MuJoCo resolves the anchor at qpos0: assembled by construction
    assert np.array_equal(mech.q0, mech.tree.q0)


# MuJoCo's RK4 at 1e-4 s against DOP853 at rtol 1e-10 over 0.1 s: both ~1e-12 here; 1e-8 is a margin.
RK4_TOL = 1e-8


def test_floating_quadruped_simulation_equals_mujoco_rk4():
    mech = MECH["quadruped"]
    rng = np.random.default_rng(8)
    qd0 = 0.5 * rng.standard_normal(mech.nv)
    sim = mb.simulate(mech, mech.q0, t=[0.0, 0.1], qd0=qd0, tau=0.1 * np.ones(12))
    assert sim.success and sim.energy_drift_rel < 1e-8
    m = mujoco.MjModel.from_xml_string(QUAD)
    m.opt.timestep, m.opt.integrator = 1e-4, mujoco.mjtIntegrator.mjINT_RK4
    d = mujoco.MjData(m)
    d.qpos[:], d.qvel[:], d.ctrl[:] = mech.q0, qd0, 0.1
    for _ in range(1000):
        mujoco.mj_step(m, d)
    assert np.max(np.abs(d.qpos - sim.q[1])) < RK4_TOL and np.max(np.abs(d.qvel - sim.qd[1])) < RK4_TOL


@pytest.mark.parametrize("name", ["four_bar", "planar_3rrr", "delta"])
def test_full_rate_form_equals_actuated_form_on_closed_chains(name):
    """The virtual-work least-squares form (any kinematic class) against the influence-coefficient form
    (closed chains actuated in every DOF): the same forces from the same motion."""
    mech = dataclasses.replace(mb.gallery.load(name), gravity=(0.0, -9.81, -3.0))
    rng = np.random.default_rng(9)
    na = len(mech.actuated)
    fk = mb.forward_kinematics(mech, mech.q0[mech.tree.act_qadr] + 0.1 * rng.uniform(-1, 1, (4, na)), steps=2)
    assert fk.converged.all()
    qda, qdda = rng.normal(size=(4, na)), rng.normal(size=(4, na))
    inf = mb.influence(mech, fk.q)
    qd = np.einsum("nij,nj->ni", inf.G, qda)
    qdd = np.einsum("nij,nj->ni", inf.G, qdda) + np.einsum("nijk,nj,nk->ni", inf.dG, qda, qda)
    a = mb.inverse_dynamics(mech, fk.q, qda, qdda)
    f = mb.inverse_dynamics(mech, fk.q, qd=qd, qdd=qdd)
    scale = np.max(np.abs(a.tau))
    assert a.valid.all() and np.max(np.abs(f.tau - a.tau)) < 1e-9 * scale
    # what is left does no work on any actuator-driven motion (G^T u = 0) ...
    assert np.max(np.abs(np.einsum("nij,ni->nj", inf.G, f.unactuated))) < 1e-9 * scale
    if mb.mobility(mech).idle_dof == 0:
        assert f.valid.all() and np.max(np.abs(f.unactuated)) < 1e-9 * scale
    else:  # ... it is the torque that would keep the Delta's idle forearm spins at rest (the G form
        # prescribes them at rest; the full form says that no actuator can): small, but flagged
        assert 0 < np.max(np.abs(f.unactuated)) < 1e-3 * scale and not f.valid.any()


# Central difference of M along qd with step 1e-5: truncation ~h^2 |M'''| ~ 1e-10, rounding ~1e-11.
FD_MDOT_TOL = 1e-7


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10**6))
def test_property_rnea_power_equals_kinetic_energy_rate(seed):
    """Without the engines: qd . (M qdd + c) = dT/dt = qd . M qdd + qd . Mdot qd / 2 (c's work is half the
    mass matrix's rate along the motion), with Mdot by central differences of mass_matrix on the arm."""
    mech = MECH["arm6"]
    rng = np.random.default_rng(seed)
    q, qd, qdd = rng.uniform(-2, 2, 6), rng.normal(size=6), rng.normal(size=6)
    h = 1e-5
    Md = (mb.mass_matrix(mech, q + h * qd) - mb.mass_matrix(mech, q - h * qd)) / (2 * h)
    M = mb.mass_matrix(mech, q)
    f = mb.generalized_forces(mech, q, qd, qdd, gravity=False)
    lhs = qd @ f
    rhs = qd @ M @ qdd + 0.5 * qd @ Md @ qd
    assert abs(lhs - rhs) < FD_MDOT_TOL * max(1.0, abs(rhs))
    assert np.allclose(M, M.T, rtol=0, atol=1e-15) and np.min(np.linalg.eigvalsh(M)) > 0


@pytest.mark.parametrize("name", list(XML))
def test_kernels_equal_the_numpy_formulation(name):
    """The compiled RNEA and CRBA against their numpy formulation (tests/multibody/_reference.py)."""
    from ._reference import numpy_crba, numpy_rnea

    mech = MECH[name]
    q, qd, qdd, _ = _states(mech, 70, seed=60)  # more than one parallel block
    g = np.asarray(mech.gravity)
    assert _rel(mb.generalized_forces(mech, q, qd, qdd), numpy_rnea(mech, q, qd, qdd, g)) < BATCH_RTOL
    assert _rel(mb.mass_matrix(mech, q), numpy_crba(mech, q)) < BATCH_RTOL
