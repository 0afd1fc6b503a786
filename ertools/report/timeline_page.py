"""The timeline as one self-contained, interactive HTML page.

One lane per logger (the file name without split index and recording date), one bar per bag
coloured by kind, sessions as labelled bands, problem bags hatched and marked with their
problems in the tooltip, copies drawn hollow, and each benchmark or robot log linked to the GT
files that cover it (hover or click a bar). Wheel zooms around the pointer, dragging pans, the
session links zoom to a session (``page.html#session=3`` opens zoomed to session 3).

The page loads nothing: the CSS, the script and the data are inline, a Content-Security-Policy
forbids every fetch, and the script builds the chart's SVG once from the embedded data and
afterwards only moves the existing elements. Everything that comes from a file (bag names,
problem texts) is HTML-escaped in the tables and reaches the chart only as JSON data written
into the DOM with ``textContent``.

Pure: :func:`timeline_page` returns the text; :func:`write_timeline_page` is the IO edge.
"""

from __future__ import annotations

import html
import json
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ertools.atomic import write_text
from ertools.report.timeline_assets import CSS, SCRIPT
from ertools.report.timeline_style import (
    KIND_COLORS,
    KIND_LABELS,
    MARKER_FILL,
    PROBLEM_EDGE,
    SESSION_FILL,
    UNCOVERED_COLOR,
    lane_name,
)
from ertools.timelines.model import BagEntry, Session, Timeline
from ertools.timeutil import NS_PER_S, iso_utc

# Bags of one logger that overlap (a copy, a restarted logger) are stacked in rows of the
# lane; beyond this many rows they share the last one (a folder of 1,000 copies must not make
# a lane 1,000 rows tall: the tooltips and the tables still list every one).
MAX_ROWS = 4
LANE_LABEL_CHARS = 34


def _esc(value: object) -> str:
    return html.escape(str(value), quote=True)


def hms(ns: int) -> str:
    """``15:00:34`` (UTC) of a nanosecond timestamp."""
    return iso_utc(ns)[11:19]


def _when(ns: int | None) -> str:
    return "-" if ns is None else iso_utc(ns)[:23].replace("T", " ")


def session_label(session: Session) -> str:
    """``session 3, 15:00:00-15:00:34, 7 bags``: the label of a session's band and link."""
    n = len(session.paths)
    return (
        f"session {session.index}, {hms(session.start_ns)}-{hms(session.end_ns)}, "
        f"{n} bag{'s' if n != 1 else ''}"
    )


def display_names(paths: Sequence[str]) -> dict[str, str]:
    """Paths relative to the folder they all share (full paths when they share none)."""
    if not paths:
        return {}
    parents = [os.path.dirname(p) for p in paths]
    try:
        root = os.path.commonpath(parents) if len(paths) > 1 else parents[0]
    except ValueError:  # absolute and relative paths mixed
        return {p: p for p in paths}
    if not root:
        return {p: p for p in paths}
    return {p: os.path.relpath(p, root) for p in paths}


def lanes_and_rows(bags: Sequence[BagEntry]) -> tuple[list[str], list[int], dict[str, int]]:
    """Lanes (loggers, by their first bag's start), rows per lane, and each bag's row.

    A bag goes into the first row of its lane whose last bag has ended by its start, so the
    touching split files of one logger share a row and a copy (same span) gets the next one.
    """
    lanes: dict[str, int] = {}
    row_ends: list[list[int]] = []
    row_of: dict[str, int] = {}
    for b in bags:
        if b.start_ns is None or b.end_ns is None:
            continue
        lane = lanes.setdefault(lane_name(b), len(lanes))
        if lane == len(row_ends):
            row_ends.append([])
        ends = row_ends[lane]
        row = next((i for i, end in enumerate(ends) if end <= b.start_ns), None)
        if row is None:
            if len(ends) < MAX_ROWS:
                row = len(ends)
                ends.append(b.end_ns)
            else:
                row = MAX_ROWS - 1
        ends[row] = max(ends[row], b.end_ns)
        row_of[b.path] = row
    return list(lanes), [len(e) for e in row_ends], row_of


