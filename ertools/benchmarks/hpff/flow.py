"""HPFF's samples: the script's own, followed through the log, or ertools' 2 Hz grid.

The script (docs/hpff.md, "Control flow") checks the robot and the person once (3 attempts of
0.5 s, the referee asked while it fails), requests its one goal, sleeps 8 s, then samples
until the goal ends: each sample a relative lookup (the robot in the cap's frame) and an
absolute one (in the testbed), one 0.2 s attempt each, the rest of the 0.5 s slept. The
moments are the log's (:mod:`ertools.benchmarks.hnf.flow` explains them): each successful
lookup is a logged ``/robot`` broadcast; the schedule between them is the script's own
arithmetic (``0.5 - elapsed.to_sec()`` slept, rounded to nanoseconds by ``rospy.sleep``).
"""

from __future__ import annotations

import numpy as np

from ertools.arrays import I64
from ertools.benchmarks.hpff.config import PERIOD_S, SETTLE_S
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.log import EndKind, GoalEvent, GoalOutcome, RsbbRun
from ertools.rsbb.py2 import to_sec
from ertools.rsbb.tf import TfTrack, helper_lookup

PROMPT_START = "Failed to acquire pose of human or robot"
NS = 1_000_000_000


@frozen_dataclass(eq=False)
class HpffFlow:
    """The samples of a run and the moments around them.

    Attributes:
        t_start_ns: ``execute()`` began (the RefBox's EXECUTING_BENCHMARK).
        goal: the run's goal (None: the script never requested it).
        started_ns: the script's ``benchmark_start_time`` (after ``request_goal``).
        sample_ns: (K,) each sample's start.
        relative_ns, absolute_ns: (K,) each sample's lookup moments (-1: the lookup failed).
        end_ns: the loop's end (``benchmark_end_time``), None when the script returned first.
        stopped: the script returned from its loop (a stop): its score is ``{}``.
        never_returned: the benchmark stopped before the goal: the script loops for ever.
        stop_ns, stop_kind: the run's stop (referee, global timeout, or the log's end).
        log_ended: the log ends while the script ran.
        remarks: what a referee should know of the flow.
    """

    t_start_ns: int
    goal: GoalEvent | None
    started_ns: int | None
    sample_ns: I64
    relative_ns: I64
    absolute_ns: I64
    end_ns: int | None
    stopped: bool
    never_returned: bool
    stop_ns: int | None
    stop_kind: EndKind
    log_ended: bool
    remarks: tuple[str, ...]

    @property
    def relative_ok(self) -> np.ndarray:
        return np.asarray(self.relative_ns >= 0)

    @property
    def absolute_ok(self) -> np.ndarray:
        return np.asarray(self.absolute_ns >= 0)


def _stop_of(run: RsbbRun, log_end_ns: int) -> int | None:
    if run.end_kind in (EndKind.STOP, EndKind.GLOBAL_TIMEOUT, EndKind.OTHER):
        return run.t_end_ns
    if run.end_kind is EndKind.LOG_ENDS:
        return log_end_ns
    return None


def _executed(g: GoalEvent | None, clock: int, stop: int | None) -> bool:
    return (
        g is not None
        and g.outcome in (GoalOutcome.RESULT, GoalOutcome.TIMEOUT)
        and g.t_end_ns is not None
        and g.t_end_ns <= clock
        and (stop is None or g.t_end_ns < stop)
    )


