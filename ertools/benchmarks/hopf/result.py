"""The HOPF result: the result file's ``score`` as the rules make it, one record per goal, the
comparison with the scores the run left, and their YAML/JSON/CSV forms."""

from __future__ import annotations

from typing import Any, ClassVar

from ertools.benchmarks.base import Rows
from ertools.benchmarks.common.interval_output import ScoreRow
from ertools.benchmarks.common.score_form import ScoreFormResult
from ertools.benchmarks.hopf.goals import GoalRecord
from ertools.frozen_dataclass import frozen_dataclass
from ertools.timeutil import ns_to_s

TOTAL_KEY = "pose_score"


def goal_key(index: int) -> str:
    """The dotted score key of goal ``index``'s pose score (its interval's key)."""
    return f"goal_{index}.partial_score.pose_score"


@frozen_dataclass(eq=False, kw_only=True)
class HopfResult(ScoreFormResult):
    """A scored HOPF run (implements ``BenchmarkResult``): :class:`ScoreFormResult`'s fields
    (its intervals: the pose scores'), then these.

    Attributes:
        goals: one record per iteration the run began.
        rules: ``ertools`` or the script version reproduced (``2019``...).
        crashed: why the script died on this run (``--rules``), None when it did not.
        origin_ns: the bag's first message (table times count from it).
        end: how the benchmark ended (``end``, ``stop``, ``global_timeout``, ``log_ends``).
        notes: what the scoring says on stderr.
    """

    goals: tuple[GoalRecord, ...] = ()
    rules: str = "ertools"
    crashed: str | None = None
    origin_ns: int | None = None
    end: str = ""
    notes: tuple[str, ...] = ()
    name: str = "hopf"

    INTERVALS_LAST: ClassVar[tuple[str, ...]] = (TOTAL_KEY,)
    UNCERTAINTY_IN_YAML: ClassVar[bool] = True

    @property
    def pose_score(self) -> float | None:
        """The total pose score (the leaderboard's number)."""
        value = self.score.get(TOTAL_KEY)
        return float(value) if isinstance(value, int | float) else None

    @property
    def nothing_scored(self) -> bool:
        """No goal was scored and the data is at fault (no ground truth for any answer)."""
        if any(g.status == "scored" for g in self.goals):
            return False
        return any(g.status == "unscoreable" for g in self.goals)

    def score_rows(self) -> list[ScoreRow]:
        """The total pose score, then each scored goal's, with their intervals."""
        rows = [ScoreRow(TOTAL_KEY, self.pose_score, self.interval(TOTAL_KEY), 1.0, "")]
        for g in self.goals:
            key = goal_key(g.index)
            if key in self.intervals.intervals and g.terms is not None:
                rows.append(
                    ScoreRow(f"goal_{g.index} pose_score", g.terms[5], self.interval(key), 1.0, "")
                )
        return rows

    def _rel(self, t: int | None) -> float | None:
        return None if t is None or self.origin_ns is None else ns_to_s(t - self.origin_ns)

    def tables(self) -> dict[str, Rows]:
        """``goals`` (one row per iteration), ``summary``, ``comparison`` (one row per score
        field, when there is something to compare with) and ``uncertainty``."""
        rows: Rows = []
        for g in self.goals:
            truth = g.truth.pose if g.truth is not None and g.truth.pose is not None else None
            ans = g.answer
            terms = g.terms
            iv = self.interval(goal_key(g.index))
            rows.append(
                {
                    "goal": g.index,
                    "status": g.status,
                    "counted": g.counted,
                    "item_id": None if g.item is None else g.item.id,
                    "item_class": None if g.item is None else str(g.item.item_class),
                    "item_instance": None if g.item is None else str(g.item.instance),
                    "lookup_s": self._rel(None if g.truth is None else g.truth.moment_ns),
                    "lookup_inferred": None if g.truth is None else g.truth.inferred,
                    "gap_ms": None if g.truth is None else g.truth.gap_ns / 1e6,
                    "start_s": self._rel(None if g.times is None else g.times.start_ns),
                    "end_s": self._rel(None if g.times is None else g.times.end_ns),
                    "segment_time_s": None if g.segment_ns is None else g.segment_ns / 1e9,
                    "truth_x": None if truth is None else truth[0],
                    "truth_y": None if truth is None else truth[1],
                    "truth_theta": None if truth is None else truth[2],
                    "answer_x": None if ans is None or ans.pose is None else ans.pose[0],
                    "answer_y": None if ans is None or ans.pose is None else ans.pose[1],
                    "answer_theta": None if ans is None or ans.pose is None else ans.pose[2],
                    "answer_class": None if ans is None else _text(ans.item_class),
                    "answer_instance": None if ans is None else _text(ans.instance),
                    "class_ok": g.class_ok,
                    "instance_ok": g.instance_ok,
                    "x_err": None if terms is None else terms[0],
                    "y_err": None if terms is None else terms[1],
                    "w_err": None if terms is None else terms[2],
                    "translation": None if terms is None else terms[3],
                    "rotation": None if terms is None else terms[4],
                    "pose_score": None if terms is None else terms[5],
                    "pose_score_low": None if iv is None else iv.low,
                    "pose_score_high": None if iv is None else iv.high,
                    "problem": None if ans is None else ans.problem,
                    "no_truth_reason": None if g.truth is None else g.truth.reason,
                }
            )
        total = self.interval(TOTAL_KEY)
        summary: Rows = [
            {
                "rules": self.rules,
                "class_accuracy": self.score.get("class_accuracy"),
                "instance_accuracy": self.score.get("instance_accuracy"),
                "pose_score": self.score.get("pose_score"),
                "pose_score_low": None if total is None else total.low,
                "pose_score_high": None if total is None else total.high,
                "execution_time_s": self.score.get("execution_time"),
                "goals": len(self.goals),
                "counted": sum(g.counted for g in self.goals),
                "end": self.end,
                "crashed": self.crashed,
            }
        ]
        return self.closing_tables(rows, summary)


def _text(value: Any) -> str | None:
    return None if value is None else str(value)
