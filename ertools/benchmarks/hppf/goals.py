"""HPPF's goals scored by the rules: the script's loop over the passes
(:mod:`ertools.benchmarks.hppf.runs`), the arithmetic in :mod:`ertools.benchmarks.hppf.formula`
vectorised over the goals, giving the result file's ``score`` and one record per pass.

Under ``--rules 2019`` the flow is the script's, saves included: a script that dies on an
answer leaves its last save (that goal's segment time, the previous totals). Under ertools'
reading the same events are scored with the deviations of :mod:`ertools.benchmarks.hppf.rules`.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ertools.benchmarks.hppf.config import HppfOptions
from ertools.benchmarks.hppf.formula import (
    distance_error,
    position_errors,
    position_text,
    recognized_percent,
)
from ertools.benchmarks.hppf.runs import Iteration
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.answers import is_number, parse_answer
from ertools.rsbb.py2 import to_sec

XY = tuple[float, float]


@frozen_dataclass
class Truth:
    """The cap's (x, y) in the testbed frame at the lookup after a goal, or None with the
    reason (``gap_ns``: the widest spacing of the samples used around the moment)."""

    xy: XY | None
    moment_ns: int
    gap_ns: int = 0
    reason: str | None = None


@frozen_dataclass
class Answer:
    """A goal's result string read as the BmBox read it (``yaml.load``).

    Attributes:
        text: the robot's string.
        xy: (x, y) as numbers, None when missing or no number.
        values: (x, y) as sent, None likewise.
        name: ``person_name`` when it is text, else None.
        problem: what is missing or unreadable (None: complete).
        fatal: the script died on it (a missing key of x, y, theta, person_name; a value
            the ``%.2f`` refuses; a name without ``lower()``).
    """

    text: str
    xy: XY | None
    values: tuple[Any, Any] | None
    name: str | None
    problem: str | None
    fatal: bool


def read_answer(text: str) -> Answer:
    """The answer's fields, and whether the script would have died on them (l. 186-190)."""
    data, refused = parse_answer(text)
    if refused is not None:
        return Answer(text, None, None, None, refused, True)
    missing = [k for k in ("x", "y", "theta", "person_name") if k not in data]
    bad = [k for k in ("x", "y", "theta") if k in data and not is_number(data[k])]
    name = data.get("person_name")
    problems = []
    if missing:
        problems.append("no " + ", ".join(missing))
    if bad:
        problems.append(", ".join(f"{k} {data[k]!r} is no number" for k in bad))
    if "person_name" in data and not isinstance(name, str):
        problems.append(f"person_name {name!r} is no text")
    fatal = bool(problems)
    xy_ok = all(k in data and is_number(data[k]) for k in ("x", "y"))
    xy = (float(data["x"]), float(data["y"])) if xy_ok else None
    if xy is not None and not all(math.isfinite(v) for v in xy):
        problems.append("x or y is not finite")  # the script went on with it
    return Answer(
        text,
        xy,
        (data["x"], data["y"]) if xy_ok else None,
        name if isinstance(name, str) else None,
        "; ".join(problems) or None,
        fatal,
    )


@frozen_dataclass
class PassRecord:
    """One pass of the loop as scored.

    Attributes:
        index: the goal number.
        person: the person drawn.
        status: ``detected``, ``timeout``, ``stopped`` (during the goal), ``restarted`` (no
            ground truth after the answer: the script tried again), ``not_sent`` (ended
            before its goal), ``unfinished`` (the log ends in it), ``crashed`` (the script
            died on its answer), ``unscoreable`` (ertools: no ground truth, see ``truth``).
        iteration: the pass's events.
        truth: the ground truth after the goal (None: not looked up).
        answer: the robot's answer (None: none).
        position_error: metres (None: not scored).
        recognized: the name right (None: not compared).
    """

    index: int
    person: str
    status: str
    iteration: Iteration
    truth: Truth | None = None
    answer: Answer | None = None
    position_error: float | None = None
    recognized: bool | None = None


@frozen_dataclass
class Scored:
    """The score mapping as the rules make it, the passes, and what the script would have done.

    Attributes:
        score: the result file's ``score`` (the script's last save under ``--rules``).
        passes: one record per pass.
        crashed: why the script died (``--rules``), None when it did not.
        notes: what the reader should know.
        people: N, the divisor of the percentage.
    """

    score: dict[str, Any]
    passes: tuple[PassRecord, ...]
    crashed: str | None
    notes: tuple[str, ...]
    people: int


def _same(answer: str, person: str, exact: bool) -> bool:
    if exact:
        return answer.lower() == person.lower()
    return answer.strip().lower() == person.strip().lower()


def _errors(
    its: Sequence[Iteration], truths: Sequence[Truth | None], answers: Sequence[Answer | None]
) -> list[float | None]:
    """Each pass's position error (one vectorised call over the passes that have one)."""
    rows = [
        k
        for k, (t, a) in enumerate(zip(truths, answers, strict=True))
        if t is not None and t.xy is not None and a is not None and a.xy is not None
    ]
    out: list[float | None] = [None] * len(its)
    if rows:
        ans = np.array([answers[k].xy for k in rows], dtype=np.float64)  # type: ignore[union-attr]
        tru = np.array([truths[k].xy for k in rows], dtype=np.float64)  # type: ignore[union-attr]
        for k, e in zip(rows, position_errors(ans, tru).tolist(), strict=True):
            out[k] = float(e)
    return out


def _answers(its: Sequence[Iteration]) -> list[Answer | None]:
    return [
        read_answer(it.goal.result or "")
        if it.times is not None and it.times.completed and it.goal is not None
        else None
        for it in its
    ]


