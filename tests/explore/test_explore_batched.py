"""The paper studies' design-batched chunks equal the per-design evaluation, design by design.

Each reference below is the study's per-design loop as it was before its kernels took per-design
arrays: one public mechanism call per design.  The batched chunk must give the same metrics on a few
dozen Sobol designs, with rejected designs (None parameter objects) among them, for any design block.
"""

import dataclasses
import inspect

import numpy as np
import pytest

from robomech.explore import Variable, design_matrix, with_variables
from robomech.explore import _omnileg as om
from robomech.explore import _spherical_leg as sls
from robomech.explore import _vectored_thrust as vts
from robomech.mechanisms import omnileg as ol
from robomech.mechanisms import spherical_leg as sl
from robomech.mechanisms import vectored_thrust as vt
from robomech.mechanisms.spherical_leg._workspace import _singular_values

# The spherical leg's batched map takes J's singular values in closed form (to a few ulps of each),
# the per-design map from LAPACK's SVD (to rounding of sigma_max in each): the dexterity
# sigma_min / sigma_max of the two differs by a few ulps of 1 (measured 5e-16 on 2e5 random J).
DEXTERITY_ATOL = {"min_dexterity": 4e-15, "mean_dexterity": 4e-15}
# The OmniLeg's batched dynamics multiplies each body's inertia per sample where a single leg makes one
# BLAS product: the same three products and two sums per component, possibly in another order (a few
# ulps of each body's term; measured bit-identical here, where the default inertias are diagonal).
OMNILEG_RTOL = 1e-13


def _spherical_leg_per_design(study, params, X):
    """``_spherical_leg.evaluate`` as one ``workspace_map`` and one ``inverse_dynamics`` per design."""
    n = len(params)
    out = {m.name: np.full(n, np.nan) for m in study.metrics}
    for k in ("has_workspace", "fig5b_ok"):
        out[k] = np.zeros(n, dtype=bool)
    a, b = sls._task_grid()
    q, qd, qdd = sls._fig5b()
    m = a.size
    a_all, b_all = np.concatenate([a, q[:, 0]]), np.concatenate([b, q[:, 1]])
    for i, leg in enumerate(params):
        if leg is None:
            continue
        both = sl.workspace_map(leg, a_all, b_all)
        reach = both.reachable[:m] & ~both.singular[:m]
        out["workspace_fraction"][i] = reach.mean()
        if reach.any():
            dex = both.sigma_min[:m][reach] / both.sigma_max[:m][reach]
            out["min_dexterity"][i] = dex.min()
            out["mean_dexterity"][i] = dex.mean()
            out["has_workspace"][i] = True
        sign = np.sign(both.dl3_dalpha[m:])
        if not (both.reachable[m:].all() and np.all(sign == sign[0]) and sign[0] != 0):
            continue
        dyn = sl.inverse_dynamics(leg, q, qd, qdd, driven_legs=sl.PAPER_DRIVEN_LEGS)
        ok = bool(dyn.valid.all())
        out["fig5b_ok"][i] = ok
        if ok:
            out["peak_force"][i] = np.max(np.abs(dyn.leg_forces))
    return out


def _omnileg_per_design(study, params, X):
    """``_omnileg.evaluate`` as one ``jacobian`` and one ``inverse_dynamics`` per design."""
    n = len(params)
    out = {m.name: np.full((n, *m.shape), np.nan) for m in study.metrics}
    motion = ol.joint_trajectory_eq52(np.arange(0.0, 6.0 + 1e-9, om.EQ52_STEP))
    for i, leg in enumerate(params):
        if leg is None:
            continue
        q, w = om._grid(leg)
        det = np.abs(np.linalg.det(ol.jacobian(leg, q)))
        out["workspace_volume"][i] = np.dot(w, det)
        out["min_abs_det_j"][i] = det.min()
        tau = ol.inverse_dynamics(leg, motion.q, motion.qd, motion.qdd).tau
        peaks = np.abs(tau).max(axis=0)
        out["peak_torque_joint"][i] = peaks
        out["peak_torque"][i] = peaks.max()
    return out


