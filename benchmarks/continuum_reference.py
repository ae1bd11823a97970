"""Tables of the continuum references recorded in ``docs/mechanisms/continuum_cosserat.md``.

Not a timed benchmark (``run.py`` collects ``bench_*.py`` only): the Cosserat solves are expensive
(~1-3 minutes on one core), so the tables are generated here once and recorded in the docs, while the
tests solve a few cases of each.  Run: ``PYTHONPATH=src python benchmarks/continuum_reference.py``.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from robomech.verify import continuum as V


def main(argv: list[str]) -> None:
    which = set(argv) or {"convergence"}
    if "convergence" in which:
        t0 = time.perf_counter()
        table = V.convergence_table()
        print(table.markdown())
        print(
            f"\n{int(table.taut.sum())} taut cases, {int(table.converged.sum())} converged unloaded, "
            f"{int(table.loaded_converged.sum())} converged loaded; {time.perf_counter() - t0:.0f} s"
        )
    if "disks" in which:
        t0 = time.perf_counter()
        segments = (1, 2) if "disks2" in which else (1,)
        for n in segments:  # row by row, printed as they finish (the whole table takes long)
            for t in V.CONVERGENCE_PRETENSIONS_N:
                table = V.disk_agreement_table((n,), (t,))
                print(table.markdown().splitlines()[-1], flush=True)
                v = table.valid
                if v.any():
                    print(
                        f"  chord max {1e3 * np.nanmax(table.chord_error[v]):.2f} mm, arc max "
                        f"{1e3 * np.nanmax(table.arc_error[v]):.2f} mm, elongation max "
                        f"{1e6 * np.nanmax(table.elongation_error[v]):.1f} µm, "
                        f"{int(v.sum())}/{v.size} valid, "
                        f"{time.perf_counter() - t0:.0f} s",
                        flush=True,
                    )
    if "ident" in which:
        for estimator, stiff in (("pose", False), ("tip", False), ("tip", True), ("tip-eiv", False)):
            t0 = time.perf_counter()
            est, ok = V.identification_from_reference(estimator=estimator, fit_stiffness=stiff)
            print(f"{estimator} (stiffness fitted: {stiff}): estimate {est.mu}, std {est.std}")
            print(f"  95% CI low {est.ci_low}, high {est.ci_high}")
            print(
                f"  residual rms {est.residual_rms:.3g}, {int(ok.sum())}/{ok.size} reference solves "
                "converged, "
                f"{time.perf_counter() - t0:.0f} s",
                flush=True,
            )


if __name__ == "__main__":
    main(sys.argv[1:])
