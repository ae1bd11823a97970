"""The examples of issue 14's "Why" section, each failing on the code before the issue was fixed."""

import numpy as np
import pytest

from robomech import spatial


def test_exp_so3_rejects_nan():
    with pytest.raises(ValueError, match="w"):
        spatial.exp_so3([np.nan, 0.0, 0.0])


def test_hat_rejects_a_fourth_value():
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 3\)"):
        spatial.hat([1.0, 2.0, 3.0, 4.0])


def test_screw_from_axis_rejects_a_zero_axis():
    with pytest.raises(ValueError, match="axis"):
        spatial.screw_from_axis(np.zeros(3), np.zeros(3))


def test_log_so3_rejects_a_matrix_that_is_not_a_rotation():
    with pytest.raises(ValueError, match="rotation"):
        spatial.log_so3(2.0 * np.eye(3))


def test_as_array_rejects_complex_instead_of_dropping_the_imaginary_part():
    with pytest.raises(ValueError, match="real"):
        spatial.hat(np.array([1.0 + 2.0j, 0.0, 0.0]))


def test_numba_cache_is_not_written_into_the_package(tmp_path):
    """numba's cache goes to robomech._numba.cache_dir(), never the installed package's __pycache__;
    every module that compiles kernels imports numba through robomech._numba."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    import robomech

    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path)}
    env.pop("NUMBA_CACHE_DIR", None)
    code = "from robomech._numba import import_numba; print(import_numba().config.CACHE_DIR)"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert Path(out.stdout.strip()).parent == tmp_path / "robomech" / "numba"  # then the sources' folder
    pkg = Path(robomech.__file__).parent
    direct = [
        str(p.relative_to(pkg))
        for p in pkg.rglob("*.py")
        if p.name != "_numba.py" and any(ln.strip() == "import numba" for ln in p.read_text().splitlines())
    ]
    assert not direct, f"import numba through robomech._numba.import_numba(): {direct}"


def test_lstsq_exact_cond_must_be_a_bool():
    """An unvalidated exact_cond="yes" compiled a fresh kernel specialisation (7 s)."""
    from robomech.analysis import lstsq

    with pytest.raises(ValueError, match="exact_cond"):
        lstsq.solve(np.eye(3), np.ones(3), exact_cond="yes")


def test_actuator_forces_with_one_inf_sample_returns_and_masks_it():
    from robomech import dynamics

    J = np.tile(np.array([[1.0, 0.0], [0.0, 2.0], [1.0, 1.0]]), (3, 1, 1))
    J[1, 0, 0] = np.inf
    r = dynamics.actuator_forces(J, np.ones((3, 2)))
    assert np.all(np.isnan(r.forces[1])) and np.isnan(r.residual[1])
    assert r.valid.tolist() == [True, False, True]
    assert np.all(np.isfinite(r.forces[[0, 2]])) and np.all(r.residual[[0, 2]] < 1e-12)


def test_a_batch_with_one_nan_jacobian_is_masked_by_singularity_map():
    # condition_number returns a bare number per sample, with no mask: it refuses a non-finite J;
    # singularity_map keeps the batch and masks the sample
    from robomech.analysis import workspace

    J = np.tile(np.eye(3), (3, 1, 1))
    J[2, 1, 1] = np.nan
    with pytest.raises(ValueError, match="J"):
        workspace.condition_number(J)
    m = workspace.singularity_map(J)
    assert m.singular.tolist() == [False, False, True] and np.allclose(m.cond[:2], 1.0)


def test_normal_equations_with_one_huge_finite_sample_keeps_the_batch():
    from robomech.analysis import lstsq

    A = np.tile(np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]), (3, 1, 1))
    A[0] *= 1e200
    r = lstsq.solve_normal_equations(A, np.ones((3, 3)))
    assert not r.ok[0] and np.all(r.ok[1:]) and np.all(np.isfinite(r.x[1:]))


def test_lstsq_never_reports_ok_with_a_non_finite_residual():
    from robomech.analysis import lstsq

    A = np.tile(np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]), (2, 1, 1))
    b = np.ones((2, 3))
    b[0] = [1e300, -1e300, 1e300]  # finite, but the residual overflows
    r = lstsq.solve(A, b)
    assert np.all(np.isfinite(r.residual_norm[r.ok])) and np.all(np.isfinite(r.x[r.ok]))
    assert r.ok[1]


def test_mobility_rejects_a_nan_tolerance():
    from robomech.analysis import mobility

    screws = np.array([[0.0, 0.0, 1.0, 0.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="tol"):
        mobility.analyze([screws], tol=np.nan)


def test_mobility_rejects_a_chain_passed_transposed():
    from robomech.analysis import mobility
    from robomech.spatial import screw_from_axis

    rng = np.random.default_rng(1)
    chain = screw_from_axis(rng.normal(size=(6, 3)), rng.normal(size=(6, 3)))  # (6, 6), rows are screws
    mobility.analyze([chain])
    with pytest.raises(ValueError, match=r"chains\[0\]"):
        mobility.analyze([chain.T])


def test_mobility_flags_the_vectored_thruster_on_its_rank_one_curve():
    """Defect 8: on the idle-input curve the DOF is 1 while the modified count says 2: flagged."""
    from robomech.mechanisms import vectored_thrust as vt

    th = vt.VectoredThruster()
    q1 = 0.3
    m = vt.platform_mobility(th, (q1, float(vt.idle_input_curve(th, q1))))
    assert (m.dof, m.modified_gruebler_kutzbach) == (1, 2)
    assert m.singular and "singular" in m.warning
    regular = vt.platform_mobility(th, (0.3, -0.2))
    assert regular.dof == 2 and not regular.singular and regular.warning == ""


def test_spherical_leg_rejects_a_missing_parameter_object():
    from robomech.mechanisms import spherical_leg as sl

    with pytest.raises(ValueError, match=r"Expected leg to be a SphericalLeg, got NoneType\."):
        sl.inverse_kinematics(None, 0.1, 0.2)


def test_parameter_fields_store_floats_never_strings():
    from robomech.mechanisms import spherical_leg as sl

    with pytest.raises(ValueError, match="R"):
        sl.SphericalLeg(R="0.075")
    leg = sl.SphericalLeg(R=np.float32(0.075), h=1)
    assert type(leg.R) is float and type(leg.h) is float


def test_continuum_integer_fields_reject_bools_and_capstan_rejects_n_zero():
    from robomech.mechanisms import continuum as c

    with pytest.raises(ValueError, match="n_segments"):
        c.ContinuumRobot(n_segments=True)
    with pytest.raises(ValueError, match="n"):
        c.capstan_coefficient(np.array([2.0]), 1.0, 0.0)


def test_lstsq_docs_name_the_compiled_kernel_and_the_one_norm_condition_number():
    """Defect 7: the solver is robomech's compiled Householder kernel, and cond is the 1-norm one of R."""
    from robomech.analysis import lstsq

    assert "compiled" in lstsq.__doc__ and "(LAPACK)" not in lstsq.__doc__.splitlines()[0]
    assert "1-norm" in lstsq.LstsqResult.__doc__ and "||R||_1 ||R^-1||_1" in lstsq.LstsqResult.__doc__


