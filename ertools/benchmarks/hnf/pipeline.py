"""HNF's stages: the run bag and its side files read (:func:`load`), the script followed
through the log (:func:`find_runs`), the poses looked up and the score made (:func:`score_runs`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from ertools.arrays import I64
from ertools.benchmarks.base import notice
from ertools.benchmarks.common.interval_output import ResultIntervals
from ertools.benchmarks.hnf.config import SCRIPT_FRAMES, SEASONS, HnfOptions
from ertools.benchmarks.hnf.flow import HnfFlow, script_flow
from ertools.benchmarks.hnf.formula import SegmentErrors, accuracies, segment_errors
from ertools.benchmarks.hnf.intervals import hnf_intervals
from ertools.benchmarks.hnf.listing import score_listing
from ertools.benchmarks.hnf.logs import HnfLogs
from ertools.benchmarks.hnf.result import HnfResult, HnfSegment, deviations_of
from ertools.configs._yaml import parse_yaml
from ertools.errors import ConfigError, SegmentationError
from ertools.io.summary import summary
from ertools.rsbb.log import EndKind, RsbbRun
from ertools.rsbb.opened import one_run_bag, open_run
from ertools.rsbb.results import RsbbResult
from ertools.rsbb.score import compare_scores
from ertools.rsbb.sidefiles import read_side_yaml, script_transform
from ertools.rsbb.tf import TfTrack, read_tf_tracks, script_poses
from ertools.streams import Provenance
from ertools.timeutil import ns_to_s

CODE = "HNF"
FRAME = SCRIPT_FRAMES[0]  # /robot under /robot_markerset, in /testbed_origin
BODY = FRAME.parent.lstrip("/")
# the transform's key the script at each commit read (renamed in 00e3106)
TRANSFORM_KEY = {
    "069fd1d": "marker_to_robot_transform",
    "f594ff1": "marker_to_robot_transform",
}


def _waypoints(params: Any, where: str) -> tuple[tuple[Any, Any, Any], ...]:
    waypoints = params.get("waypoints") if isinstance(params, dict) else None
    if not isinstance(waypoints, list) or not waypoints:
        raise ConfigError(f"{where}: no waypoints list ([[x, y, theta], ...])")
    out = []
    for k, w in enumerate(waypoints):
        ok = isinstance(w, list) and len(w) == 3
        ok = ok and all(isinstance(v, int | float) and not isinstance(v, bool) for v in w)
        if not ok or not all(math.isfinite(float(v)) for v in w):
            raise ConfigError(f"{where}: waypoint {k + 1} is {w!r}, not [x, y, theta] numbers")
        out.append((w[0], w[1], w[2]))
    return tuple(out)


def _config(
    options: HnfOptions, found: Path | None, result: RsbbResult | None
) -> tuple[tuple[tuple[Any, Any, Any], ...], str]:
    path = options.config or found
    if path is not None:
        return _waypoints(read_side_yaml(path, "HNF config"), str(path)), str(path)
    if result is not None and isinstance(result.params, dict):
        where = f"{result.path} (benchmark_info.params)"
        return _waypoints(result.params, where), where
    raise ConfigError(
        "no HNF.yaml beside the bag or in the RSBB layout, and no result file with the "
        "params: give --config HNF.yaml (its waypoints) or --result result_run_<n>_<date>.yaml"
    )


def _logged_waypoints(run: RsbbRun) -> list[Any]:
    """Each goal's request as the BmBox published it (None where unreadable or absent)."""
    out: list[Any] = []
    for g in run.goals:
        try:
            out.append(None if g.request is None else parse_yaml(g.request, "goal payload"))
        except ConfigError:
            out.append(None)
    return out


