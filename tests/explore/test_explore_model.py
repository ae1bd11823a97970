"""Studies of a user's own mechanism (explore.model_study): a planar five-bar from a Builder function.

Independent references, computed here without the engine: the reachable workspace is the intersection
of the two legs' annuli ``|L1 - L2| <= |P - A_i| <= L1 + L2`` (closed form per point); the dexterity is
the SVD of the five-bar's velocity equations ``(P - E_i) . (dP - dE_i) = 0`` with
``dE_i = dtheta_i e_z x (E_i - A_i)`` (the elbows from the actuated angles).
"""

import math
from pathlib import Path

import numpy as np
import pytest

from robomech import multibody as mb
from robomech.cli import main
from robomech.explore import (
    UserMetric,
    Variable,
    load_model,
    model_study,
    open_results,
    optimize_nsga2,
    run_sweep,
)
from robomech.explore._model import dexterity, reach, reach_bound, task_grid

MODEL = Path(__file__).resolve().parents[2] / "examples" / "models" / "five_bar.py"
BOX = [[-0.5, 0.5], [-0.5, 0.5]]
GRID = 32  # task cells per axis (cell 31.25 mm), the grid
FINE = 8  # sub-samples per cell axis of the reference, to find the cells the boundary cuts
VARS = [Variable("L1", 0.15, 0.25, "m"), Variable("L2", 0.15, 0.25, "m"), Variable("B", 0.05, 0.15, "m")]
METRICS = ("workspace_measure", "task_fraction", "dexterity_min", "dexterity_mean", "type2_distance")
# Task points closer than this to an annulus boundary (m) may go either way in the engine's IK
# (its convergence tolerance on a point at the boundary, where the Jacobian is singular).
EDGE = 1e-6
# Relative agreement of the two formulations at samples whose velocity equations are well conditioned
# (cond(M) <= WELL_CONDITIONED): 1e-14 at cond(M) ~ 10, growing with cond(M) as the IK's closure
# tolerance is amplified (measured 2.9e-8 at cond(M) ~ 1e3).
SVD_RTOL = 1e-7
WELL_CONDITIONED = 1e3
# Near a type II singularity (cond(M) up to 5e3 on this task grid) the two differ more: the IK's
# closure tolerance is amplified by cond(M); measured 9e-4 relative at cond(M) = 4.6e3.
NEAR_SINGULAR_RTOL = 2e-3


@pytest.fixture(scope="module")
def build():
    return load_model(f"{MODEL}:build")


@pytest.fixture(scope="module")
def study(build):
    return model_study(build, VARS, site="tip", metrics=METRICS, task_box=BOX, task_grid_size=GRID, chunk=3)


@pytest.fixture(scope="module")
def small(build):
    """The same study on an 8 x 8 task grid, for the store and cluster paths."""
    return model_study(build, VARS, site="tip", metrics=METRICS, task_box=BOX, task_grid_size=8, chunk=3)


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    cluster = LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address="127.0.0.1:0", silence_logs=40
    )
    c = Client(cluster)
    yield c
    c.close()
    cluster.close()


def _in_annuli(P, L1, L2, B):
    ok = np.ones(P.shape[0], bool)
    margin = np.full(P.shape[0], np.inf)
    for s in (-1.0, 1.0):
        r = np.hypot(P[:, 0] - s * B / 2, P[:, 1])
        ok &= (r >= abs(L1 - L2)) & (r <= L1 + L2)
        margin = np.minimum(margin, np.minimum(np.abs(r - abs(L1 - L2)), np.abs(r - (L1 + L2))))
    return ok, margin


ROWS = np.array([[0.2, 0.25, 0.1], [0.15, 0.15, 0.1], [0.25, 0.16, 0.05], [0.18, 0.22, 0.15]])


