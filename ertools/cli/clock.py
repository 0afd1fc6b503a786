"""Query an NTP server once (SNTP) and report the local clock's offset from it.

The 2015 system synchronised every machine to the Referee Box with chrony (seed 3.4). Run this
before a benchmark on each logging machine: it exits 0 when the offset is within --tolerance,
1 when it is outside or the server cannot be reached.
"""

from __future__ import annotations

import argparse

from ertools.cli.options import add_output, port, positive, seconds
from ertools.cli.output import dump_json, write_text
from ertools.live.clock import query_sntp
from ertools.serialize import dump_yaml

EPILOG = """examples:
  ertools clock --server 192.168.1.1
  ertools clock --server 192.168.1.1 --tolerance 0.002
  ertools clock --server ntp.local --port 10123 --timeout 1
  ertools clock --server 192.168.1.1 --format json     # offset, delay in seconds
"""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--server", required=True, help="NTP server host (the 2015 one: 192.168.1.1)"
    )
    parser.add_argument("--port", type=port, default=123, help="UDP port (default 123)")
    parser.add_argument(
        "--tolerance",
        type=seconds,
        default=0.005,
        metavar="S",
        help="largest acceptable |offset| in seconds (default 0.005)",
    )
    parser.add_argument(
        "--timeout", type=positive, default=2.0, metavar="S", help="reply timeout (default 2 s)"
    )
    add_output(parser, ("text", "json", "yaml"))


def run(args: argparse.Namespace) -> int:
    check = query_sntp(args.server, args.port, timeout_s=args.timeout)
    ok = check.within(args.tolerance)
    if args.format == "text":
        if ok:
            text = f"ok: {check.describe()}; within {args.tolerance:g} s"
        else:
            text = f"outside tolerance: {check.describe()}; |offset| > {args.tolerance:g} s"
    else:
        data = {
            "server": check.server,
            "port": check.port,
            "offset": check.offset_s,
            "delay": check.delay_s,
            "stratum": check.stratum,
            "measured_at": check.measured_at_ns / 1e9,
            "tolerance": args.tolerance,
            "within_tolerance": ok,
        }
        text = dump_json(data) if args.format == "json" else dump_yaml(data)
    write_text(text, args.out)
    return 0 if ok else 1
