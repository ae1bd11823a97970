"""``robomech sweep STUDY --out DIR``: a design study on Dask into a Zarr store (robomech.explore)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

__all__ = ["register"]


def _variable(text: str):
    """``NAME=LO:HI`` (a range, SI units) or ``NAME=SIGMA`` (a manufacturing error's sigma)."""
    from robomech.explore import Variable

    name, sep, spec = text.partition("=")
    if not sep or not name:
        raise ValueError(f"Expected --var NAME=LO:HI or NAME=SIGMA, got {text!r}.")
    try:
        if ":" in spec:
            lo, hi = spec.split(":", 1)
            return Variable(name.strip(), float(lo), float(hi))
        return Variable(name.strip(), kind="normal", sigma=float(spec))
    except ValueError as exc:
        if "Expected" in str(exc):
            raise
        raise ValueError(f"Expected numbers in --var {text!r} (NAME=LO:HI or NAME=SIGMA).") from exc


def _box(text: str, what: str) -> list[list[float]]:
    """``LO:HI,LO:HI,...`` as ``[[lo, hi], ...]``."""
    try:
        out = []
        for part in text.split(","):
            lo, hi = part.split(":")
            out.append([float(lo), float(hi)])
        return out
    except ValueError as exc:
        raise ValueError(f"Expected {what} LO:HI[,LO:HI...] (numbers, SI units), got {text!r}.") from exc


def _model_study(args: argparse.Namespace):
    """The study of ``--model FILE.py:NAME`` (or a template file) with the command line's task and metrics."""
    from robomech.explore import load_model, model_study

    if args.study is not None:
        raise ValueError(f"Expected either STUDY or --model, got both ({args.study!r} and {args.model!r}).")
    if not args.site:
        raise ValueError("Expected --site NAME (the output site of the model) with --model, got none.")
    variables = [_variable(v) for v in args.var]
    kwargs: dict[str, list[list[float]]] = {}
    if args.task_box:
        kwargs["task_box"] = _box(args.task_box, "--task-box")
    if args.input_box:
        kwargs["input_box"] = _box(args.input_box, "--input-box")
    metrics = args.metric or ["workspace_measure", "task_fraction", "dexterity_min", "dexterity_mean"]
    objectives = []
    for o in args.objective:
        from robomech.explore import Objective

        name, _, sense = o.partition(":")
        objectives.append(Objective(name, sense or "max"))
    return model_study(
        load_model(args.model),
        variables,
        site=args.site,
        metrics=metrics,
        outputs=args.outputs,
        task_grid_size=args.task_grid,
        input_grid=args.input_grid,
        objectives=objectives,
        name=f"model:{args.model}",
        task_box=kwargs.get("task_box"),
        input_box=kwargs.get("input_box"),
    )


def _cmd_sweep(args: argparse.Namespace) -> int:
    from robomech.explore import get_study, run_sweep

    try:
        if args.model:
            study = _model_study(args)
            variables = []
        elif args.study is None:
            raise ValueError("Expected a STUDY name or --model FILE.py:NAME, got neither.")
        else:
            study = get_study(args.study)
            variables = [_variable(v) for v in args.var]
        if args.method == "nsga2":
            from robomech.explore import optimize_nsga2

            summary = optimize_nsga2(
                study,
                args.out,
                population=args.designs,
                generations=args.generations,
                seed=args.seed,
                variables=variables,
                scheduler=args.scheduler,
                workers=args.workers,
                progress=not args.quiet,
                connect_timeout=args.connect_timeout,
            )
        else:
            summary = run_sweep(
                study,
                args.out,
                designs=args.designs,
                seed=args.seed,
                sampler=args.sampler,
                chunk_size=args.chunk_size,
                variables=variables,
                scheduler=args.scheduler,
                workers=args.workers,
                progress=not args.quiet,
                connect_timeout=args.connect_timeout,
            )
    except ValueError as exc:  # unknown study, bad variable, foreign store, unreachable scheduler
        print(f"robomech sweep: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(
            f"\nrobomech sweep: interrupted; finished chunks are stored in {args.out}, "
            "rerun the same command to compute the rest",
            file=sys.stderr,
        )
        return 130
    result = summary.as_dict()
    if args.report:
        from robomech.studies._sweep import write_sweep_report

        result["report"] = str(write_sweep_report(Path(args.out), Path(args.out) / "report"))
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        print(
            f"{result['study']}: {result['n_designs']} designs in {result['n_chunks']} chunks "
            f"({result['computed_chunks']} computed, {result['skipped_chunks']} already stored) "
            f"in {result['seconds']:.1f} s -> {result['out']}"
            + (f"; report {result['report']}" if "report" in result else "")
        )
    return 0


def register(subparsers) -> None:
    """Add the ``sweep`` subcommand to the ``robomech`` parser's subparsers."""
    sp = subparsers.add_parser(
        "sweep",
        help="design study (synthesis / tolerances) on Dask into a Zarr store",
        description="Run or resume a design study; results are a Zarr group under --out (docs/explore.md). "
        "Studies: spherical-leg-synthesis, vectored-thrust-tolerance, omnileg-synthesis.",
    )
    sp.add_argument("study", metavar="STUDY", nargs="?", default=None, help="built-in design study name")
    sp.add_argument(
        "--model",
        default=None,
        metavar="FILE.py:NAME|FILE.xml",
        help="a study of your own mechanism: build(**params) -> Mechanism, or an MJCF/URDF template",
    )
    sp.add_argument("--site", default=None, help="--model: the output site")
    sp.add_argument("--outputs", default="xy", help="--model: output axes of the task (default xy)")
    sp.add_argument("--task-box", default=None, metavar="LO:HI,LO:HI", help="--model: task box (m)")
    sp.add_argument("--task-grid", type=int, default=32, help="--model: task cells per axis (default 32)")
    sp.add_argument("--input-box", default=None, metavar="LO:HI,LO:HI", help="--model: actuator box")
    sp.add_argument("--input-grid", type=int, default=8, help="--model: actuator grid per axis (default 8)")
    sp.add_argument("--metric", action="append", default=[], help="--model: a generic metric (repeatable)")
    sp.add_argument(
        "--objective", action="append", default=[], metavar="METRIC:max|min", help="--model: objective"
    )
    sp.add_argument(
        "--out", required=True, help="Zarr store directory (created, or resumed if it is this sweep's)"
    )
    sp.add_argument("--designs", type=int, default=None, help="number of designs (NSGA-II: population size)")
    sp.add_argument("--seed", type=int, default=0, help="seed of the sampler and of every chunk (default 0)")
    sp.add_argument("--scheduler", default=None, help="tcp://HOST:PORT of an existing Dask scheduler")
    sp.add_argument("--connect-timeout", type=float, default=10.0, help="seconds to reach --scheduler")
    sp.add_argument(
        "--workers", type=int, default=None, help="LocalCluster worker processes (default: cores)"
    )
    sp.add_argument("--sampler", default=None, choices=("sobol", "lhs", "grid", "random"))
    sp.add_argument("--chunk-size", type=int, default=None, help="designs per Dask task")
    sp.add_argument(
        "--var",
        action="append",
        default=[],
        metavar="NAME=LO:HI|NAME=SIGMA",
        help="override or add a design variable (SI units); repeatable",
    )
    sp.add_argument("--method", default="sample", choices=("sample", "nsga2"))
    sp.add_argument("--generations", type=int, default=10, help="NSGA-II generations (default 10)")
    sp.add_argument("--report", action="store_true", help="write PNGs and a report page under DIR/report")
    sp.add_argument("--json", action="store_true", help="print a JSON summary")
    sp.add_argument("--quiet", action="store_true", help="no progress bar")
    sp.set_defaults(func=_cmd_sweep)
