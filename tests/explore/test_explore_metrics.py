"""The built-in studies' metrics against independent formulations (docs/explore.md defines them)."""

import dataclasses
import math

import numpy as np
import pytest

from robomech.explore import Variable, design_matrix, get_study, with_variables
from robomech.explore import _omnileg as om
from robomech.explore import _spherical_leg as sls
from robomech.explore import _vectored_thrust as vts
from robomech.mechanisms import omnileg as ol
from robomech.mechanisms import spherical_leg as sl
from robomech.mechanisms import vectored_thrust as vt

# Closed forms vs the kernels: rounding of O(1) trigonometry, a few hundred ulps.
ROUNDING = 1e-12
# Simpson with 13 points per axis vs the exact projected-area volume: measured relative error 6.0e-5 for
# all three designs (the integrand's shape does not change with L1, L4), bounded here with margin.
SIMPSON_RTOL = 1.5e-4
# Shoelace polygon of the projected boundary with 4 x 4000 edges: second-order in the edge length.
POLYGON_RTOL = 1e-6
# Monte Carlo mean of rms^2 vs the linearised prediction: 5 standard errors, plus the second-order
# terms the linearisation drops (errors of 0.1 deg near singular poses: measured 4 %).
MC_SIGMAS = 5.0
LINEARISATION_RTOL = 0.08
# Central differences of eq. (11) with a 1e-5 rad step: truncation ~1e-10, rounding ~1e-11 relative.
FD_STEP = 1e-5
FD_RTOL = 1e-7


def test_spherical_leg_dexterity_and_fraction_match_an_svd_of_the_jacobian():
    leg = sl.SphericalLeg.paper()
    rows = np.array([[leg.R, leg.r, leg.h]])
    res = sls.STUDY.evaluate_rows(rows, None)
    a, b = sls._task_grid()
    J = sl.jacobian(leg, a, b)  # (P, 3, 2), independent of the closed-form Gram eigenvalues
    s = np.linalg.svd(J, compute_uv=False)
    L = sl.inverse_kinematics(leg, a, b).lengths
    reach = np.all((L >= leg.length_min) & (L <= leg.length_max), -1) & (s[:, 1] / s[:, 0] >= 1e-8)
    dex = s[reach, 1] / s[reach, 0]
    assert res["workspace_fraction"][0] == pytest.approx(reach.mean(), abs=0)
    assert res["min_dexterity"][0] == pytest.approx(dex.min(), rel=1e-9)
    assert res["mean_dexterity"][0] == pytest.approx(dex.mean(), rel=1e-9)


def test_spherical_leg_peak_force_is_the_studys_fig5b_peak_and_flags_singular_designs():
    leg = sl.SphericalLeg.paper()
    res = sls.STUDY.evaluate_rows(np.array([[leg.R, leg.r, leg.h]]), None)
    t = np.arange(0.0, 25.0 + 1e-9, 0.1)
    f = sl.inverse_dynamics(leg, *sl.fig5_motion("b", t), driven_legs=sl.PAPER_DRIVEN_LEGS).leg_forces
    assert res["fig5b_ok"][0] and res["peak_force"][0] == np.max(np.abs(f))
    # r = 45 mm, h = 70 mm: h cos b cos a + r sin a = 0 is met on the Fig. 5(b) sway (|a| <= 60 deg)
    bad = sls.STUDY.evaluate_rows(np.array([[0.075, 0.045, 0.040]]), None)
    assert not bad["fig5b_ok"][0] and np.isnan(bad["peak_force"][0])


def test_rejected_parameters_are_failed_designs_not_exceptions():
    st = with_variables(sls.STUDY, [Variable("length_max", 0.01, 0.2)])  # below length_min: rejected
    rows = np.array([[0.075, 0.03, 0.1, 0.02], [0.075, 0.03, 0.1, 0.17]])
    res = st.evaluate_rows(rows, None)
    assert res["design_ok"].tolist() == [False, True]
    assert np.isnan(res["workspace_fraction"][0]) and not res["has_workspace"][0]
    assert np.isfinite(res["workspace_fraction"][1])


def test_as_built_thruster_without_errors_is_the_librarys_forward_kinematics():
    th = vt.VectoredThruster.paper()
    q = vts.workspace(th)
    s0, ok = vts.as_built_axis(th, {}, q)
    assert ok.all()
    np.testing.assert_allclose(s0, vt.forward_kinematics(th, q).axis, atol=ROUNDING)


