"""What a benchmark script's goal calls returned, and when, read from the log.

Every script sends a goal the same way (``BenchmarkObjects.py`` at 2bb8a41):
``request_goal(goal)``, ``start_time = rospy.Time.now()``, ``wait_goal_result()``,
``end_time = rospy.Time.now()``, then ``goal.has_timed_out()`` (True, False, or None when the
stop came first) and ``goal.has_been_completed()``. :func:`goal_times` gives those four from a
:class:`~ertools.rsbb.log.GoalEvent`, as the replays' World answers them (docs/rsbb.md, "A
run, event by event"): ``request_goal`` returns when the robot started (the RefBox's
EXECUTING_GOAL), or at a timeout during its preparation, or at once when the benchmark has
stopped; ``wait_goal_result`` returns at the result or the timeout (the RefBox's READY), or at
the stop.
"""

from __future__ import annotations

from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.log import GoalEvent, GoalOutcome


@frozen_dataclass
class GoalTimes:
    """A goal as the script saw it.

    Attributes:
        start_ns: ``start_time`` (after ``request_goal``).
        end_ns: ``end_time`` (after ``wait_goal_result``).
        timeout: ``goal.has_timed_out()``: True, False, or None (the stop came first).
        completed: ``goal.has_been_completed()`` (a result, not a timeout).
    """

    start_ns: int
    end_ns: int
    timeout: bool | None
    completed: bool

    @property
    def segment_ns(self) -> int:
        """``end_time - start_time``."""
        return self.end_ns - self.start_ns


def goal_times(goal: GoalEvent, clock_ns: int, stop_ns: int | None) -> GoalTimes | None:
    """The script's start and end times of ``goal`` and what the goal object said.

    Args:
        goal: the goal's events.
        clock_ns: the script's clock when it called ``request_goal`` (the previous event it
            waited for: a manual operation's completion, a lookup).
        stop_ns: when the benchmark stopped (referee stop or global timeout), None if never.

    Returns:
        None when the log ends before the script's calls returned.
    """

    def stopped_by(t: int) -> bool:
        return stop_ns is not None and stop_ns <= t

    ended = goal.outcome in (GoalOutcome.RESULT, GoalOutcome.TIMEOUT) and goal.t_end_ns is not None
    returns = goal.t_start_ns
    if returns is None and ended and goal.outcome is GoalOutcome.TIMEOUT:
        returns = goal.t_end_ns  # timed out while the robot prepared: request_goal ends then
    if returns is None or stopped_by(returns):
        if stop_ns is None:
            return None
        start = max(clock_ns, stop_ns)  # the calls return at once once the stop is known
        return GoalTimes(start, start, None, False)
    start = max(clock_ns, returns)
    if goal.t_start_ns is None:  # the timeout during the preparation: wait_goal_result is done
        return GoalTimes(start, start, True, False)
    if not ended or goal.t_end_ns is None or stopped_by(goal.t_end_ns):
        if stop_ns is None:
            return None
        return GoalTimes(start, max(start, stop_ns), None, False)
    end = max(start, goal.t_end_ns)
    if goal.outcome is GoalOutcome.TIMEOUT:
        return GoalTimes(start, end, True, False)
    return GoalTimes(start, end, False, True)
