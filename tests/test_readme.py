"""The README a pip user follows: its library snippet runs and prints what the README says it prints,
and every link in it points inside the repository."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
# A fresh interpreter (the snippet must be self-contained); 300 s bounds a first-use numba compile.
TIMEOUT_S = 300


def _blocks_after(heading: str) -> tuple[str, str]:
    section = README.split(heading, 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    out = re.search(r"prints\n\n```text\n(.*?)```", section, re.S).group(1)
    return code, out


def test_library_snippet_runs_and_prints_what_the_readme_shows():
    code, expected = _blocks_after("## Library")
    r = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        env={**os.environ, "PYTHONPATH": str(ROOT / "src")},
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout == expected


def test_links_point_inside_the_repository():
    for target in re.findall(r"\]\(([^)#]+)\)", README):
        assert not target.startswith(("http", "..")), target
        assert (ROOT / target).exists(), f"README links to a missing file: {target}"


def test_install_lines_name_the_extras_that_exist():
    import tomllib

    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    for extra in re.findall(r'pip install "?\.\[([a-z,]+)\]', README):
        assert set(extra.split(",")) <= set(extras), extra


def test_citation_and_license_match_the_package():
    import tomllib

    from robomech import __version__

    cff = (ROOT / "CITATION.cff").read_text()
    assert f'version: "{__version__}"' in cff and "license: BSD-3-Clause" in cff
    assert (
        tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["license"]["text"] == "BSD-3-Clause"
    )
    assert (ROOT / "LICENSE").read_text().startswith("BSD 3-Clause License")
    assert f"## [{__version__}]" in (ROOT / "CHANGELOG.md").read_text()


def test_multibody_snippet_runs_and_prints_what_the_readme_shows():
    pytest.importorskip("mujoco")  # the gallery is read through MuJoCo's MJCF compiler ([verify] extra)
    code, expected = _blocks_after("## Model your own mechanism")
    r = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        env={**os.environ, "PYTHONPATH": str(ROOT / "src")},
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout == expected
