"""HGMF's stages: the run bag and its side files read (:func:`load`), the script followed
through the log (:func:`find_runs`), the heights and positions looked up and the score made
(:func:`score_runs`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ertools.arrays import I64
from ertools.benchmarks.base import notice
from ertools.benchmarks.common.interval_output import ResultIntervals
from ertools.benchmarks.hgmf.checks import sample_heights, timer_heights, timer_ticks
from ertools.benchmarks.hgmf.config import CODE, OBJECT_BODY, SCRIPT_FRAMES, TABLE, HgmfOptions
from ertools.benchmarks.hgmf.flow import Attempt, HgmfFlow, script_flow
from ertools.benchmarks.hgmf.formula import first_rise, planar_distance
from ertools.benchmarks.hgmf.intervals import hgmf_intervals
from ertools.benchmarks.hgmf.listing import score_listing
from ertools.benchmarks.hgmf.result import HgmfGoal, HgmfResult, deviations_of
from ertools.errors import ConfigError, SegmentationError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.summary import summary
from ertools.rsbb.log import RsbbRun
from ertools.rsbb.opened import one_run_bag, open_run
from ertools.rsbb.results import RsbbResult
from ertools.rsbb.score import compare_scores
from ertools.rsbb.sidefiles import read_side_yaml
from ertools.rsbb.tf import TfTrack, read_tf_tracks, script_poses
from ertools.streams import Provenance

FRAME = SCRIPT_FRAMES[0]  # /object under /actor_markerset, in /table_origin
IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


@frozen_dataclass
class HgmfObject:
    """One object of ``HGMF.yaml``: its id (an integer) and description."""

    ident: int
    description: str


@frozen_dataclass(eq=False)
class HgmfLogs:
    """A run bag and what the script read.

    Attributes:
        bag: the run bag.
        run: its RefBox/BmBox events and live scores.
        table, actor: the table's and the object's marker sets on ``/tf``.
        stamps: the script's ``/object`` lookups (their ``now``).
        objects: the config's objects.
        config_source: where they came from.
        result_file: the run's result file (None: not found).
        team: the team.
        log_end_ns: the bag's last message.
    """

    bag: Path
    run: RsbbRun
    table: TfTrack
    actor: TfTrack
    stamps: I64
    objects: tuple[HgmfObject, ...]
    config_source: str
    result_file: RsbbResult | None
    team: str | None
    log_end_ns: int


def _objects(params: Any, where: str) -> tuple[HgmfObject, ...]:
    objects = params.get("objects") if isinstance(params, dict) else None
    if not isinstance(objects, list) or not objects:
        raise ConfigError(f"{where}: no objects list ([{{id: 1, description: ...}}, ...])")
    out = []
    for k, o in enumerate(objects):
        ident = o.get("id") if isinstance(o, dict) else None
        if not isinstance(ident, int) or isinstance(ident, bool):
            raise ConfigError(f"{where}: object {k + 1} has no whole-number id")
        out.append(HgmfObject(ident, str(o.get("description", ""))))
    return tuple(out)


def _config(
    options: HgmfOptions, found: Path | None, result: RsbbResult | None
) -> tuple[tuple[HgmfObject, ...], str]:
    path = options.config or found
    if path is not None:
        return _objects(read_side_yaml(path, "HGMF config"), str(path)), str(path)
    if result is not None and isinstance(result.params, dict):
        where = f"{result.path} (benchmark_info.params)"
        return _objects(result.params, where), where
    raise ConfigError(
        "no HGMF.yaml beside the bag or in the RSBB layout, and no result file with the "
        "params: give --config HGMF.yaml (its objects) or --result result_run_<n>_<date>.yaml"
    )


def load(logs: Sequence[Path], options: HgmfOptions) -> HgmfLogs:
    """Read the run bag and its side files (found ones named on stderr).

    Raises:
        UsageError: not one bag.
        ConfigError: another benchmark's bag or result file, no config anywhere, an
            unreadable side file.
        SegmentationError: the benchmark never started in the log.
        TopicError, BagError: an unreadable bag.
    """
    bag = one_run_bag(logs, CODE)
    opened = open_run([bag], CODE, options, want=("config", "result"), say=notice)
    run, result = opened.run, opened.result_file
    objects, config_source = _config(options, opened.side.config, result)
    if run.t_start_ns is None:
        raise SegmentationError(
            f"{bag}: the benchmark never started (no EXECUTING_BENCHMARK): nothing to score"
        )
    tracks = read_tf_tracks(bag)
    log_end = max(t.last_ns for t in summary(bag).topics if t.last_ns is not None)
    return HgmfLogs(
        bag,
        run,
        tracks.body(TABLE),
        tracks.body(OBJECT_BODY),
        tracks.broadcasts(FRAME),
        objects,
        config_source,
        result,
        opened.team,
        int(log_end),
    )


def find_runs(logs: HgmfLogs, options: HgmfOptions) -> HgmfFlow:
    """The 2019 script followed through the log."""
    del options  # one control flow: the options change the arithmetic only
    return script_flow(
        logs.run, logs.stamps, (logs.table, logs.actor), len(logs.objects), logs.log_end_ns
    )


def _grasp(
    logs: HgmfLogs, a: Attempt, z_ref: float, options: HgmfOptions
) -> tuple[bool, int | None, float | None]:
    """Whether the object rose more than 3 cm during the goal, when first, and by how much at
    most (at the timer's ticks with ``--grasp-sampling timer``, else at every sample)."""
    start, end = a.times.start_ns, a.times.end_ns
    if options.grasp_timer:
        h = timer_heights(logs.actor, logs.table, timer_ticks(start, end))
    else:
        h = sample_heights(logs.actor, logs.table, start, end)
    z = h.z[h.ok]
    t = h.checked_ns[h.ok]
    first = first_rise(t, z, z_ref)
    top = float(np.max(z) - z_ref) if z.size else None
    return first is not None, first, top


def _goals(logs: HgmfLogs, flow: HgmfFlow, options: HgmfOptions) -> list[HgmfGoal]:
    """Each attempt with its height, grasp and final position (the lookups vectorised)."""
    max_gap = round(options.max_gap_s * 1e9)
    refs = np.array([a.ref_ns for a in flow.attempts], dtype=np.int64)
    ref = script_poses(logs.actor, refs, IDENTITY, reference=logs.table)
    finals = [a for a in flow.attempts if a.final_ns is not None]
    t_final = np.array([a.final_ns for a in finals], dtype=np.int64)
    final = script_poses(logs.actor, t_final, IDENTITY, reference=logs.table)
    at_final = {id(a): k for k, a in enumerate(finals)}
    descriptions = {o.ident: o.description for o in logs.objects}
    out = []
    for k, a in enumerate(flow.attempts):
        ref_ok = bool(ref.inside[k]) and (options.gaps_interpolate or ref.gap_ns[k] <= max_gap)
        z_ref = float(ref.z[k])
        grasped, first, top = (
            _grasp(logs, a, z_ref, options)
            if a.goal is not None
            else (
                False,
                None,
                None,
            )
        )
        j = at_final.get(id(a))
        position = None if j is None else (float(final.x[j]), float(final.y[j]))
        final_gap = None if j is None else int(final.gap_ns[j])
        final_ok = j is not None and bool(final.inside[j])
        final_ok = final_ok and (options.gaps_interpolate or (final_gap or 0) <= max_gap)
        distance = None
        if position is not None and a.target is not None and final_ok and ref_ok:
            distance = float(planar_distance(np.array(a.target), np.array(position)))
        out.append(
            HgmfGoal(
                attempt=a,
                description=descriptions.get(a.object_id, "") if a.object_id is not None else "",
                z_ref=z_ref,
                ref_gap_ns=int(ref.gap_ns[k]),
                ref_ok=ref_ok,
                grasped=grasped,
                first_rise_ns=first,
                max_rise=top,
                position=position,
                final_gap_ns=final_gap,
                distance_error=distance,
            )
        )
    return out


def _check_objects(logs: HgmfLogs, goals: Sequence[HgmfGoal]) -> list[str]:
    """The config and the log agree on the objects (ids in the payloads, the placed names)."""
    out = []
    for g in goals:
        a = g.attempt
        if a.goal is None:
            continue
        if a.object_id is None or a.target is None:
            out.append(f"goal_{a.index}: its payload is not [target_x, target_y, id]: not scored")
        elif not g.description:
            out.append(f"goal_{a.index}: object id {a.object_id} is not in {logs.config_source}")
        elif a.placed and a.placed != g.description:
            out.append(
                f"goal_{a.index}: the referee placed the {a.placed}, the goal names object "
                f"{a.object_id} ({g.description})"
            )
        if a.target is not None and not all(math.isfinite(v) for v in a.target):
            out.append(f"goal_{a.index}: its target is not finite")
    return out


def score_runs(logs: HgmfLogs, flow: HgmfFlow, options: HgmfOptions) -> HgmfResult:
    """The score of the run, in the result file's form, with its comparison and intervals."""
    goals = _goals(logs, flow, options)
    listing = score_listing(goals, flow, len(logs.objects), options)
    warnings = list(flow.remarks) + _check_objects(logs, goals) + listing.notes
    comparison = compare_scores(listing.score, logs.run.live, logs.result_file)
    intervals, uncertainty = hgmf_intervals(
        (logs.actor, logs.table), goals, listing.average, listing.counted, options
    )
    provenance = Provenance(
        inputs=(str(logs.bag), logs.config_source)
        + ((logs.result_file.path,) if logs.result_file is not None else ()),
        parameters=(
            ("rules", options.rules),
            ("restarted_goals", "2019" if options.restarted_goals_2019 else "ertools"),
            ("grasp_sampling", "timer" if options.grasp_timer else "samples"),
            ("gt_gaps", "interpolate" if options.gaps_interpolate else "limit"),
            ("max_gap_s", str(options.max_gap_s)),
            ("config", logs.config_source),
        ),
        team=logs.team,
        team_source="RSBB layout" if logs.team else None,
    )
    return HgmfResult(
        score=listing.score,
        goals=tuple(goals),
        objects=len(logs.objects),
        average=listing.average,
        counted=listing.counted,
        grasped=listing.grasped,
        rules=options.rules,
        t_start_ns=flow.t_start_ns,
        stop_ns=flow.stop_ns,
        comparison=comparison,
        intervals=ResultIntervals(intervals, uncertainty),
        track=_path_of(logs.actor, logs.table),
        warnings=tuple(warnings),
        deviations=deviations_of(options, goals),
        failures=tuple(listing.failures),
        provenance=provenance,
    )


def _path_of(actor: TfTrack, table: TfTrack) -> tuple[I64, Any]:
    """The object's (x, y, z) in the table's frame, thinned to ~2,000 points (plots)."""
    step = max(1, len(actor) // 2000)
    t = actor.t_ns[::step].copy()
    poses = script_poses(actor, t, IDENTITY, reference=table)
    keep = poses.inside
    return t[keep], poses.xyz[keep]