def load(logs: Sequence[Path], options: HnfOptions) -> HnfLogs:
    """Read the run bag, the waypoints (HNF.yaml, else the result file's params) and the team
    transform; the side files found are named on stderr.

    Raises:
        UsageError: not one bag.
        ConfigError: another benchmark's bag or result file; no waypoints or transform found,
            or one unreadable.
        SegmentationError: the benchmark never started in the log.
        TopicError, BagError: an unreadable bag.
    """
    bag = one_run_bag(logs, CODE)
    opened = open_run([bag], CODE, options, want=("config", "transform", "result"), say=notice)
    run, result, team = opened.run, opened.result_file, opened.team
    transform_path = opened.transform_file()
    warnings: list[str] = []
    key = TRANSFORM_KEY.get(options.script, "markerset_to_robot_transform")
    try:
        transform = script_transform(transform_path, (key,))
    except ConfigError:
        transform = script_transform(transform_path)
        warnings.append(
            f"{transform_path} has no {key} (the script at {options.script} read that key): "
            "the other spelling used"
        )
    waypoints, config_source = _config(options, opened.side.config, result)
    if run.t_start_ns is None:
        raise SegmentationError(
            f"{bag}: the benchmark never started (no EXECUTING_BENCHMARK): nothing to score"
        )
    tracks = read_tf_tracks(bag)
    body = tracks.body(BODY)
    logged = _logged_waypoints(run)
    for k, (goal_wp, cfg) in enumerate(zip(logged, waypoints, strict=False)):
        if not (isinstance(goal_wp, list) and len(goal_wp) == 3):
            continue
        if [float(v) for v in goal_wp] != [float(v) for v in cfg]:
            warnings.append(
                f"goal {k + 1} requested {goal_wp} in the log, the config ({config_source}) says "
                f"{list(cfg)}: the config's waypoint scored"
            )
    log_end = max(t.last_ns for t in summary(bag).topics if t.last_ns is not None)
    return HnfLogs(
        bag,
        run,
        body,
        tracks.broadcasts(FRAME),
        waypoints,
        config_source,
        transform,
        str(transform_path),
        result,
        team,
        int(log_end),
        tuple(warnings),
    )


def find_runs(logs: HnfLogs, options: HnfOptions) -> HnfFlow:
    """The script at ``options.script`` followed through the log."""
    return script_flow(
        logs.run, logs.stamps, logs.body, len(logs.waypoints), options.script, logs.log_end_ns
    )


def _segments(logs: HnfLogs, flow: HnfFlow, options: HnfOptions) -> list[HnfSegment]:
    """The segments with their poses and errors (vectorised over the lookups)."""
    looked = [s for s in flow.segments if s.lookup_ns is not None]
    t = np.array([s.lookup_ns for s in looked], dtype=np.int64)
    poses = script_poses(logs.body, t, logs.transform)
    gap_ok = poses.inside & (
        options.gaps_interpolate | (poses.gap_ns <= round(options.max_gap_s * 1e9))
    )
    target = np.array([[float(v) for v in logs.waypoints[s.index]] for s in looked]).reshape(-1, 3)
    errors = segment_errors(
        poses.x,
        poses.y,
        poses.theta,
        target,
        wrap=not options.orientation_2019,
        fabs=options.script != "069fd1d",
    )
    by_index = {s.index: k for k, s in enumerate(looked)}
    out = []
    for s in flow.segments:
        k = by_index.get(s.index)
        measured = k is not None and bool(gap_ok[k])
        out.append(
            HnfSegment(
                index=s.index,
                waypoint=logs.waypoints[s.index],
                flow=s,
                robot=None
                if k is None
                else (float(poses.x[k]), float(poses.y[k]), float(poses.theta[k])),
                gap_ns=None if k is None else int(poses.gap_ns[k]),
                measured=measured,
                distance_error=float(errors.distance[k]) if measured and k is not None else None,
                orientation_error=float(errors.orientation[k])
                if measured and k is not None
                else None,
                dtheta=float(errors.dtheta[k]) if measured and k is not None else None,
                sin=float(errors.sin[k]) if measured and k is not None else 0.0,
                cos=float(errors.cos[k]) if measured and k is not None else 0.0,
            )
        )
    return out


