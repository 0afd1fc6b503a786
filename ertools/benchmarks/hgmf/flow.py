"""HGMF's control flow followed on the log: what the script did for each object, and when
(fbm6_grasping_manipulation.py at 2bb8a41, l. 87-259; docs/hgmf.md, "Control flow").

Per object: the referee places it (a manual operation); the script looks its height up (the
helper: 3 attempts of 1 s; while that fails, the referee is asked again); a goal with the
target; when the robot completed it, the object's final position (3 attempts). A failed final
lookup restarts the goal with the same index. The moments are the log's (the RefBox's states,
the script's ``/object`` broadcasts), as :mod:`ertools.rsbb.clock` and
:func:`ertools.rsbb.tf.helper_lookup` read them; one pass over the run's few events.
"""

from __future__ import annotations

import math
from typing import Any

import yaml

from ertools.arrays import I64
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.clock import GoalTimes, goal_times
from ertools.rsbb.log import EndKind, GoalEvent, RsbbRun
from ertools.rsbb.tf import TfTrack, helper_lookup
from ertools.yamlin import load

ATTEMPTS = 3
ATTEMPT_S = 1.0
PLACE_START = "Place the "
PLACE_END = " on the table, with MoCap markers attached."


@frozen_dataclass
class Attempt:
    """One goal the script sent (goal ``index`` of the score; a restarted goal's attempts
    share it).

    Attributes:
        index: the score's ``goal_<index>``.
        goal: the log's goal event (None: the benchmark stopped before the script sent it).
        object_id: the object's id (the goal's payload), None when unreadable.
        target: the target (x, y) as the payload carries it (the script's exact floats).
        placed: the object the referee was asked to place (the manual operation's text).
        ref_ns: the reference height's lookup (its ``now``).
        times: the goal as the script saw it (start, end, timeout, completed).
        final_ns: the final position's lookup, None when none succeeded.
        restarted: completed, its final lookup failed: the script ran the goal again.
    """

    index: int
    goal: GoalEvent | None
    object_id: int | None
    target: tuple[float, float] | None
    placed: str
    ref_ns: int
    times: GoalTimes
    final_ns: int | None
    restarted: bool


@frozen_dataclass
class HgmfFlow:
    """The script's run through the log.

    Attributes:
        t_start_ns: ``execute()`` began (the RefBox's EXECUTING_BENCHMARK).
        attempts: every goal sent, in order.
        begun: the indices whose ``goal_<i>`` the script set to ``{}`` (every iteration's).
        stop_ns: the referee's stop or the global timeout (the log's end when it ends first).
        stop_kind: the run's end as the RefBox published it.
        log_ended: the log ends while the script still ran.
        remarks: what a referee should know of the flow.
    """

    t_start_ns: int
    attempts: tuple[Attempt, ...]
    begun: tuple[int, ...]
    stop_ns: int | None
    stop_kind: EndKind
    log_ended: bool
    remarks: tuple[str, ...]


def goal_payload(text: str | None) -> tuple[tuple[float, float] | None, int | None]:
    """``[target_x, target_y, id]`` of a goal's payload (the script's ``yaml.dump``)."""
    if text is None:
        return None, None
    try:
        value: Any = load(text)
    except yaml.YAMLError:
        return None, None
    if not (isinstance(value, list) and len(value) == 3):
        return None, None
    x, y, ident = value
    numbers = all(isinstance(v, int | float) and not isinstance(v, bool) for v in (x, y))
    if not numbers or not (math.isfinite(float(x)) and math.isfinite(float(y))):
        return None, None
    whole = isinstance(ident, int) and not isinstance(ident, bool)
    return (float(x), float(y)), (ident if whole else None)


def placed_object(request: str) -> str:
    """The description in ``Place the <description> on the table, ...`` ("" if not so)."""
    if request.startswith(PLACE_START) and request.endswith(PLACE_END):
        return request[len(PLACE_START) : -len(PLACE_END)]
    return ""