def _status(it: Iteration) -> str:
    t = it.times
    if t is None:
        return "unfinished" if it.goal is not None else "not_sent"
    if t.timeout:
        return "timeout"
    if not t.completed:
        return "stopped"
    return "restarted" if it.restarted else "detected"


def run_script(
    its: Sequence[Iteration], people: int, truths: Sequence[Truth | None], options: HppfOptions
) -> Scored:
    """The score as the 2019 script left it (its last save)."""
    answers = _answers(its)
    errors = _errors(its, truths, answers)
    data: dict[str, Any] = {}
    saved: dict[str, Any] = {}
    out: list[PassRecord] = []
    notes: list[str] = []
    crashed: str | None = None
    detected = recognized = 0
    errs: list[float] = []
    unknown = False
    exec_ns = 0

    def save() -> None:
        nonlocal saved
        saved = copy.deepcopy(data)

    for k, it in enumerate(its):
        g = f"goal_{it.index}"
        data[g] = {}
        status = _status(it)
        times = it.times
        if times is None:
            out.append(PassRecord(it.index, it.person, status, it))
            break
        exec_ns += times.segment_ns
        data[g]["segment_time [s]"] = to_sec(times.segment_ns)
        save()
        data[g]["timeout"] = times.timeout
        data[g]["completed"] = times.completed
        if times.completed:
            if it.restarted:
                exec_ns -= times.segment_ns
                out.append(PassRecord(it.index, it.person, status, it, truths[k], answers[k]))
                continue
            detected += 1
            answer, truth = answers[k], truths[k]
            assert answer is not None
            if answer.fatal:
                crashed = f"goal {it.index}: {answer.problem}: the script died here"
                out.append(PassRecord(it.index, it.person, "crashed", it, truth, answer))
                break
            assert answer.name is not None and answer.values is not None
            ok = _same(answer.name, it.person, options.exact_names)
            recognized += ok
            err = errors[k]
            if err is None or truth is None or truth.xy is None:
                unknown = True
                reason = truth.reason if truth is not None else None
                notes.append(
                    f"goal {it.index}: no ground truth could be recomputed"
                    + (f" ({reason})" if reason else "")
                    + ": its position error and the Distance error are unknown"
                )
            else:
                errs.append(err)
            entry = data[g]
            entry["detected"] = True
            entry["recognized"] = ok
            entry["position_error"] = err
            entry["ground-truth person position"] = (
                None if truth is None or truth.xy is None else position_text(*truth.xy)
            )
            entry["robot-estimated person position"] = position_text(*answer.values)
            data["Recognized persons"] = recognized
            data["% Recognized persons"] = recognized_percent(recognized, people)
            total = distance_error(np.asarray(errs, np.float64), detected)
            data["Distance error"] = None if unknown else total
            out.append(PassRecord(it.index, it.person, status, it, truth, answer, err, ok))
        else:
            data[g]["detected"] = False
            out.append(PassRecord(it.index, it.person, status, it))
        data["execution_time"] = to_sec(exec_ns)
        save()
        if times.timeout is None:  # stopped during the goal
            break
    final = saved if crashed is not None else data
    return Scored(copy.deepcopy(final), tuple(out), crashed, tuple(notes), people)


def run_ertools(
    its: Sequence[Iteration], people: int, truths: Sequence[Truth | None], options: HppfOptions
) -> Scored:
    """The score by ertools' reading (docs/hppf.md, "Deviations")."""
    answers = _answers(its)
    errors = _errors(its, truths, answers)
    data: dict[str, Any] = {}
    out: list[PassRecord] = []
    notes: list[str] = []
    detected = recognized = 0
    errs: list[float] = []
    exec_ns = 0
    for k, it in enumerate(its):
        g = f"goal_{it.index}"
        status = _status(it)
        entry: dict[str, Any] = {"status": status}
        data[g] = entry
        times = it.times
        if times is None:
            out.append(PassRecord(it.index, it.person, status, it))
            continue
        exec_ns += times.segment_ns
        entry["segment_time [s]"] = to_sec(times.segment_ns)
        entry["timeout"] = times.timeout
        entry["completed"] = times.completed
        if not times.completed:
            entry["detected"] = False
            out.append(PassRecord(it.index, it.person, status, it))
            continue
        if it.restarted:
            exec_ns -= times.segment_ns
            out.append(PassRecord(it.index, it.person, status, it, truths[k], answers[k]))
            continue
        detected += 1
        answer, truth = answers[k], truths[k]
        assert answer is not None
        ok = answer.name is not None and _same(answer.name, it.person, options.exact_names)
        recognized += ok
        err = errors[k]
        if answer.xy is None or not all(math.isfinite(v) for v in answer.xy):
            err = None
        if truth is not None and truth.xy is None:
            status = entry["status"] = "unscoreable"
            entry["unscoreable_reason"] = truth.reason
        if err is not None:
            errs.append(err)
        if answer.problem is not None:
            entry["answer_problem"] = answer.problem
            notes.append(f"goal {it.index}: {answer.problem}: scored without it")
        entry["detected"] = True
        entry["recognized"] = ok
        entry["position_error"] = err
        entry["ground-truth person position"] = (
            None if truth is None or truth.xy is None else position_text(*truth.xy)
        )
        entry["robot-estimated person position"] = (
            None if answer.values is None else position_text(*answer.values)
        )
        data["Recognized persons"] = recognized
        data["% Recognized persons"] = recognized_percent(recognized, people)
        data["Distance error"] = distance_error(np.asarray(errs, np.float64), len(errs))
        out.append(PassRecord(it.index, it.person, status, it, truth, answer, err, ok))
    data["execution_time"] = to_sec(exec_ns)
    return Scored(data, tuple(out), None, tuple(notes), people)
