"""Order bags from many machines by time: overlaps, sessions, GT pairing, problems.

The 2015 rockin_bags_timeliner, done right: folders are walked for .bag, .bag.active, .mcap and
rosbag2 bags; only each file's index is read (plus one second of one pose topic per recording for
the clock check). Unreadable files are listed with the reason; the exit status is 1 only when no
file at all could be read.
"""

from __future__ import annotations

import argparse
import csv
import io
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

from ertools.cli.options import add_output, plot_file, seconds
from ertools.cli.output import dump_json, note, write_text
from ertools.cli.text import error_text, printable
from ertools.csvsafe import spreadsheet_safe
from ertools.report.plots_timeline import save_timeline_plot
from ertools.serialize import dump_yaml
from ertools.timelines.model import KIND_LABELS, TimelineConfig
from ertools.timelines.scan import scan
from ertools.timeutil import iso_utc, s_to_ns

if TYPE_CHECKING:
    from ertools.timelines.model import Timeline

EPILOG = """examples:
  ertools timeline bags/                         # table of every bag under bags/
  ertools timeline gt/ robots/ --format json > timeline.json
  ertools timeline bags/ --plot day.html         # interactive page: zoom, sessions, problems
  ertools timeline bags/ --plot day.png          # one panel per session, problems numbered
  ertools timeline bags/ --clock-tolerance 0.2 --format csv -o timeline.csv
  ertools timeline bags/ --format yaml -o timeline.yaml

JSON layout: {"bags": [{"path", "format", "start", "end", "duration", "kind", "benchmarks",
"overlaps", "problems", "copy_of", "copies"}], "sessions": [{"index", "start", "end",
"duration", "bags", "pairings"}], "problems": [{"path", "problem"}]}, times in epoch seconds.
"""


# Suffixes ``--plot`` writes: an interactive page, or one panel per session.
TIMELINE_PLOT_SUFFIXES = (".png", ".svg", ".html", ".htm")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("paths", type=Path, nargs="+", metavar="PATH", help="bags or folders")
    add_output(parser, ("text", "json", "yaml", "csv"), aliases={"table": "text"})
    parser.add_argument(
        "--plot",
        type=plot_file(TIMELINE_PLOT_SUFFIXES),
        action="append",
        metavar="FILE",
        help="write a picture, by suffix: .html an interactive page (zoom, sessions, problems "
        "on hover), .png/.svg one panel per session; repeat for several",
    )
    parser.add_argument(
        "--clock-tolerance",
        type=seconds,
        default=0.5,
        metavar="S",
        help="flag bags whose header stamps and record times differ by more (default 0.5 s)",
    )
    parser.add_argument(
        "--gap-tolerance",
        type=seconds,
        default=1.0,
        metavar="S",
        help="flag pauses longer than this between split files of a logger (default 1 s)",
    )
    parser.add_argument(
        "--no-clock-check",
        action="store_true",
        help="skip the clock check (reads only the files' indexes)",
    )


def run(args: argparse.Namespace) -> int:

    # a bad --plot suffix was refused by argparse (exit 2), not after minutes of reading
    plots: list[Path] = args.plot or []
    config = TimelineConfig(
        clock_tolerance_ns=s_to_ns(args.clock_tolerance),
        gap_tolerance_ns=s_to_ns(args.gap_tolerance),
    )
    timeline = scan(
        args.paths,
        config,
        check_clocks=not args.no_clock_check,
        progress=getattr(args, "progress", None),
    )
    if args.format == "json":
        write_text(dump_json(timeline.to_dict()), args.out)
    elif args.format == "yaml":
        write_text(dump_yaml(timeline.to_dict()), args.out)  # the JSON's keys, as YAML
    elif args.format == "csv":
        write_text(to_csv(timeline), args.out)
    else:
        color = args.out is None and sys.stdout.isatty()
        write_text(to_table(timeline, color=color), args.out)
    if plots and timeline.readable_count > 0:  # no empty chart on failure
        for plot in plots:
            note(f"wrote {save_timeline_plot(timeline, plot)}")
    if timeline.readable_count == 0:
        where = ", ".join(map(str, args.paths))
        # Say why on the one error line: the reasons are otherwise only in the table on stdout.
        reasons = [" ".join(f"{p.path}: {p.problem}".split()) for p in timeline.problems]
        why = "; ".join(reasons[:3]) + (f"; {len(reasons) - 3} more" if len(reasons) > 3 else "")
        print(
            error_text(f"no readable bag in {where}" + (f"; {why}" if why else "")),
            file=sys.stderr,
        )
        return 1
    # Unreadable, truncated or mistyped files do not stop the others being read (exit 0), but
    # each is said on stderr too, where a referee redirecting stdout to a file still sees it.
    by_path: dict[str, list[str]] = {}
    for pr in timeline.problems:
        by_path.setdefault(pr.path, []).append(pr.problem)
    for shown, (path, problems) in enumerate(by_path.items()):
        if shown == MAX_PROBLEM_NOTES:
            note(f"warning: {len(by_path) - shown} more file(s) with problems: see the output")
            break
        note(" ".join(f"warning: {printable(path)}: {'; '.join(problems)}".split()))  # one line
    return 0


MAX_PROBLEM_NOTES = 10


