"""The RSBB as a benchmark script saw it: BmBox calls, the clock, tf, the timer.

A :class:`Timeline` says what happened (each manual operation's end and answer, each goal's
start, end and outcome, the benchmark's stop, the moments of the successful lookups, the
mocap data with arrival times); a :class:`World` answers the script's calls from it the way
``BenchmarkObjects.py`` (2bb8a41) answered them: a blocking call returns at the moment the
timeline gives, or at once when the benchmark no longer runs (docs/rsbb.md, "A run, event by
event"). The replays call the World where the scripts called ``self``, ``rospy`` and the tf
listener, with one addition: each ``rospy.Time.now()`` names what it is for (``lookup``,
``timer``, other), so that a lookup's ``now`` can be taken from the log (its broadcast).
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import yaml

from tests.helpers.rsbb_replay.py2 import dump_request
from tests.helpers.rsbb_replay.tf2 import Buffer, Quat, TfError, Vec, frame

MS = 1_000_000
NS = 1_000_000_000
LOOKUP_SLACK_NS = 50 * MS


class EndlessLoopError(Exception):
    """The script would loop forever (HPFF asking the referee after a stop)."""


@dataclass(frozen=True)
class TManual:
    """A manual operation's outcome: completed at ``t_done_ns`` with ``answer``, or (None)
    interrupted by the stop. ``request``, when given, is checked against the script's text."""

    t_done_ns: int | None
    answer: str | None = ""
    request: str | None = None


@dataclass(frozen=True)
class TGoal:
    """A goal's outcome. ``t_start_ns``: when ``request_goal`` returned (the robot started; None
    if it never did); ``t_end_ns``: when the result or the timeout came (None: the stop came
    first); ``outcome``: ``result``, ``timeout`` or ``stopped``; ``result``: the robot's string.
    ``request``, when given, is checked against the script's payload text."""

    t_start_ns: int | None
    t_end_ns: int | None
    outcome: str
    result: str | None = None
    request: str | None = None


@dataclass
class Timeline:
    """What happened during one run, as the script would meet it.

    Attributes:
        t_ready_ns: the BmBox went READY (``execute()`` starts).
        stop_ns: the RefBox stop or global timeout reached the BmBox (None: never).
        stop_kind: ``stop`` or ``global_timeout``.
        manual: the manual operations in order.
        goals: the goals in order.
        lookups: per broadcast frame (tf spelling, no slash) the stamps of the successful
            lookups (the ``now`` each one took).
        tf: the mocap's links with arrival times (the script's broadcasts are added by the
            world as it makes them).
        params: the benchmark config.
        team: the team.
        files: other inputs (``transform``: the team transform pair, ``items``: the items).
    """

    t_ready_ns: int
    stop_ns: int | None = None
    stop_kind: str = "stop"
    manual: list[TManual] = field(default_factory=list)
    goals: list[TGoal] = field(default_factory=list)
    lookups: dict[str, list[int]] = field(default_factory=dict)
    tf: Buffer = field(default_factory=Buffer)
    params: Any = None
    team: str = "team"
    files: dict[str, Any] = field(default_factory=dict)


class ManualOperationObject:
    """BenchmarkObjects.py's manual operation: a request, and a result once completed."""

    def __init__(self, request: str) -> None:
        self._request = request
        self._executed = False
        self._result: str | None = None

    def get_request(self) -> str:
        return self._request

    def has_been_completed(self) -> bool:
        return self._executed

    def get_result(self) -> str | None:
        return self._result if self._executed else None

    def set_result(self, result: str | None) -> None:
        self._result = result
        self._executed = True


class GoalObject:
    """BenchmarkObjects.py's goal: ``has_timed_out()`` is None until the goal ended."""

    def __init__(self, request: Any = None, timeout: Any = 0) -> None:
        self._request = request
        self._timeout = timeout
        self._executed = False
        self._result: Any = None
        self._has_timed_out: bool | None = None

    def get_request_string(self) -> str:
        return dump_request(self._request)

    def has_been_completed(self) -> bool:
        return self._executed and not self._has_timed_out

    def has_timed_out(self) -> bool | None:
        return self._has_timed_out

    def set_has_timed_out(self) -> None:
        self._has_timed_out = True
        self._executed = True

    def get_result(self) -> Any:
        return self._result if self._executed else None

    def set_result_string(self, text: str) -> None:
        # The BmBox used yaml.load; the answers are plain YAML, read safely here.
        self._result = yaml.safe_load(text)
        self._has_timed_out = False
        self._executed = True


class Timer:
    """A ``rospy.Timer``: ticks at start + k * period (k >= 1), a late callback delays the next."""

    def __init__(self, world: World, period_s: float, callback: Callable[[], None]) -> None:
        self.world = world
        self.period_ns = round(period_s * NS)
        self.callback = callback
        self.start = world.clock
        self.k = 1
        self.free_at = world.clock

    def run_until(self, t_ns: int) -> None:
        """Run the ticks due up to ``t_ns`` (the timer's thread, beside the script's)."""
        while True:
            tick = max(self.start + self.k * self.period_ns, self.free_at)
            if tick > t_ns:
                return
            self.k += 1
            self.free_at = self.world.in_thread(tick, self.callback)

    def shutdown(self) -> None:
        self.run_until(self.world.clock)
        self.world.timers.remove(self)


