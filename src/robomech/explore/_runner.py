"""Running a sweep on Dask: chunks of designs as tasks, results written to the Zarr store as they arrive.

By default a ``LocalCluster`` on this machine's cores (one single-threaded worker process per core);
``scheduler="tcp://HOST:PORT"`` uses an existing cluster.  Each chunk is one task computing
``study.evaluate_rows`` on its rows with its own seed (:func:`chunk_seed`), so a chunk's result does not
depend on which worker runs it, on how many workers there are, or on whether it ran before: the same
sweep is bit-identical locally and on a cluster (same numpy build and CPU family).  The client is the only
writer of the store.  A worker that dies takes only its running chunk with it: the scheduler reruns it
elsewhere.
"""

from __future__ import annotations

import functools
import importlib.metadata
import os
import pickle
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from robomech._validation import check_bool, check_choice, check_int, check_positive

from ._sampling import SAMPLERS, chunk_seed, design_matrix
from ._store import ChunkWriter, damage_message, open_store, prepare_store, store_array, verify_store
from ._study import DesignStudy, Variable, check_variables, with_variables

if TYPE_CHECKING:
    from distributed import Client, LocalCluster

__all__ = ["SchedulerUnreachable", "SweepSummary", "evaluate_chunk", "run_sweep"]

# Seconds to wait for an existing scheduler before calling it unreachable.
CONNECT_TIMEOUT = 10.0
# Retries of a chunk whose task raised (a worker dying is handled by the scheduler, not by these).
TASK_RETRIES = 2
# Environment of the LocalCluster's worker processes: one thread per process for every threaded library
# (OpenMP, MKL, OpenBLAS, numba), so K single-threaded workers use K cores and never oversubscribe them.
WORKER_ENV = {
    "OMP_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "NUMBA_NUM_THREADS": "1",
}
# Dask settings of the LocalCluster (scheduler, nannies, workers and client; each server reads them when
# it is created, a nanny hands its snapshot to the worker process it starts and restarts): Dask's
# periodic background work, which on a 2-core machine takes CPU from the chunks.  CPU of an idle
# 2-worker cluster measured per process (psutil, ms of CPU per s of wall time; docs/performance.md):
# client process (scheduler + nannies + client) 52, each worker 37, i.e. 126 ms/s = 6 % of two cores;
# with these four settings 10 and 3 + 3 (16 ms/s).  None of them is used by a sweep.
LOCAL_CLUSTER_CONFIG: dict[str, object] = {
    # the statistical profiler (dashboard "Profile" page) samples each worker's threads every 10 ms,
    # taking the GIL from the running chunk: alone, 37 -> 20 ms/s per idle worker
    "distributed.worker.profile.enabled": False,
    # event-loop health check of every server (blocked-loop warnings), 20 ms by default: alone, the
    # client process 52 -> 20 ms/s
    "distributed.admin.tick.interval": "1s",
    # nanny's and worker's memory check (spill/pause/terminate thresholds), 100 ms by default: a worker
    # past its memory limit is still stopped, within a second instead of 0.1 s
    "distributed.worker.memory.monitor-interval": "1s",
    # per-server psutil sample (CPU, memory, network, disk) for the dashboard, 500 ms by default
    "distributed.admin.system-monitor.interval": "5s",
}


class SchedulerUnreachable(ValueError):
    """The ``--scheduler`` address does not answer.

    A ``ValueError`` subclass, raised by :func:`run_sweep` and :func:`optimize_nsga2` when
    ``scheduler`` is not of the form ``tcp://HOST:PORT`` or no scheduler answers within
    ``connect_timeout`` seconds.

    Parameters
    ----------
    message : str
        What was expected and what was got (the scheduler address, the timeout).
    """


