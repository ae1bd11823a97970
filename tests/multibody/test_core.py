"""robomech.multibody core: description, MJCF round trip, tree FK, closures, assembly, G, site J and H.

References: the Freudenstein equation of the planar four-bar (closed form), MuJoCo's own closure
residual (``efc_pos``) and constraint Jacobian (``efc_J``), and central differences
(``robomech.testing``) for every derivative.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robomech import multibody as mb
from robomech.testing import numerical_jacobian

from ._helpers import fd_site_hessian, fd_site_jacobian, mujoco_closure

# Newton stops at rounding (~1e-15 L); closed-form identities of O(1) terms then hold to ~1e-14.
CLOSED_FORM_TOL = 1e-12
# Central differences (step 6e-6) of functions of order one: truncation + rounding ~1e-10; the
# derivatives here are of order 1-10, so 1e-7 absolute leaves margin without hiding an O(1) error.
FD_TOL = 1e-7
# MuJoCo evaluates the same closure in its own code: agreement to rounding of O(1) coordinates.
ENGINE_TOL = 1e-12
# FK∘IK round trips (acceptance: 1e-10).
ROUND_TRIP_TOL = 1e-10

FOUR_BAR = mb.gallery.load("four_bar")
A, B, C, D = 0.3, np.sqrt(1.06), 0.8, 0.9


def _freudenstein(q):
    t2, t4 = np.pi / 2 + q[..., 0], np.pi / 2 + q[..., 2]
    K1, K2, K3 = D / A, D / C, (A * A - B * B + C * C + D * D) / (2 * A * C)
    return K1 * np.cos(t4) - K2 * np.cos(t2) + K3 - np.cos(t2 - t4)


def _rssr(closure_kind="point"):
    """Spatial RSSR: crank (hinge z), coupler on a ball, rocker (hinge about a skew axis), cut at S2."""
    b = mb.Builder("rssr")
    b.body("crank", joints=[b.hinge("t1", axis=(0, 0, 1))])
    b.body("coupler", parent="crank", pos=(0.3, 0, 0), joints=[b.ball("s1")])
    b.body("rocker", pos=(0.2, 0.9, 0.1), quat=(0.9, 0.1, 0.3, 0.0), joints=[b.hinge("t4", axis=(1, 0, 0))])
    b.site("tip", "coupler", pos=(0.05, 0.4, 0.15), quat=(0.8, 0.2, 0.1, 0.3))
    b.connect("S2", "coupler", "rocker", anchor1=(0.1, 0.8, 0.3))
    b.actuate("t1")
    return b.build()


def _four_bar_weld():
    """The gallery four-bar with its loop cut through a weld: coupler -- weld -- pin -- hinge -- rocker."""
    b = mb.Builder("four-bar-weld")
    b.body("crank", quat=(np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)), joints=[b.hinge("theta2")])
    b.body(
        "coupler",
        parent="crank",
        pos=(0.3, 0, 0),
        quat=(np.cos(np.pi / 4), 0, 0, -np.sin(np.pi / 4)),
        joints=[b.hinge("theta3")],
    )
    b.body(
        "rocker",
        pos=(0.9, 0, 0),
        quat=(np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)),
        joints=[b.hinge("theta4")],
    )
    b.body("pin", parent="rocker", pos=(0.8, 0, 0), quat=(0.9, 0.0, 0.0, 0.3), joints=[b.hinge("theta5")])
    b.weld("C", "coupler", "pin", anchor2=(0.05, 0.02, 0.0))
    b.actuate("theta2")
    return b.build()


def test_four_bar_fk_satisfies_freudenstein_and_mujoco():
    qa = np.linspace(-np.pi, np.pi, 13)[:, None]
    fk = mb.forward_kinematics(FOUR_BAR, qa, steps=4)
    assert fk.converged.all()
    assert np.max(np.abs(_freudenstein(fk.q))) < CLOSED_FORM_TOL
    assert np.max(mujoco_closure(mb.to_mjcf(FOUR_BAR), fk.q)) < ENGINE_TOL
    with open(mb.gallery.path("four_bar")) as f:  # the shipped file itself, read by MuJoCo
        assert np.max(mujoco_closure(f.read(), fk.q)) < ENGINE_TOL


def test_four_bar_ik_round_trip_and_derivatives():
    qa = np.linspace(-1.0, 1.0, 7)[:, None]
    fk = mb.forward_kinematics(FOUR_BAR, qa)
    T = mb.site_pose(FOUR_BAR, fk.q, "coupler_point")
    ik = mb.inverse_kinematics(FOUR_BAR, "coupler_point", T)
    assert ik.converged.all()
    assert np.max(np.abs(ik.q_act - qa)) < ROUND_TRIP_TOL
    assert np.max(np.abs(ik.q - fk.q)) < ROUND_TRIP_TOL
    J = mb.site_jacobian(FOUR_BAR, fk.q, "coupler_point")
    H = mb.site_hessian(FOUR_BAR, fk.q, "coupler_point")
    assert J.shape == (7, 6, 1) and H.shape == (7, 6, 1, 1)
    assert np.max(np.abs(J - fd_site_jacobian(FOUR_BAR, fk.q, "coupler_point"))) < FD_TOL
    assert np.max(np.abs(H - fd_site_hessian(FOUR_BAR, fk.q, "coupler_point"))) < FD_TOL


def test_four_bar_rocker_rate_is_the_freudenstein_derivative():
    """G's rocker row equals dθ4/dθ2 from the implicit derivative of the Freudenstein equation."""
    fk = mb.forward_kinematics(FOUR_BAR, np.linspace(-1, 1, 5)[:, None])
    G = mb.influence(FOUR_BAR, fk.q).G
    t2, t4 = np.pi / 2 + fk.q[:, 0], np.pi / 2 + fk.q[:, 2]
    K1, K2 = D / A, D / C
    # F(t2, t4) = K1 cos t4 - K2 cos t2 + K3 - cos(t2 - t4) = 0
    dF2 = K2 * np.sin(t2) + np.sin(t2 - t4)
    dF4 = -K1 * np.sin(t4) - np.sin(t2 - t4)
    assert np.max(np.abs(G[:, 2, 0] - (-dF2 / dF4))) < CLOSED_FORM_TOL


