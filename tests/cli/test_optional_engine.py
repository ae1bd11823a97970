"""Without the ``verify`` extra (no MuJoCo) the CLI still runs everything that needs no engine.

How this is tested, and why not in a second virtual environment inside the suite: a venv with
``pip install .`` and no extras costs a download/installation of numpy, scipy, numba and matplotlib
(minutes, and network) on every run.  Here a subprocess runs the real CLI with an import hook that
makes ``import mujoco`` raise ``ModuleNotFoundError`` exactly as an environment without the package
does (``importlib.util.find_spec`` raises too, so the availability check sees it as absent).  A last
test shows that, with MuJoCo installed, discovery and ``list`` do not import it.
``.ci/run`` additionally runs the same commands in a fresh venv without extras (``make check-minimal``).
"""

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[2] / "src"
# The subprocesses below run real studies and checks; 300 s bounds a hang, far above their ~20 s.
TIMEOUT_S = 300

_BLOCKER = textwrap.dedent(
    """
    import sys, importlib.abc
    class _NoEngine(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] == "mujoco":
                raise ModuleNotFoundError(f"No module named {name!r}", name=name)
            return None
    sys.meta_path.insert(0, _NoEngine())
    sys.modules.pop("mujoco", None)
    import os
    keep = os.environ.get("KEEP_STUDIES")
    if keep:  # run `reproduce` (all) over a subset of the registered studies, to keep the test short
        import robomech.studies as studies
        full = studies.available_studies()
        studies.available_studies = lambda: {n: s for n, s in full.items() if n in keep.split(",")}
    from robomech.cli import main
    raise SystemExit(main(sys.argv[1:]))
    """
)


def _run(*args, block=True, cwd=None, keep_studies=""):
    env_code = (
        _BLOCKER
        if block
        else "import sys\nfrom robomech.cli import main\nraise SystemExit(main(sys.argv[1:]))"
    )
    return subprocess.run(
        [sys.executable, "-c", env_code, *args],
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        cwd=cwd,
        # the caller's environment (HOME: the numba kernel cache is shared, not rebuilt per test)
        env={**os.environ, "PYTHONPATH": str(SRC), "MPLBACKEND": "Agg", "KEEP_STUDIES": keep_studies},
    )


def test_list_names_the_skipped_ones_and_never_imports_the_engine(tmp_path):
    r = _run("list", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    registered = r.stdout.split("\nmechanisms")[0]  # the mechanisms section reuses the papers' names
    lines = {line.split()[0]: line for line in registered.splitlines() if line.startswith("  ")}
    for name in ("omnileg", "vectored-thrust"):
        assert "skipped: install robomech[verify]" in lines[name]
    assert "skipped" not in lines["continuum"] and "skipped" not in lines["demo"]


def test_a_named_study_that_needs_the_engine_is_a_usage_error(tmp_path):
    r = _run("reproduce", "omnileg", "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert r.returncode == 2
    assert "install robomech[verify]" in r.stderr and "Traceback" not in r.stderr
    r = _run("verify", "spherical-leg", cwd=tmp_path)
    assert r.returncode == 2 and "install robomech[verify]" in r.stderr


@pytest.mark.slow
def test_reproduce_and_verify_all_run_without_the_engine(tmp_path):
    # `reproduce continuum` (the acceptance command) runs in CI's `make check-minimal` in a real venv
    # without extras; here `reproduce` (all) over three studies shows the same paths in less time:
    # two need the engine (skipped), demo needs none.  (Every study reproduces, with strict JSON, in
    # tests/cli/test_cli.py; spherical-leg's own no-engine fallback catches EngineUnavailable, an
    # ImportError: test_engine_unavailable_is_an_import_error_naming_the_extra.)
    out = tmp_path / "out"
    keep = "demo,omnileg,vectored-thrust"
    r = _run("reproduce", "--out", str(out), "--quiet", cwd=tmp_path, keep_studies=keep)
    assert r.returncode == 0, r.stderr
    skipped_lines = [line for line in r.stdout.splitlines() if line.startswith("skipped:")]
    assert {line.split()[1] for line in skipped_lines} == {"omnileg", "vectored-thrust"}
    assert all("install robomech[verify]" in line for line in skipped_lines)
    index = (out / "index.md").read_text()
    assert "**omnileg** — install robomech[verify]" in index
    assert "[demo](demo/report.md)" in index

    r = _run("verify", "--json", "--quiet", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout, parse_constant=lambda c: pytest.fail(f"non-strict JSON {c}"))
    ran = {c["mechanism"] for c in report["checks"]}
    skipped = {s["mechanism"]: s["reason"] for s in report["skipped"]}
    assert ran == {"continuum"}
    assert set(skipped) == {"omnileg", "skid-steer", "spherical-leg", "vectored-thrust"}
    assert all("install robomech[verify]" in why for why in skipped.values())
    assert report["passed"] and all(c["passed"] for c in report["checks"])


def test_with_the_engine_installed_discovery_still_does_not_import_it(tmp_path):
    code = (
        "import sys; from robomech.cli import main; main(['list']);"
        "from robomech.verify import available_verifications; available_verifications();"
        "print('mujoco' in sys.modules)"
    )
    r = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        env={**os.environ, "PYTHONPATH": str(SRC), "MPLBACKEND": "Agg"},
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().splitlines()[-1] == "False"


def test_engine_unavailable_is_an_import_error_naming_the_extra():
    from robomech.verify import EngineUnavailable, optional_module

    engine = optional_module("robomech_no_such_engine")
    with pytest.raises(ImportError, match=r"pip install 'robomech\[robomech_no_such_engine\]'") as e:
        engine.MjModel  # noqa: B018 - the attribute access is the import
    assert isinstance(e.value, EngineUnavailable)
    assert "not yet imported" in repr(engine)
