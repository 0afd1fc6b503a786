"""The ``scores`` table a report writes: each score with its interval's ends, in SI units."""

from __future__ import annotations

from ertools.benchmarks.common.interval_output import ScoreRow, score_table
from ertools.benchmarks.common.uncertainty import Interval


def test_a_score_with_and_without_an_interval() -> None:
    rows = [
        ScoreRow("position_accuracy[m]", 0.0533, Interval(0.0531, 0.0535), 1000.0, "mm"),
        ScoreRow("orientation_accuracy[rad]", 0.067, None),
        ScoreRow("execution_time[s]", None, None),
    ]
    assert score_table(rows) == [
        # the table keeps SI units: the scale is for printing only
        {"score": "position_accuracy[m]", "value": 0.0533, "low": 0.0531, "high": 0.0535},
        {"score": "orientation_accuracy[rad]", "value": 0.067, "low": None, "high": None},
        {"score": "execution_time[s]", "value": None, "low": None, "high": None},
    ]
