"""The frozen data of an audit: what happened in a benchmark execution, and how its live score
compares with the recomputed one.

:mod:`ertools.auditing.analyse` builds an :class:`Audit` from the state topics,
:mod:`ertools.auditing.compare` builds a :class:`ScoreComparison`, :mod:`ertools.auditing.recompute`
recomputes the score. This module holds the types they share and their output (JSON, YAML, CSV
tables, text), so that none of them needs another to describe its result.
"""

from __future__ import annotations

from dataclasses import field
from typing import TYPE_CHECKING, Any

from ertools.benchmarks.base import Rows
from ertools.fidelity import Deviation
from ertools.frames import tables_to_frames
from ertools.frozen_dataclass import frozen_dataclass
from ertools.serialize import dump_yaml, jsonable
from ertools.states import Machine
from ertools.streams import Provenance
from ertools.timeutil import iso_utc, ns_to_s

if TYPE_CHECKING:
    import pandas as pd

    from ertools.benchmarks.base import BenchmarkResult


@frozen_dataclass
class TimelineEntry:
    """One state (or payload) of one machine, from its first message to the next change."""

    machine: Machine
    state: int
    state_name: str
    start_ns: int
    end_ns: int
    payload: str
    kind: str  # "manual_operation", "goal", "result", "score", "end_reason", "payload" or ""

    @property
    def duration_ns(self) -> int:
        return self.end_ns - self.start_ns


@frozen_dataclass
class IllegalTransition:
    """A BmBox transition not in :data:`ertools.states.BMBOX_TRANSITIONS`."""

    t_ns: int
    from_state: str
    to_state: str
    allowed: tuple[str, ...]


@frozen_dataclass
class Silence:
    """A gap in a state topic's heartbeat longer than the threshold."""

    machine: Machine
    topic: str
    start_ns: int  # the last message before the gap
    end_ns: int  # the first message after it (the end of the log when ``trailing``)
    state_name: str  # the state published before the gap
    trailing: bool = False  # the topic stopped before the log ended, not in END

    @property
    def duration_ns(self) -> int:
        return self.end_ns - self.start_ns


@frozen_dataclass
class EarlyEnd:
    """The RefBox ended the benchmark (seed 6.4: payload ``timeout`` or ``halt``)."""

    t_ns: int
    reason: str  # "timeout" or "halt" (ertools.states.end_reason: a timeout or a stop)
    payload: str
    run: int | None  # the run it interrupted, None between runs
    bmbox_state: str  # the BmBox state at that moment


@frozen_dataclass
class AuditRun:
    """One run (FBM1, FBM3) or segment (FBM2) as the BmBox went through it."""

    index: int
    start_ns: int
    end_ns: int
    outcome: str  # "completed", "timeout", "halt", "cancelled", "aborted", "unfinished"
    states: tuple[str, ...]
    manual_operation: str = ""
    goal: str = ""
    result: str = ""
    result_ns: int | None = None
    executing_ns: int | None = None  # when the BmBox entered EXECUTING_GOAL

    @property
    def duration_ns(self) -> int:
        return self.end_ns - self.start_ns