def test_mjcf_round_trip_is_the_same_mechanism():
    for mech in (FOUR_BAR, _rssr(), _four_bar_weld()):
        back = mb.from_mjcf(mb.to_mjcf(mech))
        assert [b.name for b in back.bodies] == [b.name for b in mech.bodies]
        assert back.actuated == mech.actuated
        for b1, b2 in zip(back.bodies, mech.bodies, strict=True):
            assert b1.parent == b2.parent and [j.type for j in b1.joints] == [j.type for j in b2.joints]
            assert np.allclose(b1.pos, b2.pos, atol=1e-15) and np.allclose(b1.quat, b2.quat, atol=1e-15)
            for j1, j2 in zip(b1.joints, b2.joints, strict=True):
                assert np.allclose(j1.axis, j2.axis, atol=1e-15) and np.isclose(j1.ref, j2.ref, atol=1e-15)
            if b2.inertial is not None:
                assert np.allclose(b1.inertial.mass, b2.inertial.mass)
        for c1, c2 in zip(back.closures, mech.closures, strict=True):
            assert (c1.kind, c1.body1, c1.body2) == (c2.kind, c2.body1, c2.body2)
            for f in ("anchor1", "anchor2", "relpos", "relquat"):
                assert np.allclose(getattr(c1, f), getattr(c2, f), atol=1e-12), (mech.name, f)
        assert {s.name: s for s in back.sites} == {s.name: s for s in mech.sites} or all(
            np.allclose(s.pos, mech.site(s.name).pos, atol=1e-15) for s in back.sites
        )


