"""Recompute an FBM2@Home (navigation) score from the logs (seed 7.2, Listing 13).

Per waypoint: the robot pose when it was reached (ground-truth marker pose interpolated at that
moment, composed with the team's marker-to-robot transform), its distance and orientation
error, the segment time; then position_accuracy, orientation_accuracy and execution_time.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, cast

from ertools.cli.common import add_output_options, all_failed, emit_result, note

if TYPE_CHECKING:
    from ertools.benchmarks.base import BenchmarkResult

EPILOG = """examples:
  ertools score fbm2h run.bag --team homer --transforms transforms/
  ertools score fbm2h run.bag --goal configs/fbm2h.yaml --transform transform-homer.yaml
  ertools score fbm2h log.bag --goal goal.yaml --transform configs/transform-identity.yaml \\
      --reached timing log_reached_waypoint_timing.yaml
  ertools score fbm2h log.bag --goal goal.yaml --reached auto --format json

--reached: states (default when the bag has /fbm2h/bmbox_state): segment i starts when the
BmBox has sent the goal and ends at the Client's COMPLETED_GOAL; timing FILE: a reached-waypoint
timing file (p0 starts, p(k+1) closes segment k, seconds from the bag's first message); auto:
stops detected in the ground truth, assigned to the waypoints in order.
Orientation errors are wrapped to [0, pi]; --orientation-2015 reproduces the 2015 numbers.
Accuracies are null (exit 1) when a segment is not scored; --unscored-segments 2015 divides
the sum over the scored segments by N as 2015 did. --2015: every 2015 behaviour at once."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    # nargs="*": `--reached timing FILE log.bag` (option first) leaves the bag inside --reached's
    # values; run() takes it back from there (see _reached), else one BAG is required.
    parser.add_argument("bags", nargs="*", type=Path, metavar="BAG", help="log file(s)")
    parser.add_argument(
        "--goal", type=Path, metavar="FILE", help="goal list (Listing 10); default: from the log"
    )
    parser.add_argument(
        "--transform", type=Path, metavar="FILE", help="marker-to-robot transform (Listing 11)"
    )
    parser.add_argument(
        "--transforms", type=Path, metavar="DIR", help="folder of transform-<team>.yaml files"
    )
    parser.add_argument(
        "--topic",
        metavar="TOPIC",
        help="marker set pose topic, any pose type (default /fbm2h/robot_at_home/pose)",
    )
    parser.add_argument(
        "--tf-frame",
        "--frame",
        dest="tf_frame",
        metavar="FRAME",
        help="take the marker set from /tf world -> FRAME instead",
    )
    parser.add_argument(
        "--time-source",
        choices=("header", "record"),
        default="header",
        help="pose time: header stamp (mocap time, default) or bag record time",
    )
    parser.add_argument(
        "--reached",
        nargs="+",
        metavar="MODE",
        help="states | timing FILE | auto (default: states when the log has them)",
    )
    parser.add_argument(
        "--max-gap",
        type=float,
        default=0.1,
        metavar="S",
        help="a reached moment needs a GT sample within S seconds (default 0.1)",
    )
    parser.add_argument("--hits", type=int, metavar="N", help="the referee's count of hits")
    legacy = parser.add_argument_group("2015 behaviour (each difference can be undone)")
    legacy.add_argument(
        "--orientation-2015",
        action="store_true",
        help="orientation errors as 2015 computed them (unwrapped |dtheta|; wrong across +-pi)",
    )
    legacy.add_argument(
        "--unscored-segments",
        choices=("null", "2015"),
        default="null",
        help="segments not scored (RefBox timeout, never reached): null accuracies and exit 1 "
        "(default), or 2015: sums over the scored segments divided by N, the timed-out "
        "segment's time counted",
    )
    legacy.add_argument(
        "--2015",
        dest="all_2015",
        action="store_true",
        help="every 2015 behaviour above (--orientation-2015 --unscored-segments 2015)",
    )
    parser.add_argument(
        "--namespace", default="fbm2h", help="benchmark namespace of the state topics"
    )
    auto = parser.add_argument_group("--reached auto (stop detection)")
    auto.add_argument(
        "--stop-speed", type=float, default=0.05, metavar="M_S", help="(default 0.05 m/s)"
    )
    auto.add_argument(
        "--stop-yaw-rate", type=float, default=0.1, metavar="RAD_S", help="(default 0.1 rad/s)"
    )
    auto.add_argument(
        "--stop-min-duration", type=float, default=0.5, metavar="S", help="(default 0.5 s)"
    )
    auto.add_argument(
        "--stop-radius",
        type=float,
        default=0.5,
        metavar="M",
        help="a stop counts for a waypoint only this close to it (default 0.5 m)",
    )
    add_output_options(parser)


NO_BAG = "give at least one BAG (the log file); `ertools score fbm2h --help` shows how"


def _reached(
    values: list[str] | None, bags: list[Path]
) -> tuple[str | None, Path | None, list[Path]]:
    """Mode, timing file and bags. With no BAG before the options, the values --reached
    swallowed after its own (``--reached timing FILE log.bag``) are the bags."""
    from ertools.errors import UsageError

    if not values:
        if not bags:
            raise UsageError(NO_BAG)
        return None, None, bags
    mode, rest = values[0], values[1:]
    need = 1 if mode == "timing" else 0
    if not bags and len(rest) > need:
        bags = [Path(v) for v in rest[need:]]
        rest = rest[:need]
    if not bags:
        raise UsageError(NO_BAG)
    if mode == "timing":
        if len(rest) != 1:
            raise UsageError("--reached timing needs exactly one FILE")
        return mode, Path(rest[0]), bags
    if mode in ("states", "auto") and not rest:
        return mode, None, bags
    raise UsageError(f"--reached: expected states, timing FILE or auto, got {' '.join(values)}")


def run(args: argparse.Namespace) -> int:
    from ertools.benchmarks.fbm2h.benchmark import Fbm2hOptions, score_fbm2h
    from ertools.benchmarks.fbm2h.segments import StopParams

    mode, timing, bags = _reached(args.reached, list(args.bags))
    args.bags = bags
    options = Fbm2hOptions(
        goal=args.goal,
        transform=args.transform,
        team=args.team,
        transforms_dir=args.transforms,
        topic=args.topic,
        tf_frame=args.tf_frame,
        time_source=args.time_source,
        reached=mode,
        timing=timing,
        max_gap_s=args.max_gap,
        hits=args.hits,
        orientation_2015=args.orientation_2015 or args.all_2015,
        unscored_2015=args.unscored_segments == "2015" or args.all_2015,
        namespace=args.namespace,
        stops=StopParams(
            speed=args.stop_speed,
            yaw_rate=args.stop_yaw_rate,
            min_duration_s=args.stop_min_duration,
            radius=args.stop_radius,
        ),
    )
    result = score_fbm2h(args.bags, options)
    if args.verbose:
        for line in result.notes:
            note(line)
    if not all_failed(result):  # nothing scored: only the errors (emit_result)
        _print_table(result)
    # A frozen dataclass has read-only fields; the Protocol declares plain attributes.
    return emit_result(cast("BenchmarkResult", result), args, list(args.bags))


def _print_table(result: object) -> None:
    from ertools.benchmarks.fbm2h.result import Fbm2hResult

    assert isinstance(result, Fbm2hResult)
    note(
        f"reached moments: {result.reached_method}; transform: {result.transform.source}; "
        "times from the log's first message"
    )
    n = len(result.segments)
    scored = sum(s.status == "ok" for s in result.segments)
    if result.position_accuracy is None:
        averaged = "none (a segment is not scored: see the warnings)"
    elif result.unscored_2015:
        averaged = f"sum over the {scored} scored segment(s) / N = {n} (2015)"
    else:
        averaged = f"mean over all {n} segments"
    note(f"accuracies: {averaged}")
    for row in result.tables()["segments"]:
        values = ("reached_s", "segment_time_s", "distance_error_m", "orientation_error_rad")
        if row["status"] != "ok" or any(row[k] is None for k in values):
            note(f"  segment {row['segment']}: {row['status']}")
            continue
        note(
            f"  segment {row['segment']}: reached {row['reached_s']:.3f} s, "
            f"time {row['segment_time_s']:.3f} s, distance {row['distance_error_m']:.4f} m, "
            f"orientation {row['orientation_error_rad']:.4f} rad"
        )
