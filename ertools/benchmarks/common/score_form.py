"""A result written in an ERL 2017-19 RSBB result file's ``score`` form, as the script dumped
it, with the intervals beside the scores (:class:`ScoreFormResult`): what the results of the
benchmarks re-scoring an RSBB script share (the comparison with the run's own scores, the
intervals, the outputs and tables), written once on :class:`~ertools.benchmarks.results.ResultBase`.

The intervals are by dotted score key (:class:`ResultIntervals`): a total's (``pose_score``)
or a goal's (``goal_2.partial_score.pose_score``), ``K_interval`` written right after ``K`` at
its depth, the script's keys keeping their order (as a 2015 listing's do).
"""

from __future__ import annotations

from abc import abstractmethod
from collections.abc import Mapping
from dataclasses import field
from typing import Any, ClassVar

from ertools.benchmarks.base import Rows
from ertools.benchmarks.common.interval_output import (
    NO_INTERVALS,
    ResultIntervals,
    ScoreRow,
    as_list,
    interval_lines,
    interval_tables,
)
from ertools.benchmarks.common.uncertainty import Interval, interval_keys, uncertainty_rows
from ertools.benchmarks.results import ResultBase
from ertools.fidelity import Deviation
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.score import ScoreComparison, plain, score_yaml
from ertools.streams import Provenance


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


@frozen_dataclass(eq=False, kw_only=True)
class ScoreFormResult(ResultBase):
    """The part of a result in a result file's ``score`` form that every such benchmark has;
    the benchmark's result adds its records and ``name``, its :meth:`score_rows` and
    :meth:`~ResultBase.tables`.

    The listing (``--format json``) is the score with ``K_interval`` ([low, high], null when
    withheld) after each key with an interval, then the ``uncertainty`` block when an interval
    stands at the top; the YAML is the script's dump of it (keys sorted).

    Attributes:
        score: the result file's ``score`` by the rules (``--rules``: the script's).
        comparison: the score against the live score and the result file (None: neither).
        intervals: the scores' intervals by dotted key (none with ``--draws 0``).
    """

    #: Keys whose ``K_interval`` follows the script's keys instead of ``K`` (HOPF's and HPPF's
    #: total, where their listings have always put it), null when the key has none.
    INTERVALS_LAST: ClassVar[tuple[str, ...]] = ()
    #: Whether the YAML carries the ``uncertainty`` block too (HOPF, HPPF) or only the JSON.
    UNCERTAINTY_IN_YAML: ClassVar[bool] = False

    score: dict[str, Any]
    comparison: ScoreComparison | None = None
    intervals: ResultIntervals = NO_INTERVALS
    warnings: tuple[str, ...] = ()
    deviations: tuple[Deviation, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)

    @abstractmethod
    def score_rows(self) -> list[ScoreRow]:
        """The scores with their intervals (the stderr lines; the ``scores`` table)."""

    def interval(self, key: str) -> Interval | None:
        """The interval of the score at dotted ``key`` (None: none or withheld)."""
        return self.intervals.intervals.get(key)

    def _scored(self) -> tuple[dict[str, Any], bool]:
        """The score with its intervals, and whether one stands at the top."""
        score: dict[str, Any] = plain(self.score)
        if self.intervals.uncertainty is None:
            return score, False
        ivs = self.intervals.intervals
        out = nested_intervals(
            score, {k: v for k, v in ivs.items() if k not in self.INTERVALS_LAST}
        )
        for key in self.INTERVALS_LAST:
            out[f"{key}_interval"] = as_list(ivs.get(key))
        return out, len(out) > len(score)

    def listing(self) -> dict[Any, Any]:
        """The score with its intervals, then how they were obtained (only beside an interval
        at the top: a score without its totals, a stopped run's, has none)."""
        out, top = self._scored()
        if top and self.intervals.uncertainty is not None:
            out["uncertainty"] = self.intervals.uncertainty.to_dict()
        return out

    def to_yaml(self) -> str:
        """The score as the BmBox wrote it into the result file (keys sorted), with its
        intervals."""
        return score_yaml(self.listing() if self.UNCERTAINTY_IN_YAML else self._scored()[0])

    def interval_lines(self) -> list[str]:
        """The stderr lines of the intervals (none without them)."""
        return interval_lines(self.score_rows(), self.intervals.uncertainty)

    def closing_tables(self, goals: Rows, summary: Rows) -> dict[str, Rows]:
        """HOPF's and HPPF's tables: ``goals``, ``summary``, then ``comparison`` (when there is
        something to compare with) and ``uncertainty`` (with intervals)."""
        out: dict[str, Rows] = {"goals": goals, "summary": summary}
        if self.comparison is not None:
            out["comparison"] = self.comparison.rows()
        if self.intervals.uncertainty is not None:
            out["uncertainty"] = uncertainty_rows(self.intervals.uncertainty)
        return out

    def result_tables(self, own: dict[str, Rows], scores: Rows) -> dict[str, Rows]:
        """HNF's, HPFF's and HGMF's tables: ``own`` (the runs' rows), ``scores``,
        ``comparison`` (each score field against the live score and the file) and the
        interval tables, in this order."""
        out = {**own, "scores": scores}
        if self.comparison is not None:
            out["comparison"] = self.comparison.rows()
        out.update(interval_tables(self.intervals.intervals, self.intervals.uncertainty))
        return out
