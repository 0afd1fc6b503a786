"""HGMF's score in the result file's form (docs/hgmf.md, "Score"), as the script wrote it:
per goal its time, outcome and, once completed and measured, the grasp, the distance, the
positions and the object; then the totals (l. 180-259).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import field
from typing import Any

from ertools.benchmarks.hgmf.config import HgmfOptions
from ertools.benchmarks.hgmf.flow import HgmfFlow
from ertools.benchmarks.hgmf.formula import grasp_text, object_text, position_text, to_sec
from ertools.benchmarks.hgmf.result import HgmfGoal
from ertools.frozen_dataclass import frozen_dataclass

GRASPED = "Objects grasped"
AVERAGE = "Avg distance error"
EXECUTION_TIME = "execution_time"


@frozen_dataclass
class Listing:
    """The score mapping and its totals.

    Attributes:
        score: ``goal_<i>`` mappings and the totals, as the script left them.
        average: ``Avg distance error`` (None: never written).
        counted: its divisor (the goals counted).
        grasped: the grasps counted.
        notes: what a referee should know of the listing.
        failures: what could not be scored.
    """

    score: dict[str, Any]
    average: float | None
    counted: int
    grasped: int
    notes: list[str] = field(default_factory=list)
    failures: list[str] = field(default_factory=list)


def score_listing(
    goals: Sequence[HgmfGoal], flow: HgmfFlow, objects: int, options: HgmfOptions
) -> Listing:
    """The score of the attempts in the script's order (``2019`` rules: its counts; ertools'
    reading: only the goals measured count)."""
    score: dict[str, Any] = {}
    elapsed = 0  # ns, the script's Duration sum
    counted = grasped = 0
    total: float = 0  # the script's distance_error_sum, an int 0 until a distance is added
    average: float | None = None
    notes: list[str] = []
    failures: list[str] = []
    for g in goals:
        a = g.attempt
        key = f"goal_{a.index}"
        entry: dict[str, Any] = {}
        score[key] = entry
        segment = a.times.segment_ns
        elapsed += segment
        entry["segment_time [s]"] = float(to_sec(segment))
        entry["timeout"] = a.times.timeout
        entry["completed"] = a.times.completed
        if a.times.completed:
            scored = g.distance_error is not None
            if scored or (options.restarted_goals_2019 and a.restarted):
                counted += 1
                grasped += int(g.grasped)
            if a.restarted:
                elapsed -= segment
                notes.append(
                    f"{key}: completed, but the object's final position could not be looked "
                    "up: the script ran the goal again"
                    + (" (still counted, 2019)" if options.restarted_goals_2019 else "")
                )
                continue
            entry["Object grasped"] = g.grasped
            entry["Distance error"] = g.distance_error
            if a.target is not None:
                entry["Target object position"] = position_text(*a.target)
            if g.position is not None:
                entry["Measured object position"] = position_text(*g.position)
            if a.object_id is not None:
                entry["Object type"] = object_text(g.description, a.object_id)
            if scored and g.distance_error is not None:
                total += g.distance_error
                score[GRASPED] = grasp_text(grasped, objects)
                average = total / counted
                score[AVERAGE] = average
            elif a.target is None:
                failures.append(g.unscored_reason(options.max_gap_s))
            else:
                notes.append(g.unscored_reason(options.max_gap_s))
        else:
            entry["result"] = "Not completed"
        score[EXECUTION_TIME] = float(to_sec(elapsed))
    if len(flow.begun) > len(goals):  # the last iteration ended before its goal (a stop)
        score[f"goal_{flow.begun[-1]}"] = {}
    if not options.exact and counted and any(g.distance_error is not None for g in goals):
        # ertools' reading: the totals over every goal counted (the script wrote them at each
        # measured goal only, so a goal counted after the last one left them stale)
        average = total / counted
        score[GRASPED] = grasp_text(grasped, objects)
        score[AVERAGE] = average
    return Listing(score, average, counted, grasped, notes, failures)
