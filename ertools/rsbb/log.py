"""An RSBB run bag read into its events (docs/rsbb.md, "A run, event by event").

The RefBox state topic says when each goal was requested, started and ended and with which
result, when each manual operation was asked and what the referee answered, and how the
benchmark ended; ``/timeout`` tells a goal's timeout from an empty result; the BmBox state
topic carries the goal requests (its payloads); the live score topic the script's saves. The
messages are decoded with the definitions stored in the bag
(:func:`ertools.io.messages.read_messages` and :func:`ertools.io.reader.read_states`); the
streams are NumPy arrays and the events are derived from their changes, not from every message.
"""

from __future__ import annotations

import enum
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64, U8
from ertools.errors import ConfigError, TopicError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.io.messages import read_messages
from ertools.io.reader import read_states, read_tf, topics
from ertools.io.summary import summary
from ertools.rsbb.results import LiveScore, parse_live_score
from ertools.rsbb_states import (
    BMBOX_STATE_TOPIC,
    CORE_TO_GUI_TOPIC,
    LIVE_SCORE_TOPIC,
    REFBOX_FIELDS,
    REFBOX_STATE_TOPIC,
    TIMEOUT_TOPIC,
    BmBoxState,
    RefBoxState,
    ScriptFrame,
)
from ertools.streams import PoseStream, StateStream

PathsLike = str | Path | Sequence[str | Path]

# The BmBox publishes at 10 Hz only: its message with a goal's request can come up to one
# period before the RefBox's TRANSMITTING_GOAL (it enters the state before calling the RefBox).
BMBOX_LEAD_NS = 200_000_000
# The referee items are read from the last second of /core/to_gui (10 Hz, large messages).
GUI_WINDOW_NS = 1_000_000_000


@frozen_dataclass(eq=False)
class RefBoxStream:
    """``/rsbb/bmbox/refbox_state``: per message the three sub-machines' states and payloads.

    Attributes:
        t_ns: (N,) record times.
        benchmark, goal, manual: (N,) uint8 states (:class:`~ertools.rsbb_states.RefBoxState`).
        benchmark_payload, goal_payload, manual_payload: N strings each.
        source: where it was read.
    """

    t_ns: I64
    benchmark: U8
    goal: U8
    manual: U8
    benchmark_payload: tuple[str, ...]
    goal_payload: tuple[str, ...]
    manual_payload: tuple[str, ...]
    source: str = ""

    def __len__(self) -> int:
        return int(self.t_ns.shape[0])

    def take(self, index: npt.NDArray[np.intp]) -> RefBoxStream:
        """A new stream with the selected messages."""
        idx = index.tolist()
        return RefBoxStream(
            self.t_ns[index],
            self.benchmark[index],
            self.goal[index],
            self.manual[index],
            tuple(self.benchmark_payload[i] for i in idx),
            tuple(self.goal_payload[i] for i in idx),
            tuple(self.manual_payload[i] for i in idx),
            self.source,
        )

    def changes(self) -> RefBoxStream:
        """The first message and every message where a state or a payload changed (the 10 Hz
        re-publications of an unchanged state dropped)."""
        n = len(self)
        keep = np.zeros(n, dtype=bool)
        keep[:1] = True
        if n > 1:
            for codes in (self.benchmark, self.goal, self.manual):
                keep[1:] |= codes[1:] != codes[:-1]
            for texts in (self.benchmark_payload, self.goal_payload, self.manual_payload):
                arr = np.asarray(texts, dtype=object)
                keep[1:] |= arr[1:] != arr[:-1]
        return self.take(np.flatnonzero(keep))


def _paths(paths: PathsLike) -> list[Path]:
    if isinstance(paths, str | Path):
        return [Path(paths)]
    return [Path(p) for p in paths]


def _where(plist: list[Path]) -> str:
    return str(plist[0]) if len(plist) == 1 else ";".join(map(str, plist))


def read_refbox_states(paths: PathsLike, topic: str = REFBOX_STATE_TOPIC) -> RefBoxStream:
    """The RefBox state stream of a run bag.

    Raises:
        TopicError: the topic is absent or its type has not the RefBoxState fields.
    """
    plist = _paths(paths)
    msgs = read_messages(plist, topic)
    fields = [name for pair in REFBOX_FIELDS for name in pair]
    if msgs and not all(hasattr(msgs[0].msg, f) for f in fields):
        raise TopicError(
            f"topic {topic} ({msgs[0].msgtype}) has not the RSBB RefBoxState fields "
            f"({', '.join(fields)})",
            path=plist[0],
        )
    n = len(msgs)

    def codes(name: str) -> U8:
        return np.fromiter((int(getattr(m.msg, name)) for m in msgs), dtype=np.uint8, count=n)

    def texts(name: str) -> tuple[str, ...]:
        return tuple(str(getattr(m.msg, name)) for m in msgs)

    return RefBoxStream(
        np.fromiter((m.t_ns for m in msgs), dtype=np.int64, count=n),
        codes("benchmark_state"),
        codes("goal_execution_state"),
        codes("manual_operation_state"),
        texts("benchmark_payload"),
        texts("goal_execution_payload"),
        texts("manual_operation_payload"),
        _where(plist),
    )


