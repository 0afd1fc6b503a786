"""FBM1 runs from the three state topics: when each item was presented, asked for and answered.

Per run the 2015 BmBox went ``READY -> WAITING_MANUAL_OPERATION`` (payload ``Place item <id>
(<instance>) on the table`` at @Home) ``-> COMPLETED_MANUAL_OPERATION -> TRANSMITTING_GOAL ->
EXECUTING_GOAL -> WAITING_RESULT -> READY``. The node measured its execution time from the
moment ``SendGoal`` returned (BmBox in ``EXECUTING_GOAL``) to the moment ``WaitResult``
returned (BmBox leaving ``WAITING_RESULT``); the answer is the Client's ``COMPLETED_GOAL``
payload. At @Work the Referee Box chose the item: its ``EXECUTING_MANUAL_OPERATION`` payload
names it. A RefBox ``END`` that is a timeout or a stop (:func:`ertools.states.end_reason`:
``reason: timeout`` ends a run without answer, ``reason: stop`` ends the benchmark, the 2015
BmBox's strings; by default the seed's ``timeout`` / ``halt`` too, not under
``--exact-end-payloads``) before the robot answered ends the run; another END payload is warned
about once, with its file and time, and read as the BmBox read it (neither). A log that ends
inside a run is that run stopped there (:mod:`ertools.benchmarks.common.ending`), said in a
warning.

The states were re-published at 10 Hz, so a state shorter than 100 ms may be missing from the
log: each moment is the first message of the first state at or past it.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import replace

from ertools.benchmarks.common.ending import (
    cut_warning,
    end_payload_deviation,
    end_payload_warnings,
    log_cut,
    refbox_ends,
)
from ertools.fidelity import Deviation
from ertools.frozen_dataclass import frozen_dataclass
from ertools.states import BmBoxState, ClientState, EndReason, RefBoxState
from ertools.streams import StateStream

_GOAL_STATES = (BmBoxState.TRANSMITTING_GOAL, BmBoxState.EXECUTING_GOAL, BmBoxState.WAITING_RESULT)
_EXECUTING_STATES = (BmBoxState.EXECUTING_GOAL, BmBoxState.WAITING_RESULT)

_PLACE_RE = re.compile(r"^\s*place\s+item\s+(\d+)\s*\((.*)\)\s*on\s+the\s+table\s*$", re.I)


@frozen_dataclass
class ItemRef:
    """What a run's manual-operation payload (or ``--items-order``) says was presented."""

    item_id: int | None
    instance: str | None
    text: str
    source: str  # "bmbox payload", "refbox payload", "--items-order"


@frozen_dataclass
class Fbm1Run:
    """One presented item, with the moments the 2015 node acted on (int64 ns).

    Attributes:
        index: 1-based, in the order the node counted its runs.
        start_ns: the manual operation was requested (or the goal sent, without one).
        end_ns: the next run's start, or the last state message.
        placed_ns: the referee confirmed the item was placed (COMPLETED_MANUAL_OPERATION).
        goal_ns: the goal was sent (first goal state); None for a run that never got there.
        executing_ns: the robot acknowledged the goal (2015 ``start_time``).
        result_ns: the BmBox stopped waiting for the result (2015 ``end_time``).
        item: which item was presented, None when nothing names it.
        answer_payload: the Client's COMPLETED_GOAL payload, None without answer.
        answer_ns: when the Client completed the goal.
        ended_by: ``timeout`` or ``stop`` when the RefBox ended the run without answer.
    """

    index: int
    start_ns: int
    end_ns: int
    placed_ns: int | None = None
    goal_ns: int | None = None
    executing_ns: int | None = None
    result_ns: int | None = None
    item: ItemRef | None = None
    answer_payload: str | None = None
    answer_ns: int | None = None
    ended_by: str | None = None

    @property
    def status(self) -> str:
        """``answered``, ``no_answer`` (goal sent, nothing came back) or ``aborted``."""
        if self.goal_ns is None:
            return "aborted"
        return "answered" if self.answer_payload is not None else "no_answer"


@frozen_dataclass
class RunsFound:
    """The runs of a benchmark and what the state log said besides."""

    runs: tuple[Fbm1Run, ...]
    warnings: tuple[str, ...] = ()
    logged_score: str | None = None  # the BmBox TRANSMITTING_SCORE payload
    deviations: tuple[Deviation, ...] = ()  # where the state log was read unlike 2015


def parse_item_ref(text: str, source: str) -> ItemRef | None:
    """``Place item 3 (a3) on the table`` -> id 3, instance a3; a bare id or instance too.

    The 2015 @Work RefBox sent the bare instance name; the @Home BmBox the full sentence.
    """
    stripped = text.strip()
    if not stripped:
        return None
    match = _PLACE_RE.match(stripped)
    if match:
        return ItemRef(int(match.group(1)), match.group(2).strip(), stripped, source)
    if stripped.isdigit():
        return ItemRef(int(stripped), None, stripped, source)
    return ItemRef(None, stripped, stripped, source)


