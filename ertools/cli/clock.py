"""Query an NTP server once (SNTP) and report the local clock's offset from it.

The 2015 system synchronised every machine to the Referee Box with chrony (seed 3.4). Run this
before a benchmark on each logging machine: it exits 0 when the offset is within --tolerance,
1 when it is outside or the server cannot be reached.
"""

from __future__ import annotations

import argparse

EPILOG = """examples:
  ertools clock --server 192.168.1.1
  ertools clock --server 192.168.1.1 --tolerance 0.002
  ertools clock --server ntp.local --port 10123 --timeout 1
"""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--server", required=True, help="NTP server host (the 2015 one: 192.168.1.1)"
    )
    parser.add_argument("--port", type=int, default=123, help="UDP port (default 123)")
    parser.add_argument(
        "--tolerance",
        type=float,
        default=0.005,
        metavar="S",
        help="largest acceptable |offset| in seconds (default 0.005)",
    )
    parser.add_argument(
        "--timeout", type=float, default=2.0, metavar="S", help="reply timeout (default 2 s)"
    )


def run(args: argparse.Namespace) -> int:
    from ertools.errors import UsageError
    from ertools.live.clock import query_sntp

    if args.tolerance < 0 or args.timeout <= 0:
        raise UsageError("--tolerance must be >= 0 and --timeout > 0")
    check = query_sntp(args.server, args.port, timeout_s=args.timeout)
    if check.within(args.tolerance):
        print(f"ok: {check.describe()}; within {args.tolerance:g} s")
        return 0
    print(f"outside tolerance: {check.describe()}; |offset| > {args.tolerance:g} s")
    return 1
