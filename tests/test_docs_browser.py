"""The built docs site in Debian's headless Chromium: the pages with equations render them with the
site's own MathJax (offline: no network is needed), without a TeX error or a console error.  Runs
against an existing build (`make docs`); skipped where there is none or no browser."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

HTML = Path(__file__).resolve().parents[1] / "docs" / "_build" / "html"
CHROMIUM = os.environ.get("ROBOMECH_CHROMIUM", "/usr/bin/chromium-headless-shell")
# Pages whose equations were Unicode or inline code before: each must typeset at least this many.
MATH_PAGES = {
    "mechanisms/spherical_leg.html": 100,
    "mechanisms/omnileg.html": 100,
    "mechanisms/continuum.html": 100,
    "mechanisms/continuum_cosserat.html": 100,
    "mechanisms/skid_steer.html": 100,
    "mechanisms/vectored_thrust.html": 100,
    "dynamics.html": 20,
    "conventions.html": 10,
}
# MathJax's marks of bad TeX: an error node (a missing argument, an unbalanced brace) and, for an
# undefined macro (its `noundefined` extension), the macro's name as red text.
TEX_ERRORS = """Array.from(document.querySelectorAll(
    '[data-mjx-error], [data-mml-node="mtext"][fill="red"]')).map(e => e.dataset.mjxError || e.textContent)"""
# Bound (ms) of one page's load and typesetting.
PAGE_MS = 60_000

playwright_sync = pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
if not (HTML / "index.html").exists():
    pytest.skip("no built site (make docs)", allow_module_level=True)
if not (Path(CHROMIUM).is_file() or shutil.which(CHROMIUM)):
    pytest.skip(f"no headless Chromium at {CHROMIUM} (make install-browser)", allow_module_level=True)


def test_equations_render_as_math_offline():
    problems: list[str] = []
    with playwright_sync.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"], timeout=PAGE_MS)
        try:
            page = browser.new_page()
            errors: list[str] = []
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            # offline: any request that leaves the file system fails the page
            page.route(
                "http*://**", lambda route: (errors.append(f"network: {route.request.url}"), route.abort())
            )
            for name, least in MATH_PAGES.items():
                errors.clear()
                page.goto((HTML / name).as_uri(), timeout=PAGE_MS)
                page.wait_for_function("window.MathJax?.startup?.promise", timeout=PAGE_MS)
                page.evaluate("MathJax.startup.promise")
                n = page.locator("mjx-container").count()
                tex_errors = page.evaluate(TEX_ERRORS)
                if n < least or tex_errors or errors:
                    problems.append(
                        f"{name}: {n} formulas (at least {least}), TeX errors {tex_errors}, {errors}"
                    )
        finally:
            browser.close()
    assert not problems, "\n".join(problems)