_ENDED_BY = {EndReason.TIMEOUT: "timeout", EndReason.STOP: "stop"}


def _bmbox_runs(bmbox: StateStream) -> tuple[list[Fbm1Run], str | None]:
    """Split the BmBox transitions into runs (a small state machine over ~100 transitions)."""
    changes = bmbox.changes()
    runs: list[Fbm1Run] = []
    logged_score: str | None = None
    prev_state: int | None = None
    for t, state, payload in zip(
        changes.t_ns.tolist(), changes.state.tolist(), changes.payload, strict=True
    ):
        cur = runs[-1] if runs else None
        # A READY lasting less than one 10 Hz heartbeat may be missing: any state that is not
        # "still executing this goal" closes the open run.
        new_goal = state == BmBoxState.TRANSMITTING_GOAL and prev_state in _EXECUTING_STATES
        if (
            cur is not None
            and cur.goal_ns is not None
            and cur.result_ns is None
            and (state not in _GOAL_STATES or new_goal)
        ):
            cur = runs[-1] = replace(cur, result_ns=t)
        if state == BmBoxState.WAITING_MANUAL_OPERATION:
            if prev_state != BmBoxState.WAITING_MANUAL_OPERATION:
                item = parse_item_ref(payload, "bmbox payload")
                runs.append(Fbm1Run(len(runs) + 1, t, t, item=item))
        elif state in _GOAL_STATES:
            after_manual = prev_state in (
                BmBoxState.WAITING_MANUAL_OPERATION,
                BmBoxState.COMPLETED_MANUAL_OPERATION,
            )
            if (
                cur is None
                or cur.result_ns is not None
                or (cur.goal_ns is None and not after_manual)
            ):
                # A goal without a manual operation before it (a log cut, or a run without
                # the table operation): still a run.
                cur = Fbm1Run(len(runs) + 1, t, t)
                runs.append(cur)
            if cur.goal_ns is None:
                cur = runs[-1] = replace(cur, goal_ns=t)
            if state in _EXECUTING_STATES and cur.executing_ns is None:
                runs[-1] = replace(cur, executing_ns=t)
        elif state == BmBoxState.COMPLETED_MANUAL_OPERATION:
            if cur is not None and cur.placed_ns is None and cur.goal_ns is None:
                runs[-1] = replace(cur, placed_ns=t)
        elif state == BmBoxState.TRANSMITTING_SCORE:
            logged_score = payload
        prev_state = state
    last_ns = int(bmbox.t_ns[-1]) if len(bmbox) else 0
    for k, run in enumerate(runs):
        end = runs[k + 1].start_ns if k + 1 < len(runs) else max(last_ns, run.start_ns)
        runs[k] = replace(run, end_ns=end)
    return runs, logged_score


