"""The results site (ertools.competition.site) from a hand-built results document."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any
from urllib.parse import unquote, urlsplit

import pytest

from ertools.competition.site import ranked, write_site
from ertools.errors import ConfigError
from ertools.report.timeline_page import write_timeline_page
from tests.helpers.timeline_day import day_timeline
from tests.rescore.site_results import EVIL, Page, expected_board, results, write_folder


def build(out: Path) -> tuple[dict[str, Any], Path]:
    doc = results()
    write_folder(out, doc)
    write_timeline_page(day_timeline(), out / "timeline.html")
    # The site is rebuilt from results.json alone: go through the file, as a user would.
    loaded = json.loads((out / "results.json").read_text(encoding="utf-8"))
    return doc, write_site(loaded, out)


def test_leaderboards_ranked_by_each_rule(tmp_path: Path) -> None:
    doc, index = build(tmp_path)
    page = Page(index.read_text(encoding="utf-8"))
    assert set(page.boards) == {"lb-fbm3w", "lb-fbm1h", "lb-fbm2h"}
    for bench in ("fbm3w", "fbm1h", "fbm2h"):
        shown = page.board(f"lb-{bench}")
        assert shown == expected_board(doc, bench), bench
    # Written down from the values in site_results: the tie shares rank 2 (shown "=2": equal
    # values are tied with or without intervals), the next is 4.
    assert [r[:2] for r in page.boards["lb-fbm3w"]] == [
        ["1", "smartbots"],
        ["=2", "b-it-bots"],
        ["=2", "homer"],
        ["4", EVIL],
    ]
    # fbm1h: higher class accuracy first (0.9, 0.8, 0.6).
    assert [r[1] for r in page.boards["lb-fbm1h"]] == ["smartbots", "homer", "b-it-bots"]
    # The rule and its direction are stated on the page.
    assert "the best run's distance error (lower is better)" in page.rules["lb-fbm3w"]
    assert "class accuracy (higher is better)" in page.rules["lb-fbm1h"]
    assert page.rules["lb-fbm2h"].count("better") == 1  # not said twice
    # Values in the display unit of the ranked key at the page's resolution (0.01 mm): 0.0081 m
    # is 8.10 mm; the live 2015 value (0.0095 m) beside it, and that row flagged.
    smart = page.boards["lb-fbm3w"][0]
    assert smart[2] == f"{0.0081 * 1000:.2f}" == "8.10"
    assert smart[3].startswith("9.50") and "differs" in smart[3]
    # b-it-bots: the live best_distance_error equals the recomputed one (its best_run does not)
    assert page.boards["lb-fbm3w"][1][3] == "12.30"
    assert page.differs_rows == 1


def test_problems_deviations_timeline_and_executions(tmp_path: Path) -> None:
    doc, index = build(tmp_path)
    text = index.read_text(encoding="utf-8")
    page = Page(text)
    assert page.scripts == 0 and EVIL not in text  # hostile names stay text
    assert "<title>Lisbon 2015</title>" in text  # the manifest's title
    for p in doc["problems"]:
        assert p["message"] in page.sections["problems"]
    for d in doc["deviations_in_force"]:
        assert d in page.sections["deviations"]
    assert page.frames == ["timeline.html"]
    assert "6 session(s)" in page.sections["timeline"]
    # Live 2015 vs recomputed: the three differing fields first, each with its difference
    # (recomputed - live: 8.1 - 9.5 = -1.40 mm; best_run 2 - 1 = +1 and 2 - 3 = -1).
    live = page.sections["live"]
    assert "show only the 3 differing row(s)" in live
    assert "best_distance_error\n9.50 mm8.10 mm\n-1.40 mm" in live
    assert "best_run\n12\n+1" in live and "best_run\n32\n-1" in live
    first_same = live.index("\nsame\n")  # the first row that agrees
    assert live.index("-1.40 mm") < first_same and live.index("\n-1\n") < first_same
    # One row per execution with its status; the failed and unscoreable ones say why.
    assert page.executions == [e["status"] for e in doc["executions"]]
    assert page.executions.count("failed") == page.executions.count("unscoreable") == 1
    assert "truncated at byte 1234" in page.sections["executions"]
    assert "no items file for team robotnik" in page.sections["executions"]
    # Provenance: version, manifest hash and every input hash.
    prov = page.sections["provenance"]
    assert "0.1.0" in prov and "cd" * 32 in prov
    for i in doc["inputs"]:
        assert i["sha256"] in prov and i["path"] in prov


def test_every_link_resolves(tmp_path: Path) -> None:
    doc, index = build(tmp_path)
    page = Page(index.read_text(encoding="utf-8"))
    reports = [e["report"] for e in doc["executions"] if e["report"]]
    # every report folder linked (from its leaderboard row and its execution row)
    assert set(reports) <= {unquote(link) for link in page.links}  # links percent-encoded
    assert {"results.json", "results.csv", "timeline.html"} <= set(page.links)
    for link in page.links:
        parts = urlsplit(link)
        assert not parts.scheme and not parts.netloc, link  # nothing off the folder
        if parts.path:
            assert (index.parent / unquote(parts.path)).is_file(), link
        if parts.fragment:
            assert not parts.path and parts.fragment in page.ids, link


def test_missing_report_is_text_not_a_dead_link(tmp_path: Path) -> None:
    doc, _ = build(tmp_path)
    gone = doc["executions"][0]["report"]
    (tmp_path / gone).unlink()
    page = Page(write_site(doc, tmp_path).read_text(encoding="utf-8"))
    assert gone not in page.links
    assert f"{gone} (missing)" in page.sections["executions"]


def test_ranked_shares_ranks_and_puts_no_value_last() -> None:
    rows = [
        {"team": "c", "value": None},
        {"team": "b", "value": 2.0},
        {"team": "a", "value": 2.0},
        {"team": "d", "value": 1.0},
        {"team": "e", "value": float("nan")},
    ]
    low = [(r, row["team"]) for r, row in ranked(rows, lower_is_better=True)]
    assert low == [(1, "d"), (2, "a"), (2, "b"), (None, "c"), (None, "e")]
    high = [(r, row["team"]) for r, row in ranked(rows, lower_is_better=False)]
    assert high == [(1, "a"), (1, "b"), (3, "d"), (None, "c"), (None, "e")]


@pytest.mark.parametrize("doc", [{"schema_version": 2}, {}, []])
def test_not_a_results_document(tmp_path: Path, doc: object) -> None:
    with pytest.raises(ConfigError, match="schema_version 1"):
        write_site(doc, tmp_path)
    assert not (tmp_path / "index.html").exists()
