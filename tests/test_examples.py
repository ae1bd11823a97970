"""Every script of the example gallery (examples/*.py) runs and passes its own checks.

Each example asserts its result against an independent reference (a closed form, a power balance,
a published optimum, MuJoCo) and prints ``OK`` last; it runs here in a fresh interpreter, exactly as
a user would run it, using this checkout's robomech.  The docs site shows each script with its
printed output and figures (sphinx-gallery runs examples/ when the docs are built).
"""

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

import robomech

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))
# Needs the optional engine: skipped (not failed) without the verify extra.
NEEDS_MUJOCO = {"verify_against_mujoco.py"}
# Seconds a single example may take before it counts as hung (each runs in a few seconds).
TIMEOUT_S = 300


def test_there_is_a_gallery():
    assert len(EXAMPLES) >= 5, [p.name for p in EXAMPLES]


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.name)
def test_example_runs(script, tmp_path):
    if script.name in NEEDS_MUJOCO and importlib.util.find_spec("mujoco") is None:
        pytest.skip("needs robomech[verify] (MuJoCo)")
    env = dict(os.environ, MPLBACKEND="Agg")
    src = str(Path(robomech.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([src, env.get("PYTHONPATH", "")])
    run = subprocess.run(
        [sys.executable, str(script)],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    assert run.stdout.rstrip().endswith("OK"), run.stdout


def test_every_example_is_a_gallery_page():
    # sphinx-gallery (docs/conf.py) makes a page of every examples/*.py whose docstring opens with an
    # underlined title; the gallery's own page is examples/GALLERY_HEADER.rst
    assert (ROOT / "examples" / "GALLERY_HEADER.rst").exists()
    for script in EXAMPLES:
        lines = script.read_text().split('"""')[1].strip().splitlines()
        assert len(lines) > 1 and lines[1] == "=" * len(lines[0]), f"{script.name}: no gallery title"
