"""FBM3@Work trajectory following (seed 7.3): load -> find runs -> score -> result.

:func:`load`, :func:`find_runs` and :func:`score_runs` are the stages (bags read through
:mod:`ertools.io`); :func:`score_paths` is pure (pose stream + run windows + config ->
:class:`Fbm3wResult`). The scoring itself is in
:mod:`ertools.benchmarks.fbm3w.formula`, run finding in :mod:`ertools.benchmarks.fbm3w.runs`.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.benchmarks.common.ending import end_payload_deviation
from ertools.benchmarks.common.epsilon import (
    NoiseResult,
    noise_from_stream,
)
from ertools.benchmarks.common.frozen import frozen_warnings
from ertools.benchmarks.common.hygiene import (
    frame_change_warning,
    identical_poses,
    impossible_warning,
)
from ertools.benchmarks.common.uncertainty import few_warning
from ertools.benchmarks.common.validity import (
    STILL_M,
    SampleMask,
    coverage,
    coverage_problem,
    last_measured,
    lost_spans,
    measured,
    sample_codes,
    summarise,
)
from ertools.benchmarks.fbm3w.auto_runs import find_auto
from ertools.benchmarks.fbm3w.config import (
    DEFAULT_TOPIC,
    NAMESPACE,
    Fbm3wOptions,
)
from ertools.benchmarks.fbm3w.formula import score_path, shape_floor, try_score
from ertools.benchmarks.fbm3w.intervals import with_intervals
from ertools.benchmarks.fbm3w.logs import Fbm3wLogs, read_fbm3w_poses
from ertools.benchmarks.fbm3w.result import Fbm3wResult, RunResult
from ertools.benchmarks.fbm3w.rules import (
    RULE_ARC_LENGTH,
    RULE_D_MIN,
    RULE_LIVE_CLOCK,
    RULE_POSE_TOPIC,
    RULE_RUN_FINDING,
    RULE_STOPPED_RUNS,
    RULE_TIMEOUT_RUNS,
    RULE_UNSCOREABLE_RUNS,
    RULE_USER_SHAPES,
)
from ertools.benchmarks.fbm3w.runs import (
    RunWindow,
    find_states,
    find_windows,
    with_specs,
)
from ertools.benchmarks.fbm3w.settings import DEFAULT_D_MIN, Fbm3wConfig
from ertools.errors import ConfigError, ScoringError
from ertools.fidelity import Deviation
from ertools.io.clock import check_header_clock
from ertools.io.reader import read_benchmark_states, topics
from ertools.io.summary import summary
from ertools.progress import Reporter, current
from ertools.streams import PoseStream, Provenance

log = logging.getLogger("ertools.benchmarks.fbm3w.pipeline")

# The reference pose is the last sample at or before the reference time; older than this, the
# marker set was probably not tracked at that moment.
STALE_REFERENCE_S = 0.5
# Below this reference-start distance the run frame's direction is uncertain (1 mm of noise
# turns a 1 cm baseline by ~0.1 rad).
SHORT_BASELINE_M = 0.01
# The shape floor worth a warning.
FLOOR_WARN_M = 0.0005
# A kept path this much longer than the target is suspicious (the sample's runs: 1.00-1.01).
LONG_PATH_RATIO = 1.15
# A run is unscoreable when valid data covers less than this fraction of its path window,
# or a stretch without it longer than MAX_INNER_GAP_S lies between two valid samples (the
# 2015 formula then follows a straight chord where the robot went). A tracking loss whose two
# ends are within STILL_M of each other hid no motion. Why these values: docs/uncertainty.md.
MIN_COVERAGE = 0.9
MAX_INNER_GAP_S = 0.5


def load(paths: Sequence[Path], options: Fbm3wOptions) -> Fbm3wLogs:
    """Read the poses and, when the runs come from them, the state topics.

    The run mode is settled here: explicit windows when given, else the BmBox states when the
    log has them, else runs found from motion (``--runs auto``).

    Raises:
        ErtoolsError: unreadable bags, no poses, no state topic for ``--runs states``.
    """

    plist = tuple(Path(p) for p in paths)
    poses = read_fbm3w_poses(plist, options)
    summaries = [summary(p) for p in plist]
    mode = options.runs
    if mode is None:
        if options.windows:
            mode = "windows"
        else:
            bmbox_topics = {f"/{NAMESPACE}/bmbox_state", f"/{NAMESPACE}/bbbox_state"}
            mode = "states" if bmbox_topics & set(topics(plist)) else "auto"
            if mode == "auto":
                log.info("no /fbm3w state topics: finding the runs from motion (--runs auto)")
    states = read_benchmark_states(list(plist), NAMESPACE) if mode == "states" else None
    return Fbm3wLogs(
        paths=plist,
        poses=poses,
        bag_start_ns=min(x.start_ns for x in summaries),
        bag_end_ns=max(x.end_ns for x in summaries),
        mode=mode,
        states=states,
    )


def find_runs(logs: Fbm3wLogs, options: Fbm3wOptions) -> list[RunWindow]:
    """The run windows: from explicit windows, the BmBox states or motion.

    Raises:
        ConfigError: ``--runs windows`` without windows.
        SegmentationError: no run in the states.
        ClockError: header-stamped poses on another clock than the state messages.
    """
    mode = logs.mode
    if mode == "windows":
        if not options.windows:
            raise ConfigError("--runs windows needs --run SPEC:REF_T:START_T:END_T or --runs-file")
        windows = find_windows(options.windows, logs.bag_start_ns, logs.bag_end_ns)
    elif mode == "states":
        assert logs.states is not None
        windows = find_states(logs.states, exact_2015=options.exact_end_payloads)
    else:
        windows = find_auto(logs.poses, options.config or Fbm3wConfig(), **_still(options))
    # State messages and --run windows are timed by record time: header-stamped poses from a
    # mocap clock seconds off would be cut at other moments (a wrong score that looks right).

    what = {"states": "state messages", "auto": None}.get(
        mode, "run windows (times from the log start)"
    )
    check_header_clock(list(logs.paths), logs.poses, what, time_source=options.time_source)
    return windows


def score_runs(logs: Fbm3wLogs, windows: Sequence[RunWindow], options: Fbm3wOptions) -> Fbm3wResult:
    """Score the runs found (:func:`score_paths` on the logs' poses)."""
    result = score_paths(
        logs.poses,
        windows,
        options.config or Fbm3wConfig(),
        options=options,
        bag_start_ns=logs.bag_start_ns,
        inputs=tuple(str(p) for p in logs.paths),
        progress=current(),
    )
    if logs.mode != "states" or logs.states is None or logs.states.bmbox is None:
        return result
    # Only the state finder reads the RefBox, and it counts time from the first BmBox message.
    t0 = int(logs.states.bmbox.t_ns[0])
    said = end_payload_deviation(logs.states.refbox, t0, exact_2015=options.exact_end_payloads)
    return result if said is None else replace(result, deviations=(*result.deviations, said))


def _still(options: Fbm3wOptions) -> dict[str, float]:
    out = {}
    if options.still_speed is not None:
        out["still_speed"] = options.still_speed
    if options.min_still_s is not None:
        out["min_still_s"] = options.min_still_s
    return out


def score_paths(
    poses: PoseStream,
    windows: Sequence[RunWindow],
    config: Fbm3wConfig,
    *,
    options: Fbm3wOptions = Fbm3wOptions(),
    bag_start_ns: int | None = None,
    inputs: tuple[str, ...] = (),
    progress: Reporter | None = None,
) -> Fbm3wResult:
    """Score every run of ``windows`` on ``poses`` (pure; no file access), each run
    reported to ``progress`` when scored."""
    cfg = config if options.d_min is None else config.with_d_min(options.d_min)
    start_ns = poses.start_ns if bag_start_ns is None else bag_start_ns
    runs_in, warnings = with_specs(list(windows), cfg)
    for w in runs_in:
        warnings.extend(w.warnings)
    specs = cfg.runs_specifications
    if runs_in and runs_in[0].mode == "auto" and len(runs_in) < len(specs):
        last = runs_in[-1]
        after = "" if last.end_ns is None else f" after {(last.end_ns - start_ns) / 1e9:.2f} s"
        warnings.append(
            f"--runs auto found {len(runs_in)} of the {len(specs)} runs the config lists: no "
            f"move{after} (the end of run {last.index}'s path) matches run {len(runs_in)}'s "
            f"shape {specs[len(runs_in)]!r} between still phases; the log ends there or the "
            "rest need --runs windows"
        )
    mask = sample_codes(poses.t_ns, poses.xyz, poses.quat_xyzw)
    full, usable = poses, measured(mask)  # scored without the impossible poses
    poses = poses if usable.all() else poses.take(usable)
    noise, same = _noise(poses, options, warnings), identical_poses(full)
    said = (frame_change_warning(full, start_ns), impossible_warning(full, start_ns))
    warnings.extend(w for w in said if w)
    results: list[RunResult] = []
    failures: list[str] = []
    if progress is not None:
        progress.task("scoring runs", len(runs_in), "runs")
    for window in runs_in:
        run = _score_one(full, same, window, cfg, options, start_ns, warnings, mask, usable)
        if progress is not None:
            progress.advance(1)
        results.append(run)
        if run.error is not None:
            failures.append(f"run {window.index} ({run.spec}): {run.error}")
    if noise is not None and noise.distances.size and cfg.d_min < noise.suggested_d_min:
        frac = float(np.mean(noise.distances >= cfg.d_min)) if noise.distances.size else 0.0
        warnings.append(
            f"d_min {cfg.d_min * 1000:.3g} mm is below the mocap noise measured in this bag "
            f"(epsilon {noise.epsilon * 1000:.3g} mm over {noise.duration_s:.1f} s of "
            f"stationary phases; {frac:.1%} of still steps exceed d_min, inflating L): "
            f"suggested d_min {noise.suggested_d_min:.5f} m ({noise.c:g} * epsilon); see "
            "--d-min-sweep"
        )
    # the reference and starting positions set the run frame: a frozen pose there is the last
    # one before a tracking loss, not where the marker set was
    moments = (("reference", "ref_ns"), ("start", "start_ns"), ("end", "end_ns"))
    at = [(f"run {w.index}", what, getattr(w, k)) for w in runs_in for what, k in moments]
    warnings.extend(frozen_warnings(poses, [m for m in at if m[2] is not None], start_ns))
    mode = runs_in[0].mode if runs_in else (options.runs or "states")
    results, best_interval, uncertainty = with_intervals(
        poses, identical_poses(poses), results, cfg, options, noise
    )
    return Fbm3wResult(
        runs=tuple(results),
        best_interval=best_interval,
        uncertainty=uncertainty,
        d_min=cfg.d_min,
        noise=noise,
        sweep_values=tuple(options.sweep),
        warnings=tuple(warnings),
        deviations=tuple(_deviations(cfg, results, mode, poses, options)),
        failures=tuple(failures),
        provenance=Provenance(
            inputs=inputs or (poses.source,),
            parameters=(
                ("config", cfg.source),
                ("d_min", repr(cfg.d_min)),
                ("runs", mode),
                ("poses", poses.source),
                ("timeout_runs", options.timeout_runs),
                ("stopped_runs", options.stopped_runs),
            ),
        ),
        count_stopped=options.stopped_runs != "2015",
    )


def _noise(poses: PoseStream, options: Fbm3wOptions, warnings: list[str]) -> NoiseResult | None:
    try:
        return noise_from_stream(
            poses,
            stationary=True,
            c=options.noise_c,
            still_speed=options.still_speed,
            min_still_s=options.min_still_s,
        )
    except ScoringError:
        warnings.append(
            "no stationary phase in the poses: the mocap noise (and whether d_min is above it) "
            "could not be estimated"
        )
        return None


def _score_one(
    poses: PoseStream,
    same: npt.NDArray[np.bool_],
    window: RunWindow,
    cfg: Fbm3wConfig,
    options: Fbm3wOptions,
    bag_start_ns: int,
    warnings: list[str],
    mask: SampleMask | None = None,
    usable: npt.NDArray[np.bool_] | None = None,
) -> RunResult:
    spec = window.spec or ""

    def result(error: str | None, **kw: Any) -> RunResult:
        base: dict[str, Any] = {
            "window": window,
            "spec": spec or "?",
            "score": None,
            "error": error,
            "samples": 0,
            "tracking_losses": 0,
            "reference_xy": None,
            "target_length": None,
            "d_min": cfg.d_min,
            "bag_start_ns": bag_start_ns,
        }
        base.update(kw)
        return RunResult(**base)

    if not spec:
        return result("no spec for this run (the config lists fewer runs); add it to the config")
    try:
        shape = cfg.shape(spec)
    except ConfigError as err:
        return result(err.message)
    if options.arc_length:
        shape = shape.by_arc_length()
    target_length = shape.length()
    partial = window.status == "timeout" and options.timeout_runs == "2015"
    if window.status in ("interrupted", "timeout", "stopped") and not partial:
        return result(None, target_length=target_length)  # reported, not scored
    if window.start_ns is None or window.end_ns is None or window.ref_ns is None:
        return result("no reference time or path window was found for this run")
    lo = int(np.searchsorted(poses.t_ns, window.start_ns, side="left"))
    hi = int(np.searchsorted(poses.t_ns, window.end_ns, side="right"))
    window_xy = poses.xyz[lo:hi, :2]
    keep = np.ones(hi - lo, dtype=bool) if usable is None else usable[lo:hi]
    xy = window_xy[keep]  # the samples scored: without the impossible ones
    losses = int(np.sum(same[lo : max(lo, hi - 1)])) if hi - lo > 1 else 0
    common: dict[str, Any] = {
        "samples": hi - lo,
        "tracking_losses": losses,
        "target_length": target_length,
    }
    problem = None
    if mask is not None:
        validity = summarise(mask, window.start_ns, window.end_ns)
        lost = lost_spans(validity, window_xy, STILL_M)
        common["validity"] = validity
        common["path_coverage"] = coverage(validity, lost)
        problem = coverage_problem(validity, MIN_COVERAGE, MAX_INNER_GAP_S, lost)
        if problem is not None:
            common["unscoreable_reason"] = problem
    rel = (window.start_ns - bag_start_ns) / 1e9, (window.end_ns - bag_start_ns) / 1e9
    as_2015 = options.unscoreable_runs == "2015"
    if len(xy) < (1 if as_2015 else 2):
        crashed = " (the 2015 node failed here, robot_path[0] of an empty path, and sent no score)"
        return result(
            f"{len(xy)} pose sample(s) in the path window {rel[0]:.3f}-{rel[1]:.3f} s; "
            "at least 2 are needed (tracking lost, or wrong window?)"
            + (crashed if as_2015 else ""),
            **common,
        )
    ref_i = int(np.searchsorted(poses.t_ns, window.ref_ns, side="right")) - 1
    ref_i = ref_i if usable is None else last_measured(usable, ref_i)
    ref_rel = (window.ref_ns - bag_start_ns) / 1e9
    if ref_i < 0:
        return result(f"no pose at or before the reference time {ref_rel:.3f} s", **common)
    age = (window.ref_ns - int(poses.t_ns[ref_i])) / 1e9
    if age > STALE_REFERENCE_S:
        warnings.append(
            f"run {window.index}: the reference pose is {age:.2f} s older than the reference "
            f"time {ref_rel:.3f} s (tracking lost then?)"
        )
    ref_xy = poses.xyz[ref_i, :2].copy()
    common["reference_xy"] = (float(ref_xy[0]), float(ref_xy[1]))
    try:
        score = score_path(xy, ref_xy, shape, cfg.d_min, as_2015=as_2015)
    except ScoringError as err:
        return result(err.message, **common)
    if problem is not None and options.unscoreable_runs != "2015":
        # no number, but the path in its frame: the plot shows where the data is missing
        return result(
            None, frame_xy=score.frame.to_frame(xy), sample_t_ns=poses.t_ns[lo:hi][keep], **common
        )
    if problem is not None:
        warnings.append(
            f"run {window.index}: 2015 scored this run from {common['path_coverage']:.1%} of "
            f"its path (--unscoreable 2015); by default it is unscoreable: {problem}"
        )
    if len(score.kept) == 1:
        warnings.append(
            f"run {window.index}: no pose of its path moved d_min from the first: 2015 scored "
            "it error_sum / N = 0.0 over its one kept pose (--unscoreable 2015); by default it "
            "has no distance_error"
        )
    else:
        few = few_warning(len(score.kept), "kept path point(s)", f"run {window.index}")
        warnings.extend([few] if few else [])
    baseline = float(np.hypot(*(xy[0] - ref_xy)))
    if baseline < SHORT_BASELINE_M:
        warnings.append(
            f"run {window.index}: the reference and starting positions are only "
            f"{baseline * 1000:.1f} mm apart; the run frame's direction is uncertain"
        )
    if partial:
        warnings.append(
            f"run {window.index} was ended by a RefBox timeout: scored on the "
            f"{score.path_length:.4f} m of path it covered (target {target_length:.4f} m), "
            "normalised by its own length, and eligible as best run (--timeout-runs 2015)"
        )
    ratio = score.path_length / target_length
    if ratio > LONG_PATH_RATIO:
        warnings.append(
            f"run {window.index}: the kept path is {ratio - 1:.0%} longer than the target "
            f"({score.path_length:.4f} vs {target_length:.4f} m): jitter passing d_min or a "
            "detour inflates L and shifts l/L; see --d-min-sweep"
        )
    swept = tuple((d, try_score(xy, ref_xy, shape, d)) for d in options.sweep)
    floor = shape_floor(shape, cfg.d_min)
    if floor > FLOOR_WARN_M and not any(spec in w and "floor" in w for w in warnings):
        warnings.append(
            f"shape {spec!r} is not parametrised by arc length: a robot exactly on it scores "
            f"{floor * 1000:.2f} mm with the 2015 formula (shape_floor); --arc-length compares "
            "at equal fractions of the target's length instead"
        )
    return result(
        None,
        score=score,
        sweep=swept,
        frame_xy=score.frame.to_frame(xy),
        sample_t_ns=poses.t_ns[lo:hi][keep],
        shape_floor=floor,
        target_dense=shape.dense(501),
        **common,
    )


def _deviations(
    cfg: Fbm3wConfig,
    runs: Sequence[RunResult],
    mode: str,
    poses: PoseStream,
    options: Fbm3wOptions,
) -> list[Deviation]:
    out = []
    if mode == "states":
        out.append(
            RULE_LIVE_CLOCK.deviation(
                "reference = last logged pose at or before the BmBox left "
                "WAITING_MANUAL_OPERATION and "
                "execution_time from the BmBox state messages' record times; 2015 read the live "
                "tf and its own wall clock at the same transitions"
            )
        )
    elif mode == "windows":
        out.append(
            RULE_RUN_FINDING.deviation(
                "runs from explicit windows; the 2015 node only had its state machine"
            )
        )
    else:
        out.append(
            RULE_RUN_FINDING.deviation(
                "runs found from motion (--runs auto); the 2015 node only had its state machine"
            )
        )
    if not poses.source.endswith(DEFAULT_TOPIC):
        out.append(
            RULE_POSE_TOPIC.deviation(
                f"poses from {poses.source.rsplit(':', 1)[-1]}; 2015 used {DEFAULT_TOPIC}"
            )
        )
    if not math.isclose(cfg.d_min, DEFAULT_D_MIN, rel_tol=0, abs_tol=1e-12):
        out.append(
            RULE_D_MIN.deviation(f"d_min = {cfg.d_min} m; the 2015 script used {DEFAULT_D_MIN} m")
        )
    custom = sorted(
        {r.spec for r in runs if r.spec in cfg.shapes and not cfg.shapes[r.spec].builtin}
    )
    if custom:
        out.append(
            RULE_USER_SHAPES.deviation(
                f"user-defined shape(s) {', '.join(custom)}; 2015 had only its built-in shapes"
            )
        )
    if options.arc_length:
        out.append(
            RULE_ARC_LENGTH.deviation(
                "targets compared at equal fractions of their arc length (--arc-length); 2015 "
                "evaluated each shape at its own parameter"
            )
        )
    timed_out = [str(r.index) for r in runs if r.window.status == "timeout"]
    if options.timeout_runs != "2015" and timed_out:
        out.append(
            RULE_TIMEOUT_RUNS.deviation(
                f"a run the RefBox timed out (run {', '.join(timed_out)}) is listed with its "
                "time and no distance_error and cannot be the best run; the 2015 node scored it "
                "on the path it had covered and it could be the best run"
            )
        )
    unscoreable = [r for r in runs if r.status == "unscoreable"]
    if unscoreable:
        listed = "; ".join(f"run {r.index}: {r.unscoreable_reason}" for r in unscoreable)
        out.append(
            RULE_UNSCOREABLE_RUNS.deviation(
                f"unscoreable, no distance_error ({listed}); the 2015 node scored such a run "
                "from the poses it had"
            )
        )
    stopped = [str(r.index) for r in runs if r.window.status == "stopped"]
    if options.stopped_runs != "2015" and stopped:
        out.append(
            RULE_STOPPED_RUNS.deviation(
                f"a run the RefBox stopped (run {', '.join(stopped)}) counts in execution_time; "
                "the 2015 node treated it as aborted and left its time out"
            )
        )
    return out
