"""The docs site covers the package: every public subpackage has an API page, every Markdown page
under docs/ is in a table of contents, and the build configuration names its extensions' packages
in the `docs` extra.  (`make docs` itself runs in CI with warnings as errors; it is not re-run here.)"""

import re
import tomllib
from pathlib import Path

import robomech

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


def _api_modules() -> set[str]:
    text = "\n".join(p.read_text() for p in (DOCS / "api").glob("*.rst"))
    return set(re.findall(r"\.\. automodule:: (robomech[\w.]*)", text))


def test_every_public_subpackage_has_an_api_page():
    documented = _api_modules()
    for name in robomech._SUBPACKAGES:
        assert f"robomech.{name}" in documented, f"docs/api has no page for robomech.{name}"
    for sub in ("lstsq", "mobility", "workspace"):
        assert f"robomech.analysis.{sub}" in documented
    for m in ("spherical_leg", "omnileg", "continuum", "skid_steer", "vectored_thrust"):
        assert f"robomech.mechanisms.{m}" in documented
    assert "robomech.cli" in documented


def test_every_markdown_page_is_in_a_toctree():
    toc = "\n".join(p.read_text() for p in DOCS.rglob("*.md"))
    for page in DOCS.rglob("*.md"):
        rel = page.relative_to(DOCS).with_suffix("").as_posix()
        if rel in ("index",):
            continue
        names = {rel, rel.split("/", 1)[-1]}  # api pages are listed relative to api/index
        assert any(re.search(rf"^{re.escape(n)}$", toc, re.M) for n in names), f"docs/{rel}.md: no toctree"


def test_docs_extra_installs_the_configured_extensions():
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]["docs"]
    conf = (DOCS / "conf.py").read_text()
    needed = {"sphinx": "sphinx", "numpydoc": "numpydoc", "myst_parser": "myst-parser"}
    for module, dist in needed.items():
        assert module in conf and any(e.startswith(dist) for e in extras), dist
