"""A result in an RSBB script's score form (``ertools.benchmarks.common.score_form``): each
interval lands beside the score it is named after, at its depth, and the script's keys keep
their order; HNF's, HPFF's and HGMF's totals carry theirs right after them (the JSON alone the
``uncertainty`` block, only beside an interval), HOPF's and HPPF's total after the script's
keys (the expected documents written out by hand)."""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any, ClassVar

import yaml

from ertools.benchmarks.base import Rows
from ertools.benchmarks.common.interval_output import ResultIntervals, ScoreRow
from ertools.benchmarks.common.score_form import ScoreFormResult, nested_intervals
from ertools.benchmarks.common.uncertainty import Interval, Source, Uncertainty
from ertools.rsbb.score import compare_scores

GOALS: dict[str, Any] = {
    "goal_1": {"timeout": False, "partial": {"score": 0.5, "error": 0.1}},
    "goal_2": {"timeout": True},
    "total": 0.5,
    "execution_time": 3.0,
}
TOTALS: dict[str, Any] = {"segment_1": {"distance_error": 0.25}, "total[m]": 0.25, "reached": 1}
UNCERTAINTY = Uncertainty(
    0.9, "Monte Carlo", 100, 7, (Source("mocap_noise", 0.0002, "m", True),), {}, {}
)


@dataclass(frozen=True, eq=False, kw_only=True)
class Goals(ScoreFormResult):
    """HOPF's and HPPF's shape: the total's interval after the script's keys."""

    name: str = "goals"

    INTERVALS_LAST: ClassVar[tuple[str, ...]] = ("total",)
    UNCERTAINTY_IN_YAML: ClassVar[bool] = True

    def score_rows(self) -> list[ScoreRow]:
        return [ScoreRow("total", self.score.get("total"), self.interval("total"))]

    def tables(self) -> dict[str, Rows]:
        return self.closing_tables([], [])


@dataclass(frozen=True, eq=False, kw_only=True)
class Totals(ScoreFormResult):
    """HNF's, HPFF's and HGMF's shape: each total's interval right after it."""

    name: str = "totals"

    def score_rows(self) -> list[ScoreRow]:
        return [ScoreRow("total[m]", self.score.get("total[m]"), self.interval("total[m]"))]

    def tables(self) -> dict[str, Rows]:
        return self.result_tables({"runs": []}, [])


def totals(score: dict[str, Any], intervals: ResultIntervals) -> Totals:
    return Totals(score=score, comparison=compare_scores(score, None, None), intervals=intervals)


def test_an_interval_lands_after_its_key_at_its_depth() -> None:
    out = nested_intervals(
        GOALS, {"goal_1.partial.score": Interval(0.4, 0.6), "goal_3.partial.score": None}
    )
    assert out["goal_1"]["partial"] == {"score": 0.5, "score_interval": [0.4, 0.6], "error": 0.1}
    assert "goal_3" not in out  # a goal the score does not hold: nothing invented
    assert out["goal_2"] == {"timeout": True}
    assert GOALS["goal_1"]["partial"] == {"score": 0.5, "error": 0.1}  # the score untouched


def test_the_goals_listing_keeps_the_scripts_keys_then_the_total_interval() -> None:
    uncertainty = Uncertainty(0.95, "Monte Carlo", 10, 0, (), {})
    ivs = ResultIntervals(
        {"total": Interval(0.45, 0.55), "goal_1.partial.score": Interval(0.4, 0.6)}, uncertainty
    )
    listing = Goals(score=GOALS, intervals=ivs).to_dict()
    assert list(listing) == [
        "goal_1",
        "goal_2",
        "total",
        "execution_time",
        "total_interval",
        "uncertainty",
    ]
    assert listing["total_interval"] == [0.45, 0.55]
    assert listing["goal_1"]["partial"]["score_interval"] == [0.4, 0.6]
    assert json.loads(json.dumps(listing)) == listing
    # the YAML is the script's dump: keys sorted, the same values, the uncertainty too
    assert yaml.safe_load(Goals(score=GOALS, intervals=ivs).to_yaml()) == listing


def test_without_intervals_the_listing_is_the_score() -> None:
    toy = Goals(score=GOALS)
    assert toy.to_dict() == GOALS
    assert toy.interval_lines() == []
    assert list(toy.tables()) == ["goals", "summary"]


def test_each_total_interval_stands_right_after_its_total() -> None:
    r = totals(TOTALS, ResultIntervals({"total[m]": Interval(0.2, 0.3)}, UNCERTAINTY))
    out = r.to_dict()
    assert list(out) == ["segment_1", "total[m]", "total[m]_interval", "reached", "uncertainty"]
    assert out["total[m]_interval"] == [0.2, 0.3]
    assert out["uncertainty"]["confidence"] == 0.9 and out["uncertainty"]["seed"] == 7
    back = yaml.safe_load(r.to_yaml())
    assert back["total[m]_interval"] == [0.2, 0.3] and "uncertainty" not in back
    assert back["segment_1"] == {"distance_error": 0.25} and back["reached"] == 1
    assert list(r.tables()) == [
        "runs",
        "scores",
        "comparison",
        "interval_shares",
        "interval_sources",
    ]


def test_a_withheld_interval_is_null_and_none_without_intervals() -> None:
    withheld = totals(TOTALS, ResultIntervals({"total[m]": None}, UNCERTAINTY)).to_dict()
    assert withheld["total[m]_interval"] is None and "uncertainty" in withheld
    plain = totals(TOTALS, ResultIntervals({}, None))
    assert plain.to_dict() == TOTALS
    assert yaml.safe_load(plain.to_yaml()) == TOTALS


def test_a_score_without_its_totals_carries_no_interval_nor_uncertainty() -> None:
    # a stopped run under the script's rules: the totals were not written
    stopped: dict[str, Any] = {"segment_1": {"distance_error": 0.25}}
    ivs = ResultIntervals({"total[m]": Interval(0.2, 0.3)}, UNCERTAINTY)
    assert totals(stopped, ivs).to_dict() == stopped
