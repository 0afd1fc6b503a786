"""``ertools report``: several report folders combined into one page."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
from report_fakes import FakeResult, fbm3w_like

from ertools.cli.main import main
from ertools.report.folder import write_report


@pytest.fixture
def results(tmp_path: Path) -> list[Path]:
    folders = []
    for team, best in (("tripod", 0.0123), ("b<it>bots", 0.0087)):
        out = tmp_path / "results" / f"fbm3w-{best}"
        write_report(fbm3w_like(best), out, inputs=[], argv=["ertools", "--team", team])
        folders.append(out)
    fbm2h = FakeResult("fbm2h", {"position_accuracy": 0.2, "orientation_accuracy": 0.05})
    out = tmp_path / "results" / "fbm2h-homer"
    write_report(fbm2h, out, inputs=[], argv=["ertools", "--team", "homer"])
    folders.append(out)
    return folders


def test_combined_page(
    results: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "competition"
    # Mixed ways of naming a result: folder, its result.json, its score.json.
    args = [str(results[0]), str(results[1] / "result.json"), str(results[2] / "score.json")]
    assert main(["report", *args, "--out", str(out), "--title", "Lisbon <2015>"]) == 0
    assert capsys.readouterr().out.strip() == str(out / "index.html")
    with (out / "results.csv").open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [(r["benchmark"], r["team"]) for r in rows] == [
        ("fbm2h", "homer"),
        ("fbm3w", "b<it>bots"),
        ("fbm3w", "tripod"),
    ]
    assert float(rows[1]["best_distance_error"]) == 0.0087
    assert json.loads((out / "results.json").read_text())[2]["best_run"] == 1
    page = (out / "index.html").read_text(encoding="utf-8")
    assert page.count("<table>") == 2 + 3  # one table per benchmark, one per team
    # tripod, lengths in mm on the page (0.0123 m), times in s; results.csv keeps metres.
    assert f"{0.0123 * 1000:.6g}" == "12.3"
    assert "best_distance_error 12.3 mm, best_run 1, execution_time 41.5 s" in page
    assert "<th>best_distance_error (mm)</th>" in page and '<td class="num">8.7</td>' in page
    assert "b&lt;it&gt;bots" in page and "<it>" not in page
    assert "Lisbon &lt;2015&gt;" in page
    assert 'href="../results/fbm3w-0.0123/index.html"' in page


def test_lone_score_json_is_recognised(tmp_path: Path) -> None:
    from ertools.report.combine import load_entry

    path = tmp_path / "score.json"
    path.write_text(json.dumps({"best_distance_error": 0.01, "runs_details": {}}))
    entry = load_entry(path)
    assert (entry.benchmark, entry.team, entry.headline) == (
        "fbm3w",
        "",
        {"best_distance_error": 0.01},
    )


def test_bad_result_path(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "empty").mkdir()
    assert main(["report", str(tmp_path / "empty"), "--out", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not a report folder" in err[0]
    bad = tmp_path / "score.json"
    bad.write_text("{not json")
    assert main(["report", str(bad), "--out", str(tmp_path / "o")]) == 1
    assert "cannot read a result" in capsys.readouterr().err
