"""Engine results that a study also shows, computed once per output folder.

Some verification computations are also a study's figures and tables: the vectored thruster's
checks, the OmniLeg's 2 s forward simulation, the continuum's compensation solves on the
disk-resolved reference.  Each goes through :func:`computed_once`, which, by the mode set around it,

* outside any mode: computes (the Python API, ``robomech verify`` without ``--out``);
* inside :func:`recording` (``robomech verify --out DIR``): computes and writes the result to
  ``DIR/verification-results/<name>.npz``;
* inside :func:`reading` (``robomech reproduce --out DIR``, :func:`robomech.studies._report.publish_study`):
  returns the stored result when it was computed by the same code with the same parameters (its key
  matches), and otherwise computes it by the very same function (nothing is written: the verification
  alone records).

So ``make run`` (``verify --out`` first, then ``reproduce --out``) computes each such result once.

Format of a stored result: one NumPy ``.npz`` file (``numpy.savez``, no pickles; read with
``allow_pickle=False``) holding the result's arrays under their names (a scalar as a 0-d array, text
as a unicode array) and ``__key__``, the hex SHA-256 of: the result's name; its parameters (frozen
dataclasses field by field, floats by ``float.hex``, arrays by dtype, shape and bytes); the bytes of
every ``.py`` file of the installed ``robomech`` package; and the versions of numpy, scipy and
mujoco.  Any change of code, parameters or engine makes the stored result stale (recomputed).
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import importlib.metadata
import os
import tempfile
from collections.abc import Callable, Iterator, Mapping
from contextvars import ContextVar
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from robomech._progress import LOGGER

from ._core import Check, Tolerance

__all__ = [
    "RESULTS_FOLDER",
    "checks_from_arrays",
    "checks_to_arrays",
    "computed_once",
    "reading",
    "recording",
    "result_key",
]

RESULTS_FOLDER = "verification-results"
_KEY = "__key__"
# (folder, write): where computed_once reads or writes; None outside recording() / reading()
_MODE: ContextVar[tuple[Path, bool] | None] = ContextVar("robomech_verification_store", default=None)


def _folder(out_root: object) -> Path:
    if not isinstance(out_root, str | Path):
        raise ValueError(
            f"Expected out_root to be a folder path (str or Path), got {type(out_root).__name__}."
        )
    return Path(out_root) / RESULTS_FOLDER


@contextlib.contextmanager
def _mode(out_root: str | Path, write: bool) -> Iterator[Path]:
    folder = _folder(out_root)
    token = _MODE.set((folder, write))
    try:
        yield folder
    finally:
        _MODE.reset(token)


def recording(out_root: str | Path) -> contextlib.AbstractContextManager[Path]:
    """Within the block, :func:`computed_once` computes and writes to ``out_root/verification-results``.

    Yields that folder (created on the first write).
    """
    return _mode(out_root, True)


def reading(out_root: str | Path) -> contextlib.AbstractContextManager[Path]:
    """Within the block, :func:`computed_once` returns the results stored in
    ``out_root/verification-results`` whose key matches, and computes the others (writing nothing).

    Yields that folder.
    """
    return _mode(out_root, False)


def _canonical(obj: Any) -> Any:
    """A hashable text form of parameters that tells apart any two different values."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        fields = tuple((f.name, _canonical(getattr(obj, f.name))) for f in dataclasses.fields(obj))
        return (type(obj).__qualname__, fields)
    if isinstance(obj, np.ndarray):
        return (
            "ndarray",
            obj.dtype.str,
            obj.shape,
            hashlib.sha256(np.ascontiguousarray(obj).tobytes()).hexdigest(),
        )
    if isinstance(obj, float | np.floating):
        return float(obj).hex()
    if isinstance(obj, list | tuple):
        return tuple(_canonical(v) for v in obj)
    if isinstance(obj, Mapping):
        return tuple(sorted((str(k), _canonical(v)) for k, v in obj.items()))
    if obj is None or isinstance(obj, bool | int | str | np.integer | np.bool_):
        return repr(obj)
    raise ValueError(
        f"Expected parameters of dataclasses, arrays, numbers and text, got {type(obj).__name__}."
    )


@lru_cache(maxsize=1)
def _code_digest() -> str:
    """SHA-256 of the robomech package's sources and of the numeric libraries' versions."""
    import robomech

    root = Path(robomech.__file__).parent
    h = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        h.update(path.relative_to(root).as_posix().encode())
        h.update(path.read_bytes())
    for dist in ("numpy", "scipy", "mujoco"):
        try:
            version = importlib.metadata.version(dist)
        except importlib.metadata.PackageNotFoundError:
            version = "absent"
        h.update(f"{dist}={version}".encode())
    return h.hexdigest()


