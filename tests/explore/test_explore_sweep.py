"""Sweeps end to end in one process (an in-process Dask cluster): store, resume, bad input, exit codes."""

import hashlib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hst

from robomech.cli import main
from robomech.explore import (
    SAMPLERS,
    StoreMismatch,
    Variable,
    design_matrix,
    get_study,
    open_results,
    pareto_front,
    run_sweep,
    with_variables,
)

STUDY = "spherical-leg-synthesis"
SMALL = {"designs": 24, "chunk_size": 6, "seed": 3}


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


def _tree_digest(path: Path) -> str:
    h = hashlib.sha256()
    for p in sorted(path.rglob("*")):
        h.update(str(p.relative_to(path)).encode())
        if p.is_file():
            h.update(p.read_bytes())
    return h.hexdigest()


def test_store_layout_and_attributes(tmp_path, client):
    s = run_sweep(get_study(STUDY), tmp_path / "s", client=client, progress=False, **SMALL)
    assert s.n_chunks == 4 and s.computed_chunks == (0, 1, 2, 3) and s.skipped_chunks == 0
    r = open_results(tmp_path / "s", as_dict=True)
    st = get_study(STUDY)
    assert r["designs"].shape == (24, 3)
    np.testing.assert_array_equal(r["designs"], design_matrix(st.variables, 24, "sobol", 3, 6))
    for m in st.metrics:
        assert r[m.name].shape[0] == 24
    assert r["chunk_done"].all() and np.all(r["chunk_seconds"] > 0) and np.all(r["chunk_cpu_seconds"] > 0)
    a = r["attrs"]
    assert a["study"] == STUDY and a["robomech_version"] and a["units"]["R"] == "m"
    assert [v["name"] for v in a["variables"]] == ["R", "r", "h"]
    assert a["parameters"]["task_grid"] == 41 and a["fingerprint"]["seed"] == 3
    direct = st.evaluate_rows(r["designs"], None)
    for k, v in direct.items():  # the Dask path returns exactly the direct evaluation
        np.testing.assert_array_equal(r[k], v)


def test_rerun_computes_nothing_and_interrupted_run_resumes_missing_chunks(tmp_path, client):
    out = tmp_path / "s"

    def stop_after_two(k, seen=[]):  # noqa: B006 - counts calls within this run
        seen.append(k)
        if len(seen) == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_sweep(get_study(STUDY), out, client=client, progress=False, on_chunk=stop_after_two, **SMALL)
    done = open_results(out, as_dict=True)["chunk_done"]
    assert done.sum() == 2
    s = run_sweep(get_study(STUDY), out, client=client, progress=False, **SMALL)
    assert set(s.computed_chunks) == set(np.flatnonzero(~done)) and s.skipped_chunks == 2
    again = run_sweep(get_study(STUDY), out, client=client, progress=False, **SMALL)
    assert again.computed_chunks == () and again.skipped_chunks == 4
    ref = run_sweep(get_study(STUDY), tmp_path / "ref", client=client, progress=False, **SMALL)
    assert ref.computed_chunks == (0, 1, 2, 3)
    a, b = open_results(out, as_dict=True), open_results(tmp_path / "ref", as_dict=True)
    for m in get_study(STUDY).metrics:
        assert a[m.name].tobytes() == b[m.name].tobytes()


def test_another_sweep_in_the_same_store_is_refused_and_nothing_is_overwritten(tmp_path, client):
    out = tmp_path / "s"
    run_sweep(get_study(STUDY), out, client=client, progress=False, **SMALL)
    before = _tree_digest(out)
    with pytest.raises(StoreMismatch, match="nothing was overwritten"):
        run_sweep(get_study("omnileg-synthesis"), out, client=client, progress=False, designs=4)
    with pytest.raises(StoreMismatch, match="seed"):
        run_sweep(get_study(STUDY), out, client=client, progress=False, **{**SMALL, "seed": 4})
    assert main(["sweep", "omnileg-synthesis", "--out", str(out), "--quiet"]) == 2
    assert _tree_digest(out) == before