def _thruster_per_design(study, params, X):
    """``_vectored_thrust.evaluate`` design by design: each as-built thruster (its arc angle in its
    parameter object) with its other errors, against the nominal axes at the workspace poses."""
    n = len(params)
    out = {m.name: np.full(n, np.nan) for m in study.metrics}
    out["assembles"] = np.zeros(n, dtype=bool)
    nominal = study.nominal()
    q = vts.workspace(nominal)
    nom = vt.forward_kinematics(nominal, q).axis
    for i, th in enumerate(params):
        if th is None:  # a thruster that cannot be built assembles nowhere
            out["assembled_fraction"][i] = 0.0
            continue
        errors = {name: X[i, k] for k, name in enumerate(study.variable_names) if name != "arc_angle"}
        err, ok = vts._pointing_error(th, errors, q, nom)
        out["assembled_fraction"][i] = ok.mean()
        out["assembles"][i] = ok.all()
        if ok.all():
            out["rms_error"][i] = np.sqrt(np.mean(err * err))
            out["p50_error"][i] = np.percentile(err, 50)
            out["p95_error"][i] = np.percentile(err, 95)
            out["max_error"][i] = err.max()
    return out


def _rows_with_rejected(study, n, bad):
    """``n`` Sobol designs of ``study`` with ``bad`` (a row the parameter object rejects) at rows 3, 17."""
    X = design_matrix(study.variables, n, "sobol", 3, n)
    X[[3, 17]] = bad
    return X


def _assert_same(study, X, reference, rtol=0.0, atol=None):
    """The study's chunk equals ``reference`` bit for bit, or to ``rtol`` (and ``atol`` per metric)."""
    got = study.evaluate_rows(X, None)
    ref = reference(study, study.designs_to_params(X), X)
    assert not got["design_ok"].all() and got["design_ok"].any()
    for k, v in ref.items():
        a = (atol or {}).get(k, 0.0)
        if rtol == 0.0 and a == 0.0:
            assert got[k].tobytes() == v.tobytes(), k
        else:  # NaN exactly where the reference has NaN
            np.testing.assert_allclose(got[k], v, rtol=rtol, atol=a, err_msg=k)
    return got


def test_spherical_leg_batched_chunk_equals_each_design_alone():
    X = _rows_with_rejected(sls.STUDY, 48, [0.075, -0.03, 0.1])  # r < 0: rejected
    got = _assert_same(sls.STUDY, X, _spherical_leg_per_design, atol=DEXTERITY_ATOL)
    # the sample holds designs with and without workspace, with a feasible and an infeasible Fig. 5(b)
    ok = got["design_ok"]
    assert 0 < got["fig5b_ok"].sum() < ok.sum() and got["has_workspace"][ok].all()


def test_spherical_leg_legs_varying_beyond_r_r_h_are_evaluated_in_their_own_groups():
    # length_max varies per design: every design is its own group; below length_min it is rejected
    st = with_variables(sls.STUDY, [Variable("length_max", 0.01, 0.2, "m")])
    X = _rows_with_rejected(st, 24, [0.075, 0.03, 0.1, 0.02])
    got = _assert_same(st, X, _spherical_leg_per_design, atol=DEXTERITY_ATOL)
    assert np.unique(got["workspace_fraction"][got["design_ok"]]).size > 1


@pytest.mark.parametrize("block", [1, 7])
def test_spherical_leg_design_blocks_change_no_bit(monkeypatch, block):
    X = _rows_with_rejected(sls.STUDY, 24, [0.075, -0.03, 0.1])
    whole = sls.STUDY.evaluate_rows(X, None)
    monkeypatch.setattr(sls, "DESIGN_BLOCK", block)
    blocked = sls.STUDY.evaluate_rows(X, None)
    for k, v in whole.items():
        assert v.tobytes() == blocked[k].tobytes(), k


def test_spherical_leg_designs_carry_each_legs_derived_geometry():
    legs = [dataclasses.replace(sl.SphericalLeg.paper(), R=R, r=r) for R, r in [(0.06, 0.03), (0.09, 0.04)]]
    d = sls.Legs.of(legs)
    for i, leg in enumerate(legs):
        for name in ("base_points", "platform_points_home", "cardan_axes"):
            np.testing.assert_array_equal(getattr(d, name)[i, 0], getattr(leg, name))
    assert d.platform_mass == legs[0].platform_mass


