"""The Zarr store of a sweep: one array per metric, the design matrix, and what identifies the sweep.

Layout of the group ``DIR``::

    designs        (n, n_variables) float64   the design matrix, written when the store is created
    design_ok      (n,) bool                  the parameter dataclass accepted the design
    <metric>       (n, *shape)                one array per metric, chunked like the sweep
    chunk_done     (n_chunks,) bool           chunk k's rows of every metric are written
    chunk_seconds  (n_chunks,) float64        worker wall time of chunk k (for the overhead figures)
    chunk_cpu_seconds (n_chunks,) float64     worker CPU time of chunk k (its process)
    attrs          robomech: {format, version, study, fingerprint, variables, metrics, units, ...}

A chunk's metric rows are written before its ``chunk_done`` flag, so an interrupted run never marks
a chunk it did not finish: a rerun computes exactly the chunks whose flag is false.
"""

from __future__ import annotations

import asyncio
import json
import threading
from collections.abc import Coroutine, Mapping, Sequence
from concurrent.futures import Future
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np
from numpy.typing import NDArray

from ._study import DesignStudy

if TYPE_CHECKING:
    import zarr
    from zarr import AsyncArray

__all__ = ["ChunkWriter", "StoreMismatch", "open_results", "open_store", "prepare_store"]

_T = TypeVar("_T")
# Seconds close() waits for a chunk write still in flight (an interrupt during a write) to finish.
WRITE_GRACE = 30.0

FORMAT = "robomech-sweep/1"


class StoreMismatch(ValueError):
    """``--out`` already holds something that is not this sweep's store (nothing is overwritten).

    A ``ValueError`` subclass, raised by :func:`run_sweep` and :func:`optimize_nsga2` before anything
    is written when the directory is not empty and not a store with the same sweep fingerprint.

    Parameters
    ----------
    message : str
        Which part of the store differs from this sweep's (path, fingerprint, array).
    """


def _check_path(out: object, name: str) -> Path:
    if not isinstance(out, str | Path) or str(out) == "":
        raise ValueError(f"Expected {name} to be a directory path (str or Path), got {out!r}.")
    return Path(out)


def _canonical(obj: Any) -> Any:
    return json.loads(json.dumps(obj, sort_keys=True, default=str))


def _meta(g: zarr.Group) -> dict[str, Any]:
    """The group's ``robomech`` attributes ({} when absent or not a mapping)."""
    meta = g.attrs.asdict().get("robomech")
    return dict(meta) if isinstance(meta, Mapping) else {}


def store_array(g: zarr.Group, name: str) -> zarr.Array:
    """Array ``name`` of the store ``g`` (StoreMismatch if it is a group)."""
    import zarr

    a = g[name]
    if not isinstance(a, zarr.Array):
        raise StoreMismatch(f"Expected {name!r} in the store to be an array, got a group.")
    return a


def open_store(
    out: Path, fingerprint: dict[str, Any], designs: NDArray[np.float64] | None
) -> zarr.Group | None:
    """The existing store of this sweep at ``out``, None if ``out`` is absent or empty; StoreMismatch else."""
    import zarr

    out = Path(out)
    fp = _canonical(fingerprint)
    if not out.exists():
        return None
    if not out.is_dir():
        raise StoreMismatch(f"Expected --out {str(out)!r} to be a directory, got a file.")
    if not any(out.iterdir()):
        return None
    try:
        g = zarr.open_group(str(out), mode="r+")
    except Exception as exc:  # zarr raises several kinds for a non-store folder
        raise StoreMismatch(
            f"Expected --out {str(out)!r} to be empty or a robomech sweep store, got a folder "
            "holding other files; nothing was written."
        ) from exc
    meta = _meta(g)
    if meta.get("format") != FORMAT:
        raise StoreMismatch(
            f"Expected --out {str(out)!r} to be a robomech sweep store, got a Zarr group without "
            "robomech sweep attributes; nothing was written."
        )
    old = meta.get("fingerprint")
    old = dict(old) if isinstance(old, Mapping) else {}
    if old != fp:
        diff = sorted(k for k in set(old) | set(fp) if old.get(k) != fp.get(k))
        raise StoreMismatch(
            f"Expected --out {str(out)!r} to hold this sweep ({fp['study']}) or nothing, "
            f"got the store of study {old.get('study')!r} differing in {', '.join(diff)}; "
            "use another --out (nothing was overwritten)."
        )
    if designs is not None and not np.array_equal(np.asarray(store_array(g, "designs")[...]), designs):
        raise StoreMismatch(f"The design matrix stored in {str(out)!r} differs from this sweep's.")
    return g


