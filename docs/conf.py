"""Sphinx configuration of the robomech documentation (`make docs`)."""

import importlib.util
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

import robomech  # noqa: E402

project = "robomech"
author = "the robomech contributors"
copyright = "2026, the robomech contributors"
release = version = robomech.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build"]
root_doc = "index"

# autodoc: members are the public __all__; types are documented in the numpydoc sections (the
# signatures' annotations are often `object` for array-likes and would only add noise).
autodoc_default_options = {"members": True, "member-order": "bysource", "show-inheritance": False}
autodoc_typehints = "none"
autodoc_mock_imports: list[str] = []
# numpydoc: no per-class member tables (autodoc lists members) and no type cross-references (no
# intersphinx: the docs build offline).
numpydoc_show_class_members = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()

myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3

html_theme = "alabaster"
html_title = f"robomech {release}"
html_static_path: list[str] = []

# Docstrings are written for readers of the source: |x| means an absolute value or a norm, not a
# reStructuredText substitution.  Escape the bars outside ``literals`` before docutils sees them.
_LITERAL = re.compile(r"(``.*?``|`[^`]*`)")


def _escape_bars(app, what, name, obj, options, lines):
    for i, line in enumerate(lines):
        if "|" in line:
            parts = _LITERAL.split(line)
            lines[i] = "".join(p if k % 2 else p.replace("|", r"\|") for k, p in enumerate(parts))


def _generate(app) -> None:
    _example_outputs()
    _paper_pages()


def setup(app):
    app.connect("autodoc-process-docstring", _escape_bars)
    app.connect("builder-inited", _generate)  # before the sources (and the papers/* glob) are read


# No intersphinx (this project builds offline): references into the standard library and
# unparsed generic annotations cannot resolve, and are the only nitpicks ignored.
nitpick_ignore = [("py:class", "collections.abc.Mapping")]
nitpick_ignore_regex = [("py:class", r"'?(list|dict|tuple)\[.*")]


# ----------------------------------------------------------------------------- generated at build time
# Nothing below is committed: the example outputs go to docs/_build/example-output/, the studies'
# reports to docs/_build/reports/ and their pages to docs/papers/ (git-ignored), rebuilt by every
# `make docs` from this checkout's source.
BUILD = ROOT / "docs" / "_build"
RUN_ENV = dict(
    os.environ,
    PYTHONPATH=os.pathsep.join(p for p in (str(ROOT / "src"), os.environ.get("PYTHONPATH", "")) if p),
    MPLBACKEND="Agg",
)
# Seconds before a hung example or study fails the build.
RUN_TIMEOUT_S = 900
# Example scripts that need the optional engine (the docs extra does not install it by itself).
EXAMPLES_NEED_MUJOCO = {"verify_against_mujoco.py"}


def _example_outputs() -> None:
    """Run every examples/*.py and keep its printed output for docs/examples.md (literalinclude)."""
    out = BUILD / "example-output"
    out.mkdir(parents=True, exist_ok=True)
    for script in sorted((ROOT / "examples").glob("*.py")):
        if script.name in EXAMPLES_NEED_MUJOCO and importlib.util.find_spec("mujoco") is None:
            (out / f"{script.stem}.txt").write_text("(not run: needs robomech[verify], MuJoCo)\n")
            continue
        run = subprocess.run(
            [sys.executable, str(script)],
            cwd=out,
            env=RUN_ENV,
            capture_output=True,
            text=True,
            timeout=RUN_TIMEOUT_S,
        )
        if run.returncode != 0:
            raise RuntimeError(f"examples/{script.name} failed in the docs build:\n{run.stdout}{run.stderr}")
        (out / f"{script.stem}.txt").write_text(run.stdout)


# The studies whose reports the site shows, one page per study (docs/papers.md).  By default these
# are reproduced from this checkout by `robomech reproduce` during the build and reused by later
# builds until a source file changes: the demonstration and paper 1 (spherical leg), 9 s and 54 s
# on the shared machine, where continuum and skid-steer took 736 s and 536 s.  With
# ROBOMECH_DOCS_REPORTS=DIR (`make docs REPORTS=out` after `make run`) every study folder of an
# existing `robomech reproduce --out DIR` is shown instead.
PAPER_STUDIES = ("demo", "spherical-leg")
REPORTS_DIR = os.environ.get("ROBOMECH_DOCS_REPORTS", "")
PAPERS = ROOT / "docs" / "papers"
_DROP_LINE = re.compile(r"^\[(← all studies|↑ contents)\]")


def _paper_page(study: str, report_md: str) -> str:
    """The study's report.md as a page of this site: the report's own navigation (back links to its
    index, its table of contents) is dropped; Sphinx gives the page its contents and navigation."""
    lines, skip = [], False
    for line in report_md.splitlines():
        if line.startswith("## "):
            skip = line.strip() == "## Contents"
        if skip or _DROP_LINE.match(line):
            continue
        lines.append(line)
    title, rest = lines[0], "\n".join(lines[1:])
    note = (
        f"*Reproduced by `robomech reproduce {study}` when this site was built; the run's data:* "
        "{download}`results.json <results.json>`"
    )
    return f"{title}\n\n{note}\n{rest}\n"


def _report_is_current(report: Path) -> bool:
    """A report from an earlier build is reused while no source file is newer than it."""
    if not report.exists():
        return False
    newest = max(p.stat().st_mtime for p in (ROOT / "src" / "robomech").rglob("*") if p.is_file())
    return report.stat().st_mtime > newest


def _paper_pages() -> None:
    if REPORTS_DIR:
        reports = Path(REPORTS_DIR).resolve()
        studies = sorted(p.parent.name for p in reports.glob("*/report.md"))
        if not studies:
            raise RuntimeError(f"ROBOMECH_DOCS_REPORTS={REPORTS_DIR}: no <study>/report.md in it")
    else:
        reports, studies = BUILD / "reports", list(PAPER_STUDIES)
        stale = [s for s in studies if not _report_is_current(reports / s / "report.md")]
        if stale:
            subprocess.run(
                [sys.executable, "-m", "robomech", "reproduce", *stale, "--out", str(reports), "--quiet"],
                env=RUN_ENV,
                check=True,
                timeout=RUN_TIMEOUT_S,
                stdout=subprocess.DEVNULL,  # the "report index: ..." line; errors still reach stderr
            )
    shutil.rmtree(PAPERS, ignore_errors=True)
    for study in studies:
        src, dst = reports / study, PAPERS / study
        dst.mkdir(parents=True)
        for f in src.iterdir():
            if f.suffix in (".png", ".svg", ".gif", ".json"):
                shutil.copy2(f, dst / f.name)
        page = _paper_page(study, (src / "report.md").read_text(encoding="utf-8"))
        (dst / "index.md").write_text(page, encoding="utf-8")

