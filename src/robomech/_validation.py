"""Input validation at the public boundary.

Kernels trust their inputs; public functions call these once and raise ``ValueError`` naming the
argument with what was expected and what was received (the SciPy style).  Physical failures
(unreachable poses, singular configurations) are *not* errors: they are reported per sample by the
result objects of each model.

Helpers:

- arrays: ``as_array`` (real float64, trailing shape, finiteness), ``check_finite``,
  ``broadcast_batch`` / ``broadcast_to_batch`` (batch shapes of several arguments that
  must broadcast together), ``finite_samples`` (per-sample finiteness mask for models that mask instead
  of raising);
- parameter objects: ``check_params`` (``Expected leg to be a SphericalLeg, got NoneType.``);
- scalar options: ``check_real``, ``check_positive``, ``check_int``, ``check_bool``, ``check_choice``;
- frozen dataclass fields: ``coerce_float_fields``, ``coerce_int_fields`` (store the validated value
  with ``object.__setattr__``, so a field never keeps a str, a bool or a NumPy 0-d array).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Sequence

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "MAX_MAGNITUDE",
    "as_array",
    "broadcast_batch",
    "broadcast_to_batch",
    "check_bool",
    "check_choice",
    "check_finite",
    "check_int",
    "check_params",
    "check_positive",
    "check_real",
    "coerce_float_fields",
    "coerce_int_fields",
    "finite_samples",
]

# dtype kinds accepted as real numbers: signed/unsigned integers and floats.  Complex ('c') would lose
# its imaginary part in a float64 cast, bool ('b') is a flag not a number, and str/bytes/object/
# datetime kinds are not numbers at all.
_REAL_KINDS = frozenset("iuf")

# Largest magnitude accepted where a finite number is required.  Models multiply up to a few inputs
# together (squares of lengths, cubes in Jacobian products, rates squared times inertias): with
# |x| <= 1e100 a product of three stays below 1e300 < 1.8e308, so float64 cannot overflow to inf
# silently.  No physical quantity in SI units of these mechanisms comes near 1e100.
MAX_MAGNITUDE = 1e100


def _shape_text(tail: Sequence[int | None]) -> str:
    parts = ["..."] + ["n" if d is None else str(d) for d in tail]
    return "(" + ", ".join(parts) + ")"


def _type_text(x: object) -> str:
    if isinstance(x, np.ndarray):
        return f"an array of dtype {x.dtype}"
    return type(x).__name__


def as_array(
    x: object,
    name: str,
    tail: Sequence[int | None] = (),
    *,
    finite: bool | str = True,
    min_ndim: int | None = None,
    nonempty: bool = False,
    nan_rows: bool = False,
) -> np.ndarray:
    """Return ``x`` as a float64 array whose trailing dimensions are ``tail``.

    Only real numbers are accepted (integer or float dtypes); complex, bool, str and object inputs
    (including ``None`` and ragged lists) raise.  ``None`` in ``tail`` accepts any length.
    ``finite=True`` rejects NaN, infinity and magnitudes above :data:`MAX_MAGNITUDE`; a model that
    prefers to flag such samples per sample passes ``finite=False`` and masks them itself (see
    ``finite_samples``), or ``finite="mask"``, which also turns every magnitude above
    :data:`MAX_MAGNITUDE` (and inf) into NaN, for models that mask NaN samples.
    ``nonempty=True`` also requires every free (``None``) trailing dimension to be at least 1: a
    Jacobian ``(..., m, n)`` with no rows or no columns has no condition, rank or solution to report.
    ``nan_rows=True`` accepts NaN as the mark of a failed sample of an earlier call (docs/conventions.md,
    "Failed samples chain"): a sample (the trailing ``tail`` axes) with a NaN entry is returned all NaN;
    ±inf and magnitudes above :data:`MAX_MAGNITUDE` still raise (no failed sample but a wrong input).
    """
    if x is None or isinstance(x, str | bytes):
        raise ValueError(f"Expected {name} to be an array of real numbers, got {type(x).__name__}.")
    try:
        raw = np.asarray(x)
    except (TypeError, ValueError) as exc:  # ragged nested sequences
        raise ValueError(f"Expected {name} to be an array of real numbers, got {_type_text(x)}.") from exc
    if raw.dtype.kind not in _REAL_KINDS:
        got = f"dtype {raw.dtype}"
        if not isinstance(x, np.ndarray):
            got = f"{type(x).__name__} of {got}"
        raise ValueError(f"Expected {name} to be an array of real numbers, got {got}.")
    a = raw.astype(np.float64, copy=False)
    need = len(tail) if min_ndim is None else max(min_ndim, len(tail))
    if a.ndim < need or any(
        d is not None and a.shape[a.ndim - len(tail) + i] != d for i, d in enumerate(tail)
    ):
        raise ValueError(f"Expected {name} to have shape {_shape_text(tail)}, got {a.shape}.")
    if nonempty and any(d is None and a.shape[a.ndim - len(tail) + i] == 0 for i, d in enumerate(tail)):
        free = ", ".join("n >= 1" if d is None else str(d) for d in tail)
        raise ValueError(
            f"Expected {name} to have shape (..., {free}) with no empty dimension, got {a.shape}."
        )
    if nan_rows:
        wrong = ~np.isnan(a) & ~(np.abs(a) <= MAX_MAGNITUDE)
        if np.any(wrong):
            raise ValueError(
                f"Expected {name} finite with |value| <= {MAX_MAGNITUDE:g} (NaN marks a failed sample), "
                f"got {a[wrong].flat[0]:g}."
            )
        nan = np.isnan(a)
        if len(tail):
            nan = np.asarray(nan.any(axis=tuple(range(a.ndim - len(tail), a.ndim)), keepdims=True))
        return np.where(nan, np.nan, a) if nan.any() else a
    if finite == "mask":
        return usable(a)
    if finite:
        if not np.all(np.isfinite(a)):
            bad = int(np.size(a) - np.count_nonzero(np.isfinite(a)))
            raise ValueError(f"Expected {name} to be finite, got {bad} non-finite value(s).")
        if a.size and np.max(np.abs(a)) > MAX_MAGNITUDE:
            raise ValueError(
                f"Expected {name} to have magnitudes <= {MAX_MAGNITUDE:g} (float64 products overflow "
                f"beyond), got {float(np.max(np.abs(a))):.3g}."
            )
    return a


def finite_samples(a: np.ndarray, n_core: int) -> np.ndarray:
    """Per-sample usability: every entry finite and within :data:`MAX_MAGNITUDE`, over the last
    ``n_core`` axes of ``a`` (the mask a model applies before its kernels)."""
    with np.errstate(invalid="ignore"):
        f = np.abs(a) <= MAX_MAGNITUDE  # False for NaN and inf too
    if n_core:
        f = f.all(axis=tuple(range(a.ndim - n_core, a.ndim)))
    return np.asarray(f)


def usable(a: np.ndarray) -> np.ndarray:
    """``a`` with every entry that is not finite or exceeds :data:`MAX_MAGNITUDE` replaced by NaN, for
    models that mask non-finite samples themselves (``as_array(..., finite=False)``)."""
    with np.errstate(invalid="ignore"):
        return np.where(np.abs(a) <= MAX_MAGNITUDE, a, np.nan)


def check_finite(a: np.ndarray, name: str) -> None:
    if not np.all(np.isfinite(a)):
        raise ValueError(f"Expected {name} to be finite, got non-finite value(s).")


def check_params(obj: object, cls: type | tuple[type, ...], name: str) -> None:
    """Raise unless ``obj`` is an instance of ``cls`` (the mechanism's parameter dataclass)."""
    if not isinstance(obj, cls):
        want = cls.__name__ if isinstance(cls, type) else " or ".join(c.__name__ for c in cls)
        article = "an" if want[:1].lower() in "aeiou" else "a"
        raise ValueError(f"Expected {name} to be {article} {want}, got {type(obj).__name__}.")


def _scalar(value: object, name: str) -> float:
    """A real scalar (Python or NumPy number, or a 0-d / size-1 real array) as a float."""
    if isinstance(value, bool | np.bool_) or value is None or isinstance(value, str | bytes):
        raise ValueError(f"Expected {name} to be a real number, got {type(value).__name__}.")
    if isinstance(value, numbers.Real):
        return float(value)
    if isinstance(value, np.ndarray) and value.size == 1 and value.dtype.kind in _REAL_KINDS:
        return float(value.reshape(()))
    raise ValueError(f"Expected {name} to be a real number, got {_type_text(value)}.")


def check_real(
    value: object,
    name: str,
    *,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    high_open: bool = False,
    finite: bool = True,
) -> float:
    """Validate a real scalar option and return it as a float (bounds inclusive unless ``*_open``)."""
    v = _scalar(value, name)
    if math.isnan(v) or (finite and not math.isfinite(v)):
        raise ValueError(f"Expected {name} to be a finite real number, got {value!r}.")
    if finite and abs(v) > MAX_MAGNITUDE:
        raise ValueError(f"Expected {name} to have magnitude <= {MAX_MAGNITUDE:g}, got {value!r}.")
    if low is not None and (v < low or (low_open and v == low)):
        raise ValueError(f"Expected {name} {'>' if low_open else '>='} {low}, got {value!r}.")
    if high is not None and (v > high or (high_open and v == high)):
        raise ValueError(f"Expected {name} {'<' if high_open else '<='} {high}, got {value!r}.")
    return v


def check_positive(value: object, name: str, *, allow_zero: bool = False) -> float:
    """Validate one positive (or non-negative) finite real scalar; return it as a float."""
    v = _scalar(value, name)
    ok = math.isfinite(v) and abs(v) <= MAX_MAGNITUDE and (v >= 0.0 if allow_zero else v > 0.0)
    if not ok:
        rel = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"Expected {name} {rel} and finite, got {value!r}.")
    return v


