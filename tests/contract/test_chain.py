"""Failed samples chain: a forward-kinematics output with a failed sample feeds every multibody function.

The rule (docs/conventions.md, "Failed samples chain"): a NaN row of ``q`` is a failed sample; a
batched function gives that sample NaN / False and the other samples exactly what they give alone;
a function of one configuration refuses it with a ValueError naming ``q``.  ``CHAIN`` must name
every public multibody function that takes ``q`` (or ``q0``), so a new one cannot be left out.
"""

from __future__ import annotations

import dataclasses
import inspect
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from chain_check import check_chain

from robomech import multibody as mb

MECH = mb.gallery.load("four_bar")
SITE = "coupler_point"
FK = mb.forward_kinematics(MECH, np.array([[0.2], [np.nan], [-0.4]]))  # sample 1 failed
GOOD = [0, 2]
QD = np.full((3, MECH.nv), 0.1)
QDA = np.full((3, 1), 0.3)

# batched functions: call(q) on a batch of configurations
CHAIN: dict[str, Callable[[np.ndarray], Any]] = {
    "site_pose": lambda q: mb.site_pose(MECH, q, SITE),
    "site_jacobian": lambda q: mb.site_jacobian(MECH, q, SITE),
    "site_hessian": lambda q: mb.site_hessian(MECH, q, SITE),
    "influence": lambda q: mb.influence(MECH, q),
    "constraint_residual": lambda q: mb.constraint_residual(MECH, q),
    "constraint_jacobian": lambda q: mb.constraint_jacobian(MECH, q),
    "constraint_jacobian_rate": lambda q: mb.constraint_jacobian_rate(MECH, q, QD[: len(q)]),
    "singularities": lambda q: mb.singularities(MECH, q, SITE),
    "forward_kinematics": lambda q: mb.forward_kinematics(MECH, np.full((len(q), 1), 0.25), q),  # guess
    "inverse_kinematics": lambda q: mb.inverse_kinematics(MECH, SITE, mb.site_pose(MECH, MECH.q0, SITE), q),
    "inverse_dynamics": lambda q: mb.inverse_dynamics(MECH, q, QDA[: len(q)], QDA[: len(q)]),
    "statics": lambda q: mb.statics(MECH, q),
    "site_wrench": lambda q: mb.site_wrench(MECH, q, SITE, np.ones((len(q), 1))),
    "forward_dynamics": lambda q: mb.forward_dynamics(MECH, q, QDA[: len(q)], np.ones((len(q), 1))),
    "energy": lambda q: mb.energy(MECH, q, QD[: len(q)]),
    "mass_matrix": lambda q: mb.mass_matrix(MECH, q),
    "generalized_forces": lambda q: mb.generalized_forces(MECH, q, QD[: len(q)], QD[: len(q)]),
    "singularity_map": lambda q: mb.singularity_map(
        MECH, SITE, q_act=np.full((len(q), 1), 0.25), guess=q, steps=1
    ),
}
# functions of one configuration (or a trajectory / a start state): a failed sample is refused
SINGLE: dict[str, Callable[[np.ndarray], Any]] = {
    "mobility": lambda q: mb.mobility(MECH, q[1]),
    "body_segments": lambda q: mb.body_segments(MECH, q[1]),
    "draw": lambda q: mb.draw(MECH, q[1]),
    "animate": lambda q: mb.animate(MECH, q, "/nonexistent-dir/x.gif"),
    "view": lambda q: mb.view(MECH, q[1]),
    "simulate": lambda q: mb.simulate(MECH, q[1], QDA[1], np.linspace(0.0, 0.01, 3)),
}


def _takes_q(name: str) -> bool:
    obj = getattr(mb, name)
    if not inspect.isfunction(obj):
        return False
    params = inspect.signature(obj).parameters
    return "q" in params or "q0" in params or "guess" in params


def test_every_multibody_function_taking_q_is_in_the_chain():
    names = {n for n in mb.__all__ if _takes_q(n)}
    missing = names - set(CHAIN) - set(SINGLE)
    assert not missing, f"add these to CHAIN or SINGLE: {sorted(missing)}"


