"""``_validation.broadcast_batch`` / ``broadcast_to_batch``: the boundary check of several batched arrays."""

import numpy as np
import pytest

from robomech._validation import broadcast_batch, broadcast_to_batch


def test_common_batch_shape_with_scalars_and_size_one_axes():
    q, qd, t = np.zeros((4, 1, 3)), np.zeros((5, 3)), np.zeros(())
    assert broadcast_batch((q, 1, "q"), (qd, 1, "qd"), (t, 0, "t")) == (4, 5)
    assert broadcast_batch((np.zeros((2, 6, 3)), 2, "J")) == (2,)


def test_mismatch_names_every_argument_with_its_core_and_batch_shape():
    with pytest.raises(ValueError) as info:
        broadcast_batch(
            (np.zeros((2, 3)), 1, "q"), (np.zeros((3, 3)), 1, "qd"), (np.zeros((3, 6, 3)), 2, "J")
        )
    assert str(info.value) == (
        "Expected q (..., 3), qd (..., 3) and J (..., 6, 3) with batch shapes (...) that broadcast together, "
        "got batch shapes q (2,), qd (3,), J (3,)."
    )


def test_fewer_axes_than_the_core_is_named():
    with pytest.raises(ValueError, match=r"Expected H to have at least 3 dimension\(s\), got shape \(6, 3\)"):
        broadcast_batch((np.zeros((6, 3)), 3, "H"), (np.zeros(3), 1, "qd"))


def test_broadcast_to_batch_keeps_each_core():
    q, w = np.arange(3.0), np.ones((2, 6))
    qb, wb = broadcast_to_batch((q, 1, "q"), (w, 1, "w"))
    assert qb.shape == (2, 3) and wb.shape == (2, 6)
    assert np.array_equal(qb[1], q)
    with pytest.raises(ValueError, match="q"):
        broadcast_to_batch((np.zeros((2, 3)), 1, "q"), (np.zeros((3, 6)), 1, "w"))