@dataclass(frozen=True)
class SweepSummary:
    """What a run of :func:`run_sweep` or :func:`optimize_nsga2` did.

    Attributes
    ----------
    study : str
        The study's name.
    out : str
        Path of the Zarr store.
    n_designs : int
        Designs of the whole sweep (stored and computed).
    n_chunks : int
        Chunks of the sweep (generations, for NSGA-II).
    computed_chunks : tuple of int
        Indices of the chunks this run computed, ascending.
    skipped_chunks : int
        Chunks already in the store (resumed).
    seconds : float
        Wall time of this run (s).
    workers : int
        Dask workers seen by the client (0 when nothing was computed).
    computed_designs : int
        Designs computed by this run; ``designs_per_second`` divides it by ``seconds``.
    """

    study: str
    out: str
    n_designs: int
    n_chunks: int
    computed_chunks: tuple[int, ...]  # chunks computed by this run
    skipped_chunks: int  # chunks already in the store
    seconds: float
    workers: int
    computed_designs: int  # designs computed by this run

    @property
    def designs_per_second(self) -> float:
        """``computed_designs / seconds`` (1/s; NaN for a run that took no time)."""
        return self.computed_designs / self.seconds if self.seconds > 0 else float("nan")

    def as_dict(self) -> dict[str, Any]:
        """The summary as plain JSON-ready data (``computed_chunks`` as a count)."""
        return {
            "study": self.study,
            "out": self.out,
            "n_designs": self.n_designs,
            "n_chunks": self.n_chunks,
            "computed_chunks": len(self.computed_chunks),
            "skipped_chunks": self.skipped_chunks,
            "seconds": self.seconds,
            "workers": self.workers,
            "computed_designs": self.computed_designs,
        }


def robomech_version() -> str:
    import robomech

    try:
        return importlib.metadata.version("robomech")
    except importlib.metadata.PackageNotFoundError:
        return robomech.__version__


ChunkResult = tuple[int, dict[str, NDArray[Any]], float, float]


def evaluate_chunk(study: DesignStudy, rows: NDArray[np.float64], seed: int, chunk: int) -> ChunkResult:
    """One task: the metrics of chunk ``chunk``'s design rows, and the wall and CPU seconds it took."""
    t0, c0 = time.perf_counter(), time.process_time()
    res = study.evaluate_rows(rows, chunk_seed(seed, chunk))
    return chunk, res, time.perf_counter() - t0, time.process_time() - c0


@functools.lru_cache(maxsize=4)
def _study_from_bytes(blob: bytes) -> DesignStudy:
    """The study of a sweep, unpickled once per worker process (a sweep's tasks share one blob)."""
    study = pickle.loads(blob)
    if not isinstance(study, DesignStudy):  # only the client's own cloudpickle of a DesignStudy
        raise TypeError(f"expected a pickled DesignStudy, got {type(study).__name__}")
    return study


def _chunk_task(blob: bytes, rows: NDArray[np.float64], seed: int, chunk: int) -> ChunkResult:
    """The Dask task of a sweep: :func:`evaluate_chunk` on the study pickled once by the client."""
    return evaluate_chunk(_study_from_bytes(blob), rows, seed, chunk)


@contextmanager
def dask_client(
    scheduler: str | None = None, workers: int | None = None, timeout: float = CONNECT_TIMEOUT
) -> Iterator[Client]:
    """A ``distributed.Client``: to ``scheduler`` if given, else to a new LocalCluster (closed after)."""
    from distributed import Client

    if scheduler:
        if not isinstance(scheduler, str) or "://" not in scheduler:
            raise SchedulerUnreachable(
                f"Expected a scheduler address like tcp://HOST:PORT, got {scheduler!r}."
            )
        probe_scheduler(scheduler, timeout)
        try:
            client = Client(scheduler, timeout=timeout)
        except (OSError, TimeoutError, MemoryError, ValueError, TypeError) as exc:
            raise SchedulerUnreachable(
                f"Expected a Dask scheduler at {scheduler!r}, got no answer within {timeout:g} s "
                f"({type(exc).__name__}: {exc})."
            ) from exc
        try:
            yield client
        finally:
            client.close()
        return
    n = int(workers) if workers else (os.cpu_count() or 1)
    import dask.config

    with dask.config.set(LOCAL_CLUSTER_CONFIG):  # the Client is created under the same settings
        cluster = local_cluster(n)
        client = Client(cluster)
    try:
        yield client
    finally:
        client.close()
        cluster.close()


def local_cluster(workers: int) -> LocalCluster:
    """The sweeps' local Dask cluster, for sweeps that share one cluster (a report, a notebook).

    ``workers`` single-threaded worker processes (each with a nanny, which restarts it if it dies) on
    127.0.0.1 only, with ``WORKER_ENV`` (one thread per BLAS/OpenMP/numba) and
    ``LOCAL_CLUSTER_CONFIG`` (Dask's background work cut: no worker profiler, 1 s scheduler tick and
    memory monitor, 5 s system monitor; measured in ``docs/performance.md``).  :func:`run_sweep` without a
    ``client`` builds the same cluster itself.

    Parameters
    ----------
    workers : int
        Number of worker processes (>= 1).

    Returns
    -------
    distributed.LocalCluster
        A running cluster; use it as a context manager (or call ``close()``) so that its processes stop.

    Raises
    ------
    ValueError
        If ``workers`` is not an integer >= 1.

    Examples
    --------
    >>> from distributed import Client
    >>> from robomech.explore import get_study, local_cluster, run_sweep
    >>> with local_cluster(2) as cluster, Client(cluster) as client:  # doctest: +SKIP
    ...     s = run_sweep(get_study("omnileg-synthesis"), "out.zarr", designs=64, client=client)
    """
    n = check_int(workers, "workers", low=1)
    import dask.config
    from distributed import LocalCluster

    with dask.config.set(LOCAL_CLUSTER_CONFIG):
        return LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address="127.0.0.1:0",  # loopback, any free port (None: :8787 on every interface)
            silence_logs=40,
            env=WORKER_ENV,  # passed to each worker's Nanny: set before the worker process imports numpy
        )


