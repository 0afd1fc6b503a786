"""Rank stability on the results of ``ertools rescore``: the leaderboards of results.json and
results.csv carry each team's interval, P(swap) with the next and its tie group, and the page
shows them with the plot.

The executions are hand-built (tests/rescore/site_results.py) with intervals written into
their scores as the scorers write them (``best_distance_error_interval`` and an
``uncertainty`` block, docs/uncertainty.md); the leaderboards are made by the pipeline's own
function, then the page from the document. The expected probabilities are computed here from
the normal CDF. (End to end, with intervals the scorers compute, is left to the sample
competition's test once the scorers write them.)
"""

from __future__ import annotations

import csv
import html
import io
import json
import math
import re
from pathlib import Path

import pytest

from ertools.competition.pipeline import csv_text
from ertools.competition.site import write_site
from tests.rescore.site_results import EVIL, Page, ranked_document, write_folder

Z95 = 1.959963984540054


def phi(x: float) -> float:
    return 0.5 * (1.0 + math.erf(x / math.sqrt(2.0)))


# smartbots-homer: 0.2 mm apart; facing sides 0.2 mm (smartbots above) and 0.3 mm (homer below)
P_SMART = phi(-0.2 / math.hypot(0.2 / Z95, 0.3 / Z95))
# homer-b-it-bots: 1.7 mm apart; facing sides 0.4 mm and 0.2 mm
P_HOMER = phi(-1.7 / math.hypot(0.4 / Z95, 0.2 / Z95))


def test_results_json_and_csv() -> None:
    assert abs(P_SMART - 0.1385) < 5e-4  # Phi(-1.087), from tables
    doc = ranked_document()
    (board,) = [b for b in doc["leaderboards"] if b["benchmark"] == "fbm3w"]
    assert board["confidence"] == 0.95
    rows = {r["team"]: r for r in board["rows"]}
    assert [r["team"] for r in board["rows"]] == ["smartbots", "homer", "b-it-bots", EVIL]
    assert rows["smartbots"]["p_swap_next"] == pytest.approx(P_SMART, rel=1e-9)
    assert rows["homer"]["p_swap_next"] == pytest.approx(P_HOMER, abs=1e-12)  # both ~5e-14
    assert rows["homer"]["interval"] == [0.0080, 0.0087]  # its best execution's
    assert rows["homer"]["execution"] == "fbm3w-homer-20151120T091000"
    assert [(r["rank"], r["rank_group"]) for r in board["rows"]] == [(1, 1), (2, 1), (3, 3), (4, 4)]
    assert rows["smartbots"]["tied_with"] == ["homer"] and rows["b-it-bots"]["tied_with"] == []
    assert (
        rows[EVIL]["interval"] is None and rows[EVIL]["rank_note"] == "no interval in this result"
    )
    assert rows["b-it-bots"]["rank_note"] == "the next has no interval"
    json.dumps(doc, allow_nan=False)  # the document stays strict JSON
    table = {r["id"]: r for r in csv.DictReader(io.StringIO(csv_text(doc)))}
    smart = table["fbm3w-smartbots-20151120T090000"]
    assert (smart["rank"], smart["rank_group"], smart["tied_with"]) == ("1", "1", "homer")
    assert (float(smart["interval_low"]), float(smart["interval_high"])) == (0.0079, 0.0083)
    assert float(smart["p_swap_next"]) == pytest.approx(P_SMART, rel=1e-9)
    # homer's second execution is not on the leaderboard: no place of its own
    assert table["fbm3w-homer-20151120T094000"]["rank"] == ""
    # fbm2h: no intervals, ranked by the values alone
    (fbm2h_board,) = [b for b in doc["leaderboards"] if b["benchmark"] == "fbm2h"]
    assert [r["p_swap_next"] for r in fbm2h_board["rows"]] == [None, None]
    assert [r["team"] for r in fbm2h_board["rows"]] == ["smartbots", "homer"]
    assert fbm2h_board["unranked"] == [
        {
            "execution": "fbm2h-robotnik-20151120T112000",
            "value": 0.010,
            "note": "robotnik: unscoreable (no GT at waypoint 2)",
        }
    ]


def test_page_shows_intervals_ties_and_plot(tmp_path: Path) -> None:
    doc = ranked_document()
    write_folder(tmp_path, doc)
    loaded = json.loads((tmp_path / "results.json").read_text(encoding="utf-8"))
    index = write_site(loaded, tmp_path)
    text = index.read_text(encoding="utf-8")
    page = Page(text)
    board = page.boards["lb-fbm3w"]
    assert [r[:2] for r in board] == [
        ["=1", "smartbots"],
        ["=1", "homer"],
        ["3", "b-it-bots"],
        ["4", EVIL],
    ]
    assert page.board("lb-fbm3w") == [(1, "smartbots"), (2, "homer"), (3, "b-it-bots"), (4, EVIL)]
    # value, interval (mm, 0.01 mm), P(swap) with the next
    assert board[0][2:5] == ["8.10", "7.90 to 8.30", f"{P_SMART * 100:.1f} %"]
    assert board[0][4] == "13.8 %"
    assert board[1][3:5] == ["8.00 to 8.70", "< 0.1 %"]
    assert board[2][4] == "\u2014 (the next has no interval)"
    assert board[3][3:5] == ["\u2014", "\u2014 (no interval in this result)"]
    start = text.index('id="lb-fbm3w"')
    section = text[start : text.index("</section>", start)]
    classes = re.findall(r'<tr class="standing([^"]*)"', section)
    assert classes == [" tied first", " tied last", "", ""]
    assert "95 % interval (mm)" in section and "does not support the order" in section
    assert "1 of 3 adjacent order(s) supported by the data" in section
    assert "tied: smartbots, homer (=1)" in section
    assert "best of the execution&#39;s runs" in section  # what FBM3W's interval covers
    svg = section[section.index("<svg") : section.index("</svg>")]
    assert svg.count('class="interval"') == 3 and svg.count("no-interval") == 1
    assert svg.count('class="tie"') == 1
    assert EVIL not in svg and html.escape(EVIL, quote=False)[:20] in svg  # a name stays text
    assert page.scripts == 0
    # fbm2h has no interval: no such columns, no plot, and the page says why
    start = text.index('id="lb-fbm2h"')
    fbm2h = text[start : text.index("</section>", start)]
    assert "interval (mm)" not in fbm2h and "<svg" not in fbm2h
    assert "No result here has a confidence interval" in fbm2h
    assert "robotnik: unscoreable (no GT at waypoint 2)" in fbm2h  # out of the ranking


def test_an_older_document_takes_the_intervals_from_the_scores(tmp_path: Path) -> None:
    """A results.json written before leaderboards carried rank stability (rows: rank, team,
    value, execution only): the page reads each interval from its execution's score and
    gives the same table."""
    doc = ranked_document()
    keep = ("rank", "team", "value", "execution")
    for board in doc["leaderboards"]:
        board.pop("confidence")
        board["rows"] = [{k: r[k] for k in keep} for r in board["rows"]]
    fresh = Page(write_site(ranked_document(), tmp_path / "fresh").read_text(encoding="utf-8"))
    old = Page(write_site(doc, tmp_path / "old").read_text(encoding="utf-8"))
    assert old.boards["lb-fbm3w"][0][:5] == ["=1", "smartbots", "8.10", "7.90 to 8.30", "13.8 %"]
    assert old.boards == fresh.boards
