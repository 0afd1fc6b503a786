"""HOPF's goals scored by the rules: the script's control flow (one pass over at most ten
iterations, the arithmetic in :mod:`ertools.benchmarks.hopf.formula`, vectorised over the
goals), giving the result file's ``score`` as the rules make it and one record per goal.

Under ``--rules 2019/2017/2017-11`` the flow is the script's at that commit, saves included: a
script that dies on an answer leaves its last save (docs/hopf.md, "Quirks"). Under ertools'
reading the same events are scored with the deviations of :mod:`ertools.benchmarks.hopf.rules`.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ertools.benchmarks.hopf.config import CLIP_TRANSLATION_M, HopfOptions
from ertools.benchmarks.hopf.formula import PoseTerms, pose_terms, totals
from ertools.benchmarks.hopf.items import HopfItem, HopfItems
from ertools.benchmarks.hopf.runs import Iteration
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.answers import is_number, parse_answer
from ertools.rsbb.clock import GoalTimes, goal_times
from ertools.rsbb.py2 import to_sec

Pose2 = tuple[float, float, float]
N_GOALS = 10  # the script's N (l. 54)
NOT_EXECUTED = "not executed"  # 2017's text of a manual operation the stop cut short


@frozen_dataclass
class Truth:
    """A goal's ground truth: the item (x, y, yaw) in the table frame at ``moment_ns``, or
    None with the reason.

    Attributes:
        pose: (x, y, theta), None when there is none.
        moment_ns: the lookup's moment.
        inferred: the moment was not logged (no ``/item`` broadcast): taken when the
            placement was confirmed.
        gap_ns: the widest spacing of the samples used around the moment.
        reason: why there is no pose.
    """

    pose: Pose2 | None
    moment_ns: int | None
    inferred: bool = False
    gap_ns: int = 0
    reason: str | None = None


def script_goal(it: Iteration, stop_ns: int | None) -> GoalTimes | None:
    """The script's view of the iteration's goal (None: no goal, or the log ends first); its
    clock when it sent the goal was the removal's completion."""
    if it.goal is None:
        return None
    clock = it.remove.t_done_ns if it.remove is not None and it.remove.t_done_ns else 0
    return goal_times(it.goal, clock, stop_ns)


@frozen_dataclass
class Answer:
    """A goal's result string read as the BmBox read it (``yaml.load``).

    Attributes:
        text: the robot's string.
        data: the parsed value (None when not YAML).
        pose: (x, y, theta) as numbers, None when a field is missing or no number.
        values: (x, y, theta) as sent (an integer stays one), None likewise.
        item_class, instance: as sent, None when missing.
        problem: what is missing or unreadable (None: a complete answer).
        fatal: the problem made the script die (a missing key, a value the ``%.2f`` refuses).
    """

    text: str
    data: Any
    pose: Pose2 | None
    values: tuple[Any, Any, Any] | None
    item_class: Any
    instance: Any
    problem: str | None
    fatal: bool


def read_answer(text: str) -> Answer:
    """The answer's fields, and what the script would have made of them (l. 245-250)."""
    data, refused = parse_answer(text)
    if refused is not None:
        return Answer(text, data, None, None, None, None, refused, True)
    missing = [k for k in ("x", "y", "theta", "class", "instance") if k not in data]
    item_class, instance = data.get("class"), data.get("instance")
    raw: tuple[Any, Any, Any] = (data.get("x"), data.get("y"), data.get("theta"))
    unreadable = [
        k for k, v in zip(("x", "y", "theta"), raw, strict=True) if k in data and not is_number(v)
    ]
    problems = []
    if missing:
        problems.append("no " + ", ".join(missing))
    if unreadable:
        problems.append(", ".join(f"{k} {data[k]!r} is no number" for k in unreadable))
    pose_ok = not any(k in ("x", "y", "theta") for k in missing + unreadable)
    pose = (float(raw[0]), float(raw[1]), float(raw[2])) if pose_ok else None
    fatal = bool(missing or unreadable)
    if pose is not None and not all(math.isfinite(v) for v in pose):
        problems.append("a pose value is not finite")  # the script went on with it
    problem = "; ".join(problems) or None
    return Answer(text, data, pose, raw if pose_ok else None, item_class, instance, problem, fatal)


