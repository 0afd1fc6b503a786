"""What ``make demo`` publishes: the sample competition rescored (its own step of the demo)
and its results site opened in headless Chromium, offline, from disk.

The leaderboards, the problems and the timeline are on the page as Chromium built it, every
link and frame resolves to a file the rescore wrote (or an anchor on the page), and the
page's rows say what results.json says. The scores themselves are checked against the
competition's answers in test_rescore_sample.py.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from ertools.benchmarks import registry
from ertools.demo import make_competition
from tests.helpers.fakes import BROWSER
from tests.rescore.site_results import Page, assert_links_resolve, expected_board
from tests.rescore.test_rescore_site_browser import chromium

pytestmark = [
    pytest.mark.browser,
    pytest.mark.slow,
    pytest.mark.skipif(BROWSER is None, reason="chromium not installed (apt-get install chromium)"),
]


@pytest.fixture(scope="module")
def demo_site(
    sample_competition: Path, rescored_competition: Path
) -> tuple[Path, dict[str, Any], Path]:
    # the demo's rescore step, run once for the session (tests/conftest.py)
    day = sample_competition  # what make_competition writes (tests/conftest.py)
    make_competition(day)  # there already: not generated again
    answers = json.loads((day / "answers.json").read_text(encoding="utf-8"))
    return rescored_competition / "index.html", answers, day


def test_the_demo_site_opens_with_its_boards_problems_and_timeline(
    demo_site: tuple[Path, dict[str, Any], Path], tmp_path: Path
) -> None:
    index, answers, _ = demo_site
    doc = json.loads((index.parent / "results.json").read_text(encoding="utf-8"))
    page = Page(chromium(tmp_path, index.as_uri(), "--dump-dom").stdout)
    # one leaderboard per benchmark the day held, in the benchmark's own ranking
    held = {e["benchmark"] for e in answers["executions"]}
    assert held <= set(registry.names())
    for bench in sorted(held):
        shown = page.board(f"lb-{bench}")
        assert shown == expected_board(doc, bench), bench
        assert shown, bench
    # every execution of the answers is a row with the answers' status (robot logs besides)
    statuses = {e["id"]: e["status"] for e in answers["executions"]}
    rows = {r["id"]: r["status"] for r in doc["executions"]}
    assert {k: rows[k] for k in statuses} == statuses
    assert sorted(page.executions) == sorted(rows.values())
    # the planted problems are listed, each with its file
    problems = page.sections["problems"]
    for p in doc["problems"]:  # with paths relative to the folder scanned
        assert p["message"].replace(doc["root"] + "/", "") in problems
    for planted in ("truncated", "active", "duplicate"):
        (path,) = [p["path"] for p in answers["problems"] if p["kind"] == planted]
        assert Path(path).name in problems, planted
    # FBM2H's hits, the referee's count the manifest does not give, is not recomputed: the
    # live value is shown beside no recomputed one, never flagged as a difference
    with_hits = [
        e
        for e in doc["executions"]
        if e["status"] == "scored" and "hits" in (e["live_score"] or {})
    ]
    assert len(with_hits) == 4
    for e in with_hits:
        assert e["score"]["hits"] is None
        assert not any(line.startswith("hits:") for line in e["live_differences"]), e["id"]
    assert "not recomputed" in page.sections["live"]
    # the day's timeline, framed
    assert page.frames == ["timeline.html"]
    assert (index.parent / "timeline.html").is_file()
    # every link resolves: to a file the rescore wrote, or an anchor of the page
    assert len(page.links) > 20
    assert_links_resolve(page, index)


def test_each_execution_links_its_report_folder(
    demo_site: tuple[Path, dict[str, Any], Path],
) -> None:
    index, _, _ = demo_site
    doc = json.loads((index.parent / "results.json").read_text(encoding="utf-8"))
    links = Page(index.read_text(encoding="utf-8")).links
    scored = [row for row in doc["executions"] if row["status"] == "scored"]
    assert len(scored) == 12  # 13 executions and a robot log; 2 unscoreable as planted
    for row in scored:
        assert (index.parent / row["report"]).is_file(), row["id"]
        assert row["report"] in links, row["id"]
