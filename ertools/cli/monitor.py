"""Watch the log folder while recording and warn when the log stops growing (seed 5.2).

Every --interval seconds: the newest file being written, its growth and, for MCAP files, the
rate of every pose topic. Warnings (stderr, with a terminal bell under --bell as the 2015
log_monitor): no file being written, several at once, growth below --min-growth, a pose topic
whose rate fell below --drop-fraction of its best or below --min-rate.

Runs until Ctrl-C; --once looks twice one interval apart and exits, --duration S stops after S
seconds. With --once or --duration the exit status is 1 when any warning was given.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ertools.cli.options import fraction, non_negative, positive
from ertools.errors import UsageError
from ertools.live.monitor import MonitorOptions, watch

EPILOG = """examples:
  ertools monitor logs/ --bell
  ertools monitor logs/ --interval 5 --min-growth 20000 --min-rate 100
  ertools monitor logs/ --prefix log_fbm2h_mocap    # only the @Home logger's files
  ertools monitor logs/ --once          # scripted check: exit 1 on any warning
"""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "directory", type=Path, metavar="DIR", help="the recorder's --out-dir folder"
    )
    parser.add_argument(
        "--interval", type=positive, default=2.0, metavar="S", help="seconds between looks (2)"
    )
    parser.add_argument(
        "--min-growth",
        type=non_negative,
        default=2_000.0,
        metavar="BYTES_PER_S",
        help="least acceptable growth of the file being written (2000 B/s; one body at 120 Hz "
        "writes about 12000 B/s)",
    )
    parser.add_argument(
        "--stale",
        type=positive,
        metavar="S",
        help="a file not modified for S s is not being written (default 3 intervals, >= 5 s)",
    )
    parser.add_argument(
        "--drop-fraction",
        type=fraction,
        default=0.5,
        help="warn when a pose topic's rate falls below this fraction of its best (0.5)",
    )
    parser.add_argument("--min-rate", type=positive, metavar="HZ", help="least pose rate per topic")
    parser.add_argument(
        "--prefix",
        default="",
        help="only files whose name starts with this, e.g. log_fbm2h_mocap (the 2015 script's "
        "log_prefix: two loggers writing into one folder)",
    )
    parser.add_argument("--bell", action="store_true", help="ring the terminal bell on warnings")
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--once", action="store_true", help="look once (after one interval), exit")
    group.add_argument("--duration", type=positive, metavar="S", help="stop after S seconds")


def run(args: argparse.Namespace) -> int:
    if not args.directory.is_dir():
        raise UsageError(f"{args.directory} is not a folder")
    options = MonitorOptions(
        directory=args.directory,
        interval_s=args.interval,
        min_growth_bps=args.min_growth,
        stale_s=args.stale,
        drop_fraction=args.drop_fraction,
        min_rate_hz=args.min_rate,
        prefix=args.prefix,
    )

    def status(line: str) -> None:
        print(f"{time.strftime('%H:%M:%S')} {line}", flush=True)

    def warn(line: str) -> None:
        bell = "\a" if args.bell else ""
        print(f"{bell}ertools: monitor: WARNING: {line}", file=sys.stderr, flush=True)

    warnings = watch(options, duration_s=args.duration, once=args.once, status=status, warn=warn)
    return 1 if warnings and (args.once or args.duration is not None) else 0
