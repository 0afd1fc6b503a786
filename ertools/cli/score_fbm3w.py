"""Recompute an FBM3@Work (trajectory following) score from the logs (seed 7.3, Listing 16).

Per run: the measured end-effector path subsampled with d_min, put in the run frame (origin at
the starting position, x axis along reference -> start), compared with the target shape at
each kept point's normalised path length; distance_error = the mean distance (Eq. 1). Then
best_run, best_distance_error and execution_time (sum of the run times).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import TYPE_CHECKING, cast

from ertools.cli.common import add_output_options, all_failed, emit_result, note

if TYPE_CHECKING:
    from ertools.benchmarks.base import BenchmarkResult

EPILOG = """examples:
  ertools score fbm3w log_fbm3w_mocap.bag
  ertools score fbm3w run.bag --config configs/fbm3w.yaml --format json
  ertools score fbm3w run.bag --d-min 0.0005 --plot plots/
  ertools score fbm3w run.bag --d-min-sweep 0.0001:0.001:10
  ertools score fbm3w mocap_only.bag --runs auto
  ertools score fbm3w mocap_only.bag --run line:2.0:3.1:7.1 --run spline:9.3:10.5:16

--runs: states (default when /fbm3w/bmbox_state exists): reference = pose at
COMPLETED_MANUAL_OPERATION, path from EXECUTING_GOAL until WAITING_RESULT is left, as the 2015
node; windows: --run SPEC:REF_T:START_T:END_T (repeatable) or --runs-file FILE (YAML list of
{spec, reference, start, end}), times in seconds from the bag's first message or epoch
seconds; auto: runs found from motion alone (stationary at the reference, short move,
stationary at the start, the path, stationary at the end), detected times in the output.
Warnings (d_min below the noise measured on the bag's stationary phases, shapes not
parametrised by arc length) and deviations from 2015 go to stderr."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bags", nargs="+", type=Path, metavar="BAG", help="log file(s)")
    parser.add_argument(
        "--config",
        type=Path,
        metavar="FILE",
        help="runs_specifications (Listing 14), optional d_min and shapes "
        "(default: the 2015 values, as configs/fbm3w.yaml)",
    )
    parser.add_argument(
        "--d-min", type=float, metavar="M", help="subsampling threshold in metres (2015: 0.00033)"
    )
    parser.add_argument(
        "--d-min-sweep",
        metavar="START:STOP:N",
        help="also score every run at N values of d_min from START to STOP (metres)",
    )
    parser.add_argument(
        "--runs", choices=("states", "windows", "auto"), help="how to find the runs (see below)"
    )
    parser.add_argument(
        "--run",
        action="append",
        default=[],
        metavar="SPEC:REF_T:START_T:END_T",
        help="an explicit run (repeatable; implies --runs windows)",
    )
    parser.add_argument(
        "--runs-file", type=Path, metavar="FILE", help="explicit runs from a YAML file"
    )
    parser.add_argument(
        "--topic",
        metavar="TOPIC",
        help="end-effector pose topic (default /fbm3w/robot_at_work/pose2d, then .../pose)",
    )
    parser.add_argument("--frame", metavar="FRAME", help="take the poses from /tf world -> FRAME")
    parser.add_argument(
        "--time-source",
        choices=("record", "header"),
        default="record",
        help="pose time: bag record time (default: the 2015 node received poses live) or header",
    )
    parser.add_argument(
        "--arc-length",
        action="store_true",
        help="compare at equal fractions of the target's arc length (not 2015)",
    )
    legacy = parser.add_argument_group("2015 behaviour (each difference can be undone)")
    legacy.add_argument(
        "--timeout-runs",
        choices=("unscored", "2015"),
        default="unscored",
        help="a run the RefBox timed out: listed without distance_error (default), or 2015: "
        "scored on the path it covered and eligible as best run",
    )
    legacy.add_argument(
        "--stopped-runs",
        choices=("counted", "2015"),
        default="counted",
        help="a run the RefBox stopped: its time counted in execution_time (default), or "
        "2015: left out",
    )
    legacy.add_argument(
        "--2015",
        dest="all_2015",
        action="store_true",
        help="every 2015 behaviour: --timeout-runs 2015 --stopped-runs 2015, d_min 0.00033 "
        "unless --d-min is given, no --arc-length",
    )
    parser.add_argument(
        "--still-speed",
        type=float,
        metavar="M/S",
        help="speed below which the marker set counts as still (default 0.004)",
    )
    parser.add_argument(
        "--still-min",
        type=float,
        metavar="S",
        help="shortest stationary phase in seconds (default 0.5)",
    )
    add_output_options(parser)