def test_forward_kinematics_returns_a_failed_sample():
    assert FK.converged.tolist() == [True, False, True]
    assert np.isnan(FK.q[1]).all() and np.isfinite(FK.q[GOOD]).all()


@pytest.mark.parametrize("name", sorted(CHAIN))
def test_a_failed_sample_chains(name):
    check_chain(CHAIN[name], FK.q, 1, GOOD)


@pytest.mark.parametrize("name", sorted(SINGLE))
def test_a_failed_configuration_is_refused_by_single_configuration_functions(name):
    with pytest.raises(ValueError, match=r"\bq0?\b"):
        SINGLE[name](FK.q)


@pytest.mark.parametrize(
    "name", ["site_pose", "site_jacobian", "influence", "constraint_jacobian", "singularities"]
)
@pytest.mark.parametrize("bad", [np.inf, -np.inf, 1e300])
def test_inf_and_overflowing_q_are_refused_not_chained(name, bad):
    q = FK.q.copy()
    q[0, 1] = bad
    with pytest.raises(ValueError, match=r"Expected q finite"):
        CHAIN[name](q)


def test_forward_kinematics_masks_overflowing_inputs():
    fk = mb.forward_kinematics(MECH, np.array([[0.2], [1e300], [np.inf]]))
    assert fk.converged.tolist() == [True, False, False]
    assert np.isnan(fk.q[1:]).all()


# --- controls: the rule can fail ------------------------------------------------------------------


def _strict_site_jacobian(q):
    """A function that refuses a failed sample (the old behaviour)."""
    if not np.all(np.isfinite(q)):
        raise ValueError("Expected q to be finite.")
    return mb.site_jacobian(MECH, q, SITE)


def _leaky_singularities(q):
    """A function that gives the failed sample a verdict (flag True)."""
    s = mb.singularities(MECH, q, SITE)
    return dataclasses.replace(s, singular=s.singular | np.isnan(s.sigma_I))


def _coupled_site_pose(q):
    """A function whose good samples depend on the batch (fills the failed one with the mean)."""
    qq = np.where(np.isnan(q), np.nanmean(q, axis=0), q)
    return mb.site_pose(MECH, qq, SITE)


def test_control_the_chain_rule_fails_a_function_that_refuses_failed_samples():
    with pytest.raises(ValueError):
        check_chain(_strict_site_jacobian, FK.q, 1, GOOD)


def test_control_the_chain_rule_fails_a_flag_true_at_a_failed_sample():
    with pytest.raises(AssertionError, match="flagged True"):
        check_chain(_leaky_singularities, FK.q, 1, GOOD)


def test_control_the_chain_rule_fails_a_failed_sample_given_a_value():
    with pytest.raises(AssertionError, match="not NaN"):
        check_chain(_coupled_site_pose, FK.q, 1, GOOD)


def test_control_the_coverage_rule_sees_a_function_taking_q():
    assert _takes_q("site_pose") and _takes_q("forward_kinematics") and not _takes_q("to_mjcf")


def test_control_the_nan_rows_spec_rule_fails_a_function_that_does_not_propagate():
    """The contract suite's ``nan_rows`` check (test_contract._check_nan_row) rejects a function that
    fills a failed sample with a value, and passes the real one."""
    from contract_spec import Spec
    from test_contract import _check_nan_row

    q = FK.q[GOOD + GOOD[:1]]  # 3 good samples
    bad = q.copy()
    bad[1, 0] = np.nan

    def filled(mech, q):
        return mb.site_pose(mech, np.nan_to_num(q), SITE)

    def real(mech, q):
        return mb.site_pose(mech, q, SITE)

    for fn, ok in ((filled, False), (real, True)):
        spec = Spec(args={"mech": MECH, "q": q}, arrays={"q": 1}, nan_rows=("q",), call=fn)
        if ok:
            _check_nan_row(f"control-{fn.__name__}", spec, "q", {"mech": MECH, "q": bad}, 3)
        else:
            with pytest.raises(AssertionError, match="non-NaN"):
                _check_nan_row(f"control-{fn.__name__}", spec, "q", {"mech": MECH, "q": bad}, 3)
