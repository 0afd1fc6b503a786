"""HOPF's stages: the run bag and its side files loaded, the script's iterations found, the
goals scored by the rules (:func:`load`, :func:`find_runs`, :func:`score_runs`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ertools.benchmarks.base import notice
from ertools.benchmarks.hopf import rules
from ertools.benchmarks.hopf.config import (
    CLIP_TRANSLATION_M,
    CODE,
    SCRIPT_FRAMES,
    SCRIPT_TEXT,
    HopfOptions,
)
from ertools.benchmarks.hopf.goals import (
    GoalRecord,
    Scored,
    Truth,
    UnknownItemError,
    run_ertools,
    run_script,
)
from ertools.benchmarks.hopf.intervals import hopf_intervals
from ertools.benchmarks.hopf.items import HopfItems, load_items, parse_items, place_text
from ertools.benchmarks.hopf.result import HopfResult
from ertools.benchmarks.hopf.runs import HopfRuns, Iteration, find_iterations
from ertools.errors import ConfigError
from ertools.fidelity import Deviation
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.summary import summary
from ertools.rsbb.log import RsbbRun
from ertools.rsbb.opened import open_run
from ertools.rsbb.results import RsbbResult
from ertools.rsbb.score import compare_scores
from ertools.rsbb.sidefiles import SideFiles, read_side_yaml
from ertools.rsbb.tf import TfTrack, TfTracks, read_tf_tracks, script_poses
from ertools.streams import Provenance

FRAME = SCRIPT_FRAMES[0]  # /item under /positioner_origin, looked up in /table_origin
POSITIONER = FRAME.parent.lstrip("/")
TABLE = FRAME.reference.lstrip("/")


@frozen_dataclass
class HopfLogs:
    """A HOPF run's bag and side files, read.

    Attributes:
        bags: the run bag (or its split files).
        run: its RefBox/BmBox events and live scores.
        tracks: its ``/tf`` links and the script's broadcasts.
        items: the items the script drew from.
        params: the benchmark config (``HOPF.yaml``; the result file's copy), None if neither.
        result_file: the run's result file, None when none was given or found.
        side: where the side files came from.
        origin_ns: the bag's first message.
    """

    bags: tuple[Path, ...]
    run: RsbbRun
    tracks: TfTracks
    items: HopfItems
    params: Any
    result_file: RsbbResult | None
    side: SideFiles
    origin_ns: int


def _items(side: SideFiles, params: Any, options: HopfOptions) -> HopfItems:
    if options.script == "b5d91f4":  # November 2017: the items were the config's
        if isinstance(params, dict) and "items" in params:
            where = str(side.config) if side.config is not None else "the result file's params"
            return parse_items(params, where)
        if side.items is None:
            raise ConfigError(
                "--rules 2017-11 reads the items from HOPF.yaml's 'items' (November 2017): "
                "give --config HOPF.yaml, or --items FILE"
            )
    if side.items is None:
        raise ConfigError(
            "HOPF needs the items the script drew from (items_with_pose.yaml): give --items "
            "FILE, or put it beside the bag or in the RSBB layout (rsbb_etc/objects_informations/)"
        )
    return load_items(side.items)


def script_params(side: SideFiles, run: RsbbRun, result_file: RsbbResult | None) -> Any:
    """The benchmark config the script started with: the file given or found, else the first
    live score's copy (saved before ``execute()`` began), else the result file's (which holds
    the config as the script left it: November 2017 removed the items it drew)."""
    if side.config is not None:
        return read_side_yaml(side.config, f"{CODE} config")
    for message in run.live:
        info = message.result.get("benchmark_info") if message.result is not None else None
        if isinstance(info, dict) and info.get("params") not in (None, "None"):
            return info["params"]
    return None if result_file is None else result_file.params


def load(bags: Sequence[Path], options: HopfOptions) -> HopfLogs:
    """The run bag's events and ``/tf``, the items, the config and the result file.

    Raises:
        ConfigError: a side file missing or unreadable, or another benchmark's result file.
        TopicError, BagError: not an RSBB run bag.
    """
    opened = open_run(bags, CODE, options, want=("config", "items", "result"), say=notice)
    paths, side, result_file, run = opened.paths, opened.side, opened.result_file, opened.run
    params = script_params(side, run, result_file)
    items = _items(side, params, options)
    tracks = read_tf_tracks(paths)
    origin = min(summary(p).start_ns for p in paths)
    return HopfLogs(paths, run, tracks, items, params, result_file, side, origin)


def find_runs(logs: HopfLogs, options: HopfOptions) -> HopfRuns:
    """The script's iterations: each item shown, its lookup and its goal."""
    del options
    return find_iterations(logs.run, logs.tracks.broadcasts(FRAME))


def _body(tracks: TfTracks, name: str) -> TfTrack | None:
    key = next((k for k in tracks.links if k[1] == name), None)
    return None if key is None else tracks.links[key]


def _moment(it: Iteration) -> tuple[int | None, bool]:
    """The lookup's moment and whether it was inferred (a successful lookup whose broadcast
    the log lacks: the placement's confirmation)."""
    if it.lookup_ns is not None:
        return it.lookup_ns, False
    if it.remove is not None and it.placed_ns is not None:
        return it.placed_ns, True
    return None, False


def ground_truths(
    logs: HopfLogs, runs: HopfRuns, options: HopfOptions
) -> tuple[list[Truth | None], list[str]]:
    """Each iteration's ground truth at its lookup's moment, as tf gave it to the script
    (``--gt-gaps refuse``: none across a tracking gap wider than ``--max-gap``)."""
    table, positioner = _body(logs.tracks, TABLE), _body(logs.tracks, POSITIONER)
    out: list[Truth | None] = []
    validity: list[str] = []
    max_gap = round(options.max_gap_s * 1e9)
    for it in runs.iterations:
        moment, inferred = _moment(it)
        item = logs.items.by_id(it.item_id) if it.item_id is not None else None
        if moment is None or item is None:
            out.append(None)
            continue
        if table is None or positioner is None:
            missing = TABLE if table is None else POSITIONER
            out.append(Truth(None, moment, inferred, 0, f"/tf has no {missing}"))
            continue
        at = script_poses(positioner, np.array([moment], np.int64), (item.trans, item.rot), table)
        gap = int(at.gap_ns[0])
        if not bool(at.inside[0]):
            reason = "no mocap sample of the table or the positioner on both sides of the moment"
            out.append(Truth(None, moment, inferred, gap, reason))
            validity.append(f"validity: goal {it.index}: {reason}")
            continue
        pose = (float(at.x[0]), float(at.y[0]), float(at.theta[0]))
        if gap > max_gap:
            line = (
                f"validity: goal {it.index}: the table or the positioner was untracked for "
                f"{gap / 1e9:.3f} s around the lookup"
            )
            if options.gt_gaps == "refuse":
                reason = (
                    f"a tracking gap of {gap / 1e9:.3f} s around the lookup (more than "
                    f"--max-gap {options.max_gap_s:g} s): tf interpolated across it"
                )
                out.append(Truth(None, moment, inferred, gap, reason))
                validity.append(line + "; no ground truth")
                continue
            validity.append(line + "; interpolated across it, as tf did")
        out.append(Truth(pose, moment, inferred, gap))
    return out, validity


def _deviations(
    scored: Scored, truths: Sequence[Truth | None], options: HopfOptions
) -> list[Deviation]:
    """Where ertools' reading changed this run's numbers from the 2019 script's."""
    if options.script is not None:
        return []
    out: list[Deviation] = []
    goals = scored.goals
    clipped = [
        g.index
        for g in goals
        if g.terms is not None and float(np.hypot(g.terms[0], g.terms[1])) > CLIP_TRANSLATION_M
    ]
    if clipped and options.clip_translation:
        out.append(
            rules.RULE_TRANSLATION_CLIP.deviation(
                f"the translation term of goal(s) {_list(clipped)} clipped at 1 m"
            )
        )
    if not options.single_wrap:
        wrapped = [
            g.index
            for g in goals
            if g.answer is not None
            and g.answer.pose is not None
            and g.truth is not None
            and g.truth.pose is not None
            and abs(_single(g.answer.pose[2] - g.truth.pose[2])) > np.pi
        ]
        if wrapped:
            out.append(
                rules.RULE_THETA_WRAP.deviation(
                    f"the theta error of goal(s) {_list(wrapped)} wrapped fully"
                )
            )
    if not options.exact_names:
        blanks = [
            g.index
            for g in goals
            if g.answer is not None
            and g.item is not None
            and any(
                isinstance(a, str) and isinstance(b, str) and a != b and a.strip() == b.strip()
                for a, b in (
                    (g.answer.item_class, g.item.item_class),
                    (g.answer.instance, g.item.instance),
                )
            )
        ]
        if blanks:
            out.append(
                rules.RULE_NAMES.deviation(
                    f"goal(s) {_list(blanks)}: names equal without their blanks"
                )
            )
    if not options.stopped_goals_2019:
        cut = [g.index for g in goals if g.status in ("stopped", "not_sent")]
        if cut:
            out.append(
                rules.RULE_STOPPED_GOAL.deviation(
                    f"goal(s) {_list(cut)} cut short by the stop, not counted in the totals"
                )
            )
    fatal = [g.index for g in goals if g.answer is not None and g.answer.fatal]
    if fatal:
        out.append(
            rules.RULE_ANSWER_FIELDS.deviation(
                f"goal(s) {_list(fatal)}: an incomplete answer scored as wrong where the "
                "script died (--rules 2019 gives its last save)"
            )
        )
    if options.gt_gaps == "refuse":
        gaps = [
            g.index
            for g in goals
            if g.status == "unscoreable"
            and g.truth is not None
            and g.truth.reason
            and "gap" in g.truth.reason
        ]
        if gaps:
            out.append(
                rules.RULE_GT_GAPS.deviation(
                    f"goal(s) {_list(gaps)} without ground truth across a tracking gap"
                )
            )
    return out


def _single(w: float) -> float:
    if w > np.pi:
        w -= 2 * np.pi
    if w < -np.pi:
        w += 2 * np.pi
    return w


def _list(ks: Sequence[int]) -> str:
    return ", ".join(str(k) for k in ks)


def _warnings(logs: HopfLogs, runs: HopfRuns, scored: Scored) -> list[str]:
    out = list(runs.problems)
    for it in runs.iterations:
        item = logs.items.by_id(it.item_id) if it.item_id is not None else None
        if item is not None and place_text(item) != it.place.request:
            out.append(
                f"goal {it.index}: the placement request {it.place.request!r} does not name "
                f"item {item.id} as {logs.items.source} describes it: another items file?"
            )
    for g in scored.goals:
        if g.status == "unfinished":
            out.append(f"goal {g.index}: the log ends during it")
    if logs.run.t_start_ns is None:
        out.append("the benchmark was never started in this log")
    return out


def _team(logs: HopfLogs) -> tuple[str | None, str | None]:
    """The team: the RSBB layout's folder (``rsbb_logs/<CODE>/<team>/``), else the result
    file's ``benchmark_info.team``."""
    if logs.side.place.team is not None:
        return logs.side.place.team, "RSBB layout"
    if logs.result_file is not None:
        return logs.result_file.team, "result file"
    return None, None


def score_runs(logs: HopfLogs, runs: HopfRuns, options: HopfOptions) -> HopfResult:
    """The goals scored by the rules, compared with the run's live score and result file."""
    truths, validity = ground_truths(logs, runs, options)
    stop = logs.run.t_end_ns if logs.run.end_kind.value in ("stop", "global_timeout") else None
    try:
        if options.script is not None:
            scored = run_script(runs.iterations, logs.items, truths, stop, options)
        else:
            scored = run_ertools(runs.iterations, logs.items, truths, stop, options)
    except UnknownItemError as err:
        raise ConfigError(str(err)) from None
    failures = [
        f"goal {g.index}: no ground truth"
        + (f" ({g.truth.reason})" if g.truth is not None and g.truth.reason else "")
        for g in scored.goals
        if g.status == "unscoreable"
    ]
    comparison = None
    if logs.run.live or logs.result_file is not None:
        comparison = compare_scores(script_fields(scored.score), logs.run.live, logs.result_file)
    notes = list(validity)
    if options.script is not None:
        notes.append(f"reproducing: {SCRIPT_TEXT[options.rules]}")
    if scored.crashed is not None:
        notes.append(f"the script died on this run: {scored.crashed}; its last save is the score")
    notes += list(scored.notes)
    intervals = hopf_intervals(
        (_body(logs.tracks, TABLE), _body(logs.tracks, POSITIONER)), scored, options
    )
    return HopfResult(
        score=scored.score,
        goals=scored.goals,
        rules=options.rules,
        crashed=scored.crashed,
        comparison=comparison,
        intervals=intervals,
        origin_ns=logs.origin_ns,
        end=logs.run.end_kind.value,
        notes=tuple(notes),
        warnings=tuple(_warnings(logs, runs, scored)),
        deviations=tuple(_deviations(scored, truths, options)),
        failures=tuple(failures),
        provenance=Provenance(
            team=_team(logs)[0],
            team_source=_team(logs)[1],
            inputs=tuple(str(p) for p in logs.bags)
            + tuple(str(p) for p in (logs.side.items, logs.side.config, logs.side.result) if p),
            parameters=(
                ("rules", options.rules),
                ("items", logs.items.source),
                ("max_gap_s", str(options.max_gap_s)),
                ("gt_gaps", options.gt_gaps),
            ),
        ),
    )


#: The keys ertools' reading adds to a goal (the script never wrote them).
EXTRA_GOAL_KEYS = ("status", "answer_problem", "unscoreable_reason")


def script_fields(score: dict[str, Any]) -> dict[str, Any]:
    """The score without the keys ertools adds, for the comparison with the script's."""
    return {
        k: {kk: vv for kk, vv in v.items() if kk not in EXTRA_GOAL_KEYS}
        if isinstance(v, dict)
        else v
        for k, v in score.items()
    }


def scored_goals(result: HopfResult) -> tuple[GoalRecord, ...]:
    """The goals with a pose score (for the figures)."""
    return tuple(g for g in result.goals if g.terms is not None)