def test_workspace_area_equals_the_annuli_intersection_to_the_grid_resolution(study):
    res = study.evaluate_rows(ROWS, None)
    assert res["design_ok"].all()
    h = 1.0 / GRID
    for (L1, L2, B), area, frac in zip(ROWS, res["workspace_measure"], res["task_fraction"], strict=True):
        centres = (np.arange(GRID) + 0.5) * h - 0.5
        P = np.stack(np.meshgrid(centres, centres, indexing="ij"), -1).reshape(-1, 2)
        inside, margin = _in_annuli(P, L1, L2, B)
        assert np.all(margin > EDGE)  # no centre on a boundary for these designs: the count is exact
        assert area == pytest.approx(inside.sum() * h * h, abs=1e-15) and frac == inside.mean()
        # the true area (fine grid) differs from the cell count by at most the cells the boundary cuts
        sub = (np.arange(GRID * FINE) + 0.5) * h / FINE - 0.5
        Q = np.stack(np.meshgrid(sub, sub, indexing="ij"), -1).reshape(-1, 2)
        fine, _ = _in_annuli(Q, L1, L2, B)
        true_area = fine.mean() * 1.0
        cells = fine.reshape(GRID, FINE, GRID, FINE).transpose(0, 2, 1, 3).reshape(GRID, GRID, -1)
        cut = np.sum(cells.any(-1) & ~cells.all(-1))
        assert abs(area - true_area) <= cut * h * h
        assert cut * h * h < 0.5 * true_area  # the bound is not vacuous


@pytest.mark.slow
def test_dexterity_equals_an_svd_of_the_five_bar_velocity_equations(study, build):
    res = study.evaluate_rows(ROWS, None)
    for (L1, L2, B), dmin, dmean in zip(ROWS, res["dexterity_min"], res["dexterity_mean"], strict=True):
        mech = build(L1=L1, L2=L2, B=B)
        pts, _ = task_grid(np.array(BOX), GRID, "xy", np.zeros(3))
        q, ok = reach(mech, "tip", pts, "xy", grid=GRID)  # the study's configurations; the Jacobian is ours
        th = q[ok][:, [mech.qpos_address(j) for j in mech.actuated]]
        P = mb.site_pose(mech, q[ok], "tip")[:, :2, 3]  # the solved tip (the task point to IK tolerance)
        np.testing.assert_allclose(P, pts[ok, :2], atol=1e-6)
        ez_cross = lambda v: np.stack([-v[..., 1], v[..., 0]], -1)  # noqa: E731
        M = np.zeros((P.shape[0], 2, 2))
        D = np.zeros((P.shape[0], 2, 2))
        for i, s in enumerate((-1.0, 1.0)):
            A = np.array([s * B / 2, 0.0])
            E = A + L1 * np.stack([np.cos(th[:, i]), np.sin(th[:, i])], -1)
            M[:, i] = P - E
            D[:, i, i] = np.sum((P - E) * ez_cross(E - A), -1)
        J = np.linalg.solve(M, D) / mech.length  # hinge columns over the characteristic length
        sv = np.linalg.svd(J, compute_uv=False)
        inv = sv[:, 1] / sv[:, 0]
        engine = dexterity(mech, q[ok], "tip", "xy")
        good = np.linalg.cond(M) <= WELL_CONDITIONED
        assert good.mean() > 0.9
        np.testing.assert_allclose(engine[good], inv[good], rtol=SVD_RTOL)
        np.testing.assert_allclose(engine, inv, rtol=NEAR_SINGULAR_RTOL)
        assert dmin == engine.min() and dmean == engine.mean()  # the study's metric is this reduction


def test_a_design_that_cannot_be_built_is_a_failed_design_not_an_error(study):
    res = study.evaluate_rows(np.array([[0.01, 0.01, 0.15], [0.2, 0.2, 0.1]]), None)
    assert res["design_ok"].tolist() == [False, True]
    assert all(math.isnan(res[m][0]) for m in METRICS) and all(np.isfinite(res[m][1]) for m in METRICS)


def test_user_metric_and_bad_input(build):
    um = UserMetric("link_sum", lambda mech, p: p["L1"] + p["L2"], "m", "total link length")
    st = model_study(build, VARS, site="tip", metrics=(), user_metrics=[um])
    assert st.evaluate_rows(ROWS[:1], None)["link_sum"][0] == pytest.approx(0.45)
    with pytest.raises(ValueError, match="task box"):
        model_study(build, VARS, site="tip", metrics=["workspace_measure"])
    with pytest.raises(ValueError, match="parameters of build"):
        model_study(build, [Variable("nope", 0, 1)], site="tip", metrics=["task_fraction"], task_box=BOX)
    with pytest.raises(ValueError, match="metrics among"):
        model_study(build, VARS, site="tip", metrics=["nope"], task_box=BOX)
    with pytest.raises(ValueError, match="build"):
        model_study(None, VARS, site="tip")


