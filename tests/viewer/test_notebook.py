"""`mb.view` in a Jupyter notebook: a real IPython kernel (ipykernel, driven by nbclient) runs the
cells, and the HTML the notebook shows for the viewer is loaded in Debian's headless Chromium.

The first cell shows ``mb.view(delta)``; its rich output must be the viewer embedded as an iframe of
the kernel's server on 127.0.0.1, and that page, opened as a notebook front end would open the cell's
HTML, must load the viewer without console errors.  A second cell moves the actuators from Python
(``v.set_q_act``) and the embedded view must show the new pose; a last cell stops the viewer, whose
display then says so.  The kernel and the browser are shut down at the end; every wait is bounded.
"""

from __future__ import annotations

import json
import re
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from test_browser import MOVE_S, PAGE_S, _q, open_page

pytestmark = pytest.mark.slow

nbclient = pytest.importorskip("nbclient", reason="nbclient is not installed (pip install 'robomech[test]')")
nbformat = pytest.importorskip("nbformat", reason="nbformat is not installed (pip install 'robomech[test]')")
pytest.importorskip("ipykernel", reason="ipykernel is not installed (pip install 'robomech[test]')")
playwright_sync = pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
pytest.importorskip("viser", reason="viser is not installed (pip install 'robomech[view]')")

# Bound (s) of one cell in the kernel: imports, the Delta's first assembly and the server's start.
CELL_S = 120
# The actuator angles the second cell sets (rad): inside the Delta's assembled range, far from q0.
Q_ACT = [0.3, -0.2, 0.1]

SHOW = """\
from robomech import multibody as mb
v = mb.view(mb.gallery.BUILDERS["delta"]())
v"""
MOVE = f"v.set_q_act({Q_ACT}).converged"
STOP = "v.stop()\nv"


def _kernel_spec(folder: Path) -> str:
    """A kernel spec that starts ipykernel with this interpreter (the installed spec says `python`,
    whichever that is on PATH)."""
    spec = folder / "kernels" / "robomech-test"
    spec.mkdir(parents=True)
    argv = [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"]
    spec_json = {"argv": argv, "display_name": "robomech test", "language": "python"}
    (spec / "kernel.json").write_text(json.dumps(spec_json))
    return "robomech-test"


def _html(cell) -> str:
    for out in cell.outputs:
        shown = out.get("output_type") in ("execute_result", "display_data")
        if shown and "text/html" in out.get("data", {}):
            return str(out["data"]["text/html"])
    raise AssertionError(f"no HTML output: {cell.outputs}")


def test_mb_view_is_shown_inline_in_a_notebook(tmp_path, monkeypatch):
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path / "jupyter"))
    monkeypatch.setenv("JUPYTER_PLATFORM_DIRS", "1")
    kernel = _kernel_spec(tmp_path / "jupyter")
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(c) for c in (SHOW, MOVE, STOP)])
    client = nbclient.NotebookClient(nb, kernel_name=kernel, timeout=CELL_S, allow_errors=False)
    errors: list[str] = []
    with client.setup_kernel():
        client.execute_cell(nb.cells[0], 0)
        html = _html(nb.cells[0])
        m = re.search(r'<iframe src="(http://127\.0\.0\.1:\d+)"', html)
        assert m, f"the viewer is not embedded as an iframe of its local server: {html!r}"
        (tmp_path / "cell.html").write_text(f"<html><body>{html}</body></html>", encoding="utf-8")
        with playwright_sync.sync_playwright() as p:
            browser, page = open_page(p, (tmp_path / "cell.html").as_uri(), errors)
            try:
                frame = page.frame_locator("iframe")
                frame.get_by_text(re.compile(r"assembled \(initial configuration\)")).first.wait_for(
                    timeout=PAGE_S * 1000
                )
                panel = frame.locator("body")
                q_before = _q(panel.inner_text())
                client.execute_cell(nb.cells[1], 1)  # the kernel moves the actuators
                deadline = time.monotonic() + MOVE_S
                q_after = _q(panel.inner_text())
                while np.allclose(q_after, q_before) and time.monotonic() < deadline:
                    time.sleep(0.2)
                    q_after = _q(panel.inner_text())
            finally:
                browser.close()
        client.execute_cell(nb.cells[2], 2)
    assert not errors, f"console errors: {errors}"
    assert nb.cells[1].outputs[0]["data"]["text/plain"] == "True"  # the pose assembled
    assert not np.allclose(q_after, q_before), "the kernel's set_q_act did not change the embedded view"
    assert "stopped" in _html(nb.cells[2])