def script_flow(
    run: RsbbRun, stamps: I64, robot: TfTrack, actor: TfTrack, log_end_ns: int
) -> HpffFlow:
    """The script's samples, followed through the log."""
    stop = _stop_of(run, log_end_ns)
    clock = start = int(run.t_start_ns or 0)
    remarks: list[str] = []
    index = 0

    def running() -> bool:
        return stop is None or clock < stop

    def lookup(attempts: int, timeout_s: float, waits: tuple[TfTrack, ...]) -> int:
        nonlocal clock, index
        out = helper_lookup(
            stamps,
            index,
            clock,
            attempts=attempts,
            timeout_s=timeout_s,
            stop_ns=stop,
            waits=waits,
            until_ns=log_end_ns,
        )
        clock, index = out.clock_ns, out.next_index
        return -1 if out.stamp_ns is None else out.stamp_ns

    def flow(**kw: object) -> HpffFlow:
        base: dict[str, object] = dict(
            t_start_ns=start,
            goal=None,
            started_ns=None,
            sample_ns=np.empty(0, np.int64),
            relative_ns=np.empty(0, np.int64),
            absolute_ns=np.empty(0, np.int64),
            end_ns=None,
            stopped=False,
            never_returned=False,
            stop_ns=stop,
            stop_kind=run.end_kind,
            log_ended=run.end_kind is EndKind.LOG_ENDS,
            remarks=tuple(remarks),
        )
        base.update(kw)
        return HpffFlow(**base)  # type: ignore[arg-type]

    manual = list(run.manual_operations)
    while lookup(3, 0.5, (robot, actor)) < 0:
        if not running():
            return flow(never_returned=True)
        if not manual:
            remarks.append("the script asked the referee a question the log does not have")
            return flow(never_returned=True)
        mo = manual.pop(0)
        if not mo.request.startswith(PROMPT_START):
            remarks.append(f"the referee was asked {mo.request!r}, not HPFF's prompt")
        if mo.t_done_ns is None or (stop is not None and stop <= mo.t_done_ns):
            clock = max(clock, stop if stop is not None else log_end_ns)
            return flow(never_returned=True)
        clock = max(clock, mo.t_done_ns)
    if not run.goals:
        remarks.append("the script requested a goal the log does not have")
        return flow(never_returned=True)
    goal = run.goals[0]
    returns = goal.t_start_ns
    if returns is None and goal.outcome is GoalOutcome.TIMEOUT:
        returns = goal.t_end_ns
    if returns is None or (stop is not None and stop <= returns):
        clock = max(clock, stop if stop is not None else log_end_ns)
    else:
        clock = max(clock, returns)
    started = clock
    clock += round(SETTLE_S * NS)  # rospy.sleep: a stop does not cut it short
    samples: list[int] = []
    relative: list[int] = []
    absolute: list[int] = []
    while not _executed(goal, clock, stop):
        sample_start = clock
        samples.append(sample_start)
        relative.append(lookup(1, 0.2, (robot, actor)))
        absolute.append(lookup(1, 0.2, (robot,)))
        remaining = PERIOD_S - to_sec(clock - sample_start)
        if remaining > 0:
            clock += round(remaining * NS)
        if not running():
            return flow(
                goal=goal,
                started_ns=started,
                sample_ns=np.array(samples, np.int64),
                relative_ns=np.array(relative, np.int64),
                absolute_ns=np.array(absolute, np.int64),
                stopped=True,
            )
    return flow(
        goal=goal,
        started_ns=started,
        sample_ns=np.array(samples, np.int64),
        relative_ns=np.array(relative, np.int64),
        absolute_ns=np.array(absolute, np.int64),
        end_ns=clock,
    )


def grid_flow(run: RsbbRun, log_end_ns: int) -> HpffFlow:
    """ertools' samples: every 0.5 s from 8 s after the robot's start (the RefBox's
    EXECUTING_GOAL) until the goal's end, the stop or the log's end."""
    stop = _stop_of(run, log_end_ns)
    start = int(run.t_start_ns or 0)
    goal = run.goals[0] if run.goals else None
    if goal is None or goal.t_start_ns is None:
        return HpffFlow(
            start,
            goal,
            None,
            np.empty(0, np.int64),
            np.empty(0, np.int64),
            np.empty(0, np.int64),
            None,
            False,
            True,
            stop,
            run.end_kind,
            run.end_kind is EndKind.LOG_ENDS,
            (),
        )
    ends = [t for t in (goal.t_end_ns, stop, log_end_ns) if t is not None]
    end = min(ends)
    first = goal.t_start_ns + round(SETTLE_S * NS)
    step = round(PERIOD_S * NS)
    grid = np.arange(first, end, step, dtype=np.int64) if end > first else np.empty(0, np.int64)
    stopped = stop is not None and (goal.t_end_ns is None or stop <= goal.t_end_ns)
    return HpffFlow(
        start,
        goal,
        goal.t_start_ns,
        grid,
        grid.copy(),
        grid.copy(),
        None if stopped else end,
        stopped,
        False,
        stop,
        run.end_kind,
        run.end_kind is EndKind.LOG_ENDS,
        (),
    )
