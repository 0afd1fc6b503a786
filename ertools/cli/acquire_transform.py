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

from ertools.atomic import write_text as write_file
from ertools.benchmarks.common.sources import read_source, topic
from ertools.benchmarks.fbm2h.acquire import acquire_transform, check_team_name
from ertools.cli.options import (
    add_out_dir,
    add_pose_source,
    add_time_source,
    finite,
    pose_spec,
    positive,
)
from ertools.cli.output import note, write_text
from ertools.configs.transform import team_transform_path, transform_yaml
from ertools.errors import ConfigError
from ertools.io.summary import summary
from ertools.streams import Interval
from ertools.timeutil import resolve_time, s_to_ns

EPILOG = """examples:
  ertools acquire transform robot_at_origin.bag --team homer
  ertools acquire transform robot_at_origin.bag --team homer --at 12.5 --duration 5 \\
      --out-dir transforms/

--at: seconds from the bag's first message (or epoch seconds). The file is printed on stdout
too; an existing file is only replaced with --force."""

DEFAULT_TOPIC = "/fbm2h/robot_at_home/pose"


def _number(text: str) -> float:
    return finite(text)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bags", nargs="+", type=Path, metavar="BAG", help="log file(s)")
    parser.add_argument("--team", required=True, metavar="NAME", help="team name (file name)")
    parser.add_argument(
        "--at", type=_number, metavar="T", help="start of the stationary window (seconds)"
    )
    parser.add_argument(
        "--duration", type=positive, default=5.0, metavar="S", help="window length with --at (5 s)"
    )
    add_pose_source(
        parser,
        what="the marker set",
        default=DEFAULT_TOPIC,
        old_frame=("--tf-frame", "--frame"),
    )
    add_time_source(parser)
    add_out_dir(
        parser,
        "write DIR/transform-NAME.yaml (default .)",
        old=("--out",),
        default=Path("."),
    )
    parser.add_argument("--force", action="store_true", help="replace an existing file")


def run(args: argparse.Namespace) -> int:
    team = check_team_name(args.team)
    out = team_transform_path(args.out_dir, team)
    if out.exists() and not args.force:
        raise ConfigError(f"{out} exists; use --force to replace it")
    spec = pose_spec(args)
    window = None
    # Times in messages count from the log's first message, as --at does.
    bag_start = min(summary(p).start_ns for p in args.bags)
    if args.at is not None:
        start = resolve_time(args.at, bag_start)
        window = Interval(start, start + s_to_ns(args.duration))
    marker = read_source(args.bags, spec, (topic(DEFAULT_TOPIC),), what="marker set poses")
    acq = acquire_transform(marker, team, window=window, origin_ns=bag_start)
    text = transform_yaml(acq.transform)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_text(text, None)
    write_file(out, text)
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
