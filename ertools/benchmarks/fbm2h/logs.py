"""FBM2@Home log reading: the configs and the marker set poses (``read_logs``), then the
reached moments from the states, a timing file or stops in the ground truth
(``find_moments``); :mod:`ertools.benchmarks.fbm2h.pipeline`'s ``load`` and ``find_runs``
call them."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ertools.benchmarks.common.hygiene import drop_invalid, impossible_warning
from ertools.benchmarks.common.sources import PoseSpec, read_source, topic
from ertools.benchmarks.common.sources import tf as tf_source
from ertools.benchmarks.fbm2h import runs as seg
from ertools.benchmarks.fbm2h.config import DEFAULT_TOPIC, TF_2015, Fbm2hOptions
from ertools.benchmarks.fbm2h.goal import GoalList, goal_from_payload, load_goal
from ertools.benchmarks.fbm2h.runs import ReachedMoments
from ertools.benchmarks.fbm2h.timing import load_timing
from ertools.configs.transform import (
    MarkerTransform,
    identity_transform,
    load_transform,
    team_transform_path,
)
from ertools.errors import ConfigError, ScoringError, SegmentationError, TopicError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import compose, yaw_from_quat
from ertools.io.clock import check_header_clock
from ertools.io.model import BenchmarkStates
from ertools.io.reader import read_benchmark_states
from ertools.io.summary import summary
from ertools.streams import PoseStream
from ertools.timeutil import s_to_ns


def invalid_warning(count: int, source: str) -> str:
    """The warning for marker poses dropped: NaN, zero quaternions, physically impossible."""
    return (
        f"{count} marker set pose(s) with NaN, zero-quaternion or physically impossible values "
        "ignored "
        f"({source or 'the pose stream'}): reached moments near them may have no ground truth"
    )


def _load_transform(options: Fbm2hOptions) -> MarkerTransform:
    if options.marker_transform is not None:
        if options.transform is not None or options.transforms_dir is not None:
            raise ConfigError("a transform in hand excludes --transform and --transforms")
        return options.marker_transform
    # --team alone only names the team (every scoring command has it); with --transforms DIR
    # it also picks DIR/transform-TEAM.yaml, as the 2015 launch file's team_name argument did.
    if options.transform is not None:
        if options.transforms_dir is not None:
            raise ConfigError("give either --transform FILE or --team NAME --transforms DIR")
        return load_transform(options.transform)
    if options.transforms_dir is not None:
        if options.team is None:
            raise ConfigError("--transforms DIR needs --team NAME (DIR/transform-NAME.yaml)")
        return load_transform(team_transform_path(options.transforms_dir, options.team))
    return identity_transform()


def _pose_spec(options: Fbm2hOptions) -> PoseSpec:
    """The marker set's source for the one chooser (benchmarks/common/sources.py)."""

    if options.topic is not None and options.tf_frame is not None:
        raise ConfigError("give either --topic or --tf, not both")
    return PoseSpec(
        topic=options.topic,
        tf=None if options.tf_frame is None else (options.tf_parent, options.tf_frame),
        time_source="record" if options.time_source == "record" else "header",
    )


def _compare_goal(goal: GoalList, payload: str, topic: str) -> str | None:
    """A warning when the goal list given differs from the one the BmBox sent (or is unreadable)."""

    try:
        logged = goal_from_payload(payload, f"{topic} payload")
    except ConfigError as err:
        return f"the goal payload in the log is not a goal list ({err}); using {goal.source}"
    a, b = logged.as_array(), goal.as_array()
    if a.shape != b.shape or not np.allclose(a, b, atol=1e-9):
        return (
            f"the goal list given ({goal.source}) differs from the one the BmBox sent in the "
            "log; scoring against the one given"
        )
    return None


