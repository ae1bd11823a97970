"""``benchmarks/run.py`` formats its table: ratios below 1 keep their significant digits."""

import importlib.util
from pathlib import Path

RUN = Path(__file__).resolve().parent.parent / "benchmarks" / "run.py"


def _run_module():
    spec = importlib.util.spec_from_file_location("bench_run", RUN)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_ratio_below_one_is_not_printed_as_zero():
    ratio = _run_module()._ratio
    assert ratio(1 / 3, 7, 0).strip() == "0.33x"  # bench_dynamics / bench_omnileg: target_speedup=1/3
    assert ratio(0.05, 8, 1).strip() == "0.05x"
    assert ratio(250.0, 7, 0).strip() == "250x"
    assert ratio(12.34, 8, 1).strip() == "12.3x"
    assert ratio(None, 7, 0).strip() == "—"
    assert len(ratio(1 / 3, 7, 0)) == 7
