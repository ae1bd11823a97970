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