class _Script:
    """The script's clock and the log's queues of goals, manual operations and lookups."""

    def __init__(
        self, run: RsbbRun, stamps: I64, waits: tuple[TfTrack, ...], stop: int | None, end: int
    ) -> None:
        self.clock = int(run.t_start_ns or 0)
        self.stop = stop
        self.end = end
        self.goals = list(run.goals)
        self.manual = list(run.manual_operations)
        self.stamps = stamps
        self.next_stamp = 0
        self.waits = waits
        self.remarks: list[str] = []

    def running(self) -> bool:
        return self.stop is None or self.clock < self.stop

    def to_stop(self) -> None:
        self.clock = max(self.clock, self.stop if self.stop is not None else self.end)

    def manual_operation(self) -> str | None:
        """``request_manual_operation``: the request's text once completed, None when the
        benchmark stopped first (or the log has no more)."""
        if not self.running():
            return None
        if not self.manual:
            self.remarks.append("the script asked the referee something the log does not have")
            self.to_stop()
            return None
        mo = self.manual.pop(0)
        if mo.t_done_ns is None or (self.stop is not None and self.stop <= mo.t_done_ns):
            self.to_stop()
            return None
        self.clock = max(self.clock, mo.t_done_ns)
        return mo.request

    def lookup(self) -> int | None:
        out = helper_lookup(
            self.stamps,
            self.next_stamp,
            self.clock,
            attempts=ATTEMPTS,
            timeout_s=ATTEMPT_S,
            stop_ns=self.stop,
            waits=self.waits,
            until_ns=self.end,
        )
        self.clock, self.next_stamp = out.clock_ns, out.next_index
        return out.stamp_ns


def script_flow(
    run: RsbbRun, stamps: I64, waits: tuple[TfTrack, ...], objects: int, log_end_ns: int
) -> HgmfFlow:
    """The script followed through ``run`` with its logged ``/object`` lookups ``stamps``
    (``waits``: the table and the object's marker set, whose data each lookup waited for)."""
    if run.end_kind in (EndKind.STOP, EndKind.GLOBAL_TIMEOUT, EndKind.OTHER):
        stop: int | None = run.t_end_ns
    elif run.end_kind is EndKind.LOG_ENDS:
        stop = log_end_ns
    else:
        stop = None
    s = _Script(run, stamps, waits, stop, log_end_ns)
    start = s.clock
    attempts: list[Attempt] = []
    begun: list[int] = []
    i = 0
    while s.running() and i < objects:
        begun.append(i)
        request = s.manual_operation()
        if request is None:
            break
        placed = placed_object(request)
        if not placed:
            s.remarks.append(f"goal_{i}: the referee was asked {request!r}, not to place an object")
        ref = s.lookup()
        while ref is None:  # "Could not get the <object>'s pose...": asked again
            if s.manual_operation() is None:
                break
            ref = s.lookup()
        if ref is None:
            break
        goal = s.goals.pop(0) if s.running() and s.goals else None
        if goal is None and s.running():
            s.remarks.append(f"goal_{i}: the script sent a goal the log does not have")
            break
        # stopped just after the lookup: request_goal and wait_goal_result return at once
        times = (
            goal_times(goal, s.clock, s.stop)
            if goal is not None
            else GoalTimes(s.clock, s.clock, None, False)
        )
        if times is None:  # the log ends before the goal did
            s.to_stop()
            break
        s.clock = times.end_ns
        target, ident = goal_payload(None if goal is None else goal.request)
        final = s.lookup() if times.completed else None
        restarted = times.completed and final is None
        attempts.append(Attempt(i, goal, ident, target, placed, ref, times, final, restarted))
        if restarted:
            continue  # the object goes back in the list; the same index, if still running
        if not s.running():
            break
        i += 1
    log_ended = run.end_kind is EndKind.LOG_ENDS
    return HgmfFlow(
        start, tuple(attempts), tuple(begun), stop, run.end_kind, log_ended, tuple(s.remarks)
    )