class _Bar:
    """One progress line on stderr: designs done, rate, time left."""

    def __init__(self, label: str, total: int, enabled: bool, stream: IO[str] | None = None) -> None:
        self.label, self.total, self.enabled = label, total, enabled
        self.stream = stream if stream is not None else sys.stderr
        self.t0 = time.perf_counter()
        self.done = 0

    def update(self, n: int) -> None:
        self.done += n
        if not self.enabled:
            return
        dt = time.perf_counter() - self.t0
        rate = self.done / dt if dt > 0 else 0.0
        left = f"{(self.total - self.done) / rate:6.1f} s left" if rate > 0 else "     ? s left"
        pct = 100.0 * self.done / self.total if self.total else 100.0
        self.stream.write(
            f"\r{self.label}: {self.done}/{self.total} designs ({pct:3.0f}%), {rate:8.1f} designs/s, {left}"
        )
        self.stream.flush()

    def close(self) -> None:
        if self.enabled:
            self.stream.write("\n")
            self.stream.flush()


def sweep_fingerprint(study: DesignStudy, n: int, sampler: str, seed: int, chunk: int) -> dict[str, Any]:
    """What identifies a sweep's results (a store is resumed only by a sweep with the same fingerprint)."""
    return {
        "study": study.name,
        "variables": [v.as_dict() for v in study.variables],
        "parameters": dict(study.parameters),
        "sampler": sampler,
        "seed": int(seed),
        "n_designs": int(n),
        "chunk_size": int(chunk),
    }


def plan(
    study: DesignStudy,
    designs: int | None = None,
    seed: int = 0,
    sampler: str | None = None,
    chunk_size: int | None = None,
    variables: Sequence[Variable] = (),
) -> tuple[DesignStudy, np.ndarray, str, int]:
    """Validated study, design matrix, sampler and chunk size of a sweep (no computation)."""
    if not isinstance(study, DesignStudy):
        raise ValueError(f"Expected study to be a DesignStudy, got {type(study).__name__}.")
    variables = check_variables(variables)
    study = with_variables(study, variables) if variables else study
    method = study.default_sampler if sampler is None else str(check_choice(sampler, "sampler", SAMPLERS))
    chunk = study.default_chunk if chunk_size is None else check_int(chunk_size, "chunk_size", low=1)
    n = study.default_designs if designs is None else check_int(designs, "designs", low=1)
    seed = check_int(seed, "seed", low=0)
    X = design_matrix(study.variables, n, method, int(seed), chunk)
    return study, X, method, chunk


