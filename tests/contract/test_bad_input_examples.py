"""The bad-input examples of the second contract round, each as the issue states it: a parameter or
an array the library used to accept, or refused with another library's message."""

from __future__ import annotations

import numpy as np
import pytest

from robomech import dynamics as dyn
from robomech import spatial as sp
from robomech import trajectory as traj
from robomech.analysis import lstsq
from robomech.analysis import workspace as ws
from robomech.mechanisms import continuum as cr
from robomech.mechanisms import omnileg as ol
from robomech.mechanisms import skid_steer as ss
from robomech.mechanisms import spherical_leg as sl
from robomech.mechanisms import vectored_thrust as vt


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: lstsq.solve(np.zeros((0, 0)), np.zeros(0)), "A"),
        (lambda: lstsq.solve(np.zeros((5, 0)), np.zeros(5)), "A"),
        (lambda: lstsq.solve_normal_equations(np.zeros((0, 0)), np.zeros(0)), "A"),
        (lambda: lstsq.solve_normal_equations(np.zeros((5, 0)), np.zeros(5)), "A"),
        (lambda: ws.condition_number(np.zeros((3, 0))), "J"),
        (lambda: ws.singularity_map(np.zeros((3, 0))), "J"),
        (lambda: ss.dead_reckoning(np.zeros((0, 6)), 0.1), "twists"),
        (lambda: traj.quintic(np.linspace(0, 1, 5), 1.0).stack(None), "others"),
        (
            lambda: traj.quintic(np.linspace(0, 1, 5), 1.0).stack(traj.quintic(np.linspace(0, 1, 7), 1.0)),
            "others",
        ),
        (lambda: sl.SphericalLeg(lower=None), "lower"),
        (lambda: cr.ContinuumRobot(hole_radius=1e-6), "hole_radius"),  # inside the 1 mm core
        (lambda: ol.default_bodies(-0.1, 0.1, 0.1, 0.1, 0.05), "L1"),
        (lambda: dyn.spatial_inertia(1.0, np.zeros(3), np.diag([1.0, 1.0, -1.0])), "inertia"),
        (lambda: ss.dead_reckoning(np.zeros((3, 6)), 0.1, 2.0 * np.eye(4)), "T0"),  # not rigid
        (lambda: sp.wrench_at(1.0, np.zeros(3)), "force"),  # a scalar for a 3-vector
    ],
)
def test_a_bad_input_is_a_value_error_naming_it(call, name):
    with pytest.raises(ValueError, match=rf"\b{name}"):
        call()


def test_control_the_good_neighbours_of_those_inputs_pass():
    assert lstsq.solve(np.eye(2), np.ones(2)).x.shape == (2,)
    assert np.isfinite(ws.condition_number(np.eye(3)))
    p = traj.quintic(np.linspace(0, 1, 5), 1.0)
    assert p.stack(p) is not None
    assert dyn.spatial_inertia(1.0, np.zeros(3), np.eye(3)).shape == (6, 6)
    assert ss.dead_reckoning(np.zeros((3, 6)), 0.1, np.eye(4)).shape[-2:] == (4, 4)


def test_non_finite_entries_are_masked_per_sample_or_refused():
    J = np.tile(np.eye(3), (4, 1, 1))
    tau = np.ones((4, 3))
    for bad in (np.nan, np.inf, 1e300):
        Jb = J.copy()
        Jb[1, 0, 0] = bad
        r = dyn.actuator_forces(Jb, tau)
        assert r.valid.tolist() == [True, False, True, True]
        assert np.all(np.isfinite(r.forces[r.valid]))
    # a function without a mask field refuses non-finite input instead of returning it unflagged
    for bad in (np.nan, np.inf):
        with pytest.raises(ValueError, match=r"\bJ\b"):
            ws.condition_number(np.stack([np.eye(3), np.full((3, 3), bad)]))


def test_link_clearance_at_the_singular_pose_is_flagged():
    r = vt.link_clearance(vt.VectoredThruster.paper(), [0.0, np.pi / 4])
    fields = {k: np.asarray(getattr(r, k)) for k in r.__dataclass_fields__}
    finite = all(np.all(np.isfinite(v)) for k, v in fields.items() if v.dtype.kind == "f")
    assert finite or not np.all(r.valid)


def test_identify_icr_with_zero_weights_uses_no_sample_and_does_not_warn():
    n = 10
    bv = np.zeros((n, 3))
    bv[:, 0], bv[:, 2] = 0.75, 0.1
    with np.errstate(all="raise"):
        r = ss.identify_icr(np.ones(n), 0.5 * np.ones(n), bv, weights=np.zeros(n))
    assert r.n_used == 0 and not r.identifiable and not r.used.any()


def test_an_angular_velocity_the_thruster_cannot_produce_is_not_valid():
    r = vt.inverse_rates(vt.VectoredThruster.paper(), [0, 0], [0, 0, 1.0])
    assert not np.all(r.valid)
