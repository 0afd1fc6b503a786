"""HPPF's stages: the run bag and its side files loaded, the script's loop walked over the
events, the goals scored by the rules (:func:`load`, :func:`find_runs`, :func:`score_runs`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ertools.benchmarks.base import notice
from ertools.benchmarks.hppf import rules
from ertools.benchmarks.hppf.config import CODE, SCRIPT_FRAMES, SCRIPT_TEXT, HppfOptions
from ertools.benchmarks.hppf.goals import Scored, Truth, run_ertools, run_script
from ertools.benchmarks.hppf.intervals import hppf_intervals
from ertools.benchmarks.hppf.result import HppfResult
from ertools.benchmarks.hppf.runs import FlowError, HppfRuns, entered, walk
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

FRAME = SCRIPT_FRAMES[0]  # /person under /actor_markerset, in /testbed_origin
ACTOR = FRAME.parent.lstrip("/")
IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
#: The keys ertools' reading adds to a goal (the script never wrote them).
EXTRA_GOAL_KEYS = ("status", "answer_problem", "unscoreable_reason")


@frozen_dataclass
class HppfLogs:
    """An HPPF run's bag and side files, read.

    Attributes:
        bags: the run bag (or its split files).
        run: its RefBox/BmBox events and live scores.
        tracks: its ``/tf`` links and the script's broadcasts.
        people: the config's people, in order (N = their number).
        people_source: where they came from.
        result_file: the run's result file, None when none was given or found.
        side: where the side files came from.
        origin_ns: the bag's first message.
    """

    bags: tuple[Path, ...]
    run: RsbbRun
    tracks: TfTracks
    people: tuple[str, ...]
    people_source: str
    result_file: RsbbResult | None
    side: SideFiles
    origin_ns: int


def _people_of(params: Any, where: str) -> tuple[str, ...]:
    people = params.get("people") if isinstance(params, dict) else None
    if not isinstance(people, list) or not all(isinstance(p, str) for p in people):
        raise ConfigError(f"{where}: expected 'people', a list of names")
    return tuple(people)


def _people(
    side: SideFiles, run: RsbbRun, result: RsbbResult | None
) -> tuple[tuple[str, ...], str]:
    """The people the script started with: the config given or found, else the first live
    score's copy (saved before ``execute()`` began), else the result file's, which the script
    emptied as it drew (its ``params`` is the config object it removed people from): the
    people left there and those the log shows drawn."""
    if side.config is not None:
        return _people_of(read_side_yaml(side.config, "HPPF config"), str(side.config)), str(
            side.config
        )
    for message in run.live:
        info = message.result.get("benchmark_info") if message.result is not None else None
        if isinstance(info, dict) and isinstance(info.get("params"), dict):
            return _people_of(info["params"], "the live score's params"), "the first live score"
    if result is None or not isinstance(result.params, dict):
        raise ConfigError(
            "HPPF needs its people (HPPF.yaml): give --config FILE, or put it beside the bag or "
            "in the RSBB layout (rsbb_bmbox/scripts/benchmark_configs/)"
        )
    left = list(_people_of(result.params, result.path))
    drawn = [p for p in (entered(m.request) for m in run.manual_operations) if p is not None]
    for p in drawn:
        if p not in left:
            left.append(p)
    return tuple(left), f"{result.path} (the people left) and the log's draws"


def load(bags: Sequence[Path], options: HppfOptions) -> HppfLogs:
    """The run bag's events and ``/tf``, the people and the result file.

    Raises:
        ConfigError: a side file missing or unreadable, or another benchmark's.
        TopicError, BagError: not an RSBB run bag.
    """
    opened = open_run(bags, CODE, options, want=("config", "result"), say=notice)
    paths, side, result_file, run = opened.paths, opened.side, opened.result_file, opened.run
    people, source = _people(side, run, result_file)
    tracks = read_tf_tracks(paths)
    origin = min(summary(p).start_ns for p in paths)
    return HppfLogs(paths, run, tracks, people, source, result_file, side, origin)


def _actor(tracks: TfTracks) -> TfTrack | None:
    key = next((k for k in tracks.links if k[1] == ACTOR), None)
    return None if key is None else tracks.links[key]


def find_runs(logs: HppfLogs, options: HppfOptions) -> HppfRuns:
    """The script's passes over the run's events.

    Raises:
        ConfigError: the log draws someone the config lacks.
    """
    del options
    try:
        return walk(logs.run, logs.people, logs.tracks.broadcasts(FRAME), _actor(logs.tracks))
    except FlowError as err:
        raise ConfigError(str(err)) from None


def ground_truths(
    logs: HppfLogs, runs: HppfRuns, options: HppfOptions
) -> tuple[list[Truth | None], list[str]]:
    """The cap's (x, y) at each ground-truth lookup, as tf gave it to the script
    (``--gt-gaps refuse``: none across a tracking gap wider than ``--max-gap``)."""
    actor = _actor(logs.tracks)
    moments = [it.truth_ns for it in runs.iterations]
    out: list[Truth | None] = [None] * len(moments)
    validity: list[str] = []
    rows = [k for k, t in enumerate(moments) if t is not None]
    if not rows:
        return out, validity
    t_ns = np.array([moments[k] for k in rows], np.int64)
    if actor is None:
        for k in rows:
            out[k] = Truth(None, int(t_ns[0]), 0, f"/tf has no {ACTOR}")
        return out, validity
    at = script_poses(actor, t_ns, IDENTITY)
    max_gap = round(options.max_gap_s * 1e9)
    for n, k in enumerate(rows):
        it = runs.iterations[k]
        moment, gap = int(t_ns[n]), int(at.gap_ns[n])
        if not bool(at.inside[n]):
            reason = "no mocap sample of the cap on both sides of the moment"
            out[k] = Truth(None, moment, gap, reason)
            validity.append(f"validity: goal {it.index}: {reason}")
            continue
        if gap > max_gap:
            line = (
                f"validity: goal {it.index}: the cap was untracked for {gap / 1e9:.3f} s "
                "around the lookup"
            )
            if options.gt_gaps == "refuse":
                reason = (
                    f"a tracking gap of {gap / 1e9:.3f} s around the lookup (more than "
                    f"--max-gap {options.max_gap_s:g} s): tf interpolated across it"
                )
                out[k] = Truth(None, moment, gap, reason)
                validity.append(line + "; no ground truth")
                continue
            validity.append(line + "; interpolated across it, as tf did")
        out[k] = Truth((float(at.x[n]), float(at.y[n])), moment, gap)
    return out, validity


def _deviations(scored: Scored, options: HppfOptions) -> list[Deviation]:
    """Where ertools' reading changed this run's numbers from the 2019 script's."""
    if options.script is not None:
        return []
    out: list[Deviation] = []
    fatal = [p.index for p in scored.passes if p.answer is not None and p.answer.fatal]
    if fatal:
        out.append(
            rules.RULE_ANSWER_FIELDS.deviation(
                f"goal(s) {_list(fatal)}: scored without the missing or unreadable field where "
                "the script died (--rules 2019 gives its last save)"
            )
        )
    if not options.exact_names:
        blanks = [
            p.index
            for p in scored.passes
            if p.answer is not None
            and p.answer.name is not None
            and p.answer.name.lower() != p.person.lower()
            and p.answer.name.strip().lower() == p.person.strip().lower()
        ]
        if blanks:
            out.append(
                rules.RULE_NAMES.deviation(f"goal(s) {_list(blanks)}: names equal without blanks")
            )
    if options.gt_gaps == "refuse":
        gaps = [
            p.index
            for p in scored.passes
            if p.truth is not None and p.truth.reason is not None and "gap" in p.truth.reason
        ]
        if gaps:
            out.append(
                rules.RULE_GT_GAPS.deviation(
                    f"goal(s) {_list(gaps)} without ground truth across a tracking gap"
                )
            )
    return out