@frozen_dataclass
class GoalRecord:
    """One iteration as scored.

    Attributes:
        index: the script's ``i``.
        item: the item shown (None: unknown).
        status: ``scored``, ``timeout``, ``stopped`` (the stop came during the goal),
            ``not_sent`` (the iteration ended before its goal), ``unscoreable`` (no ground
            truth), ``unfinished`` (the log ends during it), ``crashed`` (the script died on
            its answer, ``--rules``).
        times: the goal's times (None: no goal).
        truth: the ground truth (None: not looked up).
        answer: the robot's answer (None: none).
        terms: its pose terms (None: not scored).
        class_ok, instance_ok: the comparisons (None: not compared).
        counted: the goal is in the totals' divisor.
    """

    index: int
    item: HopfItem | None
    status: str
    times: GoalTimes | None = None
    truth: Truth | None = None
    answer: Answer | None = None
    terms: tuple[float, float, float, float, float, float] | None = None
    class_ok: bool | None = None
    instance_ok: bool | None = None
    counted: bool = False

    @property
    def segment_ns(self) -> int | None:
        return None if self.times is None else self.times.segment_ns


@frozen_dataclass
class Scored:
    """The score mapping as the rules make it, the goals, and what the script would have done.

    Attributes:
        score: the result file's ``score`` (the script's last save under ``--rules``).
        goals: one record per iteration.
        crashed: why the script died (``--rules``), None when it did not.
        notes: what the reader should know (said on stderr).
        divisor: what the total pose score was divided by (0: no total).
    """

    score: dict[str, Any]
    goals: tuple[GoalRecord, ...]
    crashed: str | None
    notes: tuple[str, ...]
    divisor: int = 0


def _same(a: Any, b: Any, exact: bool) -> bool:
    if not exact and isinstance(a, str) and isinstance(b, str):
        return a.strip() == b.strip()
    return bool(a == b)


def _terms_of(answers: Sequence[Pose2], truths: Sequence[Pose2], options: HopfOptions) -> PoseTerms:
    clip = CLIP_TRANSLATION_M if options.clip_translation else None
    return pose_terms(
        np.asarray(answers, dtype=np.float64).reshape(-1, 3),
        np.asarray(truths, dtype=np.float64).reshape(-1, 3),
        single_wrap=options.single_wrap,
        clip=clip,
    )


def _row(terms: PoseTerms, k: int) -> tuple[float, float, float, float, float, float]:
    return (
        float(terms.x_err[k]),
        float(terms.y_err[k]),
        float(terms.w_err[k]),
        float(terms.translation[k]),
        float(terms.rotation[k]),
        float(terms.pose_score[k]),
    )


def goal_entry(rec: GoalRecord, truth_item: HopfItem, *, truth_names: bool) -> dict[str, Any]:
    """``item_acquired``, ``item_received`` and ``partial_score`` of a scored goal (l. 285-306;
    ``truth_names``: the November 2017 script recorded the item's class and instance as the
    answer's)."""
    assert rec.answer is not None and rec.truth is not None and rec.truth.pose is not None
    assert rec.terms is not None
    a = rec.answer
    values = list(a.values) if a.values is not None else [None, None, None]
    x_err, y_err, w_err, t, r, score = rec.terms
    return {
        "item_acquired": {
            "pose": list(rec.truth.pose),
            "pose_units": ["m", "m", "rad"],
            "class": truth_item.item_class,
            "instance": truth_item.instance,
        },
        "item_received": {
            "pose": values,
            "pose_units": ["m", "m", "rad"],
            "class": truth_item.item_class if truth_names else a.item_class,
            "instance": truth_item.instance if truth_names else a.instance,
        },
        "partial_score": {
            "pose_score": score,
            "pose_error_translation_score": t,
            "pose_error_translation_score_unit": "pure number",
            "pose_error_rotation_score": r,
            "pose_error_rotation_score_unit": "pure number",
            "pose_error": [x_err, y_err, w_err],
            "pose_error_units": ["m", "m", "rad"],
            "is_class_correct": rec.class_ok,
            "is_instance_correct": rec.instance_ok,
        },
    }


