"""Sphinx configuration of the robomech documentation (`make docs`)."""

import re
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


def setup(app):
    app.connect("autodoc-process-docstring", _escape_bars)


# No intersphinx (this project builds offline): references into the standard library and
# unparsed generic annotations cannot resolve, and are the only nitpicks ignored.
nitpick_ignore = [("py:class", "collections.abc.Mapping")]
nitpick_ignore_regex = [("py:class", r"'?(list|dict|tuple)\[.*")]
