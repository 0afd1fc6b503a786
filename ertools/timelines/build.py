"""The timeline of a set of bags: order, overlaps, sessions, kinds, GT pairing, problems.

The 2015 ``rockin_bags_timeliner`` ordered bags by start time and listed, for each, the earlier
bags it overlapped. This module does that and what a referee needs next: which bags form one
session, what each bag is (GT logger, benchmark log, robot log), which GT files cover each
benchmark or robot log and how much of it, and what is wrong (gaps between split files of one
logger, duplicated names, unsynchronised clocks, unreadable or unindexed files).

Two things are decided by content, not by time or name. A benchmark or robot log is paired with
the GT files of *its* benchmark (the ``/fbm2h/...`` namespace of the topics, or the
``FBM2H_<date>_<team>`` name the 2015 rockin_logger gave robot logs); a GT logger of another
benchmark recording at the same time is named but not paired. And a recording copied to another
name, folder or format (same topics, message counts, first and last message) is one recording:
its copies are listed under it and left out of overlaps, sessions and pairings, so a folder of
1,000 copies gives one recording with 999 copies, not a million overlaps.

Pure: it takes bag summaries (``ertools.io.model.BagSummary`` or anything with the same attributes),
never opens a file. :mod:`ertools.timelines.scan` is the IO edge that produces its inputs.
"""

from __future__ import annotations

import re
from collections import defaultdict
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import replace
from itertools import pairwise
from pathlib import Path

from ertools.benchmarks.common.teams import parse_robot_log_name
from ertools.io.clock import ClockCheck
from ertools.io.formats import Unreadable
from ertools.rsbb.layout import FileKind
from ertools.rsbb.layout import classify as rsbb_classify
from ertools.timelines.model import (
    BagEntry,
    Kind,
    Pairing,
    Problem,
    Session,
    SummaryLike,
    Timeline,
    TimelineConfig,
    TopicLike,
)
from ertools.timeutil import NS_PER_S

# Message types that carry a pose (ROS1 and ROS2 spellings are normalised before the lookup).
POSE_TYPES = frozenset(
    {
        "geometry_msgs/PoseStamped",
        "geometry_msgs/Pose2D",
        "geometry_msgs/TransformStamped",
        "geometry_msgs/PoseWithCovarianceStamped",
        "nav_msgs/Odometry",
        "tf/tfMessage",
        "tf2_msgs/TFMessage",
    }
)
# Topics every 2015 logger carried next to the mocap poses; they do not change a bag's kind.
HOUSEKEEPING_TOPICS = frozenset({"/rosout", "/rosout_agg", "/tf", "/tf_static", "/clock"})
HOUSEKEEPING_SUFFIXES = ("/map", "/map_metadata")
STATE_SUFFIXES = ("/bmbox_state", "/bbbox_state", "/refbox_state", "/client_state")

# rosbag record names split files <prefix>_<YYYY-MM-DD-HH-MM-SS>_<n>.bag; the date is the
# start of the recording and is the same in every split file of one recording.
_SPLIT_RE = re.compile(r"^(?P<group>.+)_(?P<index>\d+)$")
_DATE_RE = re.compile(r"_?\d{4}-\d{2}-\d{2}-\d{2}-\d{2}-\d{2}$")
_SUFFIXES = (".bag.active", ".bag", ".mcap", ".db3")
# The benchmark namespaces of the 2015 topics (/fbm2h/..., /tbm1h/...) and robot log names
# (rockin_logger: ${BENCHMARK}_${DATE}_${TEAMNAME}.bag, BENCHMARK written FBM2H or FBMH2).
_NAMESPACE_RE = re.compile(r"^[ft]bm\d[hw]$", re.IGNORECASE)


# --- names ---------------------------------------------------------------------------------


def bag_stem(path: str | Path) -> str:
    """File name without the bag suffix (``x_0.bag.active`` -> ``x_0``)."""
    name = Path(path).name
    for suffix in _SUFFIXES:
        if name.endswith(suffix):
            return name[: -len(suffix)]
    return name