@frozen_dataclass(eq=False)
class Audit:
    """The audit of one benchmark execution. Implements the BenchmarkResult protocol.

    Attributes:
        benchmark: the namespace (``fbm2h``...) or "" when unknown.
        timeline: every change of every machine, time-ordered.
        illegal_transitions: BmBox transitions 2015 did not allow.
        silences: heartbeat gaps longer than ``max_silence_ns``.
        early_ends: RefBox END with a reason.
        runs: the runs/segments the BmBox went through.
        live_score: the score sent live, parsed (None when not sent or unparsable).
        live_score_text: the raw TRANSMITTING_SCORE payload.
        recomputed: the score recomputed from the same bag (see ``ertools.auditing.recompute``).
        comparison: live vs recomputed, key by key.
    """

    benchmark: str
    timeline: tuple[TimelineEntry, ...]
    transitions_checked: int
    illegal_transitions: tuple[IllegalTransition, ...]
    silences: tuple[Silence, ...]
    early_ends: tuple[EarlyEnd, ...]
    runs: tuple[AuditRun, ...]
    live_score: Any
    live_score_text: str | None
    max_silence_ns: int
    start_ns: int
    end_ns: int
    topics: tuple[tuple[str, str, int], ...]  # (machine, topic, message count)
    warnings: tuple[str, ...] = ()
    deviations: tuple[Deviation, ...] = ()
    failures: tuple[str, ...] = ()
    provenance: Provenance = field(default_factory=Provenance)
    recomputed: BenchmarkResult | None = None
    comparison: ScoreComparison | None = None
    name: str = "audit"

    @property
    def findings(self) -> int:
        """How many things a referee must look at (illegal transitions, silences, early ends)."""
        n = len(self.illegal_transitions) + len(self.silences) + len(self.early_ends)
        if self.comparison is not None:
            n += len(self.comparison.differences)
        return n

    def _rel(self, t_ns: int) -> float:
        return round(ns_to_s(t_ns - self.start_ns), 3)

    def _silence(self, s: Silence, *, epoch: bool) -> dict[str, Any]:
        """A silence's row; ``epoch`` adds its epoch start (``from_time``) for the tables."""
        row: dict[str, Any] = {"machine": s.machine.value, "topic": s.topic}
        if epoch:
            row["from_time"] = ns_to_s(s.start_ns)
        row["from"] = self._rel(s.start_ns)
        row["to"] = self._rel(s.end_ns)
        row["duration"] = ns_to_s(s.duration_ns)
        row["state"] = s.state_name
        row["until_log_end"] = s.trailing
        return row

    def _early_end(self, e: EarlyEnd, *, table: bool) -> dict[str, Any]:
        """An early end's row: the table's leads with its epoch time and leaves out the
        payload (its reason says it)."""
        row: dict[str, Any] = {"time": ns_to_s(e.t_ns)} if table else {}
        row["t"] = self._rel(e.t_ns)
        row["reason"] = e.reason
        if not table:
            row["payload"] = e.payload
        row["run"] = e.run
        row["bmbox_state"] = e.bmbox_state
        return row

    def to_dict(self) -> dict[str, Any]:
        """JSON-able: times as seconds from the first state message, plus epoch start."""
        out: dict[str, Any] = {
            "benchmark": self.benchmark,
            "start": ns_to_s(self.start_ns),
            "start_iso": iso_utc(self.start_ns),
            "duration": ns_to_s(self.end_ns - self.start_ns),
            "max_silence": ns_to_s(self.max_silence_ns),
            "topics": [{"machine": m, "topic": t, "messages": n} for m, t, n in self.topics],
            "transitions_checked": self.transitions_checked,
            "illegal_transitions": [
                {
                    "t": self._rel(x.t_ns),
                    "from": x.from_state,
                    "to": x.to_state,
                    "allowed": list(x.allowed),
                }
                for x in self.illegal_transitions
            ],
            "silences": [self._silence(s, epoch=False) for s in self.silences],
            "early_ends": [self._early_end(e, table=False) for e in self.early_ends],
            "runs": {str(r.index): self._run_dict(r) for r in self.runs},
            "live_score": jsonable(self.live_score),
            "timeline": [self._entry_dict(e) for e in self.timeline],
            "warnings": list(self.warnings),
        }
        if self.comparison is not None:
            out["score_comparison"] = self.comparison.to_dict()
        if self.recomputed is not None:
            out["recomputed"] = {"benchmark": self.recomputed.name, **self.recomputed.to_dict()}
        return out

    def _run_dict(self, r: AuditRun) -> dict[str, Any]:
        return {
            "start": self._rel(r.start_ns),
            "end": self._rel(r.end_ns),
            "duration": ns_to_s(r.duration_ns),
            "outcome": r.outcome,
            "states": list(r.states),
            "manual_operation": r.manual_operation,
            "goal": r.goal,
            "result": r.result,
        }

    def _entry_dict(self, e: TimelineEntry) -> dict[str, Any]:
        return {
            "machine": e.machine.value,
            "state": e.state_name,
            "start": self._rel(e.start_ns),
            "duration": ns_to_s(e.duration_ns),
            "kind": e.kind,
            "payload": e.payload,
        }

    def to_yaml(self) -> str:
        return dump_yaml(jsonable(self.to_dict()))

    def to_text(self) -> str:
        """A referee's reading: findings first, then runs, the score comparison, the timeline."""
        lines = [
            f"audit of {self.benchmark or '(unknown benchmark)'}: "
            + (
                f"{iso_utc(self.start_ns)}, {ns_to_s(self.end_ns - self.start_ns):.1f} s"
                if self.timeline
                else "no state messages"
            ),
            "  topics: " + ", ".join(f"{t} ({n})" for _, t, n in self.topics),
            f"  BmBox transitions checked: {self.transitions_checked}, illegal: "
            f"{len(self.illegal_transitions)}",
            f"  silences > {ns_to_s(self.max_silence_ns):g} s: {len(self.silences)}",
            "  ended by the RefBox: "
            + (
                ", ".join(f"{e.reason} at {self._rel(e.t_ns):.1f} s" for e in self.early_ends)
                or "no"
            ),
        ]
        for x in self.illegal_transitions:
            lines.append(f"  ILLEGAL {self._rel(x.t_ns):9.3f} s  {x.from_state} -> {x.to_state}")
        for g in self.silences:
            lines.append(
                f"  SILENCE {self._rel(g.start_ns):9.3f} s  {g.topic or g.machine.value} "
                f"{ns_to_s(g.duration_ns):.2f} s in {g.state_name}"
                + (" (never resumed before the log ended)" if g.trailing else "")
            )
        lines.append(f"runs: {len(self.runs)}")
        for r in self.runs:
            what = _one_line(r.manual_operation or r.goal)
            lines.append(
                f"  {r.index:3d} {self._rel(r.start_ns):9.3f} s +{ns_to_s(r.duration_ns):7.3f} s  "
                f"{r.outcome:<10} {what}" + (f"  result: {_one_line(r.result)}" if r.result else "")
            )
        if self.comparison is not None:
            cmp = self.comparison
            title = (
                f"live vs recomputed score ({cmp.caveat})"
                if cmp.caveat
                else ("live vs recomputed score")
            )
            lines.append(
                f"{title}: {cmp.same} same, {len(cmp.differences)} differ "
                f"(tolerance {cmp.abs_tol:g})"
            )
            lines += [f"  note: {n}" for n in cmp.notes]
            # Keys only ertools computes (sample counts, detected times...) are extra detail,
            # not disagreements: counted here, listed in the JSON and CSV.
            shown = [line for line in cmp.lines if line.status != "only recomputed"]
            extra = len(cmp.lines) - len(shown)
            if extra:
                lines.append(f"  ({extra} more key(s) only in the recomputed score)")
            width = max((len(line.key) for line in shown), default=10)
            for line in shown:
                lines.append(
                    f"  {line.key:<{width}}  {_short(line.live):>14}  "
                    f"{_short(line.recomputed):>14}  {line.status}"
                )
                if line.explanation:
                    lines.append(f"  {'':<{width}}    why: {line.explanation}")
        elif self.live_score_text is not None:
            lines.append("score sent live:")
            lines += [f"  {line}" for line in self.live_score_text.splitlines()]
        lines.append("timeline:")
        for e in self.timeline:
            lines.append(
                f"  {self._rel(e.start_ns):9.3f} s {e.machine.value:<6} {e.state_name:<27} "
                f"{ns_to_s(e.duration_ns):8.3f} s  {_one_line(e.payload)}"
            )
        if self.warnings:
            lines.append("warnings:")
            lines += [f"  {w}" for w in self.warnings]
        return "\n".join(lines) + "\n"

    def to_frames(self) -> dict[str, pd.DataFrame]:
        """Every table of :meth:`tables` as a pandas DataFrame, epoch times as a UTC index
        (:func:`ertools.frames.tables_to_frames`)."""
        return tables_to_frames(self.tables())

    def tables(self) -> dict[str, Rows]:
        """``timeline``, ``runs``, ``illegal_transitions``, ``silences``, ``early_ends``
        and, after a re-score, ``score_comparison``."""
        tables: dict[str, Rows] = {
            "timeline": [
                {
                    "machine": e.machine.value,
                    "state": e.state_name,
                    "start_time": ns_to_s(e.start_ns),
                    "start": self._rel(e.start_ns),
                    "duration": ns_to_s(e.duration_ns),
                    "kind": e.kind,
                    "payload": e.payload,
                }
                for e in self.timeline
            ],
            "runs": [
                {"run": r.index, "start_time": ns_to_s(r.start_ns), **self._run_dict(r)}
                for r in self.runs
            ],
            "illegal_transitions": [
                {
                    "time": ns_to_s(x.t_ns),
                    "t": self._rel(x.t_ns),
                    "from": x.from_state,
                    "to": x.to_state,
                    "allowed": " | ".join(x.allowed),
                }
                for x in self.illegal_transitions
            ],
            "silences": [self._silence(s, epoch=True) for s in self.silences],
            "early_ends": [self._early_end(e, table=True) for e in self.early_ends],
        }
        for row in tables["runs"]:
            row["states"] = " > ".join(row["states"])
        if self.comparison is not None:
            tables["score_comparison"] = self.comparison.rows()
        return tables


