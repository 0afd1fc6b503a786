"""A result whose score is a script's own ``score`` mapping, as the ERL 2017-19 RSBB wrote it
into the run's result file (:mod:`ertools.rsbb.score`): what the results of the benchmarks
re-scoring an RSBB script share (the comparison with the run's own scores, the intervals, the
outputs and tables), written once in :class:`TotalsFormResult`."""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ertools.benchmarks.common.interval_output import (
    ScoreRow,
    interval_lines,
    interval_tables,
)
from ertools.frames import tables_to_frames
from ertools.rsbb.score import ScoreComparison, plain, score_yaml
from ertools.streams import Provenance

if TYPE_CHECKING:
    import pandas as pd  # annotations only: pandas is imported by to_frames()

    from ertools.benchmarks.base import Rows
    from ertools.benchmarks.common.uncertainty import Interval, Uncertainty
    from ertools.fidelity import Deviation


@dataclass(frozen=True, eq=False, kw_only=True)
class TotalsFormResult(ABC):
    """The part of a result in a result file's form that every such benchmark has: its
    ``score`` (the mapping as the script wrote it), the comparison with the live score and the
    result file, the intervals of its totals and what every ``BenchmarkResult`` carries.

    ``to_dict`` and ``to_yaml`` give the score with ``<key>_interval`` ([low, high], null when
    withheld) after each total that has an interval; the JSON also the ``uncertainty`` block
    (the level, the method, the sources) beside them, as the 2015 benchmarks' listings carry
    them.
    """

    score: dict[str, Any]
    comparison: ScoreComparison
    intervals: dict[str, Interval | None]
    uncertainty: Uncertainty | None
    warnings: tuple[str, ...] = ()
    deviations: tuple[Deviation, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)

    @abstractmethod
    def score_rows(self) -> list[ScoreRow]:
        """The totals with their intervals (the stderr lines, the ``scores`` table)."""

    def listing(self) -> dict[str, Any]:
        """The score with its intervals: each ``<key>_interval`` right after ``<key>``."""
        out: dict[str, Any] = {}
        for key, value in plain(self.score).items():
            out[key] = value
            if self.uncertainty is not None and key in self.intervals:
                iv = self.intervals[key]
                out[f"{key}_interval"] = None if iv is None else iv.as_list()
        return out

    def to_dict(self) -> dict[str, Any]:
        """The score (JSON) with its intervals and the ``uncertainty`` block."""
        out = self.listing()
        if self.uncertainty is not None and len(out) > len(self.score):
            # only beside an interval: a score without its totals (a stopped run) has none
            out["uncertainty"] = self.uncertainty.to_dict()
        return out

    def to_yaml(self) -> str:
        """The score as the BmBox wrote it into the result file (keys sorted), with its
        intervals."""
        return score_yaml(self.listing())

    def interval_lines(self) -> list[str]:
        return interval_lines(self.score_rows(), self.uncertainty)

    def result_tables(self, own: dict[str, Rows], scores: Rows) -> dict[str, Rows]:
        """``own`` (the runs' rows), ``scores``, ``comparison`` (each score field against the
        live score and the file) and the interval tables, in this order."""
        out = {**own, "scores": scores, "comparison": self.comparison.rows()}
        out.update(interval_tables(self.intervals, self.uncertainty))
        return out

    def to_frames(self) -> dict[str, pd.DataFrame]:
        return tables_to_frames(self.tables())

    @abstractmethod
    def tables(self) -> dict[str, Rows]:
        """CSV-ready tables by name."""
