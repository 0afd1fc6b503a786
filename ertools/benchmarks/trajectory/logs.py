"""The IO edge of the trajectory benchmark: the robot's pose topic and stream, and the GT files of
GT_PATH that cover it (or the GT topic in the robot log itself, evo's ``bag`` mode).
"""

from __future__ import annotations

from collections.abc import Sequence
from itertools import pairwise
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ertools.arrays import median
from ertools.errors import BagError, ClockError, ErtoolsError, TopicError
from ertools.io.files import open_bag
from ertools.io.formats import NO_SUCH, find_bags
from ertools.io.model import POSE_TYPES, TF_TYPES
from ertools.io.reader import load_pose_batch, read_poses
from ertools.io.summary import summary
from ertools.streams import PoseStream
from ertools.timeutil import iso_utc, ns_to_s

if TYPE_CHECKING:
    from ertools.io.model import BagSummary


def _pose_topics(s: BagSummary) -> list[str]:
    return [
        t.name for t in s.topics if t.msgtype in POSE_TYPES and t.name not in ("/tf", "/tf_static")
    ]


def pick_robot_topic(s: BagSummary, topic: str | None) -> str:
    if topic is not None:
        if s.topic(topic) is None:
            raise TopicError(
                f"robot topic {topic} not in {s.path}; pose topics there: "
                f"{', '.join(_pose_topics(s)) or 'none'}"
            )
        return topic
    cands = [
        t.name
        for t in s.topics
        if t.name.startswith("/rockin/") and t.name.endswith("/marker_pose")
    ]
    if len(cands) == 1:
        return cands[0]
    if not s.topics and s.problems:
        # a damaged file (cut short: its topics are in the lost index) is said for what it
        # is, not as a log without a pose topic
        raise BagError(f"{'; '.join(s.problems)}; re-copy the file", path=s.path)
    raise TopicError(
        f"{s.path}: give --robot-topic (found {len(cands)} /rockin/*/marker_pose topics; "
        f"pose topics there: {', '.join(_pose_topics(s)) or 'none'})"
    )


def read_robot(path: str, topic: str, time_source: str) -> PoseStream:
    """The robot's poses in recording order (not sorted: non-increasing stamps are errors)."""
    return read_robot_clocks(path, topic, time_source)[0]


def read_robot_clocks(path: str, topic: str, time_source: str) -> tuple[PoseStream, int]:
    """:func:`read_robot`, and the median of (header stamp - record time) of its messages:
    far from 0 in a bag recorded in simulation time (header stamps on the simulator's clock,
    record times on the wall clock)."""

    with open_bag(path) as bag:
        conns = bag.topic_conns(topic)
        types = {c.msgtype for c in conns}
        if not types or not types <= set(POSE_TYPES):
            raise TopicError(
                f"robot topic {topic} has type {', '.join(sorted(types)) or 'unknown'}, "
                f"not a pose type ({', '.join(POSE_TYPES)})",
                path=path,
            )
        if "geometry_msgs/Pose2D" in types and time_source == "header":
            raise TopicError(
                f"robot topic {topic} has type geometry_msgs/Pose2D, which has no header "
                "stamp; give --robot-time-source record",
                path=path,
            )
        batch = load_pose_batch(bag, conns, None, None)
    if (
        types & set(TF_TYPES)
        and len(batch)
        and (
            np.any(batch.child_idx != batch.child_idx[0])
            or np.any(batch.frame_idx != batch.frame_idx[0])
        )
    ):
        # A tf topic with several transforms: rows of different bodies, not one trajectory.
        names = zip(batch.frame_names(), batch.child_names(), strict=True)
        pairs = sorted({f"{a} -> {b}" for a, b in names})
        raise TopicError(
            f"robot topic {topic} holds the poses of several frames ({', '.join(pairs[:4])}"
            f"{' ...' if len(pairs) > 4 else ''}); give a topic with one body's poses",
            path=path,
        )
    t = batch.t_header if time_source == "header" else batch.t_record
    gap = int(median(batch.t_header - batch.t_record)) if len(batch) else 0
    return PoseStream(t, batch.xyz, batch.quat_xyzw, source=f"{path}:{topic}"), gap