def _one_line(text: str, width: int = 60) -> str:
    flat = " ".join(text.split())
    return flat if len(flat) <= width else flat[: width - 3] + "..."


def _short(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    return _one_line("" if value is None else str(value), 14)


@frozen_dataclass
class ScoreLine:
    """One leaf of the score: the live value, the recomputed one, and why they differ."""

    key: str
    live: Any
    recomputed: Any
    difference: float | None  # recomputed - live, for numbers
    status: str  # "same", "differs", "only live", "only recomputed"
    explanation: str = ""


@frozen_dataclass
class ScoreComparison:
    """Live vs recomputed score of one benchmark execution."""

    benchmark: str
    lines: tuple[ScoreLine, ...]
    abs_tol: float
    parameters: tuple[tuple[str, str], ...]
    deviations: tuple[Deviation, ...]
    notes: tuple[str, ...] = ()
    # Why the two scores cannot agree whatever the data (an identity transform), shown in the
    # comparison's title and beside every difference it causes; "" when they can.
    caveat: str = ""

    @property
    def differences(self) -> tuple[ScoreLine, ...]:
        """The lines whose values differ beyond the tolerance (numbers) or at all (text)."""
        return tuple(line for line in self.lines if line.status == "differs")

    @property
    def same(self) -> int:
        return sum(1 for line in self.lines if line.status == "same")

    def rows(self) -> Rows:
        return [
            {
                "key": line.key,
                "live": _cell(line.live),
                "recomputed": _cell(line.recomputed),
                "difference": line.difference,
                "status": line.status,
                "explanation": line.explanation,
            }
            for line in self.lines
        ]

    def to_dict(self) -> dict[str, Any]:
        return {
            "benchmark": self.benchmark,
            "caveat": self.caveat or None,
            "tolerance": self.abs_tol,
            "same": self.same,
            "differences": len(self.differences),
            "notes": list(self.notes),
            "parameters": dict(self.parameters),
            "deviations": list(self.deviations),
            "lines": jsonable(self.rows()),
        }


def _cell(value: Any) -> Any:
    if value is None or isinstance(value, bool | int | float | str):
        return value
    return str(value)
