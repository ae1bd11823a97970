"""Sweep stores damaged by hand are named, not read as NaN; bad runtime options are refused before work.

Every damage is made the way a user would (deleting or truncating a chunk file, deleting an array's
metadata); the store must then say which chunk or array is wrong (``StoreDamaged``, exit 2), and a
resume must recompute exactly the damaged chunks.  Servers started here bind 127.0.0.1, are bounded
in time and are stopped.
"""

import shutil
import socket
import threading
import time
from http.server import BaseHTTPRequestHandler, HTTPServer

import numpy as np
import pytest

from robomech.cli import main
from robomech.explore import (
    SchedulerUnreachable,
    Variable,
    design_matrix,
    get_study,
    open_results,
    run_sweep,
    with_variables,
)
from robomech.explore._store import StoreDamaged

STUDY = "spherical-leg-synthesis"
SMALL = {"designs": 24, "chunk_size": 6, "seed": 3}
# Seconds a refused connection may take end to end (connect timeout 2 s plus process overhead).
BOUNDED = 8.0


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


@pytest.fixture(scope="module")
def pristine(tmp_path_factory, client):
    out = tmp_path_factory.mktemp("pristine") / "s"
    run_sweep(get_study(STUDY), out, client=client, progress=False, **SMALL)
    return out


def _copy(pristine, tmp_path):
    out = tmp_path / "s"
    shutil.copytree(pristine, out)
    return out


def _chunk_file(out, name, k):
    base = out / name / "c" / str(k)
    return base / "0" if base.is_dir() else base


def test_a_deleted_metric_chunk_is_named_and_a_resume_recomputes_only_it(pristine, tmp_path, client, capsys):
    out = _copy(pristine, tmp_path)
    metric = get_study(STUDY).metrics[0].name
    _chunk_file(out, metric, 2).unlink()
    with pytest.raises(StoreDamaged, match=r"chunk 2: checksum mismatch"):
        open_results(out)
    s = run_sweep(get_study(STUDY), out, client=client, progress=False, **SMALL)
    assert s.computed_chunks == (2,)
    assert "chunk 2" in capsys.readouterr().err
    a, b = open_results(out, as_dict=True), open_results(pristine, as_dict=True)
    for m in get_study(STUDY).metrics:
        assert a[m.name].tobytes() == b[m.name].tobytes(), m.name


def test_a_truncated_chunk_is_named_not_a_decoder_error(pristine, tmp_path, client):
    out = _copy(pristine, tmp_path)
    metric = get_study(STUDY).metrics[0].name
    f = _chunk_file(out, metric, 1)
    f.write_bytes(f.read_bytes()[:5])
    with pytest.raises(StoreDamaged, match=rf"chunk 1: {metric} unreadable"):
        open_results(out)
    s = run_sweep(get_study(STUDY), out, client=client, progress=False, **SMALL)
    assert s.computed_chunks == (1,)
    assert open_results(out)[metric].shape[0] == 24


def test_a_deleted_array_metadata_or_chunk_done_is_named(pristine, tmp_path, client):
    metric = get_study(STUDY).metrics[-1].name
    for victim in (metric, "chunk_done"):
        out = tmp_path / victim
        shutil.copytree(pristine, out)
        (out / victim / "zarr.json").unlink()
        with pytest.raises(StoreDamaged, match=victim):
            open_results(out)
        with pytest.raises(StoreDamaged, match=victim):
            run_sweep(get_study(STUDY), out, client=client, progress=False, **SMALL)


def test_a_store_whose_creation_was_cut_short_says_so(pristine, tmp_path):
    import json

    out = _copy(pristine, tmp_path)
    meta = json.loads((out / "zarr.json").read_text())
    meta["attributes"] = {}
    (out / "zarr.json").write_text(json.dumps(meta))
    code = main(["sweep", STUDY, "--out", str(out), "--quiet", "--designs", "24", "--chunk-size", "6"])
    assert code == 2


def test_the_pristine_store_verifies_and_opens_as_a_labelled_dataset(pristine):
    ds = open_results(pristine)
    st = get_study(STUDY)
    assert ds.sizes["design"] == 24 and ds.attrs["study"] == STUDY
    for v in st.variables:
        np.testing.assert_array_equal(
            ds[v.name].values,
            design_matrix(st.variables, 24, "sobol", 3, 6)[:, st.variable_names.index(v.name)],
        )
        assert ds[v.name].attrs["unit"] == v.unit
    for m in st.metrics:
        assert ds[m.name].attrs["unit"] == m.unit
    scalar = [m.name for m in st.metrics if m.shape == ()]
    df = ds[scalar].to_dataframe()
    assert df.shape == (24, len(scalar) + len(st.variables))


def test_out_that_cannot_be_created_is_refused_before_a_cluster_starts(monkeypatch, tmp_path):
    import robomech.explore._runner as runner

    def boom(*a, **k):
        raise AssertionError("a cluster was started")

    monkeypatch.setattr(runner, "local_cluster", boom)
    with pytest.raises(ValueError, match="out"):
        run_sweep(get_study(STUDY), "/proc/x", progress=False, **SMALL)
    assert main(["sweep", STUDY, "--out", "/proc/x", "--quiet", "--designs", "4"]) == 2


def test_a_client_that_is_not_a_client_is_refused_before_a_store_is_written(tmp_path):
    with pytest.raises(ValueError, match="client"):
        run_sweep(get_study(STUDY), tmp_path / "s", client=object(), progress=False, **SMALL)
    assert not (tmp_path / "s").exists()


def test_unbounded_design_matrix_and_duplicate_variables_are_refused():
    v = [Variable("a", 0.0, 1.0)]
    with pytest.raises(ValueError, match="n"):
        design_matrix(v, 10**15, "sobol", 0, 8)
    with pytest.raises(ValueError, match="more than once"):
        design_matrix([*v, Variable("a", 0.0, 2.0)], 4, "sobol", 0, 2)
    with pytest.raises(ValueError, match="more than once"):
        with_variables(get_study(STUDY), [Variable("R", 0.1, 0.2), Variable("R", 0.1, 0.3)])


class _Http(BaseHTTPRequestHandler):
    def do_GET(self):  # pragma: no cover - never asked: Dask writes its own frames
        self.send_response(200)
        self.end_headers()

    def log_message(self, *a):
        pass


def _serve(server):
    t = threading.Thread(target=server.serve_forever, kwargs={"poll_interval": 0.05}, daemon=True)
    t.start()
    return t


@pytest.mark.slow
def test_scheduler_at_an_http_port_or_a_silent_port_is_unreachable_within_the_timeout(tmp_path):
    http = HTTPServer(("127.0.0.1", 0), _Http)
    silent = socket.socket()
    silent.bind(("127.0.0.1", 0))
    silent.listen(4)  # accepts (the kernel's backlog) and never answers
    t = _serve(http)
    try:
        for port in (http.server_address[1], silent.getsockname()[1]):
            t0 = time.monotonic()
            with pytest.raises(SchedulerUnreachable):
                run_sweep(
                    get_study(STUDY),
                    tmp_path / f"s{port}",
                    scheduler=f"tcp://127.0.0.1:{port}",
                    connect_timeout=2.0,
                    progress=False,
                    **SMALL,
                )
            assert time.monotonic() - t0 < BOUNDED
            args = ["sweep", STUDY, "--out", str(tmp_path / f"c{port}"), "--quiet", "--designs", "4"]
            args += ["--scheduler", f"tcp://127.0.0.1:{port}", "--connect-timeout", "2"]
            assert main(args) == 2
    finally:
        http.shutdown()
        http.server_close()
        silent.close()
        t.join(5)
