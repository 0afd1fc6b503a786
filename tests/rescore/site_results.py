"""A hand-built ``results.json`` document for the results-site tests (schema: docs/rescore.md).

Three benchmarks, five teams, a tie, an execution without a value, a failed and an unscoreable
execution, live 2015 scores (one differing), problems, deviations and hostile text. Every
value is written down here; the expected leaderboards are computed from these values by the
tests, not by the code under test.
"""

from __future__ import annotations

import json
from html.parser import HTMLParser
from pathlib import Path
from typing import Any
from urllib.parse import unquote, urlsplit

from ertools.competition import pipeline

EVIL = "<script>alert('team')</script>"
S = 1_000_000_000
T0 = 1_448_010_000 * S  # 2015-11-20 09:00:00 UTC


def _execution(
    benchmark: str,
    title: str,
    team: str,
    minute: int,
    status: str,
    score: dict[str, Any] | None,
    rank_value: float | None,
    *,
    reason: str | None = None,
    live: dict[str, Any] | None = None,
    differences: tuple[str, ...] = (),
    report: bool = True,
) -> dict[str, Any]:
    start = T0 + minute * 60 * S
    stamp = f"20151120T{9 + minute // 60:02d}{minute % 60:02d}00"
    ident = f"{benchmark}-{team}-{stamp}"
    return {
        "id": ident,
        "benchmark": benchmark,
        "title": title,
        "team": team,
        "team_source": "payload",
        "start_ns": start,
        "end_ns": start + 300 * S,
        "start": f"2015-11-20T{9 + minute // 60:02d}:{minute % 60:02d}:00+00:00",
        "end": f"2015-11-20T{9 + minute // 60:02d}:{minute % 60 + 5:02d}:00+00:00",
        "bags": [f"bm/{ident}.bag"],
        "inputs": [{"name": "bag", "path": f"bm/{ident}.bag", "sha256": "ab" * 32}],
        "status": status,
        "reason": reason,
        "score": score,
        "rank_value": rank_value,
        "warnings": [],
        "deviations": [],
        "live_score": live,
        "live_differences": list(differences),
        "report": f"executions/{ident}/index.html" if report else None,
        "cached": False,
        "seconds": 1.25,
    }


def fbm3w(team: str, minute: int, best: float, **kw: Any) -> dict[str, Any]:
    score = {"best_distance_error": best, "best_run": 2, "runs_details": {"0": {}}}
    return _execution("fbm3w", "FBM3@Work", team, minute, "scored", score, best, **kw)


def fbm1h(team: str, minute: int, accuracy: float, **kw: Any) -> dict[str, Any]:
    score = {"class_accuracy": accuracy, "instance_accuracy": 0.5, "pose_score": 0.7}
    return _execution("fbm1h", "FBM1@Home", team, minute, "scored", score, accuracy, **kw)


def fbm2h(team: str, minute: int, position: float, **kw: Any) -> dict[str, Any]:
    score = {"position_accuracy": position, "orientation_accuracy": 0.03}
    return _execution("fbm2h", "FBM2@Home", team, minute, "scored", score, position, **kw)


def executions() -> list[dict[str, Any]]:
    return [
        # the live score differs in best_run only: not the ranked value, no flag on the board
        fbm3w(
            "b-it-bots",
            0,
            0.0123,
            live={"best_distance_error": 0.0123, "best_run": 3},
            differences=("best_run: live 3 vs recomputed 2",),
        ),
        fbm3w(
            "smartbots",
            10,
            0.0081,
            live={"best_distance_error": 0.0095, "best_run": 1},
            differences=(
                "best_distance_error: live 0.0095 vs recomputed 0.0081",
                "best_run: live 1 vs recomputed 2",
            ),
        ),
        fbm3w("homer", 20, 0.0123),  # ties b-it-bots
        fbm3w(EVIL, 30, 0.0200),
        _execution(
            "fbm3w",
            "FBM3@Work",
            "robotnik",
            40,
            "failed",
            None,
            None,
            reason="gt.bag: truncated at byte 1234 (the GT logger stopped)",
            report=False,
        ),
        fbm1h("homer", 60, 0.8),
        fbm1h("smartbots", 70, 0.9),
        fbm1h("b-it-bots", 80, 0.6),
        _execution(
            "fbm1h",
            "FBM1@Home",
            "robotnik",
            90,
            "unscoreable",
            None,
            None,
            reason="no items file for team robotnik in the manifest",
        ),
        fbm2h("homer", 120, 0.097),
        fbm2h("smartbots", 130, 0.063),
    ]