def _tooltip(
    b: BagEntry,
    name: str,
    names: dict[str, str],
    pairing: Any,
    covers: Sequence[str],
) -> str:
    assert b.start_ns is not None and b.end_ns is not None
    lines = [
        name,
        f"{KIND_LABELS[b.kind]}, {_when(b.start_ns)} to {_when(b.end_ns)[11:]} UTC "
        f"({(b.end_ns - b.start_ns) / NS_PER_S:.3f} s)"
        + (f", session {b.session}" if b.session is not None else ""),
    ]
    if b.benchmarks:
        lines.append("benchmark: " + ", ".join(b.benchmarks))
    if b.copy_of is not None:
        lines.append(f"copy of {names.get(b.copy_of, b.copy_of)}")
    if b.copies:
        lines.append(f"{len(b.copies)} cop{'y' if len(b.copies) == 1 else 'ies'} of this recording")
    if pairing is not None:
        if pairing.gt:
            gts = ", ".join(names.get(g, g) for g in pairing.gt)
            basis = " (by time only: no benchmark named)" if pairing.basis == "time" else ""
            lines.append(f"GT coverage {pairing.coverage:.1f} % by {gts}{basis}")
        else:
            lines.append("no GT file covers it")
        for a, e in pairing.uncovered:
            lines.append(f"uncovered {_when(a)[11:]}-{_when(e)[11:]} ({(e - a) / NS_PER_S:.3f} s)")
        if pairing.other_benchmark:
            others = ", ".join(names.get(g, g) for g in pairing.other_benchmark)
            lines.append(f"not paired, another benchmark: {others}")
    if covers:
        lines.append("GT for " + ", ".join(names.get(c, c) for c in covers))
    for p in b.problems:
        lines.append(f"! {p}")
    return "\n".join(lines)


def page_data(timeline: Timeline) -> dict[str, Any]:
    """The JSON the page's script draws: times in seconds from ``t0`` (whole epoch seconds).

    Seconds relative to a whole second keep microseconds exact in a float, and the script's
    tick labels (from ``t0 + t``) fall on whole clock seconds, minutes and hours.
    """
    drawn = [b for b in timeline.bags if b.start_ns is not None and b.end_ns is not None]
    names = display_names([b.path for b in timeline.bags])
    lanes, rows, row_of = lanes_and_rows(drawn)
    lane_of = {n: i for i, n in enumerate(lanes)}
    index = {b.path: i for i, b in enumerate(drawn)}
    t0_ns = min((b.start_ns for b in drawn if b.start_ns is not None), default=0)
    t0 = t0_ns // NS_PER_S

    def rel(ns: int) -> float:
        return (ns - t0 * NS_PER_S) / NS_PER_S

    pairing_of = {p.path: p for p in timeline.pairings}
    linked: dict[str, set[str]] = {b.path: set() for b in drawn}
    covers: dict[str, list[str]] = {b.path: [] for b in drawn}
    for p in timeline.pairings:
        for g in p.gt:
            linked[p.path].add(g)
            linked.setdefault(g, set()).add(p.path)
            covers.setdefault(g, []).append(p.path)
    bags = []
    for b in drawn:
        assert b.start_ns is not None and b.end_ns is not None
        pairing = pairing_of.get(b.path)
        bags.append(
            {
                "name": names[b.path],
                "kind": b.kind,
                "lane": lane_of[lane_name(b)],
                "row": row_of[b.path],
                "s": rel(b.start_ns),
                "e": rel(b.end_ns),
                "session": b.session,
                "problems": list(b.problems),
                "copy": b.copy_of is not None,
                "linked": sorted(index[p] for p in linked.get(b.path, ()) if p in index),
                "uncovered": [[rel(a), rel(e)] for a, e in pairing.uncovered] if pairing else [],
                "tip": _tooltip(b, names[b.path], names, pairing, covers.get(b.path, ())),
            }
        )
    return {
        "t0": t0,
        "lanes": lanes,
        "rows": rows,
        "colors": {k: KIND_COLORS[k] for k in KIND_COLORS},
        "uncoveredColor": UNCOVERED_COLOR,
        "bags": bags,
        "sessions": [
            {
                "index": s.index,
                "s": rel(s.start_ns),
                "e": rel(s.end_ns),
                "label": session_label(s),
                "n": len(s.paths),
            }
            for s in timeline.sessions
        ],
    }