def split_name(path: str | Path) -> tuple[str, int] | None:
    """(recording, index) of a rosbag split file, None for a file that is not one.

    A split file is ``<prefix>_<YYYY-MM-DD-HH-MM-SS>_<n>`` (rosbag record --split) or
    ``log_<name>_..._<n>`` (the 2015 loggers' prefix). Other names ending in a number
    (``run_3.bag``) are not split files: treating them as one would report false gaps.
    """
    match = _SPLIT_RE.match(bag_stem(path))
    if match is None:
        return None
    group = match.group("group")
    if _DATE_RE.search(group) is None and not group.startswith("log_"):
        return None
    return group, int(match.group("index"))


def rsbb_run(path: str | Path) -> tuple[str, str] | None:
    """(code, team) of a run bag in the RSBB's layout (``rsbb_logs/<CODE>/<team>/run_<n>_...``),
    None for any other file."""
    found = rsbb_classify(path)
    if found is None or found.kind is not FileKind.RUN_BAG or not found.code or not found.team:
        return None
    return found.code, found.team


def logger_name(path: str | Path) -> str:
    """The logger that wrote a file: its name without split index and recording date (an
    RSBB run: ``<CODE> <team>``, the RSBB's recorder for that benchmark and team).

    One lane of the Gantt chart: the restarts of a logger stay on the same lane.
    """
    run = rsbb_run(path)
    if run is not None:
        return f"{run[0]} {run[1]}"
    split = split_name(path)
    stem = split[0] if split is not None else bag_stem(path)
    return _DATE_RE.sub("", stem) or stem


# --- classification --------------------------------------------------------------------------


def _norm_type(msgtype: str) -> str:
    """``geometry_msgs/msg/PoseStamped`` (ROS 2) -> ``geometry_msgs/PoseStamped``."""
    return msgtype.replace("/msg/", "/")


def _is_housekeeping(topic: str) -> bool:
    return topic in HOUSEKEEPING_TOPICS or topic.endswith(HOUSEKEEPING_SUFFIXES)


def classify(topics: Iterable[TopicLike]) -> Kind:
    """The kind of a bag from its topics.

    benchmark log: any state topic (``/<ns>/bmbox_state`` ...; those logs also hold mocap);
    robot log: any ``/rockin/...`` topic; GT logger: pose topics (mocap) and nothing but the
    loggers' housekeeping (``/tf``, ``/rosout``, maps); anything else is ``other``.
    """
    items = list(topics)
    names = [t.name for t in items]
    if any(n.endswith(STATE_SUFFIXES) for n in names) or any(
        _norm_type(t.msgtype).startswith("rockin_scoring/") for t in items
    ):
        return "benchmark"
    if any(n.startswith("/rockin/") for n in names):
        return "robot"
    poses = [
        t for t in items if _norm_type(t.msgtype) in POSE_TYPES and not _is_housekeeping(t.name)
    ]
    others = [
        t for t in items if _norm_type(t.msgtype) not in POSE_TYPES and not _is_housekeeping(t.name)
    ]
    if poses and not others:
        return "gt"
    if not poses and not others and any(t.name in ("/tf",) and t.count > 0 for t in items):
        return "gt"  # a mocap logger that only recorded /tf
    return "other"


def benchmark_names(topics: Iterable[TopicLike], path: str | Path = "") -> tuple[str, ...]:
    """The benchmarks a bag belongs to: its topics' namespaces (``/fbm2h/...`` -> ``fbm2h``)
    and, for a robot log, the benchmark its rockin_logger name gives (``FBM2H_...``); an RSBB
    run bag's code, from its folder (``rsbb_logs/HGMF/...`` -> ``hgmf``)."""
    run = rsbb_run(path) if path else None
    if run is not None:
        return (run[0].lower(),)
    names = {
        t.name.split("/")[1].lower()
        for t in topics
        if t.name.count("/") >= 2 and _NAMESPACE_RE.match(t.name.split("/")[1])
    }
    log_name = parse_robot_log_name(path) if path else None
    if log_name is not None:
        names.add(log_name.benchmark)
    return tuple(sorted(names))