@pytest.mark.slow
def test_sweep_store_resume_and_labelled_results(small, client, tmp_path):
    study = small
    out = tmp_path / "s"
    seen = []

    def stop_after_two(k):
        seen.append(k)
        if len(seen) == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_sweep(study, out, designs=12, seed=2, client=client, progress=False, on_chunk=stop_after_two)
    done = open_results(out).attrs["chunk_done"]
    assert done.sum() == 2
    s = run_sweep(study, out, designs=12, seed=2, client=client, progress=False)
    assert s.computed_chunks == tuple(int(k) for k in np.flatnonzero(~done))
    ds = open_results(out)
    direct = study.evaluate_rows(np.stack([ds[v.name].values for v in VARS], -1), None)
    for m in METRICS:
        assert ds[m].values.tobytes() == direct[m].tobytes(), m
    assert ds["workspace_measure"].attrs["unit"] == "m^2" and ds["L1"].attrs["unit"] == "m"
    assert ds.to_dataframe().shape == (12, len(METRICS) + 1 + len(VARS))


def test_nsga2_on_a_model_study(build, client, tmp_path):
    from robomech.explore import Objective

    st = model_study(
        build,
        VARS,
        site="tip",
        metrics=("workspace_measure", "dexterity_mean"),
        task_box=BOX,
        task_grid_size=8,
        objectives=(Objective("workspace_measure", "max"), Objective("dexterity_mean", "max")),
    )
    s = optimize_nsga2(st, tmp_path / "o", population=4, generations=2, seed=0, client=client, progress=False)
    assert s.n_chunks == 2 and len(s.computed_chunks) == 2
    assert np.isfinite(open_results(tmp_path / "o")["workspace_measure"].values).any()


def test_cli_sweep_of_a_model_file(tmp_path, capsys):
    args = ["sweep", "--model", f"{MODEL}:build", "--site", "tip", "--task-box=-0.5:0.5,-0.5:0.5"]
    args += ["--task-grid", "8", "--metric", "workspace_measure", "--designs", "4", "--chunk-size", "2"]
    args += ["--workers", "1", "--quiet", "--out", str(tmp_path / "c")]
    assert main([*args, "--var", "L1=0.15:0.25", "--var", "L2=0.15:0.25", "--var", "B=0.05:0.15"]) == 0
    assert open_results(tmp_path / "c").sizes["design"] == 4
    assert main([*args[:-2], "--out", str(tmp_path / "d"), "--var", "Q=0:1"]) == 2
    assert "parameters of build" in capsys.readouterr().err
    assert main(["sweep", "--model", str(tmp_path / "missing.py:build"), "--site", "t", "--out", "x"]) == 2
    assert main(["sweep", "--out", str(tmp_path / "e")]) == 2  # neither STUDY nor --model
    assert "neither" in capsys.readouterr().err
    assert main(["sweep", "--model", f"{MODEL}:build", "--out", str(tmp_path / "f")]) == 2  # no --site


@pytest.mark.slow
def test_bit_identical_locally_and_on_a_two_worker_loopback_cluster(small, client, tmp_path):
    study = small
    from distributed import Client

    from robomech.explore import local_cluster

    run_sweep(study, tmp_path / "a", designs=12, seed=5, client=client, progress=False)
    with local_cluster(2) as cluster, Client(cluster) as c2:
        assert all(a.startswith("tcp://127.0.0.1:") for a in c2.scheduler_info()["workers"])
        s = run_sweep(study, tmp_path / "b", designs=12, seed=5, client=c2, progress=False)
        assert s.workers == 2
    a, b = open_results(tmp_path / "a"), open_results(tmp_path / "b")
    for name in ("design_ok", *METRICS):
        assert a[name].values.tobytes() == b[name].values.tobytes(), name


