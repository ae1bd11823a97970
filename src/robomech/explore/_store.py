"""The Zarr store of a sweep: one array per metric, the design matrix, and what identifies the sweep.

Layout of the group ``DIR``::

    designs        (n, n_variables) float64   the design matrix, written when the store is created
    design_ok      (n,) bool                  the parameter dataclass accepted the design
    <metric>       (n, *shape)                one array per metric, chunked like the sweep
    chunk_done     (n_chunks,) bool           chunk k's rows of every metric are written
    chunk_seconds  (n_chunks,) float64        worker wall time of chunk k (for the overhead figures)
    chunk_cpu_seconds (n_chunks,) float64     worker CPU time of chunk k (its process)
    chunk_checksum (n_chunks,) uint64         digest of chunk k's rows of design_ok and every metric
    attrs          robomech: {format, version, study, fingerprint, variables, metrics, units, ...}

A chunk's metric rows are written before its ``chunk_done`` flag, so an interrupted run never marks
a chunk it did not finish: a rerun computes exactly the chunks whose flag is false.  Each finished
chunk's rows are digested when written (:func:`chunk_checksum`, stored in ``chunk_checksum``); a store
is verified against them when it is resumed or opened (:func:`verify_store`), so a chunk damaged by hand
(deleted, truncated, edited) is named, and recomputed by a resume, instead of read as NaN or as a
decoder error.
"""

from __future__ import annotations

import asyncio
import hashlib
import json
import threading
import warnings
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

__all__ = [
    "ChunkWriter",
    "StoreDamaged",
    "StoreMismatch",
    "chunk_checksum",
    "open_results",
    "open_store",
    "prepare_store",
    "verify_store",
]

_T = TypeVar("_T")
# Seconds close() waits for a chunk write still in flight (an interrupt during a write) to finish.
WRITE_GRACE = 30.0

FORMAT = "robomech-sweep/2"
# Stores of the first layout (no chunk_checksum array) are still read and resumed, checked for
# readability only.
FORMATS = ("robomech-sweep/1", FORMAT)
# The arrays every store holds besides the metrics.
FIXED = ("designs", "design_ok", "chunk_done", "chunk_seconds", "chunk_cpu_seconds")


class StoreMismatch(ValueError):
    """``--out`` already holds something that is not this sweep's store (nothing is overwritten).

    A ``ValueError`` subclass, raised by :func:`run_sweep` and :func:`optimize_nsga2` before anything
    is written when the directory is not empty and not a store with the same sweep fingerprint.

    Parameters
    ----------
    message : str
        Which part of the store differs from this sweep's (path, fingerprint, array).
    """


class StoreDamaged(StoreMismatch):
    """A sweep store whose arrays do not hold what it claims (an array missing, a chunk unreadable or
    not matching the checksum recorded when it was written).

    A :class:`StoreMismatch` (so a ``ValueError``), raised by :func:`open_results`, and by
    :func:`run_sweep` when an array of the store is missing (a damaged chunk is recomputed instead).

    Parameters
    ----------
    message : str
        The store, and which arrays or chunks are damaged and how.
    """


def chunk_checksum(res: Mapping[str, NDArray[Any]], names: Sequence[str]) -> int:
    """64-bit BLAKE2b digest of one chunk's arrays ``res[name]`` in the order ``names`` (dtype, shape,
    bytes), as stored in ``chunk_checksum``; never 0 (the fill value of a chunk not written)."""
    h = hashlib.blake2b(digest_size=8)
    for name in names:
        a = np.ascontiguousarray(res[name])
        h.update(f"{name}|{a.dtype.str}|{a.shape}|".encode())
        h.update(a.tobytes())
    return int.from_bytes(h.digest(), "little") or 1


def expected_arrays(meta: Mapping[str, Any]) -> list[str]:
    """Names of the arrays a store with attributes ``meta`` must hold (the fixed ones, then the metrics)."""
    metrics = [m.get("name") for m in meta.get("metrics", []) if isinstance(m, Mapping)]
    extra = ["chunk_checksum"] if meta.get("format") == FORMAT else []
    return [*FIXED, *extra, *(str(m) for m in metrics)]


