"""FBM3@Work as the registry sees it: its inputs (the options of ``ertools score fbm3w``, the
manifest keys), how they become :class:`Fbm3wOptions`, and the load -> runs -> score stages.

Every value is checked here, once: ``--d-min`` (metres, >= 0, at most 5 cm), ``--d-min-sweep``,
the run windows and the switches that contradict each other.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ertools.benchmarks.base import (
    Benchmark,
    Explanation,
    FormerName,
    Input,
    Ranking,
    resolve_values,
    tf_value,
)
from ertools.benchmarks.common.ending import EXACT_HELP
from ertools.benchmarks.common.uncertainty import INTERVAL_INPUTS, check_confidence
from ertools.benchmarks.common.validity import UNSCOREABLE_CHOICES, unscoreable_input
from ertools.benchmarks.fbm3w.benchmark import Fbm3wLogs, load, locate_runs, score_found
from ertools.benchmarks.fbm3w.config import RUN_MODES, Fbm3wOptions, options_2015
from ertools.benchmarks.fbm3w.result import Fbm3wResult
from ertools.benchmarks.fbm3w.runs import RunWindow, parse_run_spec, parse_runs_file
from ertools.configs._yaml import load_yaml
from ertools.configs.fbm3w import check_d_min, load_fbm3w_config
from ertools.errors import ConfigError, UsageError

LEGACY = "2015 behaviour (each difference can be undone)"
SWEEP_MAX = 500  # values of --d-min-sweep: enough for a smooth curve, bounded work

INPUTS = (
    Input(
        "config",
        "path",
        "runs_specifications (Listing 14), optional d_min and shapes (default: the 2015 "
        "values, as configs/fbm3w.yaml)",
        metavar="FILE",
    ),
    Input("d_min", "float", "subsampling threshold (2015: 0.00033)", unit="m", minimum=0.0),
    Input(
        "d_min_sweep",
        "str",
        "also score every run at N values of d_min from START to STOP (metres)",
        metavar="START:STOP:N",
    ),
    Input("runs", "choice", "how to find the runs (see below)", choices=RUN_MODES),
    Input(
        "run",
        "str",
        "an explicit run (repeatable; implies --runs windows)",
        repeat=True,
        metavar="SPEC:REF_T:START_T:END_T",
    ),
    Input("runs_file", "path", "explicit runs from a YAML file", metavar="FILE"),
    Input(
        "topic",
        "str",
        "end-effector pose topic (default /fbm3w/robot_at_work/pose2d, then .../pose)",
        metavar="TOPIC",
    ),
    Input(
        "tf",
        "str",
        "take the poses from /tf PARENT -> CHILD (e.g. world:robot_at_work)",
        metavar="PARENT:CHILD",
        old_flags=("--frame",),
    ),
    Input(
        "time_source",
        "choice",
        "pose time: header stamp (default; a Pose2D has none: its record time) or bag record "
        "time (the 2015 node received the poses live)",
        default="header",
        choices=("header", "record"),
    ),
    Input(
        "arc_length",
        "flag",
        "compare at equal fractions of the target's arc length (not 2015)",
    ),
    Input(
        "timeout_runs",
        "choice",
        "a run the RefBox timed out: listed without distance_error (default), or 2015: "
        "scored on the path it covered and eligible as best run",
        default="unscored",
        choices=("unscored", "2015"),
        group=LEGACY,
    ),
    Input(
        "stopped_runs",
        "choice",
        "a run the RefBox stopped: its time counted in execution_time (default), or 2015: left out",
        default="counted",
        choices=("counted", "2015"),
        group=LEGACY,
    ),
    Input("exact_end_payloads", "flag", EXACT_HELP, group=LEGACY),
    unscoreable_input(LEGACY, FormerName("unscoreable_runs")),
    Input(
        "rules",
        "choice",
        "every behaviour of one node at once: 2015 (scripts/fbm3w 50b173b, RoCKIn 2015 "
        "Lisbon: --timeout-runs 2015 --stopped-runs 2015 --exact-end-payloads --unscoreable "
        "2015, d_min 0.00033 unless --d-min is given, no --arc-length) or ertools (default)",
        choices=("ertools", "2015"),
        group=LEGACY,
    ),
    Input("all_2015", "flag", "= --rules 2015", flag="--2015", group=LEGACY),
    Input(
        "still_speed",
        "float",
        "speed below which the marker set counts as still (default 0.004)",
        unit="m/s",
        positive=True,
    ),
    Input(
        "still_min",
        "float",
        "shortest stationary phase (default 0.5)",
        unit="s",
        positive=True,
    ),
    *INTERVAL_INPUTS,
)


def parse_sweep(text: str) -> tuple[float, ...]:
    """``START:STOP:N`` -> N evenly spaced d_min values (metres).

    Raises:
        UsageError: not three fields, negative or infinite bounds, N outside 1..500.
    """

    parts = text.split(":")
    try:
        if len(parts) != 3:
            raise ValueError
        start, stop, n = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise UsageError(
            f"--d-min-sweep {text!r}: expected START:STOP:N, e.g. 0.0001:0.001:10"
        ) from None
    if not (math.isfinite(start) and math.isfinite(stop)) or min(start, stop) < 0:
        raise UsageError(f"--d-min-sweep {text!r}: START and STOP must be >= 0 metres")
    if not 1 <= n <= SWEEP_MAX:
        raise UsageError(f"--d-min-sweep {text!r}: N must be between 1 and {SWEEP_MAX}")
    if n == 1:
        return (start,)
    step = (stop - start) / (n - 1)
    return tuple(round(start + i * step, 12) for i in range(n))  # no 0.00039999999999999996


def _d_min(value: float, where: str) -> float:
    """A d_min in metres, refused (usage error) when it cannot be one."""

    try:
        return check_d_min(value, where)
    except ConfigError as err:
        raise UsageError(err.message) from None


def make_options(given: Mapping[str, Any]) -> Fbm3wOptions:
    """The values of :data:`INPUTS` -> :class:`Fbm3wOptions` (the config file read).

    Raises:
        UsageError: a value out of range, contradicting switches (exit 2).
        ConfigError: an unreadable config or runs file, a malformed run window (exit 1).
    """

    v = resolve_values(INPUTS, given)
    windows = [parse_run_spec(text, i) for i, text in enumerate(v["run"])]
    if v["runs_file"] is not None:
        windows += parse_runs_file(load_yaml(v["runs_file"], "run list"), str(v["runs_file"]))
    if windows and v["runs"] not in (None, "windows"):
        raise UsageError(
            f"--run/--runs-file give explicit windows; they contradict --runs {v['runs']}"
        )
    node = bool(v["all_2015"]) or v["rules"] == "2015"
    if node and v["arc_length"]:
        raise UsageError("--2015 and --arc-length contradict each other (2015 had no arc length)")
    if v["topic"] is not None and v["tf"] is not None:
        raise UsageError("give either --topic or --tf, not both")
    tf = tf_value("--tf", v["tf"])
    d_min = None if v["d_min"] is None else _d_min(v["d_min"], "--d-min")
    sweep = () if v["d_min_sweep"] is None else parse_sweep(v["d_min_sweep"])
    for value in sweep:
        _d_min(value, "--d-min-sweep")
    options = Fbm3wOptions(
        runs=v["runs"],
        windows=tuple(windows),
        d_min=d_min,
        sweep=sweep,
        topic=v["topic"],
        frame=None if tf is None else tf[1],
        tf_parent="world" if tf is None else tf[0],
        time_source=v["time_source"],
        still_speed=v["still_speed"],
        min_still_s=v["still_min"],
        arc_length=v["arc_length"],
        timeout_runs=v["timeout_runs"],
        stopped_runs=v["stopped_runs"],
        exact_end_payloads=v["exact_end_payloads"],
        unscoreable_runs=v["unscoreable"] or UNSCOREABLE_CHOICES[0],
        config=load_fbm3w_config(v["config"]),
        confidence=check_confidence(v["confidence"]),
        draws=v["draws"],
        seed=v["seed"],
    )
    return options_2015(options) if node else options


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


def sample(samples: Path) -> list[str] | None:
    """The FBM3@Work sample log (``make demo``)."""
    bags = sorted((samples / "fbm3w").glob("*.bag"))
    return [str(bags[0])] if bags else None


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


def gt_only(bags: Sequence[Path]) -> dict[str, Any]:
    """A GT-only FBM3@Work log (mocap alone, no state topics: the 2015 test logs) is scored
    with runs found from motion alone (``runs: auto``); its row says why when none is found
    (a marker set lying still is a noise recording, not an execution)."""
    return {"runs": "auto"}


BENCHMARK: Benchmark[Fbm3wOptions, Fbm3wLogs, Sequence[RunWindow], Fbm3wResult] = Benchmark(
    name="fbm3w",
    title="FBM3@Work",
    summary="FBM3@Work trajectory following: path error",
    example="ertools score fbm3w run.bag --config configs/fbm3w.yaml",
    description="""Recompute an FBM3@Work (trajectory following) score from the logs
(seed 7.3, Listing 16).

Per run: the measured end-effector path subsampled with d_min, put in the run frame (origin at
the starting position, x axis along reference -> start), compared with the target shape at
each kept point's normalised path length; distance_error = the mean distance (Eq. 1). Then
best_run, best_distance_error and execution_time (sum of the run times).""",
    epilog=EPILOG,
    inputs=INPUTS,
    make_options=make_options,
    load=load,
    find_runs=locate_runs,
    score_runs=score_found,
    ranking=Ranking(
        key=lambda r: r.best_distance_error,
        lower_is_better=True,
        text="best_distance_error (metres, the best run's mean distance to the target): "
        "lower is better",
    ),
    notes=notes,
    figures="ertools.report.plots_fbm3w:figure_specs",
    foxglove="ertools.report.foxglove.fbm3w:content",
    score_keys=frozenset({"best_distance_error", "runs_details"}),
    state_topics=True,
    # The 2015 node's hard-coded d_min too, whatever d_min the audit was given.
    values_2015={"all_2015": True, "d_min": None},
    sample=sample,
    explanations=EXPLANATIONS,
    gt_only=gt_only,
)
