"""HPFF (FBM5@Home 2019) as the registry sees it: its inputs (the options of ``ertools score
hpff``, the manifest keys), how they become :class:`HpffOptions`, and its stages."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import Explanation, Input, Ranking, resolve_values
from ertools.benchmarks.common.inputs import INTERVAL_INPUTS, check_confidence
from ertools.benchmarks.hpff.config import DEFAULT_MAX_GAP_S, RULE_SETS, HpffOptions, options_from
from ertools.benchmarks.hpff.flow import HpffFlow
from ertools.benchmarks.hpff.logs import HpffLogs
from ertools.benchmarks.hpff.pipeline import find_runs, load, score_runs
from ertools.benchmarks.hpff.result import HpffResult
from ertools.benchmarks.hpff.rules import RULES
from ertools.benchmarks.legacy import LegacyBenchmark

NAME = "hpff"
SCRIPT = "the 2019 script (differences can be undone one by one)"

INPUTS = (
    Input(
        "config",
        "path",
        "HPFF.yaml (distances, goal_timeout); default: found beside the bag or in the RSBB "
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
        "found beside the bag or in results/HPFF/<team>/",
        metavar="FILE",
    ),
    Input(
        "team",
        "str",
        "the team (default: rsbb_logs/HPFF/<team>/ of the bag, else the result file's)",
        metavar="NAME",
        per_team=True,
    ),
    Input(
        "max_gap",
        "float",
        f"grid samples: a body interpolated across at most S seconds between its mocap samples "
        f"(default {DEFAULT_MAX_GAP_S:g})",
        default=DEFAULT_MAX_GAP_S,
        unit="s",
        positive=True,
    ),
    Input(
        "sampling",
        "choice",
        "script: the script's own samples (its lookups; a lookup failed when the data came "
        "0.2 s late) (default grid: every 0.5 s, both bodies interpolated)",
        choices=("grid", "script"),
        group=SCRIPT,
    ),
    Input(
        "distance_plane",
        "choice",
        "actor: the distance in the cap's frame, as the script (default testbed: horizontal)",
        choices=("testbed", "actor"),
        group=SCRIPT,
    ),
    Input(
        "duration_clock",
        "choice",
        "script: from the script's start to its loop's end (default refbox: the goal's start "
        "to its end)",
        choices=("refbox", "script"),
        group=SCRIPT,
    ),
    Input(
        "rules",
        "choice",
        "2019: the script's every behaviour (rockin-robot-challenge/rsbb 2bb8a41, a stopped "
        "run's score {}); ertools (default): the options above decide",
        choices=RULE_SETS,
        group=SCRIPT,
    ),
    *INTERVAL_INPUTS,
)


def make_options(given: Mapping[str, Any]) -> HpffOptions:
    """The values of :data:`INPUTS` -> :class:`HpffOptions`.

    Raises:
        UsageError: a value out of range, or options that contradict ``--rules 2019``.
    """
    v = resolve_values(INPUTS, given)
    check_confidence(v["confidence"])
    return options_from(v)


def notes(result: HpffResult) -> list[str]:
    """The intervals, the comparison with the run's own scores, the samples and the duration."""
    out = list(result.interval_lines())
    out += result.comparison.summary()
    if result.rules != "ertools":
        out.append("reproducing: fbm5_person_following.py at 2bb8a41 (--rules 2019)")
    s = result.stats
    if s is not None:
        out.append(
            f"samples: {s.measured + s.failed}, measured {s.measured}, failed {s.failed}; "
            f"distance steps counted {int(s.counted.sum())}"
        )
    if result.duration_s is not None:
        verdict = "passed" if result.passed else "failed"
        out.append(
            f"duration {result.duration_s:.3f} s against goal_timeout {result.goal_timeout:g} "
            f"+- 15 s: {verdict}"
        )
    return out


def sample(samples: Path) -> list[str] | None:
    """The HPFF sample run (``make demo``): its bag in the RSBB layout, side files found."""
    bags = sorted((samples / NAME).glob("rsbb_logs/HPFF/*/run_*.bag"))
    return [str(bags[0])] if bags else None


EXPLANATIONS = (
    Explanation(
        r"deviation|covered|reliability",
        "the script sampled at its own lookups' moments, in the cap's frame; ertools samples "
        "a 2 Hz grid, horizontally: --sampling script --distance-plane actor",
        ("rules",),
    ),
)

EPILOG = """examples:
  ertools score hpff rsbb_output/rsbb_logs/HPFF/homer/run_1_2019-04-10-15-02-11.bag
  ertools score hpff RUN.bag --config HPFF.yaml --transform transform-homer.yaml
  ertools score hpff RUN.bag --rules 2019     # the 2019 script, field for field

The side files are found beside the bag or in the RSBB's folders, each named on stderr. The
score is printed in the result file's form; stderr compares it with the live score and the
result file, field by field."""

BENCHMARK: LegacyBenchmark[HpffOptions, HpffLogs, HpffFlow, HpffResult] = LegacyBenchmark(
    rules=RULES,
    name=NAME,
    title="HPFF (FBM5@Home 2019)",
    summary="HPFF (FBM5@Home 2019) person following: the RSBB script re-scored",
    example="ertools score hpff rsbb_logs/HPFF/homer/run_1_2019-04-10-15-02-11.bag",
    description="""Recompute an HPFF (ERL @Home FBM5, person following) score from its RSBB run bag.

The robot follows a person wearing a cap with markers for the goal's duration. Every 0.5 s
the distance between them is sampled (ertools: a 2 Hz grid over the mocap; --sampling
script: the script's own lookups); the score has the result file's fields: the average
deviation from the desired distance, the distance covered while following within range, the
reliability; a run outside goal_timeout +- 15 s fails.""",
    epilog=EPILOG,
    inputs=INPUTS,
    make_options=make_options,
    load=load,
    find_runs=find_runs,
    score_runs=score_runs,
    ranking=Ranking(
        key=lambda r: r.average_deviation,
        lower_is_better=True,
        text="average deviation from the desired following distance (metres): lower is better",
    ),
    notes=notes,
    figures="ertools.benchmarks.hpff.plots:figure_specs",
    foxglove="ertools.benchmarks.hpff.foxglove:content",
    bags_metavar="RUN_BAG",
    bags_help="the run's bag (rsbb_logs/HPFF/<team>/run_<n>_<date>.bag)",
    score_keys=frozenset({"Average deviation from desired distance", "Benchmark reliability"}),
    sample=sample,
    explanations=EXPLANATIONS,
    namespace="",
    source_inputs=(),
)
