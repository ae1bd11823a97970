"""The chain check shared by the chain tests (``test_chain*.py``): a failed sample (a NaN row) of one
call's output fed into the next call stays a failed sample there, the other samples as when alone."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np

# the good samples alone and inside the mixed batch run the same formulas on the same numbers
SAME_RTOL = 1e-12


def arrays_of(res: Any) -> dict[str, np.ndarray]:
    if isinstance(res, np.ndarray):
        items = {"result": res}
    elif isinstance(res, tuple):
        items = {f"[{i}]": r for i, r in enumerate(res)}
    else:
        items = {f.name: getattr(res, f.name) for f in dataclasses.fields(res)}
        for k, v in list(items.items()):
            if dataclasses.is_dataclass(v):
                items.update({f"{k}.{n}": a for n, a in arrays_of(v).items()})
    return {
        k: np.asarray(v) for k, v in items.items() if isinstance(v, np.ndarray) and v.dtype.kind in "biuf"
    }


def check_chain(call: Callable[[np.ndarray], Any], q: np.ndarray, bad: int, good: list[int]) -> None:
    """``call(q)`` with ``q[bad]`` failed: NaN / False there, the good samples as when alone."""
    mixed = arrays_of(call(q))
    alone = arrays_of(call(q[good]))
    n = q.shape[0]
    filled = q.copy()
    filled[bad] = q[good[0]]  # the same batch size without a failed sample: the same result shapes
    shapes = {k: v.shape for k, v in arrays_of(call(filled)).items()}
    assert {k: v.shape for k, v in mixed.items()} == shapes, "a failed sample changed a result shape"
    batched = [k for k, v in mixed.items() if v.ndim >= 1 and v.shape[0] == n]
    assert batched, "no result array has the batch"
    for k in batched:
        v = mixed[k]
        if v.dtype.kind == "f":  # NaN, or inf for a residual / condition that has no finite value
            assert not np.any(np.isfinite(v[bad])), f"{k}: the failed sample is not NaN"
        elif v.dtype.kind == "b":
            assert not np.any(v[bad]), f"{k}: the failed sample is flagged True"
        np.testing.assert_allclose(v[good], alone[k], rtol=SAME_RTOL, atol=0.0, err_msg=k)


def functions_taking(module: Any, names: set[str]) -> set[str]:
    """The public functions of ``module`` with a parameter named in ``names`` (a state argument)."""
    import inspect

    return {
        n
        for n in module.__all__
        if inspect.isfunction(getattr(module, n))
        and names & set(inspect.signature(getattr(module, n)).parameters)
    }


def check_refused(call: Callable[[np.ndarray], Any], q: np.ndarray, match: str) -> None:
    """±inf and 1e300 in a good sample of ``q`` are no failed sample but a wrong input: ValueError."""
    import pytest

    good = int(np.flatnonzero(np.isfinite(q).all(axis=-1))[0])
    for bad in (np.inf, -np.inf, 1e300):
        b = q.copy()
        b[good, -1] = bad
        with pytest.raises(ValueError, match=match):
            call(b)


def check_strict_fails(call: Callable[[np.ndarray], Any], q: np.ndarray, bad: int, good: list[int]) -> None:
    """Control: ``call``, a function that refuses NaN (the undecorated boundary), fails the chain check."""
    import pytest

    with pytest.raises(ValueError):
        check_chain(call, q, bad, good)