def select_gt(
    summaries: Sequence[BagSummary],
    start_ns: int,
    end_ns: int,
    gt_topic: str | None,
) -> tuple[list[BagSummary], str, list[str]]:
    """GT files overlapping [start, end] that hold the GT topic, by start time.

    Returns the files, the topic (guessed when None and unambiguous) and warnings.
    """
    overlapping = sorted(
        (s for s in summaries if s.message_count and s.start_ns <= end_ns and s.end_ns >= start_ns),
        key=lambda s: (s.start_ns, s.path),
    )
    if not overlapping:
        spans = "; ".join(
            f"{Path(s.path).name} {iso_utc(s.start_ns)} to {iso_utc(s.end_ns)}"
            for s in sorted(summaries, key=lambda s: s.start_ns)[:4]
        )
        raise ClockError(
            f"no GT file overlaps the robot log ({iso_utc(start_ns)} to {iso_utc(end_ns)}, "
            "search margin included); "
            f"GT files: {spans or 'none'}{' ...' if len(summaries) > 4 else ''}; "
            "if the robot's clock was far off, give --offset S"
        )
    if gt_topic is None:
        cands = sorted(
            {
                t.name
                for s in overlapping
                for t in s.topics
                if t.msgtype == "geometry_msgs/PoseStamped" and not t.name.startswith("/rockin/")
            }
        )
        if len(cands) != 1:
            raise TopicError(
                f"give --gt-topic: the overlapping GT files hold {len(cands)} PoseStamped "
                f"topics ({', '.join(cands) or 'none'})"
            )
        gt_topic = cands[0]
    with_topic = [s for s in overlapping if s.topic(gt_topic) is not None]
    if not with_topic:
        topics = sorted({n for s in overlapping for n in _pose_topics(s)})
        raise TopicError(
            f"GT topic {gt_topic} is in none of the {len(overlapping)} GT file(s) overlapping "
            f"the robot log ({Path(overlapping[0].path).name}...); pose topics there: "
            f"{', '.join(topics) or 'none'}"
        )
    warnings = []
    for a, b in pairwise(with_topic):
        if b.start_ns < a.end_ns:
            warnings.append(
                f"GT files {Path(a.path).name} and {Path(b.path).name} overlap in time "
                f"({ns_to_s(a.end_ns - b.start_ns):.1f} s); their poses are merged in time order"
            )
    return with_topic, gt_topic, warnings


def read_gt(
    files: Sequence[str],
    topic: str,
    start_ns: int | None,
    end_ns: int | None,
    time_source: str = "header",
    prefilter: bool = True,
) -> PoseStream:
    """GT poses with stamps (``time_source``) in [start_ns, end_ns], in one read of all the
    files. ``prefilter`` False: the window is not also applied to the record times while
    reading (header stamps on another clock than the record times: simulation time).

    The reader streams a ROS1 bag's chunks into preallocated arrays: one read of an hour of
    120 Hz GT peaks at ~85 MiB (measured, docs/performance.md), so the 10-minute windows this
    once took (each re-reading 60 s of extra chunks at both ends) only cost time.
    """

    if prefilter:
        return read_poses(files, topic, time_source=time_source, start_ns=start_ns, end_ns=end_ns)
    return read_poses(files, topic, time_source=time_source).window(start_ns, end_ns)


def read_gt_chain(files: Sequence[str], topic: str) -> PoseStream:
    """GT poses as the 2015 script read them: whole files, chained in the order given (by
    start time), each in record order; header stamps, not sorted (``--gt-order chain``)."""

    streams = []
    for path in files:
        with open_bag(path) as bag:
            conns = bag.topic_conns(topic)
            if not conns:
                continue
            batch = load_pose_batch(bag, conns, None, None)
        # rosbag's read_messages yields a file's messages by record time.
        order = np.argsort(batch.t_record, kind="stable")
        streams.append(
            PoseStream(
                batch.t_header[order],
                batch.xyz[order],
                batch.quat_xyzw[order],
                source=f"{path}:{topic}",
            )
        )
    if not streams:
        raise TopicError(f"GT topic {topic} is in none of {', '.join(files)}")
    return PoseStream(
        np.concatenate([s.t_ns for s in streams]),
        np.concatenate([s.xyz for s in streams]),
        np.concatenate([s.quat_xyzw for s in streams]),
        source=", ".join(s.source for s in streams),
    )


