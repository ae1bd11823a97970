"""``make bench``: time every workload of ``benchmarks/bench_*.py`` and print one table.

Usage: ``python benchmarks/run.py [--only SUBSTRING] [--json FILE]``.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import platform
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _harness import Workload, best_time, measure_floors  # noqa: E402


def _load_workloads(only: str | None) -> list[Workload]:
    out: list[Workload] = []
    for path in sorted(HERE.glob("bench_*.py")):
        spec = importlib.util.spec_from_file_location(path.stem, path)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        out.extend(w for w in mod.workloads() if only is None or only in w.name)
    return out


# Significant digits of a ratio below 1 (a target of 1/3 prints as 0.33x, not as 0x).
RATIO_SIGNIFICANT_BELOW_ONE = 2


def _ratio(value: float | None, width: int, digits: int) -> str:
    """A ratio as ``12.3x`` (``digits`` decimals; below 1 with ``RATIO_SIGNIFICANT_BELOW_ONE`` significant
    digits, ``0.33x``), or a dash where there is none, right-aligned in ``width``."""
    if value is None:
        text = "—"
    elif abs(value) < 1.0:
        text = f"{value:.{RATIO_SIGNIFICANT_BELOW_ONE}g}x"
    else:
        text = f"{value:.{digits}f}x"
    return text.rjust(width)


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--only", default=None)
    p.add_argument("--json", default=None)
    args = p.parse_args()
    floors = measure_floors()
    print(
        f"machine: {platform.processor() or platform.machine()}, numpy {np.__version__}, "
        f"python {platform.python_version()}"
    )
    print(
        f"floors: memory bandwidth {floors.bandwidth / 1e9:.1f} GB/s (copy, read+write), "
        f"matmul {floors.matmul_flops / 1e9:.1f} GFLOP/s (float64)"
    )
    header = (
        f"{'#':<2} {'workload':<52} {'n':>9} {'time':>9} {'per sample':>11} {'alternative':<28} "
        f"{'speedup':>8} {'target':>7} {'x floor':>8} {'target':>7}"
    )
    print(header)
    print("-" * len(header))
    rows = []
    for w in _load_workloads(args.only):
        t = best_time(w.run, w.repeats)
        speedup = None
        if w.alternative is not None and w.n_alt > 0:
            # best of the same number of repeats as the workload: one-shot timings swing by 30 %
            t_alt = best_time(w.alternative, w.repeats) * (w.n / w.n_alt)
            speedup = t_alt / t
        floor = w.bytes_moved / floors.bandwidth if w.bytes_moved else None
        x_floor = t / floor if floor else None
        rows.append(
            {
                "group": w.group,
                "name": w.name,
                "n": w.n,
                "seconds": t,
                "per_sample_s": t / w.n,
                "alternative": w.alternative_name,
                "speedup": speedup,
                "target_speedup": w.target_speedup,
                "x_floor": x_floor,
                "target_floor_ratio": w.target_floor_ratio,
            }
        )
        print(
            f"{w.group:<2} {w.name:<52} {w.n:>9} {t:>8.3f}s {t / w.n * 1e6:>9.3f}µs {w.alternative_name:<28} "
            f"{_ratio(speedup, 8, 1)} {_ratio(w.target_speedup, 7, 0)} {_ratio(x_floor, 8, 1)} "
            f"{_ratio(w.target_floor_ratio, 7, 0)}",
            flush=True,
        )
    if args.json:
        Path(args.json).write_text(json.dumps({"floors": floors.__dict__, "rows": rows}, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
