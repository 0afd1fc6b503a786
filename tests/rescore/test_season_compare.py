"""The season bench's results comparison (bench/season_compare.py): what describes the run is
left out, anything the results say is compared exactly."""

from __future__ import annotations

import copy
from typing import Any

from season_compare import comparable, compare, differences


def doc() -> dict[str, Any]:
    return {
        "schema_version": 1,
        "generated": "2026-11-27T04:00:00+00:00",
        "command": ["ertools", "rescore", "--jobs", "1"],
        "options": {"jobs": 1, "scheduler": None},
        "manifest": {"path": "/a/season.yaml"},
        "executions": [
            {
                "id": "fbm3w-a-1",
                "status": "scored",
                "score": {"best": 0.0012, "best_interval": [0.001, 0.0014]},
                "rank_value": 0.0012,
                "report": "executions/fbm3w-a-1/index.html",
                "cached": False,
                "seconds": 2.5,
            },
            {
                "id": "fbm2h-b-2",
                "status": "unscoreable",
                "reason": "no GT",
                "score": None,
                "rank_value": None,
                "report": None,
                "cached": False,
                "seconds": 0.1,
            },
        ],
        "leaderboards": [{"benchmark": "fbm3w", "rows": [{"rank": 1, "team": "a"}]}],
        "problems": [],
    }


def test_the_run_itself_is_left_out() -> None:
    # another command, worker count, time, cache state, timing and no report folders: the
    # same results
    other = doc()
    other.update(generated="2026-11-28T00:00:00+00:00", command=["x"], options={"jobs": 2})
    other["manifest"] = {"path": "/b/season.yaml"}
    for row in other["executions"]:
        row.update(report=None, cached=True, seconds=9.9)
    ok, diffs = compare([("jobs 1", comparable(doc())), ("jobs 2", comparable(other))])
    assert ok and diffs == {}


def test_any_result_that_moves_is_named() -> None:
    base = comparable(doc())
    cases = [
        (("score", "best_interval", 1), 0.0014000000000000002, "best_interval[1]"),
        (("status",), "failed", "fbm3w-a-1.status"),
        (("rank_value",), 0.0012 + 1e-15, "rank_value: 0.0012 against 0.001200000000001"),
        (("rank_value",), 1, "rank_value: 0.0012 against 1"),
    ]
    for keys, value, named in cases:  # a change in the 13th digit counts too
        other = copy.deepcopy(doc())
        target: Any = other["executions"][0]
        for key in keys[:-1]:
            target = target[key]
        target[keys[-1]] = value
        ok, diffs = compare([("first", base), ("other", comparable(other))])
        assert not ok and any(named in line for line in diffs["other"]), diffs
    other = copy.deepcopy(doc())
    other["leaderboards"][0]["rows"].append({"rank": 2, "team": "b"})
    assert differences(base, comparable(other)) == ["leaderboards[0].rows: 1 items against 2"]
    other = copy.deepcopy(doc())
    del other["executions"][1]
    assert differences(base, comparable(other)) == ["executions.fbm2h-b-2: only in the first"]


def test_a_day_is_compared_on_its_executions_only() -> None:
    season = doc()
    day = copy.deepcopy(doc())
    day["executions"] = day["executions"][:1]
    day["leaderboards"] = []  # a day's boards are not the season's
    ids = {"fbm3w-a-1"}
    assert compare([("day", comparable(day, ids)), ("season", comparable(season, ids))])[0]
    day["executions"][0]["score"]["best"] = 0.0013
    assert not compare([("day", comparable(day, ids)), ("season", comparable(season, ids))])[0]
