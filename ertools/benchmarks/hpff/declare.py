"""HPFF (FBM5@Home 2019) as the registry sees it: its inputs and options (``config``), help,
the stages (``pipeline``) and the parts a report, a competition and the demo use. NumPy-free:
``ertools score hpff``'s parser imports it."""

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
from ertools.benchmarks.hpff.config import INPUTS, HpffOptions, make_options
from ertools.benchmarks.hpff.rules import RULES

if TYPE_CHECKING:  # annotations only: the stages import NumPy and the readers
    from ertools.benchmarks.hpff.flow import HpffFlow
    from ertools.benchmarks.hpff.logs import HpffLogs
    from ertools.benchmarks.hpff.result import HpffResult


def notes(result: HpffResult) -> list[str]:
    """The intervals, the comparison with the run's own scores, the samples and the duration."""
    out = list(result.interval_lines())
    if result.comparison is not None:
        out += result.comparison.summary()
    if result.rules != "ertools":
        out.append("reproducing: fbm5_person_following.py at 2bb8a41 (--rules 2019)")
    s = result.stats
    if s is not None:
        out.append(
            f"samples: {s.measured + s.failed}, measured {s.measured}, failed {s.failed}; "
            f"distance steps counted {int(s.counted.sum())}"
        )
    if result.duration_s is not None:
        verdict = "passed" if result.passed else "failed"
        out.append(
            f"duration {result.duration_s:.3f} s against goal_timeout {result.goal_timeout:g} "
            f"+- 15 s: {verdict}"
        )
    return out


EPILOG = """examples:
  ertools score hpff rsbb_output/rsbb_logs/HPFF/homer/run_1_2019-04-10-15-02-11.bag
  ertools score hpff RUN.bag --config HPFF.yaml --transform transform-homer.yaml
  ertools score hpff RUN.bag --rules 2019     # the 2019 script, field for field

The side files are found beside the bag or in the RSBB's folders, each named on stderr. The
score is printed in the result file's form; stderr compares it with the live score and the
result file, field by field."""

DESCRIPTION = """Recompute an HPFF (ERL @Home FBM5, person following) score from its RSBB run bag.

The robot follows a person wearing a cap with markers for the goal's duration. Every 0.5 s
the distance between them is sampled (ertools: a 2 Hz grid over the mocap; --sampling
script: the script's own lookups); the score has the result file's fields: the average
deviation from the desired distance, the distance covered while following within range, the
reliability; a run outside goal_timeout +- 15 s fails."""


class Hpff(
    Benchmark[HpffOptions, "HpffLogs", "HpffFlow", "HpffResult"],
    Described,
    Reported[HpffOptions, "HpffResult"],
    Discovered,
    Simulated,
):
    """HPFF: the 2019 person-following script followed through its run bag and re-scored."""

    name = "hpff"
    title = "HPFF (FBM5@Home 2019)"
    inputs = INPUTS
    rules = RULES
    sample_seed = 2022  # Simulated: sample_bags/ was written with it
    example = "ertools score hpff rsbb_logs/HPFF/homer/run_1_2019-04-10-15-02-11.bag"
    description = DESCRIPTION
    epilog = EPILOG
    bags_help = "the run's bag (rsbb_logs/HPFF/<team>/run_<n>_<date>.bag)"
    bags_metavar = "RUN_BAG"
    score_keys = frozenset({"Average deviation from desired distance", "Benchmark reliability"})
    ranking = Ranking(
        key=lambda r: r.average_deviation,
        lower_is_better=True,
        text="average deviation from the desired following distance (metres): lower is better",
    )
    # the RSBB's topics have no benchmark namespace, and its frames are the script's own
    log_namespace = ""
    source_inputs: tuple[str, ...] = ()

    def make_options(self, values: Mapping[str, Any]) -> HpffOptions:
        return make_options(values)

    def load(self, logs: Sequence[Path], options: HpffOptions) -> HpffLogs:
        from ertools.benchmarks.hpff import pipeline  # lazy: NumPy, the RSBB readers, 400 ms

        return pipeline.load(logs, options)

    def find_runs(self, loaded: HpffLogs, options: HpffOptions) -> HpffFlow:
        from ertools.benchmarks.hpff import pipeline  # lazy: NumPy, the RSBB readers, 400 ms

        return pipeline.find_runs(loaded, options)

    def score_runs(self, loaded: HpffLogs, runs: HpffFlow, options: HpffOptions) -> HpffResult:
        from ertools.benchmarks.hpff import pipeline  # lazy: NumPy, the RSBB readers, 400 ms

        return pipeline.score_runs(loaded, runs, options)

    def notes(self, result: HpffResult) -> Sequence[str]:
        return notes(result)

    def figures(self, result: HpffResult) -> Sequence[Any]:
        from ertools.benchmarks.hpff.plots import figure_specs  # lazy: the charts, 50 ms

        return figure_specs(result)

    def foxglove(self, out: Any, result: HpffResult, *, limit: int) -> None:
        from ertools.benchmarks.hpff.foxglove import content  # lazy: protobuf, 100 ms

        content(out, result, limit=limit)

    def sample_args(self, samples: Path) -> Sequence[str] | None:
        """The HPFF sample run (``make demo``): its bag in the RSBB layout, side files found."""
        bags = sorted((samples / self.name).glob("rsbb_logs/HPFF/*/run_*.bag"))
        return [str(bags[0])] if bags else None


BENCHMARK = Hpff()
