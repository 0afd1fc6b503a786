"""The order executions go to the workers (ertools.competition.schedule): one of each benchmark
first to learn its cost, then the longest mean first; a day's last execution is a short one."""

from __future__ import annotations

import heapq

from ertools.competition.jobs import Job, Outcome
from ertools.competition.schedule import Schedule


def jobs(*benchmarks: str) -> list[Job]:
    return [Job(f"{b}-{i}", b, f"x:{b}", None, ()) for i, b in enumerate(benchmarks)]


def ok(job: Job, seconds: float) -> Outcome:
    return Outcome(job.id, "scored", seconds=seconds)


def test_one_of_each_benchmark_first_then_the_longest_mean() -> None:
    plan = jobs("a", "b", "c", "a", "b", "c", "a", "b", "c")
    cost = {"a": 1.0, "b": 5.0, "c": 3.0}
    schedule = Schedule(plan)
    first = [schedule.next() for _ in range(3)]
    assert [j.id for j in first if j] == ["a-0", "b-1", "c-2"]
    for job in first:
        assert job is not None
        schedule.done(ok(job, cost[job.benchmark]))
    assert schedule.mean("b") == 5.0
    rest = []
    while (job := schedule.next()) is not None:
        rest.append(job.id)
        schedule.done(ok(job, cost[job.benchmark]))
    assert rest == ["b-4", "b-7", "c-5", "c-8", "a-3", "a-6"]
    assert len(schedule) == 0


def test_cache_hits_say_what_costs_most_and_failures_teach_nothing() -> None:
    plan = jobs("a", "b", "a", "b")
    schedule = Schedule(plan, known=[("a", 4.0), ("b", 1.0), ("b", 3.0)])
    assert schedule.mean("b") == 2.0
    got = schedule.next()
    assert got is not None and got.id == "a-0"
    schedule.done(Outcome(got.id, "failed", seconds=100.0))  # a dead worker: no time learnt
    assert schedule.mean("a") == 4.0
    assert [j.id for j in iter(schedule.next, None)] == ["a-2", "b-1", "b-3"]


def test_a_benchmark_being_learnt_is_not_started_twice_while_others_are_unknown() -> None:
    schedule = Schedule(jobs("a", "a", "b"))
    assert [schedule.next().id for _ in range(2)] == ["a-0", "b-2"]  # type: ignore[union-attr]
    # nothing timed yet, nothing else unknown: the benchmark still being learnt goes next
    assert schedule.next().id == "a-1"  # type: ignore[union-attr]
    assert schedule.next() is None


def makespan(order: list[float], workers: int) -> float:
    """When the last job ends, each job taken by the first worker free (by hand: a heap)."""
    free = [0.0] * workers
    for cost in order:
        heapq.heappush(free, heapq.heappop(free) + cost)
    return max(free)


def test_a_day_ending_with_its_longest_execution_ends_earlier() -> None:
    # four 2 s executions then an 8 s one, in time order: two workers finish at 4 + 8 = 12 s;
    # the schedule starts the 8 s one at once (a benchmark not yet timed): 8 s, the optimum.
    plan = jobs("x", "x", "x", "x", "y")
    cost = {"x": 2.0, "y": 8.0}
    assert makespan([cost[j.benchmark] for j in plan], 2) == 12.0
    schedule = Schedule(plan)
    free: list[tuple[float, int]] = [(0.0, 0), (0.0, 1)]
    ends = []
    while (job := schedule.next()) is not None:
        start, worker = heapq.heappop(free)
        end = start + cost[job.benchmark]
        ends.append(end)
        schedule.done(ok(job, cost[job.benchmark]))
        heapq.heappush(free, (end, worker))
    assert max(ends) == 8.0