def recording_key(summary: SummaryLike) -> tuple[object, ...]:
    """What one recording looks like whatever its file name, folder or format: its topics
    (ROS 1 and ROS 2 type spellings alike), their message counts, first and last message."""
    topics = sorted((t.name, _norm_type(t.msgtype), t.count) for t in summary.topics)
    return (summary.start_ns, summary.end_ns, summary.message_count, tuple(topics))


# --- intervals -------------------------------------------------------------------------------


def union_spans(spans: Iterable[tuple[int, int]], join_ns: int = 0) -> list[tuple[int, int]]:
    """Merge closed intervals (and those at most ``join_ns`` apart) into disjoint ones."""
    merged: list[tuple[int, int]] = []
    for start, end in sorted(spans):
        if merged and start - merged[-1][1] <= join_ns:
            if end > merged[-1][1]:
                merged[-1] = (merged[-1][0], end)
        else:
            merged.append((start, end))
    return merged


def coverage(
    start_ns: int, end_ns: int, covers: Iterable[tuple[int, int]], join_ns: int = 0
) -> tuple[float, list[tuple[int, int]]]:
    """Percent of [start, end] inside the union of ``covers``, and the uncovered spans.

    Covers at most ``join_ns`` apart count as one (the pause between them is covered).
    """
    uncovered: list[tuple[int, int]] = []
    cursor = start_ns
    covered_ns = 0
    point_covered = False
    for a, b in union_spans(covers, join_ns):
        if b < start_ns or a > end_ns:
            continue
        if a <= start_ns <= b:
            point_covered = True
        lo, hi = max(a, start_ns), min(b, end_ns)
        if lo > cursor:
            uncovered.append((cursor, lo))
        covered_ns += hi - lo
        cursor = max(cursor, hi)
    if cursor < end_ns:
        uncovered.append((cursor, end_ns))
    span = end_ns - start_ns
    if span <= 0:  # a one-message log is covered or not
        return (100.0 if point_covered else 0.0), ([] if point_covered else [(start_ns, end_ns)])
    return 100.0 * covered_ns / span, uncovered


def _overlaps(entries: Sequence[BagEntry]) -> dict[str, list[str]]:
    """For each bag, the other bags whose closed spans intersect its own (sweep by start)."""
    result: dict[str, list[str]] = {b.path: [] for b in entries}
    active: list[BagEntry] = []
    for bag in entries:  # sorted by start
        assert bag.start_ns is not None and bag.end_ns is not None
        active = [a for a in active if a.end_ns is not None and a.end_ns >= bag.start_ns]
        for other in active:
            result[other.path].append(bag.path)
            result[bag.path].append(other.path)
        active.append(bag)
    return result


# --- the timeline ----------------------------------------------------------------------------


def _fmt_s(ns: int) -> str:
    return f"{ns / NS_PER_S:.3f} s"


