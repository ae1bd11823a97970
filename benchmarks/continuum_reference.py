"""Tables of the continuum references recorded in ``docs/mechanisms/continuum_cosserat.md``.

Not a timed benchmark (``run.py`` collects ``bench_*.py`` only): the Cosserat solves are expensive
(~1-3 minutes on one core), so the tables are generated here once and recorded in the docs, while the
tests solve a few cases of each.  Run: ``PYTHONPATH=src python benchmarks/continuum_reference.py``.
"""

from __future__ import annotations

import os

# one BLAS thread: the solves are many small dense systems, and on a shared machine a multi-threaded
# BLAS spends most of its time waiting (measured: a 2-segment disk solve 52 s -> 12 s)
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

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
        segments = tuple(int(a[5:]) for a in which if a.startswith("disks") and a[5:].isdigit()) or (1, 2, 3)
        rows = []
        for n in sorted(segments):  # row by row, printed as they finish (the whole table takes long)
            for t in V.CONVERGENCE_PRETENSIONS_N:
                table = V.disk_agreement_table((n,), (t,))
                rows.append(table)
                conv, err = (part.splitlines()[-1] for part in table.markdown().split("\n\n"))
                print("conv", conv, "\nerr ", err, f"\n  {time.perf_counter() - t0:.0f} s", flush=True)
        valid = np.concatenate([r.valid.ravel() for r in rows])
        for name in ("chord_error", "arc_error", "elongation_error", "diskwise_error"):
            vals = np.concatenate([getattr(r, name).ravel() for r in rows])[valid]
            vals = vals[np.isfinite(vals)]
            if vals.size:
                print(
                    f"{name}: {vals.size} cases, min {vals.min():.3g}, "
                    f"median {np.median(vals):.3g}, max {vals.max():.3g}"
                )
        conv = np.concatenate([r.converged.ravel() for r in rows])
        taut = np.concatenate([r.taut.ravel() for r in rows])
        print(f"{int(conv.sum())}/{conv.size} converged, {int(taut.sum())} taut, {int(valid.sum())} compared")
    if "cosserat" in which:  # the disk reference with many disks vs the continuous-tendon rod
        import dataclasses
        import math

        from robomech.mechanisms.continuum import ContinuumRobot, cable_tensions
        from robomech.verify._cosserat import solve_static
        from robomech.verify._disk_rod import solve_disk_robot

        cases = (
            (1, 10.0, 90.0, (5, 10, 20, 40)),
            (1, 15.0, 60.0, (5, 10, 20, 40)),
            (2, 10.0, 45.0, (5, 10, 20)),
            (3, 5.0, 30.0, (5, 10)),
        )
        for n, t0, bend, disks in cases:
            rob = ContinuumRobot(n_segments=n, friction=(0.0,) * (3 * n), pretension=t0)
            psi = np.zeros(2 * n)
            psi[0::2], psi[1::2] = math.radians(bend), V.CONVERGENCE_PLANES[:n]
            t = cable_tensions(rob, psi, model="arc")
            cos = solve_static(V.rod_for(rob), t.tension)
            gaps = []
            for nd in disks:
                ref = V.disk_robot_for(dataclasses.replace(rob, disks_per_segment=nd))
                sol = solve_disk_robot(ref, tension=t.tension)
                gap = 1e3 * np.linalg.norm(sol.T_tip[:3, 3] - cos.T_tip[:3, 3])
                gaps.append(f"N={nd}: {gap:.3f} mm" + ("" if sol.converged else " (not converged)"))
            print(f"{n} segments, {t0:g} N, {bend:g}°: " + "; ".join(gaps), flush=True)
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