def prepare_store(
    out: Path,
    study: DesignStudy,
    designs: NDArray[np.float64] | None,
    chunk: int,
    fingerprint: dict[str, Any],
    info: dict[str, Any],
    n: int | None = None,
) -> zarr.Group:
    """Open the sweep's store at ``out`` (creating it if absent); raise StoreMismatch if it is another's.

    ``designs=None`` (NSGA-II: rows known only as the optimiser proposes them) creates ``n`` NaN rows.
    """
    import zarr

    out = Path(out)
    fp = _canonical(fingerprint)
    if designs is not None:
        n = designs.shape[0]
    elif n is None:
        raise ValueError("Expected n (the number of rows) when designs is None, got None.")
    d = len(study.variables)
    n_chunks = -(-n // chunk)
    g = open_store(out, fingerprint, designs)
    if g is not None:
        return g
    g = zarr.open_group(str(out), mode="w")
    stored = g.create_array("designs", shape=(n, d), chunks=(chunk, d), dtype="float64", fill_value=np.nan)
    if designs is not None:
        stored[...] = designs
    g.create_array("design_ok", shape=(n,), chunks=(chunk,), dtype="bool", fill_value=False)
    for m in study.metrics:
        fill = False if m.dtype == "bool" else np.nan
        a = g.create_array(
            m.name, shape=(n, *m.shape), chunks=(chunk, *m.shape), dtype=m.dtype, fill_value=fill
        )
        a.attrs.update({"unit": m.unit, "description": m.description})
    g.create_array("chunk_done", shape=(n_chunks,), chunks=(1,), dtype="bool", fill_value=False)
    for name in ("chunk_seconds", "chunk_cpu_seconds"):
        g.create_array(name, shape=(n_chunks,), chunks=(1,), dtype="float64", fill_value=np.nan)
    stored.attrs.update({"columns": [v.name for v in study.variables]})
    g.attrs.update({"robomech": _canonical({"format": FORMAT, "fingerprint": fp, **info})})
    return g


def open_results(out: Path | str) -> dict[str, Any]:
    """A sweep store as plain data: ``attrs`` (the robomech attributes) and every array as numpy.

    Parameters
    ----------
    out : str or pathlib.Path
        Directory of a store written by :func:`run_sweep` or :func:`optimize_nsga2`.

    Returns
    -------
    dict
        ``"attrs"``: the store's robomech attributes (study, fingerprint, variables, metrics, units);
        and one ndarray per array: ``designs (n, n_variables)``, ``design_ok (n,)``, each metric
        ``(n, *shape)``, ``chunk_done``, ``chunk_seconds``, ``chunk_cpu_seconds (n_chunks,)``.

    Raises
    ------
    ValueError
        If ``out`` is not a path to a directory holding a robomech sweep store.
    """
    out = _check_path(out, "out")
    if not out.is_dir():
        raise ValueError(f"Expected out to be a sweep store directory, got {str(out)!r} (not a directory).")
    import zarr

    try:
        g = zarr.open_group(str(out), mode="r")
    except Exception as exc:  # zarr raises several kinds for a folder that is not a store
        raise ValueError(f"Expected out to be a robomech sweep store, got {str(out)!r}.") from exc
    meta = _meta(g)
    if meta.get("format") != FORMAT:
        raise ValueError(
            f"Expected out {str(out)!r} to be a robomech sweep store, got no robomech attributes."
        )
    arrays = {name: np.asarray(a[...]) for name, a in g.arrays()}
    return {"attrs": meta, **arrays}


class ChunkWriter:
    """Writes finished chunks into a sweep's store: the client is the store's only writer.

    zarr's synchronous API costs one round trip to zarr's I/O loop per array and chunk (~2 ms of client
    CPU each, ten arrays per chunk); this writer sends every array of a chunk through zarr's public
    asynchronous API on its own event loop (a private thread, so it works under a running loop such as
    Jupyter's) in one round trip, then ``chunk_done[k]`` alone: measured 4x less client CPU and wall time
    per chunk (``docs/performance.md``).  ``write`` returns once the chunk is stored.
    """

    def __init__(self, out: Path, names: Sequence[str]) -> None:
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._loop.run_forever, name="robomech-store", daemon=True)
        self._thread.start()
        self._pending: Future[Any] | None = None
        try:
            self._arrays = self._run(
                self._open(str(out), [*names, "chunk_seconds", "chunk_cpu_seconds", "chunk_done"])
            )
            self._done = self._arrays.pop("chunk_done")
        except BaseException:
            self.close()
            raise

    @staticmethod
    async def _open(path: str, names: Sequence[str]) -> dict[str, AsyncArray[Any]]:
        import zarr
        import zarr.api.asynchronous as za

        g = await za.open_group(store=path, mode="r+")
        out: dict[str, AsyncArray[Any]] = {}
        for name in names:
            a = await g.getitem(name)
            if not isinstance(a, zarr.AsyncArray):
                raise StoreMismatch(f"Expected {name!r} in the store to be an array, got a group.")
            out[name] = a
        return out

    def _run(self, coro: Coroutine[Any, Any, _T]) -> _T:
        fut = asyncio.run_coroutine_threadsafe(coro, self._loop)
        self._pending = fut
        return fut.result()

    async def _write(
        self, k: int, rows: slice, res: Mapping[str, NDArray[Any]], seconds: float, cpu: float
    ) -> None:
        a = self._arrays
        await asyncio.gather(
            *(a[name].setitem(rows, arr) for name, arr in res.items()),
            a["chunk_seconds"].setitem(k, float(seconds)),
            a["chunk_cpu_seconds"].setitem(k, float(cpu)),
        )
        await self._done.setitem(k, True)  # last: the chunk's rows are all written

    def write(self, k: int, rows: slice, res: Mapping[str, NDArray[Any]], seconds: float, cpu: float) -> None:
        """Store chunk ``k``: its metric rows ``rows`` and timings, then ``chunk_done[k] = True``."""
        unknown = set(res) - set(self._arrays)
        if unknown:  # a study bug: never write a partial chunk
            raise RuntimeError(f"chunk {k} has arrays the store does not hold: {sorted(unknown)}")
        self._run(self._write(k, rows, res, seconds, cpu))

    def close(self) -> None:
        """Finish a write still in flight (an interrupt arrived during it), then stop the loop."""
        if self._pending is not None and not self._pending.done():
            try:
                self._pending.result(timeout=WRITE_GRACE)
            except Exception:  # the write's own error was raised by write(); the chunk stays not done
                pass
        self._loop.call_soon_threadsafe(self._loop.stop)
        self._thread.join()
        self._loop.close()

    def __enter__(self) -> ChunkWriter:
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()
