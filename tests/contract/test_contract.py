"""The contract suite: every public name has a bad-input spec, and every spec holds.

See README.md in this folder for how to add a spec.  What is checked (docs/conventions.md):
bad input raises ``ValueError`` naming the argument with expected vs got, never another exception;
per-sample failures are masked, never an unmasked non-finite value, never a changed good sample;
no call on bad input takes longer than ``BAD_CALL_SECONDS``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import faulthandler
import inspect
import re
import signal
from typing import Any

import numpy as np
import pytest
from contract_spec import Spec, load_specs, public_names, spec_file_for
from hypothesis import given, settings
from hypothesis import strategies as st

# Acceptance of issue 14: no public call takes longer than 5 s on bad input.
BAD_CALL_SECONDS = 5.0
# A good call may include a one-off numba compile or a MuJoCo model build.
GOOD_CALL_SECONDS = 120.0
# A hang inside compiled code (LAPACK, numba) ignores Python signals: the process is then ended with a
# traceback by faulthandler after this many seconds, so the suite can never hang.
HARD_KILL_FACTOR = 4.0
# Good samples of a mixed batch must be unchanged by a bad sample beside them.  Batched kernels process
# samples independently, so they agree to round-off; this allows a few ulps of reassociation.
SAME_RTOL = 1e-12
SAME_ATOL = 1e-12

PUBLIC = public_names()
SPECS, WHERE = load_specs()
ACTIVE = {k: v for k, v in SPECS.items() if isinstance(v, Spec)}


# --- helpers --------------------------------------------------------------------------------------
class _CallTimeout(Exception):
    pass


@contextlib.contextmanager
def bounded(seconds: float):
    """Fail a call that takes longer than ``seconds`` (SIGALRM; faulthandler for compiled code)."""

    def _alarm(signum, frame):
        raise _CallTimeout(f"call took longer than {seconds} s")

    old = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    faulthandler.dump_traceback_later(seconds * HARD_KILL_FACTOR, exit=True)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        faulthandler.cancel_dump_traceback_later()
        signal.signal(signal.SIGALRM, old)


def _target(name: str, spec: Spec):
    return spec.call if spec.call is not None else PUBLIC[name]


def _call(name: str, spec: Spec, args: dict[str, Any], seconds: float = BAD_CALL_SECONDS):
    with bounded(seconds):
        return _target(name, spec)(**args)


def _default_is_none(name: str, spec: Spec, arg: str) -> bool:
    try:
        p = inspect.signature(_target(name, spec)).parameters.get(arg)
    except (TypeError, ValueError):
        return False
    return p is not None and p.default is None


def _arrays_of(res: Any) -> list[tuple[str, np.ndarray]]:
    """The numeric arrays of a result: itself, a tuple's items, or a dataclass's fields."""
    if isinstance(res, np.ndarray):
        items = [("result", res)]
    elif isinstance(res, tuple | list):
        items = [(f"[{i}]", r) for i, r in enumerate(res)]
    elif dataclasses.is_dataclass(res):
        items = [(f.name, getattr(res, f.name)) for f in dataclasses.fields(res)]
    else:
        items = []
    return [(k, v) for k, v in items if isinstance(v, np.ndarray) and v.dtype.kind in "biuf"]


def _mask_of(spec: Spec, res: Any) -> np.ndarray:
    if callable(spec.mask):
        m = spec.mask(res)
    else:
        m = res[spec.mask] if isinstance(spec.mask, int) else getattr(res, spec.mask)
    return np.asarray(m, dtype=bool)


def _check_finite_where_valid(name: str, spec: Spec, res: Any) -> None:
    if not spec.finite_result:
        return
    if spec.mask is None:
        for label, a in _arrays_of(res):
            assert np.all(np.isfinite(a)), f"{name}: result {label} has non-finite values"
        return
    mask = _mask_of(spec, res)
    for label, a in _arrays_of(res):
        if a.dtype.kind != "f" or a.shape[: mask.ndim] != mask.shape:
            continue
        flat = np.isfinite(a).reshape(mask.size, -1).all(axis=1)
        bad = np.flatnonzero(mask.reshape(-1) & ~flat)
        assert bad.size == 0, f"{name}: result {label} not finite at samples {bad} where {spec.mask} is True"


_GOOD: dict[str, Any] = {}


def _good(name: str, spec: Spec) -> Any:
    if name not in _GOOD:
        _GOOD[name] = _call(name, spec, dict(spec.args), GOOD_CALL_SECONDS)
    return _GOOD[name]


def _expect_value_error(name: str, spec: Spec, args: dict[str, Any], arg: str, what: str) -> None:
    with pytest.raises(ValueError) as info:
        _call(name, spec, args)
    msg = str(info.value)
    assert re.search(rf"(?<![\w]){re.escape(arg)}(?![\w])", msg), (
        f"{name}({arg}={what}): the ValueError must name {arg!r}; got: {msg}"
    )
    assert "xpected" in msg, f"{name}({arg}={what}): say what was expected and what was got; got: {msg}"


def _check_masked(
    name: str, spec: Spec, arg: str, args: dict[str, Any], flat_index: int, must_mask: bool = True
) -> None:
    """NaN/inf at one sample: masked there, the other samples unchanged.  A finite but huge value
    (``must_mask=False``) may instead be used, as long as nothing under a true mask overflows."""
    good = _good(name, spec)
    a = np.asarray(spec.args[arg], dtype=float)
    core = spec.arrays[arg]
    batch = a.shape[: a.ndim - core]
    core_size = int(np.prod(a.shape[a.ndim - core :], dtype=int))
    res = _call(name, spec, args)
    mask = _mask_of(spec, res)
    gmask = _mask_of(spec, good)
    assert mask.shape == batch, (
        f"spec of {name}: masked argument {arg} must have the batch shape {mask.shape} of the result "
        f"mask, it has {batch}"
    )
    sample = flat_index // core_size
    if must_mask:
        assert not mask.reshape(-1)[sample], f"{name}: non-finite {arg} at sample {sample} is not masked"
    _check_finite_where_valid(name, spec, res)
    keep = np.ones(mask.size, dtype=bool)
    keep[sample] = False
    assert np.array_equal(mask.reshape(-1)[keep], gmask.reshape(-1)[keep]), (
        f"{name}: a bad {arg} sample changed the mask of good samples"
    )
    good_arrays = dict(_arrays_of(good))
    for label, v in _arrays_of(res):
        g = good_arrays.get(label)
        if g is None or v.shape != g.shape or v.shape[: mask.ndim] != mask.shape:
            continue
        vv = v.reshape(mask.size, -1)[keep].astype(float)
        gg = g.reshape(mask.size, -1)[keep].astype(float)
        assert np.allclose(vv, gg, rtol=SAME_RTOL, atol=SAME_ATOL, equal_nan=True), (
            f"{name}: a bad {arg} sample changed {label} of good samples"
        )


def _check_nan_row(name: str, spec: Spec, arg: str, args: dict[str, Any], flat_index: int) -> None:
    """A NaN at one sample of a ``nan_rows`` argument: that sample is non-finite (NaN, or inf for a
    residual) / False in every result array of the argument's batch shape, the other samples are
    those of the good call."""
    good = _good(name, spec)
    a = np.asarray(spec.args[arg], dtype=float)
    core = spec.arrays[arg]
    batch = a.shape[: a.ndim - core]
    sample = flat_index // int(np.prod(a.shape[a.ndim - core :], dtype=int))
    res = _call(name, spec, args)
    good_arrays = dict(_arrays_of(good))
    n = int(np.prod(batch, dtype=int))
    seen = 0
    for label, v in _arrays_of(res):
        g = good_arrays.get(label)
        if g is None or v.shape != g.shape or v.shape[: len(batch)] != batch or v.size == 0:
            continue
        seen += 1
        rows, grows = v.reshape(n, -1), g.reshape(n, -1)
        failed = ~np.isfinite(rows[sample]) if v.dtype.kind == "f" else ~rows[sample].astype(bool)
        if v.dtype.kind in "fb":
            assert np.all(failed), f"{name}: a NaN {arg} sample {sample} gives a non-NaN / True {label}"
        keep = np.arange(n) != sample
        assert np.allclose(
            rows[keep].astype(float),
            grows[keep].astype(float),
            rtol=SAME_RTOL,
            atol=SAME_ATOL,
            equal_nan=True,
        ), f"{name}: a NaN {arg} sample changed {label} of good samples"
    assert seen, f"spec of {name}: no result array has the batch shape {batch} of {arg}"


def _variants(name: str, spec: Spec, arg: str) -> list[tuple[str, Any]]:
    a = np.array(spec.args[arg], dtype=float)
    out = []
    for label, val in (("nan", np.nan), ("inf", np.inf), ("-inf", -np.inf), ("1e300", 1e300)):
        b = a.copy()
        b.flat[0] = val
        out.append((label, b))
    c = a.astype(complex)
    c.flat[0] += 1j
    out.append(("complex", c))
    core = spec.arrays[arg]
    if arg not in spec.wrong_shapes and core >= 1 and a.ndim >= 1:
        out.append(("shape+1", np.concatenate([a, a[..., :1]], axis=-1)))
    for shape in spec.wrong_shapes.get(arg, ()):
        out.append((f"shape{shape}", np.full(shape, 0.1)))
    out.append(("str", "abc"))
    if not _default_is_none(name, spec, arg):
        out.append(("None", None))
    out.append(("bool", np.ones(a.shape, dtype=bool)))
    return out


def _cases():
    arrays, params, options = [], [], []
    for name, spec in sorted(ACTIVE.items()):
        marks = [pytest.mark.slow] if spec.slow else []
        for arg in spec.arrays:
            for label, _ in _variants(name, spec, arg):
                arrays.append(pytest.param(name, arg, label, marks=marks, id=f"{name}-{arg}-{label}"))
        for arg in spec.params:
            for label in ("None", "str", "object"):
                if label == "None" and _default_is_none(name, spec, arg):
                    continue
                params.append(pytest.param(name, arg, label, marks=marks, id=f"{name}-{arg}-{label}"))
        for opt, bad in spec.options.items():
            for i, v in enumerate(bad):
                options.append(pytest.param(name, opt, i, marks=marks, id=f"{name}-{opt}-{v!r}"))
    return arrays, params, options


ARRAY_CASES, PARAM_CASES, OPTION_CASES = _cases()


# --- coverage -------------------------------------------------------------------------------------
def test_every_public_name_has_a_spec():
    missing = [n for n in sorted(PUBLIC) if n not in SPECS]
    assert not missing, "public names without a bad-input spec (see tests/contract/README.md):\n" + "\n".join(
        f"  {n}  -> add it to tests/{spec_file_for(n)}" for n in missing
    )


def test_no_spec_for_a_name_that_is_not_public():
    stale = [f"{n} (in {WHERE[n]})" for n in sorted(SPECS) if n not in PUBLIC]
    assert not stale, "specs for names that are not in any public __all__:\n  " + "\n  ".join(stale)


# --- the good call --------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "name", [pytest.param(n, marks=[pytest.mark.slow] if s.slow else []) for n, s in sorted(ACTIVE.items())]
)
def test_good_call(name):
    spec = ACTIVE[name]
    if spec.good_elsewhere:
        pytest.skip(f"the good call takes minutes: it runs in {spec.good_elsewhere}")
    res = _good(name, spec)
    if spec.mask is not None:
        assert _mask_of(spec, res).any(), f"spec of {name}: the good call should have valid samples"
    _check_finite_where_valid(name, spec, res)


# --- bad arrays -----------------------------------------------------------------------------------
@pytest.mark.parametrize(("name", "arg", "variant"), ARRAY_CASES)
def test_bad_array(name, arg, variant):
    spec = ACTIVE[name]
    value = dict(_variants(name, spec, arg))[variant]
    args = {**spec.args, arg: value}
    if arg in spec.masked and variant in ("nan", "inf", "-inf", "1e300"):
        _check_masked(name, spec, arg, args, 0, must_mask=variant != "1e300")
    elif arg in spec.nan_rows and variant == "nan":
        _check_nan_row(name, spec, arg, args, 0)
    else:
        _expect_value_error(name, spec, args, arg, variant)


@pytest.mark.parametrize(
    ("name", "arg"),
    [
        pytest.param(n, a, marks=[pytest.mark.slow] if s.slow else [], id=f"{n}-{a}")
        for n, s in sorted(ACTIVE.items())
        for a in s.arrays
        if np.size(s.args[a]) > 1
    ],
)
def test_bad_element_anywhere(name, arg):
    """Hypothesis: a non-finite or overflowing (1e300) value at any element of any array argument."""
    spec = ACTIVE[name]
    a = np.array(spec.args[arg], dtype=float)

    @settings(max_examples=4, deadline=None, database=None)
    @given(k=st.integers(0, a.size - 1), v=st.sampled_from([np.nan, np.inf, -np.inf, 1e300, -1e300]))
    def check(k, v):
        b = a.copy()
        b.flat[k] = v
        args = {**spec.args, arg: b}
        if arg in spec.masked:
            _check_masked(name, spec, arg, args, k, must_mask=not np.isfinite(v))
        elif arg in spec.nan_rows and np.isnan(v):
            _check_nan_row(name, spec, arg, args, k)
        else:
            _expect_value_error(name, spec, args, arg, f"non-finite at flat index {k}")

    check()


@pytest.mark.parametrize(
    "name",
    [
        pytest.param(n, marks=[pytest.mark.slow] if s.slow else [])
        for n, s in sorted(ACTIVE.items())
        if s.arrays
        and s.empty_batch
        and not s.good_elsewhere
        and all(np.ndim(s.args[a]) > core for a, core in s.arrays.items())
    ],
)
def test_empty_batch(name):
    """A batch of zero samples is a batch: empty results, no exception."""
    spec = ACTIVE[name]
    args = {**spec.args, **{a: np.asarray(spec.args[a], dtype=float)[:0] for a in spec.arrays}}
    res = _call(name, spec, args)
    if spec.mask is not None:
        assert _mask_of(spec, res).size == 0, f"{name}: an empty batch gave a non-empty mask"


def _dataclass_specs():
    out = []
    for n, s in sorted(ACTIVE.items()):
        target = _target(n, s)
        if inspect.isclass(target) and dataclasses.is_dataclass(target):
            out.append(n)
    return out


@pytest.mark.parametrize("name", _dataclass_specs())
def test_dataclass_fields_are_stored_as_plain_numbers(name):
    """A parameter dataclass stores validated Python floats/ints, whatever real type it was given
    (``SphericalLeg(R=np.float32(0.075)).R`` is a float), so equality and hashing see values."""
    spec = ACTIVE[name]
    numeric = {
        k: (np.int64(v) if isinstance(v, int) else np.float32(v))
        for k, v in spec.args.items()
        if isinstance(v, int | float) and not isinstance(v, bool)
    }
    obj = _call(name, spec, {**spec.args, **numeric})
    for k in numeric:
        v = getattr(obj, k)
        assert type(v) in (float, int), f"{name}.{k} stored as {type(v).__name__}, expected a plain float/int"


# --- parameter objects and options ----------------------------------------------------------------
class _Foreign:
    """A parameter object of the wrong kind (think: another mechanism's parameters)."""


@pytest.mark.parametrize(("name", "arg", "variant"), PARAM_CASES)
def test_bad_parameter_object(name, arg, variant):
    spec = ACTIVE[name]
    value = {"None": None, "str": "params", "object": _Foreign()}[variant]
    _expect_value_error(name, spec, {**spec.args, arg: value}, arg, variant)


@pytest.mark.parametrize(("name", "opt", "index"), OPTION_CASES)
def test_bad_option(name, opt, index):
    spec = ACTIVE[name]
    value = spec.options[opt][index]
    _expect_value_error(name, spec, {**spec.args, opt: value}, opt, repr(value))


# --- batches of several arguments -----------------------------------------------------------------
# docs/conventions.md: leading axes are batch axes and broadcast together (NumPy rules).  Arguments
# whose batch shapes do not broadcast must be refused at the boundary naming them and their shapes
# (``_validation.broadcast_batch``), never by a bare NumPy "operands could not be broadcast" from
# inside a kernel.  Batch lengths of the mismatch: the argument under test gets 2, the others 3.
MISMATCH_LENGTHS = (2, 3)


def _names(msg: str, arg: str) -> bool:
    return re.search(rf"(?<![\w]){re.escape(arg)}(?![\w])", msg) is not None


def _batch_shape(value: Any, core: int) -> tuple[int, ...]:
    shape = np.shape(value)
    return tuple(shape[: len(shape) - core])


def _with_last_batch_length(value: Any, core: int, n: int) -> np.ndarray:
    """``value`` with its last batch axis (the one next to its core) resampled to length ``n``: samples
    0, 1, 2, ... of the good call, cyclically, so every sample stays a valid input (a time series
    stays increasing when it is long enough)."""
    a = np.asarray(value)
    axis = a.ndim - core - 1
    return np.take(a, np.arange(n) % a.shape[axis], axis=axis)


def test_every_array_of_a_multi_array_spec_is_batched_or_declared_unbatched():
    """The information the mismatch test needs: in a spec with two or more array arguments, each one
    either has a batch in the good call or is declared ``unbatched`` (a new spec cannot skip it)."""
    bad = []
    for n, s in sorted(ACTIVE.items()):
        if len(s.arrays) < 2:
            continue
        for a in s.arrays:
            batch = _batch_shape(s.args[a], s.core(a))
            if a in s.unbatched and batch:
                bad.append(f"{n}: {a} is listed in unbatched but has the batch {batch} in args ({WHERE[n]})")
            elif a not in s.unbatched and not batch:
                bad.append(
                    f"{n}: give {a} a leading batch axis in args or list it in unbatched= ({WHERE[n]})"
                )
    head = "array arguments without batch information (tests/contract/README.md):\n  "
    assert not bad, head + "\n  ".join(bad)


@pytest.mark.parametrize(
    ("name", "arg"),
    [
        pytest.param(n, a, marks=[pytest.mark.slow] if s.slow else [], id=f"{n}-{a}")
        for n, s in sorted(ACTIVE.items())
        if len(s.batched()) >= 2
        for a in s.batched()
    ],
)
def test_batches_that_do_not_broadcast(name, arg):
    """``arg`` with a batch of 2 samples, every other batched argument with 3: a ValueError naming
    ``arg``, another of the arguments and ``arg``'s shape."""
    _check_mismatch(name, ACTIVE[name], arg)


def _check_mismatch(name: str, spec: Spec, arg: str) -> None:
    mine, theirs = MISMATCH_LENGTHS
    args = dict(spec.args)
    for a in spec.batched():
        args[a] = _with_last_batch_length(spec.args[a], spec.core(a), mine if a == arg else theirs)
    with pytest.raises(ValueError) as info:
        _call(name, spec, args)
    msg = str(info.value)
    shape = np.shape(args[arg])
    shapes = {shape[:k] for k in range(1, len(shape) + 1)}  # its shape, or its batch part by any core
    what = f"{name}({arg} {np.shape(args[arg])} beside batches of {theirs})"
    assert _names(msg, arg), f"{what}: the ValueError must name {arg!r}; got: {msg}"
    assert "xpected" in msg, f"{what}: say what was expected and what was got; got: {msg}"
    assert any(_names(msg, a) for a in spec.batched() if a != arg), (
        f"{what}: the ValueError must also name the argument(s) {arg} does not broadcast with; got: {msg}"
    )
    assert any(str(s) in msg for s in shapes), f"{what}: the ValueError must give {arg}'s shape; got: {msg}"


@pytest.mark.parametrize(
    ("name", "arg"),
    [
        pytest.param(n, a, marks=[pytest.mark.slow] if s.slow else [], id=f"{n}-{a}")
        for n, s in sorted(ACTIVE.items())
        if not s.good_elsewhere
        for a in s.arrays
    ],
)
def test_an_extra_batch_axis(name, arg):
    """One argument with an extra axis of 2 just before its core (``q (3, 2)`` -> ``(3, 2, 2)``): a
    bigger batch, which the call either broadcasts (it returns) or refuses with a ValueError naming
    the argument - never another exception (a bare NumPy broadcasting error from inside a kernel)."""
    _check_extra_axis(name, ACTIVE[name], arg)


def _check_extra_axis(name: str, spec: Spec, arg: str) -> None:
    a = np.asarray(spec.args[arg])
    b = np.stack([a, a], axis=a.ndim - spec.core(arg))
    try:
        _call(name, spec, {**spec.args, arg: b}, GOOD_CALL_SECONDS)
    except ValueError as exc:
        msg = str(exc)
        assert _names(msg, arg), f"{name}({arg} {b.shape}): the ValueError must name {arg!r}; got: {msg}"
        assert "xpected" in msg, f"{name}({arg} {b.shape}): say what was expected and got; got: {msg}"
    except Exception as exc:  # any other exception is the defect under test
        pytest.fail(
            f"{name}({arg} {b.shape}): expected a result or a ValueError naming {arg!r}, "
            f"got {type(exc).__name__}: {exc}"
        )


# The two checks above are not passed by accident: a function that leaves the mismatch to NumPy
# fails them, the same function with the boundary check passes.
def _unchecked(q, qd):
    return np.asarray(q, dtype=float) * np.asarray(qd, dtype=float)


def _checked(q, qd):
    from robomech._validation import as_array, broadcast_batch

    q, qd = as_array(q, "q", (3,)), as_array(qd, "qd", (3,))
    broadcast_batch((q, 1, "q"), (qd, 1, "qd"))
    return q * qd


_Q3 = np.arange(9.0).reshape(3, 3)


@pytest.mark.parametrize("arg", ["q", "qd"])
def test_the_batch_checks_fail_a_function_that_leaves_the_mismatch_to_numpy(arg):
    spec = Spec(args={"q": _Q3, "qd": _Q3[::-1]}, arrays={"q": 1, "qd": 1}, call=_unchecked)
    with pytest.raises(AssertionError, match="must name"):
        _check_mismatch("unchecked", spec, arg)
    with pytest.raises(AssertionError, match="must name"):  # NumPy's ValueError names no argument
        _check_extra_axis("unchecked", spec, arg)
    checked = Spec(args=spec.args, arrays=spec.arrays, call=_checked)
    _check_mismatch("checked", checked, arg)
    _check_extra_axis("checked", checked, arg)