PENDULUM = (
    '<mujoco><worldbody><body name="b"><joint name="j" type="hinge" axis="0 0 1"/>'
    '<geom type="capsule" fromto="0 0 0 {L} 0 0" size="0.01"/><site name="tip" pos="{L} 0 0"/>'
    "</body></worldbody><actuator><motor joint='j'/></actuator></mujoco>"
)


def test_an_mjcf_template_study_reaches_the_circle_of_its_radius(tmp_path):
    from robomech.explore import template_builder

    path = tmp_path / "pendulum.xml"
    path.write_text(PENDULUM)
    build = template_builder(path)
    assert build.names == ("L",)
    st = model_study(
        build,
        [Variable("L", 0.1, 0.3, "m")],
        site="tip",
        metrics=["task_fraction"],
        task_points=[[0.0, 0.2, 0.0], [0.2, 0.0, 0.0], [0.5, 0.0, 0.0]],
    )
    res = st.evaluate_rows(np.array([[0.2], [0.25]]), None)
    # the tip reaches exactly the points at distance L from the hinge
    assert res["task_fraction"].tolist() == [2 / 3, 0.0]
    path2 = tmp_path / "dollar.xml"
    path2.write_text(PENDULUM.replace("{L}", "$L"))
    assert template_builder(path2)(L=0.2).nq == 1


DELTA = Path(__file__).resolve().parents[2] / "examples" / "models" / "delta.py"
# Central-difference step of the actuated angles (rad) for the virtual-work reference, and the
# tolerance on the torque: truncation O(h^2) times dU''' ~ 1 J plus the FK's closure tolerance
# over h (1e-10 m / 1e-5 rad of a ~1 kg mechanism: ~1e-4 N m).
FD_STEP = 1e-5
VIRTUAL_WORK_ATOL = 1e-4


@pytest.mark.slow
def test_delta_peak_torque_at_rest_equals_virtual_work_of_gravity():
    """Held at rest (a 'trajectory' that does not move), the actuator torques are the gravity load,
    tau_i = dU/dtheta_i: the potential energy differentiated through the forward kinematics
    (multibody.energy of the assembled configurations), independent of the inverse dynamics."""
    build = load_model(f"{DELTA}:build")
    params = {"arm": 0.22, "forearm": 0.55, "R": 0.18, "r": 0.05}
    mech = build(**params)
    z = mb.site_pose(mech, mech.q0, "tcp")[2, 3]
    still = (np.linspace(0.0, 1.0, 5), np.tile([0.03, -0.02, z + 0.02], (5, 1)))
    st = model_study(
        build,
        [Variable(k, v * 0.9, v * 1.1, "m") for k, v in params.items()],
        site="tcp",
        outputs="xyz",
        metrics=("peak_force", "rms_force"),
        trajectory=still,
    )
    res = st.evaluate_rows(np.array([list(params.values())]), None)
    ik = mb.inverse_kinematics(
        mech,
        "tcp",
        np.eye(4) + np.pad([[0.03], [-0.02], [z + 0.02]], ((0, 1), (3, 0))),
        weights=(0, 0, 0, 1, 1, 1),
        steps=4,
    )
    assert bool(ik.converged)
    th = ik.q_act
    grad = np.zeros(3)
    for i in range(3):
        e = np.eye(3)[i] * FD_STEP
        U = []
        for sgn in (1.0, -1.0):
            fk = mb.forward_kinematics(mech, th + sgn * e, ik.q)
            assert bool(fk.converged)
            U.append(mb.energy(mech, fk.q, np.zeros(mech.nv))[1])
        grad[i] = (U[0] - U[1]) / (2 * FD_STEP)
    assert res["peak_force"][0] == pytest.approx(np.max(np.abs(grad)), abs=VIRTUAL_WORK_ATOL)
    assert res["rms_force"][0] == pytest.approx(np.sqrt(np.mean(grad**2)), abs=VIRTUAL_WORK_ATOL)
    assert np.max(np.abs(grad)) > 0.1  # a real load (N m), not a vacuous comparison