def run_sweep(
    study: DesignStudy,
    out: Path | str,
    *,
    designs: int | None = None,
    seed: int = 0,
    sampler: str | None = None,
    chunk_size: int | None = None,
    variables: Sequence[Variable] = (),
    scheduler: str | None = None,
    workers: int | None = None,
    client: Any = None,
    progress: bool = True,
    on_chunk: Callable[[int], None] | None = None,
    connect_timeout: float = CONNECT_TIMEOUT,
) -> SweepSummary:
    """Run (or resume) a sweep of ``study`` into the Zarr store ``out``; see the module docstring.

    ``variables`` override or extend the study's design variables; ``client`` an existing
    ``distributed.Client`` (else ``scheduler`` / a LocalCluster of ``workers`` processes).  ``on_chunk(k)``
    is called after chunk ``k`` is stored.  Returns which chunks this run computed.

    A store already holding this sweep (same fingerprint: study, variables, designs, sampler, seed,
    chunk size) is resumed: only the chunks whose ``chunk_done`` flag is false are computed.

    Parameters
    ----------
    study : DesignStudy
        The study (e.g. :func:`get_study`).
    out : str or pathlib.Path
        Directory of the Zarr store (created if absent).
    designs : int, optional
        Number of designs (>= 1; default ``study.default_designs``; ``grid`` rounds it).
    seed : int, optional
        Seed of the design matrix and the per-chunk streams (>= 0; default 0).
    sampler : str, optional
        ``"sobol"``, ``"lhs"``, ``"grid"`` or ``"random"`` (default ``study.default_sampler``).
    chunk_size : int, optional
        Designs per task (>= 1; default ``study.default_chunk``).
    variables : sequence of Variable, optional
        Overrides or additions to the study's variables (:func:`with_variables`).
    scheduler : str, optional
        Address ``tcp://HOST:PORT`` of an existing Dask scheduler; None (default): a LocalCluster.
    workers : int, optional
        Worker processes of the LocalCluster (>= 1; default one per core).
    client : distributed.Client, optional
        An existing client to use instead (not closed).
    progress : bool, optional
        Print a progress line on stderr (default True).
    on_chunk : callable, optional
        ``on_chunk(k)`` called after chunk ``k`` is stored.
    connect_timeout : float, optional
        Seconds to wait for ``scheduler`` (> 0; default ``CONNECT_TIMEOUT``).

    Returns
    -------
    SweepSummary
        Designs and chunks of the sweep, the chunks computed and skipped, wall time and workers.

    Raises
    ------
    ValueError
        If an argument is of the wrong type or out of range (``study`` not a DesignStudy, ``out`` not
        a path, ...).
    StoreMismatch
        If ``out`` holds something other than this sweep's store (nothing is overwritten).
    SchedulerUnreachable
        If ``scheduler`` is malformed or does not answer.
    """
    study, X, sampler, chunk = plan(study, designs, seed, sampler, chunk_size, variables)
    out = check_runtime(out, scheduler, workers, progress, connect_timeout, on_chunk)
    n = X.shape[0]
    fp = sweep_fingerprint(study, n, sampler, int(seed), chunk)
    info = {
        **study.describe(),
        "robomech_version": robomech_version(),
        "units": {**{v.name: v.unit for v in study.variables}, **{m.name: m.unit for m in study.metrics}},
    }
    n_chunks = -(-n // chunk)
    client = check_client(client)
    g = open_store(Path(out), fp, X)  # raises StoreMismatch before anything is written
    if g is None:
        check_writable(out)  # before a cluster is started
    done = np.zeros(n_chunks, bool) if g is None else resume_flags(g, out, progress)
    missing = [k for k in range(done.size) if not done[k]]
    t0 = time.perf_counter()
    computed: list[int] = []
    n_workers = 0
    bar = _Bar(study.name, n, progress)
    bar.update(sum(min(chunk, n - k * chunk) for k in range(done.size) if done[k]))
    if missing:
        ctx = _existing(client) if client is not None else dask_client(scheduler, workers, connect_timeout)
        with ctx as c:  # connect (or start the LocalCluster) before creating the store
            from distributed import as_completed

            if g is None:
                g = prepare_store(Path(out), study, X, chunk, fp, info)
            n_workers = len(c.scheduler_info().get("workers", {}))
            blob = _pickle_study(study)  # once per sweep, not once per task
            futures = [
                c.submit(
                    _chunk_task,
                    blob,
                    X[k * chunk : (k + 1) * chunk],
                    int(seed),
                    k,
                    pure=False,
                    retries=TASK_RETRIES,
                )
                for k in missing
            ]
            try:
                with ChunkWriter(Path(out), ["design_ok", *(m.name for m in study.metrics)]) as writer:
                    for fut in as_completed(futures):
                        k, res, secs, cpu = fut.result()
                        rows = slice(k * chunk, min((k + 1) * chunk, n))
                        writer.write(k, rows, res, secs, cpu)  # chunk_done[k] last
                        computed.append(k)
                        bar.update(rows.stop - rows.start)
                        if on_chunk is not None:
                            on_chunk(k)
            finally:
                for fut in futures:
                    if not fut.done():
                        fut.cancel()
    bar.close()
    return SweepSummary(
        study.name,
        str(out),
        n,
        done.size,
        tuple(sorted(computed)),
        done.size - len(missing),
        time.perf_counter() - t0,
        n_workers,
        sum(min(chunk, n - k * chunk) for k in computed),
    )


def resume_flags(g: Any, out: Path, progress: bool) -> np.ndarray:
    """``chunk_done`` of a store being resumed, false for every chunk :func:`verify_store` finds damaged
    (those are recomputed; a warning names them on stderr)."""
    damaged = verify_store(g, out)  # StoreDamaged if an array is missing: nothing to resume into
    done = np.asarray(store_array(g, "chunk_done")[...], dtype=bool)
    if damaged:
        done[list(damaged)] = False
        print(f"robomech sweep: {damage_message(out, damaged)}", file=sys.stderr)
    return done


def check_client(client: object) -> Any:
    """``client`` if it is None or a ``distributed.Client``; ValueError otherwise (before any work)."""
    if client is None:
        return None
    from distributed import Client

    if not isinstance(client, Client):
        raise ValueError(f"Expected client to be a distributed.Client or None, got {type(client).__name__}.")
    return client


def check_writable(out: Path) -> None:
    """Create the directory ``out`` (and its parents) or raise ValueError saying why it cannot be."""
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / ".robomech-write-test"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise ValueError(
            f"Expected out to be a directory robomech can create and write, got {str(out)!r} "
            f"({exc.strerror or type(exc).__name__})."
        ) from exc


def probe_scheduler(address: str, timeout: float) -> None:
    """Raise SchedulerUnreachable unless a Dask scheduler answers at ``tcp://HOST:PORT`` within
    ``timeout`` seconds.

    A Dask server writes its handshake as soon as it accepts a connection: a port that refuses, accepts
    and stays silent (a stalled server), or answers with anything other than a Dask frame (an HTTP
    server answers nothing until it gets a request) is not a scheduler.  Bounds the whole connection
    attempt by ``timeout``, which the Client's own handshake does not.
    """
    import socket
    from urllib.parse import urlsplit

    parts = urlsplit(address)
    if parts.scheme != "tcp":
        return  # tls:// and other comms: left to distributed's own connection
    try:
        host, port = parts.hostname, parts.port
    except ValueError as exc:
        raise SchedulerUnreachable(
            f"Expected a scheduler address like tcp://HOST:PORT, got {address!r}."
        ) from exc
    if not host or port is None:
        raise SchedulerUnreachable(f"Expected a scheduler address like tcp://HOST:PORT, got {address!r}.")
    deadline = time.monotonic() + timeout
    try:
        with socket.create_connection((host, port), timeout=timeout) as sock:
            sock.settimeout(max(1e-3, deadline - time.monotonic()))
            head = sock.recv(8)
    except TimeoutError as exc:
        raise SchedulerUnreachable(
            f"Expected a Dask scheduler at {address!r}, got a port that accepted but sent no Dask "
            f"handshake within {timeout:g} s (not a scheduler, or a stalled one)."
        ) from exc
    except OSError as exc:
        raise SchedulerUnreachable(
            f"Expected a Dask scheduler at {address!r}, got no answer within {timeout:g} s "
            f"({exc.strerror or type(exc).__name__})."
        ) from exc
    # distributed's TCP messages start with their length (little-endian uint64): its handshake is
    # tens of bytes, an HTTP or other text reply reads as a length of exabytes
    if len(head) < 8 or int.from_bytes(head, "little") > 1 << 16:
        raise SchedulerUnreachable(
            f"Expected a Dask scheduler at {address!r}, got a server speaking another protocol "
            f"(first bytes {head[:8]!r})."
        )


def _pickle_study(study: DesignStudy) -> bytes:
    """The study as bytes for the tasks (cloudpickle: a study defined in ``__main__``, or a user model
    loaded from a file by :func:`load_model` whose module is registered to be pickled by value, travels
    to workers that cannot import it)."""
    import cloudpickle

    return bytes(cloudpickle.dumps(study))


def check_runtime(
    out: object,
    scheduler: object,
    workers: object,
    progress: object,
    connect_timeout: object,
    on_chunk: object = None,
) -> Path:
    """Validate the execution options shared by run_sweep and optimize_nsga2; return ``out`` as a Path."""
    if not isinstance(out, str | Path) or str(out) == "":
        raise ValueError(f"Expected out to be a directory path (str or Path), got {out!r}.")
    if scheduler is not None and (not isinstance(scheduler, str) or "://" not in scheduler):
        raise SchedulerUnreachable(f"Expected scheduler like tcp://HOST:PORT, got {scheduler!r}.")
    if workers is not None:
        check_int(workers, "workers", low=1)
    check_bool(progress, "progress")
    check_positive(connect_timeout, "connect_timeout")
    if on_chunk is not None and not callable(on_chunk):
        raise ValueError(f"Expected on_chunk to be callable or None, got {type(on_chunk).__name__}.")
    return Path(out)


@contextmanager
def _existing(client: Client) -> Iterator[Client]:
    yield client
