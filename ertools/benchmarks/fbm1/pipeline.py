"""FBM1@Home and FBM1@Work (object perception, seed 7.1): load -> find runs -> score -> result.

For each run the referee placed the reference board carrying one item on the FBM1 table; the
robot answered the item's class, instance and pose (x, y in metres, theta in degrees) in the
table frame. The ground truth is T_origin_item = T_world_origin^-1 * T_world_board *
T_board_item (``gt``); the seed's arithmetic is in ``formula``; runs come from the state
topics (``runs``); answers from the Client payloads or a results file (``answers``).

The stages are :func:`load`, :func:`find_runs` and :func:`score_runs` (the benchmark's slots);
:func:`score_fbm1` is the pure computation on streams they end in. Both benchmarks share
everything: ``benchmark`` only decides where the item's name is read first and which nodes
exist to reproduce.

Three references (``Fbm1Options.for_rules``): ``ertools`` (the default), ``2015`` (the 2015
nodes ``scripts/fbm1h`` and ``scripts/fbm1w``) and ``2016`` (the later @Home node, used in
2016-17). The ``RULE_*`` constants are the catalogue rows (:mod:`ertools.fidelity`) of every
place where the default differs from the 2015 nodes.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ertools.benchmarks.common.hygiene import frame_change_warning, impossible_warning
from ertools.benchmarks.common.validity import (
    SampleMask,
)
from ertools.benchmarks.fbm1.answers import (
    Answer,
    ResultsFile,
    answer_from_mapping,
    parse_answer_payload,
)
from ertools.benchmarks.fbm1.config import BENCHMARKS, Fbm1Options
from ertools.benchmarks.fbm1.formula import MAX_POSE_ERROR_2015, names_match, pose_errors, totals
from ertools.benchmarks.fbm1.gt import (
    GroundTruthError,
    board_motion,
    measure_ground_truth,
)
from ertools.benchmarks.fbm1.intervals import fbm1_intervals
from ertools.benchmarks.fbm1.logs import TF_LOOKUPS, Fbm1Logs, Fbm1Runs, read_body, read_logs
from ertools.benchmarks.fbm1.result import Fbm1Result, Fbm1RunResult
from ertools.benchmarks.fbm1.rules import (
    RULE_ABORTED,
    RULE_GT_MOMENT,
    RULE_NAMES,
    RULE_POSE_SOURCE,
    RULE_THETA_WRAP,
    RULE_TRANS_CLIP,
    RULE_UNSCOREABLE,
)
from ertools.benchmarks.fbm1.runs import Fbm1Run, RunsFound, runs_from_states
from ertools.benchmarks.fbm1.validity import body_mask, gt_validity
from ertools.configs._yaml import parse_payload
from ertools.configs.items import Item, ItemList
from ertools.errors import ConfigError, ScoringError, SegmentationError, TopicError
from ertools.fidelity import Deviation
from ertools.io.clock import check_header_clock
from ertools.io.reader import read_tf
from ertools.progress import Reporter, current
from ertools.streams import PoseStream, Provenance
from ertools.timeutil import NS_PER_S

log = logging.getLogger("ertools.benchmarks.fbm1.pipeline")


def _resolve_item(run: Fbm1Run, items: ItemList) -> tuple[Item, list[str]]:
    """The item a run presented; ScoringError when nothing or an unknown item is named."""
    where = f"run {run.index}"
    ref = run.item
    if ref is None:
        raise ScoringError(
            f"{where}: no item named (empty manual-operation payload); give --items-order"
        )
    warnings: list[str] = []
    if ref.item_id is not None:
        item = items.by_id(ref.item_id)
        if item is None:
            raise ScoringError(
                f"{where}: item id {ref.item_id} ({ref.source} {ref.text!r}) is not in "
                f"{items.source or 'the item list'}"
            )
        if ref.instance and ref.instance.strip() != item.instance.strip():
            warnings.append(
                f"{where}: {ref.source} names instance {ref.instance!r} but item {item.id} is "
                f"{item.instance!r} in the item list; using the id"
            )
        return item, warnings
    assert ref.instance is not None
    item = items.by_instance(ref.instance)
    if item is None:
        raise ScoringError(
            f"{where}: item {ref.instance!r} ({ref.source}) is not in "
            f"{items.source or 'the item list'}"
        )
    return item, warnings


def _answer_for(run: Fbm1Run, item: Item | None, results: ResultsFile | None) -> Answer | None:
    where = f"run {run.index}"
    if results is not None:
        entry = results.by_run.get(run.index)
        if entry is None and item is not None:
            entry = results.by_item.get(item.id)
        if entry is not None:
            return answer_from_mapping(entry, where, results.source)
    if run.answer_payload is None:
        return None
    return parse_answer_payload(run.answer_payload, where)


def _execution_time_ns(run: Fbm1Run) -> int | None:
    start = run.executing_ns if run.executing_ns is not None else run.goal_ns
    if start is None or run.result_ns is None:
        return None
    return run.result_ns - start


def item_broadcast(run: Fbm1Run, method: str, item_tf: PoseStream | None) -> int | None:
    """The stamp of the node's item broadcast on /tf that its lookup used, when logged.

    The 2015 nodes broadcast ``item`` once per answered run, after the result (between the goal
    and the next run); the 2016-17 node once per run, before the goal. ``now`` of that
    broadcast is the lookup's moment (tf answered ``Time(0)`` at it).
    """
    if item_tf is None or len(item_tf) == 0 or run.goal_ns is None:
        return None
    t = item_tf.t_ns
    if method == "result":
        after = t[(t > run.goal_ns) & (t <= run.end_ns)]
        return int(after[0]) if len(after) else None
    if method == "placed":
        before = t[(t >= run.start_ns) & (t <= run.goal_ns)]
        return int(before[-1]) if len(before) else None
    return None


def score_run(
    run: Fbm1Run,
    items: ItemList,
    origin: PoseStream,
    board: PoseStream,
    options: Fbm1Options,
    results: ResultsFile | None = None,
    t0_ns: int = 0,
    item_tf: PoseStream | None = None,
    masks: tuple[SampleMask, SampleMask] | None = None,
) -> Fbm1RunResult:
    """Score one run; a run that cannot be scored comes back with status ``failed``, one
    whose ground truth is no measurement with status ``unscoreable``.

    ``masks``: the validity codes of ``origin`` and ``board`` (computed here when None).

    ``item_tf``: the node's broadcasts of ``ref_board -> item`` on /tf, when logged: their
    stamps are the exact moments of the node's lookups.
    """
    where = f"run {run.index}"
    text = run.item.text if run.item else ""
    base: dict[str, Any] = {
        "index": run.index,
        "item_text": text,
        "goal_ns": run.goal_ns,
        "result_ns": run.result_ns,
        "ended_by": run.ended_by,
    }
    if run.goal_ns is None:
        return Fbm1RunResult(status="aborted", **base)
    item: Item | None = None
    warnings: list[str] = []
    try:
        item, warnings = _resolve_item(run, items)
        answer = _answer_for(run, item, results)
    except ScoringError as err:
        return Fbm1RunResult(status="failed", item=item, error=err.message, **base)
    exec_time = _execution_time_ns(run)
    if exec_time is None and answer is not None:
        warnings.append(f"{where}: no result time in the log; execution time unknown")
    if answer is None and run.result_ns is None and run.ended_by is None:
        # The log ends while the robot works on it: the 2015 node never finished this run.
        return Fbm1RunResult(
            status="unfinished",
            item=item,
            warnings=(f"{where}: the log ends before the run did; not counted",),
            **base,
        )
    if answer is None:
        # 2015: a timed-out run counted with no positives and pose score 0; a stopped run's
        # time was not added.
        counted_time = exec_time if run.ended_by != "stop" else 0
        return Fbm1RunResult(
            status="no_answer",
            item=item,
            class_ok=False,
            instance_ok=False,
            execution_time_ns=counted_time,
            warnings=tuple(warnings),
            **base,
        )
    # The board may settle any time after the referee was asked to place it; the stationary
    # tail before the goal decides (capped at max_window_s).
    start = run.start_ns
    try:
        gt, gt_warnings = measure_ground_truth(
            origin,
            board,
            item,
            search_start_ns=start,
            goal_ns=run.goal_ns,
            result_ns=run.result_ns,
            options=options.gt,
            t0_ns=t0_ns,
            placed_ns=run.placed_ns,
            at_ns=item_broadcast(run, options.gt.method, item_tf),
        )
    except GroundTruthError as err:
        return Fbm1RunResult(
            status="failed",
            item=item,
            answer=answer,
            error=f"{where}: {err}",
            warnings=tuple(warnings),
            **base,
        )
    warnings += [f"{where}: {w}" for w in gt_warnings]
    # the board stays while the robot looks: seen again before the result, a move is a move
    until = run.result_ns if run.result_ns is not None else run.end_ns
    validity, problem = gt_validity(origin, board, gt, options, masks, t0_ns, until)
    if problem is not None and not options.rules.score_unscoreable:
        return Fbm1RunResult(
            status="unscoreable",
            item=item,
            answer=answer,
            gt=gt,
            warnings=tuple(warnings),
            validity=validity,
            unscoreable_reason=problem,
            **base,
        )
    if problem is not None:
        warnings.append(
            f"{where}: 2015 scored this run from a ground truth that was not measured then "
            f"(--unscoreable 2015); by default it is unscoreable: {problem}"
        )
    if run.result_ns is not None:
        max_gap = round(options.gt.max_gap_s * NS_PER_S)
        moved = board_motion(origin, board, gt.board_xy, run.goal_ns, run.result_ns, max_gap)
        if moved is not None and moved > options.moved_warn_m:
            warnings.append(
                f"{where}: the board moved {moved * 1000:.0f} mm while the robot was looking"
            )
    errors = pose_errors(
        answer.x, answer.y, answer.theta_deg, gt.x, gt.y, gt.yaw_deg, options.rules
    )
    return Fbm1RunResult(
        status="scored",
        item=item,
        answer=answer,
        gt=gt,
        validity=validity,
        unscoreable_reason=problem,
        errors=errors,
        class_ok=names_match(answer.item_class, item.item_class, options.rules),
        instance_ok=names_match(answer.item_instance, item.instance, options.rules),
        execution_time_ns=exec_time,
        warnings=tuple(warnings),
        **base,
    )


def _deviations(
    runs: Sequence[Fbm1RunResult], options: Fbm1Options, bodies: Sequence[PoseStream] = ()
) -> list[Deviation]:
    """Where this result deliberately differs from the 2015 node, each with its rule."""
    out: list[Deviation] = []
    topics = [b.source.rsplit(":", 1)[-1] for b in bodies if not b.source.endswith(":/tf")]
    if topics:
        out.append(
            RULE_POSE_SOURCE.deviation(
                f"poses from {', '.join(topics)}; 2015 looked the origin and ref_board frames "
                "up in /tf"
            )
        )
    rules, gt = options.rules, options.gt
    scored = [r for r in runs if r.errors is not None]
    if gt.method != "result":
        used = {
            "window": f"the mean over the stationary window (up to {gt.max_window_s:g} s) "
            "before each goal, spread reported",
            "placed": "one lookup when the placement was confirmed (the 2016-17 node)",
            "goal": "one lookup when the goal was sent",
        }[gt.method]
        out.append(
            RULE_GT_MOMENT.deviation(
                f"ground truth = {used}; 2015 looked it up in tf when the result had arrived"
            )
        )
    if not rules.clip_above_diagonal:
        n = [
            str(r.index)
            for r in scored
            if r.errors is not None and 1.0 < r.errors.trans_error_m <= MAX_POSE_ERROR_2015
        ]
        affected = f"run(s) {', '.join(n)} affected" if n else "no run affected"
        out.append(
            RULE_TRANS_CLIP.deviation(
                "translation term clipped at 1 m; 2015 set only errors above sqrt(2) m to 1 "
                f"({affected})"
            )
        )
    if not rules.single_wrap:
        n = [
            str(r.index)
            for r in scored
            if r.answer is not None
            and r.gt is not None
            and abs(r.answer.theta_deg - r.gt.yaw_deg) > 540.0
        ]
        affected = f"run(s) {', '.join(n)} affected" if n else "no run affected"
        out.append(
            RULE_THETA_WRAP.deviation(
                f"theta errors wrapped fully to [-180, 180) deg; 2015 by a single 360 ({affected})"
            )
        )
    unscoreable = [r for r in runs if r.status == "unscoreable"]
    if unscoreable:
        out.append(
            RULE_UNSCOREABLE.deviation(
                f"run(s) {', '.join(str(r.index) for r in unscoreable)} unscoreable and left "
                "out of the totals: no valid mocap sample for their ground truth; the 2015 "
                "node scored what tf gave it"
            )
        )
    if not rules.exact_names:
        out.append(
            RULE_NAMES.deviation(
                "class and instance compared without surrounding blanks; 2015 compared exactly"
            )
        )
    if not rules.count_aborted:
        n_abort = sum(r.status == "aborted" for r in runs)
        out.append(
            RULE_ABORTED.deviation(
                "accuracies and pose score over the runs whose goal was sent; 2015 also counted "
                f"a run stopped before its goal ({n_abort} such run(s) here)"
            )
        )
    return out


def score_fbm1(
    origin: PoseStream,
    board: PoseStream,
    found: RunsFound,
    items: ItemList,
    options: Fbm1Options | None = None,
    *,
    results: ResultsFile | None = None,
    t0_ns: int = 0,
    provenance: Provenance | None = None,
    item_tf: PoseStream | None = None,
    progress: Reporter | None = None,
) -> Fbm1Result:
    """Score every run (pure: streams and configs in, frozen result out), each reported to
    ``progress`` when scored.

    A run that cannot be scored is reported in ``failures`` (one line naming the run) and left
    out of the totals; the other runs are still scored. ``item_tf``: the node's item
    broadcasts (``ref_board -> item`` on /tf), when logged: the exact lookup moments.
    """
    opts = options or Fbm1Options()
    if opts.benchmark not in BENCHMARKS:
        raise ConfigError(f"unknown FBM1 benchmark {opts.benchmark!r}; use fbm1h or fbm1w")
    if not found.runs:
        raise SegmentationError(
            f"no FBM1 run in the state log (no BmBox WAITING_MANUAL_OPERATION or goal); "
            f"is this an {opts.benchmark} log?"
        )
    if progress is not None:
        progress.task("scoring runs", len(found.runs), "runs")
    scored = []
    masks = (body_mask(origin), body_mask(board))
    for run in found.runs:
        scored.append(score_run(run, items, origin, board, opts, results, t0_ns, item_tf, masks))
        if progress is not None:
            progress.advance(1)
    runs = tuple(scored)
    counted = [r for r in runs if r.status in ("scored", "no_answer")]
    tot = totals(
        [bool(r.class_ok) for r in counted],
        [bool(r.instance_ok) for r in counted],
        [r.pose_score or 0.0 for r in counted],
        [r.execution_time_ns or 0 for r in counted],
        aborted=sum(r.status == "aborted" for r in runs),
        rules=opts.rules,
    )
    warnings = list(found.warnings)
    # A GT body whose frame_id changes mid-log mixes frames (ertools.streams).
    warnings += [w for w in (frame_change_warning(b, t0_ns or None) for b in (origin, board)) if w]
    warnings += [w for w in (impossible_warning(b, t0_ns or None) for b in (origin, board)) if w]
    if items.is_vanilla:
        warnings.append(
            f"{items.source or 'the item list'} has identity transforms only (a vanilla list): "
            "the ground truth is the board's own frame; measure the items with "
            "`ertools acquire items`"
        )
    for r in runs:
        warnings.extend(r.warnings)
    if results is not None:
        warnings.extend(_unused_results(results, runs))
    failures = [r.error for r in runs if r.error]
    failures += [
        f"run {r.index}: unscoreable: {r.unscoreable_reason}"
        for r in runs
        if r.status == "unscoreable"
    ]
    iv = fbm1_intervals(
        runs,
        found.runs,
        origin,
        board,
        gt_options=opts.gt,
        rules=opts.rules,
        pose_runs=tot.pose_runs,
        pose_total=tot.pose_score,
        settings=opts.intervals,
    )
    return Fbm1Result(
        name=opts.benchmark,
        runs=runs,
        totals=tot,
        logged_score=_parse_logged(found.logged_score),
        t0_ns=t0_ns,
        warnings=tuple(warnings),
        deviations=(*_deviations(runs, opts, (origin, board)), *found.deviations),
        failures=tuple(failures),
        provenance=provenance or Provenance(),
        reference=opts.reference,
        intervals=iv.intervals,
        uncertainty=iv.uncertainty,
    )


def _unused_results(results: ResultsFile, runs: Sequence[Fbm1RunResult]) -> list[str]:
    """Warnings for answers of the results file that no run used (a wrong run or item)."""
    run_numbers = {r.index for r in runs}
    item_ids = {r.item.id for r in runs if r.item is not None}
    out = []
    unused_runs = sorted(k for k in results.by_run if k not in run_numbers)
    if unused_runs:
        out.append(
            f"{results.source}: answer(s) for run(s) {unused_runs} not used: the log has runs "
            f"1 to {max(run_numbers)}"
        )
    unused_items = sorted(k for k in results.by_item if k not in item_ids)
    if unused_items:
        out.append(
            f"{results.source}: answer(s) for item(s) {unused_items} not used: no run "
            "presented them"
        )
    return out


def _parse_logged(payload: str | None) -> dict[str, Any] | None:
    """The 2015 node's own score payload, when it was logged and is a YAML mapping."""
    if not payload:
        return None

    try:
        data = parse_payload(payload, "BmBox TRANSMITTING_SCORE payload")
    except ConfigError:
        log.warning("the logged 2015 score payload is not YAML: %.60r", payload)
        return None
    return data if isinstance(data, dict) else None


