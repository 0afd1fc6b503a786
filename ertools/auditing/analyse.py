"""What happened in a benchmark, reconstructed from its three state topics (seed 6.2 to 6.4).

Pure: takes :class:`~ertools.streams.StateStream` objects (one per machine, ``None`` where a
topic is absent) and returns a frozen :class:`Audit`. Reading the bag is the CLI's job
(``ertools.io.reader.read_benchmark_states``); recomputing the score is
:mod:`ertools.auditing.recompute`'s.

The audit finds:

- the timeline of each machine (every change of state or payload, with its duration: a state
  lasts until the next change, the last one until the last heartbeat of that topic);
- every BmBox transition the 2015 implementation did not allow
  (:data:`ertools.states.BMBOX_TRANSITIONS`);
- silences: gaps in a topic's 10 Hz heartbeat longer than ``max_silence_ns``;
- the runs (a run starts when the BmBox leaves READY for a manual operation or a goal and ends
  when it returns to READY, sends the score or ends) with their manual operation, goal,
  the Client's result and how they ended;
- benchmarks ended early by the RefBox: an END whose payload is a timeout or a stop, read by
  :func:`ertools.states.end_reason` as the scorers' default reads it (the 2015 BmBox's
  ``reason: timeout`` / ``reason: stop`` and the seed's ``timeout`` / ``halt``, each compared
  whole); any other payload is warned about with its place and is neither;
- the score sent live (the payload of TRANSMITTING_SCORE), parsed without executing anything.
"""

from __future__ import annotations

import logging
from dataclasses import replace
from typing import Any

import numpy as np
import yaml

from ertools.auditing.model import (
    Audit,
    AuditRun,
    EarlyEnd,
    IllegalTransition,
    Silence,
    TimelineEntry,
)
from ertools.benchmarks.common.ending import end_payload_warnings, refbox_ends
from ertools.states import (
    BMBOX_TRANSITIONS,
    BmBoxState,
    ClientState,
    EndReason,
    Machine,
    RefBoxState,
    state_name,
)
from ertools.streams import Provenance, StateStream
from ertools.timeutil import NS_PER_S, ns_to_s
from ertools.yamlin import load as load_yaml

log = logging.getLogger("ertools.auditing.analyse")

DEFAULT_MAX_SILENCE_NS = NS_PER_S  # the machines published at 10 Hz: 1 s is 10 lost beats

# What a payload means, by machine and state (seed 6.2.1 to 6.2.3).
PAYLOAD_KINDS: dict[tuple[Machine, int], str] = {
    (Machine.BMBOX, BmBoxState.WAITING_MANUAL_OPERATION): "manual_operation",
    (Machine.BMBOX, BmBoxState.TRANSMITTING_GOAL): "goal",
    (Machine.BMBOX, BmBoxState.TRANSMITTING_SCORE): "score",
    (Machine.REFBOX, RefBoxState.EXECUTING_MANUAL_OPERATION): "manual_operation",
    (Machine.REFBOX, RefBoxState.END): "end_reason",
    (Machine.CLIENT, ClientState.COMPLETED_GOAL): "result",
}

# BmBox states that open a run when entered from READY, and those that close it.
_RUN_OPENERS = frozenset({BmBoxState.WAITING_MANUAL_OPERATION, BmBoxState.TRANSMITTING_GOAL})
_RUN_CLOSERS = frozenset({BmBoxState.READY, BmBoxState.TRANSMITTING_SCORE, BmBoxState.END})


# --------------------------------------------------------------------------------------------
# Building the audit