def check_int(value: object, name: str, *, low: int | None = None, high: int | None = None) -> int:
    """Validate an integer option (bool and non-integral floats rejected); return it as an int."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Integral):
        raise ValueError(f"Expected {name} to be an integer, got {type(value).__name__}.")
    v = int(value)
    if (low is not None and v < low) or (high is not None and v > high):
        lo = "-inf" if low is None else str(low)
        hi = "inf" if high is None else str(high)
        raise ValueError(f"Expected {name} to be an integer in [{lo}, {hi}], got {v}.")
    return v


def check_bool(value: object, name: str) -> bool:
    """Validate a flag: only ``True``/``False`` (or NumPy bools); ``"yes"``, 1, None are rejected."""
    if not isinstance(value, bool | np.bool_):
        raise ValueError(f"Expected {name} to be True or False, got {value!r}.")
    return bool(value)


def check_choice(value: object, name: str, choices: Iterable[object]) -> object:
    """Validate that ``value`` is one of ``choices`` (compared with ==, hashable types only)."""
    options = tuple(choices)
    try:
        ok = any(type(value) is type(c) and value == c for c in options)
    except (TypeError, ValueError):  # an uncomparable value (e.g. an array) is not one of the choices
        ok = False
    if not ok:
        raise ValueError(f"Expected {name} to be one of {', '.join(map(repr, options))}; got {value!r}.")
    return value


def coerce_float_fields(
    obj: object,
    names: Iterable[str],
    *,
    positive: bool = False,
    allow_zero: bool = False,
    prefix: str = "",
) -> None:
    """Validate the named fields of a frozen dataclass as real finite scalars and store them as float.

    ``positive`` requires > 0 (or >= 0 with ``allow_zero``).  Raises ``ValueError`` naming the field
    (``prefix`` is prepended, e.g. ``"lower[0]."``).
    """
    for n in names:
        v = getattr(obj, n)
        label = prefix + n
        f = check_positive(v, label, allow_zero=allow_zero) if positive else check_real(v, label)
        object.__setattr__(obj, n, f)


def coerce_int_fields(
    obj: object, names: Iterable[str], *, low: int | None = None, high: int | None = None, prefix: str = ""
) -> None:
    """Validate the named fields of a frozen dataclass as integers (bool rejected); store them as int."""
    for n in names:
        object.__setattr__(obj, n, check_int(getattr(obj, n), prefix + n, low=low, high=high))


Batched = tuple[NDArray[np.float64], int, str]
"""One argument of :func:`broadcast_batch`: ``(array, n_core, name)``, ``n_core`` the number of its
trailing core (non-batch) axes, ``name`` the argument's name in the public signature."""