def test_arc_angle_error_is_the_forward_kinematics_of_the_replaced_parameters():
    th = vt.VectoredThruster.paper()
    q = vts.workspace(th)
    da = 0.01
    s0, _ = vts.as_built_axis(th, {"arc_angle": np.array(da)}, q)
    ref = vt.forward_kinematics(dataclasses.replace(th, arc_angle=th.arc_angle + da), q).axis
    np.testing.assert_allclose(s0, ref, atol=ROUNDING)


def test_encoder_offsets_shift_the_inputs():
    th = vt.VectoredThruster.paper()
    q = vts.workspace(th)
    e = {"q1_offset": np.array(0.003), "q2_offset": np.array(-0.002)}
    s0, _ = vts.as_built_axis(th, e, q)
    ref = vt.forward_kinematics(th, q + np.array([0.003, -0.002])).axis
    np.testing.assert_allclose(s0, ref, atol=ROUNDING)


def test_input_axes_turned_together_about_z_turn_the_propeller_rigidly():
    th = vt.VectoredThruster.paper()
    q = vts.workspace(th)
    eps = 0.004  # u1 = X + eps Y, u2 = Y - eps X is the frame turned by eps about Z (up to scale)
    err, ok = vts.pointing_error(th, {"axis1_tilt_y": np.array(eps), "axis2_tilt_x": np.array(-eps)}, q)
    s0 = vt.forward_kinematics(th, q).axis
    c, s = math.cos(math.atan(eps)), math.sin(math.atan(eps))
    Rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    ref = np.arctan2(np.linalg.norm(np.cross(s0 @ Rz.T, s0), axis=-1), np.sum((s0 @ Rz.T) * s0, -1))
    assert ok.all()
    np.testing.assert_allclose(err, ref, atol=ROUNDING)


def test_monte_carlo_mean_square_matches_the_linearised_sensitivity_sum():
    st = get_study("vectored-thrust-tolerance")
    X = design_matrix(st.variables, 1000, "random", 0, 256)
    res = st.evaluate_rows(X, None)
    assert res["assembles"].all()
    ms = res["rms_error"] ** 2
    sens = vts.sensitivity(st.nominal(), {v.name: v.sigma for v in st.variables})
    predicted = sum(sens.values())
    se = ms.std() / math.sqrt(ms.size)
    assert abs(ms.mean() - predicted) <= MC_SIGMAS * se + LINEARISATION_RTOL * predicted
    assert list(sens) == sorted(sens, key=lambda k: -sens[k])
    assert np.all(res["max_error"] >= res["p95_error"]) and np.all(res["p95_error"] >= res["p50_error"])