def read_timeouts(paths: PathsLike) -> I64:
    """Record times of ``/timeout`` (goal and global timeouts); empty when none was published."""
    plist = _paths(paths)
    if TIMEOUT_TOPIC not in topics(plist):
        return np.empty(0, np.int64)
    return np.array([m.t_ns for m in read_messages(plist, TIMEOUT_TOPIC)], dtype=np.int64)


def read_live_scores(paths: PathsLike) -> tuple[LiveScore, ...]:
    """Every ``/rsbb/current_benchmark_result`` message, parsed (empty when absent)."""
    plist = _paths(paths)
    if LIVE_SCORE_TOPIC not in topics(plist):
        return ()
    return tuple(
        parse_live_score(m.t_ns, str(m.msg.data)) for m in read_messages(plist, LIVE_SCORE_TOPIC)
    )


@frozen_dataclass
class RefereeItem:
    """One referee item as the RefBox showed it (``/core/to_gui``, the zone's ``scoring``)."""

    group: str
    desc: str
    kind: str  # "bool" or "uint"
    value: int


def read_referee_items(
    paths: PathsLike, code: str, team: str, run: int | None = None
) -> tuple[int, tuple[RefereeItem, ...]] | None:
    """The referee items of the zone running ``code`` for ``team`` (and ``run``) in the last
    ``/core/to_gui`` message that has that zone: (record time, items); None when no message has
    it (or the topic is absent)."""
    plist = _paths(paths)
    lasts = [
        int(t.last_ns)
        for p in plist
        for t in summary(p).topics
        if t.name == CORE_TO_GUI_TOPIC and t.count and t.last_ns is not None
    ]
    if not lasts:
        return None
    last_ns = max(lasts)
    # A file's index may give a topic's end as its chunk's: widen the window until it holds
    # the topic's last messages (each window is read only once the narrower one came back empty).
    window = GUI_WINDOW_NS
    while True:
        start = last_ns - window
        msgs = read_messages(plist, CORE_TO_GUI_TOPIC, start_ns=start)
        if msgs or window > last_ns:
            break
        window *= 10
    for m in reversed(msgs):
        for zone in m.msg.zones:
            if zone.code != code or zone.team != team or (run is not None and zone.run != run):
                continue
            items = tuple(
                RefereeItem(
                    str(group.group_name),
                    str(desc),
                    "bool" if int(kind) == 0 else "uint",
                    int(value),
                )
                for group in zone.scoring
                for kind, desc, value in zip(
                    group.types, group.descriptions, group.current_values, strict=False
                )
            )
            return m.t_ns, items
    return None


def read_script_broadcasts(paths: PathsLike, frame: ScriptFrame) -> PoseStream:
    """The script's own broadcasts of ``frame`` (header stamps = its lookups' ``now``).

    Raises:
        TopicError: no such broadcast in the bag.
    """
    return read_tf(paths, frame.parent.lstrip("/"), frame.child.lstrip("/"))


class GoalOutcome(enum.Enum):
    """How a goal ended."""

    RESULT = "result"  # the robot reported a result (goal READY with its payload)
    TIMEOUT = "timeout"  # the RefBox's goal timer fired (/timeout, then goal READY, empty)
    STOPPED = "stopped"  # the benchmark stopped (referee stop or global timeout) first
    UNFINISHED = "unfinished"  # the log ends during the goal


@frozen_dataclass
class GoalEvent:
    """One goal of a run.

    Attributes:
        index: its order in the run (0-based).
        t_request_ns: the RefBox's goal TRANSMITTING_GOAL (the goal timer starts here).
        t_start_ns: goal EXECUTING_GOAL (the robot started; the script's start time is a few
            ms before), or None.
        t_end_ns: goal READY (the script's end time is a few ms before), the benchmark's stop,
            or None when the log ends first.
        outcome: see :class:`GoalOutcome`.
        result: the robot's result string (RESULT only).
        request: the BmBox's goal payload (the script's ``yaml.dump`` of its request), None
            when no BmBox message of the goal was recorded.
    """

    index: int
    t_request_ns: int
    t_start_ns: int | None
    t_end_ns: int | None
    outcome: GoalOutcome
    result: str | None
    request: str | None


