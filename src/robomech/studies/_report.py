"""Writing a study's report (Markdown, HTML, JSON) and the index that links every study in a folder.

``report.md`` is the source: Markdown written from the :class:`StudyResult` (summary and notes are
Markdown as the studies write them).  ``report.html`` is that Markdown rendered by the ``markdown``
library (tables, table of contents, anchors) inside the Jinja2 template ``templates/page.html``.
``results.json`` is strict JSON (no NaN) and carries the provenance; the index is rebuilt from every
``*/results.json`` in the output folder, so reproducing one study never hides another.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any

from robomech._validation import check_params, check_real
from robomech.verify._core import dumps_json
from robomech.verify._store import reading

from ._core import Printed, Progress, Study, StudyResult, Table

__all__ = [
    "INDEX_NAME",
    "VERIFICATION_FILE",
    "format_cell",
    "provenance",
    "publish_study",
    "remove_stale_temporaries",
    "render_html",
    "write_index",
    "write_study_report",
    "write_verification",
]

INDEX_NAME = "index"
# `robomech verify --out DIR` writes the checks here; the index shows each mechanism's status from it.
VERIFICATION_FILE = "verification.json"
_TMP_PREFIX = ".robomech-tmp-"


def format_cell(value: Any) -> str:
    """Text of one table cell: paper values verbatim, floats to 6 significant digits, bools yes/no."""
    if isinstance(value, Printed):
        return value.text
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            return str(value)
        if value == 0.0:
            return "0"
        a = abs(value)
        if 1e-3 <= a < 1e5:
            return f"{value:.6g}"
        return f"{value:.4e}"
    return str(value)


# ---- provenance -------------------------------------------------------------------------------------


def _git_commit() -> str | None:
    """The commit of the source tree robomech runs from, ``-dirty`` if modified; None outside git."""
    here = Path(__file__).resolve().parent
    try:
        out = subprocess.run(
            ["git", "-C", str(here), "rev-parse", "HEAD"], capture_output=True, text=True, timeout=5
        )
        if out.returncode != 0:
            return None
        commit = out.stdout.strip()
        dirty = subprocess.run(
            ["git", "-C", str(here), "status", "--porcelain", "--untracked-files=no"],
            capture_output=True,
            text=True,
            timeout=5,
        )
        return commit + ("-dirty" if dirty.returncode == 0 and dirty.stdout.strip() else "")
    except (OSError, subprocess.SubprocessError):
        return None


def provenance() -> dict[str, Any]:
    """Who made a result: robomech version, git commit (if run from a checkout), UTC date, machine."""
    import numpy

    from robomech import __version__

    versions = {"python": platform.python_version(), "numpy": numpy.__version__}
    if "mujoco" in sys.modules:
        versions["mujoco"] = getattr(sys.modules["mujoco"], "__version__", "?")
    return {
        "robomech": __version__,
        "git_commit": _git_commit(),
        "date_utc": _dt.datetime.now(_dt.UTC).replace(microsecond=0).isoformat(),
        "machine": {
            "platform": platform.platform(),
            "processor": platform.machine(),
            "cpus_visible": len(os.sched_getaffinity(0))
            if hasattr(os, "sched_getaffinity")
            else os.cpu_count(),
        },
        "versions": versions,
    }


def _provenance_line(p: Mapping[str, Any]) -> str:
    commit = p.get("git_commit") or "not a git checkout"
    m = p.get("machine", {})
    return (
        f"robomech {p.get('robomech', '?')} · commit `{commit}` · {p.get('date_utc', '?')} · "
        f"{m.get('platform', '?')}, {m.get('cpus_visible', '?')} CPUs visible · "
        + ", ".join(f"{k} {v}" for k, v in p.get("versions", {}).items())
    )


# ---- Markdown ---------------------------------------------------------------------------------------


def _slug(text: str, seen: dict[str, int]) -> str:
    from markdown.extensions.toc import slugify_unicode

    base = slugify_unicode(text, "-") or "section"
    n = seen.get(base, 0)
    seen[base] = n + 1
    return base if n == 0 else f"{base}_{n}"  # the toc extension's rule for repeated titles


def _cell_md(value: Any) -> str:
    return format_cell(value).replace("|", "\\|").replace("\n", " ")


def _numeric(t: Table, j: int) -> bool:
    cells = [row[j] for row in t.rows if row[j] not in ("—", "", None)]
    return bool(cells) and all(
        isinstance(c, int | float | Printed) and not isinstance(c, bool) for c in cells
    )


def _short(text: str, limit: int = 70) -> str:
    text = " ".join(text.split())
    if len(text) <= limit:
        return text
    return text[: text.rfind(" ", 0, limit)].rstrip(",;:") + " …"


def _md_table(t: Table) -> list[str]:
    lines = ["| " + " | ".join(str(c).replace("|", "\\|") for c in t.columns) + " |"]
    # alignment in the Markdown itself (GitHub and the HTML agree): a column of numbers to the right
    lines.append("|" + "|".join("---:" if _numeric(t, j) else ":---" for j in range(len(t.columns))) + "|")
    lines += ["| " + " | ".join(_cell_md(c) for c in row) + " |" for row in t.rows]
    if t.note:
        lines += ["", t.note]
    return lines


def _report_markdown(result: StudyResult, prov: Mapping[str, Any], ext: str) -> str:
    """The report as Markdown; ``ext`` (``md`` or ``html``) is the suffix of the links between pages."""
    seen: dict[str, int] = {}
    _slug(result.title, seen)
    contents_id = _slug("Contents", seen)
    back = f"[↑ contents](#{contents_id}) · [all studies](../{INDEX_NAME}.{ext})"
    sections: list[tuple[str, str, list[str]]] = []  # (level, title, lines)
    if result.summary:
        sections.append(("##", "Summary", [result.summary.strip()]))
    if result.tables:
        sections.append(("##", "Tables", []))
        for t in result.tables:
            sections.append(("###", t.title, _md_table(t)))
    if result.figures:
        sections.append(("##", "Figures", []))
        for k, f in enumerate(result.figures, 1):
            alt = (f.alt or f.caption).replace("[", "(").replace("]", ")").replace("\n", " ")
            lines = [f"![{alt}]({f.path.name})", "", f"*Figure {k}:* {f.caption}"]
            sections.append(("###", f"Figure {k}: {_short(f.caption)}", lines))
    if result.notes:
        sections.append(("##", "Notes", [f"- {n}" for n in result.notes]))

    md = [f"# {result.title}", "", f"[← all studies](../{INDEX_NAME}.{ext})", ""]
    md += [f"*Source:* {result.source}", "", f"*Provenance:* {_provenance_line(prov)}", ""]
    md += ["## Contents", ""]
    ids = [_slug(title, seen) for _, title, _ in sections]
    for (level, title, _), sid in zip(sections, ids, strict=True):
        indent = "    " if level == "###" else ""
        md.append(f"{indent}- [{title.replace('[', '(').replace(']', ')')}](#{sid})")
    md.append("")
    for level, title, lines in sections:
        md += [f"{level} {title}", ""]
        if lines:
            md += [*lines, "", back, ""]
    return "\n".join(md)


def render_html(markdown_text: str, title: str) -> str:
    """A full HTML page: ``markdown_text`` rendered by the ``markdown`` library in the page template."""
    import jinja2
    import markdown
    from markdown.extensions.toc import slugify_unicode

    from robomech import __version__

    body = markdown.markdown(
        markdown_text,
        extensions=["tables", "toc", "sane_lists"],
        extension_configs={"toc": {"slugify": slugify_unicode}},
        output_format="html",
    )
    env = jinja2.Environment(
        loader=jinja2.PackageLoader("robomech.studies", "templates"),
        autoescape=jinja2.select_autoescape(["html"]),
    )
    return env.get_template("page.html").render(
        title=title, body=jinja2.utils.markupsafe.Markup(body), version=__version__
    )


def _payload(result: StudyResult, prov: Mapping[str, Any], seconds: float | None) -> dict[str, Any]:
    def cell(c: Any) -> Any:
        return c.value if isinstance(c, Printed) else c

    return {
        "name": result.name,
        "title": result.title,
        "source": result.source,
        "seconds": seconds,
        "provenance": dict(prov),
        "summary": result.summary,
        "tables": [
            {
                "title": t.title,
                "columns": list(t.columns),
                "rows": [[cell(c) for c in row] for row in t.rows],
                # the paper's strings for the cells that were printed values (row, column) -> text
                "printed": [
                    [i, j, c.text]
                    for i, row in enumerate(t.rows)
                    for j, c in enumerate(row)
                    if isinstance(c, Printed)
                ],
                "note": t.note,
            }
            for t in result.tables
        ],
        "figures": [
            {"file": f.path.name, "caption": f.caption, "alt": f.alt or f.caption} for f in result.figures
        ],
        "notes": result.notes,
        "data": result.data,
    }


def _as_path(p: object, name: str) -> Path:
    if not isinstance(p, str | os.PathLike) or str(p) == "":
        raise ValueError(f"Expected {name} to be a non-empty path, got {p!r}.")
    return Path(p)


def write_study_report(
    result: StudyResult, out_dir: Path, *, seconds: float | None = None, prov: Mapping[str, Any] | None = None
) -> dict[str, Path]:
    """Write ``report.md``, ``report.html`` and ``results.json`` (strict JSON) into ``out_dir``.

    Parameters
    ----------
    result : StudyResult
        What the study returned.
    out_dir : path
        The study's folder (created if needed); its figures are already there.
    seconds : float, optional
        Run time of the study (s), recorded in ``results.json`` and shown in the index.
    prov : mapping, optional
        Provenance to record (default: ``provenance()`` of this process).

    Returns
    -------
    dict
        Paths ``md``, ``html`` and ``json`` of the three files.
    """
    check_params(result, StudyResult, "result")
    out_dir = _as_path(out_dir, "out_dir")
    if seconds is not None:
        seconds = check_real(seconds, "seconds", low=0.0)
    if prov is not None and not isinstance(prov, Mapping):
        raise ValueError(f"Expected prov to be a mapping (see provenance()), got {type(prov).__name__}.")
    out_dir.mkdir(parents=True, exist_ok=True)
    prov = provenance() if prov is None else prov
    text = dumps_json(_payload(result, prov, seconds))  # first: a non-JSON value fails before any write
    (out_dir / "report.md").write_text(_report_markdown(result, prov, "md"), encoding="utf-8")
    (out_dir / "report.html").write_text(
        render_html(_report_markdown(result, prov, "html"), result.title), encoding="utf-8"
    )
    (out_dir / "results.json").write_text(text, encoding="utf-8")
    return {"md": out_dir / "report.md", "html": out_dir / "report.html", "json": out_dir / "results.json"}


# ---- atomic publication -----------------------------------------------------------------------------


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _atomic_write(path: Path, text: str) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=_TMP_PREFIX)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp's 0600 is for the temporary, not the result
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def remove_stale_temporaries(out_root: Path) -> None:
    """Remove the temporary folders an earlier, killed run left behind (only robomech's own)."""
    for p in out_root.glob(_TMP_PREFIX + "*"):
        if p.is_dir():
            shutil.rmtree(p, ignore_errors=True)
        else:
            p.unlink(missing_ok=True)


def publish_study(
    study: Study,
    out_root: Path,
    progress: Progress,
    clock: Callable[[], float] | None = None,
) -> dict[str, Any]:
    """Run ``study`` in a temporary folder under ``out_root`` and move it to ``out_root/<name>``.

    The folder of a study is therefore either the complete previous run or the complete new one,
    never a mix, also when the run is interrupted (the temporary folder is removed).  The study reads
    the verification results that ``robomech verify --out out_root`` stored, where they were computed
    by the same code with the same parameters (:mod:`robomech.verify._store`), and computes the rest.

    Returns
    -------
    dict
        ``study``, ``seconds``, and the paths ``report`` (Markdown), ``html`` and ``json``.
    """
    import time

    clock = clock or time.perf_counter
    tmp = Path(tempfile.mkdtemp(dir=out_root, prefix=f"{_TMP_PREFIX}{study.name}-"))
    final = out_root / study.name
    old = None
    try:
        t0 = clock()
        with reading(out_root):
            result = study.run(tmp, progress)
        seconds = clock() - t0
        write_study_report(result, tmp, seconds=seconds)
        if final.exists():
            old = Path(tempfile.mkdtemp(dir=out_root, prefix=f"{_TMP_PREFIX}{study.name}-old-"))
            os.replace(final, old / "previous")
        os.chmod(tmp, 0o777 & ~_umask())  # mkdtemp's 0700 is for the temporary, not the result
        os.replace(tmp, final)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
        if old is not None:
            if not final.exists() and (old / "previous").exists():  # never lose the previous run
                os.replace(old / "previous", final)
            shutil.rmtree(old, ignore_errors=True)
    return {
        "study": study.name,
        "seconds": seconds,
        "report": final / "report.md",
        "html": final / "report.html",
        "json": final / "results.json",
    }


# ---- index ------------------------------------------------------------------------------------------


def _read_results(out_root: Path) -> list[dict[str, Any]]:
    found = []
    for path in sorted(out_root.glob("*/results.json")):
        if path.parent.name.startswith("."):
            continue
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue  # not ours or unreadable: the index lists what it can read
        if isinstance(data, dict) and data.get("name") == path.parent.name:
            found.append(data)
    return found


def _verification_status(out_root: Path) -> tuple[dict[str, str], str | None]:
    path = out_root / VERIFICATION_FILE
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}, None
    status: dict[str, list[str]] = {}
    for c in data.get("checks", []):  # "status": pass, FAIL, n/a or inconclusive (older files: "passed")
        s = c.get("status") or ("pass" if c.get("passed") else "FAIL")
        status.setdefault(str(c.get("mechanism")), []).append(str(s))
    out = {}
    for m, v in status.items():
        rest = "".join(f", {v.count(s)} {s}" for s in sorted(set(v) - {"pass", "FAIL"}))
        fails = v.count("FAIL")
        out[m] = f"FAIL ({fails} of {len(v)} checks{rest})" if fails else f"pass ({len(v)} checks{rest})"
    for s in data.get("skipped", []):
        out[str(s.get("mechanism"))] = f"skipped: {s.get('reason')}"
    return out, (data.get("provenance") or {}).get("date_utc")


