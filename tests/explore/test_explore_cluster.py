"""Acceptance: a real Dask scheduler and workers as separate processes on 127.0.0.1.

The cluster is started once for the module (a scheduler and two single-threaded workers, loopback only,
dashboards on loopback ephemeral ports, every process with an idle/lifetime limit so nothing outlives a
crashed test run) and stopped at the end, also on failure; a watchdog kills it after WATCHDOG seconds.
"""

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from robomech.cli import main
from robomech.explore import design_matrix, get_study, open_results, run_sweep
from robomech.explore._runner import evaluate_chunk

pytestmark = pytest.mark.slow

SRC = Path(__file__).resolve().parents[2] / "src"
DASK = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
WORKER = [sys.executable, "-m", "distributed.cli.dask_worker"]
# Seconds allowed for the scheduler file to appear / for workers to register (a loaded 2-core machine).
START_TIMEOUT = 90.0
# Seconds after which the watchdog kills every process this module started.
WATCHDOG = 400.0
# Idle / lifetime limits handed to the processes themselves (they stop even if the test process dies).
PROCESS_LIFETIME = "600s"
# Seconds a process gets to exit on SIGTERM before it is killed (a worker may be mid-chunk).
STOP_GRACE = 3.0

STUDY = "spherical-leg-synthesis"
ARGS = ["--designs", "48", "--chunk-size", "6", "--seed", "11", "--quiet"]  # 8 chunks


def _env():
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(SRC), *filter(None, [env.get("PYTHONPATH")])])
    env["DASK_DISTRIBUTED__WORKER__DAEMON"] = "False"
    return env


