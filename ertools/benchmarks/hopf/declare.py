"""HOPF (FBM1@Home 2017-19) as the registry sees it: its inputs (the options of
``ertools score hopf``, the manifest keys) and its stages, each delegating to the same-named
function of :mod:`ertools.benchmarks.hopf.config` or :mod:`~ertools.benchmarks.hopf.pipeline`.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import Explanation, Input, Ranking, resolve_values
from ertools.benchmarks.common.inputs import INTERVAL_INPUTS
from ertools.benchmarks.hopf import config
from ertools.benchmarks.hopf.config import DEFAULT_MAX_GAP_S, NAME, RULE_SETS, HopfOptions
from ertools.benchmarks.hopf.pipeline import HopfLogs, find_runs, load, score_runs
from ertools.benchmarks.hopf.result import HopfResult
from ertools.benchmarks.hopf.rules import RULES
from ertools.benchmarks.hopf.runs import HopfRuns
from ertools.benchmarks.legacy import LegacyBenchmark

SCRIPT_GROUP = "the RSBB script's behaviour (each difference can be undone)"

INPUTS = (
    Input(
        "items",
        "path",
        "items_with_pose.yaml, the items the script drew from (default: beside the bag or in "
        "the RSBB layout)",
        metavar="FILE",
    ),
    Input(
        "config",
        "path",
        "HOPF.yaml, the benchmark config (default: beside the bag, the layout, or the result "
        "file's params)",
        metavar="FILE",
    ),
    Input(
        "result",
        "path",
        "the run's result file result_run_<n>_<date>.yaml, compared with the recomputed score "
        "(default: beside the bag or in the RSBB layout)",
        metavar="FILE",
    ),
    Input(
        "max_gap",
        "float",
        f"no ground truth across a tracking gap wider than this (default {DEFAULT_MAX_GAP_S} s)",
        unit="s",
        positive=True,
    ),
    Input(
        "rules",
        "choice",
        "reproduce a script version whole: 2019 (rsbb 2bb8a41, 2018-19), 2017 (Enri2077/rsbb "
        "00e3106, December 2017 to May 2018), 2017-11 (b5d91f4, November 2017); ertools "
        "(default): the options of this group decide",
        choices=RULE_SETS,
        group=SCRIPT_GROUP,
    ),
    Input(
        "clip_translation",
        "choice",
        "the translation term: clipped at 1 m (default) or none (the script: pose scores below 0)",
        choices=("1", "none"),
        group=SCRIPT_GROUP,
    ),
    Input(
        "single_wrap", "flag", "wrap the theta error by one step, as the script", group=SCRIPT_GROUP
    ),
    Input(
        "exact_names",
        "flag",
        "compare class and instance with their surrounding blanks, as the script",
        group=SCRIPT_GROUP,
    ),
    Input(
        "stopped_goals",
        "choice",
        "ertools (default): totals over the goals answered or timed out; 2019: divided by the "
        "goals begun, stale after a stop before a goal",
        choices=("ertools", "2019"),
        group=SCRIPT_GROUP,
    ),
    Input(
        "gt_gaps",
        "choice",
        "refuse (default): no ground truth across a gap wider than --max-gap; interpolate: as "
        "tf did",
        choices=("refuse", "interpolate"),
        group=SCRIPT_GROUP,
    ),
    *INTERVAL_INPUTS,
)


def make_options(given: Mapping[str, Any]) -> HopfOptions:
    """The values of :data:`INPUTS` -> :class:`HopfOptions`."""
    return config.make_options(resolve_values(INPUTS, given))


def notes(result: HopfResult) -> list[str]:
    """The intervals, the comparison with the run's own scores, what the scoring says and
    (``-v``) one line per goal."""
    out = result.interval_lines()
    if result.comparison is not None:
        out += result.comparison.summary()
    out += list(result.notes)
    if logging.getLogger("ertools").isEnabledFor(logging.INFO):
        for g in result.goals:
            score = "" if g.terms is None else f", pose score {g.terms[5]:.4f}"
            item = "?" if g.item is None else f"item {g.item.id}"
            out.append(f"  goal {g.index}: {item}, {g.status}{score}")
    return out


def sample(samples: Path) -> list[str] | None:
    """The HOPF sample run (``make demo``): its bag, items and result file."""
    folder = samples / NAME
    bags = sorted(folder.rglob("run_*.bag"))
    if not bags:
        return None
    return [str(bags[0])]


def files(bags: Sequence[Path], options: HopfOptions, result: HopfResult) -> list[Path]:
    """The bags and the side files the score read."""
    del options
    return [*bags, *(Path(p) for p in result.provenance.inputs[len(bags) :])]


EXPLANATIONS = (
    Explanation(
        r"pose_score$|pose_error|translation_score",
        "ertools clips the translation term at 1 m and wraps theta fully (--rules 2019: as "
        "the script); the ground truth is tf's interpolation at the script's own lookup",
        ("rules", "max_gap_s"),
    ),
    Explanation(r"accuracy$", "ertools divides by the goals answered or timed out", ("rules",)),
)

EPILOG = """examples:
  ertools score hopf rsbb_logs/HOPF/teamA/run_1_2019-04-11-16-26-40.bag
  ertools score hopf run_1.bag --items items_with_pose.yaml --result result_run_1.yaml
  ertools score hopf run_1.bag --rules 2019

The side files are found beside the bag or in the RSBB layout (rsbb_logs/, results/,
rsbb_etc/) and named on stderr. The answers are the goal results in the bag; the ground truth
is tf's lookup at the moment the script made it (its /item broadcast). --rules 2019 (2017,
2017-11) reproduces the script at that commit, quirks included; the score is compared with the
run's live score and result file on stderr."""

BENCHMARK: LegacyBenchmark[HopfOptions, HopfLogs, HopfRuns, HopfResult] = LegacyBenchmark(
    rules=RULES,
    name=NAME,
    title="HOPF (FBM1@Home 2017-19)",
    summary="HOPF object perception (RSBB 2017-19): class, instance and pose of 10 items",
    example="ertools score hopf rsbb_logs/HOPF/teamA/run_1_<date>.bag",
    description="""Recompute a HOPF (FBM1@Home, object perception, ERL 2017-19) score from its RSBB
run bag (docs/hopf.md).

Per goal: the item shown (the placement's text), its ground truth in the table frame (the
script's tf lookup of /item), the robot's answer (the goal result): class and instance right
or wrong, pose score 1 - t/2 - r/2; then class_accuracy, instance_accuracy, pose_score and
execution_time, in the result file's score form.""",
    epilog=EPILOG,
    inputs=INPUTS,
    make_options=make_options,
    load=load,
    find_runs=find_runs,
    score_runs=score_runs,
    ranking=Ranking(
        key=lambda r: r.pose_score,
        lower_is_better=False,
        text="pose_score (the mean pose score over the goals counted): higher is better",
    ),
    notes=notes,
    figures="ertools.benchmarks.hopf.plots:figure_specs",
    foxglove="ertools.benchmarks.hopf.foxglove:content",
    files=files,
    score_keys=frozenset({"class_accuracy", "instance_accuracy", "pose_score"}),
    sample=sample,
    explanations=EXPLANATIONS,
    bags_help="the RSBB run bag (rsbb_logs/HOPF/<team>/run_<n>_<date>.bag)",
    namespace="",
    source_inputs=(),
)