def test_a_folder_with_other_files_is_refused(tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("mine")
    assert main(["sweep", STUDY, "--out", str(tmp_path), "--designs", "4", "--quiet"]) == 2
    assert "other files" in capsys.readouterr().err
    assert [p.name for p in tmp_path.iterdir()] == ["notes.txt"]


@pytest.mark.parametrize(
    "argv, message",
    [
        (["sweep", "no-such-study"], "valid studies are"),
        (["sweep", STUDY, "--var", "L9=0.1:0.2"], "name fields of SphericalLeg"),
        (["sweep", STUDY, "--var", "R=0.1:0.1"], "empty range"),
        (["sweep", STUDY, "--var", "R=0.2:0.1"], "inverted range"),
        (["sweep", STUDY, "--var", "R=a:b"], "Expected numbers"),
        (["sweep", STUDY, "--var", "R=0.01"], "manufacturing errors"),
        (["sweep", "vectored-thrust-tolerance", "--var", "q1_offset=0:1"], "standard deviation"),
        (["sweep", "vectored-thrust-tolerance", "--var", "q1_offset=-1"], "sigma > 0"),
        (["sweep", STUDY, "--designs", "0"], "designs to be an integer in [1, inf]"),
        (["sweep", STUDY, "--scheduler", "127.0.0.1:1"], "tcp://HOST:PORT"),
        (["sweep", STUDY, "--scheduler", "tcp://127.0.0.1:9", "--connect-timeout", "1"], "no answer"),
    ],
)
def test_bad_input_is_a_clear_error_with_exit_code_2(tmp_path, capsys, argv, message):
    out = tmp_path / "s"
    assert main([*argv, "--out", str(out), "--quiet"]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists() or not any(out.iterdir())


def test_variable_validation_and_overrides():
    st = get_study(STUDY)
    with pytest.raises(ValueError, match="inverted"):
        Variable("R", 0.2, 0.1)
    with pytest.raises(ValueError, match="a finite range"):
        Variable("R", 0.1, float("inf"))
    with pytest.raises(ValueError, match="high to be a finite real"):
        Variable("R", 0.1, float("nan"))
    narrowed = with_variables(st, [Variable("R", 0.07, 0.08)])
    assert narrowed.variables[0].low == 0.07 and narrowed.variables[0].unit == "m"
    extended = with_variables(st, [Variable("length_max", 0.15, 0.2)])
    assert extended.variable_names == ("R", "r", "h", "length_max")


@pytest.mark.parametrize("sampler", SAMPLERS)
def test_samplers_stay_in_range_and_are_deterministic(sampler):
    st = get_study(STUDY)
    X = design_matrix(st.variables, 30, sampler, 7, 8)
    np.testing.assert_array_equal(X, design_matrix(st.variables, 30, sampler, 7, 8))
    lo = np.array([v.low for v in st.variables])
    hi = np.array([v.high for v in st.variables])
    assert np.all((X >= lo) & (X <= hi))
    assert X.shape == ((27, 3) if sampler == "grid" else (30, 3))
    if sampler != "grid":
        assert not np.array_equal(X, design_matrix(st.variables, 30, sampler, 8, 8))


def test_random_sampler_extends_with_more_designs():
    st = get_study("vectored-thrust-tolerance")
    a = design_matrix(st.variables, 16, "random", 0, 8)
    b = design_matrix(st.variables, 40, "random", 0, 8)
    np.testing.assert_array_equal(a, b[:16])
    big = design_matrix(st.variables, 20000, "random", 0, 256)
    assert np.std(big[:, 0]) == pytest.approx(st.variables[0].sigma, rel=0.03)


def test_pareto_front_is_nondominated_and_complete():
    rng = np.random.default_rng(0)
    m = {"a": rng.random(200), "b": rng.random(200), "design_ok": np.ones(200, bool)}
    m["a"][5] = np.nan
    from robomech.explore import Objective

    objs = (Objective("a", "max"), Objective("b", "min"))
    front = pareto_front(m, objs)
    F = np.column_stack([-m["a"], m["b"]])
    for i in range(200):
        if i == 5:
            assert i not in front
            continue
        dominated = any(np.all(F[j] <= F[i]) and np.any(F[j] < F[i]) for j in range(200) if j != 5 and j != i)
        assert (i in front) == (not dominated)


def test_nsga2_evaluates_through_the_store_and_reuses_it(tmp_path, client):
    from robomech.explore import optimize_nsga2

    st = get_study(STUDY)
    s = optimize_nsga2(st, tmp_path / "o", population=8, generations=2, seed=1, client=client, progress=False)
    assert s.computed_chunks == (0, 1) and s.n_designs == 16
    r = open_results(tmp_path / "o", as_dict=True)
    assert r["chunk_done"].all() and np.isfinite(r["designs"]).all()
    direct = st.evaluate_rows(r["designs"], None)
    np.testing.assert_array_equal(r["workspace_fraction"], direct["workspace_fraction"])
    again = optimize_nsga2(
        st, tmp_path / "o", population=8, generations=2, seed=1, client=client, progress=False
    )
    assert again.computed_chunks == ()


def test_report_pages_from_stores(tmp_path, client):
    from robomech.studies._sweep import write_sweep_report

    run_sweep(get_study(STUDY), tmp_path / "a", client=client, progress=False, **SMALL)
    md = write_sweep_report(tmp_path / "a", tmp_path / "ra").read_text()
    assert "Pareto front" in md and "pareto_front.png" in md
    png = (tmp_path / "ra" / "pareto_front.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    st = get_study("vectored-thrust-tolerance")
    run_sweep(st, tmp_path / "b", client=client, progress=False, designs=64, chunk_size=32)
    md = write_sweep_report(tmp_path / "b", tmp_path / "rb").read_text()
    assert "Sensitivity ranking" in md and "tolerance_histograms.png" in md and "worst case" in md
    assert (tmp_path / "rb" / "report.html").exists() and (tmp_path / "rb" / "results.json").exists()


def test_cli_report_and_json(tmp_path, capsys):
    import json

    out = tmp_path / "s"
    argv = ["sweep", "omnileg-synthesis", "--out", str(out), "--designs", "8", "--chunk-size", "4"]
    assert main([*argv, "--workers", "1", "--report", "--json", "--quiet"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["computed_chunks"] == 2 and Path(res["report"]).exists()
    assert (out / "report" / "pareto_front.png").exists()
    assert main([*argv, "--workers", "1", "--json", "--quiet"]) == 0  # resumed: nothing to compute
    assert json.loads(capsys.readouterr().out)["computed_chunks"] == 0


def test_sweep_demo_is_a_registered_study():
    from robomech.studies import available_studies

    assert "sweep-demo" in available_studies()


@pytest.mark.parametrize(
    "name", ["spherical-leg-synthesis", "vectored-thrust-tolerance", "omnileg-synthesis"]
)
def test_a_designs_result_does_not_depend_on_its_chunk(name):
    # the basis of bit-identical sweeps with any chunking of the work among workers
    st = get_study(name)
    X = design_matrix(st.variables, 6, st.default_sampler, 2, 6)
    whole = st.evaluate_rows(X, None)
    parts = [st.evaluate_rows(X[i : i + 1], None) for i in range(6)]
    for k, v in whole.items():
        assert v.tobytes() == np.concatenate([p[k] for p in parts]).tobytes(), k


def test_progress_bar_on_stderr(tmp_path, client, capsys):
    run_sweep(get_study(STUDY), tmp_path / "s", client=client, progress=True, **SMALL)
    err = capsys.readouterr().err
    assert "24/24 designs (100%)" in err and "designs/s" in err and "s left" in err


@settings(max_examples=25)
@given(
    lo=hst.floats(-1e3, 1e3),
    width=hst.floats(1e-6, 1e3),
    n=hst.integers(1, 70),
    sampler=hst.sampled_from(["sobol", "lhs", "random"]),
    seed=hst.integers(0, 2**32),
)
def test_range_samples_stay_inside_any_range(lo, width, n, sampler, seed):
    v = Variable("x", lo, lo + width)
    X = design_matrix([v, Variable("y", 0.0, 1.0)], n, sampler, seed, 16)
    assert X.shape == (n, 2) and np.all((X[:, 0] >= v.low) & (X[:, 0] <= v.high))


def test_cli_interrupt_says_how_to_resume(monkeypatch, tmp_path, capsys):
    import robomech.explore as ex

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(ex, "run_sweep", interrupted)
    assert main(["sweep", STUDY, "--out", str(tmp_path / "s"), "--quiet"]) == 130
    assert "rerun the same command" in capsys.readouterr().err


def test_list_names_the_design_studies_in_text_and_json(capsys, monkeypatch):
    import json

    from robomech.explore import available_studies

    assert main(["list"]) == 0
    text = capsys.readouterr().out
    section = text.split("design studies (robomech sweep NAME --out DIR):\n", 1)[1]
    section_lines = []
    for ln in section.splitlines():  # up to the next heading (the gallery and descriptions follow)
        if not ln.startswith("  "):
            break
        section_lines.append(ln)
    lines = {ln.split()[0]: ln for ln in section_lines}
    assert set(lines) == set(available_studies())
    for name, st in available_studies().items():
        assert st.title in lines[name] and "skipped" not in lines[name]
    assert main(["list", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [d["name"] for d in data["design_studies"]] == list(available_studies())
    assert all(d["skipped"] is None and d["title"] for d in data["design_studies"])
    # without the Dask/Zarr extra the design studies are still listed, marked skipped with the reason
    import robomech._registry as reg

    real = reg.skip_reason
    monkeypatch.setattr(reg, "skip_reason", lambda req: "no zarr here" if "zarr" in req else real(req))
    assert main(["list", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert {d["skipped"] for d in data["design_studies"]} == {"no zarr here"}


def test_chunk_writer_writes_rows_then_the_flag_and_refuses_unknown_arrays(tmp_path):
    from robomech.explore._runner import evaluate_chunk, sweep_fingerprint
    from robomech.explore._store import ChunkWriter, prepare_store

    st = get_study("vectored-thrust-tolerance")
    X = design_matrix(st.variables, 8, st.default_sampler, 1, 4)
    out = tmp_path / "s"
    prepare_store(out, st, X, 4, sweep_fingerprint(st, 8, st.default_sampler, 1, 4), st.describe())
    k, res, secs, cpu = evaluate_chunk(st, X[4:], 1, 1)
    names = ["design_ok", *(m.name for m in st.metrics)]
    with ChunkWriter(out, names) as w:
        with pytest.raises(RuntimeError, match="other than the store"):
            w.write(0, slice(0, 4), {**res, "not_a_metric": res["rms_error"]}, secs, cpu)
        w.write(k, slice(4, 8), res, secs, cpu)
    r = open_results(out, as_dict=True)
    assert r["chunk_done"].tolist() == [False, True]  # the refused chunk wrote nothing
    assert r["chunk_seconds"][1] == secs and r["chunk_cpu_seconds"][1] == cpu
    assert np.isnan(r["rms_error"][:4]).all()
    for name, arr in res.items():
        assert r[name][4:].tobytes() == arr.tobytes(), name


@pytest.mark.slow
def test_local_cluster_workers_are_single_threaded_for_every_threaded_library():
    import os

    import dask.config

    from robomech.explore._runner import LOCAL_CLUSTER_CONFIG, WORKER_ENV, dask_client

    with dask_client(workers=1) as c:
        env = c.run(lambda: {k: os.environ.get(k) for k in WORKER_ENV})
        assert list(env.values()) == [WORKER_ENV]
        # the background settings reach the worker process (through its nanny) and the scheduler
        cfg = c.run(lambda: {k: dask.config.get(k) for k in LOCAL_CLUSTER_CONFIG})
        assert list(cfg.values()) == [LOCAL_CLUSTER_CONFIG]
        # the scheduler lives in this process: its tick callback was made while the settings were set
        tick_ms = c.run_on_scheduler(
            lambda dask_scheduler: dask_scheduler.periodic_callbacks["tick"].callback_time
        )
        assert tick_ms == 1000.0
        profiling = c.run(lambda dask_worker: "profile" in dask_worker.periodic_callbacks)
        assert list(profiling.values()) == [False]
        assert c.scheduler_info()["workers"] and all(
            w["nthreads"] == 1 for w in c.scheduler_info()["workers"].values()
        )