def write_index(
    out_root: Path,
    studies: Mapping[str, Study] | None = None,
    skipped: Iterable[tuple[str, str]] = (),
) -> Path:
    """Rebuild ``index.md`` and ``index.html`` from every ``*/results.json`` in ``out_root``.

    Parameters
    ----------
    out_root : Path
        The output folder of ``robomech reproduce``.
    studies : mapping, optional
        Registered studies by name; those without results are listed as not reproduced.
    skipped : iterable of (name, reason)
        Studies skipped in this run (e.g. the engine is not installed), listed with the reason.

    Returns
    -------
    Path
        ``out_root / "index.md"`` (``index.html`` beside it).
    """
    out_root = _as_path(out_root, "out_root")
    if studies is not None and not (
        isinstance(studies, Mapping) and all(isinstance(v, Study) for v in studies.values())
    ):
        raise ValueError(f"Expected studies to be a mapping name -> Study (or None), got {studies!r}.")
    if isinstance(skipped, str | bytes) or not isinstance(skipped, Iterable):
        raise ValueError(f"Expected skipped to be (name, reason) pairs, got {skipped!r}.")
    skipped = list(skipped)
    for i, pair in enumerate(skipped):
        if not (isinstance(pair, tuple) and len(pair) == 2 and all(isinstance(x, str) for x in pair)):
            raise ValueError(f"Expected skipped[{i}] to be a (name, reason) pair of str, got {pair!r}.")
    if not out_root.is_dir():
        raise ValueError(f"Expected out_root to be an existing folder, got {str(out_root)!r}.")
    results = _read_results(out_root)
    verified, verified_at = _verification_status(out_root)
    skipped_by_name = dict(skipped)
    md = ["# robomech — paper reproductions", ""]
    md += [
        "Each row is one study folder; a study's folder is always one complete run (its date and "
        "provenance are in the row). Verification status comes from `robomech verify --out "
        f"{out_root.name}`" + (f" (run {verified_at})." if verified_at else " (not run yet)."),
        "",
        "| study | title | verification | figures | tables | time (s) | run (UTC) | robomech | commit |",
        "|:---|:---|:---|---:|---:|---:|:---|:---|:---|",
    ]
    for r in results:
        p = r.get("provenance") or {}
        secs = r.get("seconds")
        full = str(p.get("git_commit") or "—")
        commit = full[:12] + ("-dirty" if full.endswith("-dirty") else "")
        md.append(
            "| [{n}]({n}/report.{{ext}}) | {t} | {v} | {f} | {tb} | {s} | {d} | {ver} | `{c}` |".format(
                n=r["name"],
                t=str(r.get("title", "")).replace("|", "\\|"),
                v=verified.get(r["name"], "—"),
                f=len(r.get("figures", [])),
                tb=len(r.get("tables", [])),
                s=f"{secs:.1f}" if isinstance(secs, int | float) else "—",
                d=str(p.get("date_utc", "—")).replace("T", " ").removesuffix("+00:00"),
                ver=p.get("robomech", "—"),
                c=commit,
            )
        )
    present = {r["name"] for r in results}
    missing = [
        (n, skipped_by_name.get(n) or "not reproduced yet: `robomech reproduce " + n + "`")
        for n in (studies or {})
        if n not in present
    ]
    missing += [
        (n, why) for n, why in skipped_by_name.items() if n not in present and n not in (studies or {})
    ]
    if missing:
        md += ["", "## Not in this folder", ""] + [f"- **{n}** — {why}" for n, why in missing]
    md.append("")
    template = "\n".join(md)
    index_md = out_root / f"{INDEX_NAME}.md"
    _atomic_write(index_md, template.replace("{ext}", "md"))
    _atomic_write(
        out_root / f"{INDEX_NAME}.html",
        render_html(template.replace("{ext}", "html"), "robomech — paper reproductions"),
    )
    return index_md


def write_verification(out_root: Path, report_dict: Mapping[str, Any]) -> Path:
    """Save a verification report (``VerificationReport.as_dict()``) with provenance for the index."""
    path = out_root / VERIFICATION_FILE
    _atomic_write(path, dumps_json({**report_dict, "provenance": provenance()}))
    return path
