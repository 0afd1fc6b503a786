"""Robot log vs mocap ground truth: the 2015 offline trajectory benchmark, with a clock audit.

The 2015 ``rockin_offline_trajectory_benchmark`` compared every pose a robot logged for its own
marker set (``/rockin/<team>/marker_pose``) with the mocap pose of that marker set: for each
robot pose it took the GT pose pair (p1, p2) with p1.t <= t <= p2.t, skipped the robot pose when
p1 and p2 had the same position (Motive repeats the last pose when tracking is lost), compared
with p1 ("hold") and reported the mean 3D distance and atan2(sum sin|dyaw|, sum cos|dyaw|).
Where ertools' default differs, one option restores each 2015 behaviour (the ``RULE_*``
constants) and :meth:`TrajectoryConfig.of_2015` (``--2015``) all of them at once.

Shape: load (robot stream, GT files selected by time overlap, read as one stream: ``inputs``)
-> associate (hold | nearest | linear, max-gap, tracking lost, coverage: ``association``) ->
``metrics`` -> frozen :class:`~ertools.benchmarks.trajectory.result.TrajectoryResult`
(``result``). The settings are in ``config``, the 2015 rules in ``rules``. The clock audit
(:mod:`ertools.benchmarks.common.clocks`) runs every time.
:func:`~ertools.benchmarks.trajectory.scoring.score_streams` is pure; :func:`score` is the IO
edge.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from itertools import pairwise
from pathlib import Path

from ertools.benchmarks.trajectory.config import TrajectoryConfig
from ertools.benchmarks.trajectory.inputs import (
    find_gt_files,
    pick_gt_in_robot_bag,
    pick_robot_topic,
    read_gt,
    read_robot,
    same_bag,
)
from ertools.benchmarks.trajectory.result import TrajectoryResult
from ertools.benchmarks.trajectory.rules import RULE_GT_OVERLAP
from ertools.benchmarks.trajectory.scoring import score_streams
from ertools.errors import ClockError, ScoringError
from ertools.timeutil import NS_PER_S


def score(
    robot_bag: str | Path,
    gt_paths: Sequence[str | Path],
    config: TrajectoryConfig | None = None,
    *,
    robot_topic: str | None = None,
    gt_topic: str | None = None,
    robot_time: str = "header",
) -> TrajectoryResult:
    """Score a robot log against the GT files (or folders of them) that cover it.

    With no GT path, or the robot log itself as the only one, the GT topic is read from the
    robot log (evo's ``bag`` mode: one bag recorded both topics).

    Raises:
        BagError, TopicError: unreadable files, missing topics.
        ClockError: no GT overlapping the robot log, poses outside the GT.
        ScoringError: non-increasing robot stamps.
    """
    from ertools.io import summary

    cfg = config or TrajectoryConfig()
    robot_path = str(robot_bag)
    rs = summary(robot_path)
    topic = pick_robot_topic(rs, robot_topic)
    robot = read_robot(robot_path, topic, robot_time)
    if len(robot) == 0:
        raise ScoringError(f"{robot_path}: robot topic {topic} has no messages")
    # The robot's span on the GT clock, widened by the clock audit's search range.
    lo = int(robot.t_ns.min()) + cfg.offset_ns
    hi = int(robot.t_ns.max()) + cfg.offset_ns
    margin = max(cfg.offset_range_ns, NS_PER_S)
    if same_bag(robot_path, gt_paths):
        # evo's `bag` mode: one bag holds both the robot's topic and the GT topic.
        chosen, gtopic = [rs], pick_gt_in_robot_bag(rs, gt_topic, topic, gt_paths)
        warnings: list[str] = []
        broken: list[str] = []
    else:
        chosen, gtopic, warnings, broken = find_gt_files(
            robot_path, gt_paths, lo - margin, hi + margin, gt_topic
        )
    files = [s.path for s in chosen]
    gt = read_gt(files, gtopic, lo - margin, hi + margin)
    try:
        result = score_streams(
            robot,
            gt,
            cfg,
            robot_file=robot_path,
            robot_topic=topic,
            gt_topic=gtopic,
            gt_files=files,
            warnings=warnings,
        )
    except ClockError as err:
        if not broken:
            raise
        # The warnings die with the error: name the damaged GT file where the user looks.
        raise ClockError(
            f"{err}; damaged GT file(s), read only up to the damage: {', '.join(broken)}"
        ) from err
    overlaps = sum(1 for a, b in pairwise(chosen) if b.start_ns < a.end_ns)
    if overlaps:
        dev = RULE_GT_OVERLAP.deviation(
            f"{overlaps} pair(s) of GT files overlap in time: their poses are merged in time "
            "order, a message recorded twice used once (2015 chained the files by start time "
            "and scanned the poses out of order)"
        )
        result = replace(result, deviations=(*result.deviations, dev))
    return result
