"""FBM3@Work as the registry sees it: its inputs and options (``config``), help, the stages
(``pipeline``) and the parts a report, an audit, a competition and the demo use. NumPy-free:
``ertools score fbm3w``'s parser imports it.
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
from ertools.benchmarks.fbm3w.config import INPUTS, Fbm3wOptions, make_options
from ertools.benchmarks.fbm3w.rules import RULES

if TYPE_CHECKING:  # annotations only: the stages import NumPy and the readers
    from ertools.benchmarks.fbm3w.logs import Fbm3wLogs
    from ertools.benchmarks.fbm3w.result import Fbm3wResult
    from ertools.benchmarks.fbm3w.runs import RunWindow

# Why an audit's recomputed value may differ from the live one.
EXPLANATIONS = (
    Explanation(
        r"distance_error$",
        "the FBM3 path error depends on d_min (the 2015 node hard-coded 0.00033 m), on the "
        "pose source and on which poses fall in the run window (the live node collected them "
        "by callback while EXECUTING_GOAL/WAITING_RESULT; ertools takes the logged poses "
        "between the logged state changes)",
        ("d_min", "topic", "source", "frame", "runs"),
    ),
    Explanation(
        r"^best_run$",
        "the best run is the one with the smallest distance_error: it changes when the "
        "per-run errors change",
    ),
)

EPILOG = """examples:
  ertools score fbm3w log_fbm3w_mocap.bag
  ertools score fbm3w run.bag --config configs/fbm3w.yaml --format json
  ertools score fbm3w run.bag --d-min 0.0005 --plots plots/
  ertools score fbm3w run.bag --d-min-sweep 0.0001:0.001:10
  ertools score fbm3w mocap_only.bag --runs auto
  ertools score fbm3w mocap_only.bag --run line:2.0:3.1:7.1 --run spline:9.3:10.5:16

--runs: states (default when /fbm3w/bmbox_state exists): reference = the pose when the BmBox
leaves WAITING_MANUAL_OPERATION, path from EXECUTING_GOAL until WAITING_RESULT is left, as the
2015 node; windows: --run SPEC:REF_T:START_T:END_T (repeatable) or --runs-file FILE (YAML list of
{spec, reference, start, end}), times in seconds from the bag's first message or epoch
seconds; auto: runs found from motion alone (stationary at the reference, short move,
stationary at the start, the path, stationary at the end), detected times in the output.
Warnings (d_min below the noise measured on the bag's stationary phases, shapes not
parametrised by arc length) and deviations from 2015 go to stderr."""


DESCRIPTION = """Recompute an FBM3@Work (trajectory following) score from the logs
(seed 7.3, Listing 16).

Per run: the measured end-effector path subsampled with d_min, put in the run frame (origin at
the starting position, x axis along reference -> start), compared with the target shape at
each kept point's normalised path length; distance_error = the mean distance (Eq. 1). Then
best_run, best_distance_error and execution_time (sum of the run times)."""


class Fbm3w(
    Benchmark[Fbm3wOptions, "Fbm3wLogs", "Sequence[RunWindow]", "Fbm3wResult"],
    Described,
    Reported[Fbm3wOptions, "Fbm3wResult"],
    Audited[Fbm3wOptions],
    Discovered,
    Simulated,
):
    """FBM3@Work: the runs of an end effector along target shapes, scored by Eq. (1)."""

    name = "fbm3w"
    title = "FBM3@Work"
    inputs = INPUTS
    rules = RULES
    sample_seed = 2015  # Simulated: sample_bags/ was written with it
    example = "ertools score fbm3w run.bag --config configs/fbm3w.yaml"
    description = DESCRIPTION
    epilog = EPILOG
    score_keys = frozenset({"best_distance_error", "runs_details"})
    # The 2015 node's hard-coded d_min too, whatever d_min the audit was given.
    values_2015: Mapping[str, Any] = {"all_2015": True, "d_min": None}
    explanations = EXPLANATIONS
    ranking = Ranking(
        key=lambda r: r.best_distance_error,
        lower_is_better=True,
        text="best_distance_error (metres, the best run's mean distance to the target): "
        "lower is better",
    )
    log_namespace = "fbm3w"

    def make_options(self, values: Mapping[str, Any]) -> Fbm3wOptions:
        return make_options(values)

    def load(self, logs: Sequence[Path], options: Fbm3wOptions) -> Fbm3wLogs:
        from ertools.benchmarks.fbm3w import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.load(logs, options)

    def find_runs(self, loaded: Fbm3wLogs, options: Fbm3wOptions) -> Sequence[RunWindow]:
        from ertools.benchmarks.fbm3w import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.find_runs(loaded, options)

    def score_runs(
        self, loaded: Fbm3wLogs, runs: Sequence[RunWindow], options: Fbm3wOptions
    ) -> Fbm3wResult:
        from ertools.benchmarks.fbm3w import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.score_runs(loaded, runs, options)

    def notes(self, result: Fbm3wResult) -> Sequence[str]:
        return notes(result)

    def figures(self, result: Fbm3wResult) -> Sequence[Any]:
        from ertools.benchmarks.fbm3w.plots import figure_specs  # lazy: the charts, 40 ms

        return figure_specs(result)

    def foxglove(self, out: Any, result: Fbm3wResult, *, limit: int) -> None:
        from ertools.benchmarks.fbm3w.foxglove import content  # lazy: protobuf, 50 ms

        content(out, result, limit=limit)

    def gt_only(self, logs: Sequence[Path]) -> Mapping[str, Any] | str | None:
        """A GT-only FBM3@Work log (mocap alone, no state topics: the 2015 test logs) is
        scored with runs found from motion alone (``runs: auto``); its row says why when none
        is found (a marker set lying still is a noise recording, not an execution)."""
        return {"runs": "auto"}

    def sample_args(self, samples: Path) -> Sequence[str] | None:
        """The FBM3@Work sample log (``make demo``)."""
        bags = sorted((samples / "fbm3w").glob("*.bag"))
        return [str(bags[0])] if bags else None


def notes(result: Fbm3wResult) -> list[str]:
    """The score intervals, the runs found from motion and the d_min sweep, for stderr."""
    out = result.interval_lines()
    for r in result.runs:
        if r.window.mode == "auto":
            d = r.details()
            out.append(
                f"run {r.index} ({r.spec}) found at reference {d['reference_time']} s, "
                f"path {d['start_time']}-{d['end_time']} s (seconds from the bag's first message)"
            )
    if result.sweep_values:
        out.append("distance_error of every run over d_min (--d-min-sweep):")
        out += ["  " + line for line in result.sweep_text().splitlines()]
    return out


BENCHMARK = Fbm3w()
