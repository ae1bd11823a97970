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

import json
from pathlib import Path
from typing import Any

import numpy as np

from ._study import DesignStudy

__all__ = ["StoreMismatch", "open_results", "open_store", "prepare_store"]

FORMAT = "robomech-sweep/1"


class StoreMismatch(ValueError):
    """``--out`` already holds something that is not this sweep's store (nothing is overwritten)."""


def _check_path(out: object, name: str) -> Path:
    if not isinstance(out, str | Path) or str(out) == "":
        raise ValueError(f"Expected {name} to be a directory path (str or Path), got {out!r}.")
    return Path(out)


def _canonical(obj: Any) -> Any:
    return json.loads(json.dumps(obj, sort_keys=True, default=str))


def open_store(out: Path, fingerprint: dict[str, Any], designs: np.ndarray | None):
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
    meta = dict(g.attrs).get("robomech", {})
    if meta.get("format") != FORMAT:
        raise StoreMismatch(
            f"Expected --out {str(out)!r} to be a robomech sweep store, got a Zarr group without "
            "robomech sweep attributes; nothing was written."
        )
    old = meta.get("fingerprint", {})
    if old != fp:
        diff = sorted(k for k in set(old) | set(fp) if old.get(k) != fp.get(k))
        raise StoreMismatch(
            f"Expected --out {str(out)!r} to hold this sweep ({fp['study']}) or nothing, "
            f"got the store of study {old.get('study')!r} differing in {', '.join(diff)}; "
            "use another --out (nothing was overwritten)."
        )
    if designs is not None and not np.array_equal(g["designs"][:], designs):
        raise StoreMismatch(f"The design matrix stored in {str(out)!r} differs from this sweep's.")
    return g


def prepare_store(
    out: Path,
    study: DesignStudy,
    designs: np.ndarray | None,
    chunk: int,
    fingerprint: dict[str, Any],
    info: dict,
    n: int | None = None,
):
    """Open the sweep's store at ``out`` (creating it if absent); raise StoreMismatch if it is another's.

    ``designs=None`` (NSGA-II: rows known only as the optimiser proposes them) creates ``n`` NaN rows.
    """
    import zarr

    out = Path(out)
    fp = _canonical(fingerprint)
    n = designs.shape[0] if designs is not None else int(n)
    d = len(study.variables)
    n_chunks = -(-n // chunk)
    g = open_store(out, fingerprint, designs)
    if g is not None:
        return g
    g = zarr.open_group(str(out), mode="w")
    g.create_array("designs", shape=(n, d), chunks=(chunk, d), dtype="float64", fill_value=np.nan)
    if designs is not None:
        g["designs"][:] = designs
    g.create_array("design_ok", shape=(n,), chunks=(chunk,), dtype="bool", fill_value=False)
    for m in study.metrics:
        fill = False if m.dtype == "bool" else np.nan
        g.create_array(m.name, shape=(n, *m.shape), chunks=(chunk, *m.shape), dtype=m.dtype, fill_value=fill)
        g[m.name].attrs.update({"unit": m.unit, "description": m.description})
    g.create_array("chunk_done", shape=(n_chunks,), chunks=(1,), dtype="bool", fill_value=False)
    for name in ("chunk_seconds", "chunk_cpu_seconds"):
        g.create_array(name, shape=(n_chunks,), chunks=(1,), dtype="float64", fill_value=np.nan)
    g["designs"].attrs.update({"columns": [v.name for v in study.variables]})
    g.attrs.update({"robomech": _canonical({"format": FORMAT, "fingerprint": fp, **info})})
    return g


def open_results(out: Path | str) -> dict[str, Any]:
    """A sweep store as plain data: ``attrs`` (the robomech attributes) and every array as numpy."""
    out = _check_path(out, "out")
    if not out.is_dir():
        raise ValueError(f"Expected out to be a sweep store directory, got {str(out)!r} (not a directory).")
    import zarr

    try:
        g = zarr.open_group(str(out), mode="r")
    except Exception as exc:  # zarr raises several kinds for a folder that is not a store
        raise ValueError(f"Expected out to be a robomech sweep store, got {str(out)!r}.") from exc
    meta = dict(g.attrs).get("robomech", {})
    if meta.get("format") != FORMAT:
        raise ValueError(
            f"Expected out {str(out)!r} to be a robomech sweep store, got no robomech attributes."
        )
    arrays = {name: np.asarray(a[...]) for name, a in g.arrays()}
    return {"attrs": meta, **arrays}
