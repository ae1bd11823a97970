"""The command line and the report writer, end to end on the demonstration study."""

import json

import pytest

from robomech.cli import main
from robomech.studies import Table, available_studies, comparison_table, get_study


def test_reproduce_demo_writes_report_json_and_figure(tmp_path, capsys):
    assert main(["reproduce", "demo", "--out", str(tmp_path), "--quiet"]) == 0
    d = tmp_path / "demo"
    report = (d / "report.md").read_text()
    assert "Mobility by screw theory" in report and "![" in report
    assert (d / "report.html").exists() and (tmp_path / "index.html").exists()
    data = json.loads((d / "results.json").read_text())
    assert data["name"] == "demo" and data["figures"]
    png = d / data["figures"][0]["file"]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
    assert "demo/report.md" in (tmp_path / "index.md").read_text()


def test_reproduce_json_summary(tmp_path, capsys):
    assert main(["reproduce", "demo", "--out", str(tmp_path), "--json", "--quiet"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["studies"][0]["study"] == "demo"


def test_unknown_study_is_a_clear_error_with_nonzero_exit(tmp_path, capsys):
    assert main(["reproduce", "no-such-study", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "no-such-study" in err and "demo" in err
    with pytest.raises(ValueError, match="valid studies"):
        get_study("no-such-study")


def test_unknown_mechanism_for_verify_is_a_clear_error(capsys):
    assert main(["verify", "no-such-mechanism"]) == 2
    assert "no-such-mechanism" in capsys.readouterr().err


def test_list_names_every_study(capsys):
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    for name in available_studies():
        assert name in out


def test_comparison_table_computes_differences():
    t = comparison_table("t", [("l1", 100.0, 100.5, "mm"), ("l2", None, 3.0, "mm"), ("a", 0.0, 1e-9, "rad")])
    assert t.rows[0][4] == pytest.approx(0.5) and t.rows[0][5] == pytest.approx(0.005)
    assert t.rows[1][2] == "—"
    assert t.rows[2][4] == pytest.approx(1e-9) and t.rows[2][5] == "—"


def test_markdown_table_escapes_pipes_in_headers_and_cells(tmp_path):
    from robomech.studies import StudyResult, write_study_report

    res = StudyResult("x", "X", "src", tables=[Table("T", ["max |f|", "b"], [["|a|", 1.0]])])
    md = write_study_report(res, tmp_path)["md"].read_text()
    header = next(line for line in md.splitlines() if line.startswith("| max"))
    assert header == "| max \\|f\\| | b |"
    with pytest.raises(ValueError, match="cells"):
        Table("bad", ["a", "b"], [[1]])


def test_verify_cli_exits_nonzero_on_a_failed_check(monkeypatch, capsys):
    from robomech import verify
    from robomech.verify import Check, Tolerance, Verification

    failing = Verification(
        name="broken",
        title="a deliberately failing check",
        engine="none",
        run=lambda: [Check("broken", "x", 1.0, Tolerance(1e-3, "test"))],
    )
    monkeypatch.setattr(verify, "available_verifications", lambda: {"broken": failing})
    assert main(["verify", "broken"]) == 1
    out = capsys.readouterr().out
    assert "FAIL" in out and "0 passed, 1 failed" in out


def test_printed_values_are_shown_as_the_paper_printed_them(tmp_path):
    from robomech.studies import StudyResult, write_study_report
    from robomech.studies._core import Printed

    t = comparison_table("t", [("l1", 126.7305, 126.73, "mm"), ("r", "1.50", 1.5, "m"), ("n", 12, 12.0, "")])
    assert [r[2] for r in t.rows] == [
        Printed("126.7305", 126.7305),
        Printed("1.50", 1.5),
        Printed("12", 12.0),
    ]
    paths = write_study_report(StudyResult("x", "X", "src", tables=[t]), tmp_path)
    md = paths["md"].read_text()
    assert "| l1 | mm | 126.7305 | 126.73 |" in md and "| r | m | 1.50 | 1.5 |" in md
    data = json.loads(paths["json"].read_text())
    assert data["tables"][0]["rows"][0][2] == 126.7305  # a number in JSON, the string beside it
    assert [0, 2, "126.7305"] in data["tables"][0]["printed"]


def test_report_html_is_rendered_markdown_with_contents_back_links_and_alt_text(tmp_path):
    from robomech.studies import Figure, StudyResult, write_study_report

    res = StudyResult(
        "x",
        "X study",
        "src",
        summary="**Exact:** the `code` and a list\n\n- one\n- two",
        tables=[Table("T1", ["a"], [[1.0]])],
        figures=[Figure(tmp_path / "f.png", "A caption", alt="what the plot shows")],
        notes=["a *note*"],
    )
    page = write_study_report(res, tmp_path)["html"].read_text()
    assert "<strong>Exact:</strong>" in page and "<code>code</code>" in page and "**" not in page
    assert '<h2 id="contents">' in page and 'href="#t1"' in page and 'id="t1"' in page
    assert 'href="../index.html"' in page and '<img alt="what the plot shows" src="f.png"' in page
    assert "<em>note</em>" in page and "robomech" in page.split("<body>")[0]  # provenance in the page
    assert "Provenance" in page and "CPUs visible" in page


def test_index_is_rebuilt_from_every_results_json_and_shows_verification(tmp_path, monkeypatch, capsys):
    from robomech import verify
    from robomech.verify import Check, Tolerance, Verification

    assert main(["reproduce", "demo", "--out", str(tmp_path), "--quiet"]) == 0
    # a second study folder from another run: reproducing demo again must not hide it
    other = tmp_path / "other"
    other.mkdir()
    data = json.loads((tmp_path / "demo" / "results.json").read_text())
    (other / "results.json").write_text(json.dumps({**data, "name": "other", "title": "Other"}))
    assert main(["reproduce", "demo", "--out", str(tmp_path), "--quiet"]) == 0
    index = (tmp_path / "index.md").read_text()
    assert "[other](other/report.md)" in index and "[demo](demo/report.md)" in index
    assert "spherical-leg" in index and "not reproduced yet" in index

    rows = [
        Check("demo", "x", 0.0, Tolerance(1e-3, "t")),
        Check("demo", "y", 0.0, Tolerance(1e-3, "t"), verdict="n/a"),
    ]
    v = Verification("demo", "D", "none", run=lambda: rows)
    monkeypatch.setattr(verify, "available_verifications", lambda: {"demo": v})
    assert main(["verify", "--out", str(tmp_path), "--quiet"]) == 0
    assert (tmp_path / "verification.json").exists()
    row = next(line for line in (tmp_path / "index.md").read_text().splitlines() if "[demo]" in line)
    assert "pass (2 checks, 1 n/a)" in row  # an n/a row is counted, not failed
    html = (tmp_path / "index.html").read_text()
    assert 'href="demo/report.html"' in html and "<table>" in html
