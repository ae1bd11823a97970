"""CLI conventions: version, help listing names, exit codes, bad --out, Ctrl-C, strict JSON."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from robomech import __version__
from robomech.cli import available_commands, main
from robomech.studies import Study, available_studies
from robomech.verify import available_verifications

SRC = Path(__file__).resolve().parents[2] / "src"
# Subprocesses run real studies; 300 s bounds a hang, far above their few seconds.
TIMEOUT_S = 300


def strict_json(text):
    """json.loads that rejects NaN and ±Infinity (Python's json accepts them by default)."""

    def bad(constant):
        raise ValueError(f"non-strict JSON constant {constant}")

    return json.loads(text, parse_constant=bad)


def test_version_flag_and_python_dash_m(capsys):
    with pytest.raises(SystemExit) as e:
        main(["--version"])
    assert e.value.code == 0 and capsys.readouterr().out.strip() == f"robomech {__version__}"
    r = subprocess.run(
        [sys.executable, "-m", "robomech", "--version"],
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        env={**os.environ, "PYTHONPATH": str(SRC)},
    )
    assert r.returncode == 0 and r.stdout.strip() == f"robomech {__version__}"


def test_version_is_single_sourced():
    import tomllib

    meta = tomllib.loads((SRC.parent / "pyproject.toml").read_text())
    assert "version" in meta["project"]["dynamic"] and "version" not in meta["project"]
    assert meta["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "robomech.__version__"}


@pytest.mark.parametrize(
    ("command", "names"),
    [("reproduce", lambda: available_studies()), ("verify", lambda: available_verifications())],
)
def test_subcommand_help_lists_the_names(command, names, capsys):
    with pytest.raises(SystemExit) as e:
        main([command, "--help"])
    out = capsys.readouterr().out
    assert e.value.code == 0
    for name in names():
        assert f"  {name} " in out


def test_commands_are_discovered_from_modules():
    assert {"list", "reproduce", "sweep", "verify"} <= set(available_commands())


def test_usage_errors_exit_2_without_traceback(capsys):
    with pytest.raises(SystemExit) as e:
        main(["no-such-command"])
    assert e.value.code == 2
    assert main(["reproduce", "no-such-study", "--out", "x"]) == 2
    assert "Traceback" not in capsys.readouterr().err


@pytest.mark.parametrize("case", ["file", "under-file", "empty", "unwritable"])
def test_bad_out_is_a_usage_error(case, tmp_path, capsys, monkeypatch):
    f = tmp_path / "a-file"
    f.write_text("x")
    out = {"file": str(f), "under-file": str(f / "sub"), "empty": "", "unwritable": str(tmp_path / "ro")}[
        case
    ]
    if case == "unwritable":  # root may write anywhere: make the probe fail as a read-only folder does
        import robomech.cli._core as core

        def refuse(*a, **k):
            raise PermissionError(13, "Permission denied")

        monkeypatch.setattr(core.tempfile, "mkstemp", refuse)
    cwd_before = sorted(os.listdir(tmp_path))
    monkeypatch.chdir(tmp_path)
    assert main(["reproduce", "demo", "--out", out, "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("robomech reproduce: --out:") and "Traceback" not in err
    assert sorted(os.listdir(tmp_path)) == cwd_before + (["ro"] if case == "unwritable" else [])
    assert main(["verify", "demo-does-not-matter", "--out", out]) == 2  # same check for verify --out


def test_internal_error_exits_3_with_one_line(monkeypatch, tmp_path, capsys):
    import robomech.studies as studies

    def crash(out_dir, progress):
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr(studies, "available_studies", lambda: {"bug": Study("bug", "B", "s", crash)})
    assert main(["reproduce", "bug", "--out", str(tmp_path), "--quiet"]) == 3
    err = capsys.readouterr().err
    assert "internal error: ZeroDivisionError: a bug" in err and "Traceback" not in err
    assert main(["--traceback", "reproduce", "bug", "--out", str(tmp_path), "--quiet"]) == 3
    assert "Traceback" in capsys.readouterr().err


def test_interrupt_exits_130_and_keeps_only_complete_study_folders(monkeypatch, tmp_path, capsys):
    import robomech.studies as studies

    real = available_studies()
    assert main(["reproduce", "demo", "--out", str(tmp_path), "--quiet"]) == 0
    old = strict_json((tmp_path / "demo" / "results.json").read_text())["provenance"]["date_utc"]

    def interrupted(out_dir, progress):
        (out_dir / "half-written.png").write_bytes(b"partial")
        raise KeyboardInterrupt

    fake = {"demo": real["demo"], "zz-long": Study("zz-long", "Long", "s", interrupted)}
    monkeypatch.setattr(studies, "available_studies", lambda: fake)
    time.sleep(1.1)  # the provenance date has one-second resolution
    assert main(["reproduce", "--out", str(tmp_path), "--quiet"]) == 130
    err = capsys.readouterr().err
    assert "interrupted" in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["demo", "index.html", "index.md"]  # no temporaries
    new = strict_json((tmp_path / "demo" / "results.json").read_text())["provenance"]["date_utc"]
    assert new != old  # demo completed in this run, and the index (written last) says so
    index = (tmp_path / "index.md").read_text()
    assert (
        new.replace("T", " ").removesuffix("+00:00") in index
        and "zz-long" in index
        and "not reproduced yet" in index
    )


def test_real_sigint_mid_study_exits_130_without_traceback(tmp_path):
    out = tmp_path / "out"
    p = subprocess.Popen(
        [sys.executable, "-m", "robomech", "reproduce", "skid-steer", "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": str(SRC), "MPLBACKEND": "Agg"},
    )
    try:
        for line in p.stderr:  # wait until the study is running, then Ctrl-C
            if "ground truth" in line:
                break
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=TIMEOUT_S)
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    assert p.returncode == 130, err
    assert "Traceback" not in err and "interrupted" in err
    assert sorted(x.name for x in out.iterdir()) == ["index.html", "index.md"]


def test_strict_json_of_list(capsys):
    assert main(["list", "--json"]) == 0
    data = strict_json(capsys.readouterr().out)
    assert {s["name"] for s in data["studies"]} == set(available_studies())


@pytest.mark.slow  # ~8 s: builds and runs the three engine verifications
def test_verify_json_is_strict_for_the_engine_mechanisms(capsys):
    # continuum: strict JSON checked in test_optional_engine (it runs there without the engine)
    names = ["omnileg", "skid-steer", "spherical-leg", "vectored-thrust"]
    assert main(["verify", *names, "--json", "--quiet"]) == 0
    out = strict_json(capsys.readouterr().out)
    assert {c["mechanism"] for c in out["checks"]} == set(names) and out["passed"]
    for c in out["checks"]:
        assert type(c["passed"]) is bool and type(c["relative"]) is bool
        assert c["max_error"] is None or type(c["max_error"]) is float


def test_verify_json_maps_numpy_and_non_finite_values_to_strict_json(monkeypatch, capsys):
    import numpy as np

    from robomech import verify
    from robomech.verify import Check, Tolerance, Verification

    checks = [
        Check("m", "nan error", np.float64("nan"), Tolerance(np.float64(1e-3), "t", relative=np.bool_(True))),
        Check("m", "numpy error", np.float32(1e-5), Tolerance(1e-3, "t")),
    ]
    v = Verification("m", "M", "none", run=lambda: checks)
    monkeypatch.setattr(verify, "available_verifications", lambda: {"m": v})
    assert main(["verify", "--json", "--quiet"]) == 1  # the NaN check fails, and says so in JSON
    out = strict_json(capsys.readouterr().out)
    assert out["checks"][0]["max_error"] is None and out["checks"][0]["passed"] is False
    assert out["checks"][1]["passed"] is True and out["passed"] is False


def test_numba_compile_is_announced_on_stderr(capsys):
    import numba

    from robomech.cli._core import announce_compiles

    assert announce_compiles()

    @numba.njit
    def _fresh_kernel(x):  # a new function: never in any cache
        return x + 1

    _fresh_kernel(1)
    err = capsys.readouterr().err
    assert "compiling" in err and "_fresh_kernel" in err and "compiled in" in err
    announce_compiles(enabled=False)
    _fresh_kernel(1.5)  # a new signature compiles again, silently
    assert capsys.readouterr().err == ""
    announce_compiles(enabled=True)


@pytest.mark.slow
def test_every_study_reproduces_with_strict_json_and_a_complete_index(tmp_path, capsys, monkeypatch):
    import robomech.studies.skid_steer as ss

    # The throughput table times 250 000 systems (~30 s) and the ground truth runs at 500 Hz: smaller
    # sizes exercise the same code paths (this test is about the writing, not the numbers).
    monkeypatch.setattr(ss, "N_THROUGHPUT", 5_000)
    monkeypatch.setattr(ss, "N_LOOP", 50)
    monkeypatch.setattr(ss, "RATE", 100.0)
    # sweep-demo (robomech.explore) starts a local Dask cluster (~12 s); its results.json goes through
    # the same strict writer (dumps_json raises on a value strict JSON cannot hold)
    names = [n for n in available_studies() if n != "sweep-demo"]
    assert main(["reproduce", *names, "--out", str(tmp_path), "--json", "--quiet"]) == 0
    summary = strict_json(capsys.readouterr().out)
    assert [s["study"] for s in summary["studies"]] == names
    for n in names:
        data = strict_json((tmp_path / n / "results.json").read_text())
        assert data["name"] == n and data["provenance"]["robomech"] == __version__
        html = (tmp_path / n / "report.html").read_text()
        assert "<table>" in html and 'id="contents"' in html and "../index.html" in html
        assert all((tmp_path / n / f["file"]).exists() for f in data["figures"])
        assert html.count('<img alt="') == len(data["figures"])  # every figure has its alt text
    index = (tmp_path / "index.md").read_text()
    assert all(f"]({n}/report.md)" in index for n in names)
