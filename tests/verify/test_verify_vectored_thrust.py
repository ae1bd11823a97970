"""Paper 5 vectored thruster vs MuJoCo: the checks pass, and they fail for a deliberately wrong model."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("mujoco")

from robomech.mechanisms import vectored_thrust as vt
from robomech.verify import available_verifications
from robomech.verify import vectored_thrust as vv

TH = vt.VectoredThruster.paper()


def test_registered_and_all_checks_pass() -> None:
    v = available_verifications()["vectored-thrust"]
    checks = v.run()
    assert len(checks) >= 9
    failed = [(c.quantity, c.max_error, c.tolerance.value) for c in checks if not c.passed]
    assert not failed


def _paper_eq32_like(th: vt.VectoredThruster, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
    """Angular acceleration without the velocity-product (Lie-bracket) terms, as eq. (32) has it."""
    J = vt.jacobian(th, q).J
    return np.einsum("...ij,...j->...i", J, qdd)


def test_teeth_acceleration_without_lie_brackets_fails() -> None:
    checks = {c.quantity: c for c in vv.run(TH, omega_dot_model=_paper_eq32_like)}
    assert not checks["angular acceleration, RR tree (rel)"].passed
    assert not checks["angular acceleration, RRR tree (rel)"].passed
    assert checks["propeller tip position (rel)"].passed


def test_teeth_printed_eq12_fails_against_engine_tip() -> None:
    t = np.linspace(0.0, 2 * math.pi, 41)
    q, qd, qdd = vv.table1_trajectory(t)
    tr = vv.engine_trace(TH, t, q, qd, qdd)
    r = math.sqrt(2) / 2
    s1, c1, s2, c2 = np.sin(q[:, 0]), np.cos(q[:, 0]), np.sin(q[:, 1]), np.cos(q[:, 1])
    L, M, N = -r * s1 * s2, r * (s2 - c1 * c2), -r * s1 * c2
    n = np.sqrt(L * L + M * M + N * N)
    L, M, N = L / n, M / n, N / n
    printed = TH.propeller_arm * np.stack([-s1 * M, s2 * L + c2 * N, -c2 * M], -1)  # sin(phi1), as printed
    assert np.abs(printed - tr.tip_engine).max() > 1e-3
    assert np.abs(tr.tip_analytic - tr.tip_engine).max() < 1e-15


def test_mjcf_is_the_generic_export_of_the_description() -> None:
    import dataclasses

    import mujoco

    from robomech import multibody as mb

    th = dataclasses.replace(TH, propeller_arm=0.12)
    xml = vv.build_mjcf(th)
    assert 'name="propeller" pos="0.0 0.0 0.12"' in xml
    m = mujoco.MjModel.from_xml_string(xml)
    mech = vt.to_multibody(th)
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(m.njnt)]
    assert names == [j.name for b in mech.bodies for j in b.joints]
    assert m.nu == 0 and m.neq == 2  # the s13 hinge: two connects along its axis (mb.to_mjcf)
    assert mujoco.MjModel.from_xml_string(vv.build_mjcf(th, actuated=True)).nu == 2
    # the same bodies, joints and closures as the description read back
    back = mb.from_mjcf(xml)
    assert [b.name for b in back.bodies] == [b.name for b in mech.bodies]


def test_teeth_a_perturbed_parameter_fails() -> None:
    import dataclasses

    arc = {c.quantity: c for c in vv.run(TH, analytic=dataclasses.replace(TH, arc_angle=TH.arc_angle + 1e-3))}
    assert not arc["loop closure |efc_pos| (s13 hinge as 2 connects), m"].passed
    assert not arc["platform orientation, RRR tree (rel)"].passed
    assert not arc["angular velocity, RRR tree (rel)"].passed
    assert not arc["angular acceleration, RRR tree (rel)"].passed
    arm = {c.quantity: c for c in vv.run(TH, analytic=dataclasses.replace(TH, propeller_arm=0.08008))}
    assert not arm["propeller tip position (rel)"].passed
    assert arm["platform orientation (rel)"].passed  # the arm length changes no orientation
