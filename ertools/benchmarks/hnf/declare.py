"""HNF (FBM2@Home 2017-19) as the registry sees it: its inputs and options (``config``), help,
the stages (``pipeline``) and the parts a report, a competition and the demo use. NumPy-free:
``ertools score hnf``'s parser imports it."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.benchmarks.base import (
    Benchmark,
    Described,
    Discovered,
    LiveText,
    Ranking,
    Reported,
    Simulated,
)
from ertools.benchmarks.hnf.config import INPUTS, HnfOptions, make_options, pose_dump
from ertools.benchmarks.hnf.rules import RULES

if TYPE_CHECKING:  # annotations only: the stages import NumPy and the readers
    from ertools.benchmarks.hnf.flow import HnfFlow
    from ertools.benchmarks.hnf.logs import HnfLogs
    from ertools.benchmarks.hnf.result import HnfResult


def notes(result: HnfResult) -> list[str]:
    """The comparison with the run's own scores, the intervals, and the segments."""
    out = list(result.interval_lines())
    if result.comparison is not None:
        out += result.comparison.summary()
    if result.rules != "ertools":
        out.append(f"reproducing: fbm2_navigation.py at {result.script} (--rules {result.rules})")
    for s in result.segments:
        f = s.flow
        head = (
            f"  segment {s.index + 1}: "
            + ("completed" if f.completed else "timed out" if f.timeout else "not completed")
            + f", {(f.end_ns - f.start_ns) / 1e9:.3f} s"
        )
        if s.distance_error is not None and s.orientation_error is not None:
            out.append(
                f"{head}, distance {s.distance_error:.4f} m, "
                f"orientation {s.orientation_error:.4f} rad"
            )
        else:
            out.append(f"{head}, {s.status}")
    return out


EPILOG = """examples:
  ertools score hnf rsbb_output/rsbb_logs/HNF/homer/run_1_2019-04-10-14-31-06.bag
  ertools score hnf run_1.bag --config HNF.yaml --transform transform-homer.yaml
  ertools score hnf RUN.bag --rules 2019      # the 2019 script, field for field
  ertools score hnf RUN.bag --rules 2017      # the December 2017 script (00e3106)

The side files are found beside the bag or in the RSBB's folders (rsbb_etc/transforms/,
rsbb_bmbox/scripts/benchmark_configs/, results/HNF/<team>/), each named on stderr. The score
is printed in the result file's form; stderr compares it with the live score
(/rsbb/current_benchmark_result) and the result file, field by field."""

DESCRIPTION = """Recompute an HNF (ERL @Home FBM2, navigation) score from its RSBB run bag.

The script's control flow is followed through the log (goals, timeouts, the referee's skip
and stop); the robot's pose is looked up at the moments the script's own /tf broadcasts record,
as tf computed it (marker set interpolated, the team transform composed). The score has the
result file's fields: per segment its times, outcome, poses and errors; then
position_accuracy, orientation_accuracy and execution_time."""


class Hnf(
    Benchmark[HnfOptions, "HnfLogs", "HnfFlow", "HnfResult"],
    Described,
    Reported[HnfOptions, "HnfResult"],
    Discovered,
    LiveText,
    Simulated,
):
    """HNF: the 2017-19 navigation script followed through its run bag and re-scored."""

    name = "hnf"
    title = "HNF (FBM2@Home 2017-19)"
    inputs = INPUTS
    rules = RULES
    sample_seed = 2021  # Simulated: sample_bags/ was written with it
    example = "ertools score hnf rsbb_logs/HNF/homer/run_1_2019-04-10-14-31-06.bag"
    description = DESCRIPTION
    epilog = EPILOG
    bags_help = "the run's bag (rsbb_logs/HNF/<team>/run_<n>_<date>.bag)"
    bags_metavar = "RUN_BAG"
    score_keys = frozenset({"position_accuracy[m]", "orientation_accuracy[rad]"})
    ranking = Ranking(
        key=lambda r: r.position_accuracy,
        lower_is_better=True,
        text="position_accuracy (metres, the mean distance to the waypoints): lower is better",
    )
    # the RSBB's topics have no benchmark namespace, and its frames are the script's own
    log_namespace = ""
    source_inputs: tuple[str, ...] = ()

    def live_numbers(self, value: str) -> tuple[tuple[str, float], ...] | None:
        return pose_dump(value)  # LiveText: the live robot_pose

    def make_options(self, values: Mapping[str, Any]) -> HnfOptions:
        return make_options(values)

    def load(self, logs: Sequence[Path], options: HnfOptions) -> HnfLogs:
        from ertools.benchmarks.hnf import pipeline  # lazy: NumPy, the RSBB readers, 400 ms

        return pipeline.load(logs, options)

    def find_runs(self, loaded: HnfLogs, options: HnfOptions) -> HnfFlow:
        from ertools.benchmarks.hnf import pipeline  # lazy: NumPy, the RSBB readers, 400 ms

        return pipeline.find_runs(loaded, options)

    def score_runs(self, loaded: HnfLogs, runs: HnfFlow, options: HnfOptions) -> HnfResult:
        from ertools.benchmarks.hnf import pipeline  # lazy: NumPy, the RSBB readers, 400 ms

        return pipeline.score_runs(loaded, runs, options)

    def notes(self, result: HnfResult) -> Sequence[str]:
        return notes(result)

    def figures(self, result: HnfResult) -> Sequence[Any]:
        from ertools.benchmarks.hnf.plots import figure_specs  # lazy: the charts, 50 ms

        return figure_specs(result)

    def foxglove(self, out: Any, result: HnfResult, *, limit: int) -> None:
        from ertools.benchmarks.hnf.foxglove import content  # lazy: protobuf, 100 ms

        content(out, result, limit=limit)

    def sample_args(self, samples: Path) -> Sequence[str] | None:
        """The HNF sample run (``make demo``): its bag in the RSBB layout, side files found."""
        bags = sorted((samples / self.name).glob("rsbb_logs/HNF/*/run_*.bag"))
        return [str(bags[0])] if bags else None


BENCHMARK = Hnf()
