"""Acquire FBM1 item transforms from a mocap log (seed 7.1.4) and write Listing 9.

For each item of a vanilla list (ids, classes, instances; no or identity trans/rot) the item
stood on the reference board at the table origin for a while; its transform in the board
frame is ref_board^-1 * origin averaged over that window. Windows are given (--windows) or
found as the consecutive still phases of the board near the origin, one per item, in order.
The list is written in the Listing 9 format, each item with the spread of its measurement.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from ertools.benchmarks.common.sources import pose_source
from ertools.benchmarks.document import all_failed
from ertools.benchmarks.fbm1.acquire import AcquireOptions, acquire_items_bag
from ertools.benchmarks.fbm1.config import BENCHMARKS
from ertools.cli.options import (
    add_output,
    add_pose_source,
    add_time_source,
    deprecated,
    pose_spec,
    positive,
)
from ertools.cli.output import note, write_text
from ertools.configs.items import items_to_yaml
from ertools.errors import UsageError

if TYPE_CHECKING:
    from ertools.benchmarks.common.spec import PoseSpec
    from ertools.io.model import PoseSource

EPILOG = """examples:
  ertools acquire items items.bag --items fbm1h-vanilla.yaml -o fbm1h.yaml
  ertools acquire items items.bag --items fbm1w-vanilla.yaml --namespace fbm1w \\
      --windows 12.0:15.5,21:24,30.2:33

--windows: START:END per item in list order, seconds from the log's first message (values
above 1e9 are epoch seconds). Without it the board's still phases near the origin are used
(--still-min, --max-distance); their number must equal the number of items.
Exit status 1 when an item could not be acquired (it is written unchanged and named on stderr)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("bags", nargs="+", type=Path, metavar="BAG", help="log file(s)")
    parser.add_argument(
        "--items", type=Path, required=True, metavar="FILE", help="vanilla item list"
    )
    parser.add_argument(
        "--windows", metavar="S:E,...", help="one START:END window per item (see below)"
    )
    parser.add_argument(
        "--namespace",
        default=BENCHMARKS[0],
        choices=BENCHMARKS,
        help=f"topic namespace of origin and ref_board (default {BENCHMARKS[0]})",
    )
    add_pose_source(parser, "origin-", what="the table origin", default="the namespace's")
    add_pose_source(parser, "ref-board-", what="the reference board", default="the namespace's")
    add_time_source(parser)
    parser.add_argument(
        "--still-min", type=positive, default=2.0, metavar="S", help="shortest placement (2 s)"
    )
    deprecated(parser, "--min-still", "--still-min", "still_min", convert=positive, metavar="S")
    parser.add_argument(
        "--max-distance",
        type=positive,
        default=0.5,
        metavar="M",
        help="a placement has the board within M of the origin (0.5 m)",
    )
    parser.add_argument(
        "--still", type=positive, default=0.002, metavar="M", help="still: < M per 0.25 s (0.002)"
    )
    add_output(parser, ("yaml",), out_help="write the list to FILE instead of stdout")


def _windows(text: str | None) -> list[tuple[float, float]] | None:
    if text is None:
        return None
    out = []
    for part in text.split(","):
        a, sep, b = part.strip().partition(":")
        try:
            start, end = float(a), float(b)
        except ValueError:
            raise UsageError(f"--windows: {part!r} is not START:END in seconds") from None
        if not sep or not (math.isfinite(start) and math.isfinite(end)):
            raise UsageError(f"--windows: {part!r} is not START:END in seconds")
        out.append((start, end))
    return out


def _io(spec: PoseSpec, namespace: str, body: str) -> PoseSource | None:
    """The reader's source; None for the scorer's default (the 2015 topic, else the /tf
    frame), unless a time source was asked for: then the 2015 topic at that time."""

    if not spec.given and spec.time_source_given:
        spec = replace(spec, topic=f"/{namespace}/{body}/pose")
    return pose_source(spec) if spec.given else None


def run(args: argparse.Namespace) -> int:
    origin = pose_spec(args, "origin-", time_prefix="")
    board = pose_spec(args, "ref-board-", time_prefix="")
    options = AcquireOptions(
        min_still_s=args.still_min, still_m=args.still, max_distance_m=args.max_distance
    )
    result = acquire_items_bag(
        args.bags,
        args.items,
        namespace=args.namespace,
        windows_s=_windows(args.windows),
        options=options,
        sources=(_io(origin, args.namespace, "origin"), _io(board, args.namespace, "ref_board")),
    )
    if all_failed(result):  # no item measured: only the errors, not the vanilla list back
        for failure in result.failures:
            note(f"error: {failure}")
        return 1
    write_text(items_to_yaml(result.items), args.out)
    note(
        f"{'id':>3} {'instance':<16} {'window s':>17} {'n':>5} {'x m':>8} {'y m':>8} "
        f"{'yaw deg':>8} {'spread mm':>9} {'deg':>6}"
    )
    for item in result.items:
        s = item.spread
        if s is None or item.trans is None or item.rot is None:
            note(f"{item.id:>3} {item.instance[:16]:<16}  not acquired")
            continue
        x, y, z, w = item.rot
        yaw = math.degrees(math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)))
        note(
            f"{item.id:>3} {item.instance[:16]:<16} {s.start_s:8.2f}:{s.end_s:<8.2f} "
            f"{s.samples:>5} {item.trans[0]:8.4f} {item.trans[1]:8.4f} {yaw:8.2f} "
            f"{s.position_m * 1000:9.3f} {s.angle_deg:6.3f}"
        )
    for warning in result.warnings:
        note(f"warning: {warning}")
    for deviation in result.deviations:
        note(f"differs from 2015: {deviation}")
    for failure in result.failures:
        note(f"error: {failure}")
    return 1 if result.failures else 0
