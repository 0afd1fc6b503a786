"""``ertools report``: several report folders combined into one page."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
import yaml

from ertools.benchmarks.fbm2h.sample import generate
from ertools.cli.main import main
from ertools.report.combine import load_entry
from ertools.report.folder import write_report
from ertools.streams import Provenance
from tests.helpers.report_fakes import FakeResult, fbm3w_like


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
    assert main(["report", *args, "--report", str(out), "--title", "Lisbon <2015>"]) == 0
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
    # to the data's resolution: 0.01 mm, 1 ms
    assert "best_distance_error 12.30 mm, best_run 1, execution_time 41.500 s" in page
    assert "<th>best_distance_error (mm)</th>" in page and '<td class="num">8.70</td>' in page
    assert "b&lt;it&gt;bots" in page and "<it>" not in page
    assert "Lisbon &lt;2015&gt;" in page
    assert 'href="../results/fbm3w-0.0123/index.html"' in page


def test_lone_score_json_is_recognised(tmp_path: Path) -> None:
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
    assert main(["report", str(tmp_path / "empty"), "--report", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not a report folder" in err[0]
    bad = tmp_path / "score.json"
    bad.write_text("{not json")
    assert main(["report", str(bad), "--report", str(tmp_path / "o")]) == 1
    assert "cannot read a result" in capsys.readouterr().err


# --------------------------------------------------------------------------------------------
# One execution, one row: results of the same inputs merged, teams never "(unknown)" when a
# name can be found


def _csv(out: Path) -> list[dict[str, str]]:
    with (out / "results.csv").open(newline="") as fh:
        return list(csv.DictReader(fh))


def test_same_inputs_are_one_execution(tmp_path: Path) -> None:
    log = tmp_path / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
    log.write_bytes(b"one recording")
    same = tmp_path / "copy" / log.name  # the same bytes elsewhere: the same execution
    same.parent.mkdir()
    same.write_bytes(b"one recording")
    other = tmp_path / "FBM3W_201511201200_robox.bag"  # another execution, named by its logger
    other.write_bytes(b"another recording")
    runs = [
        ("plain", log, Provenance(), 0.0123, ["ertools", "score", "fbm3w", str(log)]),
        (
            "named",
            same,
            Provenance(team="tripod", team_source="explicit"),
            0.0125,
            ["ertools", "score", "fbm3w", str(same), "--team", "tripod", "--format", "json"],
        ),
        ("robox", other, Provenance(), 0.02, ["ertools", "score", "fbm3w", str(other)]),
    ]
    folders = []
    for name, bag, prov, best, argv in runs:
        result = fbm3w_like(best)
        result = type(result)(**{**result.__dict__, "provenance": prov})
        write_report(result, tmp_path / name, inputs=[bag], argv=argv)
        folders.append(str(tmp_path / name))
    # A report written before team_source existed: no team recorded, the name still says.
    meta_path = tmp_path / "robox" / "result.json"
    meta = json.loads(meta_path.read_text())
    assert (meta["team"], meta["team_source"]) == ("robox", "log name")
    meta.pop("team_source")
    meta["team"] = None
    meta_path.write_text(json.dumps(meta))

    out = tmp_path / "out"
    assert main(["report", *folders, "--report", str(out)]) == 0
    rows = _csv(out)
    # In rank order (lower best_distance_error first): tripod 0.0125 m, robox 0.02 m.
    assert [(r["team"], r["team_source"]) for r in rows] == [
        ("tripod", "explicit"),
        ("robox", "log name"),
    ]
    tripod = rows[0]
    # The named result is shown; the other is listed by its options (--format is output only).
    assert float(tripod["best_distance_error"]) == 0.0125
    # an option list begins like a formula: a spreadsheet shows the apostrophed text as is
    assert tripod["options"] == "'--team tripod"
    assert tripod["other results"] == "(defaults): best_distance_error 12.30 mm"
    assert rows[1]["other results"] == ""
    page = (out / "index.html").read_text(encoding="utf-8")
    assert "(unknown)" not in page
    assert "3 result(s) of 2 execution(s)" in page


@pytest.mark.slow
def test_the_fbm2h_sample_scored_twice_is_one_row(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 19: the FBM2H log scored with the identity transform and with --team simbot
    --transforms was listed twice, once as "(unknown)"; it is one execution of simbot."""

    folder = Path(__file__).resolve().parents[2] / "sample_bags" / "fbm2h"
    if not folder.is_dir():
        generate(tmp_path / "fbm2h", seed=2016)
        folder = tmp_path / "fbm2h"
    (bag,) = folder.glob("log_fbm2h_*.bag")
    (answers,) = folder.glob("*.answers.yaml")
    truth = yaml.safe_load(answers.read_text())
    score = ["score", "fbm2h", str(bag)]
    assert main([*score, "--report", str(tmp_path / "identity")]) == 0
    simbot = ["--team", "simbot", "--transforms", str(folder)]
    assert main([*score, *simbot, "--report", str(tmp_path / "simbot")]) == 0
    capsys.readouterr()
    out = tmp_path / "out"
    assert (
        main(["report", str(tmp_path / "identity"), str(tmp_path / "simbot"), "--report", str(out)])
        == 0
    )
    rows = _csv(out)
    assert len(rows) == 1
    row = rows[0]
    assert (row["benchmark"], row["team"], row["team_source"]) == ("fbm2h", "simbot", "explicit")
    # The shown numbers are simbot's (the transform it was scored with): the generator's truth.
    tol = truth["tolerance"]["distance_error"]["abs"]
    expected = truth["expected"]["position_accuracy"]
    assert float(row["position_accuracy"]) == pytest.approx(expected, abs=tol)
    assert row["options"] == f"'--team simbot --transforms {folder}"  # text, not a formula
    assert row["other results"].startswith("(defaults): position_accuracy ")
    assert "(unknown)" not in (out / "index.html").read_text(encoding="utf-8")
