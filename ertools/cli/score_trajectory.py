"""Compare a robot's own pose log with the mocap ground truth (2015 offline trajectory benchmark).

The GT files are picked from GT_PATH (bags or folders) by time overlap with the robot log and
read as one stream; without GT_PATH the GT topic is read from the robot log itself (evo's
``bag`` mode). Every run also audits the clocks: it estimates the offset between the
robot's stamps and the GT clock and says when it matters.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import cast

EPILOG = """examples:
  ertools score trajectory robot.bag gt/ --robot-topic /rockin/homer/marker_pose \\
      --gt-topic /fbm2h/robot_at_home/pose
  ertools score trajectory robot.bag gt/ --2015        # what the 2015 script computed
  ertools score trajectory robot.bag gt/ --association hold --gaps compare
  ertools score trajectory robot.bag gt/ --offset auto --apply-offset --format json
  ertools score trajectory robot.bag gt/log_0.bag gt/log_1.bag --offset -0.35 --plot figs/
  ertools score trajectory both.bag --robot-topic /rockin/homer/marker_pose \
      --gt-topic /fbm2h/robot_at_home/pose     # one bag holding both topics (evo's bag mode)

offset: seconds added to the robot's stamps to put them on the GT clock (negative when the
robot's clock runs ahead). exit status: 0 scored, 1 unusable data, 2 usage error.
"""


def _offset(text: str) -> str | float:
    if text == "auto":
        return text
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"--offset takes seconds or 'auto', not {text!r}"
        ) from None


def _positive(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be positive, not {value}")
    return value


def _2015_options() -> str:
    from ertools.benchmarks.trajectory.config import SETTINGS_2015

    return " ".join(f"--{k.replace('_', '-')} {v}" for k, v in SETTINGS_2015.items())


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from ertools.cli.common import add_output_options

    parser.add_argument("robot_bag", type=Path, metavar="ROBOT_BAG", help="the robot's log")
    parser.add_argument(
        "gt_paths",
        type=Path,
        nargs="*",
        metavar="GT_PATH",
        help="GT bags or folders of them (none: the GT topic is in ROBOT_BAG itself)",
    )
    parser.add_argument(
        "--robot-topic",
        help="the robot's pose of its marker set (default: the one /rockin/*/marker_pose)",
    )
    parser.add_argument(
        "--gt-topic", help="the mocap pose of that marker set (default: the one PoseStamped topic)"
    )
    parser.add_argument(
        "--association",
        choices=("linear", "nearest", "hold"),
        default=None,
        help="GT pose at a robot time: interpolated (linear, default), nearest, or the last "
        "before (hold, 2015)",
    )
    parser.add_argument(
        "--ties",
        choices=("at", "before"),
        default=None,
        help="with --association hold, a robot pose stamped exactly at a GT sample is "
        "compared with that sample (at, default) or the one before it (before, 2015)",
    )
    parser.add_argument(
        "--gaps",
        choices=("skip", "compare"),
        default=None,
        help="robot poses in GT gaps longer than --max-gap: not compared (skip, default) or "
        "compared with the GT pose across the gap and counted (compare, 2015)",
    )
    parser.add_argument(
        "--before-gt",
        choices=("uncovered", "first"),
        default=None,
        help="robot poses before the first GT pose: uncovered (default: an error, or not "
        "scored with --allow-partial) or compared with the first GT pose (first, 2015)",
    )
    parser.add_argument(
        "--2015",
        dest="as_2015",
        action="store_true",
        help="compute what the 2015 script did: --association hold --ties before --gaps "
        "compare --before-gt first (2015's orientation error is orientation_error_2015)",
    )
    parser.add_argument(
        "--max-gap",
        type=_positive,
        default=0.1,
        metavar="S",
        help="a robot pose whose surrounding GT poses are further apart is in a GT gap "
        "(default 0.1 s; see --gaps)",
    )
    parser.add_argument(
        "--offset",
        type=_offset,
        default=0.0,
        metavar="S|auto",
        help="shift the robot stamps by S seconds, or estimate the shift (auto)",
    )
    parser.add_argument(
        "--apply-offset",
        action="store_true",
        help="with --offset auto: score with the estimated offset (else it is only reported)",
    )
    parser.add_argument(
        "--offset-range",
        type=_positive,
        default=5.0,
        metavar="S",
        help="the clock audit searches offsets within +-S seconds (default 5)",
    )
    parser.add_argument(
        "--allow-partial",
        action="store_true",
        help="score the covered part when robot poses lie outside the GT",
    )
    parser.add_argument(
        "--robot-time",
        choices=("header", "record"),
        default="header",
        help="robot pose time: message stamp (default) or the robot bag's record time",
    )
    add_output_options(parser)


def run(args: argparse.Namespace) -> int:
    from ertools.benchmarks.base import BenchmarkResult
    from ertools.benchmarks.trajectory.benchmark import score
    from ertools.benchmarks.trajectory.config import SETTINGS_2015, TrajectoryConfig
    from ertools.cli.common import emit_result
    from ertools.errors import UsageError
    from ertools.timeutil import s_to_ns

    auto = args.offset == "auto"
    if args.apply_offset and not auto:
        raise UsageError("--apply-offset needs --offset auto")
    chosen = {
        "association": args.association,
        "ties": args.ties,
        "gaps": args.gaps,
        "before_gt": args.before_gt,
    }
    settings = {k: v for k, v in chosen.items() if v is not None}
    if args.as_2015:
        clash = [
            f"--{k.replace('_', '-')} {v}" for k, v in settings.items() if SETTINGS_2015[k] != v
        ]
        if clash:
            raise UsageError(f"--2015 sets {_2015_options()}; it cannot take {', '.join(clash)}")
        settings = dict(SETTINGS_2015)
    if settings.get("ties") == "before" and settings.get("association") != "hold":
        raise UsageError("--ties before needs --association hold")
    config = TrajectoryConfig(
        **settings,
        max_gap_ns=s_to_ns(args.max_gap),
        offset_ns=0 if auto else s_to_ns(float(args.offset)),
        auto_offset=auto,
        apply_offset=bool(args.apply_offset),
        offset_range_ns=s_to_ns(args.offset_range),
        allow_partial=bool(args.allow_partial),
    )
    result = score(
        args.robot_bag,
        args.gt_paths,
        config,
        robot_topic=args.robot_topic,
        gt_topic=args.gt_topic,
        robot_time=args.robot_time,
    )
    # cast: the frozen dataclass's fields are read-only, the Protocol declares plain attributes.
    # In evo's bag mode the robot log is also the GT file: listed once.
    inputs = list(dict.fromkeys([args.robot_bag, *map(Path, result.gt_files)]))
    return emit_result(cast("BenchmarkResult", result), args, inputs)
