"""Mocap noise statistics of a stationary marker set and the d_min they suggest (seed 7.3.13).

The distance in the plane between consecutive measurements (binned as the 2015
mocap_noise_statistics tool, 0.15 mm), the lost samples (two consecutive identical poses:
Motive repeats the last pose when tracking is lost), epsilon = the mean distance between
consecutive measurements that differ, percentiles, and suggested d_min = c * epsilon.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import cast

from ertools.benchmarks.common.epsilon import NoiseResult
from ertools.benchmarks.noise.declare import BENCHMARK
from ertools.benchmarks.scoring import score_execution
from ertools.cli.emit import write_plots
from ertools.cli.options import (
    add_output,
    add_plots,
    add_pose_source,
    add_time_source,
    positive,
)
from ertools.cli.output import dump_json, note, write_text
from ertools.report.figures import figure_specs
from ertools.serialize import dump_yaml

EPILOG = """examples:
  ertools noise log_fbm3w_noise.bag
  ertools noise stationary.bag --topic /fbm3w/robot_at_work/pose --format json
  ertools noise log_fbm3w_mocap.bag --stationary auto --plot noise.png
  ertools noise still.bag --bin 0.0001 --c 4

Poses: --topic TOPIC or --tf PARENT:CHILD, else /fbm3w/robot_at_work/pose2d,
/fbm3w/robot_at_work/pose, /tf world:robot_at_work, else the bag's only pose topic.
--stationary auto keeps only the phases where the marker set stood still (any bag, e.g. a
benchmark run); the default takes the whole
recording as stationary, as the 2015 tool did. JSON keys: samples, lost, epsilon, percentiles
{"50", "95", "99"}, suggested_d_min (metres)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bags", nargs="+", type=Path, metavar="BAG", help="log file(s)")
    add_pose_source(
        parser,
        what="the marker set",
        default="the fbm3w pose2d, pose, tf world:robot_at_work, else the only pose topic",
        old_frame=("--frame",),
    )
    add_time_source(parser)
    parser.add_argument(
        "--stationary",
        choices=("all", "auto"),
        default="all",
        help="all: the whole recording is stationary (2015); auto: detect the still phases",
    )
    parser.add_argument(
        "--bin",
        type=positive,
        default=0.00015,
        metavar="M",
        help="histogram bin (default 0.00015 m)",
    )
    parser.add_argument(
        "--c", type=positive, default=3.0, help="suggested d_min = C * epsilon (default 3)"
    )
    add_output(parser, ("text", "json", "yaml"))
    add_plots(parser, what="the histogram")


def run(args: argparse.Namespace) -> int:
    tf = None if args.tf is None else ":".join(args.tf)
    values = {
        "topic": args.topic,
        "tf": tf,
        "time_source": args.time_source,
        "stationary": args.stationary,
        "bin": args.bin,
        "c": args.c,
    }
    # the stages of `ertools score noise`; this command prints the 2015 tool's text too
    result = cast(NoiseResult, score_execution(BENCHMARK, args.bags, values).result)
    if args.format == "json":
        text = dump_json(result.to_dict())
    elif args.format == "yaml":
        text = dump_yaml(result.to_dict())
    else:
        text = result.to_text()
    write_text(text, args.out)
    for warning in result.warnings:
        note(f"warning: {warning}")
    if args.plot is not None or args.plots is not None:
        write_plots(figure_specs(result), args)
    return 0
