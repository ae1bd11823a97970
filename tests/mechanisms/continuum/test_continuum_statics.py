"""Statics by virtual work, pretension in the null space, slack flags, coupling moments, friction."""

from __future__ import annotations

import numpy as np
import pytest

from robomech.mechanisms import continuum as C
from robomech.testing import numerical_jacobian

PAPER = C.ContinuumRobot.paper()
TWO = C.ContinuumRobot(n_segments=2, friction=(0.26, 0.31, 0.28) * 2)
# Central differences of energies/lengths with step 1e-6: truncation ~1e-12 relative; the balances
# below are O(0.01-0.1) N m, so 1e-9 N m is a strict but safe bound.
VW_TOL = 1e-9
H = 1e-6


def psi_batch(robot, seed=0, batch=5, theta_max=1.6):
    rng = np.random.default_rng(seed)
    th = rng.uniform(0.05, theta_max, (batch, robot.n_segments))
    be = rng.uniform(-np.pi, np.pi, (batch, robot.n_segments))
    return np.stack([th, be], -1).reshape(batch, -1)


@pytest.mark.parametrize("robot", [PAPER, TWO], ids=["one", "two"])
@pytest.mark.parametrize("model", ["arc", "chord"])
def test_virtual_work_balance_with_tip_wrench(robot, model):
    """-tau . dL + W . dx = dU for every virtual displacement (frictionless cables)."""
    rng = np.random.default_rng(1)
    psi = psi_batch(robot)
    W = rng.normal(scale=[0.01, 0.01, 0.01, 0.2, 0.2, 0.2], size=(5, 6))  # [m (N m); f (N)]
    tr = C.cable_tensions(robot, psi, wrench=W, model=model)
    assert tr.residual.max() < 1e-12
    for _ in range(3):
        d = rng.normal(size=psi.shape)
        L_p, L_m = C.cable_lengths(robot, psi + H * d, model), C.cable_lengths(robot, psi - H * d, model)
        dL = (L_p - L_m) / (2 * H)
        dU = (C.elastic_energy(robot, psi + H * d) - C.elastic_energy(robot, psi - H * d)) / (2 * H)
        dx = np.einsum("...ij,...j->...i", C.tip_jacobian(robot, psi), d)  # [d phi; d p]
        work = -np.sum(tr.tension * dL, -1) + np.sum(W * dx, -1)
        assert np.abs(work - dU).max() < VW_TOL


def test_virtual_work_balance_with_friction():
    """With friction every span carries its own tension: -sum_k T_k d l_k = dU."""
    rng = np.random.default_rng(2)
    psi = psi_batch(TWO, seed=3)
    direction = rng.choice([-1.0, 1.0], size=(5, TWO.n_cables))
    tr = C.cable_tensions(TWO, psi, direction=direction)
    P = C.friction_factors(TWO, psi, direction)
    d = rng.normal(size=psi.shape)
    dl = (C.span_lengths(TWO, psi + H * d) - C.span_lengths(TWO, psi - H * d)) / (2 * H)
    dU = (C.elastic_energy(TWO, psi + H * d) - C.elastic_energy(TWO, psi - H * d)) / (2 * H)
    work = -np.sum(tr.tension[..., None] * P * dl, axis=(-1, -2))
    assert np.abs(work - dU).max() < VW_TOL


def test_concave_side_cable_pulls():
    """Bending toward beta = 0 shortens cable 1: it must carry the largest tension (errata: printed sign
    makes it push)."""
    tr = C.cable_tensions(PAPER, [1.0, 0.0], pretension=0.0, model="arc")
    assert tr.tension[0] > 0 and tr.tension[1] < 0 and tr.tension[2] < 0
    M = PAPER.bending_stiffness * 1.0 / PAPER.segment_length
    assert abs(PAPER.hole_radius * (tr.tension[0] - 0.5 * tr.tension[1] - 0.5 * tr.tension[2]) - M) < 1e-15


def test_pretension_lies_in_null_space_and_shifts_all_cables():
    psi = psi_batch(TWO, seed=4)
    a = C.cable_tensions(TWO, psi, pretension=0.0, model="arc")
    b = C.cable_tensions(TWO, psi, pretension=7.0, model="arc")
    assert np.abs(b.tension - a.tension - 7.0).max() < 1e-12  # (1, 1, 1) per segment is in the null space
    assert np.abs(a.tension - a.minimum_norm).max() < 1e-12
    # chord spans shorten together as the segment bends, so a uniform tension does work: the projected
    # pretension is no longer uniform but still does no virtual work
    a = C.cable_tensions(TWO, psi, pretension=0.0, model="chord")
    b = C.cable_tensions(TWO, psi, pretension=7.0, model="chord")
    G = C.cable_jacobian(TWO, psi, "chord")
    assert np.abs(np.einsum("...ij,...i->...j", G, b.tension - a.tension)).max() < 1e-12
    _, _, Vt = np.linalg.svd(np.swapaxes(G, -1, -2))
    null = Vt[..., 4:, :]  # orthonormal basis of the 2-dimensional null space of G^T (6 cables, 4 dof)
    proj = np.einsum("...ki,...kj->...ij", null, null)
    assert np.abs(b.tension - a.tension - 7.0 * proj.sum(-1)).max() < 1e-12