def parse_sweep(text: str) -> tuple[float, ...]:
    """``START:STOP:N`` -> N evenly spaced d_min values (metres)."""
    from ertools.errors import UsageError

    parts = text.split(":")
    try:
        start, stop, n = float(parts[0]), float(parts[1]), int(parts[2])
        if len(parts) != 3:
            raise ValueError
    except (ValueError, IndexError):
        raise UsageError(
            f"--d-min-sweep {text!r}: expected START:STOP:N, e.g. 0.0001:0.001:10"
        ) from None
    if not (math.isfinite(start) and math.isfinite(stop)) or min(start, stop) < 0:
        raise UsageError(f"--d-min-sweep {text!r}: START and STOP must be >= 0 metres")
    if not 1 <= n <= 500:
        raise UsageError(f"--d-min-sweep {text!r}: N must be between 1 and 500")
    if n == 1:
        return (start,)
    step = (stop - start) / (n - 1)
    return tuple(round(start + i * step, 12) for i in range(n))  # no 0.00039999999999999996


def run(args: argparse.Namespace) -> int:
    from ertools.benchmarks.fbm3w.benchmark import Fbm3wOptions, options_2015, score_fbm3w
    from ertools.benchmarks.fbm3w.runs import parse_run_spec, parse_runs_file
    from ertools.configs._yaml import load_yaml
    from ertools.configs.fbm3w import check_d_min, load_fbm3w_config
    from ertools.errors import UsageError

    config = load_fbm3w_config(args.config)
    windows = [parse_run_spec(text, i) for i, text in enumerate(args.run)]
    if args.runs_file is not None:
        windows += parse_runs_file(load_yaml(args.runs_file, "run list"), str(args.runs_file))
    if windows and args.runs not in (None, "windows"):
        raise UsageError(
            f"--run/--runs-file give explicit windows; they contradict --runs {args.runs}"
        )
    d_min = None if args.d_min is None else check_d_min(args.d_min, "--d-min")
    sweep = () if args.d_min_sweep is None else parse_sweep(args.d_min_sweep)
    for value in sweep:
        check_d_min(value, "--d-min-sweep")
    options = Fbm3wOptions(
        runs=args.runs,
        windows=tuple(windows),
        d_min=d_min,
        sweep=sweep,
        topic=args.topic,
        frame=args.frame,
        time_source=args.time_source,
        still_speed=args.still_speed,
        min_still_s=args.still_min,
        arc_length=args.arc_length,
        timeout_runs=args.timeout_runs,
        stopped_runs=args.stopped_runs,
    )
    if args.all_2015:
        if args.arc_length:
            raise UsageError(
                "--2015 and --arc-length contradict each other (2015 had no arc length)"
            )
        options = options_2015(options)
    result = score_fbm3w(args.bags, config, options)
    if all_failed(result):  # nothing scored: only the errors
        return emit_result(cast("BenchmarkResult", result), args, list(args.bags))
    for r in result.runs:
        if r.window.mode == "auto":
            note(
                f"run {r.index} ({r.spec}) found at reference {r.details()['reference_time']} s, "
                f"path {r.details()['start_time']}-{r.details()['end_time']} s "
                "(seconds from the bag's first message)"
            )
    if result.sweep_values:
        note("distance_error of every run over d_min (--d-min-sweep):")
        for line in result.sweep_text().splitlines():
            note("  " + line)
    return emit_result(cast("BenchmarkResult", result), args, list(args.bags))
