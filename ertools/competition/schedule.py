"""The order in which executions go to the workers: the longest expected first.

With two workers, a day ends when its last execution ends: handed out in time order, a
costly FBM1@Home execution taken last leaves the other worker idle for most of it. Handed
out longest first, the short ones fill the gaps at the end (the longest-processing-time
rule: within 4/3 of the best order).

An execution's cost is not known before it is scored, and its span says little (FBM1@Home's
executions are the shortest and cost the most: docs/performance.md), so the schedule
learns each benchmark's mean time from the outcomes as they arrive (and from this run's
cache hits, which carry the time they took): one execution of every benchmark not yet
measured is handed out first, then the benchmark with the longest mean time, in plan order
within a benchmark. The order changes when work is done, never what is computed: results
are listed in plan order whatever order they were scored in.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from ertools.competition.jobs import Job, Outcome


class Schedule:
    """The jobs still to hand out, and what each benchmark's executions took so far."""

    def __init__(self, jobs: Sequence[Job], known: Iterable[tuple[str, float]] = ()) -> None:
        """``known``: (benchmark, seconds) of executions already timed (cache hits)."""
        self._pending: dict[str, list[Job]] = {}
        for job in jobs:
            self._pending.setdefault(job.benchmark, []).append(job)
        self._benchmark = {job.id: job.benchmark for job in jobs}
        self._total: dict[str, float] = {}
        self._count: dict[str, int] = {}
        self._running: dict[str, int] = {}
        for benchmark, seconds in known:
            self._add(benchmark, seconds)

    def __len__(self) -> int:
        return sum(len(jobs) for jobs in self._pending.values())

    def _add(self, benchmark: str, seconds: float) -> None:
        self._total[benchmark] = self._total.get(benchmark, 0.0) + max(seconds, 0.0)
        self._count[benchmark] = self._count.get(benchmark, 0) + 1

    def mean(self, benchmark: str) -> float | None:
        """The mean time of ``benchmark``'s executions so far (None: none timed yet)."""
        n = self._count.get(benchmark, 0)
        return self._total[benchmark] / n if n else None

    def next(self) -> Job | None:
        """The next job to hand out (None: none left)."""
        waiting = [b for b, jobs in self._pending.items() if jobs]
        if not waiting:
            return None
        # a benchmark never timed nor running: one of its executions first, to learn its cost
        unknown = [b for b in waiting if self.mean(b) is None and not self._running.get(b)]
        if unknown:
            chosen = unknown[0]
        else:
            # the longest mean first; a benchmark still being learnt counts as the longest
            chosen = max(waiting, key=lambda b: (self.mean(b) is None, self.mean(b) or 0.0))
        self._running[chosen] = self._running.get(chosen, 0) + 1
        return self._pending[chosen].pop(0)

    def done(self, outcome: Outcome) -> None:
        """Learn from ``outcome`` (of a job this schedule handed out) what its benchmark costs."""
        benchmark = self._benchmark.get(outcome.id)
        if benchmark is None:
            return
        self._running[benchmark] = max(0, self._running.get(benchmark, 0) - 1)
        if outcome.status != "failed":  # a dead worker's time says nothing of the scoring
            self._add(benchmark, outcome.seconds)
