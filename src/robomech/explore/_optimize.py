"""Multi-objective optimisation with pymoo's NSGA-II, each population evaluated as Dask chunks.

The store holds every evaluated individual: generation g's population is rows ``[g P, (g + 1) P)`` (P the
population size) and one store chunk; its Dask tasks are the study's usual chunks of designs.  pymoo is
seeded, and evaluation is deterministic, so a rerun proposes the same populations: a rerun into the same
store takes every generation already stored from the store (checked row by row) and computes only the
rest.  Designs the parameter dataclass rejects, or with a non-finite objective, are infeasible (pymoo
constraint ``G = 1``).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from robomech._validation import check_int

from ._pareto import objective_matrix
from ._runner import (
    CONNECT_TIMEOUT,
    SweepSummary,
    _Bar,
    _existing,
    check_client,
    check_runtime,
    check_writable,
    dask_client,
    evaluate_chunk,
    resume_flags,
    robomech_version,
    sweep_fingerprint,
)
from ._store import chunk_checksum, open_store, prepare_store, store_array
from ._study import DesignStudy, Variable, check_variables, with_variables

__all__ = ["optimize_nsga2"]

# A generation's population is split into this many Dask tasks (at most; at least one design each).
NSGA2_TASKS_PER_GENERATION = 8


def optimize_nsga2(
    study: DesignStudy,
    out: Path | str,
    *,
    population: int | None = None,
    generations: int = 10,
    seed: int = 0,
    variables: Sequence[Variable] = (),
    scheduler: str | None = None,
    workers: int | None = None,
    client: Any = None,
    progress: bool = True,
    connect_timeout: float = CONNECT_TIMEOUT,
) -> SweepSummary:
    """NSGA-II over the study's range variables and objectives; all evaluations stored under ``out``.

    Generation g's population is rows ``[g P, (g + 1) P)`` of the store (module docstring); a rerun into
    the same store reuses every generation already stored.  Pareto-optimal designs:
    ``pareto_front(open_results(out), study.objectives)``.

    Parameters
    ----------
    study : DesignStudy
        A study with objectives and only range variables.
    out : str or pathlib.Path
        Directory of the Zarr store (created if absent).
    population : int, optional
        Population size P (>= 4; default 32).
    generations : int, optional
        Number of generations (>= 1; default 10).
    seed : int, optional
        pymoo's seed and the chunks' (>= 0; default 0).
    variables : sequence of Variable, optional
        Overrides or additions to the study's variables (:func:`with_variables`).
    scheduler : str, optional
        Address ``tcp://HOST:PORT`` of an existing Dask scheduler; None (default): a LocalCluster.
    workers : int, optional
        Worker processes of the LocalCluster (>= 1; default one per core).
    client : distributed.Client, optional
        An existing client to use instead (not closed).
    progress : bool, optional
        Print a progress line on stderr (default True).
    connect_timeout : float, optional
        Seconds to wait for ``scheduler`` (> 0).

    Returns
    -------
    SweepSummary
        One chunk per generation: the generations computed and those taken from the store.

    Raises
    ------
    ValueError
        If an argument is of the wrong type or out of range, or the study has no objectives or a
        normal (tolerance) variable.
    StoreMismatch
        If ``out`` holds something other than this optimisation's store.
    SchedulerUnreachable
        If ``scheduler`` is malformed or does not answer.
    """
    if not isinstance(study, DesignStudy):
        raise ValueError(f"Expected study to be a DesignStudy, got {type(study).__name__}.")
    variables = check_variables(variables)
    P = 32 if population is None else check_int(population, "population", low=4)
    G = check_int(generations, "generations", low=1)
    seed = check_int(seed, "seed", low=0)
    out = check_runtime(out, scheduler, workers, progress, connect_timeout)
    study = with_variables(study, variables) if variables else study
    if not study.objectives or any(v.kind != "range" for v in study.variables):
        raise ValueError(
            f"Expected a study with objectives and range variables for NSGA-II, got {study.name!r} "
            "(a tolerance study has neither: sample it)."
        )
    P = int(population or 32)
    G = int(generations)
    if P < 4 or G < 1:
        raise ValueError(
            f"Expected population >= 4 and generations >= 1, got {population!r}, {generations!r}."
        )
    if isinstance(seed, bool) or int(seed) != seed or seed < 0:
        raise ValueError(f"Expected seed to be a non-negative integer, got {seed!r}.")
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.core.problem import Problem
    from pymoo.optimize import minimize

    fp = {**sweep_fingerprint(study, P * G, "nsga2", int(seed), P), "population": P, "generations": G}
    info = {**study.describe(), "robomech_version": robomech_version(), "method": "nsga2"}
    prepare = (Path(out), study, None, P, fp, info, P * G)
    client = check_client(client)
    g = open_store(Path(out), fp, None)  # raises StoreMismatch before anything is written
    if g is None:
        check_writable(Path(out))  # before a cluster is started
    else:
        flags = resume_flags(g, Path(out), progress)  # damaged generations are recomputed
        store_array(g, "chunk_done")[...] = flags
    xl = np.array([v.low for v in study.variables])
    xu = np.array([v.high for v in study.variables])
    bar = _Bar(f"{study.name} (NSGA-II)", P * G, progress)
    computed: list[int] = []
    gen = [0]
    # Dask tasks per generation: a fixed split (never the worker count: chunk seeds must not depend on it)
    sub = max(1, min(study.default_chunk, -(-P // NSGA2_TASKS_PER_GENERATION)))

    def evaluate(X: np.ndarray, c) -> dict[str, np.ndarray]:
        g = store[0]
        k = gen[0]
        gen[0] += 1
        if X.shape[0] > P:  # pymoo's NSGA-II proposes n_offsprings = pop_size rows per generation
            raise RuntimeError(f"NSGA-II proposed {X.shape[0]} rows, more than the population {P}")
        rows = slice(k * P, k * P + X.shape[0])
        if bool(store_array(g, "chunk_done")[k]) and np.array_equal(
            np.asarray(store_array(g, "designs")[rows]), X
        ):
            res = {
                name: np.asarray(store_array(g, name)[rows])
                for name in ["design_ok", *(m.name for m in study.metrics)]
            }
        else:
            futures = [
                c.submit(evaluate_chunk, study, X[i : i + sub], int(seed), k * P + i, pure=False, retries=2)
                for i in range(0, X.shape[0], sub)
            ]
            parts = [f.result()[1] for f in futures]  # in order: deterministic regardless of workers
            res = {name: np.concatenate([p[name] for p in parts]) for name in parts[0]}
            store_array(g, "designs")[rows] = X
            names = ["design_ok", *(m.name for m in study.metrics)]
            for name in names:
                store_array(g, name)[rows] = res[name]
            if "chunk_checksum" in g:
                full = slice(k * P, (k + 1) * P)  # the stored chunk, as verify_store reads it
                back = {name: np.asarray(store_array(g, name)[full]) for name in names}
                store_array(g, "chunk_checksum")[k] = chunk_checksum(back, names)
            store_array(g, "chunk_done")[k] = True
            computed.append(k)
        bar.update(X.shape[0])
        return res

    class _Problem(Problem):
        def __init__(self, c) -> None:
            super().__init__(n_var=len(xl), n_obj=len(study.objectives), n_ieq_constr=1, xl=xl, xu=xu)
            self.c = c

        def _evaluate(self, X, out, *args, **kwargs):
            res = evaluate(np.asarray(X, dtype=float), self.c)
            F, ok = objective_matrix(res, study.objectives)
            out["F"] = np.where(ok[:, None], F, 0.0)
            out["G"] = np.where(ok, -1.0, 1.0)[:, None]

    import time

    t0 = time.perf_counter()
    ctx = _existing(client) if client is not None else dask_client(scheduler, workers, connect_timeout)
    with ctx as c:
        store = [g if g is not None else prepare_store(*prepare)]
        n_workers = len(c.scheduler_info().get("workers", {}))
        minimize(_Problem(c), NSGA2(pop_size=P), ("n_gen", G), seed=int(seed), verbose=False)
    bar.close()
    return SweepSummary(
        study.name,
        str(out),
        P * G,
        G,
        tuple(computed),
        G - len(computed),
        time.perf_counter() - t0,
        n_workers,
        len(computed) * P,
    )
