"""Contract rules for four more classes of bad input, each with a control that shows it can fail.

- **zero-width cores**: an array argument whose core (non-batch) axes have length 0 (a Jacobian
  ``(3, 0)``, a system ``A (5, 0)``, a history of 0 twists) is either a result or a ``ValueError``
  naming the argument -- never an ``IndexError`` or a reshape error from inside a kernel;
- **one argument batched beside single samples**: in a spec of several batched arrays, one array with
  its batch (also an empty one) beside single samples of the others (core shape only) broadcasts to
  that batch -- the result's mask has the batch shape -- or is refused naming an argument, never a
  bare NumPy error from a kernel that stacks per-argument slices;
- **parameter dataclass fields**: every field of a parameter dataclass given None, a str or a
  foreign object raises a ``ValueError`` naming the field (not a ``TypeError`` from ``len(None)``);
- **a mask is a flag, not the finiteness of a value**: a spec with masked arguments names a result
  field (or a function of flags), not ``np.isfinite`` of the values -- a NaN value with no flag is
  the unmasked propagation the contract forbids.
"""

from __future__ import annotations

import dataclasses
import inspect

import numpy as np
import pytest
from contract_spec import Spec
from test_contract import ACTIVE, GOOD_CALL_SECONDS, _call, _mask_of, _names, _target

# --- zero-width cores -----------------------------------------------------------------------------


def _zero_width_cases():
    out = []
    for name, spec in sorted(ACTIVE.items()):
        if spec.good_elsewhere:
            continue
        for arg, core in spec.arrays.items():
            a = np.asarray(spec.args[arg])
            for k in range(1, min(core, 2) + 1):  # the last and the second-to-last core axis
                if a.ndim >= k and a.shape[-k] > 0:
                    marks = [pytest.mark.slow] if spec.slow else []
                    out.append(pytest.param(name, arg, k, marks=marks, id=f"{name}-{arg}-axis-{k}"))
    return out


def _check_zero_width(name: str, spec: Spec, arg: str, k: int) -> None:
    a = np.asarray(spec.args[arg], dtype=float)
    cut = np.take(a, np.arange(0), axis=a.ndim - k)
    try:
        _call(name, spec, {**spec.args, arg: cut})
    except ValueError as exc:  # the cut may make another argument disagree with it: naming either is right
        assert any(_names(str(exc), o) for o in (*spec.arrays, *spec.params)), (
            f"{name}({arg} {cut.shape}): the ValueError must name an argument; got: {exc}"
        )
    except Exception as exc:  # any other exception is the defect under test
        pytest.fail(
            f"{name}({arg} {cut.shape}): expected a result or a ValueError, got {type(exc).__name__}: {exc}"
        )


@pytest.mark.parametrize(("name", "arg", "k"), _zero_width_cases())
def test_a_zero_width_core_is_a_result_or_a_value_error(name, arg, k):
    _check_zero_width(name, ACTIVE[name], arg, k)


def _indexes_the_first_column(J):
    J = np.asarray(J, dtype=float)
    return J[..., 0] / np.linalg.norm(J, axis=(-2, -1))[..., None]


def _checks_the_columns(J):
    from robomech._validation import as_array

    return _indexes_the_first_column(as_array(J, "J", (None, None), nonempty=True))


def test_the_zero_width_rule_fails_a_kernel_that_indexes_an_empty_axis():
    spec = Spec(args={"J": np.ones((2, 3, 2))}, arrays={"J": 2}, call=_indexes_the_first_column)
    with pytest.raises(pytest.fail.Exception, match="IndexError"):
        _check_zero_width("unchecked", spec, "J", 1)
    _check_zero_width("checked", Spec(args=spec.args, arrays=spec.arrays, call=_checks_the_columns), "J", 1)


# --- one argument batched beside single samples ---------------------------------------------------


def _single_beside_batch_cases():
    out = []
    for name, spec in sorted(ACTIVE.items()):
        batched = [a for a in spec.batched() if np.ndim(spec.args[a]) > spec.core(a)]
        if len(batched) < 2 or spec.good_elsewhere:
            continue
        marks = [pytest.mark.slow] if spec.slow else []
        for arg in batched:
            for n in (2, 0):
                out.append(pytest.param(name, arg, n, marks=marks, id=f"{name}-{arg}-batch-{n}"))
    return out


