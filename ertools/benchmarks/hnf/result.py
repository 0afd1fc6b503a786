"""The HNF result: the score in the result file's form, each segment's details, the comparison
with the run's own scores, the intervals, and what ertools' reading changed."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ertools.arrays import F64, I64
from ertools.benchmarks.base import Rows
from ertools.benchmarks.common.interval_output import (
    ScoreRow,
    score_table,
)
from ertools.benchmarks.common.score_form import ScoreFormResult
from ertools.benchmarks.hnf.config import HnfOptions
from ertools.benchmarks.hnf.flow import HnfFlow, SegmentFlow
from ertools.benchmarks.hnf.rules import (
    RULE_DIVISOR,
    RULE_GT_GAPS,
    RULE_ORIENTATION_WRAP,
    RULE_SCORE_FORMAT,
    RULE_SKIPPED,
    RULE_STOPPED,
)
from ertools.fidelity import Deviation
from ertools.frozen_dataclass import frozen_dataclass
from ertools.timeutil import ns_to_s

POSITION_KEY = "position_accuracy[m]"
ORIENTATION_KEY = "orientation_accuracy[rad]"


@frozen_dataclass
class HnfSegment:
    """One waypoint as scored.

    Attributes:
        index: its position in the config (the score's ``segment_<index+1>``).
        waypoint: (x, y, theta) as the config typed them.
        flow: what the script did there (times, outcome, lookup, the referee's answers).
        robot: the robot's (x, y, yaw) at the lookup as tf gave it (None: no lookup).
        gap_ns: the interval between the mocap samples around the lookup.
        measured: the pose counts (it exists and, in ertools' reading, no wider gap than
            ``--max-gap`` lies under it).
        distance_error, orientation_error: metres, radians (None unless measured).
        dtheta: robot yaw minus waypoint theta as summed (wrapped in ertools' reading).
        sin, cos: the summands of the orientation accuracy (0 unless measured).
    """

    index: int
    waypoint: tuple[Any, Any, Any]
    flow: SegmentFlow
    robot: tuple[float, float, float] | None
    gap_ns: int | None
    measured: bool
    distance_error: float | None
    orientation_error: float | None
    dtheta: float | None
    sin: float
    cos: float

    @property
    def status(self) -> str:
        """``measured``, ``skipped``, ``gap``, ``stopped`` or ``no pose``."""
        if self.measured:
            return "measured"
        if self.flow.skipped:
            return "skipped"
        if self.robot is not None:
            return "gap"
        if self.flow.interrupted:
            return "stopped"
        return "no pose"

    def row(self, t_start_ns: int) -> dict[str, Any]:
        f = self.flow
        rx, ry, rt = self.robot if self.robot is not None else (None, None, None)
        return {
            "segment": self.index + 1,
            "status": self.status,
            "start_s": ns_to_s(f.start_ns - t_start_ns),
            "end_s": ns_to_s(f.end_ns - t_start_ns),
            "segment_time_s": ns_to_s(f.end_ns - f.start_ns),
            "timeout": f.timeout,
            "completed": f.completed,
            "lookup_s": None if f.lookup_ns is None else ns_to_s(f.lookup_ns - t_start_ns),
            "target_x": float(self.waypoint[0]),
            "target_y": float(self.waypoint[1]),
            "target_theta": float(self.waypoint[2]),
            "robot_x": rx,
            "robot_y": ry,
            "robot_theta": rt,
            "mocap_gap_s": None if self.gap_ns is None else self.gap_ns / 1e9,
            "distance_error_m": self.distance_error,
            "orientation_error_rad": self.orientation_error,
            "referee_answers": " | ".join("(not executed)" if a is None else a for a in f.answers),
        }


@frozen_dataclass(eq=False)
class HnfResult(ScoreFormResult):
    """A scored HNF run (implements ``BenchmarkResult``; its score, comparison, intervals and
    outputs: :class:`ScoreFormResult`).

    Attributes:
        segments: the waypoints the script got to.
        waypoints: every waypoint of the config.
        position_accuracy, orientation_accuracy: the totals (None: not computed).
        totals: the totals were written.
        rules: ``--rules``; script: the commit whose control flow was followed.
        t_start_ns: the benchmark's start (times in tables are seconds from it).
        stop_ns: the referee's stop or the global timeout, None when the script ended it.
        track: the marker set's (t_ns, (x, y)) thinned, for plots and Foxglove.
    """

    segments: tuple[HnfSegment, ...]
    waypoints: tuple[tuple[Any, Any, Any], ...]
    position_accuracy: float | None
    orientation_accuracy: float | None
    totals: bool
    rules: str
    script: str
    t_start_ns: int
    stop_ns: int | None
    track: tuple[I64, F64]
    name: str = "hnf"

    @property
    def nothing_scored(self) -> bool:
        return not any(s.measured for s in self.segments)

    @property
    def execution_time(self) -> float:
        return float(sum(ns_to_s(s.flow.end_ns - s.flow.start_ns) for s in self.segments))

    def score_rows(self) -> list[ScoreRow]:
        return [
            ScoreRow(POSITION_KEY, self.position_accuracy, self.interval(POSITION_KEY)),
            ScoreRow(ORIENTATION_KEY, self.orientation_accuracy, self.interval(ORIENTATION_KEY)),
        ]

    def tables(self) -> dict[str, Rows]:
        """``segments``, ``scores`` (the totals with their intervals), ``comparison`` (each
        score field against the live score and the file) and the interval tables."""
        return self.result_tables(
            {"segments": [s.row(self.t_start_ns) for s in self.segments]},
            score_table(self.score_rows()),
        )


def deviations_of(
    options: HnfOptions, segments: Sequence[HnfSegment], flow: HnfFlow
) -> tuple[Deviation, ...]:
    """What ertools' reading changed in this run, one line per rule not at the script's."""
    out: list[Deviation] = []
    measured = [s for s in segments if s.measured]
    if not options.orientation_2019:
        crossing = [
            s.index + 1
            for s in measured
            if s.robot is not None and abs(s.robot[2] - float(s.waypoint[2])) > math.pi
        ]
        where = (
            f"segment(s) {', '.join(map(str, crossing))} cross +-pi here"
            if crossing
            else "no segment crosses +-pi here: the same numbers"
        )
        out.append(
            RULE_ORIENTATION_WRAP.deviation(
                f"yaw differences wrapped to [-pi, pi] before sin/cos ({where})"
            )
        )
    if not options.divisor_2019:
        completed = sum(s.flow.completed for s in segments)
        used = sum(s.measured and s.flow.completed for s in segments)
        out.append(
            RULE_DIVISOR.deviation(
                f"accuracies over the {used} completed goal(s) with a measured pose; the script "
                f"divides the errors of all {len(measured)} measured pose(s) by the {completed} "
                "completed goal(s)"
            )
        )
        skipped = [s.index + 1 for s in segments if s.flow.skipped and s.flow.completed]
        if skipped:
            out.append(
                RULE_SKIPPED.deviation(
                    f"completed segment(s) {', '.join(map(str, skipped))} skipped by the referee "
                    "left out of the accuracies; the script counts them in its divisor"
                )
            )
    if not options.stopped_2019 and not flow.totals:
        out.append(
            RULE_STOPPED.deviation(
                f"totals over the {len(segments)} segment(s) the script got to before the stop; "
                "the script returned without totals"
            )
        )
    if not options.gaps_interpolate:
        out.append(
            RULE_GT_GAPS.deviation(
                f"a pose only where the marker set's samples around the lookup are at most "
                f"{options.max_gap_s:g} s apart; tf interpolated across any gap"
            )
        )
    if not options.score_format_2019:
        out.append(
            RULE_SCORE_FORMAT.deviation(
                "target_pose and robot_pose as {x, y, theta}; the script wrote YAML dumps of "
                "Pose2D objects"
            )
        )
    return tuple(out)


def as_array(values: Sequence[float | None]) -> F64:
    """Values with None as NaN."""
    return np.array([np.nan if v is None else v for v in values], dtype=np.float64)
