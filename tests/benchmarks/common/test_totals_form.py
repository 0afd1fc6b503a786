"""A result in an RSBB result file's score form (``TotalsFormResult``): each total with an
interval carries ``<total>_interval`` right after it, in the JSON and the YAML; the JSON also
the ``uncertainty`` block, only beside an interval."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import yaml

from ertools.benchmarks.base import Rows
from ertools.benchmarks.common.interval_output import ScoreRow
from ertools.benchmarks.common.totals_form import TotalsFormResult
from ertools.benchmarks.common.uncertainty import Interval, Source, Uncertainty
from ertools.rsbb.score import compare_scores

UNCERTAINTY = Uncertainty(
    0.9, "Monte Carlo", 100, 7, (Source("mocap_noise", 0.0002, "m", True),), {}, {}
)


@dataclass(frozen=True, eq=False)
class Toy(TotalsFormResult):
    name: str = "toy"

    def score_rows(self) -> list[ScoreRow]:
        return [ScoreRow("total[m]", self.score.get("total[m]"), self.intervals.get("total[m]"))]

    def tables(self) -> dict[str, Rows]:
        return self.result_tables({"runs": []}, [])


def toy(score: dict[str, Any], intervals: dict[str, Interval | None], u: Uncertainty | None) -> Toy:
    return Toy(
        score=score,
        comparison=compare_scores(score, None, None),
        intervals=intervals,
        uncertainty=u,
    )


SCORE: dict[str, Any] = {"segment_1": {"distance_error": 0.25}, "total[m]": 0.25, "reached": 1}


def test_each_interval_stands_right_after_its_total() -> None:
    r = toy(SCORE, {"total[m]": Interval(0.2, 0.3)}, UNCERTAINTY)
    out = r.to_dict()
    assert list(out) == ["segment_1", "total[m]", "total[m]_interval", "reached", "uncertainty"]
    assert out["total[m]_interval"] == [0.2, 0.3]
    assert out["uncertainty"]["confidence"] == 0.9 and out["uncertainty"]["seed"] == 7
    back = yaml.safe_load(r.to_yaml())
    assert back["total[m]_interval"] == [0.2, 0.3] and "uncertainty" not in back
    assert back["segment_1"] == {"distance_error": 0.25} and back["reached"] == 1


def test_a_withheld_interval_is_null_and_none_without_intervals() -> None:
    withheld = toy(SCORE, {"total[m]": None}, UNCERTAINTY).to_dict()
    assert withheld["total[m]_interval"] is None and "uncertainty" in withheld
    plain = toy(SCORE, {}, None)
    assert plain.to_dict() == SCORE
    assert yaml.safe_load(plain.to_yaml()) == SCORE


def test_a_score_without_its_totals_carries_no_interval_nor_uncertainty() -> None:
    # a stopped run under the script's rules: the totals were not written
    stopped: dict[str, Any] = {"segment_1": {"distance_error": 0.25}}
    out = toy(stopped, {"total[m]": Interval(0.2, 0.3)}, UNCERTAINTY).to_dict()
    assert out == stopped
