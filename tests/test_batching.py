"""``robomech._batching``: a chunked evaluation equals the whole-batch evaluation bit for bit; a failed
sample (a NaN row) is filled, the other samples are those of the batch without it."""

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from robomech._batching import carries_failed_rows, chunked, chunked_rows, on_rows, slices
from robomech._validation import as_array


@dataclass(frozen=True)
class _Pair:
    a: np.ndarray
    b: np.ndarray


class _Tup(NamedTuple):
    a: np.ndarray
    b: np.ndarray


X = np.random.default_rng(0).normal(size=(23, 3))


def _pair(s: slice) -> _Pair:
    return _Pair(np.sin(X[s]), (X[s, 0] > 0))


@pytest.mark.parametrize("chunk", [1, 5, 23, 100])
@pytest.mark.parametrize("batch", [(24,), (4, 6), (2, 3, 4), (0, 2)])
def test_chunked_rows_gives_the_whole_batch_result_back_in_the_input_batch_shape(chunk, batch):
    x = np.random.default_rng(1).normal(size=(*batch, 3))
    got = chunked_rows(lambda r: _Pair(np.cross(r, [0.0, 0.0, 1.0]), r[:, 0] > 0), x, chunk)
    assert isinstance(got, _Pair) and got.a.shape == (*batch, 3) and got.b.shape == batch
    np.testing.assert_array_equal(got.a, np.cross(x, [0.0, 0.0, 1.0]))
    np.testing.assert_array_equal(got.b, x[..., 0] > 0)


@given(n=st.integers(0, 23), chunk=st.integers(1, 30))
def test_slices_cover_the_batch_once_in_order(n, chunk):
    covered = [i for s in slices(n, chunk) for i in range(n)[s]]
    assert covered == list(range(n))
    assert all(s.stop - s.start <= chunk for s in slices(n, chunk))


@pytest.mark.parametrize("chunk", [1, 4, 7, 23, 100])
def test_array_tuple_dataclass_results_equal_the_whole_batch(chunk):
    whole = _pair(slice(0, 23))
    got = chunked(_pair, 23, chunk)
    assert isinstance(got, _Pair)
    np.testing.assert_array_equal(got.a, whole.a)
    np.testing.assert_array_equal(got.b, whole.b)
    assert got.b.dtype == bool
    tup = chunked(lambda s: _Tup(X[s] * 2, X[s, :1]), 23, chunk)
    assert isinstance(tup, _Tup) and tup.a.shape == (23, 3) and tup.b.shape == (23, 1)
    np.testing.assert_array_equal(tup.a, X * 2)
    plain = chunked(lambda s: (X[s], X[s].sum(1)), 23, chunk)
    assert isinstance(plain, tuple)
    np.testing.assert_array_equal(plain[1], X.sum(1))
    np.testing.assert_array_equal(chunked(lambda s: X[s] ** 2, 23, chunk), X**2)


def test_in_place_kernels_are_called_once_per_chunk():
    out = np.zeros(23)
    calls = []

    def fill(s):
        calls.append(s)
        out[s] = X[s, 1]

    assert chunked(fill, 23, 5) is None
    np.testing.assert_array_equal(out, X[:, 1])
    assert len(calls) == 5


def test_empty_batch_calls_the_kernel_once_with_an_empty_slice():
    got = chunked(lambda s: X[s] + 1, 0, 8)
    assert got.shape == (0, 3)


# --- failed samples: on_rows, carries_failed_rows ------------------------------------------------


def _stats(x: np.ndarray) -> _Pair:
    """A per-sample result: float (..., 3), bool (...)."""
    return _Pair(np.sin(x), x[..., 0] > 0)


@given(st.lists(st.booleans(), min_size=1, max_size=12))
def test_on_rows_fills_failed_samples_and_keeps_the_others_bit_identical(failed):
    failed = np.array(failed)
    x = X[: failed.size]
    out = on_rows(failed, _stats, x)
    alone = _stats(x[~failed])
    assert np.isnan(out.a[failed]).all() and not out.b[failed].any()
    assert np.array_equal(out.a[~failed], alone.a) and np.array_equal(out.b[~failed], alone.b)


def test_on_rows_keeps_batch_shapes_ints_and_unbatched_arrays():
    x = X[:6].reshape(2, 3, 3)
    failed = np.array([[False, True, False], [False, False, True]])
    const = np.eye(4)[:, :3]  # (4, 3), fixed: its leading length is that of the 4 computed samples

    def fn(r):
        return (np.cos(r), np.full(r.shape[0], 7), const)

    cos, ints, c = on_rows(failed, fn, x)
    assert cos.shape == (2, 3, 3) and np.isnan(cos[failed]).all()
    assert ints.tolist() == [[7, 0, 7], [7, 7, 0]] and c is const
    every = on_rows(np.ones(4, bool), fn, X[:4])  # no sample left: shapes from the empty batch
    assert every[0].shape == (4, 3) and np.isnan(every[0]).all()


def test_on_rows_with_a_probe_where_every_sample_failed():
    out = on_rows(np.ones(2, bool), lambda r: (r[:, :1] * 2,), X[:2], probe=(X[:1],))
    assert out[0].shape == (2, 1) and np.isnan(out[0]).all()


@carries_failed_rows({"q": 1}, {"w": 1})
def _decorated(q, w, *, scale=1.0):
    q = as_array(q, "q", (3,))  # the strict boundary of the function itself
    return _Pair(scale * q + w, q[..., 0] > 0)


def test_carries_failed_rows_masks_a_nan_row_and_still_refuses_wrong_inputs():
    q = X[:4].copy()
    q[2, 1] = np.nan
    r = _decorated(q, np.ones(3), scale=2.0)
    good = _decorated(q[[0, 1, 3]], np.ones(3), scale=2.0)
    assert np.isnan(r.a[2]).all() and not r.b[2]
    assert np.array_equal(r.a[[0, 1, 3]], good.a)
    assert np.array_equal(_decorated(X[:4], 0.0).a, X[:4])  # no NaN: the function itself
    for bad in (np.inf, -1e300):
        q[0, 0] = bad
        with pytest.raises(ValueError, match="Expected q finite"):
            _decorated(q, np.ones(3))
    with pytest.raises(ValueError, match="q"):
        _decorated(np.full((2, 4), np.nan), np.ones(3))  # wrong shape with NaN: still refused
    with pytest.raises(ValueError, match="w"):
        _decorated(np.full((2, 3), np.nan), np.ones((3, 3)))  # batches that do not broadcast
    w = np.ones((4, 3))
    w[2, 0] = np.inf  # at the failed sample: dropped from the call, still refused
    q[0, 0] = 0.0
    with pytest.raises(ValueError, match="Expected w to be finite"):
        _decorated(q, w)


def test_control_without_the_decorator_a_nan_row_raises():
    with pytest.raises(ValueError, match="q"):
        _decorated.__wrapped__(np.full((2, 3), np.nan), np.ones(3))
