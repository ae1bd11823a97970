"""Sphinx configuration of the robomech documentation (`make docs`)."""

import importlib
import importlib.util
import inspect
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
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "_templates"]
templates_path = ["_templates"]
root_doc = "index"

# autodoc: members are the public __all__; types are documented in the numpydoc sections (the
# signatures' annotations are often `object` for array-likes and would only add noise).
autodoc_default_options = {"member-order": "bysource", "show-inheritance": False}
autodoc_typehints = "none"
autodoc_mock_imports: list[str] = []
# autosummary: one page per public function and class (docs/api/generated/, from the pages that
# _api_pages writes from each module's __all__; templates in docs/_templates/autosummary/).
autosummary_ignore_module_all = False
# numpydoc: no per-class member tables (autodoc lists members) and no type cross-references (no
# intersphinx: the docs build offline).
numpydoc_show_class_members = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()

# Markdown pages: $...$ and $$...$$ (and ```{math} blocks) are LaTeX math.
myst_enable_extensions = ["dollarmath", "amsmath", "substitution"]
myst_heading_anchors = 3


def _citation_md(paper) -> str:
    """A paper's citation as Markdown: title in italics, the DOI as a link."""
    text = f"{', '.join(paper.authors)}: *{paper.title}*. {paper.venue}, {paper.year}"
    text += f", pp. {paper.pages}" if paper.pages else ""
    return text + (f". [doi:{paper.doi}](https://doi.org/{paper.doi})" if paper.doi else "")


# {{ paper1 }} ... {{ paper5 }}: each paper's citation, from the one table the reports use too
# (robomech/studies/_papers.py).
from robomech.studies._papers import PAPERS as _CITED  # noqa: E402

myst_substitutions = {f"paper{n}": _citation_md(p) for n, p in _CITED.items()}

