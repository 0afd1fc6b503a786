"""A result in an RSBB script's score form (``ertools.benchmarks.common.score_form``): each
interval lands beside the score it is named after, at its depth, and the script's keys keep
their order (the expected documents written out by hand)."""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any, ClassVar

import yaml

from ertools.benchmarks.base import Rows
from ertools.benchmarks.common.score_form import GoalIntervals, ScoreFormResult, nested_intervals
from ertools.benchmarks.common.uncertainty import Interval, Uncertainty

SCORE: dict[str, Any] = {
    "goal_1": {"timeout": False, "partial": {"score": 0.5, "error": 0.1}},
    "goal_2": {"timeout": True},
    "total": 0.5,
    "execution_time": 3.0,
}


@dataclass(frozen=True, eq=False)
class Toy(ScoreFormResult):
    name: str = "toy"

    TOTAL: ClassVar[str] = "total"
    GOAL_SCORE: ClassVar[str] = "partial.score"

    def tables(self) -> dict[str, Rows]:
        return self.closing_tables([], [])


def test_an_interval_lands_after_its_key_at_its_depth() -> None:
    out = nested_intervals(
        SCORE, {"goal_1.partial.score": Interval(0.4, 0.6), "goal_3.partial.score": None}
    )
    assert out["goal_1"]["partial"] == {"score": 0.5, "score_interval": [0.4, 0.6], "error": 0.1}
    assert "goal_3" not in out  # a goal the score does not hold: nothing invented
    assert out["goal_2"] == {"timeout": True}
    assert SCORE["goal_1"]["partial"] == {"score": 0.5, "error": 0.1}  # the score untouched


def test_the_listing_keeps_the_scripts_keys_then_the_total_interval() -> None:
    uncertainty = Uncertainty(0.95, "Monte Carlo", 10, 0, (), {})
    ivs = GoalIntervals(Interval(0.45, 0.55), {1: Interval(0.4, 0.6)}, uncertainty)
    listing = Toy(score=SCORE, intervals=ivs).to_dict()
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
    # the YAML is the script's dump: keys sorted, the same values
    assert yaml.safe_load(Toy(score=SCORE, intervals=ivs).to_yaml()) == listing


def test_without_intervals_the_listing_is_the_score() -> None:
    toy = Toy(score=SCORE)
    assert toy.to_dict() == SCORE
    assert list(toy.tables()) == ["goals", "summary"]
