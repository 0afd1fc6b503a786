"""FBM2@Home (navigation, seed 7.2): load -> find reached moments -> score -> result.

The three stages ``load``, ``find_runs`` and ``score_runs`` (what ``ertools score fbm2h``
runs); :func:`compute` is the pure part (streams and configs in, result out) that tests call
directly; reading the log and finding the reached moments is
:mod:`ertools.benchmarks.fbm2h.logs`.

How 2015 scored (``scripts/fbm2h`` of ``benchmark_and_scoring_fbm``, final 2015 version): for
each waypoint i (segment i, from 0), ``start_segment_time`` when the goal had been sent,
``end_segment_time`` when the Client's result arrived, ``segment_time`` their difference;
the robot pose was the tf ``world -> robot_at_home`` composed with the team's
``marker_to_robot_transform`` (broadcast as a child frame stamped ``now``, the ROS time just
after the result arrived, so tf interpolated the marker pose at that moment) and reduced to
(x, y, yaw); ``dinstance_error`` the planar
distance to the waypoint; ``orientation_error = atan2(sin|dtheta|, cos|dtheta|)`` with
``dtheta`` the unwrapped yaw difference; ``position_accuracy = sum(distance) / N``,
``orientation_accuracy = atan2(sum sin|dtheta|, sum cos|dtheta|)``, ``execution_time`` the
sum of the segment times.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np
import numpy.typing as npt

from ertools.benchmarks.common.arena import check_in_arena
from ertools.benchmarks.common.frozen import frozen_around
from ertools.benchmarks.common.hygiene import drop_invalid, frame_change_warning
from ertools.benchmarks.common.path_gaps import GapOnPath
from ertools.benchmarks.common.validity import (
    Validity,
    sample_codes,
    span_lost,
    summarise,
    valid_near,
)
from ertools.benchmarks.fbm2h.config import DEFAULT_MAX_GAP_S, TF_2015, Fbm2hOptions
from ertools.benchmarks.fbm2h.formula import robot_poses_at, segment_errors
from ertools.benchmarks.fbm2h.goal import GoalList
from ertools.benchmarks.fbm2h.intervals import with_intervals
from ertools.benchmarks.fbm2h.logs import (
    Fbm2hLogs,
    Fbm2hRuns,
    find_moments,
    invalid_warning,
    read_logs,
)
from ertools.benchmarks.fbm2h.result import Fbm2hResult, SegmentResult
from ertools.benchmarks.fbm2h.rules import (
    RULE_ORIENTATION_WRAP,
    RULE_POSE_MOMENT,
    RULE_POSE_SOURCE,
    RULE_SCORE_FORMAT,
    RULE_SEGMENT_CLOCK,
    RULE_UNSCORED,
)
from ertools.benchmarks.fbm2h.runs import ReachedMoments
from ertools.configs.transform import MarkerTransform
from ertools.errors import ConfigError, SegmentationError
from ertools.fidelity import Deviation
from ertools.geometry import compose, yaw_from_quat
from ertools.streams import PoseStream, Provenance
from ertools.timeutil import ns_to_s, s_to_ns

log = logging.getLogger("ertools.benchmarks.fbm2h.pipeline")

# Figures need the path, not every 120 Hz sample.
PATH_POINTS = 3000


def _decimate(stream: PoseStream, points: int) -> PoseStream:
    step = max(1, math.ceil(len(stream) / points))
    return stream.take(slice(0, len(stream), step))


def compute(
    goal: GoalList,
    transform: MarkerTransform,
    marker: PoseStream,
    moments: ReachedMoments,
    *,
    max_gap_s: float = DEFAULT_MAX_GAP_S,
    hits: int | None = None,
    orientation_2015: bool = False,
    unscored_2015: bool = False,
    unscoreable_2015: bool = False,
    unreached: Sequence[str] = (),
    warnings: Sequence[str] = (),
    provenance: Provenance | None = None,
    origin_ns: int | None = None,
) -> Fbm2hResult:
    """Score the segments of ``moments`` against ``goal`` (pure: no file is read).

    ``moments`` may have fewer segments than waypoints only when ``unreached`` says why; the
    missing segments are then failures (with ``unscored_2015``: counted as 2015 did, with a
    warning). More moments than waypoints is an error.
    """
    n = len(goal)
    k = len(moments)
    if k > n or (k < n and not unreached):
        raise SegmentationError(
            f"{k} reached moments ({moments.method}) for {n} waypoints ({goal.source}); "
            "each waypoint needs exactly one"
        )
    early = moments.early_end
    # --unscored-segments 2015: the segment a RefBox END or the log's end cut short is scored
    # where the node's WaitResult() returned, as every segment was (scripts/fbm2h 50b173b).
    ended = (
        k
        if unscored_2015
        and k < n
        and early is not None
        and early.segment == k
        and early.start_ns is not None
        and early.end_ns is not None
        else None
    )
    first_unreached = k
    if ended is not None:
        assert early is not None and early.start_ns is not None and early.end_ns is not None
        moments = replace(
            moments,
            start_ns=np.append(moments.start_ns, np.int64(early.start_ns)),
            end_ns=np.append(moments.end_ns, np.int64(early.end_ns)),
            payloads=(*moments.payloads, ""),
        )
        k += 1
    if hits is not None and hits < 0:
        raise ConfigError(f"--hits must be >= 0, got {hits}")

    mask = sample_codes(marker.t_ns, marker.xyz, marker.quat_xyzw)
    marker, invalid = drop_invalid(marker)
    all_warnings = list(warnings)
    if invalid:
        all_warnings.append(invalid_warning(invalid, marker.source))
    t_mr = transform.arrays()
    poses = robot_poses_at(marker, t_mr, moments.end_ns, s_to_ns(max_gap_s))
    # GT within the tolerance, but only repeated poses of a lost marker set (or clock jumps):
    # the pose there was not measured then
    invalid_gt = poses.ok[:k] & ~valid_near(mask, moments.end_ns[:k], s_to_ns(max_gap_s))
    target = goal.as_array()
    far = check_in_arena(target[:, :2], marker.xyz, what="goal.waypoints", source=goal.source)
    if far:
        all_warnings.append(far)
    errs = segment_errors(poses.xyyaw[:k], target[:k], orientation_2015=orientation_2015)
    # a moment refused for its invalid GT says so in its failure; scored (2015), it is warned
    warn_at = poses.ok[:k] & (~invalid_gt | unscoreable_2015)
    all_warnings.extend(_frozen_warnings(marker, moments, warn_at, max_gap_s, origin_ns))
    frames = frame_change_warning(marker, origin_ns)
    if frames:
        all_warnings.append(frames)
    failures: list[str] = []
    segments: list[SegmentResult] = []
    # Failure messages count time as the table does: from the log's first message when known.
    t_rel0 = origin_ns if origin_ns is not None else int(moments.start_ns[0]) if k else 0
    since = "the log's first message" if origin_ns is not None else "the first segment start"
    for i in range(n):
        tgt = (float(target[i, 0]), float(target[i, 1]), float(target[i, 2]))
        if i >= k:
            j = i - first_unreached
            reason = unreached[j] if j < len(unreached) else f"segment {i}: not reached"
            timed_out = early is not None and early.is_timeout
            if not unscored_2015:
                failures.append(reason)
                segments.append(SegmentResult(i, tgt, "unreached", timeout=timed_out))
                continue
            # The node never sent this goal: nothing of it, 0 in the sums, 1 in N.
            all_warnings.append(f"{reason}: counted in N with no error, as 2015 did")
            segments.append(SegmentResult(i, tgt, "unreached"))
            continue
        start, end = int(moments.start_ns[i]), int(moments.end_ns[i])
        if i == ended:
            assert early is not None
            all_warnings.append(
                f"segment {i}: {early.reason}; scored where the 2015 node's WaitResult() "
                f"returned, {ns_to_s(end - t_rel0):.3f} s after {since}"
                + (", and counted in timeout_segments" if early.is_timeout else "")
                + " (--unscored-segments 2015)"
            )
        common = {
            "start_ns": start,
            "end_ns": end,
            "gt_offset_ns": int(poses.nearest_ns[i]),
            "result_payload": moments.payloads[i],
            "validity": (validity := summarise(mask, start, end, gap_s=max_gap_s)),
            "gaps": _gaps(validity, marker, t_mr, max_gap_s, t_rel0),
        }
        if invalid_gt[i]:
            why = (
                f"no valid ground truth within --gt-tolerance {max_gap_s} s of the reached "
                f"moment {ns_to_s(end - t_rel0):.3f} s after {since}: only repeated poses of a "
                "lost marker set (tracking lost)"
            )
            if not unscoreable_2015:
                failures.append(f"segment {i}: {why} in {marker.source or 'the pose stream'}")
                segments.append(
                    SegmentResult(i, tgt, "no_gt", unscoreable_reason=why, **common)  # type: ignore[arg-type]
                )
                continue
            all_warnings.append(
                f"segment {i}: 2015 scored this segment from a pose that was not measured then "
                f"(--unscoreable 2015); by default it has no GT: {why}"
            )
            common["unscoreable_reason"] = why
        if not poses.ok[i]:
            gap = poses.nearest_ns[i]
            nearest = (
                "no GT sample at all"
                if gap == np.iinfo(np.int64).max
                else (f"nearest GT sample {gap / 1e9:.3g} s away")  # 3 digits, even below 1 ms
            )
            why = (
                f"no ground truth within --gt-tolerance {max_gap_s} s of the reached "
                f"moment {ns_to_s(end - t_rel0):.3f} s after {since} "
                f"({nearest}; tracking lost?)"
            )
            failures.append(f"segment {i}: {why} in {marker.source or 'the pose stream'}")
            segments.append(
                SegmentResult(i, tgt, "no_gt", unscoreable_reason=why, **common)  # type: ignore[arg-type]
            )
            continue
        xyyaw = poses.xyyaw[i]
        segments.append(
            SegmentResult(
                i,
                tgt,
                "ok",
                timeout=i == ended and early is not None and early.is_timeout,
                robot=(float(xyyaw[0]), float(xyyaw[1]), float(xyyaw[2])),
                distance_error=float(errs.distance[i]),
                orientation_error=float(errs.orientation[i]),
                dtheta=float(errs.dtheta[i]),
                **common,  # type: ignore[arg-type]
            )
        )
    scored = all(s.status == "ok" for s in segments)
    # Summed in int64 ns: a sum of float seconds prints binary noise (41.199999999999996).
    execution_time = ns_to_s(
        sum(
            s.end_ns - s.start_ns
            for s in segments
            if s.start_ns is not None
            and s.end_ns is not None
            and (s.status != "unreached" or s.timeout)
        )
    )
    position, orientation = _accuracies(
        segments, poses.xyyaw, target, n, orientation_2015, unscored_2015
    )
    if position is None:
        missing = [s.index for s in segments if s.status != "ok"]
        all_warnings.append(
            f"position_accuracy and orientation_accuracy are null: segment(s) "
            f"{', '.join(map(str, missing))} of {n} not scored and ertools averages only when "
            "every segment is (see the failures; --unscored-segments 2015 divides the sum over "
            f"the {n - len(missing)} scored by N = {n} as 2015 did, when the missing ones were "
            "not lost by tracking)"
        )
    if transform.is_identity:
        all_warnings.append(
            "identity marker-to-robot transform: the marker set is taken to sit on the robot's "
            "odometric centre (give --transform or --team/--transforms otherwise)"
        )
    deviations: list[Deviation] = [
        RULE_POSE_MOMENT.deviation(
            "robot pose interpolated (linear + SLERP) at the logged reached moment; 2015's tf "
            "lookup interpolated at the ROS time its node handled the result, a few ms later"
        ),
        RULE_SCORE_FORMAT.deviation(
            "segments_details nested under details as in Listing 13 (the 2015 node wrote it at "
            "the top level); poses as {x, y, theta} (2015 wrote yaml dumps of Pose2D objects); "
            "segment times from the log's clock (2015: the BmBox machine's time.time())"
        ),
    ]
    if moments.method == "states" and moments.clock == "client" and k:
        deviations.insert(
            0,
            RULE_SEGMENT_CLOCK.deviation(
                "segments timed from the BmBox EXECUTING_GOAL to the Client's COMPLETED_GOAL, "
                "the pose taken then; the 2015 node read its clock when the BmBox itself "
                "moved on (its next state message)"
            ),
        )
    if not unscored_2015 and not scored:
        unscored = sum(s.status != "ok" for s in segments)
        deviations.insert(
            0,
            RULE_UNSCORED.deviation(
                f"position_accuracy and orientation_accuracy are null: {unscored} of {n} "
                "segments not scored; 2015 "
                + (
                    f"scored segment {early.segment} where its wait returned ({early.reason}), "
                    if early is not None
                    and early.start_ns is not None
                    and early.end_ns is not None
                    and early.segment < n
                    else ""
                )
                + f"divided the sums over the scored segments by N = {n}, counting the others "
                "as 0"
            ),
        )
    if orientation_2015:
        all_warnings.append(
            "--orientation-2015: orientation errors use the unwrapped |dtheta| as 2015 did "
            "(negative or wrong when the yaw difference crosses +-pi)"
        )
    else:
        deviations.insert(
            0,
            RULE_ORIENTATION_WRAP.deviation(
                "orientation errors are the yaw difference wrapped to [0, pi] before sin/cos; "
                "2015 used the unwrapped |dtheta|, wrong across +-pi"
            ),
        )
    if moments.method != "states":
        all_warnings.append(
            f"reached moments from {moments.method!r}, not from the benchmark state topics: "
            "segment times are only as good as those moments"
        )
    path = _decimate(marker, PATH_POINTS)
    if len(path):
        rt, rq = t_mr

        pt, pq = compose(
            path.xyz,
            path.quat_xyzw,
            np.broadcast_to(rt, path.xyz.shape).copy(),
            np.broadcast_to(rq, path.quat_xyzw.shape).copy(),
        )
        path_xyyaw = np.column_stack([pt[:, 0], pt[:, 1], yaw_from_quat(pq)])
    else:
        path_xyyaw = np.empty((0, 3))
    return Fbm2hResult(
        segments=tuple(segments),
        position_accuracy=position,
        orientation_accuracy=orientation,
        execution_time=execution_time,
        hits=hits,
        timeout_segments=sum(1 for s in segments if s.timeout),
        transform=transform,
        goal=goal,
        reached_method=moments.method,
        orientation_2015=orientation_2015,
        unscored_2015=unscored_2015,
        path_t_ns=path.t_ns,
        path_xyyaw=path_xyyaw,
        notes=moments.notes,
        origin_ns=origin_ns,
        warnings=tuple(all_warnings),
        deviations=(*deviations, *moments.deviations),
        failures=tuple(failures),
        provenance=provenance or Provenance(),
    )


def _accuracies(
    segments: Sequence[SegmentResult],
    xyyaw: npt.NDArray[np.float64],
    target: npt.NDArray[np.float64],
    n: int,
    orientation_2015: bool,
    unscored_2015: bool,
) -> tuple[float | None, float | None]:
    """(position_accuracy, orientation_accuracy), None when there is no honest number.

    By default both are means over the segments, and only when every segment was scored. With
    ``unscored_2015`` the 2015 node's arithmetic: ``sum_d / N`` and ``atan2(sum_sin,
    sum_cos)`` where the sums run over the scored segments only (a timed-out or unreached
    segment added nothing) and N is the number of waypoints; a segment whose ground truth was
    lost still gives None (2015 waited for tf: the pose it got cannot be known).
    """
    ok = np.array([s.status == "ok" for s in segments], dtype=bool)
    if any(s.status == "no_gt" for s in segments) or (not unscored_2015 and not ok.all()):
        return None, None
    idx = np.flatnonzero(ok)
    errs = segment_errors(xyyaw[idx], target[idx], orientation_2015=orientation_2015)
    if not unscored_2015:
        return errs.position_accuracy, errs.orientation_accuracy
    if not idx.size:
        return 0.0, 0.0  # 2015: sum_d = 0.0 over N, atan2(0.0, 0.0)
    return float(errs.distance.sum()) / n, errs.orientation_accuracy


def _gaps(
    validity: Validity,
    marker: PoseStream,
    t_mr: tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]],
    max_gap_s: float,
    origin_ns: int,
) -> tuple[GapOnPath, ...]:
    """The segment's invalid spans with the robot's world (x, y) at their ends (None at the
    segment's edges, where the span counts as lost), for the path plot."""
    if not validity.spans:
        return ()
    ends = np.array([t for s in validity.spans for t in (s.start_ns, s.end_ns)], dtype=np.int64)
    at = robot_poses_at(marker, t_mr, ends, s_to_ns(max_gap_s))
    out = []
    for k, s in enumerate(validity.spans):
        xy = [
            None if idx < 0 or not at.ok[j] else (float(at.xyyaw[j, 0]), float(at.xyyaw[j, 1]))
            for idx, j in ((s.before, 2 * k), (s.after, 2 * k + 1))
        ]
        out.append(
            GapOnPath(
                (s.start_ns - origin_ns) / 1e9,
                (s.end_ns - origin_ns) / 1e9,
                s.reason,
                xy[0],
                xy[1],
                # at a segment's edge nothing shows the robot stood still
                span_lost(s, xy[0], xy[1]) if None not in xy else True,
            )
        )
    return tuple(out)


def _frozen_warnings(
    marker: PoseStream,
    moments: ReachedMoments,
    ok: npt.NDArray[np.bool_],
    max_gap_s: float,
    origin_ns: int | None,
) -> list[str]:
    """A warning per scored reached moment whose ground truth is a frozen (repeated) pose.

    The threshold is ``--gt-tolerance``: a frozen stretch longer than the gap ertools accepts hides
    a tracking loss of the size it refuses (see
    :data:`ertools.benchmarks.common.frozen.FROZEN_MIN_S`).
    """

    if not len(moments):
        return []
    t0 = origin_ns if origin_ns is not None else int(moments.start_ns[0])
    since = "the log's first message" if origin_ns is not None else "the first segment start"
    out = []
    for i, span in enumerate(frozen_around(marker, moments.end_ns, max_gap_s)):
        if span is None or not ok[i]:
            continue
        at = int(moments.end_ns[i])
        out.append(
            f"segment {i}: the ground truth at the reached moment {ns_to_s(at - t0):.3f} s is "
            f"frozen: {span.samples} identical poses over {span.duration_s:.3f} s "
            f"({ns_to_s(span.start_ns - t0):.3f}-{ns_to_s(span.end_ns - t0):.3f} s; tracking "
            f"lost?), so the pose scored was last measured {ns_to_s(at - span.start_ns):.3f} s "
            f"before (times from {since})"
        )
    return out


def load(paths: Sequence[Path], options: Fbm2hOptions) -> Fbm2hLogs:
    """The configs, the marker set poses and the states (:func:`logs.read_logs`)."""
    return read_logs(paths, options)


def find_runs(logs: Fbm2hLogs, options: Fbm2hOptions) -> Fbm2hRuns:
    """The reached moments (:func:`logs.find_moments`)."""
    return find_moments(logs, options)


def score_runs(logs: Fbm2hLogs, runs: Fbm2hRuns, options: Fbm2hOptions) -> Fbm2hResult:
    """Score the reached moments (:func:`compute`), with the provenance of the inputs."""
    provenance = Provenance(
        inputs=tuple(str(p) for p in logs.paths)
        + tuple(str(p) for p in (options.goal, options.transform, options.timing) if p),
        parameters=(
            ("reached", runs.moments.method),
            ("pose_source", logs.marker.source),
            ("max_gap_s", str(options.max_gap_s)),
            ("transform", logs.transform.described),
            ("goal_layout", logs.goal.layout if logs.goal is not None else "log payload"),
            ("orientation_2015", str(options.orientation_2015)),
            ("unscored_segments", "2015" if options.unscored_2015 else "null"),
            # the node reproduced, when one is (the notes name its commit)
            *((("rules", options.rules),) if options.rules != "ertools" else ()),
        ),
    )
    result = compute(
        runs.goal,
        logs.transform,
        logs.marker,
        runs.moments,
        max_gap_s=options.max_gap_s,
        hits=options.hits,
        orientation_2015=options.orientation_2015,
        unscored_2015=options.unscored_2015,
        unscoreable_2015=options.unscoreable_2015,
        unreached=runs.unreached,
        warnings=[*logs.warnings, *runs.warnings],
        provenance=provenance,
        origin_ns=logs.bag_start_ns,
    )
    result = with_intervals(result, logs.marker, logs.transform, runs.moments, options)
    if _is_tf_2015(logs.marker):
        return result
    if options.pose_2015:
        warning = (
            f"--2015: the 2015 node read the marker set from /tf {TF_2015[0]} -> {TF_2015[1]}, "
            f"not in this log; scored from {logs.marker.source or 'the pose stream'}"
        )
        return replace(result, warnings=(*result.warnings, warning))
    deviation = RULE_POSE_SOURCE.deviation(
        f"marker set poses from {logs.marker.source or 'the pose topic'}; the 2015 node looked "
        f"them up in /tf ({TF_2015[0]} -> {TF_2015[1]}), the same poses stamped a few "
        "microseconds later"
    )
    return replace(result, deviations=(*result.deviations, deviation))


def _is_tf_2015(marker: PoseStream) -> bool:
    """Whether the marker poses come from the 2015 node's source: /tf world -> robot_at_home."""
    from_tf = marker.source.rsplit(":", 1)[-1] in ("/tf", "/tf_static")
    return from_tf and (marker.frame_id, marker.child_frame_id) == TF_2015
