"""Every user mistake exits 2 with one line saying why; exit 3 is kept for real internal errors.

User mistakes: a file that does not exist or is not well-formed XML, a misspelt study or mechanism
name (answered with the closest name), an output path that cannot be written (a missing folder, a
folder, ``/proc``), and an optional engine that is not installed (``robomech[verify]``).  The last one
is simulated as in ``test_optional_engine.py``: a subprocess whose import hook makes ``import mujoco``
raise ``ModuleNotFoundError``.
"""

from __future__ import annotations

import subprocess
import sys

import pytest
from test_optional_engine import _BLOCKER, SRC, TIMEOUT_S

import robomech.cli as cli
from robomech.cli import main
from robomech.cli._core import EXIT_INTERNAL, EXIT_USAGE, Command

PENDULUM = """<mujoco model="pendulum">
  <worldbody>
    <body name="link">
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.02" mass="1"/>
    </body>
  </worldbody>
</mujoco>
"""


def _one_line_usage_error(capsys, argv):
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code == EXIT_USAGE, err
    assert len(err.splitlines()) == 1, err
    assert "bug in robomech" not in err and "Traceback" not in err and "path_or_xml" not in err
    return err


@pytest.mark.parametrize("command", ["verify", "export", "view"])
def test_a_missing_file_says_so(capsys, tmp_path, command):
    err = _one_line_usage_error(capsys, [command, str(tmp_path / "x.xml")])
    assert err.endswith(f"no such file: {tmp_path / 'x.xml'}")


@pytest.mark.parametrize("command", ["verify", "export", "view"])
def test_malformed_xml_is_reported_with_file_and_line(capsys, tmp_path, command):
    bad = tmp_path / "bad.xml"
    bad.write_text("<mujoco>\n<worldbody>\n<body>\n</worldbody>\n</mujoco>\n")
    err = _one_line_usage_error(capsys, [command, str(bad)])
    assert f"{bad}:4:" in err and "malformed XML" in err and "XML_ERROR" not in err


@pytest.mark.parametrize(
    ("argv", "suggestion"),
    [
        (["reproduce", "omnlieg"], "omnileg"),
        (["verify", "spherical-lge"], "spherical-leg"),
        (["export", "four_bra"], "four_bar"),
    ],
)
def test_a_misspelt_name_gets_the_closest_one(capsys, argv, suggestion):
    err = _one_line_usage_error(capsys, argv)
    assert f"did you mean {suggestion!r}?" in err


def test_a_name_close_to_nothing_gets_no_suggestion(capsys):
    err = _one_line_usage_error(capsys, ["reproduce", "zzzzzz"])
    assert "did you mean" not in err and "valid studies are" in err


@pytest.mark.parametrize("where", ["missing-folder", "folder", "proc"])
def test_an_output_path_that_cannot_be_written(capsys, tmp_path, where):
    target = {
        "missing-folder": str(tmp_path / "no" / "such" / "d.xml"),
        "folder": str(tmp_path),
        "proc": "/proc/robomech-d.xml",
    }[where]
    err = _one_line_usage_error(capsys, ["export", "delta", "--mjcf", target])
    assert "cannot write" in err


def test_export_to_a_writable_file_still_works(capsys, tmp_path):
    assert main(["export", "four_bar", "--mjcf", str(tmp_path / "f.xml")]) == 0
    assert (tmp_path / "f.xml").read_text().startswith("<mujoco")


def _run_without_engine(*args, cwd):
    return subprocess.run(
        [sys.executable, "-c", _BLOCKER, *args],
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        cwd=cwd,
        env={"PYTHONPATH": str(SRC), "MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin", "HOME": str(cwd)},
    )


@pytest.mark.parametrize("argv", [["export", "four_bar"], ["verify", "pendulum.xml"]])
def test_without_the_engine_the_engine_commands_say_what_to_install(tmp_path, argv):
    (tmp_path / "pendulum.xml").write_text(PENDULUM)
    r = _run_without_engine(*argv, cwd=tmp_path)
    assert r.returncode == EXIT_USAGE, r.stderr
    assert "install robomech[verify]" in r.stderr and "bug in robomech" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr


def _crashing(exc):
    def run(args):
        raise exc

    return Command(name="crash", help="raises", add_arguments=lambda p: None, run=run)


@pytest.mark.parametrize(
    "exc",
    [
        RuntimeError("boom"),
        ModuleNotFoundError("No module named 'robomech.nothing'", name="robomech.nothing"),
    ],
)
def test_a_real_internal_error_is_still_exit_3(capsys, monkeypatch, exc):
    # control: the user-error paths above do not swallow bugs (a missing module of robomech itself
    # is a bug, not a missing extra)
    monkeypatch.setattr(cli, "available_commands", lambda: {"crash": _crashing(exc)})
    assert main(["crash"]) == EXIT_INTERNAL
    assert "bug in robomech" in capsys.readouterr().err


def test_a_missing_optional_engine_in_process_is_exit_2(capsys, monkeypatch):
    exc = ModuleNotFoundError("No module named 'mujoco'", name="mujoco")
    monkeypatch.setattr(cli, "available_commands", lambda: {"crash": _crashing(exc)})
    assert main(["crash"]) == EXIT_USAGE
    assert "install robomech[verify]" in capsys.readouterr().err


@pytest.mark.parametrize(
    "argv",
    [
        ["frobnicate"],
        ["verify", "four_bar", "--duration", "abc"],
        ["verify", "four_bar", "--engine", "bullet"],
        ["sweep", "--designs", "-3"],
        ["export"],
        ["list", "--bogus"],
    ],
)
def test_an_argument_error_is_one_line_naming_the_help(capsys, argv):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    err = capsys.readouterr().err.strip()
    assert exc.value.code == EXIT_USAGE
    assert len(err.splitlines()) == 1 and err.endswith("--help)"), err


def test_control_help_still_prints_the_usage(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["verify", "--help"])
    assert exc.value.code == 0 and "usage:" in capsys.readouterr().out


def test_start_rates_without_a_start_configuration_are_named_by_their_options(capsys):
    err = _one_line_usage_error(capsys, ["verify", "four_bar", "--qd0", "1"])
    assert "--qd0 needs --q0" in err and "qd_act0" not in err
    err = _one_line_usage_error(capsys, ["verify", "four_bar", "--qvel0", "1", "0", "0"])
    assert "--qvel0 needs --q0" in err and "qd0" not in err.replace("--qvel0", "")
