"""The HPFF result: the score in the result file's form, the samples, the duration rule, the
comparison with the run's own scores, the intervals, and what ertools' reading changed."""

from __future__ import annotations

import numpy as np

from ertools.arrays import F64, I64, Bool
from ertools.benchmarks.base import Rows
from ertools.benchmarks.common.interval_output import ScoreRow
from ertools.benchmarks.common.score_form import ScoreFormResult
from ertools.benchmarks.hpff.config import HpffOptions
from ertools.benchmarks.hpff.formula import Following
from ertools.benchmarks.hpff.rules import (
    RULE_DURATION,
    RULE_PLANE,
    RULE_RELIABILITY,
    RULE_SAMPLING,
    RULE_STOPPED,
)
from ertools.fidelity import Deviation
from ertools.frozen_dataclass import frozen_dataclass

DEVIATION_KEY = "Average deviation from desired distance"
COVERED_KEY = "Distance covered while following"
RELIABILITY_KEY = "Benchmark reliability"


@frozen_dataclass(eq=False)
class HpffSamples:
    """The run's samples as scored.

    Attributes:
        t_ns: (K,) each sample's moment (its start; the grid's point).
        distance: (K,) the following distance (NaN where not measured).
        measured: (K,) the distance was measured (the script's relative lookup succeeded).
        robot_xy: (K, 2) the robot's position in the testbed (NaN where unknown).
        robot_ok: (K,) the robot's position is known.
        person_xy: (K, 2) the cap's position (NaN where unknown; for the figures).
    """

    t_ns: I64
    distance: F64
    measured: Bool
    robot_xy: F64
    robot_ok: Bool
    person_xy: F64


@frozen_dataclass(eq=False)
class HpffResult(ScoreFormResult):
    """A scored HPFF run (implements ``BenchmarkResult``; its score, comparison, intervals and
    outputs: :class:`ScoreFormResult`).

    Attributes:
        samples, stats: the samples and their statistics (None: nothing was sampled).
        duration_s: the run's duration as the duration rule measures it (None: not measured).
        passed: the duration rule passed (None: not checked, the run stopped first).
        goal_timeout, desired, minimum, maximum: the config's values.
        t_start_ns: the benchmark's start (tables are in seconds from it).
        rules: ``--rules``.
        tracks: the robot's and the person's (t_ns, (x, y)) thinned, for figures and Foxglove.
    """

    samples: HpffSamples
    stats: Following | None
    duration_s: float | None
    passed: bool | None
    goal_timeout: float
    desired: float
    minimum: float
    maximum: float
    t_start_ns: int
    rules: str
    tracks: tuple[tuple[I64, F64], tuple[I64, F64]]
    name: str = "hpff"

    @property
    def nothing_scored(self) -> bool:
        return self.stats is None or self.stats.measured == 0

    @property
    def average_deviation(self) -> float | None:
        return None if self.stats is None else self.stats.average_deviation

    def score_rows(self) -> list[ScoreRow]:
        covered = None if self.stats is None else float(self.stats.covered)
        return [
            ScoreRow(DEVIATION_KEY, self.average_deviation, self.interval(DEVIATION_KEY)),
            ScoreRow(COVERED_KEY, covered, self.interval(COVERED_KEY)),
        ]

    def tables(self) -> dict[str, Rows]:
        """``samples`` (one row per sample), ``scores`` and ``comparison``."""
        s = self.samples
        stats = self.stats
        rows = []
        for k in range(len(s.t_ns)):
            rows.append(
                {
                    "sample": k,
                    "t_s": (int(s.t_ns[k]) - self.t_start_ns) / 1e9,
                    "measured": bool(s.measured[k]),
                    "distance_m": None if not s.measured[k] else float(s.distance[k]),
                    "deviation_m": None
                    if stats is None or not s.measured[k]
                    else float(stats.deviation[k]),
                    "robot_x": None if not s.robot_ok[k] else float(s.robot_xy[k, 0]),
                    "robot_y": None if not s.robot_ok[k] else float(s.robot_xy[k, 1]),
                    "covered_step_m": None
                    if stats is None or not stats.counted[k]
                    else float(stats.steps[k]),
                }
            )
        scores = [
            {
                "score": r.name,
                "value": r.value,
                "low": None if r.interval is None else r.interval.low,
                "high": None if r.interval is None else r.interval.high,
            }
            for r in self.score_rows()
        ]
        scores.append({"score": "duration_s", "value": self.duration_s, "low": None, "high": None})
        return self.result_tables({"samples": rows}, scores)


def deviations_of(
    options: HpffOptions, stopped: bool, failed_duration: bool
) -> tuple[Deviation, ...]:
    """What ertools' reading changed in this run, one line per rule not at the script's."""
    out: list[Deviation] = []
    if not options.sampling_script:
        out.append(
            RULE_SAMPLING.deviation(
                f"samples on a 2 Hz grid, both bodies interpolated within {options.max_gap_s:g} s; "
                "the script sampled at its own lookups' moments"
            )
        )
        out.append(
            RULE_RELIABILITY.deviation(
                "reliability from the grid samples without valid mocap; the script counted its "
                "failed relative lookups"
            )
        )
    if not options.plane_actor:
        out.append(
            RULE_PLANE.deviation(
                "the horizontal distance in the testbed frame; the script measured it in the "
                "cap's frame"
            )
        )
    if not options.clock_script:
        out.append(
            RULE_DURATION.deviation(
                "the duration from the RefBox's goal start to its end; the script timed its "
                "own loop"
            )
        )
    if not options.stopped_2019 and (stopped or failed_duration):
        out.append(
            RULE_STOPPED.deviation(
                "the statistics of the samples kept beside the Result; the script wrote "
                + ("{} for a stopped run" if stopped else "the Result alone")
            )
        )
    return tuple(out)


def nan_xy(xy: F64, ok: Bool) -> F64:
    """(K, 2) positions with NaN where not known."""
    return np.asarray(np.where(ok[:, None], xy, np.nan))