@frozen_dataclass(eq=False)
class Fbm2hLogs:
    """What :func:`load` read: the bags, the transform, the goal list given (if any), the
    marker set poses (invalid ones dropped), the log's span and, when the reached moments
    come from them, the state streams."""

    paths: tuple[Path, ...]
    transform: MarkerTransform
    goal: GoalList | None
    marker: PoseStream
    bag_start_ns: int
    bag_end_ns: int
    warnings: tuple[str, ...]
    states: BenchmarkStates | None = None


@frozen_dataclass
class Fbm2hRuns:
    """What :func:`find_runs` found: the reached moments, the goal list they close (given,
    or the one the BmBox sent), the waypoints not reached and why, and warnings."""

    moments: ReachedMoments
    goal: GoalList
    unreached: tuple[str, ...]
    warnings: tuple[str, ...]


def read_logs(paths: Sequence[Path], options: Fbm2hOptions) -> Fbm2hLogs:
    """Read the configs, the marker set poses and, for ``--reached states``, the states.

    Raises:
        ConfigError, SegmentationError, ScoringError: no bag, bad configs, no poses, no
            state topics when the reached moments need them.
    """

    if not paths:
        raise ConfigError("no bag given")
    plist = tuple(Path(p) for p in paths)
    transform = _load_transform(options)
    goal = load_goal(options.goal) if options.goal is not None else None
    # The 2015 node looked the marker set up in tf; the topic carries the same poses stamped
    # a few microseconds earlier, and is what most tools show: the default reads it.
    spec = _pose_spec(options)
    defaults: tuple[PoseSpec, ...] = (topic(DEFAULT_TOPIC),)
    try:
        marker = read_source(
            list(plist),
            spec,
            (tf_source(TF_2015[1], TF_2015[0]), *defaults) if options.pose_2015 else defaults,
            what="marker set poses",
        )
    except TopicError:
        if not options.pose_2015 or spec.given:
            raise
        # /tf without the marker set: the topic, said in the result (score_runs).
        marker = read_source(list(plist), spec, defaults, what="marker set poses")
    if len(marker) == 0:
        raise SegmentationError(f"{marker.source or plist[0]}: the marker set pose stream is empty")
    total = len(marker)
    impossible = impossible_warning(marker)
    marker, invalid = drop_invalid(marker)
    if len(marker) == 0:
        raise ScoringError(
            f"{marker.source or plist[0]}: all {total} marker set poses are NaN, have a zero "
            "quaternion or are physically impossible: nothing to score (was the body tracked?)"
        )
    infos = [summary(p) for p in plist]
    states = None
    if options.reached in (None, "states"):
        states = read_benchmark_states(list(plist), options.namespace)
        if states.bmbox is None:
            raise SegmentationError(_stateless(Path(plist[0]), options))
    return Fbm2hLogs(
        paths=plist,
        transform=transform,
        goal=goal,
        marker=marker,
        bag_start_ns=min(i.start_ns for i in infos),
        bag_end_ns=max(i.end_ns for i in infos),
        warnings=tuple(
            w for w in (invalid and invalid_warning(invalid, marker.source), impossible) if w
        ),
        states=states,
    )


# Where the 2015 loggers left a GT-only log's other inputs: the timing file beside the log,
# a goal list in its folder (../shared/real_bags: fbm2h_test_optitrackless_goal.yaml).
TIMING_SUFFIX = "_reached_waypoint_timing.yaml"
GOAL_PATTERN = "*goal*.yaml"


def _stateless(bag: Path, options: Fbm2hOptions) -> str:
    """What a log without state topics needs, all in one message: the reached moments (a
    timing file, or stops) and, unless given, the goal list; the files found beside the log
    are named (only their names are looked at here)."""
    why = (
        f"no /{options.namespace}/bmbox_state topic"
        if options.reached == "states"
        else "no benchmark state topics (a ground-truth-only log)"
    )
    timing = bag.with_name(bag.name.removesuffix(".bag") + TIMING_SUFFIX)
    goals = sorted(bag.parent.glob(GOAL_PATTERN)) if options.goal is None else []
    needed = "the reached moments" + (" and the waypoints" if options.goal is None else "")
    found = timing.is_file()
    give = [f"--reached timing {timing}" if found else "--reached timing FILE"]
    if options.goal is None:
        found = found and len(goals) == 1
        give.append(f"--goal {goals[0]}" if len(goals) == 1 else "--goal FILE (Listing 10)")
    where = " (found beside the log)" if found else ""
    return (
        f"{bag}: {why}: give {needed}; {' '.join(give)}{where}; "
        "or --reached auto (stops found in the ground truth)"
    )


