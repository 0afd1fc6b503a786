"""HPPF (FBM4@Home 2019) as the registry sees it: its inputs (the options of
``ertools score hppf``, the manifest keys) and its stages, each delegating to the same-named
function of :mod:`ertools.benchmarks.hppf.config` or :mod:`~ertools.benchmarks.hppf.pipeline`.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import Explanation, Input, Ranking, resolve_values
from ertools.benchmarks.common.inputs import INTERVAL_INPUTS
from ertools.benchmarks.hppf import config
from ertools.benchmarks.hppf.config import DEFAULT_MAX_GAP_S, NAME, RULE_SETS, HppfOptions
from ertools.benchmarks.hppf.pipeline import HppfLogs, find_runs, load, score_runs
from ertools.benchmarks.hppf.result import HppfResult
from ertools.benchmarks.hppf.rules import RULES
from ertools.benchmarks.hppf.runs import HppfRuns
from ertools.benchmarks.legacy import LegacyBenchmark

SCRIPT_GROUP = "the RSBB script's behaviour (each difference can be undone)"

INPUTS = (
    Input(
        "config",
        "path",
        "HPPF.yaml, its people (default: beside the bag, the layout, or the run's first live "
        "score)",
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
        "reproduce the script whole: 2019 (rsbb 2bb8a41, 2018-19); ertools (default): the "
        "options of this group decide",
        choices=RULE_SETS,
        group=SCRIPT_GROUP,
    ),
    Input(
        "exact_names",
        "flag",
        "compare the names lower-cased with their surrounding blanks, as the script",
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


def make_options(given: Mapping[str, Any]) -> HppfOptions:
    """The values of :data:`INPUTS` -> :class:`HppfOptions`."""
    return config.make_options(resolve_values(INPUTS, given))


def notes(result: HppfResult) -> list[str]:
    """The intervals, the comparison with the run's own scores, what the scoring says and
    (``-v``) one line per pass."""
    out = result.interval_lines()
    if result.comparison is not None:
        out += result.comparison.summary()
    out += list(result.notes)
    if logging.getLogger("ertools").isEnabledFor(logging.INFO):
        for p in result.passes:
            err = "" if p.position_error is None else f", {p.position_error:.3f} m"
            out.append(f"  goal {p.index}: {p.person}, {p.status}{err}")
    return out


def sample(samples: Path) -> list[str] | None:
    """The HPPF sample run (``make demo``)."""
    bags = sorted((samples / NAME).rglob("run_*.bag"))
    return [str(bags[0])] if bags else None


def files(bags: Sequence[Path], options: HppfOptions, result: HppfResult) -> list[Path]:
    """The bags and the side files the score read."""
    del options
    return [*bags, *(Path(p) for p in result.provenance.inputs[len(bags) :])]


EXPLANATIONS = (
    Explanation(
        r"position_error|Distance error|person position",
        "the ground truth is tf's interpolation at the script's own lookup; ertools refuses it "
        "across a tracking gap (--rules 2019: as the script)",
        ("rules", "max_gap_s"),
    ),
    Explanation(r"[Rr]ecogni", "ertools compares the names without surrounding blanks", ("rules",)),
)

EPILOG = """examples:
  ertools score hppf rsbb_logs/HPPF/teamA/run_1_2019-04-11-16-26-40.bag
  ertools score hppf run_1.bag --config HPPF.yaml --result result_run_1.yaml
  ertools score hppf run_1.bag --rules 2019

The side files are found beside the bag or in the RSBB layout and named on stderr. The
answers are the goal results in the bag; the ground truth is tf's lookup of the cap when the
script made it (its /person broadcast after the answer). --rules 2019 reproduces the script,
quirks included (a missing theta kills it; its percentage text); the score is compared with
the run's live score and result file on stderr."""

BENCHMARK: LegacyBenchmark[HppfOptions, HppfLogs, HppfRuns, HppfResult] = LegacyBenchmark(
    rules=RULES,
    name=NAME,
    title="HPPF (FBM4@Home 2019)",
    summary="HPPF people perception (RSBB 2019): who each person is and where",
    example="ertools score hppf rsbb_logs/HPPF/teamA/run_1_<date>.bag",
    description="""Recompute an HPPF (FBM4@Home, people perception, ERL 2019) score from its RSBB
run bag (docs/hppf.md).

Per goal: the person shown (the entry's text), the cap's position after the answer (the
script's tf lookup of /person), the robot's answer (the goal result): the name right or
wrong, the position error; then Recognized persons, % Recognized persons (over all the
people), Distance error (over the goals detected) and execution_time, in the result file's
score form.""",
    epilog=EPILOG,
    inputs=INPUTS,
    make_options=make_options,
    load=load,
    find_runs=find_runs,
    score_runs=score_runs,
    ranking=Ranking(
        key=lambda r: r.distance_error,
        lower_is_better=True,
        text="Distance error (metres, the mean position error over the goals detected): lower "
        "is better",
    ),
    notes=notes,
    figures="ertools.benchmarks.hppf.plots:figure_specs",
    foxglove="ertools.benchmarks.hppf.foxglove:content",
    files=files,
    score_keys=frozenset({"Distance error", "% Recognized persons"}),
    sample=sample,
    explanations=EXPLANATIONS,
    bags_help="the RSBB run bag (rsbb_logs/HPPF/<team>/run_<n>_<date>.bag)",
    namespace="",
    source_inputs=(),
)
