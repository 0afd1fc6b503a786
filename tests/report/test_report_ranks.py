"""``ertools report`` of several teams with confidence intervals: each benchmark's table in
rank order with the intervals, the swap probabilities and the ties, and the plot.

The results are written by hand as `ertools score --report` writes ``result.json`` (the score
with ``K_interval`` beside ``K`` and an ``uncertainty`` block, docs/uncertainty.md); the
expected probabilities are computed here from the normal CDF.
"""

from __future__ import annotations

import csv
import html
import json
import math
import re
from pathlib import Path
from typing import Any

import pytest

from ertools.cli.main import main

Z95 = 1.959963984540054


def phi(x: float) -> float:
    return 0.5 * (1.0 + math.erf(x / math.sqrt(2.0)))


def write_result(
    folder: Path, benchmark: str, team: str, score: dict[str, Any], *, confidence: float = 0.95
) -> Path:
    if any(k.endswith("_interval") for k in score):
        score = {
            **score,
            "uncertainty": {
                "confidence": confidence,
                "method": "monte_carlo",
                "draws": 1000,
                "seed": 1,
                "sources": [],
                "shares": {},
            },
        }
    meta = {
        "benchmark": benchmark,
        "team": team,
        "team_source": "explicit",
        "generated": "2026-11-27T00:00:00+00:00",
        "inputs": [],
        "headline": {k: v for k, v in score.items() if not isinstance(v, dict | list)},
        "score": score,
        "warnings": [],
        "failures": [],
        "audit": None,
    }
    folder.mkdir(parents=True)
    (folder / "result.json").write_text(json.dumps(meta), encoding="utf-8")
    return folder


def fbm3w(best: float, interval: tuple[float, float] | None = None) -> dict[str, Any]:
    score: dict[str, Any] = {"best_distance_error": best, "best_run": 0}
    if interval is not None:
        score["best_distance_error_interval"] = list(interval)
    return score


@pytest.fixture
def competition(tmp_path: Path) -> tuple[Path, dict[str, Any]]:
    res = tmp_path / "results"
    folders = [
        # bravo-alpha: 0.05 mm apart, 0.10 mm half-widths: tied at 95 %
        write_result(res / "a", "fbm3w", "alpha", fbm3w(0.00050, (0.00040, 0.00060))),
        write_result(res / "b", "fbm3w", "bravo", fbm3w(0.00055, (0.00045, 0.00065))),
        # charlie: 0.45 mm behind bravo, narrow: the order stands
        write_result(res / "c", "fbm3w", "charlie", fbm3w(0.00100, (0.00095, 0.00105))),
        # delta: a result written before intervals
        write_result(res / "d", "fbm3w", "delta", fbm3w(0.00200)),
        write_result(
            res / "e",
            "fbm3w",
            "echo",
            {
                "best_distance_error": None,
                "status": "unscoreable",
                "unscoreable_reason": "no GT within 0.1 s of any waypoint",
            },
        ),
        # fbm2h: no interval anywhere
        write_result(res / "f", "fbm2h", "homer", {"position_accuracy": 0.2}),
        write_result(res / "g", "fbm2h", "tiago", {"position_accuracy": 0.1}),
    ]
    out = tmp_path / "out"
    assert main(["report", *map(str, folders), "--report", str(out)]) == 0
    expected = {
        "alpha": phi(-0.05 / math.hypot(0.10 / Z95, 0.10 / Z95)),
        "bravo": phi(-0.45 / math.hypot(0.10 / Z95, 0.05 / Z95)),
    }
    return out, expected


def test_json_and_csv_carry_the_rank_stability(competition: tuple[Path, dict[str, Any]]) -> None:
    out, expected = competition
    assert expected["alpha"] == pytest.approx(0.244, abs=1e-3)  # Phi(-0.693), from tables
    rows = json.loads((out / "results.json").read_text(encoding="utf-8"))
    fbm3w_rows = [r for r in rows if r["benchmark"] == "fbm3w"]
    assert [r["team"] for r in fbm3w_rows] == ["alpha", "bravo", "charlie", "delta", "echo"]
    by = {r["team"]: r for r in fbm3w_rows}
    assert by["alpha"]["p_swap_next"] == pytest.approx(expected["alpha"], rel=1e-9)
    assert by["bravo"]["p_swap_next"] == pytest.approx(expected["bravo"], rel=1e-6, abs=1e-15)
    assert [(by[t]["rank"], by[t]["rank_group"]) for t in ("alpha", "bravo", "charlie")] == [
        (1, 1),
        (2, 1),
        (3, 3),
    ]
    assert by["alpha"]["tied_with"] == ["bravo"] and by["charlie"]["tied_with"] == []
    assert by["alpha"]["interval"] == [0.00040, 0.00060]
    assert by["alpha"]["confidence"] == 0.95
    assert by["delta"]["interval"] is None and by["delta"]["rank"] == 4
    assert by["delta"]["rank_note"] == "no interval in this result"
    assert by["echo"]["rank"] is None
    assert by["echo"]["rank_note"] == "unscoreable: no GT within 0.1 s of any waypoint"
    with (out / "results.csv").open(newline="") as fh:
        table = {r["team"]: r for r in csv.DictReader(fh)}
    assert float(table["alpha"]["interval_low"]) == 0.0004
    assert float(table["alpha"]["interval_high"]) == 0.0006
    assert table["bravo"]["tied_with"] == "alpha" and table["bravo"]["rank_group"] == "1"