def _precompute(
    its: Sequence[Iteration],
    items: HopfItems,
    truths: Sequence[Truth | None],
    stop_ns: int | None,
    options: HopfOptions,
) -> list[GoalRecord]:
    """Each iteration's item, times, answer, comparisons and pose terms (every goal with an
    answer pose and a ground truth, in one vectorised call)."""
    recs: list[GoalRecord] = []
    pairs: list[tuple[int, Pose2, Pose2]] = []
    for k, it in enumerate(its):
        item = items.by_id(it.item_id) if it.item_id is not None else None
        times = script_goal(it, stop_ns)
        truth = truths[k]
        answer: Answer | None = None
        class_ok = instance_ok = None
        if times is not None and times.completed and it.goal is not None:
            answer = read_answer(it.goal.result or "")
            if item is not None:
                class_ok = answer.item_class is not None and _same(
                    answer.item_class, item.item_class, options.exact_names
                )
                instance_ok = answer.instance is not None and _same(
                    answer.instance, item.instance, options.exact_names
                )
            if answer.pose is not None and truth is not None and truth.pose is not None:
                pairs.append((k, answer.pose, truth.pose))
        recs.append(
            GoalRecord(it.index, item, "", times, truth, answer, None, class_ok, instance_ok)
        )
    if pairs:
        terms = _terms_of([p[1] for p in pairs], [p[2] for p in pairs], options)
        for n, (k, _, _) in enumerate(pairs):
            r = recs[k]
            recs[k] = GoalRecord(
                r.index,
                r.item,
                "",
                r.times,
                r.truth,
                r.answer,
                _row(terms, n),
                r.class_ok,
                r.instance_ok,
            )
    return recs


def _mo(op: Any) -> str:
    """2017's ``manual_operation_N`` value: the referee's answer, or ``not executed``."""
    if op is None or op.t_done_ns is None:
        return NOT_EXECUTED
    return str(op.answer or "")


def _with(rec: GoalRecord, status: str, counted: bool = False) -> GoalRecord:
    return GoalRecord(
        rec.index,
        rec.item,
        status,
        rec.times,
        rec.truth,
        rec.answer,
        rec.terms,
        rec.class_ok,
        rec.instance_ok,
        counted,
    )


def _status(rec: GoalRecord) -> str:
    t = rec.times
    if t is None:
        return "not_sent"
    if t.timeout:
        return "timeout"
    if not t.completed:
        return "stopped"
    if rec.truth is None or rec.truth.pose is None:
        return "unscoreable"
    return "scored"


