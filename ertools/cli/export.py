"""Write poses as TUM, KITTI or CSV for evo, pandas and other tools.

One source: a pose topic (--topic) or a tf frame (--tf PARENT:CHILD) of BAG... to -o FILE
(stdout without -o). The pair: with --out-dir, the first BAG is the robot log and the rest are
GT bags or folders, read as `ertools score trajectory` reads them; DIR gets robot.<fmt> and
gt.<fmt> for `evo_ape`. --matched writes only the pairs ertools scored, at the same stamps, so
that evo's APE (translation part, no alignment) equals ertools' position error.

Times are the int64 nanosecond stamps written as seconds with 9 exact decimals; numbers are
written with every digit (the shortest text that reads back to the same double).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ertools.benchmarks.trajectory.config import TrajectoryConfig
from ertools.benchmarks.trajectory.pairs import trajectory_pair
from ertools.cli.options import (
    add_pose_source,
    add_time_source,
    deprecated,
    non_negative,
    pose_spec,
    positive,
    seconds_or_auto,
)
from ertools.cli.output import note, write_text
from ertools.errors import UsageError
from ertools.exporting.formats import FORMATS, format_poses, format_times
from ertools.exporting.write import (
    KITTI_NEEDS_MATCHED,
    export_source,
    pair_paths,
    refuse_inputs,
    write_pair,
)
from ertools.geometry import Association
from ertools.io.names import INPUT_FORMATS, TextFormat
from ertools.io.text import is_text_trajectory, read_text_poses
from ertools.timeutil import iso_utc, ns_to_s, s_to_ns

EPILOG = """examples:
  ertools export gt.bag --topic /fbm2h/robot_at_home/pose --format tum -o gt.tum
  ertools export run.bag --tf world:robot_at_work --format csv -o robot.csv
  ertools export run.bag --topic /odom --format kitti -o odom.kitti --times times.txt
  ertools export robot.bag gt/ --out-dir evo/ --matched      # the pairs ertools scored
  evo_ape tum evo/gt.tum evo/robot.tum                       # = ertools' position_error

formats: tum = `t tx ty tz qx qy qz qw` per line; kitti = the 3x4 [R|t] row-major per line,
no time stamps (--times writes them, seconds from the first pose, like KITTI's times.txt);
csv = header, then t_ns,t_s,x,y,z,qx,qy,qz,qw,frame_id.
pair mode: robot stamps are on the GT clock (the applied --offset added). Without --matched
the GT is every GT pose within 1 s of the robot poses, for evo to associate itself.
exit status: 0 written, 1 unusable data, 2 usage error."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "bags",
        type=Path,
        nargs="+",
        metavar="BAG",
        help="log file(s); with --out-dir: ROBOT_BAG [GT_PATH...] (GT bags or folders; none when "
        "the robot bag holds the GT topic too, as evo's bag mode)",
    )
    # A file format (what the file holds), not the printing format of the other commands.
    parser.add_argument("--format", choices=FORMATS, default="tum", help="file format (tum)")
    parser.add_argument(
        "--input-format",
        choices=INPUT_FORMATS,
        default=None,
        help="read the inputs as this (default: detected by content): a TUM, KITTI, EuRoC or "
        "ertools CSV text trajectory, or a bag",
    )
    one = parser.add_argument_group("one pose source")
    add_pose_source(one, what="the poses")
    add_time_source(one)
    one.add_argument("-o", "--out", type=Path, metavar="FILE", help="write here (default: stdout)")
    deprecated(one, "--output", "--out", "out", convert=Path, metavar="FILE")
    one.add_argument(
        "--times",
        type=Path,
        metavar="FILE",
        help="with --format kitti: also write the times (s from the first pose) to FILE",
    )
    pair = parser.add_argument_group("the robot/GT pair of `score trajectory` (for evo_ape)")
    pair.add_argument(
        "--out-dir", type=Path, metavar="DIR", help="write DIR/robot.<fmt> and DIR/gt.<fmt>"
    )
    pair.add_argument(
        "--matched",
        action="store_true",
        help="only the scored pairs, GT taken at the robot stamps by --association",
    )
    pair.add_argument("--robot-topic", metavar="TOPIC", help="as in `score trajectory`")
    pair.add_argument("--gt-topic", metavar="TOPIC", help="as in `score trajectory`")
    pair.add_argument(
        "--association",
        choices=("linear", "nearest", "hold"),
        default=None,
        help="GT pose at a robot time with --matched (default linear; nearest with --t-max-diff)",
    )
    pair.add_argument(
        "--max-gap", type=positive, default=0.1, metavar="S", help="as in `score trajectory`"
    )
    pair.add_argument(
        "--t-max-diff",
        type=non_negative,
        default=None,
        metavar="S",
        help="evo's pairs (`evo_ape ... --t_max_diff S`; implies --association nearest), as "
        "in `score trajectory`",
    )
    pair.add_argument(
        "--offset",
        type=seconds_or_auto,
        default=0.0,
        metavar="S|auto",
        help="shift the robot stamps by S seconds (auto: with --apply-offset, the estimate)",
    )
    pair.add_argument("--apply-offset", action="store_true", help="as in `score trajectory`")
    pair.add_argument("--allow-partial", action="store_true", help="as in `score trajectory`")
    add_time_source(pair, "robot-", old=("--robot-time",))


# Pair options and their defaults: given without --out-dir they would be silently ignored.
PAIR_ONLY = {
    "matched": False,
    "robot_topic": None,
    "gt_topic": None,
    "association": None,
    "max_gap": 0.1,
    "t_max_diff": None,
    "offset": 0.0,
    "apply_offset": False,
    "allow_partial": False,
    "robot_time_source": None,
}