def _json_for_script(data: object) -> str:
    """JSON safe inside ``<script type="application/json">``: no ``<``, ``>`` or ``&`` left,
    so no bag name can close the element or open a comment."""
    text = json.dumps(data, ensure_ascii=True, allow_nan=False, separators=(",", ":"))
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def _legend(timeline: Timeline) -> str:
    kinds = [k for k in KIND_COLORS if any(b.kind == k for b in timeline.bags if b.readable)]
    items = [
        f'<li><span class="sw" data-kind="{k}" style="background:{KIND_COLORS[k]}"></span>'
        f"{_esc(KIND_LABELS[k])}</li>"
        for k in kinds
    ]
    readable = [b for b in timeline.bags if b.readable]
    # only what the chart shows: a legend entry with no bar to match is noise
    if any(b.problems for b in readable):
        items.append(
            '<li><span class="sw sw-problem"></span>has problems (hatched, outlined, '
            '<span class="mk">!</span>; hover for the reason)</li>'
        )
    if any(b.copy_of for b in readable):
        items.append('<li><span class="sw sw-copy"></span>copy of another file (hollow)</li>')
    if any(p.uncovered for p in timeline.pairings):
        items.append('<li><span class="sw sw-uncov"></span>span of a log no GT file covers</li>')
    items.append('<li><span class="sw sw-session"></span>session</li>')
    return '<ul class="legend">' + "".join(items) + "</ul>"


def _table(head: Sequence[str], rows: Sequence[Sequence[str]], attrs: Sequence[str] = ()) -> str:
    """A table of already-escaped cells; ``attrs`` are extra row attributes (escaped)."""
    out = ['<div class="wrap"><table><thead><tr>']
    out += [f"<th>{_esc(h)}</th>" for h in head]
    out.append("</tr></thead><tbody>")
    for i, row in enumerate(rows):
        extra = f" {attrs[i]}" if i < len(attrs) and attrs[i] else ""
        out.append(f"<tr{extra}>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>")
    out.append("</tbody></table></div>")
    return "".join(out)


def _ts(ns: int | None) -> str:
    """A timestamp cell's text, kept on one line (a break inside a time misreads)."""
    return f'<span class="ts">{_esc(_when(ns))}</span>'


def _problems_cell(problems: Sequence[str]) -> str:
    if not problems:
        return ""
    return '<ul class="pl">' + "".join(f"<li>{_esc(p)}</li>" for p in problems) + "</ul>"


