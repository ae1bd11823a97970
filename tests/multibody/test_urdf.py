"""from_urdf: a UR5-like arm and a mimic-joint gripper against the URDF's own transform chain,
Pinocchio's URDF parser (FK, frame Jacobian, rnea, crba) and MuJoCo."""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from robomech import multibody as mb

from ._helpers import axis_angle as _axis_angle
from ._helpers import urdf_rpy as _rpy

DATA = Path(__file__).parent / "data"
ARM = DATA / "ur5_like.urdf"
GRIPPER = DATA / "gripper_mimic.urdf"

# Double-precision agreement between independently formulated chains/engines on a ~1 m arm with
# ~10 kg links: products of a handful of 4x4 matrices and O(10) RNEA terms lose a few ulps.
TOL_FK = 1e-12
# Batched vs per-sample calls run the same kernel code: they agree to rounding.
TOL_BATCH = 1e-13
TOL_ENGINE = 1e-9  # relative, the acceptance bound for dynamics against Pinocchio/MuJoCo


def _load(path, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # the arm's missing meshes (tested separately)
        return mb.from_urdf(path, **kw)


def _urdf_chain(path, q_by_joint, link):
    """World pose of ``link``: the URDF's joint origins composed with the joint motions, root to link."""
    root = ET.parse(path).getroot()
    by_child = {j.find("child").get("link"): j for j in root.findall("joint")}
    T = np.eye(4)
    name = link
    while name in by_child:
        j = by_child[name]
        o = j.find("origin")
        xyz = [float(v) for v in (o.get("xyz", "0 0 0") if o is not None else "0 0 0").split()]
        rpy = [float(v) for v in (o.get("rpy", "0 0 0") if o is not None else "0 0 0").split()]
        To = np.eye(4)
        To[:3, :3], To[:3, 3] = _rpy(*rpy), xyz
        Tq = np.eye(4)
        if j.get("type") != "fixed":
            ax = j.find("axis")
            a = [float(v) for v in (ax.get("xyz") if ax is not None else "1 0 0").split()]
            qj = q_by_joint[j.get("name")]
            if j.get("type") == "prismatic":
                Tq[:3, 3] = qj * np.asarray(a) / np.linalg.norm(a)
            else:
                Tq[:3, :3] = _axis_angle(a, qj)
        T = To @ Tq @ T
        name = j.find("parent").get("link")
    return T


@pytest.fixture(scope="module")
def arm():
    return _load(ARM)


@pytest.fixture(scope="module")
def qs():
    return np.random.default_rng(24).uniform(-np.pi, np.pi, (5, 6))


def test_arm_structure(arm):
    names = [j.get("name") for j in ET.parse(ARM).getroot().findall("joint") if j.get("type") != "fixed"]
    assert arm.actuated == tuple(names)
    assert "tool0" in [b.name for b in arm.bodies]  # the fixed-joint link is kept, not fused
    assert {s.name for s in arm.sites} >= {"base_link", "wrist_3_link", "tool0"}


def test_missing_meshes_warn_not_block():
    with pytest.warns(UserWarning, match="mesh"):
        mb.from_urdf(ARM)


def test_tool_pose_against_urdf_chain(arm, qs):
    T = mb.site_pose(arm, qs, "tool0")
    for k, q in enumerate(qs):
        for link in ("tool0", "wrist_2_link", "upper_arm_link"):
            ref = _urdf_chain(ARM, dict(zip(arm.actuated, q, strict=True)), link)
            got = mb.site_pose(arm, q, link)
            np.testing.assert_allclose(got, ref, atol=TOL_FK)
        np.testing.assert_allclose(
            T[k], _urdf_chain(ARM, dict(zip(arm.actuated, q, strict=True)), "tool0"), atol=TOL_FK
        )


def test_open_chain_fk_is_identity(arm, qs):
    fk = mb.forward_kinematics(arm, qs)
    assert fk.converged.all()
    np.testing.assert_allclose(fk.q, qs, atol=0)


def test_against_pinocchio(arm, qs):
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromUrdf(str(ARM))
    data = model.createData()
    fid = model.getFrameId("tool0")
    rng = np.random.default_rng(1)
    qd, qdd = rng.normal(size=qs.shape), rng.normal(size=qs.shape)
    tau = mb.generalized_forces(arm, qs, qd, qdd)
    M = mb.mass_matrix(arm, qs)
    J = mb.site_jacobian(arm, qs, "tool0")
    for k, q in enumerate(qs):
        pin.framesForwardKinematics(model, data, q)
        np.testing.assert_allclose(mb.site_pose(arm, q, "tool0"), data.oMf[fid].homogeneous, atol=TOL_FK)
        Jp = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(J[k], np.vstack([Jp[3:], Jp[:3]]), atol=TOL_FK)
        ref = pin.rnea(model, data, q, qd[k], qdd[k])
        np.testing.assert_allclose(tau[k], ref, rtol=TOL_ENGINE, atol=TOL_ENGINE * np.abs(ref).max())
        Mp = pin.crba(model, data, q)
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        np.testing.assert_allclose(M[k], Mp, rtol=TOL_ENGINE, atol=TOL_ENGINE * np.abs(Mp).max())


def test_against_mujoco(arm, qs):
    mujoco = pytest.importorskip("mujoco")
    m = mujoco.MjModel.from_xml_string(mb.to_mjcf(arm))
    d = mujoco.MjData(m)
    rng = np.random.default_rng(2)
    qd, qdd = rng.normal(size=qs.shape), rng.normal(size=qs.shape)
    tau = mb.generalized_forces(arm, qs, qd, qdd)
    for k, q in enumerate(qs):
        d.qpos[:], d.qvel[:], d.qacc[:] = q, qd[k], qdd[k]
        mujoco.mj_inverse(m, d)
        np.testing.assert_allclose(
            tau[k], d.qfrc_inverse, rtol=TOL_ENGINE, atol=TOL_ENGINE * np.abs(d.qfrc_inverse).max()
        )


def test_gripper_mimic_is_a_coupling():
    g = _load(GRIPPER)
    assert g.actuated == ("wrist", "left_joint")
    (cp,) = [c for c in g.couplings if c.joint1 == "right_joint"]
    assert cp.joint2 == "left_joint" and cp.polycoef[:2] == (0.01, -1.0)
    q_act = np.array([[0.4, 0.015], [-1.0, 0.03]])
    fk = mb.forward_kinematics(g, q_act)
    assert fk.converged.all()
    for q, qa in zip(fk.q, q_act, strict=True):
        qj = {"wrist": qa[0], "left_joint": qa[1], "right_joint": -qa[1] + 0.01}
        for link in ("left_tip", "right_finger"):
            np.testing.assert_allclose(mb.site_pose(g, q, link), _urdf_chain(GRIPPER, qj, link), atol=TOL_FK)


def test_actuated_and_closures_arguments():
    g = _load(GRIPPER, actuated=["left_joint"])
    assert g.actuated == ("left_joint",)
    with pytest.raises(ValueError, match="fixed joint"):
        _load(GRIPPER, actuated=["left_tip_joint"])
    with pytest.raises(ValueError, match="actuated"):
        _load(GRIPPER, actuated=["nope"])
    # a closure a URDF cannot hold: weld the left tip to the palm, as a Closure and as an MJCF snippet
    snippet = '<equality><weld name="w" body1="palm" body2="left_tip"/></equality>'
    a = _load(GRIPPER, actuated=[], closures=snippet)
    assert [c.kind for c in a.closures] == ["rigid"]
    b = _load(GRIPPER, actuated=[], closures=[a.closures[0]])
    assert b.closures == a.closures
    with pytest.raises(ValueError, match="closures"):
        _load(GRIPPER, closures=[1])


@pytest.mark.parametrize("bad", [3, 2.5, object()])
def test_closures_and_actuated_that_are_no_sequence_name_the_argument(bad):
    with pytest.raises(ValueError, match="Expected closures"):
        _load(GRIPPER, closures=bad)
    with pytest.raises(ValueError, match="Expected actuated"):
        _load(GRIPPER, actuated=bad)


def test_a_closure_snippet_that_does_not_compile_names_closures():
    """MuJoCo's error on the snippet is reported against ``closures``, not the internal MJCF document."""
    snippet = '<equality><weld name="w" body1="palm" body2="no_such_link"/></equality>'
    with pytest.raises(ValueError, match=r"Expected closures.*no_such_link|Expected closures.*MuJoCo"):
        _load(GRIPPER, actuated=[], closures=snippet)


FLOATING = """<robot name="floating_slide">
  <link name="world"/>
  <link name="base"><inertial><origin xyz="0.01 0 0.02" rpy="0.1 0 0"/><mass value="5"/>
    <inertia ixx="0.1" iyy="0.12" izz="0.08" ixy="0.01" ixz="0" iyz="0.002"/></inertial></link>
  <link name="slider"><inertial><origin xyz="0 0.02 0"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="float" type="floating"><parent link="world"/><child link="base"/><origin xyz="0 0 1"/></joint>
  <joint name="s" type="prismatic"><parent link="base"/><child link="slider"/>
    <origin xyz="0.1 0 0" rpy="0 0.3 0"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>"""


def test_a_floating_joint_is_a_free_base_not_an_actuator():
    """``actuated=None`` actuates the revolute, continuous and prismatic joints only; naming the floating
    joint is refused with its type."""
    mech = _load(FLOATING)
    assert mech.actuated == ("s",)
    assert [j.type for b in mech.bodies for j in b.joints] == ["free", "slide"]
    with pytest.raises(ValueError, match="floating"):
        _load(FLOATING, actuated=["float"])


def test_a_root_link_named_world_is_no_platform():
    """The URDF's root link ``world`` is a site on the world body; the default platform of ``mobility`` is
    the first site's body that moves (here ``base``), not the world (which moves with no DOF)."""
    m = mb.mobility(_load(FLOATING))
    assert _load(FLOATING).sites[0].body == "world"  # control: the first site is the world's
    assert m.platform == "base" and m.platform_dof == 6


def test_from_mjcf_refuses_urdf():
    with pytest.raises(ValueError, match="from_urdf"):
        mb.from_mjcf(GRIPPER)
    with pytest.raises(ValueError, match="URDF"):
        mb.from_urdf(mb.gallery.path("four_bar"))


def test_cli_verify_and_export(tmp_path, capsys):
    from robomech.cli import main

    out = tmp_path / "g.xml"
    assert main(["export", str(GRIPPER), "--mjcf", str(out)]) == 0
    back = mb.from_mjcf(out)
    assert back.actuated == ("wrist", "left_joint")
    assert main(["verify", str(ARM)]) == 0
    capsys.readouterr()


@pytest.mark.parametrize("n", [1, 300])
def test_batched_equals_per_sample_and_engines(arm, n):
    """Batches of 1 and 300: each sample equals its own call and Pinocchio (from the URDF text) and
    MuJoCo's mj_rne / mj_fullM."""
    pin = pytest.importorskip("pinocchio")
    mujoco = pytest.importorskip("mujoco")
    model = pin.buildModelFromXML(ARM.read_text())
    data = model.createData()
    m = mujoco.MjModel.from_xml_string(mb.to_mjcf(arm))
    d = mujoco.MjData(m)
    rng = np.random.default_rng(n)
    q, qd, qdd = (rng.uniform(-np.pi, np.pi, (n, 6)) for _ in range(3))
    tau = mb.generalized_forces(arm, q, qd, qdd)
    M = mb.mass_matrix(arm, q)
    T = mb.site_pose(arm, q, "tool0")
    fid = model.getFrameId("tool0")
    for k in range(0, n, max(1, n // 30)):
        tk = mb.generalized_forces(arm, q[k], qd[k], qdd[k])
        np.testing.assert_allclose(tk, tau[k], rtol=TOL_BATCH, atol=TOL_BATCH * np.abs(tau[k]).max())
        np.testing.assert_allclose(
            mb.mass_matrix(arm, q[k]), M[k], rtol=TOL_BATCH, atol=TOL_BATCH * np.abs(M[k]).max()
        )
        pin.framesForwardKinematics(model, data, q[k])
        np.testing.assert_allclose(T[k], data.oMf[fid].homogeneous, atol=TOL_FK)
        ref = pin.rnea(model, data, q[k], qd[k], qdd[k])
        np.testing.assert_allclose(tau[k], ref, rtol=TOL_ENGINE, atol=TOL_ENGINE * np.abs(ref).max())
        Mp = pin.crba(model, data, q[k])
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        np.testing.assert_allclose(M[k], Mp, rtol=TOL_ENGINE, atol=TOL_ENGINE * np.abs(Mp).max())
        d.qpos[:], d.qvel[:], d.qacc[:] = q[k], qd[k], np.zeros(6)
        mujoco.mj_forward(m, d)
        Mm = np.zeros((6, 6))
        mujoco.mj_fullM(m, d, Mm)
        np.testing.assert_allclose(M[k], Mm, rtol=TOL_ENGINE, atol=TOL_ENGINE * np.abs(Mm).max())
        d.qacc[:] = qdd[k]
        mujoco.mj_rne(m, d, 1, rne := np.zeros(6))
        np.testing.assert_allclose(tau[k], rne, rtol=TOL_ENGINE, atol=TOL_ENGINE * np.abs(rne).max())
