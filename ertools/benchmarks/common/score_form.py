"""A result written in an ERL 2017-19 RSBB result file's ``score`` form, as the script dumped
it, with the intervals beside the scores: ``K_interval`` right after each goal's score ``K``,
the total's after the script's keys (which keep their order, as a 2015 listing's do), then the
``uncertainty`` block. Its tables end alike: the summary, the comparison with the scores the
run left, how the intervals were obtained.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

from ertools.benchmarks.base import Rows
from ertools.benchmarks.common.interval_output import as_list
from ertools.benchmarks.common.uncertainty import (
    Interval,
    Uncertainty,
    interval_keys,
    uncertainty_rows,
)
from ertools.benchmarks.results import ResultBase
from ertools.fidelity import Deviation
from ertools.rsbb.score import ScoreComparison, score_yaml
from ertools.streams import Provenance


@dataclass(frozen=True)
class GoalIntervals:
    """The intervals of a run's total and of each goal's score.

    Attributes:
        total: of the total (None: none given).
        goals: of each scored goal's score, by goal number.
        uncertainty: how they were obtained.
    """

    total: Interval | None
    goals: dict[int, Interval | None]
    uncertainty: Uncertainty


def nested_intervals(
    data: Mapping[str, Any], intervals: Mapping[str, Interval | None]
) -> dict[str, Any]:
    """``data`` with ``K_interval`` after each key ``K`` named by a dotted key of ``intervals``
    (``goal_2.partial_score.pose_score``), at its depth; keys that are not there are skipped."""
    out = interval_keys(data, {k: v for k, v in intervals.items() if "." not in k})
    for key, value in out.items():
        prefix = f"{key}."
        inner = {k[len(prefix) :]: v for k, v in intervals.items() if k.startswith(prefix)}
        if inner and isinstance(value, Mapping):
            out[key] = nested_intervals(value, inner)
    return out


@dataclass(frozen=True, eq=False)
class ScoreFormResult(ResultBase):
    """What a scored run of an RSBB script holds besides its goals, and its :meth:`listing`
    in the score form; the benchmark's result adds its goals and ``name``, and names its
    total (``TOTAL``) and where a goal's score stands under ``goal_<i>`` (``GOAL_SCORE``).

    Attributes:
        score: the result file's ``score`` by the rules (``--rules``: the script's last save).
        rules: ``ertools`` or the script version reproduced (``2019``...).
        crashed: why the script died on this run (``--rules``), None when it did not.
        comparison: the score against the live score and the result file (None: neither).
        intervals: the scores' intervals (None with ``--draws 0`` or nothing scored).
        origin_ns: the bag's first message (table times count from it).
        end: how the benchmark ended (``end``, ``stop``, ``global_timeout``, ``log_ends``).
        notes: what the scoring says on stderr.
    """

    TOTAL: ClassVar[str]
    GOAL_SCORE: ClassVar[str]

    score: dict[str, Any]
    rules: str = "ertools"
    crashed: str | None = None
    comparison: ScoreComparison | None = None
    intervals: GoalIntervals | None = None
    origin_ns: int | None = None
    end: str = ""
    notes: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()
    deviations: tuple[Deviation, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)

    def listing(self) -> dict[Any, Any]:
        """The score (result-file form), the intervals beside, then how they were obtained."""
        iv = self.intervals
        if iv is None:
            return dict(self.score)
        goals = {f"goal_{i}.{self.GOAL_SCORE}": v for i, v in iv.goals.items()}
        return {
            **nested_intervals(self.score, goals),
            f"{self.TOTAL}_interval": as_list(iv.total),
            "uncertainty": iv.uncertainty.to_dict(),
        }

    def to_yaml(self) -> str:
        """The listing as the BmBox wrote the score into the result file (keys sorted)."""
        return score_yaml(self.listing())

    def closing_tables(self, goals: Rows, summary: Rows) -> dict[str, Rows]:
        """``goals``, ``summary``, then ``comparison`` (when there is something to compare
        with) and ``uncertainty`` (with intervals)."""
        out: dict[str, Rows] = {"goals": goals, "summary": summary}
        if self.comparison is not None:
            out["comparison"] = self.comparison.rows()
        if self.intervals is not None:
            out["uncertainty"] = uncertainty_rows(self.intervals.uncertainty)
        return out