def _batch_parts(items: Sequence[Batched]) -> list[tuple[str, tuple[int, ...], tuple[int, ...]]]:
    """``(name, batch shape, core shape)`` of each item (an array with fewer than ``n_core`` axes raises)."""
    out = []
    for a, n_core, name in items:
        shape = tuple(int(d) for d in np.shape(a))
        if len(shape) < n_core:
            raise ValueError(f"Expected {name} to have at least {n_core} dimension(s), got shape {shape}.")
        cut = len(shape) - n_core
        out.append((name, shape[:cut], shape[cut:]))
    return out


def broadcast_batch(*items: Batched) -> tuple[int, ...]:
    """The common batch shape of several arguments, each ``(array, n_core, name)``.

    The batch part of an array is everything before its last ``n_core`` axes (its core, already
    checked by :func:`as_array`); the batch parts must broadcast together (NumPy rules).  Call it at
    the boundary of every public function that takes two or more batched arrays, right after their
    ``as_array`` checks, so that a mismatch is reported in the arguments' names instead of as a bare
    NumPy broadcasting error from inside a kernel::

        broadcast_batch((q, 1, "q"), (qd, 1, "qd"))
        # ValueError: Expected q (..., 3) and qd (..., 3) with batch shapes (...) that broadcast
        #             together, got batch shapes q (2,), qd (3,).

    Scalars (``n_core=0`` arrays of shape ``()``) broadcast with everything.  Returns the common
    batch shape.
    """
    parts = _batch_parts(items)
    try:
        return tuple(int(d) for d in np.broadcast_shapes(*(b for _, b, _ in parts)))
    except ValueError as exc:
        want = [f"{n} {_shape_text(c)}" for n, _, c in parts]
        wanted = ", ".join(want[:-1]) + " and " + want[-1] if len(want) > 1 else want[0]
        got = ", ".join(f"{n} {b}" for n, b, _ in parts)
        raise ValueError(
            f"Expected {wanted} with batch shapes (...) that broadcast together, got batch shapes {got}."
        ) from exc


def broadcast_to_batch(*items: Batched) -> tuple[NDArray[np.float64], ...]:
    """:func:`broadcast_batch`, then every array broadcast to the common batch shape followed by its
    own core shape (read-only views, as ``np.broadcast_to`` returns)."""
    batch = broadcast_batch(*items)
    return tuple(
        np.broadcast_to(a, batch + core)
        for (a, _, _), (_, _, core) in zip(items, _batch_parts(items), strict=True)
    )
