"""HNF's control flow followed on the log: what the script did at each waypoint, and when.

The script (docs/hnf.md, "Control flow") requests one goal per waypoint, times it, then looks
the robot up (the helper: 5 attempts of 1 s; no limit before 00e3106), asks the referee to try
again or skip (``s``) while it fails (from 00e3106), and returns without totals when the
benchmark stops before the pose (from 00e3106). Its moments are the log's: ``execute()``
starts at the RefBox's EXECUTING_BENCHMARK, ``request_goal`` returns at the goal's
EXECUTING_GOAL (at its READY when it timed out before the robot started), ``wait_goal_result``
at its READY, a manual operation at the referee's answer, a stop at the RefBox's STOP or
GLOBAL_TIMEOUT, a successful lookup at its broadcast's stamp. One pass over the run's few
events; the poses are computed afterwards, vectorised (:mod:`ertools.benchmarks.hnf.formula`).
"""

from __future__ import annotations

from typing import Any

import yaml

from ertools.arrays import I64
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.log import EndKind, GoalEvent, GoalOutcome, RsbbRun
from ertools.rsbb.tf import TfTrack, helper_lookup
from ertools.yamlin import load

#: The referee's prompt when the pose could not be acquired (00e3106 and 2bb8a41).
PROMPT_START = "The position of the robot markerset could not be acquired"
ATTEMPTS = 5
ATTEMPT_S = 1.0


@frozen_dataclass
class SegmentFlow:
    """What the script did for waypoint ``index`` (0-based; the score's ``segment_<index+1>``).

    Attributes:
        index: the waypoint's position in the config.
        goal: the log's goal event (None: the log has no goal for it).
        start_ns, end_ns: the script's ``start_segment_time`` and ``end_segment_time``.
        timeout: ``goal.has_timed_out()`` (None: neither result nor timeout, a stop came).
        completed: ``goal.has_been_completed()``.
        result: the robot's result as the BmBox parsed it (``completed`` only).
        lookup_ns: the successful lookup's ``now`` (None: no pose).
        answers: the referee's answers to the prompt, in order (None: not executed, the
            benchmark had stopped).
        skipped: the referee answered ``s``.
        poses_written: the script wrote ``target_pose`` and ``robot_pose``.
        interrupted: the script returned during this segment's lookup (a stop): no totals.
    """

    index: int
    goal: GoalEvent | None
    start_ns: int
    end_ns: int
    timeout: bool | None
    completed: bool
    result: Any
    lookup_ns: int | None
    answers: tuple[str | None, ...]
    skipped: bool
    poses_written: bool
    interrupted: bool


@frozen_dataclass
class HnfFlow:
    """The script's run through the log.

    Attributes:
        script: the commit followed.
        t_start_ns: ``start_benchmark_time`` (the RefBox's EXECUTING_BENCHMARK).
        segments: the waypoints the script got to, in order.
        totals: the script reached its totals (it did not return early).
        stop_ns: when the benchmark stopped (referee or global timeout; the log's end when it
            ends first), or None.
        stop_kind: the run's end as the RefBox published it.
        log_ended: the log ends while the script still ran (scored as if it stopped there).
        remarks: what a referee should know of the flow (a prompt text that differs...).
    """

    script: str
    t_start_ns: int
    segments: tuple[SegmentFlow, ...]
    totals: bool
    stop_ns: int | None
    stop_kind: EndKind
    log_ended: bool
    remarks: tuple[str, ...]


def parse_result(text: str | None) -> Any:
    """The robot's result as the BmBox's ``yaml.load`` gave it (read safely here); the text
    itself when it is not YAML."""
    if text is None:
        return None
    try:
        return load(text)
    except yaml.YAMLError:
        return text