def audit_states(
    bmbox: StateStream | None,
    refbox: StateStream | None = None,
    client: StateStream | None = None,
    *,
    benchmark: str = "",
    max_silence_ns: int = DEFAULT_MAX_SILENCE_NS,
    inputs: tuple[str, ...] = (),
) -> Audit:
    """Audit one benchmark execution from its state streams.

    Args:
        bmbox: the BmBox state stream (every heartbeat, not only changes).
        refbox: the RefBox state stream, or None when absent.
        client: the Client state stream, or None when absent.
        benchmark: the namespace (``fbm2h``...) for the output.
        max_silence_ns: heartbeat gaps longer than this are reported.
        inputs: the files the streams came from (provenance).

    Returns:
        The frozen audit. Nothing is raised for what the audit finds; an audit of no stream
        at all has an empty timeline and a warning.
    """
    streams = {m: s for m, s in _by_machine(bmbox, refbox, client).items() if s is not None}
    warnings: list[str] = []
    for machine in Machine:
        if machine not in streams or len(streams[machine]) == 0:
            warnings.append(f"no {machine.value} state messages: that machine is not audited")
    nonempty = {m: s for m, s in streams.items() if len(s)}
    if nonempty:
        start_ns = min(int(s.t_ns[0]) for s in nonempty.values())
        end_ns = max(int(s.t_ns[-1]) for s in nonempty.values())
    else:
        start_ns = end_ns = 0

    entries: list[TimelineEntry] = []
    changes: dict[Machine, StateStream] = {}
    for machine, stream in nonempty.items():
        changes[machine] = stream.changes()
        entries.extend(_timeline(machine, changes[machine], int(stream.t_ns[-1])))
    order = {Machine.BMBOX: 0, Machine.REFBOX: 1, Machine.CLIENT: 2}
    entries.sort(key=lambda e: (e.start_ns, order[e.machine]))

    bm = changes.get(Machine.BMBOX)
    illegal, checked = _check_transitions(bm) if bm is not None else ((), 0)
    silences = tuple(
        s for m, st in nonempty.items() for s in _silences(m, st, max_silence_ns, end_ns)
    )
    silences = tuple(sorted(silences, key=lambda s: s.start_ns))
    runs = _runs(bm, changes.get(Machine.REFBOX), changes.get(Machine.CLIENT))
    early, unknown = _early_ends(changes.get(Machine.REFBOX), bm, runs, start_ns)
    warnings.extend(unknown)
    runs = _mark_early_ends(runs, early)
    live_text, live, live_warning = _live_score(bm)
    if live_warning:
        warnings.append(live_warning)
    if bm is not None and len(bm):
        first = state_name(Machine.BMBOX, int(bm.state[0]))
        if int(bm.state[0]) != BmBoxState.START:
            warnings.append(
                f"the BmBox log starts in {first}, not START: the recording began late, "
                "earlier transitions are not checked"
            )
        reached_end = bool(np.any(bm.state == BmBoxState.END))
        if reached_end and live_text is None and not early:
            warnings.append("the BmBox reached END without sending a score")
    for x in illegal:
        warnings.append(f"illegal BmBox transition {x.from_state} -> {x.to_state}")
    for s in silences:
        warnings.append(
            f"{s.topic or s.machine.value} silent for {ns_to_s(s.duration_ns):.2f} s "
            f"(in {s.state_name})" + (" until the end of the log" if s.trailing else "")
        )
    for e in early:
        where = f"during run {e.run}" if e.run is not None else f"in BmBox {e.bmbox_state}"
        warnings.append(f"benchmark ended by the RefBox ({e.reason}) {where}")

    topics = tuple((m.value, streams[m].topic, len(streams[m])) for m in Machine if m in streams)
    return Audit(
        benchmark=benchmark.strip("/"),
        timeline=tuple(entries),
        transitions_checked=checked,
        illegal_transitions=illegal,
        silences=silences,
        early_ends=early,
        runs=runs,
        live_score=live,
        live_score_text=live_text,
        max_silence_ns=int(max_silence_ns),
        start_ns=start_ns,
        end_ns=end_ns,
        topics=topics,
        warnings=tuple(warnings),
        provenance=Provenance(
            inputs=inputs,
            parameters=(("max_silence", f"{ns_to_s(max_silence_ns):g} s"),),
        ),
    )


def _by_machine(
    bmbox: StateStream | None, refbox: StateStream | None, client: StateStream | None
) -> dict[Machine, StateStream | None]:
    return {Machine.BMBOX: bmbox, Machine.REFBOX: refbox, Machine.CLIENT: client}


def _kind(machine: Machine, state: int, payload: str) -> str:
    kind = PAYLOAD_KINDS.get((machine, state), "")
    if not payload.strip():
        return "" if kind != "goal" else "goal"
    return kind or "payload"