def runs_from_states(
    bmbox: StateStream,
    refbox: StateStream | None,
    client: StateStream | None,
    *,
    benchmark: str = "fbm1h",
    items_order: Sequence[str] | None = None,
    t0_ns: int | None = None,
    exact_2015: bool = False,
) -> RunsFound:
    """The runs of one FBM1 execution.

    Args:
        bmbox: the BmBox state topic (required: it delimits the runs).
        refbox: the RefBox state topic (@Work item names, timeouts); None when absent.
        client: the Client state topic (answers); None when absent (then ``--results``).
        benchmark: ``fbm1h`` (item from the BmBox payload first) or ``fbm1w`` (RefBox first).
        items_order: item ids or instance names per run, overriding the payloads.
        t0_ns: the log's first message (times in warnings count from it; default: the first
            BmBox message).
        exact_2015: RefBox END payloads read as the 2015 BmBox did (``--exact-end-payloads``).
    """
    t0 = int(bmbox.t_ns[0]) if t0_ns is None else t0_ns
    warnings = end_payload_warnings(refbox, t0, exact_2015=exact_2015)
    runs, logged_score = _bmbox_runs(bmbox)
    ref_changes = refbox.changes() if refbox is not None else None
    cli_changes = client.changes() if client is not None else None
    out: list[Fbm1Run] = []
    for k, run in enumerate(runs):
        lo: int | None = None
        if k > 0:
            prev = runs[k - 1]
            lo = prev.goal_ns if prev.goal_ns is not None else prev.start_ns
        hi = run.goal_ns if run.goal_ns is not None else run.end_ns
        refbox_item = _refbox_item(ref_changes, lo, hi)
        # @Work the RefBox chose the item; @Home the BmBox did. Each falls back on the other.
        first, second = (refbox_item, run.item) if benchmark == "fbm1w" else (run.item, refbox_item)
        item = first or second
        answer_payload: str | None = None
        answer_ns: int | None = None
        ended_by: str | None = None
        if run.goal_ns is not None:
            nxt = runs[k + 1].start_ns if k + 1 < len(runs) else None
            if cli_changes is not None:
                done = cli_changes.window(run.goal_ns, nxt)
                hits = [
                    i for i, s in enumerate(done.state.tolist()) if s == ClientState.COMPLETED_GOAL
                ]
                if hits:
                    answer_payload = done.payload[hits[0]]
                    answer_ns = int(done.t_ns[hits[0]])
            for end in refbox_ends(refbox, run.goal_ns, nxt, exact_2015=exact_2015):
                if answer_ns is not None and end.t_ns >= answer_ns:
                    break
                if end.reason.ends_early:  # any other END (warned above) is neither
                    ended_by = _ENDED_BY[end.reason]
                    break
            if ended_by is not None and answer_ns is not None:
                # The RefBox ended the run before the robot answered: 2015 ignored the answer.
                answer_payload = answer_ns = None
        out.append(
            replace(
                run,
                item=item,
                answer_payload=answer_payload,
                answer_ns=answer_ns,
                ended_by=ended_by,
            )
        )
    cut = log_cut(bmbox, refbox, exact_2015=exact_2015)
    if cut is not None:
        out = _stopped_at_cut(out, cut, bmbox, t0, warnings)
    if items_order is not None:
        out = _apply_order(out, items_order, warnings)
    said = end_payload_deviation(refbox, t0, exact_2015=exact_2015)
    return RunsFound(tuple(out), tuple(warnings), logged_score, () if said is None else (said,))


def _stopped_at_cut(
    runs: list[Fbm1Run], cut_ns: int, bmbox: StateStream, t0_ns: int, warnings: list[str]
) -> list[Fbm1Run]:
    """The log ends inside the benchmark: the run in progress is stopped there (2015 on a
    stop: counted in ``runs``, no answer, no time), and the output says so."""
    last = runs[-1] if runs else None
    if last is None or last.result_ns is not None or last.ended_by is not None:
        warnings.append(cut_warning(cut_ns, bmbox, t0_ns, "the benchmark", "no run was open"))
        return runs
    k = last.index
    if last.goal_ns is None:
        what = f"run {k} is stopped before its goal (aborted)"
    elif last.answer_payload is None:
        what = f"run {k} is stopped without answer (counted, score 0, no time)"
    else:
        # The answer came before the log ended: the node had it (the BmBox's READY is what
        # the log lacks), so the run is scored; its time is unknown.
        what = f"run {k} was answered before the log ended and is scored"
    warnings.append(cut_warning(cut_ns, bmbox, t0_ns, f"run {k}", what))
    if last.goal_ns is None or last.answer_payload is not None:
        return runs
    return [*runs[:-1], replace(last, ended_by="stop")]


def _refbox_item(changes: StateStream | None, lo: int | None, hi: int) -> ItemRef | None:
    """The last non-empty RefBox payload of EXECUTING_MANUAL_OPERATION or EXECUTING_GOAL in
    (lo, hi].

    scripts/fbm1w (2015) took the item from what ``ManualOperation()`` returned: the RefBox
    payload in force when the BmBox left WAITING_MANUAL_OPERATION, i.e. that of the RefBox's
    EXECUTING_GOAL confirming the placement; a RefBox that named the item only while it
    executed the manual operation is read there.
    """
    if changes is None:
        return None
    window = changes.window(None if lo is None else lo + 1, hi)
    found: ItemRef | None = None
    for s, p in zip(window.state.tolist(), window.payload, strict=True):
        if s in (RefBoxState.EXECUTING_MANUAL_OPERATION, RefBoxState.EXECUTING_GOAL):
            found = parse_item_ref(p, "refbox payload") or found
    return found


def _apply_order(runs: list[Fbm1Run], order: Sequence[str], warnings: list[str]) -> list[Fbm1Run]:
    if len(order) != len(runs):
        beyond = (
            " (runs after them keep the item their payload names)" if len(order) < len(runs) else ""
        )
        warnings.append(
            f"--items-order names {len(order)} item(s) but the log has {len(runs)} run(s); "
            f"runs are matched in order{beyond}"
        )
    out = []
    for k, run in enumerate(runs):
        # Past the end of the order a run keeps its payload's item: a short --items-order
        # (fixing the first runs) must not erase what the log says of the others.
        out.append(
            replace(run, item=parse_item_ref(order[k], "--items-order")) if k < len(order) else run
        )
    return out
