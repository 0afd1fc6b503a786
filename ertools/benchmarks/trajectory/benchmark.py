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
from dataclasses import dataclass, field, replace
from itertools import pairwise
from pathlib import Path
from typing import TYPE_CHECKING

from ertools.benchmarks.trajectory.config import TrajectoryConfig
from ertools.benchmarks.trajectory.inputs import (
    find_gt_files,
    pick_gt_in_robot_bag,
    pick_robot_topic,
    read_gt,
    read_gt_chain,
    read_robot,
    same_bag,
)
from ertools.benchmarks.trajectory.result import TrajectoryResult
from ertools.benchmarks.trajectory.rules import RULE_GT_OVERLAP
from ertools.benchmarks.trajectory.scoring import score_streams
from ertools.errors import ClockError, ScoringError
from ertools.io import summary
from ertools.streams import PoseStream
from ertools.timeutil import NS_PER_S, iso_utc

if TYPE_CHECKING:
    from ertools.io import BagSummary


@dataclass(frozen=True)
class TrajectoryOptions:
    """Everything ``ertools score trajectory`` can be told: how to compare (``config``) and
    where the poses are.

    Attributes:
        config: association, gaps, offset, coverage (:class:`TrajectoryConfig`).
        robot_topic: the robot's pose of its marker set (None: the one
            ``/rockin/*/marker_pose``).
        gt_topic: the mocap pose of that marker set (None: the one PoseStamped topic).
        robot_time: ``header`` (message stamps) or ``record`` (the robot bag's record time).
    """

    config: TrajectoryConfig = field(default_factory=TrajectoryConfig)
    robot_topic: str | None = None
    gt_topic: str | None = None
    robot_time: str = "header"


@dataclass(frozen=True, eq=False)
class TrajectoryLogs:
    """What :func:`load` read: the robot stream and the GT stream read from the GT files
    chosen (by time overlap), with their topics, warnings and damaged GT files."""

    robot_path: str
    robot_topic: str
    robot: PoseStream
    chosen: tuple[BagSummary, ...]
    gt_topic: str
    gt: PoseStream
    warnings: tuple[str, ...]
    broken: tuple[str, ...]


def load(paths: Sequence[str | Path], options: TrajectoryOptions) -> TrajectoryLogs:
    """The robot log (``paths[0]``) and the GT poses of ``paths[1:]`` (bags or folders) that
    cover it; with no GT path, or the robot log itself as the only one, the GT topic is read
    from the robot log (evo's ``bag`` mode: one bag recorded both topics).

    Raises:
        BagError, TopicError: unreadable files, missing topics.
        ClockError: no GT overlapping the robot log.
        ScoringError: no robot pose.
    """

    if not paths:
        raise ScoringError("no robot log given")
    cfg = options.config
    robot_path, gt_paths = str(paths[0]), list(paths[1:])
    rs = summary(robot_path)
    topic = pick_robot_topic(rs, options.robot_topic)
    robot = read_robot(robot_path, topic, options.robot_time)
    if len(robot) == 0:
        raise ScoringError(f"{robot_path}: robot topic {topic} has no messages")
    # The robot's span on the GT clock, widened by the clock audit's search range.
    lo = int(robot.t_ns.min()) + cfg.offset_ns
    hi = int(robot.t_ns.max()) + cfg.offset_ns
    margin = max(cfg.offset_range_ns, NS_PER_S)
    if same_bag(robot_path, gt_paths):
        # evo's `bag` mode: one bag holds both the robot's topic and the GT topic.
        chosen = [rs]
        gtopic = pick_gt_in_robot_bag(rs, options.gt_topic, topic, gt_paths)
        warnings: list[str] = []
        broken: list[str] = []
    else:
        chosen, gtopic, warnings, broken = find_gt_files(
            robot_path, gt_paths, lo - margin, hi + margin, options.gt_topic
        )
    if cfg.gt_order == "chain":
        chosen, dropped = _files_2015(chosen, rs, cfg.offset_ns)
        warnings.extend(dropped)
        # 2015 read every message of every file chosen, in the files' start order.
        gt = read_gt_chain([s.path for s in chosen], gtopic)
    else:
        gt = read_gt([s.path for s in chosen], gtopic, lo - margin, hi + margin)
    return TrajectoryLogs(
        robot_path, topic, robot, tuple(chosen), gtopic, gt, tuple(warnings), tuple(broken)
    )