def test_page_shows_intervals_ties_and_plot(competition: tuple[Path, dict[str, Any]]) -> None:
    out, expected = competition
    page = (out / "index.html").read_text(encoding="utf-8")
    section = page[page.index('id="b-fbm3w"') : page.index('id="teams"')]
    assert "95 % interval (mm)" in section
    # rank marker, team, then the interval in mm and P(swap) in %
    cells = [
        html.unescape(re.sub(r"<[^>]+>", "", c))
        for c in re.findall(r"<td[^>]*>.*?</td>", section.split("<tbody>")[1].split("</tbody>")[0])
    ]
    assert cells[:2] == ["=1", "alpha"]
    # the tie bracketed in the table: alpha opens it, bravo closes it
    assert re.findall(r'<tr class="([^"]*)"', section)[:3] == ["tied first", "tied last", ""]
    assert "0.40 to 0.60" in cells and f"{expected['alpha'] * 100:.1f} %" in cells
    assert f"{expected['alpha'] * 100:.1f} %" == "24.4 %"
    assert "\u2014 (no interval in this result)" in cells  # delta
    assert "\u2014 (the next has no interval)" in cells  # charlie, above delta
    assert "< 0.1 %" in cells  # bravo above charlie: 2e-15
    assert "\u2014 (unscoreable: no GT within 0.1 s of any waypoint)" in cells
    assert "does not support the order" in section  # the words above the table
    assert "1 of 3 adjacent order(s) supported by the data" in section
    assert "tied: alpha, bravo (=1)" in section
    # The plot: inline SVG, a dot and a bar per team with an interval, the tie bracketed.
    svg = section[section.index("<svg") : section.index("</svg>")]
    assert svg.count('class="score"') == 3 and svg.count('class="interval"') == 3
    assert svg.count("no-interval") == 1  # delta: a hollow dot
    assert svg.count('class="tie"') == 1 and ">=1<" in svg
    # fbm2h: no interval anywhere, ranked by the values alone and saying why.
    fbm2h = page[page.index('id="b-fbm2h"') : page.index('id="b-fbm3w"')]
    assert "No result here has a confidence interval" in fbm2h and "<svg" not in fbm2h
    assert "interval (mm)" not in fbm2h and "P(swap" not in fbm2h  # no empty columns


def test_another_confidence_judges_the_ties(tmp_path: Path) -> None:
    """--confidence 0.5: a tie when P(swap) > 25 %; alpha-bravo (24.4 %) is then an order the
    data supports. The intervals are still read at their own 95 %."""
    res = tmp_path / "results"
    folders = [
        write_result(res / "a", "fbm3w", "alpha", fbm3w(0.00050, (0.00040, 0.00060))),
        write_result(res / "b", "fbm3w", "bravo", fbm3w(0.00055, (0.00045, 0.00065))),
    ]
    out = tmp_path / "out"
    assert main(["report", *map(str, folders), "--report", str(out), "--confidence", "0.5"]) == 0
    rows = json.loads((out / "results.json").read_text(encoding="utf-8"))
    assert [(r["rank_group"], r["tied_with"], r["confidence"]) for r in rows] == [
        (1, [], 0.5),
        (2, [], 0.5),
    ]
    assert rows[0]["p_swap_next"] == pytest.approx(phi(-0.05 / math.hypot(0.1 / Z95, 0.1 / Z95)))


@pytest.mark.parametrize("value", ["1", "0", "95", "nan"])
def test_confidence_out_of_range_is_a_usage_error(
    tmp_path: Path, value: str, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = write_result(tmp_path / "a", "fbm3w", "alpha", fbm3w(0.0005))
    argv = ["report", str(folder), "--report", str(tmp_path / "o"), "--confidence", value]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "--confidence" in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()
