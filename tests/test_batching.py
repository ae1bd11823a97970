"""``robomech._batching.chunked``: a chunked evaluation equals the whole-batch evaluation bit for bit."""

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from robomech._batching import chunked, slices


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