def same_bag(robot_bag: str | Path, gt_paths: Sequence[str | Path]) -> bool:
    """Whether the GT is read from the robot log itself: no GT path, or only the robot log."""
    robot_real = Path(robot_bag).resolve()
    return all(Path(p).resolve() == robot_real for p in gt_paths)


def pick_gt_in_robot_bag(
    s: BagSummary, gt_topic: str | None, robot_topic: str, gt_paths: Sequence[str | Path]
) -> str:
    """The GT topic in a robot log that holds both (evo's ``bag`` mode), or a one-line error."""
    how = "the robot log itself" + ("" if gt_paths else ", no GT_PATH given")
    others = [n for n in _pose_topics(s) if n != robot_topic]
    if gt_topic is not None:
        if gt_topic == robot_topic:
            raise TopicError(f"the GT topic {gt_topic} is the robot topic; give the mocap topic")
        if s.topic(gt_topic) is None:
            raise TopicError(
                f"GT topic {gt_topic} is not in the robot log {s.path} (GT read from {how}); "
                f"other pose topics there: {', '.join(others) or 'none'}; "
                "give the GT files or their folder as GT_PATH"
            )
        return gt_topic
    cands = [
        t.name
        for t in s.topics
        if t.msgtype == "geometry_msgs/PoseStamped"
        and not t.name.startswith("/rockin/")
        and t.name != robot_topic
    ]
    if len(cands) == 1:
        return cands[0]
    if not cands:
        raise TopicError(
            f"{s.path}: the GT is read from {how}, but it holds no GT pose topic besides the "
            f"robot topic {robot_topic}; give the mocap GT files or their folder as GT_PATH"
        )
    raise TopicError(
        f"{s.path}: give --gt-topic (the GT is read from {how}; its PoseStamped topics: "
        f"{', '.join(cands)})"
    )


def find_gt_files(
    robot_path: str,
    gt_paths: Sequence[str | Path],
    start_ns: int,
    end_ns: int,
    gt_topic: str | None,
) -> tuple[list[BagSummary], str, list[str], list[str]]:
    """The GT files of GT_PATH overlapping [start, end], their topic, warnings, damaged files."""

    found = find_bags([Path(p) for p in gt_paths])
    if not found.bags:
        raise ClockError(
            f"no GT bags found in {', '.join(map(str, gt_paths))}"
            + (f" ({found.problems[0].problem})" if found.problems else "")
        )
    robot_real = Path(robot_path).resolve()
    if all(Path(b).resolve() == robot_real for b in found.bags):
        raise ClockError(
            f"the only bag in GT_PATH ({', '.join(map(str, gt_paths))}) is the robot log "
            "itself: give the mocap GT files or their folder"
        )
    # Named on the command line (a file or a rosbag2 folder): unreadable is an error, not a skip.
    explicit = {Path(p) for p in gt_paths}
    skipped: list[str] = []
    for problem in found.problems:
        if problem.problem == NO_SUCH:
            # A mistyped GT path must not pass unnoticed behind the other GT files.
            raise BagError(f"GT path: {problem.problem}", path=problem.path, transient=True)
        skipped.append(f"GT path {problem.path}: {problem.problem}")
    gt_summaries = []
    broken: list[str] = []
    for p in found.bags:
        if Path(p).resolve() == Path(robot_path).resolve():
            continue
        try:
            s = summary(p)
        except ErtoolsError as err:
            if Path(p) in explicit:
                raise
            # A broken bag elsewhere in a GT folder must not stop the scoring: say so.
            skipped.append(f"skipped unreadable file in the GT folder: {p}: {err.message}")
            continue
        gt_summaries.append(s)
        damaged = [pr for pr in s.problems if not pr.startswith("not indexed")]
        if damaged:
            # Read up to the damage: GT poses past it are missing, which the coverage check
            # then reports; say why here.
            skipped.append(f"GT file {p} is damaged: {'; '.join(damaged)}")
            broken.append(str(p))
    try:
        chosen, gtopic, warnings = select_gt(gt_summaries, start_ns, end_ns, gt_topic)
    except ClockError as err:
        if not skipped:
            raise
        raise ClockError(f"{err}; also: {'; '.join(skipped)}") from err
    return chosen, gtopic, skipped + warnings, broken
