"""``robomech list``: the registered studies, verifications and design studies, and which need an
extra; and the described mechanisms that ``robomech view`` / ``export`` / ``verify`` take by name
(the gallery and the papers' multibody descriptions)."""

from __future__ import annotations

import argparse
import re

from ._core import EXIT_OK, Command
from .sweep import SWEEP_REQUIRES


def _add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="print JSON instead of text")


def _gallery() -> dict[str, str]:
    """Each gallery mechanism's title: the first sentence of its MJCF file's header comment (read as
    text: listing needs no MuJoCo)."""
    from robomech import multibody as mb

    out = {}
    for name in mb.gallery.NAMES:
        text = mb.gallery.path(name).read_text()
        m = re.search(r"<!--(.*?)-->", text, re.S)
        out[name] = _first_phrase(" ".join(m.group(1).split())) if m else name
    return out


def _first_phrase(text: str) -> str:
    """``text`` up to its first ``,``, ``;`` or ``.`` outside parentheses (a name, not the dimensions)."""
    depth = 0
    for i, c in enumerate(text):
        depth += (c == "(") - (c == ")")
        if depth == 0 and c in ",;." and (i + 1 == len(text) or text[i + 1] == " "):
            return text[:i]
    return text


def _described() -> dict[str, str]:
    """The paper mechanisms with a multibody description, by the name the commands take."""
    from robomech.studies import available_studies
    from robomech.verify._generic import _paper

    titles = {n.replace("_", "-"): s.title.split(" — ")[0] for n, s in available_studies().items()}
    return {n: f"{titles.get(n, n)} (its multibody description)" for n in _paper()}


def _run(args: argparse.Namespace) -> int:
    from robomech._registry import skip_reason
    from robomech.explore import available_studies as available_design_studies
    from robomech.studies import available_studies
    from robomech.verify import available_verifications, dumps_json

    studies = available_studies()
    verifications = available_verifications()
    design_studies = available_design_studies()  # imports no distributed stack (test_architecture)
    sweep_skip = skip_reason(SWEEP_REQUIRES)
    gallery = _gallery()
    described = _described()
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
                    "mechanisms": [
                        *({"name": n, "title": t, "source": "paper"} for n, t in described.items()),
                        *({"name": n, "title": t, "source": "gallery"} for n, t in gallery.items()),
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
    print("mechanisms (robomech view | export | verify NAME; also an MJCF file):")
    for name, title in described.items():
        print(f"  {name:<20} {title}")
    for name, title in gallery.items():
        print(f"  {name:<20} {title} [gallery]")
    return EXIT_OK


COMMAND = Command(
    name="list",
    help="list the studies, verifications, design studies and mechanisms (gallery, paper descriptions)",
    add_arguments=_add_arguments,
    run=_run,
)