def to_csv(timeline: Timeline) -> str:
    """One row per bag (the 2015 timeliner's columns and more)."""

    rows = timeline.rows()
    out = io.StringIO()
    fields = list(rows[0]) if rows else ["start", "end", "duration", "kind", "path"]
    writer = csv.DictWriter(out, fieldnames=fields, lineterminator="\n")
    writer.writeheader()
    for r in rows:
        writer.writerow({k: "" if v is None else spreadsheet_safe(v) for k, v in r.items()})
    return out.getvalue()


class _Paint:
    """ANSI colours, or nothing when the output is not a terminal."""

    CODES: ClassVar[dict[str, str]] = {
        "warn": "33",
        "error": "31",
        "hi": "36",
        "ok": "32",
        "dim": "2",
        "bold": "1",
    }

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled

    def __call__(self, text: str, style: str) -> str:
        if not self.enabled:
            return text
        return f"\033[{self.CODES[style]}m{text}\033[0m"


def _when(ns: int | None) -> str:
    if ns is None:
        return "-"

    return iso_utc(ns)[:23].replace("T", " ")


def to_table(timeline: Timeline, *, color: bool = False) -> str:
    """The human table: bags by start, then sessions with their GT pairing, then problems."""

    paint = _Paint(color)
    lines: list[str] = []
    header = f"{'start (UTC)':<23}  {'end (UTC)':<23}  {'duration':>9}  {'kind':<13}  ses  path"
    lines.append(paint(header, "bold"))
    for b in timeline.bags:
        dur = "-" if b.duration_ns is None else f"{b.duration_ns / 1e9:8.1f}s"
        ses = "-" if b.session is None else str(b.session)
        row = (
            f"{_when(b.start_ns):<23}  {_when(b.end_ns):<23}  {dur:>9}  "
            f"{KIND_LABELS[b.kind]:<13}  {ses:>3}  {printable(str(b.path))}"
        )
        style = "error" if not b.readable else ("hi" if b.overlaps else "")
        lines.append(paint(row, style) if style else row)
        if b.overlaps:
            lines.append(paint(f"{'':>77}overlaps: {printable(', '.join(b.overlaps))}", "dim"))
        if b.copies:
            lines.append(paint(f"{'':>77}{len(b.copies)} copy(ies) of this recording", "dim"))
        for p in b.problems:
            lines.append(paint(f"{'':>77}! {printable(p)}", "warn" if b.readable else "error"))
    if timeline.sessions:
        lines += ["", paint("sessions:", "bold")]
    for s in timeline.sessions:
        lines.append(
            f"  {s.index:>3}  {_when(s.start_ns)} to {_when(s.end_ns)} "
            f"({s.duration_ns / 1e9:.1f} s), {len(s.paths)} bag(s)"
        )
        names = [Path(pairing.path).name for pairing in s.pairings]
        for pairing in s.pairings:
            # the same name twice (a copy on a USB stick): show the paths to tell them apart
            full = names.count(Path(pairing.path).name) > 1
            lines.append(_pairing_line(pairing, paint, full_path=full))
    lines += _rsbb_lines(timeline, paint)
    if timeline.problems:
        lines += ["", paint(f"problems ({len(timeline.problems)}):", "bold")]
        for pr in timeline.problems:
            lines.append(paint(printable(f"  {pr.path}: {pr.problem}"), "warn"))
    return "\n".join(lines)


def _rsbb_lines(timeline: Timeline, paint: _Paint) -> list[str]:
    """The RSBB season layout: each run with its bag, result file and side files."""
    if timeline.rsbb is None:
        return []
    out = ["", paint(f"RSBB runs ({len(timeline.rsbb.runs)}, docs/rsbb.md):", "bold")]
    for r in timeline.rsbb.runs:
        out.append(f"  {r.code:<7} {printable(r.team):<16} run {r.run:<3} bag {_name(r.bag)}")
        out.append(f"{'':>32}result {_name(r.result)}")
        side = [
            (k, v)
            for k, v in (("config", r.config), ("transform", r.transform), ("items", r.items))
            if v is not None
        ]
        if side:
            out.append(f"{'':>32}" + ", ".join(f"{k} {_name(v)}" for k, v in side))
    for problem in timeline.rsbb.problems:
        out.append(paint(f"  ! {printable(problem)}", "warn"))
    return out


def _name(path: str | None) -> str:
    return "(none)" if path is None else printable(Path(path).name)


def _pairing_line(p: Any, paint: _Paint, *, full_path: bool = False) -> str:
    name = printable(str(p.path) if full_path else Path(p.path).name)
    other = ""
    if p.other_benchmark:
        names = printable(", ".join(Path(g).name for g in p.other_benchmark))
        other = f"; not paired, another benchmark: {names}"
    if not p.gt:
        return paint(f"       {KIND_LABELS[p.kind]} {name}: no GT file covers it{other}", "error")
    gts = printable(", ".join(Path(g).name for g in p.gt))
    by_time = " by time only (no benchmark named)" if p.basis == "time" else ""
    text = (
        f"       {KIND_LABELS[p.kind]} {name}: GT coverage {p.coverage:.1f} % ({gts}){by_time}"
        f"{other}"
    )
    if p.uncovered:
        spans = "; ".join(
            f"{_when(a)[11:]}-{_when(b)[11:]} ({(b - a) / 1e9:.1f} s)" for a, b in p.uncovered
        )
        return paint(f"{text}; uncovered {spans}", "warn")
    return paint(text, "ok")
