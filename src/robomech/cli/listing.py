"""``robomech list``: the registered studies, verifications and design studies, and which need an extra."""

from __future__ import annotations

import argparse

from ._core import EXIT_OK, Command
from .sweep import SWEEP_REQUIRES


def _add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="print JSON instead of text")


def _run(args: argparse.Namespace) -> int:
    from robomech._registry import skip_reason
    from robomech.explore import available_studies as available_design_studies
    from robomech.studies import available_studies
    from robomech.verify import available_verifications, dumps_json

    studies = available_studies()
    verifications = available_verifications()
    design_studies = available_design_studies()  # imports no distributed stack (test_architecture)
    sweep_skip = skip_reason(SWEEP_REQUIRES)
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
                    "design_studies": [
                        {"name": n, "title": d.title, "mechanism": d.mechanism, "skipped": sweep_skip}
                        for n, d in design_studies.items()
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
    print("design studies (robomech sweep NAME --out DIR):")
    for name, d in design_studies.items():
        print(f"  {name:<26} {d.title}" + (f"  [skipped: {sweep_skip}]" if sweep_skip else ""))
    return EXIT_OK


COMMAND = Command(
    name="list",
    help="list the registered studies, verifications and design studies",
    add_arguments=_add_arguments,
    run=_run,
)