def run_script(
    its: Sequence[Iteration],
    items: HopfItems,
    truths: Sequence[Truth | None],
    stop_ns: int | None,
    options: HopfOptions,
) -> Scored:
    """The score as the script at ``options.script`` left it (its last save)."""
    version = options.script
    assert version is not None
    late = version != "b5d91f4"
    mo_fields = version == "00e3106"
    recs = _precompute(its, items, truths, stop_ns, options)
    data: dict[str, Any] = {}
    saved: dict[str, Any] = {}
    notes: list[str] = []
    out: list[GoalRecord] = []
    crashed: str | None = None
    class_ok: list[bool] = []
    instance_ok: list[bool] = []
    scores: list[float] = []
    exec_ns = 0
    unknown_pose = False
    divisor = 0

    def save() -> None:
        nonlocal saved
        saved = copy.deepcopy(data)

    for it, rec in zip(its[:N_GOALS], recs, strict=False):
        i = it.index
        g = f"goal_{i}"
        if rec.item is None:
            raise_unknown(it, items)
        if late:
            data[g] = {}
        if mo_fields:
            data[g]["manual_operation_1"] = _mo(it.place)
            save()
        elif not late:
            data["first_manual_operation"] = _mo(it.place)
            save()
        if it.place.t_done_ns is None:
            out.append(_with(rec, "not_sent"))
            break
        cut = False
        for retry in it.retries:
            if mo_fields:
                data[g]["manual_operation_3"] = _mo(retry)
                save()
            if retry.t_done_ns is None:
                cut = True
                break
        if not cut and rec.truth is None:
            # the stop came during the lookups (or the log ends): no pose, the script returns
            # (November 2017: breaks), asking the referee in vain first
            if mo_fields and stop_ns is not None:
                data[g]["manual_operation_3"] = NOT_EXECUTED
                save()
            cut = True
        if cut:
            out.append(_with(rec, "not_sent"))
            break
        if mo_fields:
            data[g]["manual_operation_2"] = _mo(it.remove)
            save()
        elif not late:
            data["first_manual_operation"] = _mo(it.remove)
            save()
        if it.remove is None or it.remove.t_done_ns is None or rec.times is None:
            status = "unfinished" if rec.times is None and it.remove is not None else "not_sent"
            out.append(_with(rec, status))
            break
        times = rec.times
        seg = times.segment_ns
        exec_ns += seg
        if not late:
            data[g] = {}
        data[g]["timeout"] = times.timeout
        data[g]["completed"] = times.completed
        data[g]["segment_time"] = to_sec(seg)
        save()
        if times.completed:
            answer = rec.answer
            assert answer is not None
            if answer.fatal:
                crashed = f"goal {i}: {answer.problem}: the script died here"
                out.append(_with(rec, "crashed"))
                break
            class_ok.append(bool(rec.class_ok))
            instance_ok.append(bool(rec.instance_ok))
            if rec.terms is None:
                unknown_pose = True
                notes.append(
                    f"goal {i}: no ground truth could be recomputed"
                    + (f" ({rec.truth.reason})" if rec.truth and rec.truth.reason else "")
                    + ": its pose score and the total pose_score are unknown"
                )
                out.append(_with(rec, "unscoreable", True))
            else:
                scores.append(rec.terms[5])
                assert rec.item is not None
                data[g].update(goal_entry(rec, rec.item, truth_names=not late))
                save()
                out.append(_with(rec, "scored", True))
        else:
            out.append(_with(rec, _status(rec), True))
        tot = totals(
            np.asarray(class_ok, bool),
            np.asarray(instance_ok, bool),
            np.asarray(scores, np.float64),
            i,
        )
        data["class_accuracy"] = tot.class_accuracy
        data["instance_accuracy"] = tot.instance_accuracy
        data["pose_score"] = None if unknown_pose else tot.pose_score
        data["execution_time"] = to_sec(exec_ns)
        divisor = i
        save()
        if times.timeout is None:  # the stop came during the goal: the loop ends
            break
    final = saved if crashed is not None else data
    return Scored(copy.deepcopy(final), tuple(out), crashed, tuple(notes), divisor)


class UnknownItemError(Exception):
    """The log names an item the items file lacks."""


def raise_unknown(it: Iteration, items: HopfItems) -> None:
    """Raise :class:`UnknownItemError` for an iteration whose item is not in ``items``."""
    ids = ", ".join(str(i.id) for i in items.items)
    named = "an item" if it.item_id is None else f"item {it.item_id}"
    raise UnknownItemError(
        f"goal {it.index} shows {named} ({it.place.request!r}) that {items.source} lacks "
        f"(its ids: {ids}): give the items file the run used (--items)"
    )