# Seconds the killed run may take to store its first chunks (a LocalCluster start and numba compiles).
KILL_DEADLINE = 120.0


@pytest.mark.slow
def test_a_sweep_killed_with_sigkill_resumes_exactly_the_missing_chunks(small, client, tmp_path):
    """``robomech sweep --model`` in its own process group, SIGKILLed (client, cluster and all) once two
    chunks are stored; the rerun computes exactly the chunks not flagged done, and the store equals an
    uninterrupted sweep bit for bit."""
    import os
    import signal
    import subprocess
    import sys
    import time

    import zarr

    out = tmp_path / "k"
    cmd = [sys.executable, "-m", "robomech", "sweep", "--model", f"{MODEL}:build", "--site", "tip"]
    cmd += ["--var", "L1=0.15:0.25", "--var", "L2=0.15:0.25", "--var", "B=0.05:0.15"]
    cmd += [
        "--task-box=-0.5:0.5,-0.5:0.5",
        "--task-grid",
        "8",
        *[x for m in METRICS for x in ("--metric", m)],
    ]
    cmd += [
        "--designs",
        "24",
        "--chunk-size",
        "2",
        "--seed",
        "4",
        "--workers",
        "1",
        "--quiet",
        "--out",
        str(out),
    ]
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(MODEL.parents[2] / "src"), os.environ.get("PYTHONPATH", "")]),
    }
    proc = subprocess.Popen(
        cmd, env=env, start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    try:
        t0 = time.monotonic()
        done = 0
        while time.monotonic() - t0 < KILL_DEADLINE and proc.poll() is None:
            try:
                done = int(np.sum(zarr.open_group(str(out), mode="r")["chunk_done"][...]))
            except Exception:
                done = 0  # not created yet
            if done >= 2:
                break
            time.sleep(0.05)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(10)
    assert 2 <= done < 12, done
    before = np.asarray(zarr.open_group(str(out), mode="r")["chunk_done"][...], bool)
    st = model_study(load_model(f"{MODEL}:build"), [Variable("L1", 0.15, 0.25), Variable("L2", 0.15, 0.25),
                     Variable("B", 0.05, 0.15)], site="tip", metrics=METRICS, task_box=BOX, task_grid_size=8,
                     name=f"model:{MODEL}:build")  # fmt: skip
    s = run_sweep(st, out, designs=24, chunk_size=2, seed=4, client=client, progress=False)
    assert s.computed_chunks == tuple(int(k) for k in np.flatnonzero(~before))
    ref = tmp_path / "ref"
    run_sweep(st, ref, designs=24, chunk_size=2, seed=4, client=client, progress=False)
    a, b = open_results(out), open_results(ref)
    for name in ("design_ok", *METRICS):
        assert a[name].values.tobytes() == b[name].values.tobytes(), name


# Batched and per-design evaluation run the same per-sample kernels on the same numbers: equal to
# rounding (measured bit for bit on one machine); the bound leaves room for another summation order.
BATCH_RTOL = 1e-12


def _per_design(st, rows):
    """Each design alone: a chunk of one design (its own batch of one)."""
    res = [st.evaluate_rows(r[None], None) for r in rows]
    return {k: np.concatenate([r[k] for r in res]) for k in res[0]}


def _assert_same(a, b, names):
    assert a["design_ok"].tolist() == b["design_ok"].tolist()
    for name in names:
        x, y = a[name], b[name]
        assert np.array_equal(np.isnan(x), np.isnan(y)), name
        f = ~np.isnan(x)
        np.testing.assert_allclose(x[f], y[f], rtol=BATCH_RTOL, atol=0, err_msg=name)


def test_a_chunk_of_designs_in_one_batch_equals_each_design_alone(build):
    st = model_study(
        build, VARS, site="tip", metrics=(*METRICS, "constraint_distance"), task_box=BOX, task_grid_size=12
    )
    rng = np.random.default_rng(3)
    rows = np.column_stack(
        [rng.uniform(0.15, 0.25, 5), rng.uniform(0.15, 0.25, 5), rng.uniform(0.05, 0.15, 5)]
    )
    rows = np.insert(rows, 2, [0.01, 0.01, 0.15], axis=0)  # a design that cannot be built: failed, masked
    rows = np.insert(rows, 4, [np.nan, 0.2, 0.1], axis=0)  # a non-finite design row
    batched = st.evaluate_rows(rows, None)
    assert batched["design_ok"].tolist() == [True, True, False, True, False, True, True]
    _assert_same(batched, _per_design(st, rows), (*METRICS, "constraint_distance"))


@pytest.mark.slow
def test_delta_designs_in_one_batch_equal_each_design_alone():
    import sys

    sys.path.insert(0, str(DELTA.parent))
    import delta

    st = delta.study()
    rows = np.array([[0.25, 0.6, 0.2, 0.05], [0.22, 0.65, 0.18, 0.045], [0.28, 0.55, 0.22, 0.06]])
    batched = st.evaluate_rows(rows, None)
    assert batched["design_ok"].all() and np.all(np.isfinite(batched["peak_force"]))
    _assert_same(batched, _per_design(st, rows), ("peak_force", "rms_force"))


def _arm(L=0.2, n=2.0):
    """A planar arm of 2 links, or 3 when ``n >= 2.5`` (the topology changes with a parameter)."""
    b = mb.Builder("arm")
    links = 3 if n >= 2.5 else 2
    parent = "world"
    for i in range(links):
        b.body(f"l{i}", parent, pos=(0, 0, 0) if i == 0 else (L, 0, 0), joints=[b.hinge(f"j{i}", ref=0.3)])
        parent = f"l{i}"
    b.site("tip", parent, pos=(L, 0, 0))
    b.actuate(*[f"j{i}" for i in range(links)])
    return b.build()


def test_designs_of_two_structures_in_one_chunk_equal_each_design_alone():
    st = model_study(
        _arm,
        [Variable("L", 0.1, 0.2, "m"), Variable("n", 2.0, 3.0)],
        site="tip",
        metrics=("workspace_measure", "task_fraction", "dexterity_min", "dexterity_mean"),
        task_box=[[-0.7, 0.7], [-0.7, 0.7]],
        task_grid_size=8,
    )
    rows = np.array([[0.15, 2.0], [0.15, 3.0], [0.12, 2.2], [0.18, 2.9]])
    batched = st.evaluate_rows(rows, None)
    assert batched["design_ok"].all()
    # the 3-link arms reach farther than the 2-link arm of the same link length
    assert batched["workspace_measure"][1] > batched["workspace_measure"][0]
    _assert_same(batched, _per_design(st, rows), ("workspace_measure", "task_fraction", "dexterity_min"))


@pytest.mark.slow
def test_workspace_area_of_64_sobol_designs_equals_the_annuli_count(build):
    """The grid wavefront (explore._model.reach_grid) over the design space: every design's reached
    cell count against the closed-form annuli count, cells within EDGE of a boundary either way."""
    from robomech.explore import design_matrix

    st = model_study(
        build, VARS, site="tip", metrics=("workspace_measure",), task_box=BOX, task_grid_size=GRID
    )
    X = design_matrix(VARS, 64, "sobol", 0, 64)
    res = st.evaluate_rows(X, None)
    assert res["design_ok"].all()
    pts, _ = task_grid(np.array(BOX), GRID, "xy", np.zeros(3))
    h2 = (1.0 / GRID) ** 2
    for (L1, L2, B), area in zip(X, res["workspace_measure"], strict=True):
        inside, margin = _in_annuli(pts[:, :2], L1, L2, B)
        n_edge = int(np.sum(margin <= EDGE))
        assert abs(round(area / h2) - inside.sum()) <= n_edge


def test_reach_bound_is_each_legs_outer_circle_and_holds_every_configuration(build):
    """The five-bar's reach spheres: the site's own chain gives the left leg's outer circle (centre
    A_left, radius L1 + L2, closed form) and the closure the right leg's; random configurations (loops
    open) stay inside the site's own sphere, closed ones (reached task points) inside every sphere."""
    from robomech.multibody._designs import design_batch, site_poses_designs

    rows = [(0.2, 0.15, 0.1), (0.15, 0.25, 0.05), (0.25, 0.2, 0.15)]
    mechs = [build(L1=a, L2=b, B=c) for a, b, c in rows]
    batch = design_batch(mechs, "tip")
    centres, radii = reach_bound(batch)
    rng = np.random.default_rng(3)
    for i, (L1, L2, B) in enumerate(rows):
        for side in (-1.0, 1.0):
            hit = np.linalg.norm(centres[i] - [side * B / 2, 0.0, 0.0], axis=1) < 1e-12
            assert np.any(hit & (np.abs(radii[i] - (L1 + L2)) < 1e-9))
        q = rng.uniform(-np.pi, np.pi, (500, batch.q_ref.shape[1]))
        p = site_poses_designs(batch, np.full(500, i), q)[:, :3, 3]
        assert np.all(np.linalg.norm(p - centres[i, 0], axis=1) <= radii[i, 0] * (1 + 1e-12))
        c = np.linspace(-0.5, 0.5, 12)
        pts = np.stack(np.meshgrid(c, c, indexing="ij"), -1).reshape(-1, 2)
        qc, ok = reach(mechs[i], "tip", np.column_stack([pts, np.zeros(len(pts))]), "xy")
        assert ok.sum() > 10
        p = site_poses_designs(batch, np.full(ok.sum(), i), qc[ok])[:, :3, 3]
        assert np.all(np.linalg.norm(p[:, None, :] - centres[i][None], axis=-1) <= radii[i] * (1 + 1e-9))


def test_reach_bound_of_a_free_base_chain_is_infinite_and_of_its_closures_finite():
    """The Delta's platform (the site's body) is a free body: no bound from its own chain; each rod's
    closure to it bounds it through the rod's ball, the arm's hinge and the base."""
    import sys

    from robomech.multibody._designs import design_batch

    sys.path.insert(0, str(MODEL.parent))
    import delta

    centres, radii = reach_bound(design_batch([delta.build(arm=0.25, forearm=0.6, R=0.2, r=0.05)], "tcp"))
    assert np.isinf(radii[0, 0]) and radii.shape[1] == 7  # the platform's chain; six rods' closures
    # centre: the arm's hinge anchor at the base radius R; radius: hinge -> ball (arm, +-w), the rod,
    # closure point -> tcp (r, +-w), closed form
    w = delta.HALF_WIDTH
    np.testing.assert_allclose(np.linalg.norm(centres[0, 1:], axis=1), 0.2, rtol=1e-12)
    np.testing.assert_allclose(radii[0, 1:], np.hypot(0.25, w) + 0.6 + np.hypot(0.05, w), rtol=1e-9)


def test_batched_assembly_failure_equals_each_designs_forward_kinematics():
    """The assembly failure of a chunk of designs (one design-batched closure solve) equals, design by
    design, ``1 - mean(mb.forward_kinematics(mech, grid).converged)``, the metric's definition: 16
    Sobol five-bars over an input box where part of the grid does not assemble, and Deltas."""
    import sys

    from robomech.explore import design_matrix
    from robomech.explore._model import assembly_failure_designs
    from robomech.multibody._designs import design_batch

    sys.path.insert(0, str(MODEL.parent))
    import delta
    import five_bar

    X = design_matrix(VARS, 16, "sobol", 0, 16)
    cases = [
        ([five_bar.build(*r) for r in X], "tip", [[-0.5, 2.5], [0.5, 3.5]], 9),
        (
            [delta.build(a, f, 0.2, 0.05) for a, f in [(0.25, 0.6), (0.2, 0.5), (0.3, 0.7)]],
            "tcp",
            [[-1.2, 1.5]] * 3,
            4,
        ),
    ]
    for mechs, site, box, grid in cases:
        got = assembly_failure_designs(mechs, design_batch(mechs, site), box, grid)
        axes = [np.linspace(lo, hi, grid) for lo, hi in box]
        qa = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, len(box))
        want = [1.0 - np.mean(mb.forward_kinematics(m, qa).converged) for m in mechs]
        assert 0.0 < np.min(want) and np.max(want) < 1.0
        np.testing.assert_array_equal(got, want)
