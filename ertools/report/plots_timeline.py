"""The timeline as static pictures: one panel per session, and the whole day in one chart.

A day is hours long and a benchmark run seconds, so a day-wide axis shows runs as hairlines.
:func:`timeline_figure` therefore draws one panel per session, each with its own time axis
(the session plus a margin), lanes per logger or robot, bars coloured by kind with the
colour-blind-safe palette of :mod:`ertools.report.timeline_style`, problem bags hatched and
outlined in black with a numbered marker, and the numbered problems listed under the panels.
:func:`draw_gantt` is the day-wide chart (one ``Axes``), for notebooks.

Every drawing function takes an ``Axes``; figures are made with ``matplotlib.figure.Figure``
(no pyplot, nothing global). :func:`save_timeline_plot` picks the output by the file's suffix:
``.png`` / ``.svg`` the figure, ``.html`` the interactive page.
"""

from __future__ import annotations

import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ertools.atomic import replacing
from ertools.errors import UsageError
from ertools.report.timeline_page import (
    display_names,
    lanes_and_rows,
    session_label,
    write_timeline_page,
)
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

PLOT_SUFFIXES = (".png", ".svg", ".html", ".htm")
# Panels beyond this many would make a figure metres tall; the page shows every session.
MAX_PANELS = 24
MAX_LISTED_PROBLEMS = 30
HATCH = "////"


def lanes(timeline: Timeline) -> list[str]:
    """Lane names of the readable bags, ordered by their first bag's start."""
    order: dict[str, int] = {}
    for b in timeline.bags:
        if b.readable:
            order.setdefault(lane_name(b), len(order))
    return list(order)


def problem_numbers(timeline: Timeline) -> dict[str, int]:
    """1, 2, ... for the bags with problems, in the timeline's order (unreadable ones last)."""
    numbers: dict[str, int] = {}
    for b in timeline.bags:
        if b.problems:
            numbers.setdefault(b.path, len(numbers) + 1)
    return numbers


def _num(ns: int) -> float:
    import matplotlib.dates as _mdates  # lazy: matplotlib, 300 ms

    mdates: Any = _mdates  # partly untyped module
    value: float = mdates.date2num(np.datetime64(ns, "ns").astype("datetime64[us]"))
    return value


def session_bags(timeline: Timeline, session: Session) -> list[BagEntry]:
    """The bags of a session, copies included (they are drawn hollow beside the original)."""
    return [b for b in timeline.bags if b.readable and b.session == session.index]