def test_jacobian_derivative_and_trajectory_validate_their_input():
    from robomech import trajectory
    from robomech.kinematics import jacobian_derivative

    with pytest.raises(ValueError, match="qd"):
        jacobian_derivative(np.zeros((6, 3, 3)), np.zeros(4))
    with pytest.raises(ValueError, match="H"):
        jacobian_derivative(np.full((6, 3, 3), np.nan), np.zeros(3))
    with pytest.raises(ValueError, match="amplitude"):
        trajectory.sinusoid(np.zeros(3), np.nan, 1.0)
    with pytest.raises(ValueError, match="end"):
        trajectory.quintic(np.zeros(3), 1.0, 0.0, "1")


def test_dynamics_kernels_reject_non_finite_input():
    from robomech import dynamics

    G = np.broadcast_to(np.eye(6), (2, 6, 6))
    J = np.ones((2, 6, 3))
    J[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="J"):
        dynamics.mass_matrix(G, J)


def test_values_beyond_max_magnitude_are_rejected_or_masked_never_overflowed():
    """1e300 in a finite input overflowed to inf inside the models (squares, products): now a
    ValueError where a number is required, a false mask where the model flags samples."""
    from robomech._validation import MAX_MAGNITUDE
    from robomech.mechanisms import spherical_leg as sl

    leg = sl.SphericalLeg.paper()
    with pytest.raises(ValueError, match="alpha"):
        sl.inverse_kinematics(leg, np.array([0.1, 1e300]), 0.0)
    lengths = sl.inverse_kinematics(leg, np.array([0.1, 0.2]), 0.0).lengths
    lengths[1, 0] = 1e300
    fk = sl.forward_kinematics(leg, lengths)
    assert fk.valid[0] and not fk.valid[1]
    assert MAX_MAGNITUDE**3 < np.finfo(float).max