def _check_single_beside_batch(name: str, spec: Spec, arg: str, n: int) -> None:
    args = dict(spec.args)
    for other in spec.batched():
        a = np.asarray(args[other], dtype=float)
        core = spec.core(other)
        if other == arg:
            flat = a.reshape(-1, *a.shape[a.ndim - core :])
            args[other] = np.concatenate([flat[:1]] * n, axis=0) if n else flat[:0]
        elif a.ndim > core:
            args[other] = a.reshape(-1, *a.shape[a.ndim - core :])[0]  # one sample, core shape only
    try:
        res = _call(name, spec, args, GOOD_CALL_SECONDS)  # a valid call (it may compile a kernel)
    except ValueError as exc:
        assert any(_names(str(exc), o) for o in spec.arrays), (
            f"{name}({arg} batch {n} beside single samples): the ValueError must name an argument; got: {exc}"
        )
        return
    except Exception as exc:
        pytest.fail(
            f"{name}({arg} batch {n} beside single samples): expected a result or a ValueError, got "
            f"{type(exc).__name__}: {exc}"
        )
    if spec.mask is not None:
        m = _mask_of(spec, res)
        assert m.shape[:1] == (n,), (
            f"{name}: {arg} with a batch of {n} beside single samples gave a mask {m.shape}"
        )


@pytest.mark.parametrize(("name", "arg", "n"), _single_beside_batch_cases())
def test_one_batched_argument_beside_single_samples(name, arg, n):
    _check_single_beside_batch(name, ACTIVE[name], arg, n)


def _stacks_slices(q, qd):
    from robomech._validation import as_array, broadcast_batch

    q, qd = as_array(q, "q", (3,)), as_array(qd, "qd", (3,))
    broadcast_batch((q, 1, "q"), (qd, 1, "qd"))
    return np.stack([q[..., 0], qd[..., 0]], axis=-1)  # shapes (2,) and () do not stack


def _broadcasts_first(q, qd):
    from robomech._validation import broadcast_to_batch

    q, qd = broadcast_to_batch((np.asarray(q, float), 1, "q"), (np.asarray(qd, float), 1, "qd"))
    return np.stack([q[..., 0], qd[..., 0]], axis=-1)


def test_the_single_sample_rule_fails_a_kernel_that_stacks_unbroadcast_slices():
    q = np.arange(9.0).reshape(3, 3)
    spec = Spec(args={"q": q, "qd": q[::-1]}, arrays={"q": 1, "qd": 1}, call=_stacks_slices)
    with pytest.raises(AssertionError, match="must name an argument"):  # NumPy's stack error names none
        _check_single_beside_batch("unchecked", spec, "q", 2)
    fixed = Spec(args=spec.args, arrays=spec.arrays, call=_broadcasts_first)
    _check_single_beside_batch("checked", fixed, "q", 2)
    _check_single_beside_batch("checked", fixed, "q", 0)


# --- parameter dataclass fields -------------------------------------------------------------------


# Annotations of a text field (``from __future__ import annotations`` keeps them as strings).
TEXT_TYPES = ("str", str, "str | None", "Optional[str]")


class _Foreign:
    """Something that is no field value of any parameter dataclass."""


def _field_cases():
    out = []
    for name, spec in sorted(ACTIVE.items()):
        target = _target(name, spec)
        if not (inspect.isclass(target) and dataclasses.is_dataclass(target)):
            continue
        for f in dataclasses.fields(target):
            if not f.init:
                continue
            for label in ("None", "str", "object"):
                if label == "None" and f.default is None:
                    continue
                if label == "str" and (f.type in TEXT_TYPES or isinstance(f.default, str)):
                    continue  # a text field (a name, optional or not) takes any str
                marks = [pytest.mark.slow] if spec.slow else []
                case = f"{name}-{f.name}-{label}"
                out.append(pytest.param(name, f.name, label, marks=marks, id=case))
    return out


