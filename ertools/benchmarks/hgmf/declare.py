"""HGMF (FBM6@Home 2019) as the registry sees it: its inputs and options (``config``), help,
the stages (``pipeline``) and the parts a report, a competition and the demo use. NumPy-free:
``ertools score hgmf``'s parser imports it."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.benchmarks.base import (
    Benchmark,
    Described,
    Discovered,
    Ranking,
    Reported,
    Simulated,
)
from ertools.benchmarks.hgmf import config
from ertools.benchmarks.hgmf.config import CODE, INPUTS, NAME, HgmfOptions, make_options
from ertools.benchmarks.hgmf.rules import RULES

if TYPE_CHECKING:  # annotations only: the stages import NumPy and the readers
    from ertools.benchmarks.hgmf.flow import HgmfFlow
    from ertools.benchmarks.hgmf.pipeline import HgmfLogs
    from ertools.benchmarks.hgmf.result import HgmfResult


def notes(result: HgmfResult) -> list[str]:
    """The comparison with the run's own scores, the interval, and the goals."""
    out = list(result.interval_lines())
    if result.comparison is not None:
        out += result.comparison.summary()
    if result.rules != "ertools":
        out.append(f"reproducing: {config.SCRIPT_2019} (--rules {result.rules})")
    for g in result.goals:
        a = g.attempt
        head = f"  goal_{a.index} ({g.description or 'object ?'}): {g.status}"
        head += f", {a.times.segment_ns / 1e9:.3f} s"
        if a.times.completed:
            head += ", grasped" if g.grasped else ", not grasped"
        if g.distance_error is not None:
            head += f", distance {g.distance_error:.4f} m"
        out.append(head)
    return out


EPILOG = """examples:
  ertools score hgmf rsbb_output/rsbb_logs/HGMF/homer/run_1_2019-04-11-10-00-00.bag
  ertools score hgmf run_1.bag --config HGMF.yaml --result result_run_1.yaml
  ertools score hgmf RUN.bag --rules 2019      # the 2019 script, field for field

The side files are found beside the bag or in the RSBB's folders
(rsbb_bmbox/scripts/benchmark_configs/, results/HGMF/<team>/), each named on stderr. The score
is printed in the result file's form; stderr compares it with the live score
(/rsbb/current_benchmark_result) and the result file, field by field. A grasp is a rise of the
object of more than 3 cm over its height before the goal; the distance is the object's to its
target in the table's plane, at the lookup after the goal."""

DESCRIPTION = """Recompute an HGMF (ERL @Home FBM6, grasping and manipulation) score from
its RSBB run bag.

The script's control flow is followed through the log (objects placed, goals, timeouts,
restarts, the referee's stop); the object's height before each goal and its position after it
are looked up at the moments the script's own /tf broadcasts record, as tf computed them. The
score has the result file's fields: per goal its time, outcome, grasp, distance and positions;
then Objects grasped, Avg distance error and execution_time."""


class Hgmf(
    Benchmark[HgmfOptions, "HgmfLogs", "HgmfFlow", "HgmfResult"],
    Described,
    Reported[HgmfOptions, "HgmfResult"],
    Discovered,
    Simulated,
):
    """HGMF: the 2019 grasping script followed through its run bag and re-scored."""

    name = NAME
    title = config.TITLE
    inputs = INPUTS
    rules = RULES
    sample_seed = 2025  # Simulated: sample_bags/ was written with it
    example = "ertools score hgmf rsbb_logs/HGMF/homer/run_1_2019-04-11-10-00-00.bag"
    description = DESCRIPTION
    epilog = EPILOG
    bags_help = "the run's bag (rsbb_logs/HGMF/<team>/run_<n>_<date>.bag)"
    bags_metavar = "RUN_BAG"
    score_keys = frozenset({"Avg distance error", "Objects grasped"})
    ranking = Ranking(
        key=lambda r: r.average,
        lower_is_better=True,
        text="Avg distance error (metres, the objects' mean distance to their targets): "
        "lower is better",
    )
    # the RSBB's topics have no benchmark namespace, and its frames are the script's own
    log_namespace = ""
    source_inputs: tuple[str, ...] = ()

    def make_options(self, values: Mapping[str, Any]) -> HgmfOptions:
        return make_options(values)

    def load(self, logs: Sequence[Path], options: HgmfOptions) -> HgmfLogs:
        from ertools.benchmarks.hgmf import pipeline  # lazy: NumPy, the RSBB readers, 400 ms

        return pipeline.load(logs, options)

    def find_runs(self, loaded: HgmfLogs, options: HgmfOptions) -> HgmfFlow:
        from ertools.benchmarks.hgmf import pipeline  # lazy: NumPy, the RSBB readers, 400 ms

        return pipeline.find_runs(loaded, options)

    def score_runs(self, loaded: HgmfLogs, runs: HgmfFlow, options: HgmfOptions) -> HgmfResult:
        from ertools.benchmarks.hgmf import pipeline  # lazy: NumPy, the RSBB readers, 400 ms

        return pipeline.score_runs(loaded, runs, options)

    def notes(self, result: HgmfResult) -> Sequence[str]:
        return notes(result)

    def figures(self, result: HgmfResult) -> Sequence[Any]:
        from ertools.benchmarks.hgmf.plots import figure_specs  # lazy: the charts, 50 ms

        return figure_specs(result)

    def foxglove(self, out: Any, result: HgmfResult, *, limit: int) -> None:
        from ertools.benchmarks.hgmf.foxglove import content  # lazy: protobuf, 100 ms

        content(out, result, limit=limit)

    def sample_args(self, samples: Path) -> Sequence[str] | None:
        """The HGMF sample run (``make demo``): its bag in the RSBB layout, side files found."""
        bags = sorted((samples / self.name).glob(f"rsbb_logs/{CODE}/*/run_*.bag"))
        return [str(bags[0])] if bags else None


BENCHMARK = Hgmf()
