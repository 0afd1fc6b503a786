"""An HPPF run's goals found in its events: the script's loop (docs/hppf.md, "Control flow")
walked over the log, each iteration with the person drawn, the manual operations, the two
lookups (a check before the goal, the ground truth after it) and the goal.

The script's clock is the log's (docs/rsbb.md, "Timing in the log"): a manual operation
returns at the RefBox's READY, the goal calls as :func:`ertools.rsbb.clock.goal_times` says,
each lookup as :func:`ertools.rsbb.tf.helper_lookup` finds it among the ``/person``
broadcasts (three attempts of 1 s). A completed goal whose ground truth cannot be looked up is
restarted by the script: the same goal number, a new draw.
"""

from __future__ import annotations

from collections.abc import Sequence

from ertools.arrays import I64
from ertools.frozen_dataclass import frozen_dataclass
from ertools.rsbb.clock import GoalTimes, goal_times
from ertools.rsbb.log import GoalEvent, ManualOperationEvent, RsbbRun
from ertools.rsbb.tf import TfTrack, helper_lookup

ENTER = (
    " should enter the target area wearing a cap with MoCap markers, and place him/herself in "
    "an arbitrary position."
)
RETRY_PREFIX = "Could not get "
ATTEMPTS = 3  # the helper's max_failed_attempts (l. 104, 125, 172)
TIMEOUT_S = 1.0


def entered(request: str) -> str | None:
    """The person a first manual operation's request names (None: not that request)."""
    return request[: -len(ENTER)] if request.endswith(ENTER) else None


def retry_text(person: str) -> str:
    """The manual operation after a failed check (l. 107)."""
    return (
        f"Could not get {person}'s pose. Make sure (s)he is inside the designated area and "
        "wearing the markerset cap."
    )


@frozen_dataclass
class Iteration:
    """One pass of the script's loop.

    Attributes:
        index: the goal number ``i`` (from 0; a restarted goal's next pass has the same).
        person: the person drawn (the first manual operation's text).
        enter: the first manual operation.
        retries: the manual operations after failed checks.
        check_ns: the check lookup's moment (None: it never succeeded).
        goal: the goal (None: the pass ended before it).
        times: the script's view of the goal (None: no goal, or the log ends first).
        truth_ns: the ground-truth lookup's moment after a completed goal (None: failed).
        restarted: a completed goal without ground truth: the script restarted it.
        cut: the pass ended early: ``stop`` (the benchmark stopped) or ``log`` (the log ends).
    """

    index: int
    person: str
    enter: ManualOperationEvent
    retries: tuple[ManualOperationEvent, ...] = ()
    check_ns: int | None = None
    goal: GoalEvent | None = None
    times: GoalTimes | None = None
    truth_ns: int | None = None
    restarted: bool = False
    cut: str | None = None


@frozen_dataclass
class HppfRuns:
    """The passes of a run, the people of the config, and what did not fit the flow."""

    iterations: tuple[Iteration, ...]
    people: tuple[str, ...]
    problems: tuple[str, ...] = ()


class FlowError(Exception):
    """The log does not follow the script (a person not in the config, a missing event)."""


def walk(
    run: RsbbRun,
    people: Sequence[str],
    stamps: I64,
    actor: TfTrack | None,
) -> HppfRuns:
    """The script's loop over the run's events.

    Raises:
        FlowError: a first manual operation names someone the config's people lack.
    """
    stop = run.t_end_ns if run.end_kind.value in ("stop", "global_timeout") else None
    until = run.t_end_ns if run.end_kind.value == "log_ends" else None
    waits = (actor,) if actor is not None else ()
    manual = list(run.manual_operations)
    goals = list(run.goals)
    left = list(people)
    n = len(left)
    clock = run.t_start_ns or 0
    bi, i = 0, 0
    out: list[Iteration] = []
    problems: list[str] = []

    def running() -> bool:
        return stop is None or clock < stop

    def lookup(at: int) -> tuple[int | None, int]:
        nonlocal bi
        found = helper_lookup(
            stamps,
            bi,
            at,
            attempts=ATTEMPTS,
            timeout_s=TIMEOUT_S,
            stop_ns=stop,
            waits=waits,
            until_ns=until,
        )
        bi = found.next_index
        return found.stamp_ns, found.clock_ns

    while running() and i < n:
        if not manual:
            break  # the log ends before the next person was asked for
        enter = manual.pop(0)
        person = entered(enter.request)
        if person is None:
            problems.append(f"goal {i}: expected a person's entry, got {enter.request!r}")
            continue
        if person not in left:
            raise FlowError(
                f"goal {i} asks for {person!r}, who is not among the config's people left "
                f"({', '.join(left) or 'none'}): give the HPPF.yaml the run used (--config)"
            )
        left.remove(person)
        if enter.t_done_ns is None:
            out.append(Iteration(i, person, enter, cut="stop" if stop is not None else "log"))
            break
        clock = enter.t_done_ns
        check, clock = lookup(clock)
        retries: list[ManualOperationEvent] = []
        cut = None
        while check is None:
            if not running() or not manual:
                cut = "stop" if not running() else "log"
                break
            retry = manual.pop(0)
            retries.append(retry)
            if retry.t_done_ns is None:
                cut = "stop" if stop is not None else "log"
                break
            clock = retry.t_done_ns
            check, clock = lookup(clock)
        if cut is not None:
            out.append(Iteration(i, person, enter, tuple(retries), cut=cut))
            break
        goal = goals.pop(0) if goals else None
        times = None if goal is None else goal_times(goal, clock, stop)
        if goal is None or times is None:
            out.append(Iteration(i, person, enter, tuple(retries), check, goal, None, cut="log"))
            break
        clock = times.end_ns
        truth = None
        if times.completed:
            truth, clock = lookup(clock)
            if truth is None:
                out.append(
                    Iteration(i, person, enter, tuple(retries), check, goal, times, None, True)
                )
                left.append(person)
                continue
        out.append(Iteration(i, person, enter, tuple(retries), check, goal, times, truth))
        if not running():
            break
        i += 1
    return HppfRuns(tuple(out), tuple(people), tuple(problems))