def build_timeline(
    summaries: Iterable[SummaryLike],
    unreadable: Iterable[Unreadable] = (),
    clock_checks: Iterable[ClockCheck] = (),
    config: TimelineConfig | None = None,
) -> Timeline:
    """Order, relate and check bags from their summaries.

    Args:
        summaries: one per readable bag (a bag with no messages counts as unreadable).
        unreadable: paths that could not be summarised and why.
        clock_checks: measured record-minus-header offsets (see :mod:`ertools.timelines.scan`).
        config: thresholds.
    """
    cfg = config or TimelineConfig()
    problems: dict[str, list[str]] = defaultdict(list)
    base: list[BagEntry] = []
    broken: list[BagEntry] = []
    keys: dict[str, tuple[object, ...]] = {}
    for s in summaries:
        path = str(s.path)
        if s.start_ns is None or s.end_ns is None or s.message_count == 0:
            broken.append(BagEntry(path, s.format, None, None, "unreadable", logger_name(path)))
            problems[path].extend(s.problems)
            problems[path].append("no messages: no start or end time")
            continue
        base.append(
            BagEntry(
                path,
                s.format,
                int(s.start_ns),
                int(s.end_ns),
                # an RSBB run is its benchmark's log, scripted or not (a task benchmark's holds
                # the RefBox's GUI messages only): its folder says so
                "benchmark" if rsbb_run(path) is not None else classify(s.topics),
                logger_name(path),
                benchmarks=benchmark_names(s.topics, path),
            )
        )
        keys[path] = recording_key(s)
        problems[path].extend(s.problems)
        if not s.indexed and not any("index" in p for p in s.problems):
            problems[path].append("unindexed (still being recorded?): read by scanning")
    for u in unreadable:
        broken.append(BagEntry(u.path, None, None, None, "unreadable", logger_name(u.path)))
        problems[u.path].append(u.problem)

    base.sort(key=lambda b: (b.start_ns, b.end_ns, b.path))
    copy_of = _copies(base, keys)
    copies: dict[str, list[str]] = defaultdict(list)
    for copy, original in copy_of.items():
        copies[original].append(copy)
        problems[copy].append(
            f"same recording as {original} (same topics, message counts, first and last "
            "message): a copy, left out of overlaps, sessions and pairings"
        )
    copied = [b for b in base if b.path in copy_of]
    base = [b for b in base if b.path not in copy_of]
    overlaps = _overlaps(base)

    _check_duplicates([b.path for b in base + copied + broken], problems, copy_of)
    _check_split_gaps(base, cfg, problems)
    for check in clock_checks:
        if check.error:
            problems[check.path].append(
                f"cannot read the first messages of {check.topic}: {check.error}"
            )
        elif abs(check.offset_ns) > cfg.clock_tolerance_ns:
            problems[check.path].append(
                f"record times differ from header stamps on {check.topic} by "
                f"{check.offset_ns / NS_PER_S:+.3f} s (median of {check.samples} messages; "
                "clocks not synchronised?)"
            )

    sessions, session_of = _sessions(base, cfg.gap_tolerance_ns)
    entries = [
        replace(
            b,
            overlaps=tuple(overlaps[b.path]),
            problems=tuple(dict.fromkeys(problems[b.path])),
            session=session_of[b.path],
            copies=tuple(copies[b.path]),
        )
        for b in base
    ]
    entries += [
        replace(
            b,
            problems=tuple(dict.fromkeys(problems[b.path])),
            session=session_of[copy_of[b.path]],
            copy_of=copy_of[b.path],
        )
        for b in copied
    ]
    entries.sort(key=lambda b: (b.start_ns, b.end_ns, b.path))
    entries += [replace(b, problems=tuple(dict.fromkeys(problems[b.path]))) for b in broken]
    by_path = {e.path: e for e in entries if e.copy_of is None}
    sessions = [
        Session(
            s.index,
            s.start_ns,
            s.end_ns,
            s.paths,
            _pairings([by_path[p] for p in s.paths], cfg.coverage_join_ns),
        )
        for s in sessions
    ]
    flat = [Problem(e.path, p) for e in entries for p in e.problems]
    return Timeline(tuple(entries), tuple(sessions), tuple(flat), cfg)


def _sessions(entries: Sequence[BagEntry], join_ns: int) -> tuple[list[Session], dict[str, int]]:
    """Chains of overlapping bags: a bag starting at most ``join_ns`` after the chain's end
    joins it."""
    sessions: list[Session] = []
    session_of: dict[str, int] = {}
    current: list[BagEntry] = []
    end = 0

    def close() -> None:
        if current:
            index = len(sessions) + 1
            start = current[0].start_ns
            assert start is not None
            sessions.append(Session(index, start, end, tuple(b.path for b in current)))
            for b in current:
                session_of[b.path] = index

    for bag in entries:
        assert bag.start_ns is not None and bag.end_ns is not None
        if current and bag.start_ns <= end + join_ns:
            current.append(bag)
            end = max(end, bag.end_ns)
        else:
            close()
            current = [bag]
            end = bag.end_ns
    close()
    return sessions, session_of