def verify_store(g: zarr.Group, path: Path | str) -> dict[int, str]:
    """Check a store against what it claims: every array present, every finished chunk readable and
    equal to its recorded checksum.

    Returns ``{chunk: reason}`` for each chunk flagged done whose rows are damaged (empty when the
    store is sound); raises :class:`StoreDamaged` when an array is missing or ``chunk_done`` itself is
    unreadable (nothing of the store can then be trusted).
    """
    import zarr

    meta = _meta(g)
    names = expected_arrays(meta)
    with warnings.catch_warnings():  # DIR/report and the like: not zarr nodes, not the store's
        warnings.simplefilter("ignore")
        present = {name for name, _ in g.members()}
    missing = [n for n in names if n not in present]
    if missing:
        raise StoreDamaged(
            f"Expected the sweep store {str(path)!r} to hold the arrays {', '.join(names)}, got "
            f"{', '.join(missing)} missing (its metadata deleted, or its creation cut short); "
            "use another --out or remove this one."
        )
    arrays: dict[str, zarr.Array] = {}
    for name in names:
        node = g[name]
        if not isinstance(node, zarr.Array):
            raise StoreDamaged(
                f"Expected {name!r} in the sweep store {str(path)!r} to be an array, got a group."
            )
        arrays[name] = node
    try:
        done = np.asarray(arrays["chunk_done"][...], dtype=bool)
    except Exception as exc:
        raise StoreDamaged(
            f"Expected the sweep store {str(path)!r} to have a readable chunk_done array, got "
            f"{type(exc).__name__}: {exc}; use another --out or remove this one."
        ) from exc
    chunk = int(arrays["design_ok"].chunks[0])
    n = int(arrays["design_ok"].shape[0])
    metric_names = names[len(FIXED) + (1 if "chunk_checksum" in names else 0) :]
    rows_of = ["design_ok", *metric_names]
    sums: NDArray[np.uint64] | None = None
    sums_unreadable = False
    if "chunk_checksum" in arrays:
        try:
            sums = np.asarray(arrays["chunk_checksum"][...], dtype=np.uint64)
        except Exception:  # unreadable: every finished chunk is reported
            sums_unreadable = True
    whole: dict[str, NDArray[Any] | None] = {}
    for name in rows_of:
        try:
            whole[name] = np.asarray(arrays[name][...])
        except Exception:  # a chunk that cannot be decoded: found chunk by chunk below
            whole[name] = None
    damaged: dict[int, str] = {}
    for kk in np.flatnonzero(done):
        k = int(kk)
        rows = slice(k * chunk, min((k + 1) * chunk, n))
        res: dict[str, NDArray[Any]] = {}
        for name in rows_of:
            a = whole[name]
            if a is None:
                try:
                    res[name] = np.asarray(arrays[name][rows])
                except Exception as exc:
                    damaged[k] = f"{name} unreadable ({type(exc).__name__})"
                    break
            else:
                res[name] = a[rows]
        if k in damaged:
            continue
        if sums_unreadable:
            damaged[k] = "chunk_checksum unreadable"
        elif sums is not None and int(sums[k]) != chunk_checksum(res, rows_of):
            bad = [x for x in rows_of[1:] if res[x].dtype.kind == "f" and np.isnan(res[x]).all()]
            how = f"{', '.join(bad)} all NaN (chunk deleted?)" if bad else "rows differ from those written"
            damaged[k] = f"checksum mismatch: {how}"
    return damaged


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
    if meta.get("format") not in FORMATS:
        members = {name for name, _ in g.members()}
        cut = "designs" in members  # prepare_store writes the attributes last
        raise StoreMismatch(
            f"Expected --out {str(out)!r} to be a robomech sweep store, got a Zarr group without "
            "robomech sweep attributes"
            + (" (a store whose creation was cut short: remove it and rerun)" if cut else "")
            + "; nothing was written."
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
    g.create_array("chunk_checksum", shape=(n_chunks,), chunks=(1,), dtype="uint64", fill_value=0)
    for name in ("chunk_seconds", "chunk_cpu_seconds"):
        g.create_array(name, shape=(n_chunks,), chunks=(1,), dtype="float64", fill_value=np.nan)
    stored.attrs.update({"columns": [v.name for v in study.variables]})
    g.attrs.update({"robomech": _canonical({"format": FORMAT, "fingerprint": fp, **info})})
    return g


def open_results(out: Path | str, *, as_dict: bool = False) -> Any:
    """A sweep store as labelled data: an ``xarray.Dataset`` of designs x metrics (verified first).

    Parameters
    ----------
    out : str or pathlib.Path
        Directory of a store written by :func:`run_sweep` or :func:`optimize_nsga2`.
    as_dict : bool, optional
        False (default): the Dataset.  True: plain data, ``{"attrs": robomech attributes, name: ndarray}``
        for every array of the store (``designs``, ``design_ok``, each metric, ``chunk_done``,
        ``chunk_seconds``, ``chunk_cpu_seconds``).

    Returns
    -------
    xarray.Dataset or dict
        Dimension ``design`` (one row per design; metrics of shape ``(n, *shape)`` get the extra
        dimensions ``<metric>_0``, ...), with every design variable a coordinate along ``design``
        (attribute ``unit``), ``design_ok`` and each metric a data variable (attributes ``unit`` and
        ``description``); attributes ``study``, ``title``, ``mechanism``, ``units`` (name -> unit),
        ``robomech`` (every stored attribute: fingerprint, variables, parameters, version) and
        ``chunk_done``, ``chunk_seconds``, ``chunk_cpu_seconds`` (per chunk).  Designs of chunks not
        computed yet have ``design_ok`` False and NaN metrics.  ``ds.to_dataframe()`` gives pandas
        (pass the scalar metrics only, ``ds[names]``, when some metrics have extra dimensions).

    Raises
    ------
    ValueError
        If ``out`` is not a path to a directory holding a robomech sweep store, or ``as_dict`` is
        not a bool.
    StoreDamaged
        If an array of the store is missing, or a chunk marked finished is unreadable or differs
        from the checksum recorded when it was written (the message names the chunks; rerunning
        the sweep recomputes them).

    Examples
    --------
    >>> ds = open_results("out.zarr")  # doctest: +SKIP
    >>> ds["workspace_area"].attrs["unit"], ds.to_dataframe().shape  # doctest: +SKIP
    ('m^2', (256, 8))
    """
    out = _check_path(out, "out")
    if not isinstance(as_dict, bool):
        raise ValueError(f"Expected as_dict to be a bool, got {type(as_dict).__name__}.")
    if not out.is_dir():
        raise ValueError(f"Expected out to be a sweep store directory, got {str(out)!r} (not a directory).")
    import zarr

    try:
        g = zarr.open_group(str(out), mode="r")
    except Exception as exc:  # zarr raises several kinds for a folder that is not a store
        raise ValueError(f"Expected out to be a robomech sweep store, got {str(out)!r}.") from exc
    meta = _meta(g)
    if meta.get("format") not in FORMATS:
        raise ValueError(
            f"Expected out {str(out)!r} to be a robomech sweep store, got no robomech attributes."
        )
    damaged = verify_store(g, out)
    if damaged:
        raise StoreDamaged(damage_message(out, damaged))
    arrays = {name: np.asarray(store_array(g, name)[...]) for name in expected_arrays(meta)}
    if as_dict:
        return {"attrs": meta, **arrays}
    return to_dataset(meta, arrays)


def damage_message(out: Path | str, damaged: Mapping[int, str]) -> str:
    """One line naming the damaged chunks of a store and what is wrong with each (at most 10 listed)."""
    items = sorted(damaged.items())
    shown = "; ".join(f"chunk {k}: {why}" for k, why in items[:10])
    more = f"; and {len(items) - 10} more" if len(items) > 10 else ""
    return (
        f"Expected the sweep store {str(out)!r} to hold what it claims, got {len(items)} damaged "
        f"chunk(s) ({shown}{more}); rerun the same sweep to recompute them."
    )


def to_dataset(meta: Mapping[str, Any], arrays: Mapping[str, NDArray[Any]]) -> Any:
    """The labelled Dataset of a store's attributes and arrays (see :func:`open_results`)."""
    import xarray as xr

    units = dict(meta.get("units", {}))
    variables = [v for v in meta.get("variables", []) if isinstance(v, Mapping)]
    metrics = [m for m in meta.get("metrics", []) if isinstance(m, Mapping)]
    X = arrays["designs"]
    n = X.shape[0]
    taken = {"design", "design_ok", *(str(m["name"]) for m in metrics)}
    coords: dict[str, Any] = {"design": ("design", np.arange(n))}
    for j, v in enumerate(variables):
        name = str(v["name"])
        key = name if name not in taken else f"var_{name}"
        coords[key] = ("design", X[:, j], {"unit": v.get("unit", ""), "kind": v.get("kind", "range")})
    data: dict[str, Any] = {"design_ok": ("design", arrays["design_ok"], {"unit": ""})}
    for m in metrics:
        name = str(m["name"])
        a = arrays[name]
        dims = ("design", *(f"{name}_{i}" for i in range(a.ndim - 1)))
        data[name] = (dims, a, {"unit": m.get("unit", ""), "description": m.get("description", "")})
    attrs = {
        "study": meta.get("study", ""),
        "title": meta.get("title", ""),
        "mechanism": meta.get("mechanism", ""),
        "units": units,
        "robomech": dict(meta),
        **{k: arrays[k] for k in ("chunk_done", "chunk_seconds", "chunk_cpu_seconds")},
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


class ChunkWriter:
    """Writes finished chunks into a sweep's store: the client is the store's only writer.

    zarr's synchronous API costs one round trip to zarr's I/O loop per array and chunk (~2 ms of client
    CPU each, ten arrays per chunk); this writer sends every array of a chunk through zarr's public
    asynchronous API on its own event loop (a private thread, so it works under a running loop such as
    Jupyter's) in one round trip, then ``chunk_done[k]`` alone: measured 4x less client CPU and wall time
    per chunk (``docs/performance.md``).  ``write`` returns once the chunk is stored.
    """

    def __init__(self, out: Path, names: Sequence[str]) -> None:
        optional = ["chunk_checksum"]  # absent from stores of the first layout
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._loop.run_forever, name="robomech-store", daemon=True)
        self._thread.start()
        self._pending: Future[Any] | None = None
        try:
            self._arrays = self._run(
                self._open(str(out), [*names, "chunk_seconds", "chunk_cpu_seconds", "chunk_done"], optional)
            )
            self._done = self._arrays.pop("chunk_done")
            self._names = list(names)
            self._sum = self._arrays.pop("chunk_checksum", None)
        except BaseException:
            self.close()
            raise

    @staticmethod
    async def _open(path: str, names: Sequence[str], optional: Sequence[str]) -> dict[str, AsyncArray[Any]]:
        import zarr
        import zarr.api.asynchronous as za

        g = await za.open_group(store=path, mode="r+")
        out: dict[str, AsyncArray[Any]] = {}
        have = {name async for name in g.keys()}
        for name in [*names, *(o for o in optional if o in have)]:
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
        extra = [] if self._sum is None else [self._sum.setitem(k, chunk_checksum(res, self._names))]
        await asyncio.gather(
            *(a[name].setitem(rows, arr) for name, arr in res.items()),
            a["chunk_seconds"].setitem(k, float(seconds)),
            a["chunk_cpu_seconds"].setitem(k, float(cpu)),
            *extra,
        )
        await self._done.setitem(k, True)  # last: the chunk's rows are all written

    def write(self, k: int, rows: slice, res: Mapping[str, NDArray[Any]], seconds: float, cpu: float) -> None:
        """Store chunk ``k``: its metric rows ``rows`` and timings, then ``chunk_done[k] = True``."""
        unknown = set(res) ^ set(self._names)
        if unknown:  # a study bug: never write a partial chunk
            raise RuntimeError(f"chunk {k} has arrays other than the store's: {sorted(unknown)}")
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