html_theme = "pydata_sphinx_theme"
# The light/dark mode a first visit starts in (unset, the theme logs a console error on every fresh load).
html_context = {"default_mode": "auto"}
html_title = f"robomech {release}"
html_theme_options = {
    "show_toc_level": 2,
    "navigation_with_keys": False,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
# No left sidebar on pages without sub-pages (it would show an empty "Section Navigation").
html_sidebars = {
    name: []
    for name in ("index", "usage", "conventions", "architecture", "performance", "reports", "multibody",
                 "dynamics", "explore", "viewer", "mechanisms/*")
}  # fmt: skip
html_static_path = ["_static", "_build/vendor"]
html_css_files = ["robomech.css"]
html_js_files = ["robomech.js"]

# Math is rendered by MathJax served from this site (no CDN: the site works offline).  MathJax is
# not a Python package: the build installs the pinned npm release into docs/_build/npm with the
# machine's npm (Node.js) once, and copies its self-contained SVG build into _static/mathjax/.
MATHJAX_VERSION = "3.2.2"
mathjax_path = "mathjax/tex-svg.js"

# sphinx-gallery: examples/*.py run at build time; each page shows the script, its printed output
# and its figures.  Every script runs (not only plot_*.py); MuJoCo-only scripts are skipped where
# the engine is missing.
EXAMPLES_NEED_MUJOCO = {"verify_against_mujoco.py", "four_bar_from_mjcf.py"}
_HAVE_MUJOCO = importlib.util.find_spec("mujoco") is not None
sphinx_gallery_conf = {
    "examples_dirs": "../examples",
    "gallery_dirs": "examples",
    "filename_pattern": r".*\.py$",
    "ignore_pattern": r"__init__\.py|^_" if _HAVE_MUJOCO else "|".join(map(re.escape, EXAMPLES_NEED_MUJOCO)),
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "plot_gallery": "True",
    "matplotlib_animations": False,
    "within_subsection_order": "FileNameSortKey",
    "show_memory": False,
    "show_signature": False,
}

# Docstrings are written for readers of the source: |x| means an absolute value or a norm, not a
# reStructuredText substitution.  Escape the bars outside ``literals`` before docutils sees them.
_LITERAL = re.compile(r"(``.*?``|`[^`]*`)")


# Inside a literal, a dot product ``a . b`` or an ellipsis ``x ... y`` is written with the symbol
# (· and …): autosummary ends a summary at the first ". ", which would cut the literal open.
_LITERAL_DOTS = re.compile(r"(?<=\S) \. (?=\S)|(?<=\S) ?\.\.\.(?= )")


def _literal_dots(part: str) -> str:
    return _LITERAL_DOTS.sub(lambda m: " · " if m.group().strip() == "." else " …", part)


def _escape_bars(app, what, name, obj, options, lines):
    for i, line in enumerate(lines):
        if "|" in line or "." in line:
            parts = _LITERAL.split(line)
            lines[i] = "".join(
                _literal_dots(p) if k % 2 else p.replace("|", r"\|") for k, p in enumerate(parts)
            )


def _generate(app, config) -> None:
    _vendor_mathjax()
    _api_pages()
    _paper_pages()
    _mechanism_pages()


def setup(app):
    app.connect("autodoc-process-docstring", _escape_bars)
    # before Sphinx looks for the source files (the generated pages must be among them)
    app.connect("config-inited", _generate)


# No intersphinx (this project builds offline): references into the standard library and
# unparsed generic annotations cannot resolve, and are the only nitpicks ignored.
nitpick_ignore = [("py:class", "collections.abc.Mapping")]
nitpick_ignore_regex = [("py:class", r"'?(list|dict|tuple)\[.*")]


# ----------------------------------------------------------------------------- generated at build time
# Nothing below is committed: MathJax goes to docs/_build/vendor/, the API pages to docs/api/
# (robomech.*.rst, generated/), the studies' reports to docs/_build/reports/ and their pages to
# docs/papers/, the mechanism pages to docs/mechanisms/gallery/ (all git-ignored), rebuilt by every
# `make docs` from this checkout's source.
BUILD = ROOT / "docs" / "_build"
RUN_ENV = dict(
    os.environ,
    PYTHONPATH=os.pathsep.join(p for p in (str(ROOT / "src"), os.environ.get("PYTHONPATH", "")) if p),
    MPLBACKEND="Agg",
)
# Seconds before a hung study (or the one-time MathJax install) fails the build.
RUN_TIMEOUT_S = 900


def _vendor_mathjax() -> None:
    """MathJax's self-contained SVG build and its TeX extensions, in docs/_build/vendor/mathjax/."""
    vendor = BUILD / "vendor" / "mathjax"
    if (vendor / "tex-svg.js").exists():
        return
    es5 = BUILD / "npm" / "node_modules" / "mathjax" / "es5"
    if not (es5 / "tex-svg.js").exists():
        npm = shutil.which("npm")
        if npm is None:
            raise RuntimeError(
                "the docs render math with MathJax, installed from npm once per checkout: "
                "install Node.js and npm (Debian: apt-get install npm), then run make docs again"
            )
        subprocess.run(
            [npm, "install", "--no-save", "--no-audit", "--no-fund", "--prefix", str(BUILD / "npm"),
             f"mathjax@{MATHJAX_VERSION}"],
            check=True, timeout=RUN_TIMEOUT_S, stdout=subprocess.DEVNULL,
        )  # fmt: skip
    vendor.mkdir(parents=True, exist_ok=True)
    shutil.copy2(es5 / "tex-svg.js", vendor / "tex-svg.js")
    for sub in ("input/tex/extensions", "ui", "a11y"):
        if (es5 / sub).is_dir():
            shutil.copytree(es5 / sub, vendor / sub, dirs_exist_ok=True)


# The modules of the API reference, in reading order: each gets a page listing its public names
# (its __all__), and each public function and class its own page.
API_MODULES = (
    "robomech.spatial",
    "robomech.kinematics",
    "robomech.trajectory",
    "robomech.dynamics",
    "robomech.analysis",
    "robomech.analysis.lstsq",
    "robomech.analysis.mobility",
    "robomech.analysis.workspace",
    "robomech.multibody",
    "robomech.multibody.gallery",
    "robomech.viewer",
    "robomech.mechanisms",
    "robomech.mechanisms.spherical_leg",
    "robomech.mechanisms.omnileg",
    "robomech.mechanisms.continuum",
    "robomech.mechanisms.skid_steer",
    "robomech.mechanisms.vectored_thrust",
    "robomech.explore",
    "robomech.verify",
    "robomech.studies",
    "robomech.testing",
    "robomech.cli",
)
API = ROOT / "docs" / "api"
# The pages autosummary writes stubs for, named (not "every source file": in an incremental build
# that is the previous build's list, which lacks a module page added since).
autosummary_generate = [f"api/{name}.rst" for name in API_MODULES]


def _public_names(module_name: str) -> dict[str, list[str]]:
    """The module's __all__ sorted into classes, functions, submodules and constants."""
    module = importlib.import_module(module_name)
    kinds: dict[str, list[str]] = {"classes": [], "functions": [], "modules": [], "constants": []}
    for name in getattr(module, "__all__", ()):
        obj = getattr(module, name)
        if inspect.ismodule(obj):
            kinds["modules"].append(obj.__name__)
        elif inspect.isclass(obj):
            kinds["classes"].append(name)
        elif callable(obj):
            kinds["functions"].append(name)
        else:
            kinds["constants"].append(name)
    return kinds


def _api_page(module_name: str) -> str:
    kinds = _public_names(module_name)
    lines = [module_name, "=" * len(module_name), "", f".. automodule:: {module_name}", "   :no-members:", ""]
    lines += [f".. currentmodule:: {module_name}", ""]
    for kind, title in (("classes", "Classes"), ("functions", "Functions")):
        if kinds[kind]:
            lines += [title, "-" * len(title), "", ".. autosummary::", "   :toctree: generated",
                      "   :nosignatures:", "", *(f"   {n}" for n in kinds[kind]), ""]  # fmt: skip
    if kinds["constants"]:
        lines += ["Constants", "---------", ""]
        for n in kinds["constants"]:
            value = getattr(importlib.import_module(module_name), n)
            lines += [f".. autodata:: {n}"]
            lines += ["   :no-value:"] if isinstance(value, dict) else []
            lines += [""]
    if kinds["modules"]:
        lines += ["Submodules", "----------", ""]
        lines += [f"- :mod:`{m}`" for m in kinds["modules"]] + [""]
    return "\n".join(lines)


def _api_pages() -> None:
    for old in API.glob("robomech.*.rst"):
        old.unlink()
    for module_name in API_MODULES:
        (API / f"{module_name}.rst").write_text(_api_page(module_name), encoding="utf-8")


# ----------------------------------------------------------------------------- the studies' reports
# One page per registered study (docs/papers.md), each the report of `robomech reproduce NAME` run
# from this checkout during the build, into docs/_build/reports/ (git-ignored), and reused by later
# builds until a source file changes.  Measured on this 2-core machine shared with other jobs (load
# 4-8): skid-steer 178 s (its MuJoCo manoeuvres), continuum 21 s, the five others 25 s together.  A
# study whose optional dependencies are missing gets a page that says what it reproduces and how to
# run it.  With ROBOMECH_DOCS_REPORTS=DIR (`make docs REPORTS=out` after `make run`) the reports of
# that `robomech reproduce --out DIR` folder are shown instead of reproducing them.
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
        f"*Reproduced by `robomech reproduce {study}`; the run's data:* "
        "{download}`results.json <results.json>`"
    )
    return f"{title}\n\n{note}\n{rest}\n"


