"""The ``robomech`` command: ``list``, ``reproduce`` and ``verify``."""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Sequence
from pathlib import Path

__all__ = ["main"]


def _cmd_list(args: argparse.Namespace) -> int:
    from robomech.studies import available_studies
    from robomech.verify import available_verifications

    print("studies (robomech reproduce NAME):")
    for name, study in available_studies().items():
        print(f"  {name:<20} {study.title}")
    print("verifications (robomech verify NAME):")
    for name, v in available_verifications().items():
        print(f"  {name:<20} {v.title} [{v.engine}]")
    return 0


def _cmd_reproduce(args: argparse.Namespace) -> int:
    from robomech.studies import Progress, available_studies, write_index, write_study_report

    studies = available_studies()
    names = args.studies or list(studies)
    unknown = [n for n in names if n not in studies]
    if unknown:
        print(
            f"robomech: unknown study {', '.join(map(repr, unknown))}; "
            f"valid studies are: {', '.join(studies)}",
            file=sys.stderr,
        )
        return 2
    out_root = Path(args.out)
    out_root.mkdir(parents=True, exist_ok=True)
    entries = []
    summary = []
    for name in names:
        study = studies[name]
        progress = Progress(prefix=f"{name}: ", enabled=not args.quiet)
        progress.step(f"start — {study.title}")
        t0 = time.perf_counter()
        result = study.run(out_root / name, progress)
        seconds = time.perf_counter() - t0
        paths = write_study_report(result, out_root / name)
        progress.step(f"done in {seconds:.1f} s → {paths['md']}")
        entries.append((result, seconds))
        summary.append(
            {"study": name, "seconds": seconds, "report": str(paths["md"]), "json": str(paths["json"])}
        )
    index = write_index(out_root, entries)
    if args.json:
        print(json.dumps({"index": str(index), "studies": summary}, indent=2))
    else:
        print(f"report index: {index} (and {index.with_suffix('.html')})")
    return 0


def _cmd_verify(args: argparse.Namespace) -> int:
    from robomech.verify import available_verifications, run_verifications

    available = available_verifications()
    unknown = [n for n in args.mechanisms if n not in available]
    if unknown:
        print(
            f"robomech: unknown mechanism {', '.join(map(repr, unknown))}; "
            f"valid ones are: {', '.join(available)}",
            file=sys.stderr,
        )
        return 2
    report = run_verifications(args.mechanisms)
    if args.json:
        print(json.dumps({"passed": report.passed, "checks": [c.as_dict() for c in report.checks]}, indent=2))
    else:
        print(report.table())
    return 0 if report.passed else 1


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="robomech", description="Kinematics, dynamics and verification of robot mechanisms."
    )
    sub = p.add_subparsers(dest="command", required=True)

    sp = sub.add_parser("list", help="list the registered studies and verifications")
    sp.set_defaults(func=_cmd_list)

    sp = sub.add_parser("reproduce", help="regenerate papers' tables and figures as reports")
    sp.add_argument("studies", nargs="*", metavar="STUDY", help="studies to run (default: all)")
    sp.add_argument("--out", default="out", help="output folder (default: out)")
    sp.add_argument("--json", action="store_true", help="print a JSON summary instead of text")
    sp.add_argument("--quiet", action="store_true", help="no progress lines")
    sp.set_defaults(func=_cmd_reproduce)

    sp = sub.add_parser("verify", help="check models against an independent engine; non-zero exit on failure")
    sp.add_argument("mechanisms", nargs="*", metavar="MECHANISM", help="mechanisms to verify (default: all)")
    sp.add_argument("--json", action="store_true", help="print JSON instead of a table")
    sp.set_defaults(func=_cmd_verify)

    from ._sweep import register as register_sweep  # robomech.explore: docs/explore.md

    register_sweep(sub)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
