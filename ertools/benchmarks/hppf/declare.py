"""HPPF (FBM4@Home 2019) as the registry sees it: its inputs and options (``config``), help,
the stages (``pipeline``) and the parts a report, a competition and the demo use. NumPy-free:
``ertools score hppf``'s parser imports it.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.benchmarks.base import Benchmark, Described, Discovered, Ranking, Reported, Simulated
from ertools.benchmarks.hppf.config import INPUTS, NAME, HppfOptions, make_options
from ertools.benchmarks.hppf.rules import RULES

if TYPE_CHECKING:  # annotations only: the stages import NumPy and the readers
    from ertools.benchmarks.hppf.pipeline import HppfLogs
    from ertools.benchmarks.hppf.result import HppfResult
    from ertools.benchmarks.hppf.runs import HppfRuns

EPILOG = """examples:
  ertools score hppf rsbb_logs/HPPF/teamA/run_1_2019-04-11-16-26-40.bag
  ertools score hppf run_1.bag --config HPPF.yaml --result result_run_1.yaml
  ertools score hppf run_1.bag --rules 2019

The side files are found beside the bag or in the RSBB layout and named on stderr. The
answers are the goal results in the bag; the ground truth is tf's lookup of the cap when the
script made it (its /person broadcast after the answer). --rules 2019 reproduces the script,
quirks included (a missing theta kills it; its percentage text); the score is compared with
the run's live score and result file on stderr."""

DESCRIPTION = """Recompute an HPPF (FBM4@Home, people perception, ERL 2019) score from its RSBB
run bag (docs/hppf.md).

Per goal: the person shown (the entry's text), the cap's position after the answer (the
script's tf lookup of /person), the robot's answer (the goal result): the name right or
wrong, the position error; then Recognized persons, % Recognized persons (over all the
people), Distance error (over the goals detected) and execution_time, in the result file's
score form."""


class Hppf(
    Benchmark[HppfOptions, "HppfLogs", "HppfRuns", "HppfResult"],
    Described,
    Reported[HppfOptions, "HppfResult"],
    Discovered,
    Simulated,
):
    """HPPF: people shown to the robot, its answers (name, position) against the cap's."""

    name = NAME
    title = "HPPF (FBM4@Home 2019)"
    inputs = INPUTS
    rules = RULES
    sample_seed = 2024  # Simulated: sample_bags/ was written with it
    example = "ertools score hppf rsbb_logs/HPPF/teamA/run_1_<date>.bag"
    description = DESCRIPTION
    epilog = EPILOG
    bags_help = "the RSBB run bag (rsbb_logs/HPPF/<team>/run_<n>_<date>.bag)"
    score_keys = frozenset({"Distance error", "% Recognized persons"})
    ranking = Ranking(
        key=lambda r: r.distance_error,
        lower_is_better=True,
        text="Distance error (metres, the mean position error over the goals detected): lower "
        "is better",
    )
    log_namespace = ""
    source_inputs = ()

    def make_options(self, values: Mapping[str, Any]) -> HppfOptions:
        return make_options(values)

    def load(self, logs: Sequence[Path], options: HppfOptions) -> HppfLogs:
        from ertools.benchmarks.hppf import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.load(logs, options)

    def find_runs(self, loaded: HppfLogs, options: HppfOptions) -> HppfRuns:
        from ertools.benchmarks.hppf import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.find_runs(loaded, options)

    def score_runs(self, loaded: HppfLogs, runs: HppfRuns, options: HppfOptions) -> HppfResult:
        from ertools.benchmarks.hppf import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.score_runs(loaded, runs, options)

    def notes(self, result: HppfResult) -> Sequence[str]:
        return notes(result)

    def figures(self, result: HppfResult) -> Sequence[Any]:
        from ertools.benchmarks.hppf.plots import figure_specs  # lazy: the charts, 40 ms

        return figure_specs(result)

    def foxglove(self, out: Any, result: HppfResult, *, limit: int) -> None:
        from ertools.benchmarks.hppf.foxglove import content  # lazy: protobuf, 50 ms

        content(out, result, limit=limit)

    def input_files(
        self, logs: Sequence[Path], options: HppfOptions, result: HppfResult
    ) -> list[Path]:
        """The bags and the side files the score read."""
        return [*logs, *(Path(p) for p in result.provenance.inputs[len(logs) :])]

    def sample_args(self, samples: Path) -> Sequence[str] | None:
        """The HPPF sample run (``make demo``): its bag; the side files are beside it."""
        bags = sorted((samples / NAME).rglob("run_*.bag"))
        return [str(bags[0])] if bags else None


def notes(result: HppfResult) -> list[str]:
    """The intervals, the comparison with the run's own scores, what the scoring says and
    (``-v``) one line per pass."""
    out = result.interval_lines()
    if result.comparison is not None:
        out += result.comparison.summary()
    out += list(result.notes)
    if logging.getLogger("ertools").isEnabledFor(logging.INFO):
        for p in result.passes:
            err = "" if p.position_error is None else f", {p.position_error:.3f} m"
            out.append(f"  goal {p.index}: {p.person}, {p.status}{err}")
    return out


BENCHMARK = Hppf()