class _Cluster:
    def __init__(self, tmp: Path) -> None:
        self.procs: dict[str, subprocess.Popen] = {}
        self.tmp = tmp
        self.address = ""
        self._timer = threading.Timer(WATCHDOG, self.stop)
        self._timer.daemon = True

    def start(self) -> None:
        self._timer.start()
        sfile = self.tmp / "scheduler.json"
        self.procs["scheduler"] = subprocess.Popen(
            [*DASK, "--host", "127.0.0.1", "--port", "0", "--dashboard-address", "127.0.0.1:0",
             "--no-dashboard", "--scheduler-file", str(sfile), "--idle-timeout", PROCESS_LIFETIME],
            env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        deadline = time.monotonic() + START_TIMEOUT
        while not sfile.exists() or not sfile.read_text().strip():
            if time.monotonic() > deadline or self.procs["scheduler"].poll() is not None:
                raise RuntimeError("the Dask scheduler did not start")
            time.sleep(0.2)
        time.sleep(0.2)
        self.address = json.loads(sfile.read_text())["address"]
        assert self.address.startswith("tcp://127.0.0.1:")
        for name in ("w1", "w2"):
            self.add_worker(name)
        self.wait_workers(2)

    def add_worker(self, name: str) -> None:
        self.procs[name] = subprocess.Popen(
            [*WORKER, self.address, "--name", name, "--nthreads", "1", "--no-nanny", "--host", "127.0.0.1",
             "--dashboard-address", "127.0.0.1:0", "--no-dashboard", "--death-timeout", "60",
             "--lifetime", PROCESS_LIFETIME],
            env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip

    def workers(self) -> dict[str, str]:
        from distributed import Client

        with Client(self.address, timeout=30) as c:
            return {w["name"]: a for a, w in c.scheduler_info()["workers"].items()}

    def wait_workers(self, n: int) -> None:
        deadline = time.monotonic() + START_TIMEOUT
        while len(self.workers()) < n:
            if time.monotonic() > deadline:
                raise RuntimeError(f"expected {n} Dask workers to register")
            time.sleep(0.3)

    def stop(self) -> None:
        """SIGTERM every process this module started, SIGKILL what is left after STOP_GRACE seconds."""
        for p in self.procs.values():
            if p.poll() is None:
                p.send_signal(signal.SIGTERM)
        deadline = time.monotonic() + STOP_GRACE
        for p in self.procs.values():
            try:
                p.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait(timeout=30)
        self._timer.cancel()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    c = _Cluster(tmp_path_factory.mktemp("dask"))
    try:
        c.start()
        yield c
    finally:
        c.stop()
    assert all(p.poll() is not None for p in c.procs.values())


@pytest.fixture(scope="module")
def local_run(tmp_path_factory):
    """The same sweep on the default LocalCluster (one worker process here)."""
    out = tmp_path_factory.mktemp("local") / "s"
    assert main(["sweep", STUDY, "--out", str(out), "--workers", "1", *ARGS]) == 0
    return open_results(out, as_dict=True)


def _assert_identical(a: dict, b: dict) -> None:
    names = [m.name for m in get_study(STUDY).metrics] + ["designs", "design_ok", "chunk_done"]
    for name in names:
        assert a[name].dtype == b[name].dtype and a[name].tobytes() == b[name].tobytes(), name


def test_cluster_run_is_bit_identical_to_the_local_run(cluster, local_run, tmp_path, capsys):
    out = tmp_path / "s"
    assert main(["sweep", STUDY, "--out", str(out), "--scheduler", cluster.address, "--json", *ARGS]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["workers"] == 2 and summary["computed_chunks"] == 8
    r = open_results(out, as_dict=True)
    _assert_identical(r, local_run)
    assert r["attrs"]["fingerprint"] == local_run["attrs"]["fingerprint"]


def test_interrupted_cluster_run_resumes_only_the_missing_chunks(cluster, local_run, tmp_path, capsys):
    out = tmp_path / "s"
    seen = []

    def interrupt(k):
        seen.append(k)
        if len(seen) == 3:
            raise KeyboardInterrupt  # as Ctrl-C or a batch system's time limit would

    with pytest.raises(KeyboardInterrupt):
        run_sweep(get_study(STUDY), out, designs=48, chunk_size=6, seed=11, scheduler=cluster.address,
                  progress=False, on_chunk=interrupt)  # fmt: skip
    done = open_results(out, as_dict=True)["chunk_done"]
    assert done.sum() == 3
    assert main(["sweep", STUDY, "--out", str(out), "--scheduler", cluster.address, "--json", *ARGS]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["computed_chunks"] == 5 and summary["skipped_chunks"] == 3
    _assert_identical(open_results(out, as_dict=True), local_run)


def test_a_worker_killed_mid_run_costs_only_its_chunks(cluster, tmp_path):
    study = get_study("omnileg-synthesis")
    n, chunk, seed = 48, 4, 5  # 12 chunks of ~0.1-0.3 s each
    cluster.add_worker("victim")
    cluster.wait_workers(3)
    victim = cluster.workers()["victim"]
    killed = {}

    def kill_victim(k):
        """After a chunk is stored: kill the victim the first time it holds tasks (running or queued)."""
        if killed:
            return
        from distributed import Client

        with Client(cluster.address, timeout=30) as c:
            assigned = len(c.processing().get(victim, ()))
        if assigned:
            cluster.procs["victim"].kill()
            killed.update(assigned=assigned, at_chunk=k)

    s = run_sweep(study, tmp_path / "s", designs=n, chunk_size=chunk, seed=seed, scheduler=cluster.address,
                  progress=False, on_chunk=kill_victim)  # fmt: skip
    assert killed, "the victim never held a task after a chunk was stored: the test proved nothing"
    assert cluster.procs["victim"].wait(timeout=30) != 0
    assert s.computed_chunks == tuple(range(12))
    r = open_results(tmp_path / "s", as_dict=True)
    X = design_matrix(study.variables, n, study.default_sampler, seed, chunk)
    for k in range(12):
        _, ref, _, _ = evaluate_chunk(study, X[k * chunk : (k + 1) * chunk], seed, k)
        for name, arr in ref.items():
            assert r[name][k * chunk : (k + 1) * chunk].tobytes() == arr.tobytes(), (k, name)
    assert np.all(r["chunk_done"])