def test_point_and_weld_rows_equal_mujoco_efc_J():
    """Our constraint residual and Jacobian rows against MuJoCo's (any q, not only assembled)."""
    rng = np.random.default_rng(0)
    b = mb.Builder("mixed")
    b.body("crank", joints=[b.hinge("t1", axis=(0, 0, 1))])
    b.body("coupler", parent="crank", pos=(0.3, 0, 0), joints=[b.ball("s1", pos=(0.01, 0.02, 0))])
    b.body(
        "rocker",
        pos=(0.2, 0.9, 0.1),
        quat=(0.9, 0.1, 0.3, 0),
        joints=[b.hinge("t4", axis=(1, 0, 0)), b.slide("d4", axis=(0, 1, 1))],
    )
    b.body("float", pos=(0.5, 0.5, 0.5), joints=[b.free("f")])
    b.connect("S2", "coupler", "rocker", anchor1=(0.1, 0.8, 0.3))
    b.weld("W", "crank", "float", anchor2=(0.1, 0.0, 0.2))
    mech = b.build()
    m = mujoco.MjModel.from_xml_string(mb.to_mjcf(mech))
    d = mujoco.MjData(m)
    for _ in range(5):
        q = mech.q0 + 0.3 * rng.standard_normal(mech.nq)
        d.qpos[:] = q
        mujoco.mj_forward(m, d)
        J = d.efc_J.reshape(d.nefc, m.nv)
        r = mb.constraint_residual(mech, d.qpos)
        K = mb.constraint_jacobian(mech, d.qpos)
        rows = [0, 1, 2, 3, 4, 5]  # the connect, then the weld's position rows
        assert np.max(np.abs(r[rows] - d.efc_pos[rows])) < ENGINE_TOL
        assert np.max(np.abs(K[rows] - J[rows])) < ENGINE_TOL


def test_constraint_jacobian_rate_is_the_derivative_along_the_motion():
    rng = np.random.default_rng(1)
    for mech in (_rssr(), _four_bar_weld()):
        q = mech.q0 + 0.2 * rng.standard_normal((3, mech.nq))
        qd = rng.standard_normal((3, mech.nv))
        from robomech.multibody._tree import normalize_quaternions

        from ._reference import integrate

        q = normalize_quaternions(mech.tree, q)

        def K_along(t, q=q, qd=qd, mech=mech):
            return mb.constraint_jacobian(mech, integrate(mech.tree, q, qd * t[..., None]))

        Kd_num = numerical_jacobian(lambda t: np.moveaxis(K_along(t[..., 0]), 0, 0), np.zeros((3, 1)))[..., 0]
        Kd = mb.constraint_jacobian_rate(mech, q, qd)
        assert np.max(np.abs(Kd - Kd_num)) < FD_TOL


def test_spatial_rssr_with_ball_joint_fk_j_h_and_mujoco():
    mech = _rssr()
    qa = np.linspace(-0.6, 0.6, 5)[:, None]
    fk = mb.forward_kinematics(mech, qa)
    assert fk.converged.all()
    assert np.max(mujoco_closure(mech, fk.q)) < ENGINE_TOL
    J = mb.site_jacobian(mech, fk.q, "tip")
    H = mb.site_hessian(mech, fk.q, "tip")
    assert np.max(np.abs(J - fd_site_jacobian(mech, fk.q, "tip"))) < FD_TOL
    assert np.max(np.abs(H - fd_site_hessian(mech, fk.q, "tip"))) < FD_TOL
    # the coupler spins idly about S1-S2: K_p loses one rank, the site Jacobian stays unique
    inf = mb.influence(mech, fk.q)
    assert np.all(inf.passive_rank == inf.n_passive - 1)


def test_weld_cut_four_bar_equals_the_connect_cut_one():
    mech = _four_bar_weld()
    qa = np.linspace(-1.0, 1.0, 5)[:, None]
    fk = mb.forward_kinematics(mech, qa)
    ref = mb.forward_kinematics(FOUR_BAR, qa)
    assert fk.converged.all()
    assert np.max(np.abs(fk.q[:, 2] - ref.q[:, 2])) < CLOSED_FORM_TOL
    assert np.max(mujoco_closure(mech, fk.q)) < ENGINE_TOL