class World:
    """The BmBox, the RefBox and tf answering a script, from a :class:`Timeline`."""

    def __init__(self, tl: Timeline) -> None:
        self.tl = tl
        self.clock = tl.t_ready_ns
        self.params = copy.deepcopy(tl.params)
        self.score: dict[str, Any] = {}
        self.saves: list[tuple[int, dict[str, Any]]] = []
        self.timers: list[Timer] = []
        self.aborted: str | None = None
        self._manual = list(tl.manual)
        self._goals = list(tl.goals)
        self._used = {f: 0 for f in tl.lookups}
        self._goal: tuple[GoalObject, TGoal] | None = None
        self._attempt: bool | None = None  # a lookup attempt: logged (True) or not (False)
        self._threaded = False
        self._idle_calls = 0

    # -- the clock

    def advance(self, t_ns: int) -> None:
        """Move the script's clock forward (timers tick on the way)."""
        t = max(self.clock, t_ns)
        if not self._threaded:
            for timer in list(self.timers):
                timer.run_until(t)
        self.clock = t
        self._goal_callback()

    def _goal_callback(self) -> None:
        """The RefBox's GoalComplete reaching the BmBox (its own thread): the pending goal
        gets its result or timeout once the clock passes the moment, unless stopped before."""
        if self._goal is None:
            return
        goal, step = self._goal
        end = step.t_end_ns
        if goal._executed or end is None or step.outcome not in ("result", "timeout"):
            return
        if end > self.clock or self._stopped_by(end):
            return
        if step.outcome == "timeout":
            goal.set_has_timed_out()
        else:
            goal.set_result_string(step.result or "")

    def in_thread(self, t_ns: int, callback: Callable[[], None]) -> int:
        """Run ``callback`` at ``t_ns`` on its own clock; the script's clock is kept."""
        main, self.clock, self._threaded = self.clock, t_ns, True
        attempt, self._attempt = self._attempt, None
        try:
            callback()
            return self.clock
        finally:
            self.clock, self._threaded, self._attempt = main, False, attempt

    def now(self, tag: str = "", target: str | None = None, timeout_s: float = 0.0) -> int:
        """``rospy.Time.now()``. ``tag="lookup"`` (a lookup attempt's first statement): the
        next logged lookup of ``target`` (the frame the attempt broadcasts) starting within the
        wait's timeout from the clock, if any: the attempt succeeds with that ``now``; none:
        it fails."""
        if tag != "lookup" or target is None:
            return self.clock
        stamps = self.tl.lookups.get(frame(target), [])
        k = self._used.get(frame(target), 0)
        # The script's clock here is inferred from the RefBox's messages, which follow the
        # script's own moments by a few ms: a logged lookup up to LOOKUP_SLACK earlier is this.
        while k < len(stamps) and stamps[k] < self.clock - LOOKUP_SLACK_NS:
            k += 1
        self._attempt = k < len(stamps) and stamps[k] < self.clock + round(timeout_s * NS)
        if not self._attempt:
            self._used[frame(target)] = k
            return self.clock
        self._used[frame(target)] = k + 1
        self.advance(stamps[k])
        return stamps[k]

    def sleep(self, seconds: float) -> None:
        self.advance(self.clock + round(seconds * NS))

    # -- the benchmark's state

    def is_benchmark_running(self) -> bool:
        if self.aborted is not None:
            return False
        return self.tl.stop_ns is None or self.clock < self.tl.stop_ns

    def has_benchmark_timed_out(self) -> bool:
        return not self.is_benchmark_running() and self.tl.stop_kind == "global_timeout"

    def has_benchmark_been_stopped(self) -> bool:
        return not self.is_benchmark_running() and self.tl.stop_kind == "stop"

    def _stopped_by(self, t_ns: int) -> bool:
        """The stop reaches the BmBox before (or at) ``t_ns``."""
        return self.tl.stop_ns is not None and self.tl.stop_ns <= t_ns

    def _idle(self) -> None:
        self._idle_calls += 1
        if self._idle_calls > 10_000:
            raise EndlessLoopError("the script keeps calling the BmBox after the benchmark stopped")

    def request_manual_operation(self, mo: ManualOperationObject) -> None:
        if not self.is_benchmark_running():
            self._idle()
            return
        if not self._manual:
            raise AssertionError(
                f"the script asks a manual operation the log lacks: {mo.get_request()!r}"
            )
        step = self._manual.pop(0)
        if step.request is not None and step.request != mo.get_request():
            raise AssertionError(
                f"manual operation {mo.get_request()!r}, the log has {step.request!r}"
            )
        if step.t_done_ns is None or self._stopped_by(step.t_done_ns):
            assert self.tl.stop_ns is not None, "a manual operation never completed, and no stop"
            self.advance(self.tl.stop_ns)
            return
        self.advance(step.t_done_ns)
        mo.set_result(step.answer)

    def request_goal(self, goal: GoalObject) -> None:
        if not self.is_benchmark_running():
            self._idle()
            return
        if not self._goals:
            raise AssertionError("the script sends a goal the log lacks")
        step = self._goals.pop(0)
        if step.request is not None and step.request != goal.get_request_string():
            raise AssertionError(
                f"goal {goal.get_request_string()!r}, the log has {step.request!r}"
            )
        self._goal = (goal, step)
        returns = step.t_start_ns if step.t_start_ns is not None else step.t_end_ns
        if step.t_start_ns is None and step.outcome != "timeout":
            returns = None
        if returns is None or self._stopped_by(returns):
            assert self.tl.stop_ns is not None, "a goal never started, and no stop"
            self.advance(self.tl.stop_ns)
            return
        self.advance(returns)  # a timeout while the robot prepared is applied on the way

    def wait_goal_result(self) -> None:
        if not self.is_benchmark_running():
            return
        if self._goal is None:
            return
        goal, step = self._goal
        if goal._executed:
            self._goal = None
            return
        if step.outcome == "stopped" or step.t_end_ns is None or self._stopped_by(step.t_end_ns):
            assert self.tl.stop_ns is not None, "a goal never ended, and no stop"
            self.advance(self.tl.stop_ns)
        else:
            self.advance(step.t_end_ns)  # the outcome is applied on the way
        self._goal = None

    def save_and_publish_score(self) -> None:
        self.saves.append((self.clock, copy.deepcopy(self.score)))

    def abort_benchmark(self, message: str = "") -> None:
        self.aborted = message

    # -- tf

    def wait_for_transform(self, target: str, source: str, t: int, timeout_s: float) -> None:
        """``waitForTransform``; raises :class:`TfError` after ``timeout_s``."""
        until = t + round(timeout_s * NS)
        if self._attempt is False:
            self.advance(until)
            raise TfError(f"no transform {target} -> {source} at {t} within {timeout_s} s")
        if self._attempt:
            # A logged lookup: its broadcast shows the waits succeeded; they returned once the
            # data at t had arrived.
            ready = self.tl.tf.ready_at(frame(target), frame(source), t, self.clock, 2**62)
            if ready is None:
                raise AssertionError(
                    f"the logged lookup of {source} at {t} has no tf data around it"
                )
            self.advance(ready)
            return
        ready = self.tl.tf.ready_at(frame(target), frame(source), t, self.clock, until)
        if ready is None:
            self.advance(until)
            raise TfError(f"no transform {target} -> {source} at {t} within {timeout_s} s")
        self.advance(ready)

    def send_transform(self, xyz: Any, quat: Any, t: int, child: str, parent: str) -> None:
        value: tuple[Vec, Quat] = (
            (float(xyz[0]), float(xyz[1]), float(xyz[2])),
            (float(quat[0]), float(quat[1]), float(quat[2]), float(quat[3])),
        )
        self.tl.tf.add(parent, child, t, self.clock, value)

    def lookup_transform(self, target: str, source: str, t: int) -> tuple[Vec, Quat]:
        return self.tl.tf.lookup(frame(target), frame(source), t, self.clock)

    def start_timer(self, period_s: float, callback: Callable[[], None]) -> Timer:
        timer = Timer(self, period_s, callback)
        self.timers.append(timer)
        return timer


