"""FBM2@Home as the registry sees it: its inputs and options (``config``), help, the stages
(``logs``: load and the reached moments; ``pipeline``: the score) and the parts a report, an
audit, a competition and the demo use. NumPy-free: ``ertools score fbm2h``'s parser imports it.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import replace
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
from ertools.benchmarks.fbm2h.config import INPUTS, NODES, Fbm2hOptions, make_options
from ertools.benchmarks.fbm2h.rules import RULES

if TYPE_CHECKING:  # annotations only: the stages import NumPy and the readers
    from ertools.benchmarks.fbm2h.logs import Fbm2hLogs, Fbm2hRuns
    from ertools.benchmarks.fbm2h.result import Fbm2hResult

TIMING_SUFFIX = "_reached_waypoint_timing.yaml"


# Why an audit's recomputed value may differ from the live one.
EXPLANATIONS = (
    Explanation(
        r"orientation_(error|accuracy)$",
        "the 2015 node took sin and cos of the unwrapped |robot yaw - target yaw|; ertools "
        "wraps the difference to [-pi, pi] first (identical unless the difference crosses "
        "+-pi); the robot pose also depends on the marker-to-robot transform",
        ("transform", "source", "topic", "reached"),
    ),
    Explanation(
        r"(dinstance_error|distance_error|position_accuracy|position_error|robot_pose)$",
        "the live node used the latest mocap pose when the result arrived; ertools "
        "interpolates the logged ground truth at the logged moment the waypoint was reached "
        "and applies the marker-to-robot transform as a full SE(3) composition",
        ("transform", "source", "topic", "reached", "max_gap", "association"),
    ),
)


EPILOG = """examples:
  ertools score fbm2h run.bag --team homer --transforms transforms/
  ertools score fbm2h run.bag --goal configs/fbm2h.yaml --transform transform-homer.yaml
  ertools score fbm2h log.bag --goal goal.yaml --transform configs/transform-identity.yaml \\
      --reached timing log_reached_waypoint_timing.yaml
  ertools score fbm2h log.bag --goal goal.yaml --reached auto --format json

