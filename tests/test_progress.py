"""Progress of long operations (robomech._progress): log records on the "robomech" logger for the
Python API, a bar on stderr only where the command line asks for it on a terminal, nothing with
--quiet."""

import io
import logging
import sys

import pytest

from robomech import _progress
from robomech.cli import main


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.fixture(autouse=True)
def _bars_off():
    yield
    _progress.show_bars(False)


def _run_stages(names):
    with _progress.stages("demo", names) as st:
        for n in names:
            st.next(n)


def test_every_stage_is_logged_on_the_robomech_logger(caplog):
    with caplog.at_level(logging.INFO, logger="robomech"):
        _run_stages(["first", "second"])
    messages = [r.getMessage() for r in caplog.records if r.name == "robomech"]
    assert messages == ["demo: 2 stages", "demo: [1/2] first", "demo: [2/2] second", "demo: done"]


def test_bars_only_on_a_terminal(monkeypatch):
    monkeypatch.setattr(sys, "stderr", io.StringIO())
    assert _progress.show_bars(True) is False  # not a terminal: no bar even when asked
    _run_stages(["a"])
    assert sys.stderr.getvalue() == ""
    monkeypatch.setattr(sys, "stderr", _Terminal())
    assert _progress.show_bars(False) is False  # --quiet
    _run_stages(["a"])
    assert sys.stderr.getvalue() == ""
    assert _progress.show_bars(True) is True


def test_a_bar_names_the_stage_on_a_terminal(monkeypatch):
    term = _Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    assert _progress.show_bars(True)
    with _progress.stages("verify demo", ["assembly", "dynamics"]) as st:
        st.next()
        st.next()
    assert "verify demo" in term.getvalue() and "dynamics" in term.getvalue()


def test_verify_quiet_prints_nothing_on_stderr(capsys):
    pytest.importorskip("mujoco")
    assert main(["verify", "four_bar", "--quiet"]) == 0
    assert capsys.readouterr().err == ""
    assert not _progress.bars_enabled()


def test_a_study_shows_a_bar_of_its_steps_on_a_terminal_and_lines_elsewhere(monkeypatch):
    from robomech.studies import Progress

    plain = io.StringIO()
    with Progress("demo: ", stream=plain) as p:  # not a terminal: one line per step, no bar
        p.plan(["one", "two"])
        p.step("one")
        list(p.iter(range(20), "case"))
        p.step("two")
    lines = plain.getvalue().splitlines()
    assert [line.split("] ", 1)[1] for line in lines][:2] == ["demo: one", "demo: case 1/20"]
    assert lines[-1].endswith("demo: two") and "\x1b" not in plain.getvalue()

    term = _Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    assert _progress.show_bars(True)
    with Progress("demo: ") as p:
        p.plan(["one", "two"])
        p.step("one")
        for _ in p.iter(range(3), "case"):
            # a verification inside a step shares the one live display, a line of its own
            with _progress.stages("verify inner", ["a"]) as st:
                st.next()
                shown = [t.description.strip() for t in _progress._LIVE["bar"].tasks]
                assert shown == ["demo", "case", "verify inner"]
        p.step("two")
        assert [t.description for t in _progress._LIVE["bar"].tasks] == ["demo"]
    shown = term.getvalue()
    assert "demo: one" in shown and "demo: two" in shown  # the step lines stay above the bar
    assert "1/2" in shown  # the bar: one of two steps done while the second runs
    assert _progress._LIVE["bar"] is None  # removed when the study ends


def test_reproduce_quiet_prints_nothing_on_stderr(capsys, tmp_path):
    assert main(["reproduce", "demo", "--out", str(tmp_path), "--quiet"]) == 0
    assert capsys.readouterr().err == ""
