"""Where the ground truth has no valid data, as chart layers: the gaps on a path figure and the
invalid spans on a time axis, and the valid fraction in words for a figure's title.

A gap on a path is drawn from the last valid sample before it to the first valid one after it
(:class:`~ertools.benchmarks.common.path_gaps.GapOnPath`), with a marker at each end: dashed
where the robot may have moved unmeasured (the straight chord is all the score knows of that
stretch), dotted for a tracking loss of a robot that stood still (no motion hidden). A gap at
the window's edge has one measured end: only its marker is drawn. One line per kind, broken
between gaps, so the legend names each kind once.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from ertools.views.chart import COLOURS, Dash, Layer, Line, Span

# (legend label, colour, dash) of each kind of gap, in legend order.
KINDS: dict[str, tuple[str, Dash]] = {
    "GT gap": (COLOURS["orange"], "dashed"),
    "tracking lost": (COLOURS["red"], "dashed"),
    "tracking lost, robot still": (COLOURS["red"], "dotted"),
    "no GT": ("#808080", "dashed"),
    "invalid GT": (COLOURS["purple"], "dashed"),
}


def kind(reason: str, lost: bool = True) -> str:
    """The legend label of a gap of ``reason``."""
    if reason == "gap":
        return "GT gap"
    if reason == "tracking_lost":
        return "tracking lost" if lost else "tracking lost, robot still"
    if reason == "outside_window":  # the trajectory's robot poses no GT covers
        return "no GT"
    return "invalid GT"


def path_layers(gaps: Iterable[Any], scale: float) -> list[Layer]:
    """The gaps (``GapOnPath``, (x, y) in metres) as dashed/dotted chords with their ends
    marked, ``scale`` times their coordinates (the figure's unit)."""
    pieces: dict[str, list[tuple[float, float]]] = {k: [] for k in KINDS}
    for g in gaps:
        ends = [p for p in (g.start_xy, g.end_xy) if p is not None]
        if not ends:
            continue
        rows = pieces[kind(g.reason, g.lost)]
        if rows:
            rows.append((np.nan, np.nan))
        rows += [(x * scale, y * scale) for x, y in ends]
    layers: list[Layer] = []
    for label, rows in pieces.items():
        if rows:
            xy = np.asarray(rows, dtype=float)
            colour, dash = KINDS[label]
            layers.append(
                Line(xy[:, 0], xy[:, 1], colour, 1.6, dash, label, marker="o", marker_size=3.5)
            )
    return layers


def time_spans(spans: Sequence[Any], origin_ns: int) -> list[Layer]:
    """Invalid spans (``InvalidSpan``) shaded over a time axis in seconds from ``origin_ns``;
    each kind labelled once (``GT gap span``: the markers of single samples keep the plain
    label)."""
    layers: list[Layer] = []
    seen: set[str] = set()
    for s in spans:
        label = kind(s.reason)
        colour, _ = KINDS[label]
        layers.append(
            Span(
                (s.start_ns - origin_ns) / 1e9,
                (s.end_ns - origin_ns) / 1e9,
                "x",
                colour,
                0.2,
                None if label in seen else f"{label} span",
            )
        )
        seen.add(label)
    return layers


def valid_text(validity: Any) -> str:
    """``GT 97.3% valid`` ("" without a validity mask)."""
    return "" if validity is None else f"GT {validity.valid_fraction:.1%} valid"


def pooled_fraction(validities: Iterable[Any]) -> float | None:
    """The valid fraction of several windows together (valid samples over their expected
    samples), None when there is none."""
    parts = [v for v in validities if v is not None]
    expected = sum(v.expected for v in parts)
    return sum(v.valid_samples for v in parts) / expected if expected else None