def _files_2015(
    chosen: Sequence[BagSummary], robot: BagSummary, offset_ns: int
) -> tuple[list[BagSummary], list[str]]:
    """The GT files 2015 chained: those whose span overlaps the robot bag's own (``rosbag
    info`` start <= robot end and end >= robot start, no margin), in start order.

    Only the chain depends on it: a file ending just before the robot log puts its last pose
    before the first robot pose's pair. Raises ClockError when none is left (2015: exit 4).
    """
    lo, hi = robot.start_ns + offset_ns, robot.end_ns + offset_ns
    inside = [s.start_ns <= hi and s.end_ns >= lo for s in chosen]
    kept = [s for s, ok in zip(chosen, inside, strict=True) if ok]
    dropped = [
        f"GT file {s.path} does not overlap the robot log's span: not chained (--gt-order "
        "chain chains the files 2015 chose, those overlapping the robot bag)"
        for s, ok in zip(chosen, inside, strict=True)
        if not ok
    ]
    if not kept:
        raise ClockError(
            f"no GT file overlaps the robot log {robot.path} itself ({iso_utc(lo)} to "
            f"{iso_utc(hi)}): 2015 stopped there ('NO suitable rockin_mocap bags'); "
            "--gt-order time searches around it"
        )
    return kept, dropped


def locate_runs(logs: TrajectoryLogs, options: TrajectoryOptions) -> None:
    """Nothing to find: the whole robot log is the one run compared."""
    return None


def score_found(logs: TrajectoryLogs, runs: None, options: TrajectoryOptions) -> TrajectoryResult:
    """Compare the robot stream with the GT stream (:func:`score_streams`).

    Raises:
        ClockError: robot poses outside the GT (naming damaged GT files).
        ScoringError: non-increasing robot stamps.
    """
    files = [s.path for s in logs.chosen]
    try:
        result = score_streams(
            logs.robot,
            logs.gt,
            options.config,
            robot_file=logs.robot_path,
            robot_topic=logs.robot_topic,
            gt_topic=logs.gt_topic,
            gt_files=files,
            warnings=list(logs.warnings),
        )
    except ClockError as err:
        if not logs.broken:
            raise
        # The warnings die with the error: name the damaged GT file where the user looks.
        raise ClockError(
            f"{err}; damaged GT file(s), read only up to the damage: {', '.join(logs.broken)}"
        ) from err
    overlaps = sum(1 for a, b in pairwise(logs.chosen) if b.start_ns < a.end_ns)
    if overlaps and options.config.gt_order == "time":
        dev = RULE_GT_OVERLAP.deviation(
            f"{overlaps} pair(s) of GT files overlap in time: their poses are merged in time "
            "order, a message recorded twice used once (2015 chained the files by start time "
            "and scanned the poses out of order)"
        )
        result = replace(result, deviations=(*result.deviations, dev))
    return result


def score(
    robot_bag: str | Path,
    gt_paths: Sequence[str | Path],
    config: TrajectoryConfig | None = None,
    *,
    robot_topic: str | None = None,
    gt_topic: str | None = None,
    robot_time: str = "header",
) -> TrajectoryResult:
    """Score a robot log against the GT files (or folders of them) that cover it: load ->
    compare (see :func:`load`, :func:`score_found`)."""
    options = TrajectoryOptions(config or TrajectoryConfig(), robot_topic, gt_topic, robot_time)
    logs = load([robot_bag, *gt_paths], options)
    locate_runs(logs, options)  # one run: the whole robot log
    return score_found(logs, None, options)