def score_runs(logs: HnfLogs, flow: HnfFlow, options: HnfOptions) -> HnfResult:
    """The score of the run, in the result file's form, with its comparison and intervals."""
    segments = _segments(logs, flow, options)
    measured = np.array([s.measured for s in segments], dtype=bool)
    completed = np.array([s.flow.completed for s in segments], dtype=bool)
    summed = measured if options.divisor_2019 else measured & completed
    divisor = int(completed.sum()) if options.divisor_2019 else int(summed.sum())
    totals = flow.totals or not options.stopped_2019
    position, orientation = (None, None)
    if totals:
        errors = SegmentErrors(
            np.array([s.distance_error or 0.0 for s in segments]),
            np.array([s.dtheta or 0.0 for s in segments]),
            np.array([s.sin for s in segments]),
            np.array([s.cos for s in segments]),
            np.array([s.orientation_error or 0.0 for s in segments]),
        )
        position, orientation = accuracies(
            errors, summed, divisor, fabs=options.script != "069fd1d"
        )
    score = score_listing(segments, flow, options, totals, position, orientation)
    season = SEASONS[options.script]
    warnings = list(logs.warnings) + _flow_warnings(flow, segments, options)
    failures = []
    if not options.faithful and totals and position is None:
        failures.append(
            "no waypoint was reached with a measured pose: position_accuracy and "
            "orientation_accuracy are null"
        )
    # compared in the script's own format (pose dumps), so that only numbers can differ
    form = (
        score
        if options.score_format_2019
        else score_listing(
            segments, flow, replace(options, score_format_2019=True), totals, position, orientation
        )
    )
    comparison = compare_scores(form, logs.run.live, logs.result_file)
    intervals, uncertainty = hnf_intervals(logs, segments, summed, divisor, options)
    provenance = Provenance(
        inputs=(str(logs.bag), logs.config_source, logs.transform_source)
        + ((logs.result_file.path,) if logs.result_file is not None else ()),
        parameters=(
            ("rules", options.rules),
            ("script", f"{options.script} ({season})"),
            ("max_gap_s", str(options.max_gap_s)),
            ("transform", logs.transform_source),
            ("config", logs.config_source),
        ),
        team=logs.team,
        team_source="RSBB layout" if logs.team else None,
    )
    return HnfResult(
        score=score,
        segments=tuple(segments),
        waypoints=logs.waypoints,
        position_accuracy=position,
        orientation_accuracy=orientation,
        totals=totals,
        rules=options.rules,
        script=options.script,
        t_start_ns=flow.t_start_ns,
        stop_ns=flow.stop_ns,
        comparison=comparison,
        intervals=ResultIntervals(intervals, uncertainty),
        track=_path_of(logs.body),
        warnings=tuple(warnings),
        deviations=deviations_of(options, segments, flow),
        failures=tuple(failures),
        provenance=provenance,
    )


def _path_of(body: TfTrack) -> tuple[I64, Any]:
    """The marker set's (x, y) thinned to at most ~2,000 points, for plots and Foxglove."""
    step = max(1, len(body) // 2000)
    return body.t_ns[::step].copy(), body.xyz[::step, :2].copy()


def _flow_warnings(flow: HnfFlow, segments: list[HnfSegment], options: HnfOptions) -> list[str]:
    out = list(flow.remarks)
    if flow.log_ended:
        out.append("the log ends while the script still ran: scored as if stopped there")
    if flow.stop_kind in (EndKind.STOP, EndKind.GLOBAL_TIMEOUT) and flow.stop_ns is not None:
        what = (
            "the referee stopped" if flow.stop_kind is EndKind.STOP else "the global timeout ended"
        )
        out.append(
            f"{what} the run {ns_to_s(flow.stop_ns - flow.t_start_ns):.3f} s after its start"
            + ("" if flow.totals else " (the script returned without its totals)")
        )
    for s in segments:
        if s.flow.skipped:
            out.append(f"segment {s.index + 1}: the referee skipped the waypoint (no pose)")
        elif s.robot is not None and not s.measured:
            gap = (s.gap_ns or 0) / 1e9
            out.append(
                f"segment {s.index + 1}: the marker set was not tracked around the lookup "
                f"({gap:.3f} s between samples > --max-gap {options.max_gap_s:g} s): not measured"
            )
    return out
