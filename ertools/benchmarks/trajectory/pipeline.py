"""Robot log vs mocap ground truth: the 2015 offline trajectory benchmark, with a clock audit.

The 2015 ``rockin_offline_trajectory_benchmark`` compared every pose a robot logged for its own
marker set (``/rockin/<team>/marker_pose``) with the mocap pose of that marker set: for each
robot pose it took the GT pose pair (p1, p2) with p1.t <= t <= p2.t, skipped the robot pose when
p1 and p2 had the same position (Motive repeats the last pose when tracking is lost), compared
with p1 ("hold") and reported the mean 3D distance and atan2(sum sin|dyaw|, sum cos|dyaw|).
Where ertools' default differs, one option restores each 2015 behaviour (the ``RULE_*``
constants) and :meth:`TrajectoryConfig.of_2015` (``--2015``) all of them at once.

Shape: :func:`load` (robot stream, GT files selected by time overlap, read as one stream:
``logs``) -> associate (hold | nearest | linear, max-gap, tracking lost, coverage:
``association``) -> ``formula`` -> frozen
:class:`~ertools.benchmarks.trajectory.result.TrajectoryResult` (``result``): :func:`score_runs`.
The settings are in ``config``, the 2015 rules in ``rules``. The clock audit
(:mod:`ertools.benchmarks.common.clocks`) runs every time.
:func:`~ertools.benchmarks.trajectory.comparison.score_streams` is pure.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from itertools import pairwise
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ertools.benchmarks.trajectory.comparison import score_streams
from ertools.benchmarks.trajectory.config import TrajectoryOptions
from ertools.benchmarks.trajectory.logs import (
    find_gt_files,
    pick_gt_in_robot_bag,
    pick_robot_topic,
    read_gt,
    read_gt_chain,
    read_robot,
    read_robot_clocks,
    same_bag,
)
from ertools.benchmarks.trajectory.result import TrajectoryResult
from ertools.benchmarks.trajectory.rules import RULE_GT_OVERLAP
from ertools.errors import ClockError, ScoringError, UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.summary import summary
from ertools.io.text import is_text_trajectory, read_text_poses
from ertools.streams import PoseStream
from ertools.timeutil import NS_PER_S, iso_utc, ns_to_s

if TYPE_CHECKING:
    from ertools.io.model import BagSummary


@frozen_dataclass(eq=False)
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
    by_index: bool = False
    gt_file_names: tuple[str, ...] = ()

    @property
    def gt_files(self) -> list[str]:
        """The GT files read: the bags chosen, or the text trajectory."""
        return [s.path for s in self.chosen] or list(self.gt_file_names)


def load(paths: Sequence[str | Path], options: TrajectoryOptions) -> TrajectoryLogs:
    """The robot log (``paths[0]``) and the GT poses of ``paths[1:]`` (bags or folders) that
    cover it; with no GT path, or the robot log itself as the only one, the GT topic is read
    from the robot log (evo's ``bag`` mode: one bag recorded both topics). Text trajectories
    (TUM, KITTI, EuRoC, ertools CSV) are read whole (:func:`load_text`).

    Robot and GT are selected and paired by their time source (``header`` stamps by default):
    in a bag whose header stamps are on another clock than its record times (simulation
    time), the GT is read by header stamps all the same, and a warning says which was used.

    Raises:
        BagError, TopicError: unreadable files, missing topics.
        ClockError: no GT overlapping the robot log.
        ScoringError: no robot pose.
    """

    if not paths:
        raise ScoringError("no robot log given")
    cfg = options.config
    robot_path, gt_paths = str(paths[0]), list(paths[1:])
    kinds = [is_text_trajectory(p, options.input_format) for p in paths]
    if any(kinds):
        return load_text(paths, kinds, options)
    rs = summary(robot_path)
    topic = pick_robot_topic(rs, options.robot_topic)
    robot, clock_gap = read_robot_clocks(robot_path, topic, options.robot_time)
    # The robot's header stamps on the GT clock vs its record times.
    clock_gap += cfg.offset_ns if options.robot_time == "header" else 0
    if len(robot) == 0:
        raise ScoringError(f"{robot_path}: robot topic {topic} has no messages")
    # The robot's span on the GT clock, widened by the clock audit's search range.
    lo = int(robot.t_ns.min()) + cfg.offset_ns
    hi = int(robot.t_ns.max()) + cfg.offset_ns
    margin = max(cfg.offset_range_ns, NS_PER_S)
    warnings: list[str] = []
    # Header stamps and record times further apart than the log is long: a simulation clock
    # (or a robot clock far off). Record-time windows cannot find header-stamped poses then.
    apart = abs(clock_gap) > max(hi - lo, margin)
    if apart:
        used = (
            "header stamps"
            if options.robot_time == options.gt_time == "header"
            else f"robot {options.robot_time}, GT {options.gt_time} times"
        )
        warnings.append(
            f"{robot_path}: header stamps and record times differ by "
            f"{ns_to_s(clock_gap):+.3f} s, more than the log's span "
            f"({ns_to_s(hi - lo):.3f} s; simulation time?): robot and GT paired by {used} "
            "(--time-source header|record)"
        )
    evo = cfg.t_max_diff is not None
    window: tuple[int | None, int | None] = (lo - margin, hi + margin)
    gt: PoseStream | None = None
    if same_bag(robot_path, gt_paths):
        # evo's `bag` mode: one bag holds both the robot's topic and the GT topic.
        chosen = [rs]
        gtopic = pick_gt_in_robot_bag(rs, options.gt_topic, topic, gt_paths)
        broken: list[str] = []
        if evo:
            window = (None, None)  # evo reads the whole GT topic: its count picks the side
    else:
        if apart and options.robot_time == "header":
            # Simulation time: the GT files' spans are record times, so the robot's span in
            # record time finds them; their poses are then read by header stamps.
            try:
                found = find_gt_files(
                    robot_path,
                    gt_paths,
                    lo - margin - clock_gap,
                    hi + margin - clock_gap,
                    options.gt_topic,
                )
                gt = _read_gt_of(found[0], found[1], window, options.gt_time, prefilter=False)
            except ClockError:
                gt = None
            if gt is not None and len(gt) < 2:
                # Not a simulation clock shared with the GT: only the robot's stamps are off.
                # The usual selection says so (no GT file overlaps; --offset).
                gt = None
        if gt is None:
            found = find_gt_files(robot_path, gt_paths, lo - margin, hi + margin, options.gt_topic)
        chosen, gtopic, found_warnings, broken = found
        warnings += found_warnings
    if cfg.gt_order == "chain":
        chosen, dropped = _files_2015(chosen, rs, cfg.offset_ns)
        warnings.extend(dropped)
        # 2015 read every message of every file chosen, in the files' start order.
        gt = read_gt_chain([s.path for s in chosen], gtopic)
    elif gt is None:
        prefilter = not (apart and options.gt_time == "header")
        gt = _read_gt_of(chosen, gtopic, window, options.gt_time, prefilter=prefilter)
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


def _read_gt_of(
    chosen: Sequence[BagSummary],
    topic: str,
    window: tuple[int | None, int | None],
    time_source: str,
    *,
    prefilter: bool,
) -> PoseStream:
    return read_gt(
        [s.path for s in chosen], topic, *window, time_source=time_source, prefilter=prefilter
    )


def load_text(
    paths: Sequence[str | Path], kinds: Sequence[str | None], options: TrajectoryOptions
) -> TrajectoryLogs:
    """Robot and GT as text trajectories (or one of them a bag): each file read whole.

    KITTI has no time stamps: both files must be KITTI with as many rows, paired row by row
    as ``evo_ape kitti`` pairs them.

    Raises:
        UsageError: KITTI with another format, or no GT file.
        ScoringError: KITTI files with different row counts.
    """
    if len(paths) != 2:
        raise UsageError(
            f"a text trajectory holds one trajectory: give the robot's file and one GT file "
            f"(got {len(paths)} path(s))"
        )
    for time, kind, what in (
        (options.robot_time, kinds[0], "robot"),
        (options.gt_time, kinds[1], "GT"),
    ):
        if time == "record" and kind is not None:
            raise UsageError(
                f"record times asked for the {what}, but its file is a {kind.upper()} text "
                "trajectory: it has only its stamps (drop --time-source record)"
            )
    if "kitti" in kinds and kinds[0] != kinds[1]:
        raise UsageError(
            "KITTI files have no time stamps: robot and GT must both be KITTI, paired row by "
            f"row as `evo_ape kitti` pairs them (got {kinds[0] or 'a bag'} and "
            f"{kinds[1] or 'a bag'})"
        )
    streams: list[PoseStream] = []
    topics: list[str] = []
    for path, kind, topic, what in zip(
        paths, kinds, (options.robot_topic, options.gt_topic), ("robot", "GT"), strict=True
    ):
        if kind is not None:
            streams.append(read_text_poses(path, kind))  # type: ignore[arg-type]
            topics.append(kind)
            continue
        if topic is None:
            raise UsageError(
                f"the {what} is a bag beside a text trajectory: give --{what.lower()}-topic"
            )
        if what == "robot":
            streams.append(read_robot(str(path), topic, options.robot_time))
        else:
            streams.append(read_gt([str(path)], topic, None, None, time_source=options.gt_time))
        topics.append(topic)
    robot, gt = streams
    by_index = kinds[0] == "kitti"
    if by_index and len(robot) != len(gt):
        raise ScoringError(
            f"KITTI files are paired row by row: the robot's {paths[0]} has {len(robot)} rows, "
            f"the GT's {paths[1]} {len(gt)} (evo_ape kitti refuses them too)"
        )
    for stream, path in ((robot, paths[0]), (gt, paths[1])):
        if len(stream) == 0:
            raise ScoringError(f"{path}: no poses")
    if len(gt) > 1 and np.any(np.diff(gt.t_ns) < 0):
        order = np.argsort(gt.t_ns, kind="stable")
        gt = gt.take(order)
    return TrajectoryLogs(
        str(paths[0]),
        topics[0],
        robot,
        (),
        topics[1],
        gt,
        (),
        (),
        by_index=by_index,
        gt_file_names=(str(paths[1]),),
    )


def find_runs(logs: TrajectoryLogs, options: TrajectoryOptions) -> None:
    """Nothing to find: the whole robot log is the one run compared."""
    return None


def score_runs(logs: TrajectoryLogs, runs: None, options: TrajectoryOptions) -> TrajectoryResult:
    """Compare the robot stream with the GT stream (:func:`score_streams`).

    Raises:
        ClockError: robot poses outside the GT (naming damaged GT files).
        ScoringError: non-increasing robot stamps.
    """
    files = logs.gt_files
    config = options.config
    warnings = list(logs.warnings)
    if logs.by_index:
        # KITTI: the row numbers are the stamps of both files; evo's rule with a limit of 0
        # pairs row i with row i, as evo_ape kitti does.
        config = replace(config, association="nearest", t_max_diff=0.0, offset_ns=0)
        warnings.append("KITTI files have no time stamps: robot and GT paired row by row")
    try:
        result = score_streams(
            logs.robot,
            logs.gt,
            config,
            robot_file=logs.robot_path,
            robot_topic=logs.robot_topic,
            gt_topic=logs.gt_topic,
            gt_files=files,
            warnings=warnings,
            intervals=options.intervals,
        )
    except ClockError as err:
        if not logs.broken:
            raise
        # The warnings die with the error: name the damaged GT file where the user looks.
        raise ClockError(
            f"{err}; damaged GT file(s), read only up to the damage: {', '.join(logs.broken)}"
        ) from err
    if logs.by_index:
        # The clock audit compared row numbers, not times: nothing to say about clocks.
        kept = tuple(w for w in result.warnings if not w.startswith("clock audit"))
        result = replace(result, warnings=kept)
    overlaps = sum(1 for a, b in pairwise(logs.chosen) if b.start_ns < a.end_ns)
    if overlaps and options.config.gt_order == "time":
        dev = RULE_GT_OVERLAP.deviation(
            f"{overlaps} pair(s) of GT files overlap in time: their poses are merged in time "
            "order, a message recorded twice used once (2015 chained the files by start time "
            "and scanned the poses out of order)"
        )
        result = replace(result, deviations=(*result.deviations, dev))
    return result
