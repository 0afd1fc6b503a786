"""Foxglove content of an audit: the benchmark's states, what the audit found, the re-score.

Topics:

- ``/audit/states``: ``foxglove.Log`` per state change of the BmBox, RefBox and Client (name
  = the machine, message = the state and its payload), at the change;
- ``/audit/runs``: JSON per run at its end: outcome and duration;
- ``/ertools/log``: ``foxglove.Log``: illegal transitions, silences and early ends (warnings,
  at their times), live vs recomputed score lines that differ (at the log's end), notes;
- the recomputed score's own topics (``/fbm2h/...``), as ``score`` writes them.
"""

from __future__ import annotations

from ertools.auditing.model import Audit
from ertools.benchmarks import registry
from ertools.benchmarks.base import Reported
from ertools.views.foxglove import (
    INFO,
    WARNING,
    Collected,
    JsonSchema,
    log,
    result_notes,
)

RUN_SCHEMA = JsonSchema(
    "ertools.AuditRun",
    (("run", "integer"), ("outcome", "string"), ("duration", "number"), ("start", "number")),
)


def _line(text: str, width: int = 200) -> str:
    flat = " ".join(text.split())
    return flat if len(flat) <= width else flat[: width - 3] + "..."


def content(out: Collected, a: Audit, *, limit: int) -> None:
    for e in a.timeline:
        text = e.state_name + (f": {_line(e.payload)}" if e.payload.strip() else "")
        log(out, e.start_ns, INFO, text, e.machine.value, topic="/audit/states")
    for r in a.runs:
        out.json(
            "/audit/runs",
            r.end_ns,
            RUN_SCHEMA,
            {
                "run": r.index,
                "outcome": r.outcome,
                "duration": (r.end_ns - r.start_ns) / 1e9,
                "start": (r.start_ns - a.start_ns) / 1e9,
            },
        )
    for t in a.illegal_transitions:
        log(
            out,
            t.t_ns,
            WARNING,
            f"illegal BmBox transition {t.from_state} -> {t.to_state} (allowed: "
            f"{', '.join(t.allowed) or 'none'})",
            "audit",
        )
    for s in a.silences:
        log(
            out,
            s.start_ns,
            WARNING,
            f"{s.machine.value} silent on {s.topic} for {(s.end_ns - s.start_ns) / 1e9:.3f} s "
            f"in {s.state_name}" + (" (stopped before the log ended)" if s.trailing else ""),
            "audit",
        )
    for x in a.early_ends:
        run = "between runs" if x.run is None else f"run {x.run}"
        log(out, x.t_ns, WARNING, f"RefBox ended {run} early: {x.reason}", "audit")
    bench = registry.for_result(a.recomputed) if a.recomputed is not None else None
    if isinstance(bench, Reported):
        bench.foxglove(out, a.recomputed, limit=limit)
    c = a.comparison
    if c is not None:
        log(
            out,
            a.end_ns,
            INFO,
            f"live vs recomputed score: {c.same} same, {len(c.differences)} differ",
            "audit",
        )
        for line in c.differences:
            log(
                out,
                a.end_ns,
                WARNING,
                f"{line.key}: live {line.live}, recomputed {line.recomputed}",
                "audit",
            )
    result_notes(out, a, "audit")
