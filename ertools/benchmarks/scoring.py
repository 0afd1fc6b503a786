"""The one way a benchmark execution is scored: ``ertools score``, :func:`ertools.score`,
``ertools audit`` (recomputing) and ``ertools rescore`` (each job) all call
:func:`score_execution`, so that they score alike by construction; code that holds options
already (``ertools export``'s trajectory pair, tests) runs the same stages with
:func:`run_stages`."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import (
    AnyBenchmark,
    Audited,
    Benchmark,
    BenchmarkResult,
    LoadedT,
    OptionsT,
    ResultT,
    RunsT,
)
from ertools.benchmarks.common.which import refuse_other_benchmark
from ertools.frozen_dataclass import frozen_dataclass


@frozen_dataclass
class Scored:
    """A scored execution: the result, the options it was scored with, and what was taken
    from the live score (:meth:`~ertools.benchmarks.base.Audited.from_live`), one note each."""

    result: BenchmarkResult
    options: Any
    said: tuple[str, ...] = ()


def score_execution(
    bench: AnyBenchmark,
    logs: Sequence[Path],
    values: Mapping[str, Any],
    *,
    live: Any = None,
    check_logs: bool = True,
) -> Scored:
    """Score one execution: the values given (by input name) -> options -> logs loaded -> runs
    found -> the result.

    Args:
        bench: the benchmark (:func:`ertools.benchmarks.registry.get`).
        logs: its log files, in order.
        values: the values of its inputs by name (missing ones at their defaults).
        live: the live score (parsed) of an audited execution: the benchmark may take options
            from it (FBM2H: the transform its node used).
        check_logs: refuse a log that is plainly another benchmark's (a usage error naming
            the command to run); an audit and a manifest have chosen the benchmark already.

    Raises:
        UsageError: a value that does not fit its input, or another benchmark's log.
        ErtoolsError: unusable data or configuration.
    """
    if check_logs:
        refuse_other_benchmark(bench.name, logs, values)
    options = bench.make_options(values)
    said: tuple[str, ...] = ()
    if live is not None and isinstance(bench, Audited):
        options, said = bench.from_live(options, live)
    result: BenchmarkResult = run_stages(bench, logs, options)
    return Scored(result, options, said)


def run_stages(
    bench: Benchmark[OptionsT, LoadedT, RunsT, ResultT], logs: Sequence[Path], options: OptionsT
) -> ResultT:
    """The benchmark's three stages on options already made: logs loaded -> runs found ->
    the result (what :func:`score_execution` runs after ``make_options``)."""
    loaded = bench.load(logs, options)
    return bench.score_runs(loaded, bench.find_runs(loaded, options), options)