def leaderboards(exs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Leaderboards as the pipeline would write them, rows deliberately NOT in rank order
    (reversed) and ranks left out: the page must order them by the stated rule."""
    rules = {
        "fbm3w": ("FBM3@Work", "the best run's distance error", True),
        "fbm1h": ("FBM1@Home", "class accuracy", False),
        # as the registry words it: the direction already said
        "fbm2h": ("FBM2@Home", "position_accuracy (the mean distance): lower is better", True),
    }
    out = []
    for bench, (title, rule, lower) in rules.items():
        rows = [
            {"rank": None, "team": e["team"], "value": e["rank_value"], "execution": e["id"]}
            for e in exs
            if e["benchmark"] == bench and e["status"] == "scored"
        ]
        out.append(
            {
                "benchmark": bench,
                "title": title,
                "rule": rule,
                "lower_is_better": lower,
                "rows": rows[::-1],
            }
        )
    return out


def results() -> dict[str, Any]:
    exs = executions()
    return {
        "schema_version": 1,
        "ertools_version": "0.1.0",
        "generated": "2026-11-25T05:00:00+00:00",
        "command": ["ertools", "rescore", "logs/", "--config", "competition.yaml", "--out", "out"],
        "manifest": {"path": "competition.yaml", "sha256": "cd" * 32, "title": "Lisbon 2015"},
        "options": {"jobs": 2, "scheduler": None},
        "timeline": {"figure": "timeline.html", "sessions": 6},
        "executions": exs,
        "leaderboards": leaderboards(exs),
        "problems": [
            {"kind": "truncated", "path": "gt/gt_3.bag", "message": "truncated at byte 1234"},
            {"kind": "clock-offset", "path": "robots/homer.bag", "message": "clock 4.2 s ahead"},
            {"kind": "missing-input", "path": None, "message": f"no transform for team {EVIL}"},
        ],
        "deviations_in_force": [
            "[fbm3w.timeout-runs] a run the RefBox timed out is never the best run",
            "[fbm2h.orientation-wrap] the yaw difference is wrapped to [0, pi]",
        ],
        "inputs": [
            {"path": "bm/log_fbm3w.bag", "sha256": "ef" * 32, "size": 1234},
            {"path": "competition.yaml", "sha256": "cd" * 32, "size": 321},
        ],
    }


def with_interval(ex: dict[str, Any], low: float, high: float) -> dict[str, Any]:
    ex["score"]["best_distance_error_interval"] = [low, high]
    ex["score"]["uncertainty"] = {"confidence": 0.95, "method": "monte_carlo", "draws": 500}
    return ex


def ranked_document() -> dict[str, Any]:
    """Executions with intervals in their scores (as the scorers write them), the
    leaderboards made by the pipeline's own function (tests/rescore/test_rescore_ranks.py)."""
    doc = results()
    exs = [
        with_interval(fbm3w("smartbots", 0, 0.0081), 0.0079, 0.0083),
        with_interval(fbm3w("homer", 10, 0.0083), 0.0080, 0.0087),
        with_interval(fbm3w("b-it-bots", 20, 0.0100), 0.0098, 0.0102),
        fbm3w(EVIL, 30, 0.0200),  # scored before intervals existed
        # a team's second execution: only its best is ranked
        with_interval(fbm3w("homer", 40, 0.0150), 0.0140, 0.0160),
        fbm2h("homer", 120, 0.097),
        fbm2h("smartbots", 130, 0.063),
        # a score whose data cannot support it: never ranked, even with a number
        fbm2h("robotnik", 140, 0.010),
    ]
    exs[-1]["score"].update(status="unscoreable", unscoreable_reason="no GT at waypoint 2")
    doc["executions"] = exs
    doc["leaderboards"] = pipeline.leaderboards(exs)
    return doc


def expected_board(doc: dict[str, Any], bench: str) -> list[tuple[int | None, str]]:
    """(rank, team) in order: rank = 1 + the number of strictly better values (competition
    ranking: a tie shares the rank and the next rank is skipped), ties by team name; rows
    without a value last, unranked."""
    (board,) = [b for b in doc["leaderboards"] if b["benchmark"] == bench]
    lower = board["lower_is_better"]
    rows = board["rows"]
    valued = [r for r in rows if r["value"] is not None]

    def better(a: float, b: float) -> bool:
        return a < b if lower else a > b

    ranks = [(1 + sum(better(o["value"], r["value"]) for o in valued), r["team"]) for r in valued]
    return sorted(ranks) + [(None, r["team"]) for r in rows if r["value"] is None]


def write_folder(out: Path, doc: dict[str, Any]) -> None:
    """The files a rescore folder holds beside index.html: report folders, results files."""
    for e in doc["executions"]:
        if e["report"]:
            page = out / e["report"]
            page.parent.mkdir(parents=True, exist_ok=True)
            page.write_text(f"<!DOCTYPE html><title>{e['id']}</title>", encoding="utf-8")
    (out / "results.json").write_text(json.dumps(doc), encoding="utf-8")
    (out / "results.csv").write_text("id\n", encoding="utf-8")


class Page(HTMLParser):
    """What the tests read in the page (static or dumped by Chromium)."""

    def __init__(self, text: str) -> None:
        super().__init__()
        self.boards: dict[str, list[list[str]]] = {}
        # a standing's rank by the values (data-rank; the cell shows "=2" in a tie group)
        self.ranks: dict[str, list[int | None]] = {}
        self.rules: dict[str, str] = {}
        self.links: list[str] = []
        self.ids: set[str] = set()
        self.frames: list[str] = []
        self.scripts = 0
        self.sections: dict[str, str] = {}  # id -> its text
        self.executions: list[str] = []  # data-status of each execution row
        self.differs_rows = 0
        self._board: str | None = None
        self._row: list[str] | None = None
        self._cell: str | None = None
        self._rule: str | None = None
        self._section: str | None = None
        self.feed(text)

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = {k: v or "" for k, v in attrs}
        cls = a.get("class", "").split()
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "a" and "href" in a:
            self.links.append(a["href"])
        elif tag in ("img", "iframe"):
            self.links.append(a.get("src", ""))
            if tag == "iframe":
                self.frames.append(a.get("src", ""))
        elif tag == "script":
            self.scripts += 1
        elif tag == "section":
            self._section = a.get("id", "")
            self.sections[self._section] = ""
            if "leaderboard" in cls:
                self._board = self._section
                self.boards[self._board] = []
                self.ranks[self._board] = []
        elif tag == "tr" and "standing" in cls and self._board:
            self._row = []
            self.differs_rows += "differs" in cls
            self.ranks[self._board].append(int(a["data-rank"]) if a.get("data-rank") else None)
        elif tag == "tr" and "execution" in cls:
            self.executions.append(a.get("data-status", ""))
        elif tag == "td" and self._row is not None:
            self._cell = ""
        elif tag == "p" and "rule" in cls:
            self._rule = ""

    def board(self, anchor: str) -> list[tuple[int | None, str]]:
        """(rank by the values, team) of a leaderboard's standings, in page order."""
        return [(r, row[1]) for r, row in zip(self.ranks[anchor], self.boards[anchor], strict=True)]

    def handle_endtag(self, tag: str) -> None:
        if tag == "td" and self._cell is not None and self._row is not None:
            self._row.append(self._cell.strip())
            self._cell = None
        elif tag == "tr" and self._row is not None and self._board:
            self.boards[self._board].append(self._row)
            self._row = None
        elif tag == "p" and self._rule is not None and self._board:
            self.rules[self._board] = self._rule
            self._rule = None
        elif tag == "section":
            self._board = self._section = None

    def handle_data(self, data: str) -> None:
        if self._cell is not None:
            self._cell += data
        if self._rule is not None:
            self._rule += data
        if self._section is not None:
            self.sections[self._section] += data


def assert_links_resolve(page: Page, index: Path) -> None:
    """Every link and frame of the page is relative and resolves offline: to a file beside
    ``index`` or below it, or to an anchor of the page itself."""
    for link in page.links:
        parts = urlsplit(link)
        assert not parts.scheme, link
        if parts.path:
            assert (index.parent / unquote(parts.path)).is_file(), link
        if parts.fragment:
            assert parts.fragment in page.ids, link
