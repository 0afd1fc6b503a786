"""The rank-stability plot: one row per team, its score as a dot and its interval as a bar,
the teams the data cannot order bracketed together (``ertools.report.ranks``).

Written as SVG text straight from the numbers (no plotting library: a page of many
leaderboards draws in microseconds), to be put inline in an HTML page. Every text in it (team
names come from logs and manifests) is escaped here, so the caller may mark it safe.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from html import escape

from ertools.report.ranks import Standing

WIDTH = 760
ROW = 24
LABEL = 200  # px for the team names, left of the axis
RIGHT = 170  # px for the score's text, right of the axis
NAME = 26  # characters of a team name shown (the full name is in the row's tooltip)
TOP = 28
BOTTOM = 40
DOT = "#1f5fa8"
BAR = "#1f5fa8"
TIE_FILL = "#fdf1dc"
TIE_LINE = "#c77c02"


def _ticks(low: float, high: float, count: int = 5) -> list[float]:
    """Round tick values covering [low, high] (1, 2, 5 times a power of ten apart)."""
    span = high - low
    raw = span / max(count, 1)
    power = 10.0 ** math.floor(math.log10(raw))
    step = next(m * power for m in (1.0, 2.0, 5.0, 10.0) if m * power >= raw)
    first = math.ceil(low / step) * step
    out = []
    value = first
    while value <= high + step * 1e-9:
        out.append(0.0 if abs(value) < step * 1e-9 else value)
        value += step
    return out


def _text(
    x: float, y: float, text: str, *, anchor: str = "start", css: str = "", fill: str = ""
) -> str:
    style = (f' class="{css}"' if css else "") + (f' fill="{fill}"' if fill else "")
    return f'<text x="{x:.1f}" y="{y:.1f}" text-anchor="{anchor}"{style}>{escape(text)}</text>'


def interval_plot(
    standings: Sequence[Standing],
    *,
    factor: float = 1.0,
    unit: str = "",
    decimals: int = 2,
    axis: str = "score",
    confidence: float = 0.95,
) -> str:
    """An SVG of ``standings`` (in rank order): values shown times ``factor`` in ``unit``.

    Rows without an interval have a hollow dot and say so; a tie group is a shaded band with
    a bracket and its ``=N`` on the left.
    """
    rows = list(standings)
    n = len(rows)
    height = TOP + ROW * max(n, 1) + BOTTOM
    rows = [s for s in rows if math.isfinite(s.score)]  # an infinite score has no place
    n = len(rows)
    height = TOP + ROW * max(n, 1) + BOTTOM
    values = [v * factor for s in rows for v in (s.score, *(s.interval or ()))]
    low, high = (min(values), max(values)) if values else (0.0, 1.0)
    if high - low <= 0.0:
        pad = abs(high) * 0.1 or 1.0
        low, high = low - pad, high + pad
    else:
        pad = (high - low) * 0.06
        low, high = low - pad, high + pad
    left, right = LABEL, WIDTH - RIGHT

    def x(value: float) -> float:
        return left + (value * factor - low) / (high - low) * (right - left)

    def y(i: int) -> float:
        return TOP + ROW * i + ROW / 2

    pct = f"{confidence * 100:g} %"
    label = f"{axis} ({unit})" if unit else axis
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" class="rank-plot" width="{WIDTH}" '
        f'height="{height}" viewBox="0 0 {WIDTH} {height}" role="img" '
        f'font-family="sans-serif" font-size="12">',
        f"<title>{escape(f'{label}: score (dot) and its {pct} interval (bar) per team')}</title>",
    ]
    # Tie groups first, behind the rows.
    i = 0
    while i < n:
        j = i
        while j + 1 < n and rows[j + 1].group == rows[i].group:
            j += 1
        if j > i:
            top, bottom = TOP + ROW * i + 2, TOP + ROW * (j + 1) - 2
            parts.append(
                f'<rect class="tie" x="4" y="{top}" width="{WIDTH - 8}" '
                f'height="{bottom - top}" fill="{TIE_FILL}" rx="4"/>'
            )
            parts.append(
                f'<path class="bracket" d="M14 {top + 3} h-6 V{bottom - 3} h6" fill="none" '
                f'stroke="{TIE_LINE}" stroke-width="2"/>'
            )
            parts.append(
                _text(
                    18,
                    (top + bottom) / 2 + 4,
                    f"={rows[i].group}",
                    css="tie-mark",
                    fill=TIE_LINE,
                )
            )
        i = j + 1
    # Axis: grid lines and ticks.
    axis_y = TOP + ROW * max(n, 1)
    for tick in _ticks(low, high):
        tx = left + (tick - low) / (high - low) * (right - left)
        parts.append(
            f'<line x1="{tx:.1f}" y1="{TOP - 4}" x2="{tx:.1f}" y2="{axis_y}" stroke="#ddd"/>'
        )
        parts.append(_text(tx, axis_y + 14, f"{tick:g}", anchor="middle"))
    parts.append(f'<line x1="{left}" y1="{axis_y}" x2="{right}" y2="{axis_y}" stroke="#666"/>')
    parts.append(_text((left + right) / 2, axis_y + 32, label, anchor="middle"))
    parts.append(_text(left, TOP - 10, f"dot: score; bar: {pct} interval", css="legend"))
    for k, s in enumerate(rows):
        cy = y(k)
        marker = s.marker
        name = s.name if len(s.name) <= NAME else s.name[: NAME - 1] + "\u2026"
        parts.append(f'<g class="row"><title>{escape(s.name)}</title>')
        parts.append(_text(LABEL - 8, cy + 4, f"{marker}  {name}", anchor="end", css="team"))
        shown = f"{s.score * factor:.{decimals}f}"
        if s.interval is not None:
            a, b = x(s.interval[0]), x(s.interval[1])
            parts.append(
                f'<g class="interval"><line x1="{a:.1f}" y1="{cy:.1f}" x2="{b:.1f}" '
                f'y2="{cy:.1f}" stroke="{BAR}" stroke-width="2"/>'
                f'<line x1="{a:.1f}" y1="{cy - 5:.1f}" x2="{a:.1f}" y2="{cy + 5:.1f}" '
                f'stroke="{BAR}" stroke-width="2"/>'
                f'<line x1="{b:.1f}" y1="{cy - 5:.1f}" x2="{b:.1f}" y2="{cy + 5:.1f}" '
                f'stroke="{BAR}" stroke-width="2"/></g>'
            )
            parts.append(
                f'<circle class="score" cx="{x(s.score):.1f}" cy="{cy:.1f}" r="4.5" fill="{DOT}"/>'
            )
            lo, hi = (f"{v * factor:.{decimals}f}" for v in s.interval)
            parts.append(_text(right + 8, cy + 4, f"{shown} [{lo}, {hi}]", css="value"))
        else:
            parts.append(
                f'<circle class="score no-interval" cx="{x(s.score):.1f}" cy="{cy:.1f}" '
                f'r="4.5" fill="white" stroke="{DOT}" stroke-width="2"/>'
            )
            parts.append(_text(right + 8, cy + 4, f"{shown} (no interval)", css="value"))
        parts.append("</g>")
    parts.append("</svg>")
    return "".join(parts)
