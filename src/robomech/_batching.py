"""Batches: cache-sized chunks, and failed samples carried through a call.

A kernel that works elementwise per sample gives the same bits on any split of its batch, but on
10^6 samples its temporaries (tens of arrays the size of the batch) stream through memory; run on
chunks of a few thousand samples they stay in cache (the packages' benchmarks measure 1.3-2x).
:func:`chunked` is that loop, written once: a loop over chunks, never over samples.

A failed sample of an earlier call (a NaN row: what a solver returns where it did not converge) is
carried through the next call as a failed sample (docs/conventions.md, "Failed samples chain"):
:func:`on_rows` computes only the other samples and gives the failed ones NaN / False / 0;
:func:`carries_failed_rows` does it at the boundary of a public function.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import inspect
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any, TypeVar

import numpy as np

from robomech._validation import as_array, broadcast_batch

__all__ = ["carries_failed_rows", "chunked", "chunked_rows", "failed_rows", "on_rows", "slices"]

F = TypeVar("F", bound=Callable[..., Any])
R = TypeVar("R")


def slices(n: int, chunk: int) -> Iterator[slice]:
    """Consecutive slices of ``range(n)``, each of at most ``chunk`` samples (none when ``n == 0``)."""
    return (slice(s, min(s + chunk, n)) for s in range(0, n, chunk))


def _leaves(out: Any) -> list[np.ndarray]:
    if isinstance(out, np.ndarray):
        return [out]
    if dataclasses.is_dataclass(out):
        return [getattr(out, f.name) for f in dataclasses.fields(out)]
    return list(out)  # a tuple (or NamedTuple) of arrays


def _rebuild(like: Any, arrays: list[np.ndarray]) -> Any:
    if isinstance(like, np.ndarray):
        return arrays[0]
    if dataclasses.is_dataclass(like):
        fields = dataclasses.fields(like)
        return dataclasses.replace(like, **{f.name: a for f, a in zip(fields, arrays, strict=True)})  # type: ignore[type-var]
    return type(like)(*arrays) if hasattr(like, "_fields") else type(like)(arrays)


def chunked(fn: Callable[[slice], Any], n: int, chunk: int) -> Any:
    """Evaluate ``fn(s)`` on consecutive slices ``s`` of ``range(n)`` of at most ``chunk`` samples.

    Parameters
    ----------
    fn : callable
        ``fn(s)`` evaluates the samples ``s`` (a :class:`slice` of the flat batch axis).  It either
        writes its results in place (and returns ``None``) or returns an array, a tuple of arrays or
        a dataclass of arrays whose leading axis has ``s``'s length.
    n : int
        Number of samples.
    chunk : int
        Largest number of samples per call.

    Returns
    -------
    None or the type ``fn`` returns
        ``None`` for an in-place ``fn``; otherwise ``fn``'s result for all ``n`` samples, the chunks'
        results written into arrays allocated once (with the first chunk's trailing shapes and dtypes).
        With ``n <= chunk``, ``fn(slice(0, n))`` itself.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech._batching import chunked
    >>> x = np.arange(10.0)
    >>> chunked(lambda s: x[s] ** 2, 10, 4)
    array([ 0.,  1.,  4.,  9., 16., 25., 36., 49., 64., 81.])
    """
    if n <= chunk:
        return fn(slice(0, n))
    parts = slices(n, chunk)
    first = fn(next(parts))
    if first is None:
        for s in parts:
            fn(s)
        return None
    firsts = _leaves(first)
    outs = [np.empty((n, *a.shape[1:]), dtype=a.dtype) for a in firsts]
    for o, a in zip(outs, firsts, strict=True):
        o[:chunk] = a
    for s in parts:
        for o, a in zip(outs, _leaves(fn(s)), strict=True):
            o[s] = a
    return _rebuild(first, outs)


def chunked_rows(kernel: Callable[[np.ndarray], R], x: np.ndarray, chunk: int) -> R:
    """:func:`chunked` over the samples of ``x (..., k)``: ``kernel(rows)`` on blocks of at most ``chunk``
    rows ``(m, k)``, every per-sample array of the result (an array, tuple or dataclass of them) given
    ``x``'s batch shape back."""
    batch, flat = x.shape[:-1], x.reshape(-1, x.shape[-1])
    r = chunked(lambda s: kernel(flat[s]), flat.shape[0], chunk)
    return _rebuild(r, [a.reshape(batch + a.shape[1:]) for a in _leaves(r)])


def failed_rows(a: np.ndarray, n_core: int = 1) -> np.ndarray:
    """Mask of the failed samples of ``a``: True where any of its last ``n_core`` axes holds a NaN."""
    nan = np.isnan(a)
    return nan.any(axis=tuple(range(a.ndim - n_core, a.ndim))) if n_core else nan


def _fill(r: np.ndarray, ok: np.ndarray, batch: tuple[int, ...]) -> np.ndarray:
    fill: object = np.nan if r.dtype.kind in "fc" else (False if r.dtype.kind == "b" else 0)
    full = np.full((*batch, *r.shape[1:]), fill, dtype=r.dtype)
    full[ok] = r
    return full


def _scatter(res: Any, ok: np.ndarray, k: int, batch: tuple[int, ...], empty: Any = None) -> Any:
    """Every per-sample array of ``res`` (an array, a tuple / NamedTuple or a dataclass of them,
    nested), spread over ``batch`` with the failed samples filled.  Per sample: its leading axis has
    the ``k`` computed samples and, where ``empty`` (the same call on no sample) is given, 0 there;
    so an array of fixed shape whose leading length happens to be ``k`` is left alone."""
    if isinstance(res, np.ndarray):
        per_sample = res.ndim >= 1 and res.shape[0] == k
        if empty is not None:
            per_sample &= isinstance(empty, np.ndarray) and empty.ndim >= 1 and empty.shape[0] == 0
        return _fill(res, ok, batch) if per_sample else res
    if dataclasses.is_dataclass(res) and not isinstance(res, type):
        out = copy.copy(res)  # not dataclasses.replace: a result's __post_init__ is not re-run
        for f in dataclasses.fields(res):
            e = None if empty is None else getattr(empty, f.name)
            object.__setattr__(out, f.name, _scatter(getattr(res, f.name), ok, k, batch, e))
        return out
    if isinstance(res, tuple):
        es = [None] * len(res) if empty is None else list(empty)
        parts = [_scatter(r, ok, k, batch, e) for r, e in zip(res, es, strict=True)]
        return type(res)(*parts) if hasattr(res, "_fields") else tuple(parts)
    return res


def on_rows(
    failed: np.ndarray,
    compute: Callable[..., Any],
    *rows: np.ndarray,
    probe: Sequence[np.ndarray] | None = None,
) -> Any:
    """``compute(*rows)`` on the samples that did not fail only.

    Parameters
    ----------
    failed : ndarray of bool, shape ``batch``
        The failed samples (e.g. :func:`failed_rows` of the configurations).
    compute : callable
        ``compute(*rows)`` on a flat batch of samples; returns an array, a tuple (NamedTuple) or a
        dataclass of arrays (nested), those with the flat batch as leading axis being per sample.
    *rows : ndarray
        The batched arguments, each of shape ``batch + core``.
    probe : sequence of ndarray, optional
        One-sample ``rows`` to compute on where every sample failed, for a ``compute`` that cannot
        take an empty batch and whose every result array is per sample.  Without it, ``compute`` also
        runs on the empty batch (cheap): the arrays with leading length 0 there are the per-sample
        ones, so a fixed-shape result array is never mistaken for one.

    Returns
    -------
    ``compute``'s result for the whole batch: each per-sample array of shape ``batch + tail`` with
    NaN (float), False (bool) or 0 (int) at the failed samples.  A batch without failed samples is
    computed as it is (the very same call), so good samples never depend on their failed neighbours.
    """
    failed = np.asarray(failed, dtype=bool)
    if not failed.any():
        return compute(*rows)
    ok = ~failed
    k = int(np.count_nonzero(ok))
    if probe is not None:  # every result array is per sample
        if k == 0:
            return _scatter(compute(*probe), ok, 1, failed.shape)  # (1, ...) assigned to no sample
        return _scatter(compute(*(r[ok] for r in rows)), ok, k, failed.shape)
    res = compute(*(r[ok] for r in rows))
    empty = res if k == 0 else compute(*(r[ok][:0] for r in rows))  # tells per-sample arrays
    return _scatter(res, ok, k, failed.shape, empty)


def carries_failed_rows(
    nan_rows: Mapping[str, int], batched: Mapping[str, int] | None = None, *, masked: Sequence[str] = ()
) -> Callable[[F], F]:
    """Decorator: the public function carries the failed samples (NaN rows) of ``nan_rows``.

    ``nan_rows`` maps the state-like array arguments that the package's own functions output
    (joint angles, rates, lengths, ...) to their number of core axes; ``batched`` the function's
    other batched array arguments (same form).  A call without NaN in ``nan_rows`` is the function
    itself.  Otherwise each ``nan_rows`` argument is checked with ``as_array(..., nan_rows=True)``
    (±inf and magnitudes above ``MAX_MAGNITUDE`` still raise, naming it), every batched argument is
    broadcast to the common batch, and the function runs on the samples without NaN only
    (:func:`on_rows`): its boundary checks every remaining value, and the failed samples get NaN,
    False or 0 in every per-sample result array.  The other ``batched`` arguments are checked at the
    failed samples too (finite, magnitudes within ``MAX_MAGNITUDE``), as the function checks them at
    the others, except those in ``masked``: arguments the function itself masks per sample.
    """
    every = {**(batched or {}), **nan_rows}

    def wrap(fn: F) -> F:
        sig = inspect.signature(fn)

        params = list(sig.parameters)
        where = {n: params.index(n) for n in nan_rows}  # positional index of each nan_rows argument

        @functools.wraps(fn)
        def call(*args: Any, **kwargs: Any) -> Any:
            if not any(
                _has_nan(kwargs[n] if n in kwargs else args[i] if i < len(args) else None)
                for n, i in where.items()
            ):
                return fn(*args, **kwargs)  # the common case: no sample failed, no binding
            try:
                bound = sig.bind(*args, **kwargs)
            except TypeError:
                return fn(*args, **kwargs)
            given = bound.arguments
            checked = {
                n: as_array(given[n], n, (None,) * c, nan_rows=True)
                for n, c in nan_rows.items()
                if given.get(n) is not None
            }
            arrays = {
                n: checked[n] if n in checked else as_array(given[n], n, (None,) * c, finite=False)
                for n, c in every.items()
                if given.get(n) is not None
            }
            batch = broadcast_batch(*((a, every[n], n) for n, a in arrays.items()))
            failed = np.zeros(batch, bool)
            for n, a in checked.items():
                failed = failed | failed_rows(a, nan_rows[n])
            names = list(arrays)
            full = [np.broadcast_to(a, batch + a.shape[a.ndim - every[n] :]) for n, a in arrays.items()]
            for n, a in zip(names, full, strict=True):
                if n not in nan_rows and n not in masked:
                    as_array(a[failed], n)  # the values a failed sample drops: still a wrong input

            def run(*rows: np.ndarray) -> Any:
                bound.arguments.update(zip(names, rows, strict=True))
                return fn(*bound.args, **bound.kwargs)

            return on_rows(failed, run, *full)

        return call  # type: ignore[return-value]

    return wrap


def _has_nan(x: object) -> bool:
    """True for a real array (or array-like) holding a NaN; False for anything else (the function's
    own boundary check then refuses what it must)."""
    if isinstance(x, float):
        return x != x
    if isinstance(x, np.ndarray):
        return x.dtype.kind == "f" and bool(np.isnan(x).any())
    if x is None or isinstance(x, str | bytes | int):
        return False
    try:
        a = np.asarray(x)
    except (TypeError, ValueError):
        return False
    return a.dtype.kind == "f" and bool(np.isnan(a).any())