def test_revolute_closure_overconstrained_four_bar():
    """A four-bar whose cut is a hinge: 6 equations, 5 independent; Grübler would say -2, it still moves."""
    b = mb.Builder("four-bar-hinge-cut")
    r = (np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4))
    b.body("crank", quat=r, joints=[b.hinge("theta2")])
    b.body("coupler", parent="crank", pos=(0.3, 0, 0), quat=(r[0], 0, 0, -r[3]), joints=[b.hinge("theta3")])
    b.body("rocker", pos=(0.9, 0, 0), quat=r, joints=[b.hinge("theta4")])
    b.revolute("C", "coupler", "rocker", anchor1=(0.9, 0.5, 0), axis=(0, 0, 1))
    b.site("p", "coupler", pos=(0.45, 0.45, 0))
    b.actuate("theta2")
    mech = b.build()
    qa = np.linspace(-1.0, 1.0, 5)[:, None]
    fk = mb.forward_kinematics(mech, qa)
    assert fk.converged.all()
    assert np.max(np.abs(_freudenstein(fk.q))) < CLOSED_FORM_TOL
    assert np.max(np.abs(mb.site_jacobian(mech, fk.q, "p") - fd_site_jacobian(mech, fk.q, "p"))) < FD_TOL
    assert np.max(mujoco_closure(mech, fk.q)) < ENGINE_TOL


def test_helical_and_polynomial_couplings():
    b = mb.Builder("screw")
    b.body("nut", joints=[*b.helical("h", axis=(0, 0, 1), pitch=0.01)])
    b.body("arm", parent="nut", pos=(0.2, 0, 0), joints=[b.hinge("a2", axis=(0, 1, 0))])
    b.couple("poly", "a2", "h_r", (0.1, 0.5, -0.2, 0.05, 0.0))
    b.site("tip", "arm", pos=(0.1, 0, 0.05))
    b.actuate("h_r")
    mech = b.build()
    qa = np.linspace(-2, 2, 5)[:, None]
    fk = mb.forward_kinematics(mech, qa)
    assert fk.converged.all()
    assert np.max(np.abs(fk.q[:, 1] - 0.01 * qa[:, 0])) < CLOSED_FORM_TOL
    x = qa[:, 0]
    assert np.max(np.abs(fk.q[:, 2] - (0.1 + 0.5 * x - 0.2 * x**2 + 0.05 * x**3))) < CLOSED_FORM_TOL
    assert np.max(mujoco_closure(mech, fk.q)) < ENGINE_TOL
    assert np.max(np.abs(mb.site_hessian(mech, fk.q, "tip") - fd_site_hessian(mech, fk.q, "tip"))) < FD_TOL


def test_one_bad_sample_never_spoils_the_batch():
    qa = np.array([[0.2], [np.nan], [0.4], [np.inf]])
    fk = mb.forward_kinematics(FOUR_BAR, qa)
    assert fk.converged.tolist() == [True, False, True, False]
    assert np.all(np.isnan(fk.q[[1, 3]])) and np.all(np.isfinite(fk.q[[0, 2]]))
    good = mb.forward_kinematics(FOUR_BAR, qa[[0, 2]])
    assert np.array_equal(fk.q[[0, 2]], good.q)


def test_unassemblable_sample_is_flagged():
    """A coupler point target outside the workspace cannot be reached: converged False, others fine."""
    fk = mb.forward_kinematics(FOUR_BAR, np.array([[0.3], [0.5]]))
    T = mb.site_pose(FOUR_BAR, fk.q, "coupler_point")
    far = T.copy()
    far[0, :3, 3] += 5.0  # 5 m away: beyond any link length sum
    ik = mb.inverse_kinematics(FOUR_BAR, "coupler_point", far)
    assert ik.converged.tolist() == [False, True]
    assert np.abs(ik.q_act[1, 0] - 0.5) < ROUND_TRIP_TOL
    assert ik.pose_error[0] > 1.0