def _study_placeholder(study, why: str) -> str:
    """The page of a study whose report this build does not have: what it reproduces and how."""
    module = inspect.getmodule(study.run)
    doc = inspect.cleandoc(module.__doc__ or "")
    needs = f" It needs `{', '.join(study.requires)}` (an optional extra)." if study.requires else ""
    from robomech.studies._papers import PAPERS as CITED

    source = next((p.citation() for p in CITED.values() if p.short() == study.source), study.source)
    return (
        f"# {study.title}\n\n*Source:* {source}\n\n```{{note}}\n{why}{needs} To see its report "
        "here: install what it needs and run `make docs` again.\n```\n\n"
        f"## What the study reproduces\n\n{_rst_to_md(doc)}\n"
    )


def _rst_to_md(text: str) -> str:
    """A module docstring's reStructuredText literals (``x``) as Markdown code (`x`)."""
    return text.replace("``", "`")


def _report_is_current(report: Path) -> bool:
    """A report from an earlier build is reused while no source file is newer than it."""
    if not report.exists():
        return False
    newest = max(p.stat().st_mtime for p in (ROOT / "src" / "robomech").rglob("*") if p.is_file())
    return report.stat().st_mtime > newest


def _paper_pages() -> None:
    from robomech.studies import available_studies

    studies = available_studies()
    given = Path(REPORTS_DIR).resolve() if REPORTS_DIR else None
    if given is not None and not any(given.glob("*/report.md")):
        raise RuntimeError(f"ROBOMECH_DOCS_REPORTS={REPORTS_DIR}: no <study>/report.md in it")
    reports = BUILD / "reports"
    run = [s for s in studies if given is None or not (given / s / "report.md").exists()]
    run = [s for s in run if all(importlib.util.find_spec(m) for m in studies[s].requires)]
    stale = [s for s in run if not _report_is_current(reports / s / "report.md")]
    if stale:
        subprocess.run(
            [sys.executable, "-m", "robomech", "reproduce", *stale, "--out", str(reports), "--quiet"],
            env=RUN_ENV,
            check=True,
            timeout=RUN_TIMEOUT_S,
            stdout=subprocess.DEVNULL,  # the "report index: ..." line; errors still reach stderr
        )
    from robomech.studies._papers import PAPERS as CITED

    BUILD.mkdir(parents=True, exist_ok=True)
    (BUILD / "papers-cited.md").write_text(
        "\n".join(f"{p.number}. {_citation_md(p)}" for p in CITED.values()) + "\n", encoding="utf-8"
    )

    # the pages in reading order: the demonstration, the papers by number, then the rest
    def order(name: str) -> tuple[int, str]:
        m = re.match(r"Paper (\d+)", studies[name].title)
        return (int(m.group(1)) if m else (0 if name == "demo" else 99), name)

    pages = [f"papers/{n}/index" for n in sorted(studies, key=order)]
    toc = ["```{toctree}", ":maxdepth: 1", "", *pages, "```"]
    (BUILD / "papers-toc.md").write_text("\n".join(toc) + "\n", encoding="utf-8")
    shutil.rmtree(PAPERS, ignore_errors=True)
    for name, study in studies.items():
        dst = PAPERS / name
        dst.mkdir(parents=True)
        src = given / name if given is not None and (given / name / "report.md").exists() else reports / name
        if name in run or src.parent == given:
            for f in src.iterdir():
                if f.suffix in (".png", ".svg", ".gif", ".json"):
                    shutil.copy2(f, dst / f.name)
            page = _paper_page(name, (src / "report.md").read_text(encoding="utf-8"))
        else:
            page = _study_placeholder(study, "This build could not run the study.")
        (dst / "index.md").write_text(page, encoding="utf-8")


