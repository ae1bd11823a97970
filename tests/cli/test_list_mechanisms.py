"""`robomech list` names every mechanism the commands take by name, and `dir(robomech)` its subpackages."""

import json
import subprocess
import sys

from robomech import multibody as mb
from robomech.cli import main


def test_list_shows_the_gallery_and_the_paper_descriptions(capsys):
    assert main(["list", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    names = {m["name"]: m["source"] for m in data["mechanisms"]}
    assert {n: "gallery" for n in mb.gallery.NAMES}.items() <= names.items()
    assert {"spherical-leg", "omnileg", "vectored-thrust"} <= {n for n, s in names.items() if s == "paper"}
    assert data["design_studies"], "design studies are listed"
    assert main(["list"]) == 0
    text = capsys.readouterr().out
    section = text.split("\nmechanisms")[1]
    for name in mb.gallery.NAMES:
        assert f"  {name} " in section


def test_subpackages_are_listed_and_load_on_first_use():
    code = (
        "import sys, robomech as rm; d = dir(rm); "
        "assert 'robomech.explore' not in sys.modules; "
        "print(','.join(n for n in ('multibody', 'explore', 'viewer', 'studies', 'verify') if n in d)); "
        "print(rm.explore.__name__, rm.multibody.__name__, rm.viewer.__name__)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True
    )
    first, second = out.stdout.strip().splitlines()
    assert first == "multibody,explore,viewer,studies,verify"
    assert second == "robomech.explore robomech.multibody robomech.viewer"