@frozen_dataclass
class ManualOperationEvent:
    """One manual operation: the request's text and the referee's answer.

    Attributes:
        t_request_ns: manual EXECUTING_MANUAL_OPERATION.
        t_done_ns: manual READY after it, None when the benchmark stopped or the log ended.
        request: the text asked.
        answer: what the referee typed (``""`` if nothing), None when not completed.
    """

    t_request_ns: int
    t_done_ns: int | None
    request: str
    answer: str | None


class EndKind(enum.Enum):
    """How a run's benchmark ended (the RefBox benchmark state)."""

    END = "end"  # the script ended it (RefBox END)
    STOP = "stop"  # the referee (or HPFF's abort) stopped it
    GLOBAL_TIMEOUT = "global_timeout"
    OTHER = "other"  # EMERGENCY_STOP or ERROR (never set by the 2017-19 RefBox)
    LOG_ENDS = "log_ends"  # still executing when the log ends
    NOT_STARTED = "not_started"  # never EXECUTING_BENCHMARK in the log


_END_KINDS = {
    RefBoxState.END: EndKind.END,
    RefBoxState.STOP: EndKind.STOP,
    RefBoxState.GLOBAL_TIMEOUT: EndKind.GLOBAL_TIMEOUT,
    RefBoxState.EMERGENCY_STOP: EndKind.OTHER,
    RefBoxState.ERROR: EndKind.OTHER,
}


@frozen_dataclass
class RsbbRun:
    """An RSBB run bag's streams and events.

    Attributes:
        source: the bag(s).
        refbox: the RefBox state stream.
        bmbox: the BmBox state stream (None when not recorded).
        timeouts_ns: ``/timeout`` record times.
        live: the live score messages.
        t_start_ns: the RefBox's EXECUTING_BENCHMARK (the referee's start), or None.
        end_kind, t_end_ns: how and when the benchmark ended (None: never, in the log).
        manual_operations, goals: in order.
    """

    source: str
    refbox: RefBoxStream
    bmbox: StateStream | None
    timeouts_ns: I64
    live: tuple[LiveScore, ...]
    t_start_ns: int | None
    end_kind: EndKind
    t_end_ns: int | None
    manual_operations: tuple[ManualOperationEvent, ...]
    goals: tuple[GoalEvent, ...]


def _run_bounds(ch: RefBoxStream) -> tuple[int | None, EndKind, int | None, int]:
    """(start, end kind, end time, index of the end row in ``ch`` or len(ch))."""
    executing = np.flatnonzero(ch.benchmark == RefBoxState.EXECUTING_BENCHMARK)
    if executing.size == 0:
        return None, EndKind.NOT_STARTED, None, len(ch)
    first = int(executing[0])
    ended = np.flatnonzero(np.isin(ch.benchmark[first:], list(_END_KINDS))) + first
    if ended.size == 0:
        return int(ch.t_ns[first]), EndKind.LOG_ENDS, None, len(ch)
    k = int(ended[0])
    return int(ch.t_ns[first]), _END_KINDS[RefBoxState(int(ch.benchmark[k]))], int(ch.t_ns[k]), k


def _manual_operations(ch: RefBoxStream, lo: int, hi: int) -> tuple[ManualOperationEvent, ...]:
    out: list[ManualOperationEvent] = []
    pending: tuple[int, str] | None = None
    for i in range(lo, hi):
        state = ch.manual[i]
        if state == RefBoxState.EXECUTING_MANUAL_OPERATION and pending is None:
            pending = (int(ch.t_ns[i]), ch.manual_payload[i])
        elif state == RefBoxState.READY and pending is not None:
            out.append(
                ManualOperationEvent(pending[0], int(ch.t_ns[i]), pending[1], ch.manual_payload[i])
            )
            pending = None
    if pending is not None:
        out.append(ManualOperationEvent(pending[0], None, pending[1], None))
    return tuple(out)


def _goal_requests(bmbox: StateStream | None) -> tuple[I64, tuple[str, ...]]:
    """Times and payloads of the BmBox's messages carrying a goal request."""
    if bmbox is None or len(bmbox) == 0:
        return np.empty(0, np.int64), ()
    carrying = np.isin(bmbox.state, [BmBoxState.TRANSMITTING_GOAL, BmBoxState.EXECUTING_GOAL])
    idx = np.flatnonzero(carrying)
    return bmbox.t_ns[idx], tuple(bmbox.payload[i] for i in idx.tolist())