class _Script:
    """The script's clock and the log's queues of goals, manual operations and lookups."""

    def __init__(
        self, run: RsbbRun, stamps: I64, body: TfTrack, stop_ns: int | None, end_ns: int
    ) -> None:
        self.clock = int(run.t_start_ns or 0)
        self.stop = stop_ns
        self.end = end_ns
        self.goals = list(run.goals)
        self.manual = list(run.manual_operations)
        self.stamps = stamps
        self.next_stamp = 0
        self.body = body
        self.remarks: list[str] = []

    def running(self) -> bool:
        return self.stop is None or self.clock < self.stop

    def stopped_by(self, t_ns: int) -> bool:
        return self.stop is not None and self.stop <= t_ns

    def to_stop(self) -> None:
        self.clock = max(self.clock, self.stop if self.stop is not None else self.end)

    def request_goal(self) -> GoalEvent | None:
        """``request_goal``: returns when the robot started (or the goal timed out first)."""
        if not self.goals:
            self.remarks.append("the script requested a goal the log does not have")
            self.to_stop()
            return None
        g = self.goals.pop(0)
        returns = g.t_start_ns
        if returns is None and g.outcome is GoalOutcome.TIMEOUT:
            returns = g.t_end_ns  # timed out while the robot prepared
        if returns is None or self.stopped_by(returns):
            self.to_stop()
        else:
            self.clock = max(self.clock, returns)
        return g

    def executed(self, g: GoalEvent | None) -> bool:
        """The goal's result or timeout reached the BmBox (before any stop) by now."""
        return (
            g is not None
            and g.outcome in (GoalOutcome.RESULT, GoalOutcome.TIMEOUT)
            and g.t_end_ns is not None
            and g.t_end_ns <= self.clock
            and not self.stopped_by(g.t_end_ns)
        )

    def wait_goal_result(self, g: GoalEvent | None) -> None:
        if not self.running() or g is None or self.executed(g):
            return
        done = g.outcome in (GoalOutcome.RESULT, GoalOutcome.TIMEOUT)
        if not done or g.t_end_ns is None or self.stopped_by(g.t_end_ns):
            self.to_stop()
        else:
            self.clock = max(self.clock, g.t_end_ns)

    def lookup(self, attempts: int | None) -> int | None:
        """The helper from the current clock: the successful lookup's ``now``, or None."""
        out = helper_lookup(
            self.stamps,
            self.next_stamp,
            self.clock,
            attempts=attempts,
            timeout_s=ATTEMPT_S,
            stop_ns=self.stop,
            waits=(self.body,),
            until_ns=self.end,
        )
        self.clock, self.next_stamp = out.clock_ns, out.next_index
        return out.stamp_ns

    def prompt(self) -> str | None:
        """The referee's prompt: the answer, or None (not completed: the benchmark stopped)."""
        if not self.running():
            return None
        if not self.manual:
            self.remarks.append("the script asked the referee a question the log does not have")
            self.to_stop()
            return None
        mo = self.manual.pop(0)
        if not mo.request.startswith(PROMPT_START):
            self.remarks.append(f"the referee was asked {mo.request!r}, not HNF's prompt")
        if mo.t_done_ns is None or mo.answer is None or self.stopped_by(mo.t_done_ns):
            self.to_stop()
            return None
        self.clock = max(self.clock, mo.t_done_ns)
        return mo.answer


def script_flow(
    run: RsbbRun, stamps: I64, body: TfTrack, n_waypoints: int, script: str, log_end_ns: int
) -> HnfFlow:
    """The script at ``script`` (a commit of :data:`ertools.benchmarks.hnf.config.SEASONS`)
    followed through ``run`` with the logged lookups ``stamps`` of the marker set ``body``."""
    if run.end_kind in (EndKind.STOP, EndKind.GLOBAL_TIMEOUT, EndKind.OTHER):
        stop_ns: int | None = run.t_end_ns
    elif run.end_kind is EndKind.LOG_ENDS:
        stop_ns = log_end_ns
    else:
        stop_ns = None
    s = _Script(run, stamps, body, stop_ns, log_end_ns)
    start = s.clock
    unlimited = script in ("069fd1d", "f594ff1")
    segments: list[SegmentFlow] = []
    totals = True
    i = 0
    while s.running() and i < n_waypoints:
        goal = s.request_goal()
        start_seg = s.clock
        s.wait_goal_result(goal)
        end_seg = s.clock
        executed = s.executed(goal)
        timed_out = (
            None if not executed else goal is not None and goal.outcome is GoalOutcome.TIMEOUT
        )
        completed = executed and not timed_out
        stamp = s.lookup(None if unlimited else ATTEMPTS)
        answers: list[str | None] = []
        skipped = interrupted = False
        while not unlimited and stamp is None:
            answer = s.prompt()
            answers.append(answer)
            if answer == "s":
                skipped = True
                break
            if not s.running():
                interrupted = True
                break
            stamp = s.lookup(ATTEMPTS)
        written = not interrupted and (script != "069fd1d" or stamp is not None)
        segments.append(
            SegmentFlow(
                i,
                goal,
                start_seg,
                end_seg,
                timed_out,
                completed,
                parse_result(goal.result) if completed and goal is not None else None,
                stamp,
                tuple(answers),
                skipped,
                written,
                interrupted,
            )
        )
        if interrupted:
            totals = False
            break
        i += 1
    log_ended = run.end_kind is EndKind.LOG_ENDS or (stop_ns is None and s.clock > log_end_ns)
    return HnfFlow(
        script, start, tuple(segments), totals, stop_ns, run.end_kind, log_ended, tuple(s.remarks)
    )
