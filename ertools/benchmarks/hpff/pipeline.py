"""HPFF's stages: the run bag and its side files (:func:`load`), the samples (:func:`find_runs`:
the script's, or ertools' grid), the poses and the score (:func:`score_runs`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ertools.benchmarks.base import notice
from ertools.benchmarks.common.interval_output import ResultIntervals
from ertools.benchmarks.hpff.config import MARGIN_S, SCRIPT_COMMIT, SCRIPT_FRAMES, HpffOptions
from ertools.benchmarks.hpff.flow import HpffFlow, grid_flow, script_flow
from ertools.benchmarks.hpff.formula import FAILED, Following, following
from ertools.benchmarks.hpff.intervals import hpff_intervals
from ertools.benchmarks.hpff.logs import HpffLogs
from ertools.benchmarks.hpff.result import (
    COVERED_KEY,
    DEVIATION_KEY,
    RELIABILITY_KEY,
    HpffResult,
    HpffSamples,
    deviations_of,
    nan_xy,
)
from ertools.errors import ConfigError, SegmentationError
from ertools.io.summary import summary
from ertools.rsbb.log import EndKind
from ertools.rsbb.opened import one_run_bag, open_run
from ertools.rsbb.py2 import to_sec
from ertools.rsbb.score import compare_scores
from ertools.rsbb.sidefiles import read_side_yaml, script_transform
from ertools.rsbb.tf import link_at, read_tf_tracks, script_poses
from ertools.streams import Provenance
from ertools.timeutil import ns_to_s

CODE = "HPFF"
FRAME = SCRIPT_FRAMES[0]  # /robot under /robot_markerset (both lookups)
PARAMS = ("min_following_distance", "max_following_distance", "desired_following_distance")


def _params(data: Any, where: str) -> dict[str, Any]:
    if not isinstance(data, dict):
        raise ConfigError(f"{where}: not a mapping of the HPFF parameters")
    out = {}
    for key in (*PARAMS, "goal_timeout"):
        value = data.get(key)
        if (
            not isinstance(value, int | float)
            or isinstance(value, bool)
            or not math.isfinite(value)
        ):
            raise ConfigError(f"{where}: {key} is {value!r}, not a number")
        out[key] = value
    return out


def load(logs: Sequence[Path], options: HpffOptions) -> HpffLogs:
    """Read the run bag, the following parameters (HPFF.yaml, else the result file's params)
    and the team transform; the side files found are named on stderr.

    Raises:
        UsageError: not one bag.
        ConfigError: another benchmark's bag or result file; no parameters or transform
            found, or one unreadable.
        SegmentationError: the benchmark never started in the log.
        TopicError, BagError: an unreadable bag.
    """
    bag = one_run_bag(logs, CODE)
    opened = open_run([bag], CODE, options, want=("config", "transform", "result"), say=notice)
    run, result, team = opened.run, opened.result_file, opened.team
    transform_path = opened.transform_file()
    side = opened.side
    transform = script_transform(transform_path, ("markerset_to_robot_transform",))
    if side.config is not None:
        params = _params(read_side_yaml(side.config, "HPFF config"), str(side.config))
        source = str(side.config)
    elif result is not None and isinstance(result.params, dict):
        source = f"{result.path} (benchmark_info.params)"
        params = _params(result.params, source)
    else:
        raise ConfigError(
            "no HPFF.yaml beside the bag or in the RSBB layout, and no result file with the "
            "params: give --config HPFF.yaml or --result result_run_<n>_<date>.yaml"
        )
    if run.t_start_ns is None:
        raise SegmentationError(f"{bag}: the benchmark never started (no EXECUTING_BENCHMARK)")
    tracks = read_tf_tracks(bag)
    log_end = max(t.last_ns for t in summary(bag).topics if t.last_ns is not None)
    return HpffLogs(
        bag,
        run,
        tracks.body("robot_markerset"),
        tracks.body("actor_markerset"),
        tracks.broadcasts(FRAME),
        params,
        source,
        transform,
        str(transform_path),
        result,
        team,
        int(log_end),
    )


def find_runs(logs: HpffLogs, options: HpffOptions) -> HpffFlow:
    """The samples: the script's (``--sampling script``) or ertools' 2 Hz grid."""
    if options.sampling_script:
        return script_flow(logs.run, logs.stamps, logs.robot, logs.person, logs.log_end_ns)
    return grid_flow(logs.run, logs.log_end_ns)


def _samples(logs: HpffLogs, flow: HpffFlow, options: HpffOptions) -> HpffSamples:
    """The distances and robot positions of the samples (vectorised)."""
    t = flow.sample_ns
    rel_t = np.where(flow.relative_ok, flow.relative_ns, t)
    abs_t = np.where(flow.absolute_ok, flow.absolute_ns, t)
    absolute = script_poses(logs.robot, abs_t, logs.transform)
    at_rel = script_poses(logs.robot, rel_t, logs.transform)
    person = link_at(logs.person, rel_t)
    if options.plane_actor:
        relative = script_poses(logs.robot, rel_t, logs.transform, reference=logs.person)
        distance = np.hypot(relative.x, relative.y)
    else:
        distance = np.hypot(at_rel.x - person.xyz[:, 0], at_rel.y - person.xyz[:, 1])
    if options.sampling_script:
        measured = flow.relative_ok
        robot_ok = flow.absolute_ok
    else:
        gap = round(options.max_gap_s * 1e9)
        robot_ok = absolute.inside & (absolute.gap_ns <= gap)
        measured = robot_ok & person.inside & (person.gap_ns <= gap)
    robot_xy = nan_xy(np.column_stack([absolute.x, absolute.y]), robot_ok)
    return HpffSamples(
        t,
        np.where(measured, distance, np.nan),
        np.asarray(measured),
        robot_xy,
        np.asarray(robot_ok),
        nan_xy(person.xyz[:, :2], measured),
    )


def _duration(flow: HpffFlow, options: HpffOptions) -> float | None:
    if options.clock_script:
        if flow.end_ns is None or flow.started_ns is None:
            return None
        return to_sec(flow.end_ns - flow.started_ns)
    g = flow.goal
    if g is None or g.t_start_ns is None:
        return None
    end = flow.end_ns if flow.end_ns is not None else flow.stop_ns
    return None if end is None else to_sec(end - g.t_start_ns)


def _listing(
    stats: Following, passed: bool | None, options: HpffOptions, stopped: bool
) -> dict[str, Any]:
    score: dict[str, Any] = {}
    if options.stopped_2019 and (stopped or passed is None):
        return score
    if passed is False or stopped:
        score["Result"] = FAILED
        if options.stopped_2019:
            return score
    if stats.average_deviation is not None:
        score[DEVIATION_KEY] = stats.average_deviation
    score[COVERED_KEY] = stats.covered
    if stats.reliability is not None:
        score[RELIABILITY_KEY] = stats.reliability
    if stats.warning is not None:
        score["WARNING"] = stats.warning
    return score


def score_runs(logs: HpffLogs, flow: HpffFlow, options: HpffOptions) -> HpffResult:
    """The score of the run in the result file's form, compared with the run's own."""
    samples = _samples(logs, flow, options)
    p = logs.params
    stats = following(
        samples.distance,
        samples.measured,
        np.nan_to_num(samples.robot_xy),
        samples.robot_ok,
        desired=p["desired_following_distance"],
        minimum=p["min_following_distance"],
        maximum=p["max_following_distance"],
    )
    duration = _duration(flow, options)
    target = float(p["goal_timeout"])
    stopped = flow.stopped or flow.never_returned
    passed = None if duration is None else target - MARGIN_S <= duration <= target + MARGIN_S
    warnings: list[str] = list(flow.remarks)
    failures: list[str] = []
    if flow.never_returned:
        warnings.append(
            "the benchmark stopped before the robot started following"
            + (
                ": the 2019 script would loop for ever (its score stays {})"
                if options.stopped_2019
                else ""
            )
        )
    elif flow.stopped:
        warnings.append(
            f"the run was stopped {ns_to_s((flow.stop_ns or 0) - flow.t_start_ns):.3f} s after its "
            f"start, after {len(samples.t_ns)} sample(s)"
        )
    if flow.log_ended:
        warnings.append("the log ends while the script still ran: scored as if stopped there")
    crashed = passed is True and stats.failure_percent is None
    if crashed:
        warnings.append("no sample at all: the 2019 script divides by zero (l. 166) and dies")
    if passed is False and duration is not None:
        warnings.append(
            f"the run lasted {duration:.3f} s, outside goal_timeout {target:g} +- {MARGIN_S:g} s: "
            "failed"
        )
    score = {} if crashed and options.stopped_2019 else _listing(stats, passed, options, stopped)
    if not options.faithful and stats.measured == 0:
        failures.append("no sample measured both the robot and the person: nothing to score")
    comparison = compare_scores(score, logs.run.live, logs.result_file)
    intervals, uncertainty = hpff_intervals(logs, samples, options)
    step = max(1, len(logs.robot) // 2000)
    tracks = (
        (logs.robot.t_ns[::step].copy(), logs.robot.xyz[::step, :2].copy()),
        (logs.person.t_ns[::step].copy(), logs.person.xyz[::step, :2].copy()),
    )
    return HpffResult(
        score=score,
        samples=samples,
        stats=stats if len(samples.t_ns) else None,
        duration_s=duration,
        passed=passed,
        goal_timeout=target,
        desired=float(p["desired_following_distance"]),
        minimum=float(p["min_following_distance"]),
        maximum=float(p["max_following_distance"]),
        t_start_ns=flow.t_start_ns,
        rules=options.rules,
        comparison=comparison,
        intervals=ResultIntervals(intervals, uncertainty),
        tracks=tracks,
        warnings=tuple(warnings),
        deviations=deviations_of(options, stopped, passed is False),
        failures=tuple(failures),
        provenance=Provenance(
            inputs=(str(logs.bag), logs.config_source, logs.transform_source)
            + ((logs.result_file.path,) if logs.result_file is not None else ()),
            parameters=(
                ("rules", options.rules),
                ("script", SCRIPT_COMMIT),
                ("max_gap_s", str(options.max_gap_s)),
                ("transform", logs.transform_source),
                ("config", logs.config_source),
            ),
            team=logs.team,
            team_source="RSBB layout" if logs.team else None,
        ),
    )


def stopped_kind(flow: HpffFlow) -> str:
    """How the run ended, in words (for notes)."""
    return {
        EndKind.END: "ended by the script",
        EndKind.STOP: "stopped (the script's abort or the referee)",
        EndKind.GLOBAL_TIMEOUT: "ended by the global timeout",
    }.get(flow.stop_kind, "the log ends")