def result_key(name: str, params: object) -> str:
    """The key of result ``name`` computed with ``params`` by this code (see the module's docstring)."""
    if not isinstance(name, str) or not name or "/" in name:
        raise ValueError(f"Expected name to be a non-empty file stem (no '/'), got {name!r}.")
    text = repr((name, _canonical(params), _code_digest()))
    return hashlib.sha256(text.encode()).hexdigest()


def _decoded(arrays: Mapping[str, np.ndarray]) -> dict[str, Any]:
    """0-d arrays back to Python scalars (as computed), the rest as arrays."""
    return {k: (v.item() if v.ndim == 0 else v) for k, v in arrays.items() if k != _KEY}


def _load(path: Path, key: str) -> dict[str, Any] | None:
    if not path.is_file():
        LOGGER.info("verification result %s not stored: computing it", path.stem)
        return None
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (OSError, ValueError) as exc:
        LOGGER.info("verification result %s unreadable (%s): computing it", path.stem, exc)
        return None
    if _KEY not in arrays or str(arrays[_KEY]) != key:
        LOGGER.info("verification result %s stale (other code or parameters): computing it", path.stem)
        return None
    LOGGER.info("verification result %s read from %s", path.stem, path.parent)
    return _decoded(arrays)


def _save(path: Path, key: str, result: Mapping[str, Any]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    arrays: dict[str, Any] = {_KEY: np.array(key), **{k: np.asarray(v) for k, v in result.items()}}
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}-", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:  # a file object: savez would append .npz to a name
            np.savez(f, **arrays)
        os.replace(tmp, path)  # readers see the old file or the whole new one
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def computed_once(name: str, params: object, compute: Callable[[], Mapping[str, Any]]) -> dict[str, Any]:
    """``compute()`` (a mapping of arrays, numbers, bools and text), or its stored result.

    Parameters
    ----------
    name : str
        The result's file stem, e.g. ``"omnileg.forward_simulation"``.
    params : object
        Everything ``compute`` depends on besides the code: dataclasses, arrays, numbers, text
        (nested in tuples, lists or dicts).
    compute : callable
        ``compute() -> mapping``; its values must round-trip through ``numpy.savez``.

    Returns
    -------
    dict
        The result; a scalar comes back as a Python scalar, an array as an array.

    Raises
    ------
    ValueError
        If ``name`` is not a file stem, ``params`` holds something without a canonical form, or
        ``compute`` does not return a mapping.
    """
    mode = _MODE.get()
    key = result_key(name, params) if mode is not None else ""
    if mode is not None and not mode[1]:
        stored = _load(mode[0] / f"{name}.npz", key)
        if stored is not None:
            return stored
    result = compute()
    if not isinstance(result, Mapping):
        raise ValueError(f"Expected compute to return a mapping of arrays, got {type(result).__name__}.")
    if mode is not None and mode[1]:
        _save(mode[0] / f"{name}.npz", key, result)
    return dict(result)


_CHECK_FIELDS = ("mechanism", "quantity", "max_error", "tolerance", "reason", "relative", "detail")
# Columns a store written before them lacks: read as their default ("").
_OPTIONAL_FIELDS = ("verdict", "note")


def checks_to_arrays(checks: list[Check]) -> dict[str, np.ndarray]:
    """Checks as columns of arrays (what :func:`computed_once` stores)."""
    return {
        "mechanism": np.array([c.mechanism for c in checks], dtype=str),
        "quantity": np.array([c.quantity for c in checks], dtype=str),
        "max_error": np.array([c.max_error for c in checks], dtype=float),
        "tolerance": np.array([c.tolerance.value for c in checks], dtype=float),
        "reason": np.array([c.tolerance.reason for c in checks], dtype=str),
        "relative": np.array([c.tolerance.relative for c in checks], dtype=bool),
        "detail": np.array([c.detail for c in checks], dtype=str),
        **{f: np.array([getattr(c, f) for c in checks], dtype=str) for f in _OPTIONAL_FIELDS},
    }


def checks_from_arrays(columns: Mapping[str, Any]) -> list[Check]:
    """The checks of :func:`checks_to_arrays`' columns."""
    n = len(columns["quantity"])
    col = {k: np.asarray(columns[k]).reshape(n) for k in _CHECK_FIELDS}
    extra = {
        k: np.asarray(columns[k]).reshape(n) if k in columns else np.full(n, "") for k in _OPTIONAL_FIELDS
    }
    return [
        Check(
            str(col["mechanism"][i]),
            str(col["quantity"][i]),
            float(col["max_error"][i]),
            Tolerance(float(col["tolerance"][i]), str(col["reason"][i]), bool(col["relative"][i])),
            str(col["detail"][i]),
            **{k: str(extra[k][i]) for k in _OPTIONAL_FIELDS},
        )
        for i in range(n)
    ]