def session_window(session: Session) -> tuple[int, int]:
    """The panel's time span: the session plus 5 % (at least 0.2 s) on each side."""
    margin = max(session.duration_ns // 20, 200_000_000)
    return session.start_ns - margin, session.end_ns + margin


def draw_session(
    ax: Any,
    timeline: Timeline,
    session: Session,
    numbers: Mapping[str, int] | None = None,
) -> None:
    """One session: its lanes, bars, uncovered spans of its logs and numbered problem marks.

    Args:
        ax: the ``Axes`` to draw into.
        timeline: the timeline the session belongs to.
        session: the session.
        numbers: the problem number of each bag (default :func:`problem_numbers`).
    """
    import matplotlib.dates as _mdates  # lazy: matplotlib, 300 ms

    mdates: Any = _mdates  # partly untyped module
    numbers = problem_numbers(timeline) if numbers is None else numbers
    bags = session_bags(timeline, session)
    names, rows, row_of = lanes_and_rows(bags)
    lane_of = {n: i for i, n in enumerate(names)}
    lo, hi = session_window(session)
    x_lo, x_hi = _num(lo), _num(hi)
    # A bar gets at least 0.3 % of the panel, so a one-message bag is still seen.
    min_width = 0.003 * (x_hi - x_lo)
    pairing_of = {p.path: p for p in session.pairings}
    ax.axvspan(_num(session.start_ns), _num(session.end_ns), color=SESSION_FILL, zorder=0)
    for b in bags:
        assert b.start_ns is not None and b.end_ns is not None
        lane = lane_of[lane_name(b)]
        n_rows = rows[lane]
        height = 0.8 / n_rows
        y = lane - 0.4 + row_of[b.path] * height + height / 2
        x0 = _num(b.start_ns)
        width = max(_num(b.end_ns) - x0, min_width)
        color = KIND_COLORS.get(b.kind, "#999999")
        problem = bool(b.problems)
        copy = b.copy_of is not None
        ax.barh(
            y,
            width,
            left=x0,
            height=height * 0.78,
            color="white" if copy else color,
            edgecolor=PROBLEM_EDGE if problem else (color if copy else "#1d2430"),
            linewidth=1.8 if problem else (1.2 if copy else 0.5),
            linestyle="--" if copy else "-",
            hatch=HATCH if problem else None,
            zorder=2,
            gid=b.path,  # names the bar in an SVG and for tests
        )
        pairing = pairing_of.get(b.path)
        for a, e in pairing.uncovered if pairing is not None else ():
            ax.barh(
                y + height * 0.39 + height * 0.06,
                max(_num(e) - _num(a), min_width),
                left=_num(a),
                height=height * 0.12,
                color=UNCOVERED_COLOR,
                edgecolor="black",
                linewidth=0.3,
                zorder=3,
            )
        if b.path in numbers:
            ax.text(
                x0,
                y,
                str(numbers[b.path]),
                ha="center",
                va="center",
                fontsize=7,
                fontweight="bold",
                zorder=4,
                clip_on=True,
                bbox={"boxstyle": "circle,pad=0.25", "fc": MARKER_FILL, "ec": "black", "lw": 0.8},
            )
    ax.set_xlim(x_lo, x_hi)
    ax.set_ylim(len(names) - 0.5, -0.5)
    ax.set_yticks(range(len(names)), labels=names, fontsize="small")
    locator = mdates.AutoDateLocator(minticks=5, maxticks=12)
    ax.xaxis.set_major_locator(locator)
    ax.xaxis.set_major_formatter(mdates.ConciseDateFormatter(locator, show_offset=False))
    ax.tick_params(axis="x", labelsize="small")
    ax.grid(True, axis="x", alpha=0.3)
    duration = session.duration_ns / 1e9
    ax.set_title(f"{session_label(session)} ({duration:.1f} s)", loc="left", fontsize="medium")
    ax.set_label(f"session {session.index}")


def legend_handles(
    kinds: Sequence[str], *, problems: bool, copies: bool, uncovered: bool
) -> list[Any]:
    """Legend entries drawn exactly as the bars are."""
    from matplotlib.patches import Patch  # lazy: matplotlib, 300 ms

    handles: list[Any] = [
        Patch(facecolor=KIND_COLORS[k], edgecolor="#1d2430", linewidth=0.5, label=KIND_LABELS[k])
        for k in KIND_COLORS
        if k in kinds
    ]
    if problems:
        handles.append(
            Patch(
                facecolor="#bbbbbb",
                edgecolor=PROBLEM_EDGE,
                linewidth=1.8,
                hatch=HATCH,
                label="has problems (numbered, listed below)",
            )
        )
    if copies:
        handles.append(
            Patch(facecolor="white", edgecolor="#555555", linestyle="--", label="copy (hollow)")
        )
    if uncovered:
        handles.append(Patch(facecolor=UNCOVERED_COLOR, edgecolor="black", label="no GT covers"))
    handles.append(Patch(facecolor=SESSION_FILL, label="session"))
    return handles


def problem_lines(timeline: Timeline, numbers: Mapping[str, int], width: int = 150) -> list[str]:
    """``3. name: problem; problem`` per numbered bag (wrapped), at most
    :data:`MAX_LISTED_PROBLEMS` bags."""
    names = display_names([b.path for b in timeline.bags])
    by_path = {b.path: b for b in timeline.bags}
    lines: list[str] = []
    ordered = sorted(numbers.items(), key=lambda kv: kv[1])
    for path, n in ordered[:MAX_LISTED_PROBLEMS]:
        b = by_path[path]
        where = "" if b.readable else " (unreadable)"
        text = f"{n}. {names[path]}{where}: " + "; ".join(b.problems)
        lines += textwrap.wrap(text, width, subsequent_indent="     ") or [text]
    if len(ordered) > MAX_LISTED_PROBLEMS:
        lines.append(
            f"... and {len(ordered) - MAX_LISTED_PROBLEMS} more bag(s) with problems: "
            "see the table, the JSON or the HTML page"
        )
    return lines


def timeline_figure(timeline: Timeline) -> Any:
    """The figure: a legend, one panel per session (at most :data:`MAX_PANELS`), the list of
    numbered problems. Returns a ``matplotlib.figure.Figure``."""
    from matplotlib.figure import Figure  # lazy: matplotlib, 300 ms

    numbers = problem_numbers(timeline)
    sessions = list(timeline.sessions[:MAX_PANELS])
    lane_counts = [max(len(lanes_and_rows(session_bags(timeline, s))[0]), 1) for s in sessions]
    lines = problem_lines(timeline, numbers)
    if len(timeline.sessions) > MAX_PANELS:
        lines.insert(
            0,
            f"sessions {MAX_PANELS + 1} to {len(timeline.sessions)} are not drawn here "
            "(see the HTML page: --plot FILE.html)",
        )
    heights = [0.9 + 0.32 * n for n in lane_counts]
    text_height = 0.3 + 0.16 * len(lines) if lines else 0.0
    fig = Figure(
        figsize=(12.0, 0.7 + sum(heights) + text_height + 0.25 * len(heights)),
        layout="constrained",
    )
    ratios = [*heights, text_height] if lines else heights
    grid = fig.add_gridspec(max(len(ratios), 1), 1, height_ratios=ratios or [1.0])
    for i, session in enumerate(sessions):
        draw_session(fig.add_subplot(grid[i, 0]), timeline, session, numbers)
    if lines:
        ax = fig.add_subplot(grid[len(sessions), 0])
        ax.set_axis_off()
        ax.set_label("problems")
        from matplotlib.transforms import blended_transform_factory  # lazy: matplotlib, 300 ms

        # From the figure's left edge, not the axes': the panels' lane labels widen the left
        # margin every row of the grid shares, which pushed the list off the right edge.
        ax.text(
            0.01,
            1.0,
            ("Problems\n" if numbers else "") + "\n".join(lines),
            va="top",
            ha="left",
            fontsize=8,
            family="monospace",
            transform=blended_transform_factory(fig.transFigure, ax.transAxes),
        )
    readable = [b for b in timeline.bags if b.readable]
    kinds = sorted({b.kind for b in readable})
    pairings = timeline.pairings
    fig.legend(
        handles=legend_handles(
            kinds,
            problems=bool(numbers),
            copies=any(b.copy_of for b in readable),
            uncovered=any(p.uncovered for p in pairings),
        ),
        loc="outside upper center",
        ncols=8,
        fontsize="small",
        frameon=False,
    )
    return fig


def draw_gantt(ax: Any, timeline: Timeline) -> None:
    """The whole day on one axis: a bar per bag on its lane; problem bags hatched and outlined.

    Sessions of seconds are hairlines on a day-long axis: :func:`timeline_figure` draws one
    panel per session instead.
    """
    import matplotlib.dates as _mdates  # lazy: matplotlib, 300 ms

    mdates: Any = _mdates  # partly untyped module
    names = lanes(timeline)
    row = {n: i for i, n in enumerate(names)}
    spans = [(b.start_ns, b.end_ns) for b in timeline.bags if b.start_ns is not None]
    # A minute-long bag on a day-long axis would be invisible: every bar gets at least 0.4 %
    # of the axis (the true span is in the table and the JSON).
    lo = min((a for a, _ in spans), default=0)
    hi = max((e for _, e in spans if e is not None), default=0)
    min_width = 0.004 * max(_num(hi) - _num(lo), 1e-9) if spans else 1e-9
    for s in timeline.sessions:
        ax.axvspan(_num(s.start_ns), _num(s.end_ns), color=SESSION_FILL, zorder=0)
    for b in timeline.bags:
        if b.start_ns is None or b.end_ns is None:
            continue
        x0 = _num(b.start_ns)
        problem = bool(b.problems)
        color = KIND_COLORS.get(b.kind, "#999999")
        ax.barh(
            row[lane_name(b)],
            max(_num(b.end_ns) - x0, min_width),
            left=x0,
            height=0.6,
            color="white" if b.copy_of else color,
            edgecolor=PROBLEM_EDGE if problem else "#1d2430",
            linewidth=1.8 if problem else 0.5,
            hatch=HATCH if problem else None,
        )
    ax.set_yticks(range(len(names)), labels=names, fontsize="small")
    ax.invert_yaxis()
    locator = mdates.AutoDateLocator()
    ax.xaxis.set_major_locator(locator)
    ax.xaxis.set_major_formatter(mdates.ConciseDateFormatter(locator))
    ax.set_xlabel("time (UTC)")
    ax.grid(True, axis="x", alpha=0.3)
    readable = [b for b in timeline.bags if b.readable]
    handles = legend_handles(
        sorted({b.kind for b in readable}),
        problems=any(b.problems for b in readable),
        copies=any(b.copy_of for b in readable),
        uncovered=False,
    )
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")


def save_timeline_plot(timeline: Timeline, path: Path) -> Path:
    """Write ``path`` by its suffix: ``.png`` / ``.svg`` the per-session figure, ``.html`` /
    ``.htm`` the interactive page."""

    suffix = path.suffix.lower()
    if suffix not in PLOT_SUFFIXES:
        raise UsageError(f"--plot {path}: give a .png, .svg or .html file name")
    if suffix in (".html", ".htm"):
        return write_timeline_page(timeline, path)
    fig = timeline_figure(timeline)
    path.parent.mkdir(parents=True, exist_ok=True)
    with replacing(path) as tmp:
        fig.savefig(tmp, dpi=110)
    return path