def run(args: argparse.Namespace) -> int:
    if args.out_dir is None:
        given = [f"--{n.replace('_', '-')}" for n, d in PAIR_ONLY.items() if getattr(args, n) != d]
        if given:
            raise UsageError(f"{', '.join(given)}: pair options; they need --out-dir DIR")
        return _run_one(args)
    for name, flag in (
        ("topic", "--topic"),
        ("tf", "--tf"),
        ("out", "-o/--out"),
        ("times", "--times"),
    ):
        if getattr(args, name) is not None:
            raise UsageError(
                f"{flag} is for one pose source; with --out-dir give --robot-topic/--gt-topic"
            )
    return _run_pair(args)


def _run_one(args: argparse.Namespace) -> int:
    kinds = [is_text_trajectory(p, args.input_format) for p in args.bags]
    if any(kinds):
        return _run_text(args, kinds)
    if args.topic is None and args.tf is None:
        raise UsageError("give --topic TOPIC or --tf PARENT:CHILD (or --out-dir for the pair)")
    if args.times is not None and args.format != "kitti":
        raise UsageError(f"--times is for --format kitti ({args.format} files hold the times)")
    if args.times is not None and args.out is None:
        raise UsageError("--times needs -o FILE (the poses and their times go to two files)")
    outputs = [p for p in (args.out, args.times) if p is not None]
    refuse_inputs(outputs, list(args.bags))
    if args.tf is not None and args.time_source == "record":
        raise UsageError("--time-source record is for --topic; tf poses carry their own stamps")
    stream, text = export_source(list(args.bags), pose_spec(args), args.format)
    write_text(text, args.out)
    if args.times is not None:
        write_text(format_times(stream), args.times)
        note(f"times count from the first pose, {iso_utc(stream.start_ns)}")
    if args.format == "kitti":
        note("KITTI has no time stamps: a reader pairs files row by row")
    note(f"{len(stream)} poses from {stream.source}")
    return 0


def _run_text(args: argparse.Namespace, kinds: list[TextFormat | None]) -> int:
    """One text trajectory (TUM, KITTI, EuRoC, ertools CSV) converted to --format."""
    if len(args.bags) != 1 or kinds[0] is None:
        raise UsageError("a text trajectory is exported on its own: give one file")
    if args.topic is not None or args.tf is not None or args.time_source is not None:
        raise UsageError(
            f"{args.bags[0]} is a {kinds[0].upper()} text trajectory: --topic, --tf and "
            "--time-source are for bags"
        )
    if args.times is not None and args.format != "kitti":
        raise UsageError(f"--times is for --format kitti ({args.format} files hold the times)")
    outputs = [p for p in (args.out, args.times) if p is not None]
    refuse_inputs(outputs, list(args.bags))
    stream = read_text_poses(args.bags[0], kinds[0])
    write_text(format_poses(stream, args.format), args.out)
    if args.times is not None:
        write_text(format_times(stream), args.times)
    note(f"{len(stream)} poses from {stream.source} ({kinds[0].upper()})")
    return 0


def _run_pair(args: argparse.Namespace) -> int:
    auto = args.offset == "auto"
    if args.apply_offset and not auto:
        raise UsageError("--apply-offset needs --offset auto")
    if args.format == "kitti" and not args.matched:
        raise UsageError(KITTI_NEEDS_MATCHED)
    refuse_inputs(list(pair_paths(args.out_dir, args.format).values()), list(args.bags))
    association: Association = args.association or (
        "nearest" if args.t_max_diff is not None else "linear"
    )
    config = TrajectoryConfig(
        association=association,
        max_gap_ns=s_to_ns(args.max_gap),
        offset_ns=0 if auto else s_to_ns(float(args.offset)),
        auto_offset=auto,
        apply_offset=bool(args.apply_offset),
        allow_partial=bool(args.allow_partial),
        t_max_diff=args.t_max_diff,
    )
    robot_bag, *gt_paths = args.bags
    both = args.time_source
    robot_time = getattr(args, "robot_time_source", None)
    if both is not None and robot_time is not None and both != robot_time:
        raise UsageError(
            f"--time-source {both} sets the robot's time too: it cannot take "
            f"--robot-time-source {robot_time}"
        )
    pair = trajectory_pair(
        robot_bag,
        gt_paths,
        config,
        robot_topic=args.robot_topic,
        gt_topic=args.gt_topic,
        robot_time=robot_time or both or "header",
        gt_time=both or "header",
        input_format=args.input_format,
        matched=bool(args.matched),
    )
    written = write_pair(pair, args.out_dir, args.format)
    r = pair.result
    for path in written:
        note(f"wrote {path}")
    note(
        f"robot {r.robot_topic} ({len(pair.robot)} poses, stamps shifted by "
        f"{ns_to_s(r.offset_ns):+g} s), GT {r.gt_topic} ({len(pair.gt)} poses)"
    )
    for warning in r.warnings:
        note(f"warning: {warning}")
    if pair.matched:
        note(
            f"the {r.compared} pairs ertools scored ({r.config.association}; {r.gaps} in GT gaps, "
            f"{r.tracking_lost} while tracking was lost, {r.uncovered} outside the GT left out)"
        )
        if r.metrics is not None and args.format == "tum":
            note(
                f"evo_ape tum {written[1]} {written[0]} gives APE mean "
                f"{r.metrics.position_error:.6f} m = ertools' position_error"
            )
    else:
        note(
            "raw streams: evo associates them itself (its defaults: nearest stamp within "
            "0.01 s, every pose kept); --matched gives the pairs ertools scored"
        )
    return 0