def run_ertools(
    its: Sequence[Iteration],
    items: HopfItems,
    truths: Sequence[Truth | None],
    stop_ns: int | None,
    options: HopfOptions,
) -> Scored:
    """The score by ertools' reading (docs/hopf.md, "Deviations")."""
    recs = _precompute(its, items, truths, stop_ns, options)
    data: dict[str, Any] = {}
    notes: list[str] = []
    out: list[GoalRecord] = []
    exec_ns = 0
    for it, rec in zip(its[:N_GOALS], recs, strict=False):
        if rec.item is None:
            raise_unknown(it, items)
        g = f"goal_{it.index}"
        status = _status(rec)
        if rec.times is None and it.goal is not None:
            status = "unfinished"
        entry: dict[str, Any] = {"status": status}
        counted = status in ("scored", "timeout")
        if rec.times is not None:
            seg = rec.segment_ns or 0
            exec_ns += seg
            entry["timeout"] = rec.times.timeout
            entry["completed"] = rec.times.completed
            entry["segment_time"] = to_sec(seg)
        a = rec.answer
        if status == "scored" and a is not None:
            assert rec.item is not None and rec.truth is not None and rec.truth.pose is not None
            item = rec.item
            usable = a.pose is not None and all(math.isfinite(v) for v in a.pose)
            if rec.terms is None or not usable:  # no usable pose: the worst pose score
                rec = GoalRecord(
                    rec.index,
                    rec.item,
                    status,
                    rec.times,
                    rec.truth,
                    rec.answer,
                    _worst_terms(options),
                    rec.class_ok,
                    rec.instance_ok,
                )
            entry.update(goal_entry(rec, item, truth_names=False))
            if a.problem is not None:
                entry["answer_problem"] = a.problem
                notes.append(f"goal {it.index}: {a.problem}: that part scored as wrong")
        if status == "unscoreable" and rec.truth is not None:
            entry["unscoreable_reason"] = rec.truth.reason
        if rec.truth is not None and rec.truth.inferred and rec.truth.moment_ns is not None:
            notes.append(
                f"goal {it.index}: the lookup's /item broadcast is not in the log; the ground "
                "truth is taken when the placement was confirmed"
            )
        data[g] = entry
        out.append(_with(rec, status, counted))
    counted_recs = [r for r in out if r.counted]
    if options.stopped_goals_2019:
        counted_recs, divisor = _as_2019(out)
    else:
        divisor = len(counted_recs)
    scored = [r for r in counted_recs if r.status == "scored"]
    tot = totals(
        np.asarray([bool(r.class_ok) for r in scored], bool),
        np.asarray([bool(r.instance_ok) for r in scored], bool),
        np.asarray([r.terms[5] for r in scored if r.terms is not None], np.float64),
        divisor,
    )
    data["class_accuracy"] = tot.class_accuracy
    data["instance_accuracy"] = tot.instance_accuracy
    data["pose_score"] = tot.pose_score
    data["execution_time"] = to_sec(exec_ns)
    return Scored(data, tuple(out), None, tuple(notes), divisor)


def _worst_terms(options: HopfOptions) -> tuple[float, float, float, float, float, float]:
    """The terms of an answer without a usable pose: scored as wrong, pose score 0 (t at its
    clip, r = 1; no t without the clip)."""
    t = CLIP_TRANSLATION_M if options.clip_translation else math.nan
    return (math.nan, math.nan, math.nan, t, 1.0, 0.0)


def _as_2019(recs: Sequence[GoalRecord]) -> tuple[list[GoalRecord], int]:
    """The script's divisor (``--stopped-goals 2019``): the goals begun up to the last that
    reached its totals; the unscoreable ones left out."""
    last = 0
    for r in recs:
        if r.status in ("scored", "timeout", "stopped", "unscoreable"):
            last = r.index
    begun = [r for r in recs if r.index <= last]
    counted = [r for r in begun if r.status in ("scored", "timeout", "stopped")]
    return [r for r in counted if r.status == "scored"], len(counted)
