"""Same samples, same result at any batch size: every spec's good call, its batched arrays tiled to
1, 255, 256, 257 and 1000 samples, gives sample 0 the result of the batch of one (``SAME_RTOL``).

Batch sizes straddle the thresholds where implementations switch (numpy below a size, compiled or
parallel kernels above it, chunked loops at 256).  A control shows the rule fails a function whose
result depends on the batch it is in.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pytest
from contract_spec import Spec
from test_contract import ACTIVE, _target

SIZES = (1, 255, 256, 257, 1000)
# Results agree to a few ulps of reassociation (the same tolerance as the mixed-batch rule).
SAME_RTOL = 1e-12
# Specs whose leading array axis is no batch of independent samples (said why), so the rule does
# not apply; each is checked by its own tests.
NOT_A_BATCH = {
    "robomech.analysis.workspace.grid": "the arrays are axes of a grid, not samples",
    "robomech.mechanisms.continuum.simulate_history": "the leading axis is time (a history)",
    "robomech.mechanisms.continuum.identify_friction_from_tip": "one fit over all samples",
    "robomech.mechanisms.skid_steer.planar_ekf": "the leading axis is time (a filter run)",
    "robomech.mechanisms.skid_steer.imu_measurements": (
        "a noise generator: the readings of a time series are successive draws of one stream"
    ),
    "robomech.multibody.animate": "the leading axis is time (frames of one animation)",
}


def _arrays(res: Any) -> dict[str, np.ndarray]:
    if isinstance(res, np.ndarray):
        return {"": res}
    if dataclasses.is_dataclass(res):
        return {
            f.name: v for f in dataclasses.fields(res) if isinstance(v := getattr(res, f.name), np.ndarray)
        }
    if isinstance(res, tuple):
        return {str(i): v for i, v in enumerate(res) if isinstance(v, np.ndarray)}
    return {}


def _tiled(spec: Spec, n: int) -> dict[str, Any] | None:
    """The good call with every batched array cut/tiled to n samples along its leading axis."""
    batched = spec.batched()
    first = np.asarray(spec.args[batched[0]])
    nb = first.shape[0]
    args = dict(spec.args)
    for a in batched:
        v = np.asarray(spec.args[a])
        if v.ndim <= spec.core(a) or v.shape[0] != nb:
            return None
        args[a] = v[np.arange(n) % nb]
    return args


def check_batch_sizes(name: str, spec: Spec, call=None) -> None:
    call = call or _target(name, spec)
    base = None
    for n in SIZES:
        args = _tiled(spec, n)
        if args is None:
            pytest.skip("the batched arrays do not share a leading batch")
        res = _arrays(call(**args))
        if base is None:
            base = res
            continue
        for k, ref in base.items():
            v = res.get(k)
            if v is None or v.ndim == 0 or ref.ndim == 0 or v.shape[0] != n or v.shape[1:] != ref.shape[1:]:
                continue  # not a per-sample field
            x, y = v[:1], ref[:1]
            if x.dtype == bool or y.dtype == bool:
                assert np.array_equal(x, y), f"{name}: {k} of sample 0 differs at batch {n}"
                continue
            np.testing.assert_allclose(
                np.asarray(x, float), np.asarray(y, float), rtol=SAME_RTOL, atol=SAME_RTOL,
                err_msg=f"{name}: {k or 'result'} of sample 0 at batch {n} vs batch 1",
            )  # fmt: skip


def _cases():
    out = []
    for name, spec in sorted(ACTIVE.items()):
        if spec.slow or spec.good_elsewhere or name in NOT_A_BATCH or not spec.batched():
            continue
        first = np.asarray(spec.args[spec.batched()[0]])
        if first.ndim <= spec.core(spec.batched()[0]):
            continue
        out.append(pytest.param(name, id=name))
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name", _cases())
def test_same_samples_same_result_at_any_batch_size(name):
    check_batch_sizes(name, ACTIVE[name])


def test_every_not_a_batch_exemption_names_a_spec():
    assert set(NOT_A_BATCH) <= set(ACTIVE), set(NOT_A_BATCH) - set(ACTIVE)


def _depends_on_batch(x):
    """A function whose sample 0 depends on the batch: it subtracts the batch mean."""
    x = np.asarray(x, float)
    return x - x.mean(axis=0)


def test_control_the_rule_fails_a_function_whose_result_depends_on_its_batch():
    spec = Spec(args={"x": np.array([[1.0, 2.0], [3.0, 5.0]])}, arrays={"x": 1}, call=_depends_on_batch)
    with pytest.raises(AssertionError, match="sample 0 at batch"):
        check_batch_sizes("control", spec, _depends_on_batch)
    check_batch_sizes("control", spec, lambda x: 2.0 * np.asarray(x))  # a per-sample function passes