@dataclass(frozen=True)
class ReplayResult:
    """What a replayed run left.

    Attributes:
        score: the result file's ``score`` (the last save).
        saves: every save (clock, score), the live topic's messages.
        crashed: the exception that killed the script (its text), or None.
        never_returned: the script looped forever (its score was saved at the disconnect).
        aborted: HPFF's abort message, or None.
    """

    score: dict[str, Any]
    saves: tuple[tuple[int, dict[str, Any]], ...]
    crashed: str | None
    never_returned: bool
    aborted: str | None


def run_script(world: World, execute: Callable[[World], None]) -> ReplayResult:
    """``wrapped_execute()``: run the script if the benchmark runs, then ``end_benchmark()``."""
    crashed: str | None = None
    never = False
    try:
        if world.is_benchmark_running():
            execute(world)
        world.save_and_publish_score()  # end_benchmark() saves first, always
    except EndlessLoopError:
        never = True
        world.save_and_publish_score()  # terminate_benchmark() at the disconnect
    except (KeyError, IndexError, TypeError, ValueError, ZeroDivisionError, AttributeError) as err:
        crashed = f"{type(err).__name__}: {err}"
    final = world.saves[-1][1] if world.saves else {}
    return ReplayResult(copy.deepcopy(final), tuple(world.saves), crashed, never, world.aborted)


def is_tf_error(err: BaseException) -> bool:
    """What the scripts' ``except (tf.LookupException, ...)`` catches."""
    return isinstance(err, TfError)
