"""Input validation at the public boundary.

Kernels trust their inputs; public functions call these once and raise ``ValueError`` naming the
argument with what was expected and what was received (the SciPy style).  Physical failures
(unreachable poses, singular configurations) are *not* errors: they are reported per sample by the
result objects of each model.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["as_array", "broadcast_batch", "check_finite", "check_positive"]


def _shape_text(tail: Sequence[int | None]) -> str:
    parts = ["..."] + ["n" if d is None else str(d) for d in tail]
    return "(" + ", ".join(parts) + ")"


def as_array(
    x: object,
    name: str,
    tail: Sequence[int | None] = (),
    *,
    finite: bool = True,
    min_ndim: int | None = None,
) -> np.ndarray:
    """Return ``x`` as a float64 array whose trailing dimensions are ``tail``.

    ``None`` in ``tail`` accepts any length.  ``finite=True`` rejects NaN and infinity; a model that
    prefers to flag such samples per sample passes ``finite=False`` and masks them itself.
    """
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"Expected {name} to be an array of real numbers, got {type(x).__name__}.") from exc
    need = len(tail) if min_ndim is None else max(min_ndim, len(tail))
    if a.ndim < need or any(
        d is not None and a.shape[a.ndim - len(tail) + i] != d for i, d in enumerate(tail)
    ):
        raise ValueError(f"Expected {name} to have shape {_shape_text(tail)}, got {a.shape}.")
    if finite and not np.all(np.isfinite(a)):
        bad = int(np.size(a) - np.count_nonzero(np.isfinite(a)))
        raise ValueError(f"Expected {name} to be finite, got {bad} non-finite value(s).")
    return a


def check_finite(a: np.ndarray, name: str) -> None:
    if not np.all(np.isfinite(a)):
        raise ValueError(f"Expected {name} to be finite, got non-finite value(s).")


def check_positive(value: float, name: str, *, allow_zero: bool = False) -> float:
    """Validate one scalar parameter of a frozen parameter dataclass."""
    v = float(value)
    ok = np.isfinite(v) and (v >= 0.0 if allow_zero else v > 0.0)
    if not ok:
        rel = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"Expected {name} {rel} and finite, got {value!r}.")
    return v


def broadcast_batch(*arrays_and_tails: tuple[np.ndarray, int]) -> tuple[int, ...]:
    """Broadcast the batch parts of several arrays; ``(array, n_core_dims)`` pairs.

    Returns the common batch shape, or raises ``ValueError`` naming the shapes.
    """
    shapes = [a.shape[: a.ndim - k] for a, k in arrays_and_tails]
    try:
        return tuple(np.broadcast_shapes(*shapes))
    except ValueError as exc:
        raise ValueError(f"Batch shapes do not broadcast: {shapes}.") from exc