def _timeline(machine: Machine, ch: StateStream, last_ns: int) -> list[TimelineEntry]:
    starts = [int(t) for t in ch.t_ns]
    ends = [*starts[1:], last_ns]
    return [
        TimelineEntry(
            machine=machine,
            state=int(ch.state[i]),
            state_name=state_name(machine, int(ch.state[i])),
            start_ns=starts[i],
            end_ns=ends[i],
            payload=ch.payload[i],
            kind=_kind(machine, int(ch.state[i]), ch.payload[i]),
        )
        for i in range(len(ch))
    ]


def _check_transitions(bm: StateStream) -> tuple[tuple[IllegalTransition, ...], int]:
    """Every change of BmBox state (payload-only changes are not transitions)."""
    out: list[IllegalTransition] = []
    checked = 0
    for i in range(1, len(bm)):
        a, b = int(bm.state[i - 1]), int(bm.state[i])
        if a == b:
            continue
        checked += 1
        try:
            allowed = BMBOX_TRANSITIONS[BmBoxState(a)]
        except ValueError:
            allowed = frozenset()
        if b in {int(s) for s in allowed}:
            continue
        out.append(
            IllegalTransition(
                t_ns=int(bm.t_ns[i]),
                from_state=state_name(Machine.BMBOX, a),
                to_state=state_name(Machine.BMBOX, b),
                allowed=tuple(s.name for s in sorted(allowed)),
            )
        )
    return tuple(out), checked


def _silences(machine: Machine, stream: StateStream, max_ns: int, log_end_ns: int) -> list[Silence]:
    """Heartbeat gaps, and a topic that fell silent before the log's end without reaching END
    (a node that died: the 2015 machines stopped publishing only after END)."""
    out = [
        Silence(
            machine=machine,
            topic=stream.topic,
            start_ns=int(stream.t_ns[i]),
            end_ns=int(stream.t_ns[i + 1]),
            state_name=state_name(machine, int(stream.state[i])),
        )
        for i in np.flatnonzero(np.diff(stream.t_ns) > max_ns)
    ]
    last = int(stream.t_ns[-1])
    final = state_name(machine, int(stream.state[-1]))
    if log_end_ns - last > max_ns and final != "END":
        out.append(Silence(machine, stream.topic, last, log_end_ns, final, trailing=True))
    return out


def _first_in(ch: StateStream | None, state: int, lo: int, hi: int) -> tuple[str, int] | None:
    """Payload and time of the first change to ``state`` with lo <= t < hi."""
    if ch is None:
        return None
    for i in range(len(ch)):
        t = int(ch.t_ns[i])
        if lo <= t < hi and int(ch.state[i]) == state:
            return ch.payload[i], t
    return None


def _runs(
    bm: StateStream | None, refbox: StateStream | None, client: StateStream | None
) -> tuple[AuditRun, ...]:
    if bm is None or len(bm) == 0:
        return ()
    states = [int(s) for s in bm.state]
    times = [int(t) for t in bm.t_ns]
    # (start index, end index or None) of each run, in BmBox changes.
    spans: list[tuple[int, int | None]] = []
    open_at: int | None = None
    for i in range(1, len(states)):
        prev, cur = states[i - 1], states[i]
        if prev == cur:
            continue
        if open_at is None and prev == BmBoxState.READY and cur in _RUN_OPENERS:
            open_at = i
        elif open_at is not None and cur in _RUN_CLOSERS:
            spans.append((open_at, i))
            open_at = None
    if open_at is not None:
        spans.append((open_at, None))

    stream_end = times[-1]
    runs: list[AuditRun] = []
    for k, (a, b) in enumerate(spans):
        end_ns = times[b] if b is not None else stream_end
        # A result or a RefBox payload belongs to this run until the next run starts.
        window_end = times[spans[k + 1][0]] if k + 1 < len(spans) else stream_end + 1
        visited = tuple(
            dict.fromkeys(
                state_name(Machine.BMBOX, states[j])
                for j in range(a, b if b is not None else len(states))
            )
        )
        manual = ""
        goal = ""
        executing: int | None = None
        for j in range(a, b if b is not None else len(states)):
            if states[j] == BmBoxState.WAITING_MANUAL_OPERATION and not manual:
                manual = bm.payload[j]
            if states[j] == BmBoxState.TRANSMITTING_GOAL and not goal:
                goal = bm.payload[j]
            if states[j] == BmBoxState.EXECUTING_GOAL and executing is None:
                executing = times[j]
        ref_manual = _first_in(refbox, RefBoxState.EXECUTING_MANUAL_OPERATION, times[a], end_ns)
        if ref_manual is not None and ref_manual[0].strip():
            # @Work the RefBox names the item (FBM1w); keep the BmBox text when it has one.
            manual = manual or ref_manual[0]
        result = _first_in(client, ClientState.COMPLETED_GOAL, times[a], window_end)
        if b is None:
            outcome = "unfinished"
        elif states[b] == BmBoxState.END:
            outcome = "aborted"
        elif states[b - 1] == BmBoxState.WAITING_MANUAL_OPERATION:
            outcome = "cancelled"
        else:
            outcome = "completed"
        runs.append(
            AuditRun(
                index=k,
                start_ns=times[a],
                end_ns=end_ns,
                outcome=outcome,
                states=visited,
                manual_operation=manual,
                goal=goal,
                result=result[0] if result else "",
                result_ns=result[1] if result else None,
                executing_ns=executing,
            )
        )
    return tuple(runs)


