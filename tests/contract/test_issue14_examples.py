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
