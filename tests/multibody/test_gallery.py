"""The gallery of textbook mechanisms: each file loads, has its known properties, and closes in MuJoCo.

Known properties and their sources: Bennett's input-output relation (Bennett 1903; e.g. Phillips,
Freedom in Machinery, 1990); the 3-RRR's closed-form leg equations (Gosselin & Angeles 1990); the
Delta's constant platform orientation and its arm equations (Clavel 1988); the 3-RPS's 1T2R mobility
and leg-plane constraint (Lee & Shah 1988); the Gough–Stewart leg lengths (Stewart 1965).
"""

from __future__ import annotations

import numpy as np
import pytest

from robomech import multibody as mb
from robomech.multibody import gallery as g

from ._helpers import fd_site_hessian, fd_site_jacobian, mujoco_closure
from .test_core import ENGINE_TOL, FD_TOL, ROUND_TRIP_TOL

# Closed-form identities evaluated at assembled configurations: rounding of O(1) coordinates.
CLOSED_FORM_TOL = 1e-12
# Perturbation of the inputs around the reference configuration for the random samples, 0.08 rad for
# hinges and 0.08 L for slides: well inside every mechanism's workspace (checked: the samples
# assemble).  The 3-RPS's small platform tilts ~45 deg for leg-length differences of 0.1 m, so a
# fixed 0.08 m would leave its workspace.
SPREAD = 0.08

GALLERY = {name: g.load(name) for name in g.NAMES}


def _samples(mech, n=4, seed=0):
    rng = np.random.default_rng(seed)
    scale = np.where(mech.tree.dof_translational[mech.tree.act_dof], mech.length, 1.0)
    qa = mech.q0[mech.tree.act_qadr] + SPREAD * scale * rng.uniform(-1, 1, (n, len(mech.actuated)))
    fk = mb.forward_kinematics(mech, qa)
    assert fk.converged.all(), fk.residual
    return qa, fk


# The builders compute anchors with trigonometry: libm/NumPy versions differ in the last bits, so the shipped
# files and a fresh build agree to rounding (of the mechanism's 1 m scale), not character for character.
SHIPPED_ATOL = 1e-13


def _xml_numbers_equal(a, b) -> None:
    assert a.tag == b.tag and sorted(a.attrib) == sorted(b.attrib), (a.tag, a.attrib, b.attrib)
    for key, va in a.attrib.items():
        vb = b.attrib[key]
        try:
            xa = np.array(va.split(), dtype=float)
            xb = np.array(vb.split(), dtype=float)
        except ValueError:
            assert va == vb, (a.tag, key)
            continue
        assert xa.shape == xb.shape, (a.tag, key)
        np.testing.assert_allclose(xa, xb, rtol=0, atol=SHIPPED_ATOL, err_msg=f"{a.tag} {key}")
    assert len(a) == len(b), a.tag
    for ca, cb in zip(a, b, strict=True):
        _xml_numbers_equal(ca, cb)


@pytest.mark.parametrize("name", list(g.BUILDERS))
def test_shipped_file_is_what_the_builder_gives(name):
    import xml.etree.ElementTree as ET

    with open(g.path(name)) as f:
        shipped = f.read()
    _xml_numbers_equal(ET.fromstring(shipped), ET.fromstring(g.mjcf(name)))


@pytest.mark.parametrize("name", g.NAMES)
def test_fk_ik_round_trip_derivatives_and_engine_closure(name):
    mech = GALLERY[name]
    site = mech.sites[0].name
    qa, fk = _samples(mech)
    assert np.max(mujoco_closure(g.path(name).read_text(), fk.q)) < ENGINE_TOL
    T = mb.site_pose(mech, fk.q, site)
    ik = mb.inverse_kinematics(mech, site, T)
    assert ik.converged.all()
    assert np.max(np.abs(ik.q_act - qa)) < ROUND_TRIP_TOL
    assert np.max(np.abs(mb.site_pose(mech, ik.q, site) - T)) < ROUND_TRIP_TOL
    assert np.max(mujoco_closure(g.path(name).read_text(), ik.q)) < ENGINE_TOL
    J = mb.site_jacobian(mech, fk.q[:2], site)
    H = mb.site_hessian(mech, fk.q[:2], site)
    # central-difference error grows with the size of what is differenced (the 3-RPS's H reaches ~30)
    assert np.max(np.abs(J - fd_site_jacobian(mech, fk.q[:2], site))) < FD_TOL * max(1.0, np.abs(J).max())
    assert np.max(np.abs(H - fd_site_hessian(mech, fk.q[:2], site))) < FD_TOL * max(1.0, np.abs(H).max())


KNOWN = {  # dof, idle, Grübler–Kutzbach, platform rotational DOF
    "four_bar": (1, 0, 0, 0),
    "bennett": (1, 0, -2, 1),
    "planar_3rrr": (3, 0, -3, 1),
    "delta": (3, 6, 9, 0),
    "rps_3": (3, 0, 3, 2),
    "stewart": (6, 0, 6, 3),
}


@pytest.mark.parametrize("name", g.NAMES)
def test_mobility_is_the_known_one(name):
    m = mb.mobility(GALLERY[name])
    assert (m.dof, m.idle_dof, m.gruebler_kutzbach, m.platform_rotational_dof) == KNOWN[name]
    assert not m.singular and m.actuation == "exact"
    assert m.total_dof == m.gruebler_kutzbach + m.redundant_constraints
    if m.screw_theory is not None:  # serial legs: reciprocal screws agree with the constraint Jacobian
        assert m.screw_theory.dof == m.platform_dof
        assert m.screw_theory.rotational_dof == m.platform_rotational_dof