def test_slack_is_flagged_and_printed_eta_too_small():
    psi = np.array([[0.2, 0.0], [np.pi / 2, 0.0]])
    printed = C.cable_tensions(PAPER, psi, pretension=1.0, model="arc")  # paper 3: eta = (1, 1, 1) N
    assert printed.taut.tolist() == [True, False]
    assert printed.min_tension[1] < 0
    ours = C.cable_tensions(PAPER, psi, model="arc")  # default pretension 5 N
    assert ours.taut.all()


def test_coupling_moment_is_contained_in_full_model():
    """Paper 3, eq. (12): segment 2 acts on segment 1 with -M_c = (EI theta_2 / l, 0) when both bend in
    one plane; the full model gets it from segment 2's cables crossing segment 1."""
    for beta in (0.0, 1.0, -2.5):
        psi = np.array([0.6, beta, 0.9, beta])
        tr = C.cable_tensions(TWO, psi, pretension=0.0, model="arc")
        G = C.cable_jacobian(TWO, psi, "arc")
        force_on_1 = -G[3:, 0:2].T @ tr.tension[3:]
        Mc = C.coupling_moments(TWO, psi)
        assert np.abs(force_on_1 + Mc[0]).max() < 1e-14
        assert np.all(Mc[1] == 0)


def test_elastic_gradient_vs_central_differences():
    psi = psi_batch(TWO)
    g = C.elastic_gradient(TWO, psi)
    gn = numerical_jacobian(lambda p: C.elastic_energy(TWO, p)[..., None], psi)[..., 0, :]
    assert np.abs(g - gn).max() < 1e-10


def test_wrap_angles_from_geometry():
    th, N = 1.3, PAPER.disks_per_segment
    eta = C.wrap_angles(PAPER, [th, 0.7])
    assert np.abs(eta[:, 0] - th / (2 * N)).max() < 1e-14  # base plate: half a span
    assert np.abs(eta[:, 1:] - th / N).max() < 1e-14  # every cable wraps theta / N at interior disks
    # two segments in one plane: the boundary disk adds half a span of each segment
    eta2 = C.wrap_angles(TWO, [0.8, 0.4, 1.2, 0.4])
    assert np.all(eta2[:3, N:] == 0.0)  # segment 1's cables end at disk N
    assert abs(eta2[4, N] - (0.8 + 1.2) / (2 * N)) < 1e-14
    assert abs(eta2[4].sum() - (0.8 + 1.2 - 1.2 / (2 * N))) < 1e-13


def test_friction_factors_direction():
    psi = [1.2, 0.0]
    pull = C.friction_factors(PAPER, psi, [1, 1, 1])
    pay = C.friction_factors(PAPER, psi, [-1, -1, -1])
    none = C.friction_factors(PAPER, psi, None)  # frictionless model (sticking is refused, see below)
    assert np.all(np.diff(pull, axis=-1) < 0) and np.all(np.diff(pay, axis=-1) > 0)
    assert np.all(none == 1.0)
    total = 1.2 - 1.2 / (2 * PAPER.disks_per_segment)
    assert np.abs(pull[:, -1] - np.exp(-PAPER.friction_array * total)).max() < 1e-14
    with pytest.raises(ValueError, match="direction"):
        C.friction_factors(PAPER, psi, [2, 0, 0])


def test_batched_equals_per_sample():
    psi = psi_batch(TWO, seed=6, batch=4)
    d = np.random.default_rng(0).choice([-1.0, 1.0], size=(4, 6))
    W = np.random.default_rng(1).normal(scale=0.05, size=(4, 6))
    a = C.cable_tensions(TWO, psi, wrench=W, direction=d).tension
    b = np.stack([C.cable_tensions(TWO, psi[i], wrench=W[i], direction=d[i]).tension for i in range(4)])
    assert np.abs(a - b).max() < 1e-12


def test_bad_input():
    with pytest.raises(ValueError, match="wrench"):
        C.cable_tensions(PAPER, [0.1, 0.0], wrench=[1.0, 2.0])
    with pytest.raises(ValueError, match="pretension"):
        C.cable_tensions(PAPER, [0.1, 0.0], pretension=-1.0)
    with pytest.raises(ValueError, match="psi"):
        C.cable_tensions(PAPER, [np.inf, 0.0])


def test_sticking_direction_is_refused_not_frictionless():
    """Issue 14, defect 6: direction 0 (eq. (19)'s stuck branch) used to return the frictionless tension
    silently; without a stick-slip model it is a clear error for cables with friction."""
    import pytest

    from robomech.mechanisms import continuum as C

    robot = C.ContinuumRobot.paper()
    psi = np.array([0.8, 0.3])
    with pytest.raises(ValueError, match="direction"):
        C.cable_tensions(robot, psi, direction=[1.0, 0.0, -1.0])
    with pytest.raises(ValueError, match="direction"):
        C.friction_factors(robot, psi, [0.5, -1.0, -1.0])
    # frictionless cables may stick (nothing is undetermined), and None stays the frictionless model
    free = C.ContinuumRobot(friction=(0.0, 0.0, 0.0))
    a = C.cable_tensions(free, psi, direction=[0.0, 0.0, 0.0]).tension
    b = C.cable_tensions(robot, psi).tension
    assert np.allclose(a, b, rtol=0, atol=1e-12)