def find_moments(logs: Fbm2hLogs, options: Fbm2hOptions) -> Fbm2hRuns:
    """The reached moments: from the states, a timing file or stops in the ground truth.

    Raises:
        ConfigError: a mode without the goal list or timing file it needs.
        SegmentationError: moments that do not match the waypoints.
        ClockError: header-stamped poses on another clock than the moments.
    """

    goal = logs.goal
    warnings: list[str] = []
    unreached: tuple[str, ...] = ()
    reached = "states" if logs.states is not None else options.reached
    if reached == "states":
        states = logs.states
        assert states is not None and states.bmbox is not None
        moments = seg.from_states(
            states.bmbox,
            states.client,
            states.refbox,
            clock=options.segment_clock,
            exact_2015=options.exact_end_payloads,
            t0_ns=logs.bag_start_ns,
        )
        if goal is None:
            if moments.goal_payload is None:
                raise ConfigError(
                    "no --goal given and the first TRANSMITTING_GOAL has no goal payload"
                )
            goal = goal_from_payload(moments.goal_payload, f"{states.bmbox.topic} payload")
        elif moments.goal_payload:
            warning = _compare_goal(goal, moments.goal_payload, states.bmbox.topic)
            if warning:
                warnings.append(warning)
        unreached = seg.unreached_reasons(moments, len(goal), states.refbox)
        warnings.extend(moments.warnings)
        if moments.early_end is not None and moments.early_end.kind == "cut" and unreached:
            warnings.append(
                f"{states.bmbox.topic}: the log ends inside the benchmark (segment "
                f"{moments.early_end.segment} of {len(goal)}): taken as the benchmark stopped "
                "there, as the 2015 node would have scored a stop"
            )
    elif reached == "timing":
        if options.timing is None:
            raise ConfigError("--reached timing needs the timing FILE")
        if goal is None:
            raise ConfigError("--reached timing needs --goal FILE (Listing 10)")
        timing = load_timing(options.timing)
        t = timing.resolve(logs.bag_start_ns, logs.bag_end_ns)
        if len(t) - 1 != len(goal):
            raise SegmentationError(
                f"{options.timing}: {len(t)} moments close {len(t) - 1} segments, but "
                f"{goal.source} has {len(goal)} waypoints (p0 starts, p(k+1) closes segment k)"
            )
        moments = seg.from_timing(t, timing.labels)
    elif reached == "auto":
        if goal is None:
            raise ConfigError("--reached auto needs --goal FILE (Listing 10)")

        marker = logs.marker
        rt, rq = logs.transform.arrays()
        pt, pq = compose(
            marker.xyz,
            marker.quat_xyzw,
            np.broadcast_to(rt, marker.xyz.shape).copy(),
            np.broadcast_to(rq, marker.quat_xyzw.shape).copy(),
        )
        moments, unreached = seg.from_stops(
            marker.t_ns,
            pt[:, :2],
            yaw_from_quat(pq),
            goal.as_array()[:, :2],
            options.stops,
            s_to_ns(options.max_gap_s),
            origin_ns=logs.bag_start_ns,
        )
    else:
        raise ConfigError(f"--reached must be states, timing FILE or auto, not {reached!r}")

    what = {"states": "state messages", "auto": None}.get(moments.method, "timing file's moments")
    check_header_clock(list(logs.paths), logs.marker, what, time_source=options.time_source)
    return Fbm2hRuns(moments, goal, tuple(unreached), tuple(warnings))