def test_bad_input_raises_naming_the_argument():
    with pytest.raises(ValueError, match="q_act"):
        mb.forward_kinematics(FOUR_BAR, np.zeros((3, 2)))
    with pytest.raises(ValueError, match="mech"):
        mb.forward_kinematics("four_bar", np.zeros(1))
    with pytest.raises(ValueError, match="q"):  # inf is a wrong input; NaN a failed sample (chains)
        mb.site_pose(FOUR_BAR, np.full(3, np.inf), "coupler_point")
    assert np.isnan(mb.site_pose(FOUR_BAR, np.full(3, np.nan), "coupler_point")).all()
    with pytest.raises(ValueError, match="site"):
        mb.site_jacobian(FOUR_BAR, FOUR_BAR.q0, "nope")
    with pytest.raises(ValueError, match="T_target"):
        mb.inverse_kinematics(FOUR_BAR, "coupler_point", np.zeros((4, 3)))
    with pytest.raises(ValueError, match="tendon"):
        mb.from_mjcf(
            """<mujoco><worldbody><body><joint name="j"/><geom size=".1"/><site name="s"/></body>
            <site name="w"/></worldbody><tendon><spatial><site site="w"/><site site="s"/></spatial></tendon>
            </mujoco>"""
        )
    with pytest.raises(ValueError, match="actuator"):
        mb.from_mjcf(
            """<mujoco><worldbody><body><joint name="j"/><geom size=".1"/><site name="s"/></body></worldbody>
            <actuator><motor site="s" gear="1 0 0 0 0 0"/></actuator></mujoco>"""
        )
    with pytest.raises(ValueError, match="parent"):
        mb.Mechanism(bodies=(mb.Body("a", parent="b"),))
    with pytest.raises(ValueError, match="actuated"):
        mb.Mechanism(bodies=(mb.Body("a", joints=(mb.Joint("j", "ball"),)),), actuated=("j",))


def test_mjcf_semantics_degrees_defaults_and_qpos0():
    """Degrees, defaults classes and MuJoCo's qpos0 anchor rule come from MuJoCo's own compiler."""
    xml = """<mujoco><compiler angle="degree"/>
      <default><joint axis="0 1 0"/></default>
      <worldbody><body name="a" euler="0 0 30"><joint name="j" ref="10"/><geom size=".1"/>
        <body name="b" pos="0.5 0 0"><joint name="k" type="slide" axis="1 0 0"/><geom size=".1"/>
        </body></body>
        <body name="c" pos="0.6 0.3 0"><freejoint name="l"/><geom size=".1"/></body></worldbody>
      <equality><connect body1="b" body2="c" anchor="0.1 0 0"/></equality>
      <actuator><motor joint="k"/><motor joint="j"/></actuator></mujoco>"""
    mech = mb.from_mjcf(xml)
    assert mech.actuated == ("k", "j")
    assert np.isclose(mech.joint("j").ref, np.deg2rad(10))
    assert np.allclose(mech.joint("j").axis, (0, 1, 0))
    assert np.max(np.abs(mb.constraint_residual(mech, mech.q0))) < ENGINE_TOL
    fk = mb.forward_kinematics(mech, np.array([[0.05, 0.3], [0.1, 0.1]]))
    assert fk.converged.all()
    assert np.max(mujoco_closure(xml, fk.q)) < ENGINE_TOL


def test_bodies_follow_mujoco_order_so_q_is_its_qpos():
    """A builder that adds a subtree late still gives q in MuJoCo's depth-first qpos order."""
    b = mb.Builder("order")
    b.body("a", joints=[b.hinge("ja")])
    b.body("b", joints=[b.hinge("jb")])
    b.body("a_child", parent="a", pos=(0.1, 0, 0), joints=[b.slide("jc", axis=(1, 0, 0))])
    mech = b.build()
    assert [x.name for x in mech.bodies] == ["a", "a_child", "b"]
    m = mujoco.MjModel.from_xml_string(mb.to_mjcf(mech))
    assert [m.joint(i).name for i in range(m.njnt)] == list(mech.tree.jnt_names) == ["ja", "jc", "jb"]