def _check_field(name: str, spec: Spec, fname: str, label: str) -> None:
    value = {"None": None, "str": "abc", "object": _Foreign()}[label]
    try:
        obj = _call(name, spec, {**spec.args, fname: value})
    except ValueError as exc:
        assert _names(str(exc), fname), (
            f"{name}({fname}={label}): the ValueError must name {fname!r}; got: {exc}"
        )
        return
    except Exception as exc:
        pytest.fail(
            f"{name}({fname}={label}): expected a ValueError naming it, got {type(exc).__name__}: {exc}"
        )
    # None may stand for the documented default (OmniLeg(bodies=None): no overrides)
    if label == "None" and obj == _call(name, spec, {k: v for k, v in spec.args.items() if k != fname}):
        return
    pytest.fail(f"{name}({fname}={label}): accepted")


@pytest.mark.parametrize(("name", "fname", "label"), _field_cases())
def test_every_dataclass_field_refuses_none_a_str_and_a_foreign_object(name, fname, label):
    _check_field(name, ACTIVE[name], fname, label)


@dataclasses.dataclass(frozen=True)
class _Unchecked:
    bodies: tuple = ((1.0,), (2.0,))

    def __post_init__(self):
        if len(self.bodies) != 2:  # len(None) is a TypeError, not a ValueError naming the field
            raise ValueError(f"Expected bodies to have 2 entries, got {self.bodies!r}.")


@dataclasses.dataclass(frozen=True)
class _Checked(_Unchecked):
    def __post_init__(self):
        if not isinstance(self.bodies, tuple) or len(self.bodies) != 2:
            raise ValueError(f"Expected bodies to be a tuple of 2 entries, got {self.bodies!r}.")


def test_the_field_rule_fails_a_dataclass_that_trusts_its_field_type():
    with pytest.raises(pytest.fail.Exception, match="TypeError"):
        _check_field("unchecked", Spec(args={}, call=_Unchecked), "bodies", "None")
    for label in ("None", "str", "object"):
        _check_field("checked", Spec(args={}, call=_Checked), "bodies", label)


# --- a mask is a flag -----------------------------------------------------------------------------


def _mask_from_values(spec: Spec) -> bool:
    """True when the spec's mask is the finiteness of result values rather than a flag."""
    if spec.mask is np.isfinite:
        return True
    if callable(spec.mask):
        try:
            src = inspect.getsource(spec.mask)
        except (OSError, TypeError):
            return False
        return "isfinite" in src
    return False


# Functions that return a bare array, as their peers do (MuJoCo mj_rne / mj_fullM, Pinocchio rnea / crba),
# and have no physical failure (the tree's inverse dynamics and mass matrix exist at every configuration):
# a failed sample from an earlier call (a NaN row) gives a NaN row there and nowhere else, which the
# generic mask check of test_contract.py verifies; there is no flag to compute.
BARE_ARRAY_RESULTS = {"robomech.multibody.generalized_forces", "robomech.multibody.mass_matrix"}


@pytest.mark.parametrize(
    "name", sorted(n for n, s in ACTIVE.items() if s.masked and n not in BARE_ARRAY_RESULTS)
)
def test_a_masked_argument_is_flagged_by_a_result_field(name):
    assert not _mask_from_values(ACTIVE[name]), (
        f"{name}: its mask is the finiteness of its values; a non-finite input sample must be flagged by "
        "a mask field of the result (valid / ok / singular), not left as an unflagged NaN"
    )


def test_the_mask_rule_fails_a_spec_that_reads_nan_as_the_mask():
    assert _mask_from_values(Spec(args={"J": np.eye(2)}, arrays={"J": 2}, masked=("J",), mask=np.isfinite))
    assert _mask_from_values(
        Spec(args={"J": np.eye(2)}, arrays={"J": 2}, masked=("J",), mask=lambda r: np.isfinite(r[1]))
    )
    assert not _mask_from_values(Spec(args={"J": np.eye(2)}, arrays={"J": 2}, masked=("J",), mask="valid"))
