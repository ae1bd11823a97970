"""docs/multibody.md runs: every ```python block of the tutorial, in order, in one namespace."""

from __future__ import annotations

import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "multibody.md"


def test_tutorial_runs(tmp_path, monkeypatch):
    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(), flags=re.S)
    assert len(blocks) >= 8, "the tutorial lost its code"
    monkeypatch.chdir(tmp_path)  # the drawing is saved here
    ns: dict = {}
    for i, code in enumerate(blocks):
        exec(compile(code, f"{DOC.name}[block {i}]", "exec"), ns)
    assert (tmp_path / "four_bar.png").stat().st_size > 0
