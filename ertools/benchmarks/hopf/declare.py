"""HOPF (FBM1@Home 2017-19) as the registry sees it: its inputs and options (``config``), help,
the stages (``pipeline``) and the parts a report, a competition and the demo use. NumPy-free:
``ertools score hopf``'s parser imports it.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.benchmarks.base import (
    Benchmark,
    Described,
    Discovered,
    Ranking,
    Reported,
    SeasonItems,
    Simulated,
)
from ertools.benchmarks.hopf.config import INPUTS, NAME, HopfOptions, make_options
from ertools.benchmarks.hopf.rules import RULES

if TYPE_CHECKING:  # annotations only: the stages import NumPy and the readers
    from ertools.benchmarks.hopf.pipeline import HopfLogs
    from ertools.benchmarks.hopf.result import HopfResult
    from ertools.benchmarks.hopf.runs import HopfRuns

EPILOG = """examples:
  ertools score hopf rsbb_logs/HOPF/teamA/run_1_2019-04-11-16-26-40.bag
  ertools score hopf run_1.bag --items items_with_pose.yaml --result result_run_1.yaml
  ertools score hopf run_1.bag --rules 2019

The side files are found beside the bag or in the RSBB layout (rsbb_logs/, results/,
rsbb_etc/) and named on stderr. The answers are the goal results in the bag; the ground truth
is tf's lookup at the moment the script made it (its /item broadcast). --rules 2019 (2017,
2017-11) reproduces the script at that commit, quirks included; the score is compared with the
run's live score and result file on stderr."""

DESCRIPTION = """Recompute a HOPF (FBM1@Home, object perception, ERL 2017-19) score from its RSBB
run bag (docs/hopf.md).

Per goal: the item shown (the placement's text), its ground truth in the table frame (the
script's tf lookup of /item), the robot's answer (the goal result): class and instance right
or wrong, pose score 1 - t/2 - r/2; then class_accuracy, instance_accuracy, pose_score and
execution_time, in the result file's score form."""


class Hopf(
    Benchmark[HopfOptions, "HopfLogs", "HopfRuns", "HopfResult"],
    Described,
    Reported[HopfOptions, "HopfResult"],
    Discovered,
    SeasonItems,
    Simulated,
):
    """HOPF: ten items shown to the robot, its answers against tf's lookup of each."""

    name = NAME
    title = "HOPF (FBM1@Home 2017-19)"
    inputs = INPUTS
    rules = RULES
    sample_seed = 2023  # Simulated: sample_bags/ was written with it
    example = "ertools score hopf rsbb_logs/HOPF/teamA/run_1_<date>.bag"
    description = DESCRIPTION
    epilog = EPILOG
    bags_help = "the RSBB run bag (rsbb_logs/HOPF/<team>/run_<n>_<date>.bag)"
    score_keys = frozenset({"class_accuracy", "instance_accuracy", "pose_score"})
    ranking = Ranking(
        key=lambda r: r.pose_score,
        lower_is_better=False,
        text="pose_score (the mean pose score over the goals counted): higher is better",
    )
    log_namespace = ""
    source_inputs = ()
    season_items = True  # SeasonItems: the objects shown and their poses

    def make_options(self, values: Mapping[str, Any]) -> HopfOptions:
        return make_options(values)

    def load(self, logs: Sequence[Path], options: HopfOptions) -> HopfLogs:
        from ertools.benchmarks.hopf import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.load(logs, options)

    def find_runs(self, loaded: HopfLogs, options: HopfOptions) -> HopfRuns:
        from ertools.benchmarks.hopf import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.find_runs(loaded, options)

    def score_runs(self, loaded: HopfLogs, runs: HopfRuns, options: HopfOptions) -> HopfResult:
        from ertools.benchmarks.hopf import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.score_runs(loaded, runs, options)

    def notes(self, result: HopfResult) -> Sequence[str]:
        return notes(result)

    def figures(self, result: HopfResult) -> Sequence[Any]:
        from ertools.benchmarks.hopf.plots import figure_specs  # lazy: the charts, 40 ms

        return figure_specs(result)

    def foxglove(self, out: Any, result: HopfResult, *, limit: int) -> None:
        from ertools.benchmarks.hopf.foxglove import content  # lazy: protobuf, 50 ms

        content(out, result, limit=limit)

    def input_files(
        self, logs: Sequence[Path], options: HopfOptions, result: HopfResult
    ) -> list[Path]:
        """The bags and the side files the score read."""
        return [*logs, *(Path(p) for p in result.provenance.inputs[len(logs) :])]

    def sample_args(self, samples: Path) -> Sequence[str] | None:
        """The HOPF sample run (``make demo``): its bag; the side files are beside it."""
        bags = sorted((samples / NAME).rglob("run_*.bag"))
        return [str(bags[0])] if bags else None


def notes(result: HopfResult) -> list[str]:
    """The intervals, the comparison with the run's own scores, what the scoring says and
    (``-v``) one line per goal."""
    out = result.interval_lines()
    if result.comparison is not None:
        out += result.comparison.summary()
    out += list(result.notes)
    if logging.getLogger("ertools").isEnabledFor(logging.INFO):
        for g in result.goals:
            score = "" if g.terms is None else f", pose score {g.terms[5]:.4f}"
            item = "?" if g.item is None else f"item {g.item.id}"
            out.append(f"  goal {g.index}: {item}, {g.status}{score}")
    return out


BENCHMARK = Hopf()
