"""Describe bags like `rosbag info`: format, times, size, compression, topics with rates.

Works on ROS1 bags (.bag, .bag.active), rosbag2 folders (sqlite3, mcap) and .mcap files.
Only each file's index is read (no message data), so it answers in milliseconds even for
hour-long bags; --check also decompresses every chunk to find corrupted data. A folder that
is not a rosbag2 bag is searched for bags.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ertools.cli.options import add_output
from ertools.cli.output import dump_json, note, write_text
from ertools.cli.text import error_text, printable
from ertools.errors import BagError
from ertools.io import info as bag_info
from ertools.io.formats import find_bags
from ertools.io.info import span_s
from ertools.progress import reporting
from ertools.serialize import dump_yaml
from ertools.timeutil import iso_utc, ns_to_s

if TYPE_CHECKING:
    from ertools.io.info import BagInfo

EPILOG = """examples:
  ertools info run.bag                       # table, like `rosbag info`
  ertools info gt_0.bag gt_1.bag --format json
  ertools info logs/ --format yaml           # every bag under logs/
  ertools info run.bag --check               # also decompress and check every chunk

Rates are the median of the intervals between record times, from the index records, stated
for topics with at least 10 messages over at least 1 s; others show "n messages in s s".
JSON/YAML layout: {"bags": [{"path", "format", "version", "start", "start_iso", "end",
"end_iso", "duration", "size_bytes", "compression", "messages", "indexed", "index",
"checked", "problems", "topics": [{"name", "type", "count", "connections", "first", "last",
"span_s", "median_rate_hz"}]}], "problems": [{"path", "problem"}]}; times in epoch seconds,
median_rate_hz null where no rate is stated.
Exit status 1 when any bag is unreadable, truncated or (with --check) corrupt.
"""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "paths", type=Path, nargs="+", metavar="BAG", help="bags, rosbag2 folders or folders"
    )
    add_output(parser, ("text", "json", "yaml"), aliases={"table": "text"})
    parser.add_argument(
        "--check",
        action="store_true",
        help="decompress every chunk and check every indexed message (reads the whole file)",
    )


def _size(n: int) -> str:
    value = float(n)
    for unit in ("B", "KiB", "MiB", "GiB"):
        if value < 1024 or unit == "GiB":
            return f"{value:.1f} {unit}" if unit != "B" else f"{n} B"
        value /= 1024
    return f"{n} B"


def _rate(hz: float | None, count: int, span: float | None) -> str:
    """The median rate, or where none is stated what the index knows: count and span."""
    if hz is not None:
        return f"{hz:.3g} Hz" if hz < 1000 else f"{hz:.0f} Hz"
    if count < 2 or span is None:
        return "-"  # the count column already says it all
    return f"{count} messages in {span:.3g} s"


def table(info: BagInfo) -> str:
    """`rosbag info`-like text of one bag."""

    s = info.summary
    lines = [
        f"path:        {printable(str(s.path))}",
        f"format:      {s.format} (version {s.version or 'unknown'})"
        + ("" if s.indexed else "  NOT INDEXED: scanned"),
    ]
    if s.message_count:
        lines += [
            f"start:       {iso_utc(s.start_ns)}  ({ns_to_s(s.start_ns):.6f})",
            f"end:         {iso_utc(s.end_ns)}  ({ns_to_s(s.end_ns):.6f})",
            f"duration:    {ns_to_s(s.duration_ns):.3f} s",
        ]
    else:
        lines.append("start/end:   - (no messages)")
    lines += [
        f"size:        {_size(s.size_bytes)} ({s.size_bytes} bytes)",
        f"compression: {s.compression}",
        f"index:       {s.index}",
        f"messages:    {s.message_count}",
    ]
    if info.checked and not info.check_problems:
        lines.append("check:       every chunk decompressed and every indexed record found")
    for problem in info.check_problems:
        lines.append(f"check:       {problem}")
    for problem in s.problems:
        lines.append(f"problem:     {problem}")
    rows = [
        (
            t.name,
            t.msgtype,
            str(t.count),
            _rate(info.median_rate_hz.get(t.name), t.count, span_s(t.first_ns, t.last_ns)),
            f"{t.connections} conn" if t.connections > 1 else "",
        )
        for t in s.topics
    ]
    if rows:
        widths = [max(len(r[i]) for r in rows) for i in range(5)]
        header = ("topic", "type", "count", "median rate", "")
        widths = [max(w, len(h)) for w, h in zip(widths, header, strict=True)]
        lines.append("topics:")
        lines.append(
            "  " + "  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True)).rstrip()
        )
        for r in rows:
            cells = [r[0].ljust(widths[0]), r[1].ljust(widths[1]), r[2].rjust(widths[2])]
            cells += [r[3].rjust(widths[3]), r[4]]
            lines.append("  " + "  ".join(cells).rstrip())
    else:
        lines.append("topics:      none")
    return "\n".join(lines)


def _one_line(text: str) -> str:
    """``text`` with its whitespace runs (newlines of wrapped third-party messages) as one
    space: every problem is one stderr line and one YAML/JSON string."""
    return " ".join(text.split())


def run(args: argparse.Namespace) -> int:
    infos: list[BagInfo] = []
    problems: list[dict[str, str]] = []
    paths: list[Path] = []
    for given in args.paths:
        # a missing path, an empty folder, a folder that cannot be read, a FIFO: one problem
        # each, and the other bags still run
        found = find_bags([given])
        paths.extend(found.bags)
        problems.extend({"path": p.path, "problem": p.problem} for p in found.problems)
    progress = getattr(args, "progress", None)  # set by run_command
    if progress is not None and not args.check:  # --check reports the bytes of each file
        progress.task("reading indexes", len(paths), "bags")
    for path in paths:
        if progress is not None and not args.check:
            progress.advance(1)
        try:
            with reporting(None):  # only --check's own counts: not the index reads inside
                info = bag_info.describe(path, check=args.check, progress=progress)
        except BagError as err:
            problems.append({"path": str(path), "problem": _one_line(err.message)})
            continue
        infos.append(info)
        fatal = info.fatal_problem
        # an MCAP cut short (its recorder killed): one command makes it whole
        fix = (
            f"; if its recorder was killed, `ertools record --recover {path}` makes it whole"
            if path.suffix == ".mcap" and not info.summary.indexed
            else ""
        )
        if fatal is not None:
            problems.append({"path": str(path), "problem": _one_line(fatal) + fix})
        elif not info.summary.indexed and info.summary.problems:
            # a complete file read record by record (an MCAP without summary) is no warning
            note(f"warning: {path}: not indexed (still recording?){fix}; counts come from a scan")
        # each disagreement --check found is a line of its own
        problems.extend({"path": str(path), "problem": _one_line(p)} for p in info.check_problems)
    if args.format == "text":
        text = "\n\n".join(table(i) for i in infos)
    else:
        data: dict[str, Any] = {"bags": [i.to_dict() for i in infos], "problems": problems}
        # YAML: rates without binary noise, as every ertools YAML
        text = dump_json(data) if args.format == "json" else dump_yaml(data)
    if text:
        write_text(text, args.out)
    for p in problems:
        print(error_text(f"{p['path']}: {p['problem']}"), file=sys.stderr)
    return 1 if problems else 0