def _pairings(entries: Sequence[BagEntry], join_ns: int) -> tuple[Pairing, ...]:
    gt = [e for e in entries if e.kind == "gt"]
    pairings: list[Pairing] = []
    for e in entries:
        # an RSBB run bag holds its own mocap (/tf): no GT logger's file is its ground truth
        if e.kind not in ("benchmark", "robot") or rsbb_run(e.path) is not None:
            continue
        assert e.start_ns is not None and e.end_ns is not None
        overlapping = [
            g
            for g in gt
            if g.start_ns is not None
            and g.end_ns is not None
            and g.start_ns <= e.end_ns
            and g.end_ns >= e.start_ns
        ]
        # A GT logger of another benchmark at the same time (a second arena) is not this
        # log's ground truth; one that names no benchmark can only be judged by time.
        mine = set(e.benchmarks)
        other = [g for g in overlapping if mine and g.benchmarks and not mine & set(g.benchmarks)]
        covering = [g for g in overlapping if g not in other]
        by_time = not mine or any(not g.benchmarks for g in covering)
        spans = [
            (g.start_ns, g.end_ns)
            for g in covering
            if g.start_ns is not None and g.end_ns is not None
        ]
        pct, uncovered = coverage(e.start_ns, e.end_ns, spans, join_ns)
        pairings.append(
            Pairing(
                e.path,
                e.kind,
                tuple(g.path for g in covering),
                pct,
                tuple(uncovered),
                "time" if by_time else "content",
                tuple(g.path for g in other),
            )
        )
    return tuple(pairings)


def _copies(entries: Sequence[BagEntry], keys: Mapping[str, tuple[object, ...]]) -> dict[str, str]:
    """copy -> original for recordings found more than once (the first by start, then path,
    is the original: the order is the caller's)."""
    first: dict[tuple[object, ...], str] = {}
    copy_of: dict[str, str] = {}
    for e in entries:
        original = first.setdefault(keys[e.path], e.path)
        if original != e.path:
            copy_of[e.path] = original
    return copy_of


def _check_duplicates(
    paths: Sequence[str], problems: Mapping[str, list[str]], copy_of: Mapping[str, str]
) -> None:
    """One name for different files; copies of one recording are said once, as copies."""
    by_name: dict[str, list[str]] = defaultdict(list)
    for p in paths:
        by_name[Path(p).name].append(p)
    for same in by_name.values():
        if len({copy_of.get(p, p) for p in same}) < 2:
            continue
        for p in same:
            others = ", ".join(o for o in same if o != p)
            problems[p].append(f"duplicated file name (also {others})")


def _check_split_gaps(
    entries: Sequence[BagEntry], cfg: TimelineConfig, problems: Mapping[str, list[str]]
) -> None:
    """Gaps and missing files between consecutive split files of one recording."""
    groups: dict[str, dict[int, BagEntry]] = defaultdict(dict)
    for e in entries:
        split = split_name(e.path)
        if split is not None:
            groups[split[0]].setdefault(split[1], e)  # a duplicate copy adds nothing
    for group, files in groups.items():
        indices = sorted(files)
        for prev_i, next_i in pairwise(indices):
            prev, nxt = files[prev_i], files[next_i]
            assert prev.end_ns is not None and nxt.start_ns is not None
            if next_i != prev_i + 1:
                missing = ", ".join(f"_{i}" for i in range(prev_i + 1, next_i))
                problems[nxt.path].append(
                    f"split file(s) {missing} of {group} missing before this one"
                )
            gap = nxt.start_ns - prev.end_ns
            if gap > cfg.gap_tolerance_ns:
                problems[nxt.path].append(
                    f"gap of {_fmt_s(gap)} after {Path(prev.path).name} "
                    f"(split files of {logger_name(prev.path)})"
                )
            elif gap < 0:
                problems[nxt.path].append(
                    f"overlaps the previous split file {Path(prev.path).name} by {_fmt_s(-gap)}"
                )
