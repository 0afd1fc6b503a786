"""Acquire a team's marker-set-to-robot transform from a log (seed 7.2.7, Listing 11).

Record the robot standing at (x=0, y=0, theta=0) of the testbed with its marker set tracked;
this averages the marker pose over a stationary window (the longest one found, or
--at T --duration S) and writes DIR/transform-NAME.yaml in the Listing 11 format, both
directions, with the acquisition time. The spread of the averaged poses is reported.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from ertools.cli.common import note, write_text

EPILOG = """examples:
  ertools acquire transform robot_at_origin.bag --team homer
  ertools acquire transform robot_at_origin.bag --team homer --at 12.5 --duration 5 \\
      --out transforms/

--at: seconds from the bag's first message (or epoch seconds). The file is printed on stdout
too; an existing file is only replaced with --force."""

DEFAULT_TOPIC = "/fbm2h/robot_at_home/pose"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bags", nargs="+", type=Path, metavar="BAG", help="log file(s)")
    parser.add_argument("--team", required=True, metavar="NAME", help="team name (file name)")
    parser.add_argument("--at", type=float, metavar="T", help="start of the stationary window")
    parser.add_argument(
        "--duration", type=float, default=5.0, metavar="S", help="window length with --at (5 s)"
    )
    parser.add_argument(
        "--topic", metavar="TOPIC", help=f"marker set pose topic (default {DEFAULT_TOPIC})"
    )
    parser.add_argument(
        "--tf-frame",
        "--frame",
        dest="tf_frame",
        metavar="FRAME",
        help="take /tf world -> FRAME instead",
    )
    parser.add_argument(
        "--out", type=Path, default=Path("."), metavar="DIR", help="where to write (default .)"
    )
    parser.add_argument("--force", action="store_true", help="replace an existing file")


def run(args: argparse.Namespace) -> int:
    from ertools.benchmarks.fbm2h.transform import acquire_transform, check_team_name
    from ertools.configs.transform import team_transform_path, transform_yaml
    from ertools.errors import ConfigError, UsageError
    from ertools.io import PoseSource, read_pose_source, summary
    from ertools.streams import Interval
    from ertools.timeutil import resolve_time, s_to_ns

    team = check_team_name(args.team)
    out = team_transform_path(args.out, team)
    if out.exists() and not args.force:
        raise ConfigError(f"{out} exists; use --force to replace it")
    if args.topic and args.tf_frame:
        raise UsageError("give either --topic or --tf-frame, not both")
    if args.duration <= 0:
        raise UsageError(f"--duration must be > 0, got {args.duration}")
    source = (
        PoseSource(topic=None, frame=args.tf_frame)
        if args.tf_frame
        else PoseSource(topic=args.topic or DEFAULT_TOPIC)
    )
    window = None
    # Times in messages count from the log's first message, as --at does.
    bag_start = min(summary(p).start_ns for p in args.bags)
    if args.at is not None:
        start = resolve_time(args.at, bag_start)
        window = Interval(start, start + s_to_ns(args.duration))
    marker = read_pose_source(list(args.bags), source)
    acq = acquire_transform(marker, team, window=window, origin_ns=bag_start)
    text = transform_yaml(acq.transform)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_text(text, None)
    out.write_text(text, encoding="utf-8")
    how = "detected" if acq.detected else "given"
    note(
        f"window ({how}): {(acq.window.start_ns - bag_start) / 1e9:.3f} s to "
        f"{(acq.window.end_ns - bag_start) / 1e9:.3f} s after the log's first message, "
        f"{acq.marker.count} poses"
    )
    note(
        f"spread: position {acq.marker.position_std * 1000:.2f} mm RMS, "
        # degrees as in the warnings (and `acquire items`), mrad beside them
        f"orientation {math.degrees(acq.marker.angle_std):.2f} deg "
        f"({acq.marker.angle_std * 1000:.2f} mrad) RMS"
    )
    for warning in acq.warnings:
        note(f"warning: {warning}")
    note(f"wrote {out}")
    return 0
