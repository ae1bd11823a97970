"""`robomech view delta` in a real browser: Debian's headless Chromium driven by playwright.

The server runs as a subprocess on 127.0.0.1 with a free port; the page must load without console
errors, and moving the first actuated joint's slider through the page (keyboard on the slider, as a
user would) must re-assemble the Delta: the status panel's configuration ``q`` changes and still
reads "assembled"; the screenshot button must download a PNG of the view.  Every wait is bounded
and the server is killed at the end.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

CHROMIUM = os.environ.get("ROBOMECH_CHROMIUM", "/usr/bin/chromium-headless-shell")
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]
# Bounds (s): the server's start (imports, the Delta's first assembly, viser's start), a page load
# and its first scene, and one slider move's round trip (browser -> server -> FK -> browser).
SERVER_START_S = 60.0
PAGE_S = 30.0
MOVE_S = 20.0
# Keyboard steps of the slider: 20 steps of (2 pi / 400) rad move theta1 by 0.31 rad, a pose change
# far above the 4-decimal display (1e-4) and well inside the Delta's assembled range.
KEY_STEPS = 20

pytestmark = pytest.mark.slow

playwright_sync = pytest.importorskip(
    "playwright.sync_api", reason="playwright is not installed (pip install 'robomech[test]')"
)
pytest.importorskip("viser", reason="viser is not installed (pip install 'robomech[view]')")
if not (Path(CHROMIUM).is_file() or shutil.which(CHROMIUM)):
    pytest.skip(f"no headless Chromium at {CHROMIUM} (make install-browser)", allow_module_level=True)


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@pytest.fixture()
def server():
    port = _free_port()
    env = dict(os.environ)
    src = str(Path(__file__).resolve().parents[2] / "src")
    env["PYTHONPATH"] = src + os.pathsep + env.get("PYTHONPATH", "")
    proc = subprocess.Popen(
        [sys.executable, "-m", "robomech", "view", "delta", "--port", str(port), "--no-browser"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=env,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + SERVER_START_S
        ready = False
        while time.monotonic() < deadline and proc.poll() is None:
            try:
                with socket.create_connection(("127.0.0.1", port), timeout=1.0):
                    ready = True
                    break
            except OSError:
                time.sleep(0.2)
        if not ready:
            proc.kill()
            out = proc.communicate(timeout=10)[0]
            pytest.fail(f"robomech view did not serve on port {port} within {SERVER_START_S} s:\n{out}")
        yield f"http://127.0.0.1:{port}"
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGINT)
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait(timeout=10)
        if proc.stdout is not None:
            proc.stdout.close()


def _q(text: str) -> np.ndarray:
    m = re.search(r"\bq = \[([^\]]*)\]", text)
    assert m, f"no configuration in the status panel: {text[:300]!r}"
    return np.array([float(x) for x in m.group(1).split(",")])


def open_page(p, url: str, errors: list[str]):
    """Headless Chromium on ``url``; console errors and page errors are appended to ``errors``.
    Returns ``(browser, page)``: the caller closes the browser."""
    browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, timeout=PAGE_S * 1000)
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(url, timeout=PAGE_S * 1000)
    return browser, page


def test_page_loads_and_a_slider_reassembles(server):
    errors: list[str] = []
    with playwright_sync.sync_playwright() as p:
        browser, page = open_page(p, server, errors)
        try:
            status = page.get_by_text(re.compile(r"assembled \(initial configuration\)"))
            status.first.wait_for(timeout=PAGE_S * 1000)
            panel = page.locator("body")
            q_before = _q(panel.inner_text())
            slider = page.get_by_role("slider").first
            slider.wait_for(timeout=PAGE_S * 1000)
            slider.focus()
            for _ in range(KEY_STEPS):
                page.keyboard.press("ArrowRight")
            page.get_by_text(re.compile(r"assembled \(slider\)")).first.wait_for(timeout=MOVE_S * 1000)
            deadline = time.monotonic() + MOVE_S
            q_after = _q(panel.inner_text())
            while np.allclose(q_after, q_before) and time.monotonic() < deadline:
                time.sleep(0.2)
                q_after = _q(panel.inner_text())
            text = panel.inner_text()
            # the screenshot button: the browser renders the view, the server sends it back as a PNG
            with page.expect_download(timeout=MOVE_S * 1000) as download:
                page.get_by_role("button", name="Screenshot (PNG)").click()
            png = Path(download.value.path()).read_bytes()
        finally:
            browser.close()
    assert not errors, f"console errors: {errors}"
    assert "did not assemble" not in text
    assert q_after.shape == q_before.shape
    assert not np.allclose(q_after, q_before), "the slider move did not change the assembled pose"
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 1000
