"""The mocap noise measure as the registry sees it (``ertools score noise``, and the
``ertools noise`` command on the same stages): its inputs (``config``), help, the stages
(``pipeline``) and what a report and the samples use. NumPy-free: the parsers import it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.benchmarks.base import Benchmark, Described, Reported, Simulated
from ertools.benchmarks.noise.config import INPUTS, NoiseOptions, make_options
from ertools.benchmarks.noise.rules import RULES

if TYPE_CHECKING:  # annotations only: the stages import NumPy and the readers
    from ertools.benchmarks.common.epsilon import NoiseResult
    from ertools.streams import PoseStream

DESCRIPTION = """Mocap noise statistics of a stationary marker set and the d_min they suggest
(seed 7.3.13): the distance in the plane between consecutive measurements, in the 2015
mocap_noise_statistics tool's bins; lost samples (two consecutive identical poses); epsilon,
the mean distance between consecutive measurements that differ; percentiles; and the
suggested d_min = c * epsilon (seed 7.3.2). `ertools noise` runs the same stages with a text
summary and histogram."""

EPILOG = """examples:
  ertools score noise log_fbm3w_noise.bag
  ertools score noise log_fbm3w_mocap.bag --stationary auto --report noise/

Poses: --topic TOPIC or --tf PARENT:CHILD, else /fbm3w/robot_at_work/pose2d,
/fbm3w/robot_at_work/pose, /tf world:robot_at_work, else the bag's only pose topic.
Keys: samples, lost, epsilon, percentiles {"50", "95", "99"}, suggested_d_min (metres)."""


class Noise(
    Benchmark[NoiseOptions, "PoseStream", None, "NoiseResult"],
    Described,
    Reported[NoiseOptions, "NoiseResult"],
    Simulated,
):
    """The noise of a marker set lying still: one measurement per recording, no runs."""

    name = "noise"
    title = "Mocap noise"
    inputs = INPUTS
    rules = RULES
    sample_seed = 2019  # Simulated: sample_bags/ was written with it
    example = "ertools score noise stationary.bag --stationary auto"
    description = DESCRIPTION
    epilog = EPILOG
    score_keys = frozenset({"epsilon", "suggested_d_min"})
    sample_folder = "stationary"  # Simulated: a marker set lying still

    def make_options(self, values: Mapping[str, Any]) -> NoiseOptions:
        return make_options(values)

    def load(self, logs: Sequence[Path], options: NoiseOptions) -> PoseStream:
        from ertools.benchmarks.noise import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.load(logs, options)

    def find_runs(self, loaded: PoseStream, options: NoiseOptions) -> None:
        from ertools.benchmarks.noise import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.find_runs(loaded, options)

    def score_runs(self, loaded: PoseStream, runs: None, options: NoiseOptions) -> NoiseResult:
        from ertools.benchmarks.noise import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.score_runs(loaded, runs, options)

    def figures(self, result: NoiseResult) -> Sequence[Any]:
        from ertools.benchmarks.noise import plots  # lazy: the charts, 20 ms

        return plots.figure_specs(result)

    def foxglove(self, out: Any, result: NoiseResult, *, limit: int) -> None:
        from ertools.benchmarks.noise import foxglove  # lazy: protobuf, 50 ms

        foxglove.content(out, result, limit=limit)

    def sample_args(self, samples: Path) -> Sequence[str] | None:
        """The simulated recording of a marker set lying still (``make demo``)."""
        bags = sorted((samples / self.sample_folder).glob("*.bag"))
        return [str(bags[0])] if bags else None


BENCHMARK = Noise()