def test_bennett_input_output_relation():
    mech = GALLERY["bennett"]
    t1 = np.linspace(0.3, 2.6, 9)
    fk = mb.forward_kinematics(mech, t1[:, None], guess=mech.q0, steps=4)
    assert fk.converged.all()
    wrap = lambda x: (x + np.pi) % (2 * np.pi) - np.pi  # noqa: E731
    assert np.max(np.abs(wrap(fk.q[:, 1] - g.bennett_theta2(t1)))) < CLOSED_FORM_TOL
    assert np.max(np.abs(wrap(fk.q[:, 2] + t1))) < CLOSED_FORM_TOL
    assert np.max(np.abs(wrap(fk.q[:, 3] + fk.q[:, 1]))) < CLOSED_FORM_TOL


def test_planar_3rrr_leg_equations():
    mech = GALLERY["planar_3rrr"]
    _, fk = _samples(mech, 6, seed=3)
    T = mb.site_pose(mech, fk.q, "platform")
    Rb, rp, l1, l2 = (g.RRR[k] for k in ("base_radius", "platform_radius", "l1", "l2"))
    for i in range(3):
        gam = np.pi / 2 + 2 * np.pi / 3 * i
        A = Rb * np.array([np.cos(gam), np.sin(gam), 0])
        C = T[:, :3, :3] @ (rp * np.array([np.cos(gam), np.sin(gam), 0])) + T[:, :3, 3]
        th = fk.q[:, mech.qpos_address(f"base{i + 1}")]
        B = A + l1 * np.stack([np.cos(th), np.sin(th), 0 * th], axis=-1)
        assert np.max(np.abs(np.linalg.norm(C - B, axis=-1) - l2)) < CLOSED_FORM_TOL
    assert np.max(np.abs(T[:, 2, 3])) < CLOSED_FORM_TOL  # stays in its plane


def test_delta_platform_translates_and_arm_equations_hold():
    mech = GALLERY["delta"]
    _, fk = _samples(mech, 6, seed=4)
    T = mb.site_pose(mech, fk.q, "tcp")
    assert np.max(np.abs(T[:, :3, :3] - np.eye(3))) < CLOSED_FORM_TOL  # the parallelograms' purpose
    R, La, Lb, r = (g.DELTA[k] for k in ("base_radius", "arm", "rod", "platform_radius"))
    for i in range(3):
        gam = 2 * np.pi / 3 * i
        er, ez = np.array([np.cos(gam), np.sin(gam), 0]), np.array([0, 0, 1.0])
        th = fk.q[:, mech.qpos_address(f"theta{i + 1}")][:, None]
        J = R * er + La * (np.cos(th) * er - np.sin(th) * ez)
        E = T[:, :3, 3] + r * er
        assert np.max(np.abs(np.linalg.norm(E - J, axis=-1) - Lb)) < CLOSED_FORM_TOL
    # closed-form depth at equal arm angles
    fk2 = mb.forward_kinematics(mech, np.full((1, 3), 0.7), steps=3)
    z = mb.site_pose(mech, fk2.q, "tcp")[0, 2, 3]
    assert abs(z + g.delta_height(0.7)) < CLOSED_FORM_TOL


def test_3rps_leg_lengths_and_planes():
    mech = GALLERY["rps_3"]
    qa, fk = _samples(mech, 6, seed=5)
    T = mb.site_pose(mech, fk.q, "platform")
    Rb, rp, h = (g.RPS[k] for k in ("base_radius", "platform_radius", "height"))
    for i in range(3):
        gam = 2 * np.pi / 3 * i
        er, t = np.array([np.cos(gam), np.sin(gam), 0]), np.array([-np.sin(gam), np.cos(gam), 0])
        v = T[:, :3, :3] @ (rp * er) + T[:, :3, 3] - Rb * er
        l0 = np.linalg.norm(rp * er + [0, 0, h] - Rb * er)
        assert np.max(np.abs(np.linalg.norm(v, axis=-1) - (l0 + qa[:, i]))) < CLOSED_FORM_TOL
        assert np.max(np.abs(v @ t)) < CLOSED_FORM_TOL  # each leg in the plane normal to its revolute axis


def test_stewart_fk_inverts_the_closed_form_leg_lengths():
    mech = GALLERY["stewart"]
    B, P = g.stewart_points()
    p0 = np.array([0, 0, g.STEWART["height"]])
    l0 = np.linalg.norm(p0 + P - B, axis=-1)
    rng = np.random.default_rng(6)
    # random platform poses -> closed-form leg lengths -> generic FK -> the same poses
    from robomech.spatial import exp_so3

    R = exp_so3(0.1 * rng.uniform(-1, 1, (5, 3)))
    p = p0 + 0.05 * rng.uniform(-1, 1, (5, 3))
    lengths = np.linalg.norm(p[:, None] + np.einsum("nij,kj->nki", R, P) - B, axis=-1)
    fk = mb.forward_kinematics(mech, lengths - l0)
    assert fk.converged.all()
    T = mb.site_pose(mech, fk.q, "platform")
    assert np.max(np.abs(T[:, :3, :3] - R)) < CLOSED_FORM_TOL
    assert np.max(np.abs(T[:, :3, 3] - p)) < CLOSED_FORM_TOL
