"""FBM1@Home and FBM1@Work as the registry sees them: their inputs and options (``config``),
help, the stages (``pipeline``) and the parts a report, an audit, a competition and the demo
use. The two differ only in their name (the state topics' namespace, where an item's name is
read first, which nodes exist to reproduce). NumPy-free: a parser imports it.
"""

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
    Reported,
    Simulated,
)
from ertools.benchmarks.fbm1.config import Fbm1Options, inputs, make_options
from ertools.benchmarks.fbm1.rules import RULES

if TYPE_CHECKING:  # annotations only: the stages import NumPy and the readers
    from ertools.benchmarks.fbm1.logs import Fbm1Logs, Fbm1Runs
    from ertools.benchmarks.fbm1.result import Fbm1Result

# Why an audit's recomputed value may differ from the live one.
EXPLANATIONS = (
    Explanation(
        r"(pose_score|x_error|y_error|theta_error|position|orientation)$",
        "the ground truth is averaged over the window in which the board stood still "
        "(the 2015 node interpolated one tf lookup when the result arrived); theta is in "
        "degrees",
        ("window", "source", "topic", "items"),
    ),
    Explanation(
        r"(class|instance)(_accuracy|_correct)?$",
        "class and instance are compared as text with the item list",
        ("items",),
    ),
)


EPILOG = """examples:
  ertools score {name} run.bag --items configs/{name}.yaml
  ertools score fbm1w run.bag --items configs/fbm1w.yaml --items-order 3,7,1,2
  ertools score fbm1h run.bag --items fbm1h.yaml --results answers.yaml --format json
  ertools score fbm1h run.bag --items fbm1h.yaml --rules 2015   # RoCKIn 2015's node (e373be0)
  ertools score fbm1h run.bag --items fbm1h.yaml --rules 2016   # Lisbon 2016's (40ba68b)
  ertools score fbm1h run.bag --items fbm1h.yaml --rules 2017   # Lisbon 2017's (89dfa75)

--results FILE: a YAML list of answers, each {{run: N or item: ID, item_class, item_instance,
x, y, theta}} (theta in degrees), used instead of the Client payloads it covers.
The per-run table goes to stderr; stdout carries the score (YAML or JSON).
Exit status 1 when any run could not be scored (each named on stderr); the others are scored."""

DESCRIPTION = """Recompute an FBM1@Home / FBM1@Work (object perception) score from the log
(seed 7.1).

Per run: the item shown (manual-operation payload), the robot's answer (Client COMPLETED_GOAL
payload: item_class, item_instance, x, y in metres, theta in DEGREES, table frame), the
ground-truth item pose in the table frame (origin^-1 * ref_board * item transform, averaged
while the board stood still before the goal), class/instance right, pose score
1 - min(t, 1)/2 - min(|dtheta|/180, 1)/2. Totals as the 2015 node: class_accuracy,
instance_accuracy, pose_score, execution_time."""


class Fbm1(
    Benchmark[Fbm1Options, "Fbm1Logs", "Fbm1Runs", "Fbm1Result"],
    Described,
    Reported[Fbm1Options, "Fbm1Result"],
    Audited[Fbm1Options],
    Discovered,
    Simulated,
):
    """FBM1@Home or FBM1@Work: one class, two benchmarks (:data:`FBM1H`, :data:`FBM1W`)."""

    rules = RULES
    sample_seed = 2017  # Simulated: sample_bags/ was written with it
    description = DESCRIPTION
    score_keys = frozenset({"class_accuracy", "instance_accuracy"})
    explanations = EXPLANATIONS
    ranking = Ranking(
        key=lambda r: r.totals.pose_score,
        lower_is_better=False,
        text="pose_score (0..1, the mean of the runs' pose scores): higher is better",
    )
    source_inputs = ("origin_topic", "origin_tf", "ref_board_topic", "ref_board_tf")

    def __init__(self, name: str, title: str) -> None:
        self.name = name
        self.title = title
        self.inputs = inputs(name)
        self.example = f"ertools score {name} run.bag --items configs/{name}.yaml"
        self.epilog = EPILOG.format(name=name)
        self.log_namespace = name
        self.values_2015: Mapping[str, Any] = {"rules": "2015"}

    def make_options(self, values: Mapping[str, Any]) -> Fbm1Options:
        return make_options(self.name, values)

    def load(self, logs: Sequence[Path], options: Fbm1Options) -> Fbm1Logs:
        from ertools.benchmarks.fbm1 import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.load(logs, options)

    def find_runs(self, loaded: Fbm1Logs, options: Fbm1Options) -> Fbm1Runs:
        from ertools.benchmarks.fbm1 import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.find_runs(loaded, options)

    def score_runs(self, loaded: Fbm1Logs, runs: Fbm1Runs, options: Fbm1Options) -> Fbm1Result:
        from ertools.benchmarks.fbm1 import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.score_runs(loaded, runs, options)

    def notes(self, result: Fbm1Result) -> Sequence[str]:
        """The reference reproduced and the per-run table (stdout keeps the parseable score)."""
        from ertools.benchmarks.fbm1.result import notes  # lazy: NumPy, 100 ms

        return notes(result)

    def figures(self, result: Fbm1Result) -> Sequence[Any]:
        from ertools.benchmarks.fbm1.plots import figure_specs  # lazy: the charts, 40 ms

        return figure_specs(result)

    def foxglove(self, out: Any, result: Fbm1Result, *, limit: int) -> None:
        from ertools.benchmarks.fbm1.foxglove import content  # lazy: protobuf, 50 ms

        content(out, result, limit=limit)

    def input_files(
        self, logs: Sequence[Path], options: Fbm1Options, result: Fbm1Result
    ) -> list[Path]:
        """The log and the item list (the report hashes both)."""
        return [*logs, *([options.items] if options.items is not None else [])]

    def sample_args(self, samples: Path) -> Sequence[str] | None:
        """The sample log with its item list (``make demo``)."""
        folder = samples / self.name
        bags = sorted(folder.glob("*.bag"))
        items = folder / f"{self.name}.yaml"
        return [str(bags[0]), "--items", str(items)] if bags and items.is_file() else None


FBM1H = Fbm1("fbm1h", "FBM1@Home")
FBM1W = Fbm1("fbm1w", "FBM1@Work")