--reached: states (default when the bag has /fbm2h/bmbox_state): segment i starts when the
BmBox has sent the goal and ends at the Client's COMPLETED_GOAL; timing FILE: a reached-waypoint
timing file (p0 starts, p(k+1) closes segment k, seconds from the bag's first message); auto:
stops detected in the ground truth, assigned to the waypoints in order.
Orientation errors are wrapped to [0, pi]; --orientation-2015 reproduces the 2015 numbers.
Accuracies are null (exit 1) when a segment is not scored (RefBox timeout or stop, or a log
that ends inside the benchmark, taken as stopped there); --unscored-segments 2015 scores the
segment cut short where the node's wait returned and divides the sums by N as 2015 did.
--segment-clock bmbox times segments between the BmBox's own transitions as the node did.
--2015 (= --rules 2015: scripts/fbm2h at 50b173b, RoCKIn 2015; --rules 2016 and 2017 name the
same file at 40ba68b and 89dfa75): every 2015 behaviour at once, with the node's pose source
(/tf world -> robot_at_home)."""

DESCRIPTION = """Recompute an FBM2@Home (navigation) score from the logs (seed 7.2, Listing 13).

Per waypoint: the robot pose when it was reached (ground-truth marker pose interpolated at that
moment, composed with the team's marker-to-robot transform), its distance and orientation
error, the segment time; then position_accuracy, orientation_accuracy and execution_time."""


class Fbm2h(
    Benchmark[Fbm2hOptions, "Fbm2hLogs", "Fbm2hRuns", "Fbm2hResult"],
    Described,
    Reported[Fbm2hOptions, "Fbm2hResult"],
    Audited[Fbm2hOptions],
    Discovered,
    Simulated,
):
    """FBM2@Home: a robot's poses when it reached each waypoint, against the goal list."""

    name = "fbm2h"
    title = "FBM2@Home"
    inputs = INPUTS
    rules = RULES
    sample_seed = 2016  # Simulated: sample_bags/ was written with it
    example = "ertools score fbm2h run.bag --goal goal.yaml --transform transform-homer.yaml"
    description = DESCRIPTION
    epilog = EPILOG
    score_keys = frozenset({"position_accuracy", "orientation_accuracy"})
    values_2015: Mapping[str, Any] = {"all_2015": True}
    explanations = EXPLANATIONS
    ranking = Ranking(
        key=lambda r: r.position_accuracy,
        lower_is_better=True,
        text="position_accuracy (metres, the mean distance to the waypoints): lower is better",
    )
    log_namespace = "fbm2h"

    def make_options(self, values: Mapping[str, Any]) -> Fbm2hOptions:
        return make_options(values)

    def load(self, logs: Sequence[Path], options: Fbm2hOptions) -> Fbm2hLogs:
        from ertools.benchmarks.fbm2h import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.load(logs, options)

    def find_runs(self, loaded: Fbm2hLogs, options: Fbm2hOptions) -> Fbm2hRuns:
        from ertools.benchmarks.fbm2h import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.find_runs(loaded, options)

    def score_runs(self, loaded: Fbm2hLogs, runs: Fbm2hRuns, options: Fbm2hOptions) -> Fbm2hResult:
        from ertools.benchmarks.fbm2h import pipeline  # lazy: NumPy, the readers, 250 ms

        return pipeline.score_runs(loaded, runs, options)

    def notes(self, result: Fbm2hResult) -> Sequence[str]:
        return notes(result)

    def figures(self, result: Fbm2hResult) -> Sequence[Any]:
        from ertools.benchmarks.fbm2h.plots import figure_specs  # lazy: the charts, 40 ms

        return figure_specs(result)

    def foxglove(self, out: Any, result: Fbm2hResult, *, limit: int) -> None:
        from ertools.benchmarks.fbm2h.foxglove import content  # lazy: protobuf, 50 ms

        content(out, result, limit=limit)

    def from_live(self, options: Fbm2hOptions, live: Any) -> tuple[Fbm2hOptions, tuple[str, ...]]:
        """The audit's options: without ``--transform``/``--transforms``, the transform the live
        score says the node used, and a note saying so (``--team`` alone picks no transform)."""
        from ertools.configs.transform import (  # lazy: NumPy, 100 ms
            LIVE_TRANSFORM_KEY,
            live_transform,
        )

        if options.transform is not None or options.transforms_dir is not None:
            return options, ()
        found = live_transform(live)
        if found is None:
            return options, ()
        t = ", ".join(f"{v:g}" for v in found.translation)
        q = ", ".join(f"{v:.6g}" for v in found.quat_xyzw)
        return replace(options, marker_transform=found), (
            f"transform taken from the live score (details.{LIVE_TRANSFORM_KEY}: [[{t}], [{q}]]); "
            "give --transform or --team/--transforms to use another",
        )

    def gt_only(self, logs: Sequence[Path]) -> Mapping[str, Any] | str | None:
        """A GT-only FBM2@Home log (no state topics) is an execution when the 2015 reached-waypoint
        timing file lies beside it (``<log stem>_reached_waypoint_timing.yaml``, as the 2015 test
        logs ship): ``reached: [timing, FILE]``."""
        first = logs[0]
        stem = first.name.removesuffix(".active").removesuffix(".bag")
        timing = first.with_name(stem + TIMING_SUFFIX)
        if timing.is_file():
            return {"reached": ("timing", timing)}
        return (
            "the GT logger's FBM2@Home log alone: no state topics and no "
            f"{timing.name} beside it, so nothing says when each waypoint was reached (list it "
            "under executions: with reached: auto or [timing, FILE] to score it)"
        )

    def sample_args(self, samples: Path) -> Sequence[str] | None:
        """The FBM2@Home sample log with its goal list and transform (``make demo``)."""
        folder = samples / self.name
        bags = sorted(folder.glob("*.bag"))
        goals = sorted(folder.glob("*goal*.yaml"))
        transforms = sorted(folder.glob("transform-*.yaml"))
        if not (bags and goals and transforms):
            return None
        return [str(bags[0]), "--goal", str(goals[0]), "--transform", str(transforms[0])]


def notes(result: Fbm2hResult) -> list[str]:
    """The score intervals, how the reached moments were found (with ``-v``) and the
    per-segment table."""
    out = result.interval_lines()
    rules = dict(result.provenance.parameters).get("rules", "ertools")
    if rules in NODES:
        out.append(f"reproducing: {NODES[rules]}")
    if logging.getLogger("ertools").isEnabledFor(logging.INFO):  # -v
        out += list(result.notes)
    out.append(
        f"reached moments: {result.reached_method}; transform: {result.transform.described}; "
        + (
            f"goal: {result.goal.source} ({result.goal.layout} layout); "
            if result.goal.layout != "listing-10"
            else ""
        )
        + "times from the log's first message"
    )
    n = len(result.segments)
    scored = sum(s.status == "ok" for s in result.segments)
    if result.position_accuracy is None:
        averaged = "none (a segment is not scored: see the warnings)"
    elif result.unscored_2015:
        averaged = f"sum over the {scored} scored segment(s) / N = {n} (2015)"
    else:
        averaged = f"mean over all {n} segments"
    out.append(f"accuracies: {averaged}")
    values = ("reached_s", "segment_time_s", "distance_error_m", "orientation_error_rad")
    for row in result.tables()["segments"]:
        if row["status"] != "ok" or any(row[k] is None for k in values):
            out.append(f"  segment {row['segment']}: {row['status']}")
            continue
        out.append(
            f"  segment {row['segment']}: reached {row['reached_s']:.3f} s, "
            f"time {row['segment_time_s']:.3f} s, distance {row['distance_error_m']:.4f} m, "
            f"orientation {row['orientation_error_rad']:.4f} rad"
        )
    return out


BENCHMARK = Fbm2h()
