"""The HGMF result: the score in the result file's form, each goal's details, the comparison
with the run's own scores, the intervals, and what ertools' reading changed."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from ertools.arrays import F64, I64
from ertools.benchmarks.base import Rows
from ertools.benchmarks.common.interval_output import (
    ScoreRow,
    score_table,
)
from ertools.benchmarks.common.score_form import ScoreFormResult
from ertools.benchmarks.hgmf.config import GRASP_RISE_M, HgmfOptions
from ertools.benchmarks.hgmf.flow import Attempt
from ertools.benchmarks.hgmf.rules import (
    RULE_GRASP_SAMPLING,
    RULE_GT_GAPS,
    RULE_RESTARTED_GOALS,
)
from ertools.fidelity import Deviation
from ertools.frozen_dataclass import frozen_dataclass
from ertools.timeutil import ns_to_s

AVERAGE_KEY = "Avg distance error"


@frozen_dataclass
class HgmfGoal:
    """One goal the script sent, as scored.

    Attributes:
        attempt: what the script did (times, outcome, lookups, restart).
        description: the object's description (the config's, by the payload's id).
        z_ref: the object's height over the table at the lookup before the goal.
        ref_gap_ns: the interval between the samples around that lookup.
        ref_ok: that height counts (in ertools' reading: no wider gap than ``--max-gap``).
        grasped: the object rose more than 3 cm over ``z_ref`` during the goal.
        first_rise_ns: when it was first seen so high (None: never).
        max_rise: the highest rise seen, metres (None: no height looked up).
        position: the object's (x, y) at the final lookup (None: no final lookup).
        final_gap_ns: the interval between the samples around it.
        distance_error: metres to the target (None: not measured).
    """

    attempt: Attempt
    description: str
    z_ref: float
    ref_gap_ns: int
    ref_ok: bool
    grasped: bool
    first_rise_ns: int | None
    max_rise: float | None
    position: tuple[float, float] | None
    final_gap_ns: int | None
    distance_error: float | None

    @property
    def status(self) -> str:
        """``measured``, ``not completed``, ``restarted``, ``gap`` or ``no target``."""
        a = self.attempt
        if self.distance_error is not None:
            return "measured"
        if not a.times.completed:
            return "not completed"
        if a.restarted:
            return "restarted"
        if a.target is None:
            return "no target"
        return "gap"

    def unscored_reason(self, max_gap_s: float) -> str:
        """Why a completed goal with a final lookup has no distance."""
        a = self.attempt
        if a.target is None:
            return f"goal_{a.index}: its target is not in the log (goal payload): not scored"
        worst = max(self.ref_gap_ns if not self.ref_ok else 0, self.final_gap_ns or 0)
        return (
            f"goal_{a.index}: the object was not tracked around a lookup ({worst / 1e9:.3f} s "
            f"between samples > --max-gap {max_gap_s:g} s): not scored"
        )

    def row(self, t_start_ns: int) -> dict[str, Any]:
        a = self.attempt
        x, y = self.position if self.position is not None else (None, None)
        tx, ty = a.target if a.target is not None else (None, None)
        return {
            "goal": a.index,
            "status": self.status,
            "object_id": a.object_id,
            "object": self.description,
            "start_s": ns_to_s(a.times.start_ns - t_start_ns),
            "end_s": ns_to_s(a.times.end_ns - t_start_ns),
            "segment_time_s": ns_to_s(a.times.segment_ns),
            "timeout": a.times.timeout,
            "completed": a.times.completed,
            "reference_lookup_s": ns_to_s(a.ref_ns - t_start_ns),
            "reference_height_m": self.z_ref,
            "grasped": self.grasped,
            "first_rise_s": None
            if self.first_rise_ns is None
            else ns_to_s(self.first_rise_ns - t_start_ns),
            "max_rise_m": self.max_rise,
            "final_lookup_s": None if a.final_ns is None else ns_to_s(a.final_ns - t_start_ns),
            "target_x": tx,
            "target_y": ty,
            "object_x": x,
            "object_y": y,
            "mocap_gap_s": None if self.final_gap_ns is None else self.final_gap_ns / 1e9,
            "distance_error_m": self.distance_error,
        }


@frozen_dataclass(eq=False)
class HgmfResult(ScoreFormResult):
    """A scored HGMF run (implements ``BenchmarkResult``; its score, comparison, intervals and
    outputs: :class:`ScoreFormResult`).

    Attributes:
        goals: every goal the script sent, restarted ones too.
        objects: N, the config's objects.
        average: ``Avg distance error`` (None: not written).
        counted, grasped: its divisor and the grasps counted.
        rules: ``--rules``.
        t_start_ns: the benchmark's start (times in tables are seconds from it).
        stop_ns: the referee's stop or the global timeout, None when the script ended it.
        track: the object's (t_ns, (x, y, z)) in the table's frame, thinned, for plots.
    """

    goals: tuple[HgmfGoal, ...]
    objects: int
    average: float | None
    counted: int
    grasped: int
    rules: str
    t_start_ns: int
    stop_ns: int | None
    track: tuple[I64, F64]
    name: str = "hgmf"

    @property
    def nothing_scored(self) -> bool:
        completed = [g for g in self.goals if g.attempt.times.completed]
        return bool(completed) and not any(g.distance_error is not None for g in completed)

    def score_rows(self) -> list[ScoreRow]:
        return [ScoreRow(AVERAGE_KEY, self.average, self.interval(AVERAGE_KEY))]

    def tables(self) -> dict[str, Rows]:
        """``goals`` (every attempt), ``scores`` (the average and its interval),
        ``comparison`` (each score field against the live score and the file) and the
        interval tables."""
        return self.result_tables(
            {"goals": [g.row(self.t_start_ns) for g in self.goals]},
            score_table(self.score_rows()),
        )


def deviations_of(options: HgmfOptions, goals: Sequence[HgmfGoal]) -> tuple[Deviation, ...]:
    """What ertools' reading changed in this run, one line per rule not at the script's."""
    out: list[Deviation] = []
    if not options.restarted_goals_2019:
        restarted = [g.attempt.index for g in goals if g.attempt.restarted]
        where = (
            f"goal(s) {', '.join(f'goal_{i}' for i in restarted)} restarted here, not counted"
            if restarted
            else "no goal was restarted here: the same counts"
        )
        out.append(
            RULE_RESTARTED_GOALS.deviation(
                f"the divisor and the grasps count the measured goals only ({where})"
            )
        )
    if not options.grasp_timer:
        out.append(
            RULE_GRASP_SAMPLING.deviation(
                f"a grasp is a rise of more than {GRASP_RISE_M * 100:g} cm at any mocap sample "
                "during the goal; the script checked at 10 Hz at inferred moments"
            )
        )
    if not options.gaps_interpolate:
        gaps = [g.attempt.index for g in goals if g.status == "gap"]
        where = (
            f"goal(s) {', '.join(f'goal_{i}' for i in gaps)} not scored for it"
            if gaps
            else "no lookup fell in a gap here"
        )
        out.append(
            RULE_GT_GAPS.deviation(
                f"a position only where the object's samples around the lookup are at most "
                f"{options.max_gap_s:g} s apart ({where}); tf interpolated across any gap"
            )
        )
    return tuple(out)
