"""The timeline as a Gantt chart: one lane per logger, one bar per bag, coloured by kind.

``draw_gantt`` takes an ``Axes``; ``save_gantt`` makes the figure (PNG or SVG by suffix)
with a height that grows with the number of lanes. Nothing global is touched.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ertools.timeline import KIND_LABELS, Timeline

KIND_COLORS = {
    "gt": "#4c72b0",
    "benchmark": "#55a868",
    "robot": "#dd8452",
    "other": "#8c8c8c",
}


def lanes(timeline: Timeline) -> list[str]:
    """Logger names of the readable bags, ordered by their first bag's start."""
    order: dict[str, int] = {}
    for b in timeline.bags:
        if b.readable and b.logger not in order:
            order[b.logger] = len(order)
    return list(order)


def draw_gantt(ax: Any, timeline: Timeline) -> None:
    """Bars from start to end on the logger's lane; bags with problems get a red edge."""
    import matplotlib.dates as _mdates
    import numpy as np
    from matplotlib.patches import Patch

    mdates: Any = _mdates  # partly untyped module
    names = lanes(timeline)
    row = {n: i for i, n in enumerate(names)}

    def num(ns: int) -> float:
        value: float = mdates.date2num(np.datetime64(ns, "ns").astype("datetime64[us]"))
        return value

    spans = [(b.start_ns, b.end_ns) for b in timeline.bags if b.start_ns is not None]
    # A minute-long bag on a day-long axis would be invisible: every bar gets at least 0.4 %
    # of the axis (the true span is in the table and the JSON).
    lo = min((a for a, _ in spans), default=0)
    hi = max((e for _, e in spans if e is not None), default=0)
    min_width = 0.004 * max(num(hi) - num(lo), 1e-9) if spans else 1e-9
    for b in timeline.bags:
        if b.start_ns is None or b.end_ns is None:
            continue
        x0 = num(b.start_ns)
        width = max(num(b.end_ns) - x0, min_width)
        problem = bool(b.problems)
        ax.barh(
            row[b.logger],
            width,
            left=x0,
            height=0.6,
            color=KIND_COLORS.get(b.kind, "#8c8c8c"),
            edgecolor="#c44e52" if problem else "black",
            linewidth=2.0 if problem else 0.5,
            hatch="//" if problem else None,
        )
    ax.set_yticks(range(len(names)), labels=names, fontsize="small")
    ax.invert_yaxis()
    locator = mdates.AutoDateLocator()
    ax.xaxis.set_major_locator(locator)
    ax.xaxis.set_major_formatter(mdates.ConciseDateFormatter(locator))
    ax.set_xlabel("time (UTC)")
    ax.grid(True, axis="x", alpha=0.3)
    kinds = sorted({b.kind for b in timeline.bags if b.readable})
    handles = [Patch(color=KIND_COLORS.get(k, "#8c8c8c"), label=KIND_LABELS[k]) for k in kinds]
    if any(b.problems for b in timeline.bags if b.readable):
        handles.append(
            Patch(facecolor="white", edgecolor="#c44e52", hatch="//", label="has problems")
        )
    if handles:
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")


def save_gantt(timeline: Timeline, path: Path) -> Path:
    """Draw the chart into ``path`` (``.png`` or ``.svg``)."""
    from matplotlib.figure import Figure

    from ertools.errors import UsageError

    if path.suffix.lower() not in (".png", ".svg"):
        raise UsageError(f"--plot {path}: give a .png or .svg file name")
    n = max(len(lanes(timeline)), 1)
    fig = Figure(figsize=(10.0, 1.2 + 0.45 * n), layout="constrained")
    ax = fig.add_subplot()
    draw_gantt(ax, timeline)
    ax.set_title(f"{timeline.readable_count} bags, {len(timeline.sessions)} session(s)")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return path
