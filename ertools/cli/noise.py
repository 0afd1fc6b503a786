"""Mocap noise statistics of a stationary marker set and the d_min they suggest (seed 7.3.13).

The distance in the plane between consecutive measurements (binned as the 2015
mocap_noise_statistics tool, 0.15 mm), the lost samples (two consecutive identical poses:
Motive repeats the last pose when tracking is lost), epsilon = the mean distance between
consecutive measurements that differ, percentiles, and suggested d_min = c * epsilon.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from ertools.cli.common import dump_json, note, write_text

if TYPE_CHECKING:
    from ertools.streams import PoseStream

EPILOG = """examples:
  ertools noise log_fbm3w_noise.bag
  ertools noise stationary.bag --topic /fbm3w/robot_at_work/pose --format json
  ertools noise log_fbm3w_mocap.bag --stationary auto --plot noise.png
  ertools noise still.bag --bin 0.0001 --c 4

Poses: --topic, else /fbm3w/robot_at_work/pose2d, /fbm3w/robot_at_work/pose, /tf
robot_at_work, else the bag's only pose topic. --stationary auto keeps only the phases where
the marker set stood still (any bag, e.g. a benchmark run); the default takes the whole
recording as stationary, as the 2015 tool did. JSON keys: samples, lost, epsilon, percentiles
{"50", "95", "99"}, suggested_d_min (metres)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bags", nargs="+", type=Path, metavar="BAG", help="log file(s)")
    parser.add_argument("--topic", metavar="TOPIC", help="pose topic (Pose2D, PoseStamped...)")
    parser.add_argument("--frame", metavar="FRAME", help="take the poses from /tf world -> FRAME")
    parser.add_argument(
        "--stationary",
        choices=("all", "auto"),
        default="all",
        help="all: the whole recording is stationary (2015); auto: detect the still phases",
    )
    parser.add_argument(
        "--bin", type=float, default=0.00015, metavar="M", help="histogram bin (default 0.00015 m)"
    )
    parser.add_argument(
        "--c", type=float, default=3.0, help="suggested d_min = C * epsilon (default 3)"
    )
    parser.add_argument(
        "--format", choices=("text", "json"), default="text", help="output format (default text)"
    )
    parser.add_argument(
        "-o", "--output", type=Path, help="write the output to this file instead of stdout"
    )
    parser.add_argument("--plot", type=Path, metavar="FILE", help="write a histogram figure (PNG)")


def _poses(args: argparse.Namespace) -> PoseStream:
    from ertools.benchmarks.fbm3w.benchmark import Fbm3wOptions, read_fbm3w_poses
    from ertools.errors import TopicError
    from ertools.io import read_poses, topics

    opts = Fbm3wOptions(topic=args.topic, frame=args.frame, time_source="header")
    if args.topic is not None or args.frame is not None:
        return read_fbm3w_poses(args.bags, opts)
    present = topics(args.bags)
    if "/fbm3w/robot_at_work/pose2d" in present or "/fbm3w/robot_at_work/pose" in present:
        return read_fbm3w_poses(args.bags, opts)
    from ertools.io.model import POSE_TYPES, TF_TYPES

    found = [t for t, ty in present.items() if ty in POSE_TYPES and ty not in TF_TYPES]
    if len(found) == 1:
        note(f"using the only pose topic {found[0]}")
        return read_poses(args.bags, found[0])
    raise TopicError(
        f"no /fbm3w/robot_at_work pose topic; pose topics there: {', '.join(found) or 'none'}; "
        "choose one with --topic (or a tf frame with --frame)",
        path=args.bags[0],
    )


def run(args: argparse.Namespace) -> int:
    from ertools.benchmarks.noise.benchmark import noise_from_stream

    poses = _poses(args)
    result = noise_from_stream(poses, stationary=args.stationary == "auto", bin=args.bin, c=args.c)
    text = dump_json(result.to_dict()) if args.format == "json" else result.to_text()
    write_text(text, args.output)
    for warning in result.warnings:
        note(f"warning: {warning}")
    if args.plot is not None:
        from matplotlib.figure import Figure

        from ertools.report.plots_noise import figure_specs

        spec = figure_specs(result)[0]
        fig = Figure(figsize=spec.size, layout="constrained")
        ax = fig.add_subplot()
        spec.draw(ax)
        ax.set_title(spec.title)
        args.plot.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(args.plot, dpi=110)
        note(f"wrote {args.plot}")
    return 0