def timeline_page(timeline: Timeline, *, title: str = "ertools timeline") -> str:
    """The page's HTML text."""
    names = display_names([b.path for b in timeline.bags])
    drawn = [b for b in timeline.bags if b.readable]
    broken = [b for b in timeline.bags if not b.readable]
    index = {b.path: i for i, b in enumerate(drawn)}
    first = min((b.start_ns for b in drawn if b.start_ns is not None), default=None)
    last = max((b.end_ns for b in drawn if b.end_ns is not None), default=None)
    span = (
        f"{_when(first)} to {_when(last)} UTC"
        if first is not None and last is not None
        else "no readable bag"
    )
    n_problem_bags = sum(1 for b in timeline.bags if b.problems)
    subtitle = (
        f"{len(drawn)} readable bag(s), {len(broken)} unreadable, "
        f"{len(timeline.sessions)} session(s), {n_problem_bags} bag(s) with problems; {span}"
    )
    sessions_nav = "".join(
        f'<li><a class="btn" href="#session={s.index}" data-session="{s.index}">'
        f"{_esc(session_label(s))}</a></li>"
        for s in timeline.sessions
    )
    session_rows = []
    for s in timeline.sessions:
        pairs = []
        for p in s.pairings:
            gts = ", ".join(names[g] for g in p.gt) if p.gt else "no GT file covers it"
            cov = f"{p.coverage:.1f} %" if p.gt else ""
            basis = ", by time only" if p.gt and p.basis == "time" else ""
            pairs.append(f"{names[p.path]}: {cov} {gts}{basis}".replace("  ", " "))
        session_rows.append(
            [
                f'<a href="#session={s.index}" data-session="{s.index}">{s.index}</a>',
                _ts(s.start_ns),
                _ts(s.end_ns),
                f"{s.duration_ns / NS_PER_S:.3f}",
                str(len(s.paths)),
                _problems_cell(pairs),
            ]
        )
    bag_rows = [
        [
            f'<a href="#bag={index[b.path]}" data-bag="{index[b.path]}">{_esc(names[b.path])}</a>',
            _esc(KIND_LABELS[b.kind]) + (" (copy)" if b.copy_of else ""),
            _esc(lane_name(b)),
            "" if b.session is None else str(b.session),
            _ts(b.start_ns),
            _ts(b.end_ns),
            "" if b.duration_ns is None else f"{b.duration_ns / NS_PER_S:.3f}",
            _problems_cell(b.problems),
        ]
        for b in drawn
    ]
    bag_attrs = [f'class="{"problem" if b.problems else ""}"' for b in drawn]
    broken_rows = [[_esc(names[b.path]), _problems_cell(b.problems)] for b in broken]
    sections = [
        f'<section id="chart-section"><div class="toolbar">'
        f'<a class="btn" href="#day" data-day="1">fit day</a>'
        f'<button type="button" data-zoom="0.5" title="zoom in (+)">+</button>'
        f'<button type="button" data-zoom="2" title="zoom out (-)">&minus;</button>'
        f'<button type="button" data-pan="-0.25" title="pan left (&larr;)">&larr;</button>'
        f'<button type="button" data-pan="0.25" title="pan right (&rarr;)">&rarr;</button>'
        f'<span id="tl-readout" class="muted"></span></div>'
        f'<ul class="sessions">{sessions_nav}</ul>'
        f"{_legend(timeline)}"
        f'<div id="tl-chart"><svg id="tl-svg" role="img" aria-label="timeline of the bags">'
        f"</svg></div>"
        f'<p class="muted">Wheel: zoom around the pointer. Drag: pan. Click a bar: select it '
        f"and its GT pairing (linked bars); click empty space: clear. Keys: + - &larr; &rarr; 0."
        f"</p>"
        f'<pre id="tl-details" class="details">Click a bar for its details.</pre>'
        f"<noscript><p>The chart needs JavaScript; the tables below list everything.</p>"
        f"</noscript></section>",
        '<section id="sessions"><h2>Sessions</h2>'
        + _table(
            ["session", "start (UTC)", "end (UTC)", "duration (s)", "bags", "GT pairing"],
            session_rows,
        )
        + "</section>",
        '<section id="bags"><h2>Bags</h2>'
        + _table(
            [
                "bag",
                "kind",
                "lane",
                "session",
                "start (UTC)",
                "end (UTC)",
                "duration (s)",
                "problems",
            ],
            bag_rows,
            bag_attrs,
        )
        + "</section>",
    ]
    if broken:
        sections.append(
            '<section id="unreadable"><h2>Unreadable files</h2>'
            + _table(["file", "why"], broken_rows)
            + "</section>"
        )
    css = CSS % {
        "marker": MARKER_FILL,
        "edge": PROBLEM_EDGE,
        "session": SESSION_FILL,
        "uncov": UNCOVERED_COLOR,
    }
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        '<meta http-equiv="Content-Security-Policy" content="default-src \'none\'; '
        "script-src 'unsafe-inline'; style-src 'unsafe-inline'\">"
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>{_esc(title)}</title><style>{css}</style></head><body>"
        f"<header><h1>{_esc(title)}</h1><p>{_esc(subtitle)}</p></header><main>"
        + "".join(sections)
        + '</main><script type="application/json" id="tl-data">'
        + _json_for_script(page_data(timeline))
        + f"</script><script>{SCRIPT}</script></body></html>\n"
    )


def write_timeline_page(timeline: Timeline, path: Path, *, title: str | None = None) -> Path:
    """Write the page to ``path`` (folders created)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text(path, timeline_page(timeline, title=title or "ertools timeline"))
    return path