def _list(ks: Sequence[int]) -> str:
    return ", ".join(str(k) for k in ks)


def script_fields(score: dict[str, Any]) -> dict[str, Any]:
    """The score without the keys ertools adds, for the comparison with the script's."""
    return {
        k: {kk: vv for kk, vv in v.items() if kk not in EXTRA_GOAL_KEYS}
        if isinstance(v, dict)
        else v
        for k, v in score.items()
    }


def _team(logs: HppfLogs) -> tuple[str | None, str | None]:
    """The team: the RSBB layout's folder (``rsbb_logs/<CODE>/<team>/``), else the result
    file's ``benchmark_info.team``."""
    if logs.side.place.team is not None:
        return logs.side.place.team, "RSBB layout"
    if logs.result_file is not None:
        return logs.result_file.team, "result file"
    return None, None


def score_runs(logs: HppfLogs, runs: HppfRuns, options: HppfOptions) -> HppfResult:
    """The goals scored by the rules, compared with the run's live score and result file."""
    truths, validity = ground_truths(logs, runs, options)
    n = len(logs.people)
    if options.script is not None:
        scored = run_script(runs.iterations, n, truths, options)
    else:
        scored = run_ertools(runs.iterations, n, truths, options)
    failures = [
        f"goal {p.index}: no ground truth"
        + (f" ({p.truth.reason})" if p.truth is not None and p.truth.reason else "")
        for p in scored.passes
        if p.status == "unscoreable"
        or (options.script is not None and p.truth is not None and p.truth.xy is None)
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
    restarted = [p.index for p in scored.passes if p.status == "restarted"]
    if restarted:
        notes.append(
            f"goal(s) {_list(restarted)} restarted by the script: no ground truth after the "
            "answer (the next pass drew again)"
        )
    warnings = list(runs.problems)
    if logs.people_source.endswith("draws"):
        warnings.append(
            f"the people ({n}) from {logs.people_source}: give HPPF.yaml (--config) to be sure"
        )
    if logs.run.t_start_ns is None:
        warnings.append("the benchmark was never started in this log")
    return HppfResult(
        score=scored.score,
        passes=scored.passes,
        people=logs.people,
        rules=options.rules,
        crashed=scored.crashed,
        comparison=comparison,
        intervals=hppf_intervals(_actor(logs.tracks), scored, options),
        origin_ns=logs.origin_ns,
        end=logs.run.end_kind.value,
        notes=tuple(notes),
        warnings=tuple(warnings),
        deviations=tuple(_deviations(scored, options)),
        failures=tuple(failures),
        provenance=Provenance(
            team=_team(logs)[0],
            team_source=_team(logs)[1],
            inputs=tuple(str(p) for p in logs.bags)
            + tuple(str(p) for p in (logs.side.config, logs.side.result) if p),
            parameters=(
                ("rules", options.rules),
                ("people", logs.people_source),
                ("max_gap_s", str(options.max_gap_s)),
                ("gt_gaps", options.gt_gaps),
            ),
        ),
    )