def test_continuation_along_a_trajectory_keeps_the_branch():
    """From the crossed assembly of the four-bar, each step guessed from the last stays crossed."""
    q0 = FOUR_BAR.q0
    # the crossed branch at the reference input: reflect C about the line B-D (crank at 90 deg)
    B, D = np.array([0.0, 0.3]), np.array([0.9, 0.0])
    C = np.array([0.9, 0.8])
    e = (D - B) / np.linalg.norm(D - B)
    Cx = B + 2 * ((C - B) @ e) * e - (C - B)
    t3 = np.arctan2(*(Cx - B)[::-1])  # coupler angle, world
    t4 = np.arctan2(*(Cx - D)[::-1])
    crossed = np.array([q0[0], t3 - 0.0 - np.arctan2(0.5, 0.9), t4 - np.pi / 2])
    assert np.max(np.abs(mb.constraint_residual(FOUR_BAR, crossed))) < CLOSED_FORM_TOL
    q, side = crossed, []
    for x in np.linspace(0.0, 2.0, 21):
        fk = mb.forward_kinematics(FOUR_BAR, np.array([x]), guess=q)
        assert fk.converged
        q = fk.q
        side.append(np.sign(np.sin(q[2] - q[0])))  # the crossed branch keeps its orientation sign
        assert abs(_freudenstein(q)) < CLOSED_FORM_TOL
    assert len(set(side)) == 1
    # the open branch from the reference configuration has the other sign
    open_ = mb.forward_kinematics(FOUR_BAR, np.array([2.0]), steps=8).q
    assert np.sign(np.sin(open_[2] - open_[0])) != side[0]


@settings(max_examples=40)
@given(x=st.floats(-np.pi, np.pi), rate=st.floats(-5.0, 5.0))
def test_property_four_bar_closes_and_G_is_admissible(x, rate):
    """Any crank angle assembles (Grashof crank-rocker), satisfies Freudenstein, and K G qd = 0."""
    fk = mb.forward_kinematics(FOUR_BAR, np.array([x]), steps=4)
    assert fk.converged
    assert abs(_freudenstein(fk.q)) < CLOSED_FORM_TOL
    G = mb.influence(FOUR_BAR, fk.q, second_order=False).G
    K = mb.constraint_jacobian(FOUR_BAR, fk.q)
    assert np.max(np.abs(K @ G @ np.array([rate]))) < CLOSED_FORM_TOL * max(1.0, abs(rate))


def test_quat_from_matrix_refuses_a_frame_that_is_not_a_rotation():
    # A non-orthogonal frame was once projected silently onto some rotation (leg 3 of the spherical
    # leg got undocumented joint axes); a reflection or a skewed matrix must be refused by name.
    from robomech.multibody._model import _quat_from_matrix

    c, s = np.cos(0.3), np.sin(0.3)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    q = _quat_from_matrix(R)
    assert np.isclose(q[0], np.cos(0.15)) and np.isclose(q[3], np.sin(0.15))
    skewed = R.copy()
    skewed[:, 1] = [0.2, 0.9, 0.1]
    with pytest.raises(ValueError, match="proper rotation"):
        _quat_from_matrix(skewed)
    with pytest.raises(ValueError, match="proper rotation"):
        _quat_from_matrix(np.diag([1.0, 1.0, -1.0]))


@settings(max_examples=50, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 40), scale=st.floats(-30.0, 30.0))
def test_tree_cross_product_equals_numpy_bit_for_bit(seed, n, scale):
    """The numpy reference kinematics' cross product (_reference._cross3) is np.cross's arithmetic:
    equal bit for bit."""
    from ._reference import _cross3

    rng = np.random.default_rng(seed)
    a, b = rng.standard_normal((2, n, 3)) * 10.0**scale
    assert np.array_equal(_cross3(a, b), np.cross(a, b))
