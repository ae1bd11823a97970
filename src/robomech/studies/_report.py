"""Writing a study's report (Markdown, HTML, JSON) and the index that links them."""

from __future__ import annotations

import html
import json
import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from robomech._validation import check_params, check_real

from ._core import StudyResult, Table, to_jsonable

__all__ = ["format_cell", "write_index", "write_study_report"]


def format_cell(value: Any) -> str:
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


def _md_table(t: Table) -> str:
    lines = [f"### {t.title}", ""]
    lines.append("| " + " | ".join(str(c).replace("|", "\\|") for c in t.columns) + " |")
    lines.append("|" + "|".join("---" for _ in t.columns) + "|")
    for row in t.rows:
        lines.append("| " + " | ".join(format_cell(c).replace("|", "\\|") for c in row) + " |")
    if t.note:
        lines += ["", t.note]
    return "\n".join(lines) + "\n"


def _html_table(t: Table) -> str:
    head = "".join(f"<th>{html.escape(str(c))}</th>" for c in t.columns)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(format_cell(c))}</td>" for c in row) + "</tr>" for row in t.rows
    )
    note = f"<p class='note'>{html.escape(t.note)}</p>" if t.note else ""
    return f"<h3>{html.escape(t.title)}</h3><table><tr>{head}</tr>{body}</table>{note}"


_CSS = (
    "body{font-family:sans-serif;max-width:1100px;margin:2em auto;line-height:1.45}"
    "table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #bbb;padding:3px 8px;"
    "text-align:right}th{background:#eee}td:first-child{text-align:left}img{max-width:100%}"
    ".note{color:#555;font-size:90%}pre{white-space:pre-wrap}"
)


def _paragraphs_html(text: str) -> str:
    return "".join(f"<p>{html.escape(p.strip())}</p>" for p in text.split("\n\n") if p.strip())


def _as_path(p: object, name: str) -> Path:
    if not isinstance(p, str | os.PathLike) or str(p) == "":
        raise ValueError(f"Expected {name} to be a non-empty path, got {p!r}.")
    return Path(p)


def write_study_report(result: StudyResult, out_dir: Path) -> dict[str, Path]:
    """Write ``report.md``, ``report.html`` and ``results.json`` into ``out_dir``."""
    check_params(result, StudyResult, "result")
    out_dir = _as_path(out_dir, "out_dir")
    out_dir.mkdir(parents=True, exist_ok=True)
    md = [f"# {result.title}", "", f"*Source:* {result.source}", ""]
    if result.summary:
        md += [result.summary.strip(), ""]
    for t in result.tables:
        md.append(_md_table(t))
    for f in result.figures:
        md += [f"![{f.caption}]({f.path.name})", "", f"*{f.caption}*", ""]
    if result.notes:
        md += ["## Notes", ""] + [f"- {n}" for n in result.notes] + [""]
    (out_dir / "report.md").write_text("\n".join(md))

    parts = [f"<h1>{html.escape(result.title)}</h1><p><i>Source:</i> {html.escape(result.source)}</p>"]
    parts.append(_paragraphs_html(result.summary))
    parts += [_html_table(t) for t in result.tables]
    parts += [
        f"<figure><img src='{html.escape(f.path.name)}'><figcaption>{html.escape(f.caption)}</figcaption>"
        "</figure>"
        for f in result.figures
    ]
    if result.notes:
        parts.append(
            "<h2>Notes</h2><ul>" + "".join(f"<li>{html.escape(n)}</li>" for n in result.notes) + "</ul>"
        )
    (out_dir / "report.html").write_text(
        f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(result.title)}</title>"
        f"<style>{_CSS}</style></head><body>{''.join(parts)}</body></html>"
    )

    payload = {
        "name": result.name,
        "title": result.title,
        "source": result.source,
        "summary": result.summary,
        "tables": [
            {"title": t.title, "columns": list(t.columns), "rows": t.rows, "note": t.note}
            for t in result.tables
        ],
        "figures": [{"file": f.path.name, "caption": f.caption} for f in result.figures],
        "notes": result.notes,
        "data": result.data,
    }
    (out_dir / "results.json").write_text(json.dumps(to_jsonable(payload), indent=2))
    return {"md": out_dir / "report.md", "html": out_dir / "report.html", "json": out_dir / "results.json"}


def write_index(out_root: Path, entries: Sequence[tuple[StudyResult, float]]) -> Path:
    """``index.md`` and ``index.html`` linking every study report, with run times."""
    out_root = _as_path(out_root, "out_root")
    if not isinstance(entries, Sequence) or isinstance(entries, str):
        raise ValueError(f"Expected entries to be a sequence of (StudyResult, seconds), got {entries!r}.")
    for i, entry in enumerate(entries):
        if not (isinstance(entry, tuple) and len(entry) == 2 and isinstance(entry[0], StudyResult)):
            raise ValueError(f"Expected entries[{i}] to be a (StudyResult, seconds) pair, got {entry!r}.")
        check_real(entry[1], f"entries[{i}] seconds", low=0.0)
    md = [
        "# robomech — paper reproductions",
        "",
        "| study | title | figures | tables | time (s) |",
        "|---|---|---|---|---|",
    ]
    rows_html = []
    for res, seconds in entries:
        md.append(
            f"| [{res.name}]({res.name}/report.md) | {res.title} | {len(res.figures)} | {len(res.tables)} | "
            f"{seconds:.1f} |"
        )
        rows_html.append(
            f"<tr><td><a href='{html.escape(res.name)}/report.html'>{html.escape(res.name)}</a></td>"
            f"<td>{html.escape(res.title)}</td><td>{len(res.figures)}</td><td>{len(res.tables)}</td>"
            f"<td>{seconds:.1f}</td></tr>"
        )
    (out_root / "index.md").write_text("\n".join(md) + "\n")
    (out_root / "index.html").write_text(
        "<!doctype html><html><head><meta charset='utf-8'><title>robomech reproductions</title>"
        f"<style>{_CSS}</style></head><body><h1>robomech — paper reproductions</h1><table>"
        "<tr><th>study</th><th>title</th><th>figures</th><th>tables</th><th>time (s)</th></tr>"
        f"{''.join(rows_html)}</table></body></html>"
    )
    return out_root / "index.md"