def _goals(
    ch: RefBoxStream,
    lo: int,
    hi: int,
    end: tuple[EndKind, int | None],
    timeouts: I64,
    requests: tuple[I64, tuple[str, ...]],
) -> tuple[GoalEvent, ...]:
    raw: list[tuple[int, int | None, int | None, GoalOutcome, str | None]] = []
    current: list[Any] | None = None  # [t_request, t_start]
    for i in range(lo, hi):
        state, t = ch.goal[i], int(ch.t_ns[i])
        if state == RefBoxState.TRANSMITTING_GOAL and current is None:
            current = [t, None]
        elif state == RefBoxState.EXECUTING_GOAL and current is not None and current[1] is None:
            current[1] = t
        elif state == RefBoxState.READY and current is not None:
            t_req = int(current[0])
            timed_out = bool(np.any((timeouts >= t_req) & (timeouts <= t)))
            if timed_out and ch.goal_payload[i] == "":
                raw.append((t_req, current[1], t, GoalOutcome.TIMEOUT, None))
            else:
                raw.append((t_req, current[1], t, GoalOutcome.RESULT, ch.goal_payload[i]))
            current = None
    if current is not None:
        kind, t_end = end
        outcome = GoalOutcome.UNFINISHED if kind is EndKind.LOG_ENDS else GoalOutcome.STOPPED
        raw.append((int(current[0]), current[1], t_end, outcome, None))
    t_req_all, payloads = requests
    goals = []
    previous_end: int | None = None
    for k, (t_req, t_start, t_end, outcome, result) in enumerate(raw):
        lo_t = (
            t_req - BMBOX_LEAD_NS
            if previous_end is None
            else max(previous_end, t_req - BMBOX_LEAD_NS)
        )
        hi_t = t_end if t_end is not None else np.iinfo(np.int64).max
        j = int(np.searchsorted(t_req_all, lo_t, side="left"))
        request = payloads[j] if j < len(payloads) and int(t_req_all[j]) <= hi_t else None
        goals.append(GoalEvent(k, t_req, t_start, t_end, outcome, result, request or None))
        previous_end = t_end
    return tuple(goals)


def run_events(
    refbox: RefBoxStream,
    bmbox: StateStream | None,
    timeouts_ns: I64,
    live: tuple[LiveScore, ...] = (),
    source: str = "",
) -> RsbbRun:
    """The events of a run from its streams (pure: :func:`read_rsbb_run` reads the streams)."""
    ch = refbox.changes()
    t_start, kind, t_end, end_row = _run_bounds(ch)
    if t_start is None:
        lo = hi = 0
    else:
        lo = int(np.searchsorted(ch.t_ns, t_start, side="left"))
        hi = end_row
    return RsbbRun(
        source=source or refbox.source,
        refbox=refbox,
        bmbox=bmbox,
        timeouts_ns=timeouts_ns,
        live=live,
        t_start_ns=t_start,
        end_kind=kind,
        t_end_ns=t_end,
        manual_operations=_manual_operations(ch, lo, hi),
        goals=_goals(ch, lo, hi, (kind, t_end), timeouts_ns, _goal_requests(bmbox)),
    )


def read_rsbb_run(paths: PathsLike) -> RsbbRun:
    """A run bag's RefBox and BmBox states, timeouts and live scores, and its events.

    Raises:
        BagError: unreadable bag (from the readers).
        TopicError: no RefBox state topic (not an RSBB run bag).
    """
    plist = _paths(paths)
    present = topics(plist)
    if REFBOX_STATE_TOPIC not in present:
        raise TopicError(
            f"no {REFBOX_STATE_TOPIC} in {_where(plist)}: not an RSBB run bag "
            "(rsbb_logs/<CODE>/<team>/run_<n>_<date>.bag)"
        )
    refbox = read_refbox_states(plist)
    bmbox = read_states(plist, BMBOX_STATE_TOPIC) if BMBOX_STATE_TOPIC in present else None
    return run_events(refbox, bmbox, read_timeouts(plist), read_live_scores(plist), _where(plist))


def logged_code(run: RsbbRun) -> str | None:
    """The benchmark the run's live scores name (``benchmark_info.benchmark_code``, set by
    the script's setup before it published), None when none names one."""
    for message in run.live:
        info = message.result.get("benchmark_info") if message.result is not None else None
        code = info.get("benchmark_code") if isinstance(info, dict) else None
        if isinstance(code, str) and code not in ("", "undefined"):
            return code
    return None


def check_code(run: RsbbRun, code: str) -> None:
    """Refuse another benchmark's run bag (outside the RSBB layout, where its folder says).

    Raises:
        ConfigError: the live scores name another benchmark.
    """
    logged = logged_code(run)
    if logged is not None and logged != code:
        raise ConfigError(
            f"this bag is a {logged} run (its live score's benchmark_info), not {code}'s: "
            f"ertools score {logged.lower()}",
            path=run.source,
        )
