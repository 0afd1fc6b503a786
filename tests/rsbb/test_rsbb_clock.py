"""``ertools.rsbb.clock.goal_times`` against the replays' World: the script's start and end times
and the goal's outcome for every way a goal can go (a result, a timeout, a timeout while the
robot prepared, a stop before the robot started, during the goal, the log's end)."""

from __future__ import annotations

from typing import Any

import pytest

from ertools.rsbb.clock import goal_times
from ertools.rsbb.log import GoalEvent, GoalOutcome
from tests.helpers.rsbb_replay.world import GoalObject, TGoal, Timeline, World

S = 1_000_000_000
T0 = 1_555_000_000 * S


def _world_view(goal: TGoal, stop_ns: int | None) -> tuple[int, int, bool | None, bool]:
    """What the script's ``request_goal``/``wait_goal_result`` gave in the World."""
    tl = Timeline(t_ready_ns=T0, stop_ns=stop_ns, goals=[goal])
    w = World(tl)
    obj = GoalObject({}, 10)
    w.request_goal(obj)
    start = w.now()
    w.wait_goal_result()
    end = w.now()
    return start, end, obj.has_timed_out(), obj.has_been_completed()


CASES: dict[str, tuple[Any, ...]] = {
    # name: (t_start, t_end, outcome, stop)
    "result": (T0 + 2 * S, T0 + 5 * S, GoalOutcome.RESULT, None),
    "timeout": (T0 + 2 * S, T0 + 9 * S, GoalOutcome.TIMEOUT, None),
    "prep-timeout": (None, T0 + 9 * S, GoalOutcome.TIMEOUT, None),
    "stop-during": (T0 + 2 * S, T0 + 4 * S, GoalOutcome.STOPPED, T0 + 4 * S),
    "stop-before-start": (None, T0 + 3 * S, GoalOutcome.STOPPED, T0 + 3 * S),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_goal_times_are_the_worlds(case: str) -> None:
    t_start, t_end, outcome, stop = CASES[case]
    event = GoalEvent(
        0, T0 + S, t_start, t_end, outcome, "{}" if outcome is GoalOutcome.RESULT else None, "{}\n"
    )
    tgoal = TGoal(
        t_start, t_end if outcome is not GoalOutcome.STOPPED else None, outcome.value, "{}"
    )
    got = goal_times(event, T0 + S // 2, stop)
    assert got is not None
    assert (got.start_ns, got.end_ns, got.timeout, got.completed) == _world_view(tgoal, stop)


def test_the_log_ending_first_gives_nothing() -> None:
    event = GoalEvent(0, T0 + S, T0 + 2 * S, None, GoalOutcome.UNFINISHED, None, None)
    assert goal_times(event, T0, None) is None
