"""``robomech list``: the registered studies and verifications, and which need an extra."""

from __future__ import annotations

import argparse

from ._core import EXIT_OK, Command


def _add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="print JSON instead of text")


def _run(args: argparse.Namespace) -> int:
    from robomech._registry import skip_reason
    from robomech.studies import available_studies
    from robomech.verify import available_verifications, dumps_json

    studies = available_studies()
    verifications = available_verifications()
    if args.json:
        print(
            dumps_json(
                {
                    "studies": [
                        {"name": n, "title": s.title, "source": s.source, "skipped": skip_reason(s.requires)}
                        for n, s in studies.items()
                    ],
                    "verifications": [
                        {"name": n, "title": v.title, "engine": v.engine, "skipped": skip_reason(v.requires)}
                        for n, v in verifications.items()
                    ],
                }
            )
        )
        return EXIT_OK
    print("studies (robomech reproduce NAME):")
    for name, study in studies.items():
        why = skip_reason(study.requires)
        print(f"  {name:<20} {study.title}" + (f"  [skipped: {why}]" if why else ""))
    print("verifications (robomech verify NAME):")
    for name, v in verifications.items():
        why = skip_reason(v.requires)
        print(f"  {name:<20} {v.title} [{v.engine}]" + (f"  [skipped: {why}]" if why else ""))
    return EXIT_OK


COMMAND = Command(
    name="list",
    help="list the registered studies and verifications",
    add_arguments=_add_arguments,
    run=_run,
)
