"""``pytest tests/<module>`` runs the contract cases of that module's spec files, once (conftest.py)."""

from __future__ import annotations

import os
import subprocess
import sys
from collections import Counter
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
# each test starts a pytest collection in a subprocess (10-15 s on the shared machine)
pytestmark = pytest.mark.slow


def _collect(*paths: str) -> list[str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    out = subprocess.run(
        [sys.executable, "-m", "pytest", "--co", "-q", "-p", "no:cacheprovider", *paths],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    return [ln for ln in out.splitlines() if "::" in ln]


def _contract_names(ids: list[str]) -> set[str]:
    """The public names of the contract cases among node ids (``...[robomech.x.y-...]``)."""
    cases = [i for i in ids if i.startswith("tests/contract/") and "[" in i]
    return {i.split("[", 1)[1].split("-", 1)[0].rstrip("]") for i in cases}


def test_a_module_folder_runs_its_contract_cases_and_no_others():
    ids = _collect("tests/trajectory")
    names = _contract_names(ids)
    assert "robomech.trajectory.quintic" in names
    assert all(n.startswith("robomech.trajectory.") for n in names), names
    # control: the module's own tests are still there
    assert any(i.startswith("tests/trajectory/test_trajectory.py::") for i in ids)


def test_a_run_including_the_suite_has_each_case_once():
    ids = _collect("tests/trajectory", "tests/contract")
    twice = [i for i, n in Counter(ids).items() if n > 1]
    assert not twice, twice[:5]
    names = _contract_names(ids)
    assert "robomech.trajectory.quintic" in names and "robomech.spatial.exp_so3" in names