def load(paths: Sequence[Path], options: Fbm1Options) -> Fbm1Logs:
    """The item list, the answers file and the state topics (:func:`logs.read_logs`)."""
    return read_logs(paths, options)


def find_runs(logs: Fbm1Logs, options: Fbm1Options) -> Fbm1Runs:
    """The runs from the states, then the table and board poses around them.

    Raises:
        SegmentationError: no Client states and no results file (the answers are unknown).
        TopicError: a body's poses are nowhere.
        ClockError: header-stamped poses on another clock than the state messages.
    """
    ns = options.benchmark
    plist = list(logs.paths)
    states = logs.states
    assert states.bmbox is not None
    found = runs_from_states(
        states.bmbox,
        states.refbox,
        states.client,
        benchmark=ns,
        items_order=list(options.items_order) if options.items_order is not None else None,
        t0_ns=logs.t0_ns,
        exact_2015=options.exact_end_payloads,
    )
    if states.client is None and logs.results is None:
        # Scoring every run as unanswered would be a silent wrong score.
        raise SegmentationError(
            f"no /{ns}/client_state in the log: the robot's answers are unknown; "
            "give them with --results FILE",
            path=plist[0],
        )
    if not found.runs:
        # nothing to score; a bare min() below would fail as a bug
        raise SegmentationError(
            f"/{ns}/bmbox_state: no run found (the benchmarking box sent no goal in "
            f"{len(states.bmbox.t_ns)} state messages)",
            path=plist[0],
        )
    # Read the bodies only around the runs (windowed reads touch only those chunks).
    pad = round((options.gt.max_window_s + options.gt.max_gap_s + 2.0) * NS_PER_S)
    lo = min(r.start_ns for r in found.runs) - pad
    hi = max(r.end_ns for r in found.runs) + pad
    src = options.sources
    tf_first = options.gt.method in TF_LOOKUPS
    origin = read_body(plist, src.origin, f"/{ns}/origin/pose", "origin", (lo, hi), tf_first)
    board = read_body(plist, src.board, f"/{ns}/ref_board/pose", "ref_board", (lo, hi), tf_first)

    for body, source in ((origin, src.origin), (board, src.board)):
        if source is None or source.time_source == "header":
            check_header_clock(plist, body, "state messages")
    item_tf = None
    if options.gt.method != "window":
        try:
            item_tf = read_tf(plist, "ref_board", "item", start_ns=lo, end_ns=hi)
        except TopicError:
            item_tf = None  # not logged: the state messages give the moments
    return Fbm1Runs(found, origin, board, item_tf)


def score_runs(logs: Fbm1Logs, runs: Fbm1Runs, options: Fbm1Options) -> Fbm1Result:
    """Score every run found (:func:`score_fbm1`), with the provenance of the inputs."""
    gt = options.gt
    provenance = Provenance(
        inputs=tuple(str(p) for p in logs.paths)
        + (str(options.items),)
        + ((str(options.results),) if options.results is not None else ()),
        parameters=(
            ("benchmark", options.benchmark),
            ("origin", runs.origin.source),
            ("ref_board", runs.board.source),
            ("gt_method", gt.method),
            ("max_window_s", f"{gt.max_window_s:g}"),
            ("still_m", f"{gt.still_m:g}"),
            ("still_deg", f"{gt.still_deg:g}"),
            ("max_gap_s", f"{gt.max_gap_s:g}"),
            ("reference", options.reference),
            ("node_rules", ",".join(k for k, v in vars(options.rules).items() if v) or "none"),
        ),
    )
    return score_fbm1(
        runs.origin,
        runs.board,
        runs.found,
        logs.items,
        options,
        results=logs.results,
        t0_ns=logs.t0_ns,
        provenance=provenance,
        item_tf=runs.item_tf,
        progress=current(),
    )
