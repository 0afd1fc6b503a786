"""HNF (FBM2@Home 2017-19) as the registry sees it: its inputs (the options of ``ertools score
hnf``, the manifest keys), how they become :class:`HnfOptions`, and its stages."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import Explanation, Input, Ranking, resolve_values
from ertools.benchmarks.common.inputs import INTERVAL_INPUTS, check_confidence
from ertools.benchmarks.hnf.config import DEFAULT_MAX_GAP_S, RULE_SETS, HnfOptions, options_from
from ertools.benchmarks.hnf.flow import HnfFlow
from ertools.benchmarks.hnf.logs import HnfLogs
from ertools.benchmarks.hnf.pipeline import find_runs, load, score_runs
from ertools.benchmarks.hnf.result import HnfResult
from ertools.benchmarks.hnf.rules import RULES
from ertools.benchmarks.legacy import LegacyBenchmark

NAME = "hnf"
SCRIPT = "the 2019 script (differences can be undone one by one)"

INPUTS = (
    Input(
        "config",
        "path",
        "HNF.yaml (waypoints, goal_timeout); default: found beside the bag or in the RSBB "
        "layout, else the result file's benchmark_info.params",
        metavar="FILE",
    ),
    Input(
        "transform",
        "path",
        "transform-<team>.yaml (markerset_to_robot_transform); default: found beside the "
        "bag or in rsbb_etc/transforms/",
        metavar="FILE",
        per_team=True,
    ),
    Input(
        "result",
        "path",
        "the run's result_run_<n>_<date>.yaml, compared with the recomputed score; default: "
        "found beside the bag or in results/HNF/<team>/",
        metavar="FILE",
    ),
    Input(
        "team",
        "str",
        "the team (default: rsbb_logs/HNF/<team>/ of the bag, else the result file's)",
        metavar="NAME",
        per_team=True,
    ),
    Input(
        "max_gap",
        "float",
        f"a pose needs mocap samples at most S seconds apart around the lookup (default "
        f"{DEFAULT_MAX_GAP_S:g})",
        default=DEFAULT_MAX_GAP_S,
        unit="s",
        positive=True,
    ),
    Input(
        "orientation_2019",
        "flag",
        "orientation accuracy from the unwrapped |dtheta| as the script summed it",
        group=SCRIPT,
    ),
    Input(
        "divisor",
        "choice",
        "2019: every acquired pose's error (timed-out goals too) divided by the completed "
        "goals, a skipped waypoint counted (default ertools: the completed goals with a pose)",
        choices=("ertools", "2019"),
        group=SCRIPT,
    ),
    Input(
        "gt_gaps",
        "choice",
        "interpolate: tf's pose across any mocap gap (default refuse: beyond --max-gap)",
        choices=("refuse", "interpolate"),
        group=SCRIPT,
    ),
    Input(
        "score_format",
        "choice",
        "2019: target_pose and robot_pose as the script's YAML dumps (default ertools: "
        "{x, y, theta})",
        choices=("ertools", "2019"),
        group=SCRIPT,
    ),
    Input(
        "rules",
        "choice",
        "a script's every behaviour: 2019 (rockin-robot-challenge/rsbb 2bb8a41), 2017 "
        "(Enri2077/rsbb 00e3106, December 2017 to May 2018), f594ff1 and 069fd1d (November "
        "2017); ertools (default): the options above decide",
        choices=RULE_SETS,
        group=SCRIPT,
    ),
    *INTERVAL_INPUTS,
)


def make_options(given: Mapping[str, Any]) -> HnfOptions:
    """The values of :data:`INPUTS` -> :class:`HnfOptions`.

    Raises:
        UsageError: a value out of range, or options that contradict ``--rules``.
    """
    v = resolve_values(INPUTS, given)
    check_confidence(v["confidence"])
    return options_from(v)


def notes(result: HnfResult) -> list[str]:
    """The comparison with the run's own scores, the intervals, and the segments."""
    out = list(result.interval_lines())
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


def sample(samples: Path) -> list[str] | None:
    """The HNF sample run (``make demo``): its bag in the RSBB layout, side files found."""
    bags = sorted((samples / NAME).glob("rsbb_logs/HNF/*/run_*.bag"))
    return [str(bags[0])] if bags else None


EXPLANATIONS = (
    Explanation(
        r"orientation_(error|accuracy)",
        "the script summed sin and cos of the unwrapped |yaw difference|; ertools wraps it "
        "first (the same unless a segment crosses +-pi): --orientation-2019",
        ("rules",),
    ),
    Explanation(
        r"position_accuracy",
        "the script divides every acquired pose's error (timed-out goals too) by the "
        "completed goals: --divisor 2019",
        ("rules",),
    ),
)

EPILOG = """examples:
  ertools score hnf rsbb_output/rsbb_logs/HNF/homer/run_1_2019-04-10-14-31-06.bag
  ertools score hnf run_1.bag --config HNF.yaml --transform transform-homer.yaml
  ertools score hnf RUN.bag --rules 2019      # the 2019 script, field for field
  ertools score hnf RUN.bag --rules 2017      # the December 2017 script (00e3106)

The side files are found beside the bag or in the RSBB's folders (rsbb_etc/transforms/,
rsbb_bmbox/scripts/benchmark_configs/, results/HNF/<team>/), each named on stderr. The score
is printed in the result file's form; stderr compares it with the live score
(/rsbb/current_benchmark_result) and the result file, field by field."""

BENCHMARK: LegacyBenchmark[HnfOptions, HnfLogs, HnfFlow, HnfResult] = LegacyBenchmark(
    rules=RULES,
    name=NAME,
    title="HNF (FBM2@Home 2017-19)",
    summary="HNF (FBM2@Home 2017-19) navigation: the RSBB script re-scored",
    example="ertools score hnf rsbb_logs/HNF/homer/run_1_2019-04-10-14-31-06.bag",
    description="""Recompute an HNF (ERL @Home FBM2, navigation) score from its RSBB run bag.

The script's control flow is followed through the log (goals, timeouts, the referee's skip
and stop); the robot's pose is looked up at the moments the script's own /tf broadcasts record,
as tf computed it (marker set interpolated, the team transform composed). The score has the
result file's fields: per segment its times, outcome, poses and errors; then
position_accuracy, orientation_accuracy and execution_time.""",
    epilog=EPILOG,
    inputs=INPUTS,
    make_options=make_options,
    load=load,
    find_runs=find_runs,
    score_runs=score_runs,
    ranking=Ranking(
        key=lambda r: r.position_accuracy,
        lower_is_better=True,
        text="position_accuracy (metres, the mean distance to the waypoints): lower is better",
    ),
    notes=notes,
    figures="ertools.benchmarks.hnf.plots:figure_specs",
    foxglove="ertools.benchmarks.hnf.foxglove:content",
    bags_metavar="RUN_BAG",
    bags_help="the run's bag (rsbb_logs/HNF/<team>/run_<n>_<date>.bag)",
    score_keys=frozenset({"position_accuracy[m]", "orientation_accuracy[rad]"}),
    sample=sample,
    explanations=EXPLANATIONS,
    namespace="",
    source_inputs=(),
)
