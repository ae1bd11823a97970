"""``robomech verify``: every model against an independent engine or higher-fidelity model."""

from __future__ import annotations

import argparse
import contextlib
import sys

from robomech._progress import show_bars

from ._core import (
    EXIT_CHECK_FAILED,
    EXIT_OK,
    CliError,
    Command,
    announce_compiles,
    did_you_mean,
    input_file,
    looks_like_file,
    output_folder,
)


def _description() -> str:
    from robomech._registry import skip_reason
    from robomech.verify import available_verifications

    lines = ["Check the models against an independent engine; exit 1 if a check fails.", "", "mechanisms:"]
    for n, v in available_verifications().items():
        why = skip_reason(v.requires)
        lines.append(f"  {n:<18} {v.title}" + (f" [skipped: {why}]" if why else ""))
    return "\n".join(lines)


def _add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "mechanisms", nargs="*", metavar="MECHANISM", help="mechanisms, MJCF or URDF files (default: all)"
    )
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.add_argument(
        "--out",
        default=None,
        metavar="DIR",
        help="also save the checks to DIR/verification.json (the report index shows them) and the results "
        "a study also shows to DIR/verification-results/ (robomech reproduce --out DIR reads them)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    p.add_argument(
        "--duration",
        type=float,
        default=None,
        metavar="S",
        help="passive forward simulation of an MJCF / gallery mechanism: length (s, default 0.3, at most 10)",
    )
    p.add_argument(
        "--q0",
        type=float,
        nargs="+",
        default=None,
        metavar="Q",
        help="start configuration of that simulation (MuJoCo qpos, nq numbers; default: the trajectory's)",
    )
    p.add_argument(
        "--engine",
        choices=("mujoco", "pinocchio"),
        default="mujoco",
        help="the independent engine of the generic checks (pinocchio: gallery names, the rigid paper "
        "descriptions and MJCF/URDF files, against robomech[pinocchio])",
    )
    p.add_argument(
        "--qd0",
        type=float,
        nargs="+",
        default=None,
        metavar="QD",
        help="start rates of the actuated joints for that simulation (n_act numbers; default 0 with --q0)",
    )
    p.add_argument(
        "--qvel0",
        type=float,
        nargs="+",
        default=None,
        metavar="V",
        help="instead of --qd0: every coordinate's start rate (MuJoCo qvel, nv numbers), for passive, "
        "underactuated and floating-base mechanisms",
    )


def _run_pinocchio(args: argparse.Namespace, out) -> int:
    """``--engine pinocchio``: the generic checks of every target against Pinocchio."""
    import importlib.util
    from pathlib import Path

    from robomech.verify import VerificationReport, dumps_json
    from robomech.verify._generic import describe
    from robomech.verify._pinocchio_engine import check_mechanism_pinocchio

    if importlib.util.find_spec("pinocchio") is None:
        raise CliError("--engine pinocchio needs Pinocchio: install robomech[pinocchio]")
    if not args.mechanisms:
        raise CliError("--engine pinocchio needs a mechanism: a gallery name, a paper description or a file")
    report = VerificationReport()
    for t in args.mechanisms:
        if looks_like_file(t):
            input_file(t)
        try:
            mech = describe(t)
        except (ValueError, OSError) as exc:
            raise CliError(str(exc)) from exc
        label = Path(t).stem if t.endswith((".xml", ".urdf")) else t
        report.checks.extend(check_mechanism_pinocchio(mech, label))
    if out is not None:
        (out / "verify-pinocchio.json").write_text(dumps_json(report.as_dict()), encoding="utf-8")
    print(dumps_json(report.as_dict()) if args.json else report.table())
    return EXIT_OK if report.passed else EXIT_CHECK_FAILED


def _run(args: argparse.Namespace) -> int:
    from robomech._registry import skip_reason
    from robomech.verify import VerificationReport, available_verifications, dumps_json
    from robomech.verify._generic import run_generic, split_targets
    from robomech.verify._store import recording

    out = output_folder(args.out) if args.out is not None else None
    available = available_verifications()
    # MJCF paths and gallery / description names get the generic engine checks
    names, generic = split_targets(args.mechanisms, available)
    for n in [*names, *generic]:  # a file that is missing or malformed: say so in one line
        if n not in available and looks_like_file(n):
            input_file(n)
    unknown = [n for n in names if n not in available]
    if unknown:
        from robomech import multibody as mb

        hint = did_you_mean(unknown[0], [*available, *mb.gallery.NAMES])
        raise CliError(
            f"unknown mechanism {', '.join(map(repr, unknown))}{hint}; valid ones are: {', '.join(available)}"
            ", a gallery mechanism or an MJCF or URDF file"
        )
    for n in names:  # asked for by name: not running it is an error, not a skip
        why = skip_reason(available[n].requires)
        if why:
            raise CliError(f"{n} cannot run here: {why}")
    if args.engine == "pinocchio":
        return _run_pinocchio(args, out)
    announce_compiles(enabled=not args.quiet)
    show_bars(not args.quiet)  # stage bars on a terminal (robomech._progress)
    report = VerificationReport()
    sim = {
        k: v
        for k, v in (("duration", args.duration), ("q0", args.q0), ("qd_act0", args.qd0), ("qd0", args.qvel0))
        if v is not None
    }
    for flag, rates in (("--qd0", args.qd0), ("--qvel0", args.qvel0)):
        if rates is not None and args.q0 is None:
            raise CliError(f"{flag} needs --q0 (the start configuration the rates belong to)")
    if sim and not generic:
        flag = {"qd_act0": "qd0", "qd0": "qvel0"}.get(next(iter(sim)), next(iter(sim)))
        raise CliError(f"--{flag} applies to MJCF files and gallery mechanisms only")
    try:
        report.checks.extend(run_generic(generic, **sim))
    except ValueError as exc:
        raise CliError(str(exc)) from exc
    # with --out, the results a study also shows are recorded for `robomech reproduce --out` to read
    with recording(out) if out is not None else contextlib.nullcontext():
        for n in names or ([] if generic else list(available)):
            v = available[n]
            why = skip_reason(v.requires)
            if why:
                report.skipped.append((n, why))
                if not args.quiet:
                    print(f"verify: {n} skipped — {why}", file=sys.stderr, flush=True)
                continue
            if not args.quiet:
                print(f"verify: {n} — {v.title} ...", file=sys.stderr, flush=True)
            report.checks.extend(v.run())
    if out is not None:
        from robomech.studies import available_studies, write_index
        from robomech.studies._report import write_verification

        write_verification(out, report.as_dict())
        write_index(out, available_studies())
    print(dumps_json(report.as_dict()) if args.json else report.table())
    return EXIT_OK if report.passed else EXIT_CHECK_FAILED


COMMAND = Command(
    name="verify",
    help="check models against an independent engine; exit 1 on a failed check",
    add_arguments=_add_arguments,
    run=_run,
    description=_description,
)
