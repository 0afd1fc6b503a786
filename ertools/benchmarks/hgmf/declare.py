"""HGMF (FBM6@Home 2019) as the registry sees it: its inputs (the options of ``ertools score
hgmf``, the manifest keys), how they become :class:`HgmfOptions`, and its stages."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import Explanation, Input, Ranking, resolve_values
from ertools.benchmarks.common.inputs import INTERVAL_INPUTS
from ertools.benchmarks.hgmf import config
from ertools.benchmarks.hgmf.config import CODE, DEFAULT_MAX_GAP_S, NAME, RULE_SETS, HgmfOptions
from ertools.benchmarks.hgmf.flow import HgmfFlow
from ertools.benchmarks.hgmf.pipeline import HgmfLogs, find_runs, load, score_runs
from ertools.benchmarks.hgmf.result import HgmfResult
from ertools.benchmarks.hgmf.rules import RULES
from ertools.benchmarks.legacy import LegacyBenchmark

SCRIPT = "the 2019 script (differences can be undone one by one)"

INPUTS = (
    Input(
        "config",
        "path",
        "HGMF.yaml (objects, table_size, goal_timeout); default: found beside the bag or in "
        "the RSBB layout, else the result file's benchmark_info.params",
        metavar="FILE",
    ),
    Input(
        "result",
        "path",
        "the run's result_run_<n>_<date>.yaml, compared with the recomputed score; default: "
        "found beside the bag or in results/HGMF/<team>/",
        metavar="FILE",
    ),
    Input(
        "max_gap",
        "float",
        f"a position needs mocap samples at most S seconds apart around the lookup (default "
        f"{DEFAULT_MAX_GAP_S:g})",
        default=DEFAULT_MAX_GAP_S,
        unit="s",
        positive=True,
    ),
    Input(
        "restarted_goals",
        "choice",
        "2019: a goal restarted after its final lookup failed still counts in the divisor and "
        "the grasps (default ertools: the measured goals only)",
        choices=("ertools", "2019"),
        group=SCRIPT,
    ),
    Input(
        "grasp_sampling",
        "choice",
        "timer: a grasp checked at the script's 10 Hz ticks, at tf's latest common time "
        "(inferred); default samples: at every mocap sample of the object during the goal",
        choices=("samples", "timer"),
        group=SCRIPT,
    ),
    Input(
        "gt_gaps",
        "choice",
        "interpolate: tf's position across any mocap gap (default limit: --max-gap)",
        choices=("limit", "interpolate"),
        group=SCRIPT,
    ),
    Input(
        "rules",
        "choice",
        "2019: every behaviour of fbm6_grasping_manipulation.py at rockin-robot-challenge/rsbb "
        "2bb8a41, field for field; ertools (default): the options above decide",
        choices=RULE_SETS,
        group=SCRIPT,
    ),
    *INTERVAL_INPUTS,
)


def make_options(given: Mapping[str, Any]) -> HgmfOptions:
    """The values of :data:`INPUTS` -> :class:`HgmfOptions`.

    Raises:
        UsageError: a value out of range, or options that contradict ``--rules 2019``.
    """
    return config.make_options(resolve_values(INPUTS, given))


def notes(result: HgmfResult) -> list[str]:
    """The comparison with the run's own scores, the interval, and the goals."""
    out = list(result.interval_lines())
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


def sample(samples: Path) -> list[str] | None:
    """The HGMF sample run (``make demo``): its bag in the RSBB layout, side files found."""
    bags = sorted((samples / NAME).glob(f"rsbb_logs/{CODE}/*/run_*.bag"))
    return [str(bags[0])] if bags else None


EXPLANATIONS = (
    Explanation(
        r"Avg distance error|Objects grasped",
        "the script counts a goal restarted after its final lookup failed in the divisor and "
        "the grasps (--restarted-goals 2019), and checks grasps at 10 Hz (--grasp-sampling "
        "timer)",
        ("rules",),
    ),
)

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

BENCHMARK: LegacyBenchmark[HgmfOptions, HgmfLogs, HgmfFlow, HgmfResult] = LegacyBenchmark(
    rules=RULES,
    name=NAME,
    title=config.TITLE,
    summary="HGMF (FBM6@Home 2019) grasping and manipulation: the RSBB script re-scored",
    example="ertools score hgmf rsbb_logs/HGMF/homer/run_1_2019-04-11-10-00-00.bag",
    description="""Recompute an HGMF (ERL @Home FBM6, grasping and manipulation) score from
its RSBB run bag.

The script's control flow is followed through the log (objects placed, goals, timeouts,
restarts, the referee's stop); the object's height before each goal and its position after it
are looked up at the moments the script's own /tf broadcasts record, as tf computed them. The
score has the result file's fields: per goal its time, outcome, grasp, distance and positions;
then Objects grasped, Avg distance error and execution_time.""",
    epilog=EPILOG,
    inputs=INPUTS,
    make_options=make_options,
    load=load,
    find_runs=find_runs,
    score_runs=score_runs,
    ranking=Ranking(
        key=lambda r: r.average,
        lower_is_better=True,
        text="Avg distance error (metres, the objects' mean distance to their targets): "
        "lower is better",
    ),
    notes=notes,
    figures="ertools.benchmarks.hgmf.plots:figure_specs",
    foxglove="ertools.benchmarks.hgmf.foxglove:content",
    bags_metavar="RUN_BAG",
    bags_help="the run's bag (rsbb_logs/HGMF/<team>/run_<n>_<date>.bag)",
    score_keys=frozenset({"Avg distance error", "Objects grasped"}),
    sample=sample,
    explanations=EXPLANATIONS,
    namespace="",
    source_inputs=(),
)