# The audit's names of the two early ends (seed 6.2.3 calls a referee's stop a halt).
_AUDIT_REASONS = {EndReason.TIMEOUT: "timeout", EndReason.STOP: "halt"}


def _bm_state_at(bm: StateStream | None, t_ns: int) -> str:
    if bm is None or len(bm) == 0:
        return ""
    i = int(np.searchsorted(bm.t_ns, t_ns, side="right")) - 1
    return state_name(Machine.BMBOX, int(bm.state[i])) if i >= 0 else "(before BmBox)"


def _early_ends(
    refbox: StateStream | None, bm: StateStream | None, runs: tuple[AuditRun, ...], t0_ns: int
) -> tuple[tuple[EarlyEnd, ...], list[str]]:
    """The first RefBox END that is a timeout or a stop, and a warning per unknown END payload.

    END is final: later ends (a payload changed while in END) are not new ends.
    """
    if refbox is None:
        return (), []
    unknown = end_payload_warnings(refbox, t0_ns)
    for end in refbox_ends(refbox):
        if not end.reason.ends_early:
            continue
        run = next((r.index for r in runs if r.start_ns <= end.t_ns <= r.end_ns), None)
        early = EarlyEnd(
            t_ns=end.t_ns,
            reason=_AUDIT_REASONS[end.reason],
            payload=end.payload,
            run=run,
            bmbox_state=_bm_state_at(bm, end.t_ns),
        )
        return (early,), unknown
    return (), unknown


def _mark_early_ends(
    runs: tuple[AuditRun, ...], early: tuple[EarlyEnd, ...]
) -> tuple[AuditRun, ...]:
    if not early:
        return runs

    by_run = {e.run: e.reason for e in early if e.run is not None}
    return tuple(replace(r, outcome=by_run[r.index]) if r.index in by_run else r for r in runs)


def _live_score(bm: StateStream | None) -> tuple[str | None, Any, str]:
    """The last TRANSMITTING_SCORE payload, raw and parsed, and a warning if unparsable."""
    if bm is None:
        return None, None, ""
    idx = np.flatnonzero(bm.state == BmBoxState.TRANSMITTING_SCORE)
    if idx.size == 0:
        return None, None, ""
    text = bm.payload[int(idx[-1])]
    if not text.strip():
        return text, None, "the live score payload (TRANSMITTING_SCORE) is empty"
    try:
        return text, parse_payload(text), ""
    except yaml.YAMLError as err:
        line = str(err).splitlines()[0] if str(err) else type(err).__name__
        return text, None, f"the live score payload is not YAML ({line}); shown as text"


def parse_payload(text: str) -> Any:
    """A YAML payload from a bag, read safely; python tags as the 2015 nodes wrote them
    (``yaml.dump`` of a ``Pose2D``) are read as the plain data under them, and of a key given
    twice the last value counts, as the 2015 nodes read it (the scorers warn of it)."""
    return load_yaml(text, tags="plain", duplicates=[])