def test_omnileg_batched_chunk_equals_each_design_alone():
    X = _rows_with_rejected(om.STUDY, 40, [-0.15, 0.09, 0.16])  # L1 < 0: rejected
    got = _assert_same(om.STUDY, X, _omnileg_per_design, OMNILEG_RTOL)
    assert np.isfinite(got["peak_torque"][got["design_ok"]]).all()


def test_omnileg_legs_varying_beyond_their_lengths_are_evaluated_in_their_own_groups(monkeypatch):
    # L3 (the hip joints' radius) varies per design: every design is its own group; design blocks of 3
    monkeypatch.setattr(om, "DESIGN_BLOCK", 3)
    st = with_variables(om.STUDY, [Variable("L3", 0.03, 0.06, "m")])
    X = _rows_with_rejected(st, 20, [0.15, -0.09, 0.16, 0.04])  # L4 < 0: rejected
    got = _assert_same(st, X, _omnileg_per_design, OMNILEG_RTOL)
    assert np.unique(got["peak_torque"][got["design_ok"]]).size == got["design_ok"].sum()


def test_thruster_batched_chunk_equals_each_design_alone():
    # wide errors: some designs do not assemble everywhere; an arc angle below 0 is rejected
    st = with_variables(
        vts.STUDY, [Variable(v.name, unit="rad", kind="normal", sigma=0.3) for v in vts.STUDY.variables]
    )
    X = design_matrix(st.variables, 64, "random", 2, 64)
    X[[3, 17], st.variable_names.index("arc_angle")] = -1.0
    got = _assert_same(st, X, _thruster_per_design)
    ok = got["design_ok"]
    assert 0 < got["assembles"][ok].sum() < ok.sum()


def test_spherical_leg_closed_form_singular_values_are_lapacks_and_relatively_accurate():
    rng = np.random.default_rng(5)
    J = rng.normal(size=(4000, 3, 2))
    J[:, :2, 0] = 0.0  # legs 1 and 2 do not move with alpha
    J[:1000, 2, 0] *= 10.0 ** rng.uniform(-12, -2, 1000)  # near the actuation singularity
    J[1000:2000, :2, 1] *= 10.0 ** rng.uniform(-12, -2, (1000, 1))  # beta nearly uncontrolled
    J[2000, 2, 0] = 0.0  # rank 1
    smax, smin = _singular_values(J)
    s = np.linalg.svd(J, compute_uv=False)
    np.testing.assert_allclose(smax, s[:, 0], rtol=4e-15)
    assert np.all(np.abs(smin - s[:, 1]) <= 4e-15 * s[:, 0])  # LAPACK: to rounding of sigma_max
    # sigma_min sigma_max = |det [[J20, J21], [0, hypot(J01, J11)]]|, a product of relatively exact factors
    det = np.abs(J[:, 2, 0]) * np.hypot(J[:, 0, 1], J[:, 1, 1])
    np.testing.assert_allclose(smin * smax, det, rtol=4e-15, atol=0.0)
    assert smin[2000] == 0.0


def _omnileg_designs(legs):
    return om.Legs.of(legs, 1)  # one sample per design: row i is design i


@pytest.mark.parametrize(
    "make, designs, changed",
    [
        (sl.SphericalLeg.paper, sls.Legs.of, {"R": 0.06, "r": 0.04, "h": 0.12}),
        (ol.OmniLeg.paper, _omnileg_designs, {"L1": 0.12, "L4": 0.07, "L5": 0.15}),
    ],
)
def test_every_parameter_property_that_varies_per_design_is_carried_per_design(make, designs, changed):
    # Designs hands a kernel the first leg's value of any attribute it does not define: a property of
    # the parameter class that depends on the per-design fields must be defined on Designs instead
    a, b = make(), dataclasses.replace(make(), **changed)
    props = [n for n, v in inspect.getmembers(type(a)) if isinstance(v, property)]
    varying = [n for n in props if not np.array_equal(np.asarray(getattr(a, n)), np.asarray(getattr(b, n)))]
    assert varying  # the check has something to find
    d = designs([a, b])
    assert all(n in type(d).__dict__ for n in varying), varying
    for n in varying:
        for i, leg in enumerate((a, b)):
            want = np.asarray(getattr(leg, n))
            np.testing.assert_array_equal(np.asarray(getattr(d, n))[i].reshape(want.shape), want)
