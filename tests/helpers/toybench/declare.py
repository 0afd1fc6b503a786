"""The toy benchmark declared: its inputs, help texts and parts (NumPy-free: the parser of
``ertools score toy`` imports it)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.benchmarks.base import (
    Audited,
    Benchmark,
    Described,
    Discovered,
    Explanation,
    Ranking,
    Simulated,
)
from tests.helpers.toybench import rules
from tests.helpers.toybench.config import INPUTS, ToyOptions, make_options

if TYPE_CHECKING:  # annotations only: declare stays light
    from ertools.streams import PoseStream
    from tests.helpers.toybench.result import ToyResult


class Toy(
    Benchmark[ToyOptions, "PoseStream", None, "ToyResult"],
    Described,
    Audited[ToyOptions],
    Discovered,
    Simulated,
):
    """Counts the marker poses of a log."""

    # Benchmark: what every benchmark fills
    name = "toy"
    title = "Toy@Test"
    inputs = INPUTS
    rules = rules.RULES
    # Described: `ertools score toy --help`
    example = "ertools score toy toy.bag"
    description = "Count the marker poses of /toy/marker and take their mean x."
    epilog = "examples:\n  ertools score toy toy.bag --scale 2"
    # Audited: its BmBox states are logged, so `ertools audit` recomputes the live score
    values_2015: Mapping[str, Any] = {"count_nan": True}
    explanations: tuple[Explanation, ...] = ()
    # Discovered: a competition ranks it, its logs are recognised by their topics
    ranking = Ranking(key=lambda r: r.count, lower_is_better=False, text="count: higher")
    log_namespace = "toy"

    def make_options(self, values: Mapping[str, Any]) -> ToyOptions:
        return make_options(values)

    def load(self, logs: Sequence[Path], options: ToyOptions) -> PoseStream:
        from tests.helpers.toybench import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.load(logs, options)

    def find_runs(self, loaded: PoseStream, options: ToyOptions) -> None:
        from tests.helpers.toybench import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.find_runs(loaded, options)

    def score_runs(self, loaded: PoseStream, runs: None, options: ToyOptions) -> ToyResult:
        from tests.helpers.toybench import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.score_runs(loaded, runs, options)

    def sample_args(self, samples: Path) -> Sequence[str] | None:
        bag = samples / "toy" / "toy.bag"
        return [str(bag)] if bag.is_file() else None


BENCHMARK = Toy()
