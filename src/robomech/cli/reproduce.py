"""``robomech reproduce``: regenerate the papers' tables and figures as reports."""

from __future__ import annotations

import argparse
import sys

from ._core import EXIT_OK, CliError, Command, announce_compiles, did_you_mean, output_folder


def _description() -> str:
    from robomech._registry import skip_reason
    from robomech.studies import available_studies

    lines = [
        "Regenerate papers' tables and figures as reports in OUT/<study>/ (report.md, report.html,",
        "results.json, figures) and rebuild OUT/index.md and OUT/index.html.",
        "",
        "studies:",
    ]
    for n, s in available_studies().items():
        why = skip_reason(s.requires)
        lines.append(f"  {n:<18} {s.title}" + (f" [skipped: {why}]" if why else ""))
    return "\n".join(lines)


def _add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("studies", nargs="*", metavar="STUDY", help="studies to run (default: all)")
    p.add_argument("--out", default="out", metavar="DIR", help="output folder (default: out)")
    p.add_argument("--json", action="store_true", help="print a JSON summary instead of text")
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")


def _run(args: argparse.Namespace) -> int:
    from robomech._progress import show_bars
    from robomech._registry import skip_reason
    from robomech.studies import Progress, available_studies, write_index
    from robomech.studies._report import publish_study, remove_stale_temporaries
    from robomech.verify import dumps_json

    studies = available_studies()
    unknown = [n for n in args.studies if n not in studies]
    if unknown:
        raise CliError(
            f"unknown study {', '.join(map(repr, unknown))}{did_you_mean(unknown[0], list(studies))}; "
            f"valid studies are: {', '.join(studies)}"
        )
    for n in args.studies:  # asked for by name: not running it is an error, not a skip
        why = skip_reason(studies[n].requires)
        if why:
            raise CliError(f"{n} cannot run here: {why}")
    out_root = output_folder(args.out)
    remove_stale_temporaries(out_root)
    announce_compiles(enabled=not args.quiet)
    show_bars(not args.quiet)  # a bar per study on a terminal, the step lines above it
    summary, skipped = [], []
    try:
        for name in args.studies or list(studies):
            study = studies[name]
            why = skip_reason(study.requires)
            if why:
                skipped.append((name, why))
                if not args.quiet:
                    print(f"{name}: skipped — {why}", file=sys.stderr, flush=True)
                continue
            with Progress(prefix=f"{name}: ", enabled=not args.quiet) as progress:
                progress.log(f"start — {study.title}")
                entry = publish_study(study, out_root, progress)
                progress.log(f"done in {entry['seconds']:.1f} s → {entry['report']}")
            summary.append(entry)
    finally:  # also on Ctrl-C: the index lists exactly the complete study folders that exist now
        index = write_index(out_root, studies, skipped)
    if args.json:
        print(
            dumps_json(
                {
                    "index": index,
                    "studies": summary,
                    "skipped": [{"study": n, "reason": r} for n, r in skipped],
                }
            )
        )
    else:
        for n, r in skipped:
            print(f"skipped: {n} — {r}")
        print(f"report index: {index} (and {index.with_suffix('.html')})")
    return EXIT_OK


COMMAND = Command(
    name="reproduce",
    help="regenerate papers' tables and figures as reports",
    add_arguments=_add_arguments,
    run=_run,
    description=_description,
)
