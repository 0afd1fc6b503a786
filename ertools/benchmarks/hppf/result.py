"""The HPPF result: the result file's ``score`` as the rules make it, one record per pass of
the script's loop, the comparison with the scores the run left, and their output forms."""

from __future__ import annotations

from typing import ClassVar

from ertools.benchmarks.base import Rows
from ertools.benchmarks.common.interval_output import ScoreRow
from ertools.benchmarks.common.score_form import ScoreFormResult
from ertools.benchmarks.hppf.goals import PassRecord
from ertools.frozen_dataclass import frozen_dataclass
from ertools.timeutil import ns_to_s

DISTANCE_KEY = "Distance error"


def goal_key(index: int) -> str:
    """The dotted score key of goal ``index``'s position error (its interval's key)."""
    return f"goal_{index}.position_error"


@frozen_dataclass(eq=False, kw_only=True)
class HppfResult(ScoreFormResult):
    """A scored HPPF run (implements ``BenchmarkResult``): :class:`ScoreFormResult`'s fields
    (its intervals: the position errors' and the Distance error's), then these.

    Attributes:
        passes: one record per pass of the script's loop (a restarted goal has two).
        people: the config's people (N).
        rules: ``ertools`` or the script version reproduced (``2019``).
        crashed: why the script died on this run (``--rules``), None when it did not.
        origin_ns: the bag's first message (table times count from it).
        end: how the benchmark ended (``end``, ``stop``, ``global_timeout``, ``log_ends``).
        notes: what the scoring says on stderr.
    """

    passes: tuple[PassRecord, ...] = ()
    people: tuple[str, ...] = ()
    rules: str = "ertools"
    crashed: str | None = None
    origin_ns: int | None = None
    end: str = ""
    notes: tuple[str, ...] = ()
    name: str = "hppf"

    INTERVALS_LAST: ClassVar[tuple[str, ...]] = (DISTANCE_KEY,)
    UNCERTAINTY_IN_YAML: ClassVar[bool] = True

    @property
    def distance_error(self) -> float | None:
        """The Distance error (the leaderboard's number), None when nothing was detected."""
        value = self.score.get(DISTANCE_KEY)
        return float(value) if isinstance(value, int | float) else None

    @property
    def nothing_scored(self) -> bool:
        """No position error and the data is at fault (no ground truth for any answer)."""
        if any(p.position_error is not None for p in self.passes):
            return False
        return any(p.status == "unscoreable" for p in self.passes)

    def score_rows(self) -> list[ScoreRow]:
        """The Distance error, then each pass's position error, with their intervals (mm)."""
        rows = [
            ScoreRow(DISTANCE_KEY, self.distance_error, self.interval(DISTANCE_KEY), 1000.0, "mm")
        ]
        for p in self.passes:
            key = goal_key(p.index)
            if p.position_error is not None and key in self.intervals.intervals:
                rows.append(
                    ScoreRow(
                        f"goal_{p.index} position_error",
                        p.position_error,
                        self.interval(key),
                        1000.0,
                        "mm",
                    )
                )
        return rows

    def _rel(self, t: int | None) -> float | None:
        return None if t is None or self.origin_ns is None else ns_to_s(t - self.origin_ns)

    def tables(self) -> dict[str, Rows]:
        """``goals`` (one row per pass), ``summary``, ``comparison`` and ``uncertainty``."""
        rows: Rows = []
        for p in self.passes:
            it, a, t = p.iteration, p.answer, p.truth
            iv = self.interval(goal_key(p.index))
            rows.append(
                {
                    "goal": p.index,
                    "person": p.person,
                    "status": p.status,
                    "retries": len(it.retries),
                    "check_s": self._rel(it.check_ns),
                    "start_s": self._rel(None if it.times is None else it.times.start_ns),
                    "end_s": self._rel(None if it.times is None else it.times.end_ns),
                    "segment_time_s": None if it.times is None else it.times.segment_ns / 1e9,
                    "lookup_s": self._rel(it.truth_ns),
                    "gap_ms": None if t is None else t.gap_ns / 1e6,
                    "truth_x": None if t is None or t.xy is None else t.xy[0],
                    "truth_y": None if t is None or t.xy is None else t.xy[1],
                    "answer_x": None if a is None or a.xy is None else a.xy[0],
                    "answer_y": None if a is None or a.xy is None else a.xy[1],
                    "answer_name": None if a is None else a.name,
                    "recognized": p.recognized,
                    "position_error_m": p.position_error,
                    "position_error_low": None if iv is None else iv.low,
                    "position_error_high": None if iv is None else iv.high,
                    "problem": None if a is None else a.problem,
                    "no_truth_reason": None if t is None else t.reason,
                }
            )
        total = self.interval(DISTANCE_KEY)
        summary: Rows = [
            {
                "rules": self.rules,
                "people": len(self.people),
                "recognized": self.score.get("Recognized persons"),
                "recognized_percent": self.score.get("% Recognized persons"),
                "distance_error_m": self.distance_error,
                "distance_error_low": None if total is None else total.low,
                "distance_error_high": None if total is None else total.high,
                "execution_time_s": self.score.get("execution_time"),
                "end": self.end,
                "crashed": self.crashed,
            }
        ]
        return self.closing_tables(rows, summary)