# ----------------------------------------------------------------------------- the gallery mechanisms
# One page per MJCF file of robomech.multibody.gallery: its header comment, its mobility and a
# picture drawn by mb.draw at the reference configuration.
GALLERY_PAGES = ROOT / "docs" / "mechanisms" / "gallery"


def _mechanism_pages() -> None:
    import matplotlib

    matplotlib.use("Agg")  # this build process only; the library never switches backends
    import matplotlib.pyplot as plt

    from robomech import multibody as mb

    shutil.rmtree(GALLERY_PAGES, ignore_errors=True)
    GALLERY_PAGES.mkdir(parents=True)
    for name in mb.gallery.NAMES:
        xml = mb.gallery.path(name).read_text(encoding="utf-8")
        comment = re.search(r"<!--(.*?)-->", xml, re.S)
        about = " ".join(comment.group(1).split()) if comment else ""
        about = about.replace(" Generated by robomech.multibody.gallery.", "")
        if _HAVE_MUJOCO:
            mech = mb.gallery.load(name)
        elif name in mb.gallery.BUILDERS:
            mech = mb.gallery.BUILDERS[name]()
        else:
            mech = None
        label = re.split(r", base| with |\. |: ", about, maxsplit=1)[0]
        lines = [f"# {label} (`{name}`)" if label else f"# `{name}`", "", about, ""]
        if mech is not None:
            m = mb.mobility(mech)
            ax = mb.draw(mech, title=f"{name} at its reference configuration")
            ax.figure.savefig(GALLERY_PAGES / f"{name}.png", dpi=110, bbox_inches="tight")
            plt.close(ax.figure)
            lines += [
                f"![{name} drawn by robomech.multibody.draw]({name}.png)",
                "",
                "| quantity | value |",
                "|:---|---:|",
                f"| bodies | {len(mech.bodies)} |",
                f"| actuated joints | {', '.join(mech.actuated)} |",
                f"| loop closures | {len(mech.closures)} |",
                f"| degrees of freedom (reciprocal screws) | {m.dof} |",
                f"| Grübler–Kutzbach count | {m.gruebler_kutzbach} |",
                "",
            ]
        else:
            lines += ["(The picture needs MuJoCo, `robomech[verify]`, to read the MJCF file.)", ""]
        lines += [
            "Use it:",
            "",
            "```python",
            "from robomech import multibody as mb",
            f'mech = mb.gallery.load("{name}")   # or mb.from_mjcf(mb.gallery.path("{name}"))',
            "m = mb.mobility(mech)          # .dof, .redundant_constraints, .gruebler_kutzbach",
            "mb.draw(mech)                  # the picture above",
            "```",
            "",
            f"From the command line: `robomech verify {name}` checks it against MuJoCo.",
            "",
        ]
        (GALLERY_PAGES / f"{name}.md").write_text("\n".join(lines), encoding="utf-8")