def _projected_area(leg, n=4000):
    """Area of the XY projection of the thigh's sphere patch, by the shoelace formula on its boundary."""
    a_m, b_m = leg.alpha_max, leg.beta_max
    t = np.linspace(-1.0, 1.0, n, endpoint=False)
    edges = [
        np.stack([a_m * t, -b_m + 0 * t], -1),
        np.stack([a_m + 0 * t, b_m * t], -1),
        np.stack([-a_m * t, b_m + 0 * t], -1),
        np.stack([-a_m + 0 * t, -b_m * t], -1),
    ]
    ab = np.concatenate(edges)
    p = ol.forward_kinematics(leg, np.column_stack([ab, np.zeros(len(ab))]))
    x, y = p[:, 0], p[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


@pytest.mark.parametrize("L1, L4, L5", [(0.15, 0.095, 0.16), (0.11, 0.07, 0.19), (0.19, 0.115, 0.13)])
def test_omnileg_volume_is_projected_area_times_the_shank_stroke(L1, L4, L5):
    # eq. (11): p = L1 u(alpha, beta) + (0, 0, 2 L4 cos gamma + L5): vertical segments of length
    # 2 L4 (cos g_lo - cos g_max) over the projected patch, so volume = area x stroke (Cavalieri).
    leg = dataclasses.replace(ol.OmniLeg.paper(), L1=L1, L4=L4, L5=L5)
    res = om.STUDY.evaluate_rows(np.array([[L1, L4, L5]]), None)
    stroke = 2 * L4 * (math.cos(om.GAMMA_USABLE_MIN) - math.cos(leg.gamma_max))
    area = _projected_area(leg)
    assert res["workspace_volume"][0] == pytest.approx(area * stroke, rel=SIMPSON_RTOL + POLYGON_RTOL)


def test_omnileg_min_det_and_torque_against_direct_evaluation():
    leg = ol.OmniLeg.paper()
    res = om.STUDY.evaluate_rows(np.array([[leg.L1, leg.L4, leg.L5]]), None)
    # |det J| = 2 L4 sin(gamma) |d(x, y)/d(alpha, beta)| (J[2, 2] is the only gamma term): smallest at
    # gamma_lo; the (alpha, beta) factor by central differences of eq. (11) on a grid holding the nodes
    a = np.linspace(-leg.alpha_max, leg.alpha_max, 12 * 8 + 1)
    b = np.linspace(-leg.beta_max, leg.beta_max, 12 * 8 + 1)
    A, B = (x.ravel() for x in np.meshgrid(a, b, indexing="ij"))
    h = FD_STEP

    def xy(da, db):
        p = ol.forward_kinematics(leg, np.column_stack([A + da, B + db, 0 * A]))
        return p[:, :2]

    ja, jb = (xy(h, 0) - xy(-h, 0)) / (2 * h), (xy(0, h) - xy(0, -h)) / (2 * h)
    det = 2 * leg.L4 * math.sin(om.GAMMA_USABLE_MIN) * np.abs(ja[:, 0] * jb[:, 1] - ja[:, 1] * jb[:, 0])
    assert res["min_abs_det_j"][0] == pytest.approx(det.min(), rel=FD_RTOL)
    m = ol.joint_trajectory_eq52(np.arange(0.0, 6.0 + 1e-9, om.EQ52_STEP))
    tau = ol.inverse_dynamics(leg, m.q, m.qd, m.qdd).tau
    np.testing.assert_array_equal(res["peak_torque_joint"][0], np.abs(tau).max(0))
    assert res["peak_torque"][0] == np.abs(tau).max()


def test_l5_translates_the_omnileg_workspace():
    rows = np.array([[0.15, 0.095, 0.13], [0.15, 0.095, 0.19]])
    res = om.STUDY.evaluate_rows(rows, None)
    assert res["workspace_volume"][0] == pytest.approx(res["workspace_volume"][1], rel=ROUNDING)
    assert res["min_abs_det_j"][0] == pytest.approx(res["min_abs_det_j"][1], rel=ROUNDING)


def test_an_error_that_makes_the_parameters_invalid_is_a_failed_design():
    st = get_study("vectored-thrust-tolerance")
    rows = np.zeros((2, len(st.variables)))
    rows[0, st.variable_names.index("arc_angle")] = -1.0  # arc angle < 0: VectoredThruster refuses it
    res = st.evaluate_rows(rows, None)
    assert res["design_ok"].tolist() == [False, True]
    assert np.isnan(res["rms_error"][0]) and not res["assembles"][0]
    assert res["max_error"][1] == pytest.approx(0.0, abs=ROUNDING)  # no error: the nominal axis


@pytest.mark.parametrize("block", [1, 7])
def test_thruster_design_blocks_change_no_bit(monkeypatch, block):
    # wide errors: some designs do not assemble, some are rejected by the parameter object (arc angle)
    st = get_study("vectored-thrust-tolerance")
    wide = with_variables(st, [Variable(v.name, unit="rad", kind="normal", sigma=0.5) for v in st.variables])
    X = design_matrix(wide.variables, 300, "random", 1, 300)
    monkeypatch.setattr(vts, "DESIGN_BLOCK", X.shape[0])
    whole = wide.evaluate_rows(X, None)
    assert 0 < whole["assembles"].sum() < X.shape[0] and not whole["design_ok"].all()
    monkeypatch.setattr(vts, "DESIGN_BLOCK", block)
    blocked = wide.evaluate_rows(X, None)
    for k, v in whole.items():
        assert v.tobytes() == blocked[k].tobytes(), k


def test_spherical_leg_fig5b_metrics_match_the_definition_for_every_design():
    # the study runs the dynamics only where the motion is kinematically feasible: check against the
    # definition evaluated in full (stroke limits, no dl3/dalpha sign change, dynamics valid) per design
    X = design_matrix(sls.STUDY.variables, 32, "sobol", 4, 32)
    res = sls.STUDY.evaluate_rows(X, None)
    q, qd, qdd = sl.fig5_motion("b", np.arange(0.0, 25.0 + 1e-9, 0.1))
    for i, row in enumerate(X):
        leg = dataclasses.replace(sl.SphericalLeg.paper(), R=row[0], r=row[1], h=row[2])
        path = sl.workspace_map(leg, q[:, 0], q[:, 1])
        s = np.sign(path.dl3_dalpha)
        dyn = sl.inverse_dynamics(leg, q, qd, qdd, driven_legs=sl.PAPER_DRIVEN_LEGS)
        ok = path.reachable.all() and dyn.valid.all() and np.all(s == s[0]) and s[0] != 0
        assert res["fig5b_ok"][i] == ok, i
        expected = np.max(np.abs(dyn.leg_forces)) if ok else np.nan
        np.testing.assert_array_equal(res["peak_force"][i], expected)
    assert 0 < res["fig5b_ok"].sum() < X.shape[0]  # both kinds of design are in the sample
