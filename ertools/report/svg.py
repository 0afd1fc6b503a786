"""A :class:`~ertools.views.chart.Chart` as an SVG document, written straight from its arrays.

Pure: arrays in, text out, no matplotlib (a report's figure costs milliseconds, not the
0.3 - 0.5 s of a matplotlib draw and savefig: docs/performance.md, issue 29). The layout is
matplotlib's in spirit: a title above, the axes with "nice" ticks (1, 2, 2.5, 5 x 10^k) and
5 % margins around the data, a light grid, axis labels with their units, a second y scale on
the right or a colour scale when the chart has one, and the legend below the axes (where it
never hides data). Every element a test or a reader may look for carries a class:
``series`` groups (one per layer, ``data-label`` = its legend text) holding ``line``
(one ``<path>``, ``data-points`` vertices), ``marker``, ``span``, ``band``, ``errorbar``,
``bar``, ``refline``, ``arrow`` and ``label`` elements; ``xtick``/``ytick``/``rtick`` texts;
``xlabel``/``ylabel``/``rlabel``; ``title``; ``legend``.

Text widths are estimated (average widths of DejaVu Sans, the font the report names first, for
capitals, narrow and other characters), which is all the layout needs: labels are never
measured to the pixel.
"""

from __future__ import annotations

import math
from html import escape

import numpy as np

from ertools.report.svg_marks import Scale, attr, layer_svg, swatch
from ertools.views.chart import (
    PIXELS_PER_INCH,
    Arrows,
    Band,
    Bars,
    Chart,
    ErrorBars,
    FloatArray,
    Layer,
    Line,
    Rects,
    RefLine,
    Scatter,
    Span,
    Text,
    floats,
    viridis,
)

FONT = "DejaVu Sans, Verdana, Arial, sans-serif"
TICK_PX, LABEL_PX, TITLE_PX, LEGEND_PX = 11.0, 12.0, 13.0, 11.0
# Average advance widths of DejaVu Sans in em: capitals and underscores are wider than
# lower case (a legend of state names is all capitals), spaces and dots narrower.
_EM_UPPER, _EM_OTHER, _EM_NARROW = 0.72, 0.6, 0.32
_NARROW = frozenset(" .,:;|!il()[]'")
MARGIN = 0.05  # of the data's span, on each side (matplotlib's default)


def text_width(text: str, px: float) -> float:
    """Estimated width of ``text`` at ``px`` pixels."""
    upper = sum(c.isupper() or c == "_" for c in text)
    narrow = sum(c in _NARROW for c in text)
    return (upper * _EM_UPPER + narrow * _EM_NARROW + (len(text) - upper - narrow) * _EM_OTHER) * px


def nice_ticks(lo: float, hi: float, target: int) -> tuple[FloatArray, int]:
    """About ``target`` ticks inside [lo, hi] at 1, 2, 2.5 or 5 x 10^k, and the decimals
    their labels need."""
    span = hi - lo
    if not (math.isfinite(span) and span > 0):
        return np.asarray([lo], dtype=np.float64), 0
    raw = span / max(target, 1)
    power = 10.0 ** math.floor(math.log10(raw))
    step = next((m * power for m in (1.0, 2.0, 2.5, 5.0, 10.0) if m * power >= raw), 10 * power)
    first = math.ceil(lo / step - 1e-9)
    last = math.floor(hi / step + 1e-9)
    ticks = np.arange(first, last + 1, dtype=np.float64) * step
    exponent = math.floor(math.log10(step) + 1e-9)
    quarter = round(step / 10.0**exponent, 6) == 2.5  # 0.25 needs a decimal more than 0.2
    return ticks, max(0, -exponent + quarter)


def tick_text(value: float, decimals: int) -> str:
    text = f"{value:.{decimals}f}" if abs(value) < 1e7 else f"{value:.6g}"
    return "0" if text.lstrip("-").strip("0.") == "" else text


def _extent(layers: tuple[Layer, ...], axis: str, side: str) -> list[FloatArray]:
    """Every value ``layers`` put on ``axis`` (``"x"`` or ``"y"`` of ``side``)."""
    out: list[FloatArray] = []
    for layer in layers:
        if axis == "y" and getattr(layer, "side", "left") != side:
            continue
        match layer:
            case Line() | Scatter():
                out.append(floats(layer.x if axis == "x" else layer.y))
            case Arrows() | Rects():
                out += (
                    [floats(layer.x0), floats(layer.x1)]
                    if axis == "x"
                    else [floats(layer.y0), floats(layer.y1)]
                )
            case Span():
                if layer.axis == axis:
                    out.append(floats([layer.lo, layer.hi]))
            case Band():
                out += [floats(layer.x)] if axis == "x" else [floats(layer.lo), floats(layer.hi)]
            case ErrorBars():
                out.append(floats(layer.x if axis == "x" else layer.y))
                if layer.axis == axis:
                    out += [floats(layer.lo), floats(layer.hi)]
            case Bars():
                if axis == "x":
                    x = floats(layer.x)
                    out += [x - layer.width / 2, x + layer.width / 2]
                else:
                    out += [floats(layer.height), floats([0.0])]
            case RefLine():
                if layer.axis == axis:
                    out.append(floats([layer.value]))
                else:
                    out.append(floats([v for v in (layer.lo, layer.hi) if v is not None]))
            case Text():
                out.append(floats([layer.x if axis == "x" else layer.y]))
    return out


def _limits(values: list[FloatArray], include_zero: bool, margin: float) -> tuple[float, float]:
    data = np.concatenate(values) if values else np.empty(0)
    data = data[np.isfinite(data)]
    if include_zero:
        data = np.append(data, 0.0)
    if data.size == 0:
        return 0.0, 1.0
    lo, hi = float(data.min()), float(data.max())
    if hi - lo <= 1e-12 * max(abs(lo), abs(hi), 1.0):
        pad = max(abs(lo) * 0.05, 0.5)
        return lo - pad, hi + pad
    pad = (hi - lo) * margin
    bottom = lo - pad if not (include_zero and lo >= 0) else lo
    return bottom, hi + pad


def _wrap(text: str, px: float, width: float) -> list[str]:
    words, lines, line = text.split(), [], ""
    for word in words:
        candidate = f"{line} {word}".strip()
        if line and text_width(candidate, px) > width:
            lines.append(line)
            line = word
        else:
            line = candidate
    return [*lines, line] if line else lines


def render(chart: Chart, size: tuple[float, float], title: str = "", *, uid: str = "f") -> str:
    """The SVG document of ``chart`` in a ``size``-inch figure (at :data:`PIXELS_PER_INCH`),
    ``title`` above the axes; ``uid`` prefixes the ids inside (clip paths, gradients), for
    documents that hold several charts."""
    return _document(*_body(chart, size, title, uid))


def _document(body: str, width: float, height: float) -> str:
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0f}" height="{height:.0f}" '
        f'viewBox="0 0 {width:.0f} {height:.0f}" font-family="{FONT}">\n{body}</svg>\n'
    )


def stack(panels: list[tuple[Chart, tuple[float, float], str]]) -> str:
    """Several charts stacked top to bottom in one SVG document (``--plot FILE.svg``)."""
    parts, y, width = [], 0.0, 0.0
    for i, (chart, size, title) in enumerate(panels):
        body, w, h = _body(chart, size, title, f"p{i}")
        parts.append(f'<g transform="translate(0,{y:.0f})">{body}</g>')
        y += h
        width = max(width, w)
    return _document("\n".join(parts), width, y)


def _body(
    chart: Chart, size: tuple[float, float], title: str, uid: str
) -> tuple[str, float, float]:
    width, height = size[0] * PIXELS_PER_INCH, size[1] * PIXELS_PER_INCH
    layers = chart.layers
    labelled = [layer for layer in layers if getattr(layer, "label", None)]

    # Vertical budget: title, then the axes, then tick labels, x label and legend rows.
    title_lines = _wrap(title, TITLE_PX, width - 20) if title else []
    top = 10 + len(title_lines) * TITLE_PX * 1.3 + (4 if title_lines else 0)
    legend_rows = _legend_rows(labelled, width - 40) if chart.legend else []
    bottom = 8 + TICK_PX + 6 + (LABEL_PX * 1.4 if chart.x.label else 0) + 4
    bottom += len(legend_rows) * LEGEND_PX * 1.6 + (6 if legend_rows else 0)

    xlim = chart.x.limits or _limits(_extent(layers, "x", "left"), chart.x.include_zero, MARGIN)
    ylim = chart.y.limits or _limits(
        _extent(layers, "y", "left"), chart.y.include_zero, _chart_margin(chart)
    )
    rlim = None
    if chart.right is not None:
        rlim = chart.right.limits or _limits(
            _extent(layers, "y", "right"), chart.right.include_zero, _chart_margin(chart)
        )
    # Horizontal budget: y tick labels and label on the left; right scale or colour bar.
    left = right = 0.0
    for _ in range(2):  # tick labels depend on the limits, the limits (aspect) on the box
        plot_h = height - top - bottom
        yt, _ = _ticks(chart.y, ylim, plot_h, 45)
        left = 10 + (LABEL_PX * 1.5 if chart.y.label else 0) + _labels_width(yt) + 6
        right = 16.0
        if chart.right is not None and rlim is not None:
            rt, _ = _ticks(chart.right, rlim, plot_h, 45)
            right = 10 + LABEL_PX * 1.5 + _labels_width(rt) + 6
        if chart.colour_scale is not None:
            cs = chart.colour_scale
            ct, cd = nice_ticks(cs.lo, cs.hi, 5)
            right = 16 + 14 + 6 + max(text_width(tick_text(v, cd), TICK_PX) for v in ct) + 10
            right += LABEL_PX * 1.5
        plot_w = width - left - right
        if chart.equal_aspect:
            xlim, ylim = _equal(xlim, ylim, plot_w, plot_h)
    box = (left, top, plot_w, plot_h)
    sx = Scale(xlim[0], xlim[1], left, plot_w, symlog=chart.x.symlog)
    sy = Scale(ylim[0], ylim[1], top, plot_h, flip=True, symlog=chart.y.symlog)
    sr = sy
    if rlim is not None and chart.right is not None:
        sr = Scale(rlim[0], rlim[1], top, plot_h, flip=True, symlog=chart.right.symlog)

    out: list[str] = [f'<rect width="{width:.0f}" height="{height:.0f}" fill="#ffffff"/>']
    clip = f"{uid}-axes"
    out.append(
        f'<defs><clipPath id="{clip}"><rect x="{left:.1f}" y="{top:.1f}" '
        f'width="{plot_w:.1f}" height="{plot_h:.1f}"/></clipPath>'
        f'<pattern id="{uid}-hatch" width="6" height="6" patternUnits="userSpaceOnUse" '
        'patternTransform="rotate(45)"><path d="M0,0v6" stroke="#444444" stroke-width="1"/>'
        "</pattern></defs>"
    )
    xt, _ = _ticks(chart.x, xlim, plot_w, 90)
    yt, _ = _ticks(chart.y, ylim, plot_h, 45)
    grid: list[str] = []
    if chart.grid in ("both", "x"):
        grid += [f"M{sx.one(v):.1f},{top:.1f}v{plot_h:.1f}" for v, _ in xt]
    if chart.grid in ("both", "y"):
        grid += [f"M{left:.1f},{sy.one(v):.1f}h{plot_w:.1f}" for v, _ in yt]
    if grid:
        out.append(f'<path class="grid" d="{"".join(grid)}" stroke="#dddddd" stroke-width="0.7"/>')

    scale = (chart.colour_scale.lo, chart.colour_scale.hi) if chart.colour_scale else None
    out.append(f'<g clip-path="url(#{clip})">')
    for layer in layers:
        ys = sr if getattr(layer, "side", "left") == "right" else sy
        out.append(layer_svg(layer, sx, ys, box, scale, uid))
    out.append("</g>")
    out.append(
        f'<rect class="frame" x="{left:.1f}" y="{top:.1f}" width="{plot_w:.1f}" '
        f'height="{plot_h:.1f}" fill="none" stroke="#000000" stroke-width="0.8"/>'
    )
    if chart.note:
        out.append(
            f'<text class="note" x="{left + plot_w / 2:.1f}" y="{top + plot_h / 2:.1f}" '
            f'text-anchor="middle" font-size="{LABEL_PX}">{escape(chart.note)}</text>'
        )

    # Ticks and labels.
    base = top + plot_h
    ticks = [f"M{sx.one(v):.1f},{base:.1f}v4" for v, _ in xt]
    ticks += [f"M{left:.1f},{sy.one(v):.1f}h-4" for v, _ in yt]
    out += [
        f'<text class="xtick" x="{sx.one(v):.1f}" y="{base + 6 + TICK_PX:.1f}" '
        f'text-anchor="middle" font-size="{TICK_PX}">{escape(t)}</text>'
        for v, t in xt
    ]
    out += [
        f'<text class="ytick" x="{left - 6:.1f}" y="{sy.one(v) + TICK_PX * 0.35:.1f}" '
        f'text-anchor="end" font-size="{TICK_PX}">{escape(t)}</text>'
        for v, t in yt
    ]
    if chart.x.label:
        out.append(
            f'<text class="xlabel" x="{left + plot_w / 2:.1f}" '
            f'y="{base + 8 + TICK_PX + LABEL_PX * 1.2:.1f}" text-anchor="middle" '
            f'font-size="{LABEL_PX}"{attr(fill=chart.x.colour)}>{escape(chart.x.label)}</text>'
        )
    if chart.y.label:
        cx, cy = 8 + LABEL_PX, top + plot_h / 2
        out.append(
            f'<text class="ylabel" x="{cx:.1f}" y="{cy:.1f}" text-anchor="middle" '
            f'transform="rotate(-90 {cx:.1f} {cy:.1f})" font-size="{LABEL_PX}"'
            f"{attr(fill=chart.y.colour)}>{escape(chart.y.label)}</text>"
        )
    if chart.right is not None and rlim is not None:
        rt, _ = _ticks(chart.right, rlim, plot_h, 45)
        edge = left + plot_w
        ticks += [f"M{edge:.1f},{sr.one(v):.1f}h4" for v, _ in rt]
        out += [
            f'<text class="rtick" x="{edge + 6:.1f}" y="{sr.one(v) + TICK_PX * 0.35:.1f}" '
            f'font-size="{TICK_PX}">{escape(t)}</text>'
            for v, t in rt
        ]
        cx, cy = width - 8 - LABEL_PX * 0.4, top + plot_h / 2
        out.append(
            f'<text class="rlabel" x="{cx:.1f}" y="{cy:.1f}" text-anchor="middle" '
            f'transform="rotate(90 {cx:.1f} {cy:.1f})" font-size="{LABEL_PX}"'
            f"{attr(fill=chart.right.colour)}>{escape(chart.right.label)}</text>"
        )
    out.append(f'<path class="ticks" d="{"".join(ticks)}" stroke="#000000" stroke-width="0.8"/>')
    if chart.colour_scale is not None:
        out.append(_colour_bar(chart, left + plot_w + 16, top, plot_h, width, uid))
    for i, line in enumerate(title_lines):
        out.append(
            f'<text class="title" x="{width / 2:.1f}" y="{8 + TITLE_PX * (1 + 1.3 * i):.1f}" '
            f'text-anchor="middle" font-size="{TITLE_PX}">{escape(line)}</text>'
        )
    if legend_rows:
        out.append(_legend(legend_rows, height - len(legend_rows) * LEGEND_PX * 1.6 - 4, width))
    return "\n".join(out) + "\n", width, height


def _chart_margin(chart: Chart) -> float:
    """The y margin: room above bars for their labels when the chart writes some."""
    labels = any(isinstance(layer, Text) for layer in chart.layers)
    bars = any(isinstance(layer, Bars) for layer in chart.layers)
    return 0.2 if labels and bars else MARGIN


def _ticks(
    axis: object, lim: tuple[float, float], length: float, spacing: float
) -> tuple[list[tuple[float, str]], int]:
    explicit = getattr(axis, "ticks", None)
    if explicit is not None:
        return [(v, t) for v, t in explicit if lim[0] <= v <= lim[1]], 0
    threshold = getattr(axis, "symlog", None)
    if threshold is not None:  # zero and the decades beyond the linear range, both signs
        decades = threshold * 10.0 ** np.arange(0, 12)
        values = np.sort(np.r_[-decades, 0.0, decades])
        values = values[(values >= lim[0]) & (values <= lim[1])]
        return [(float(v), f"{v:g}") for v in values], 0
    values, decimals = nice_ticks(lim[0], lim[1], max(int(length / spacing), 2))
    return [(float(v), tick_text(float(v), decimals)) for v in values], decimals


def _labels_width(ticks: list[tuple[float, str]]) -> float:
    return max((text_width(t, TICK_PX) for _, t in ticks), default=0.0)


def _equal(
    xlim: tuple[float, float], ylim: tuple[float, float], w: float, h: float
) -> tuple[tuple[float, float], tuple[float, float]]:
    """Limits widened (around their centres) so that a unit is as long on both axes."""
    per_px = max((xlim[1] - xlim[0]) / w, (ylim[1] - ylim[0]) / h)
    cx, cy = (xlim[0] + xlim[1]) / 2, (ylim[0] + ylim[1]) / 2
    return (cx - per_px * w / 2, cx + per_px * w / 2), (cy - per_px * h / 2, cy + per_px * h / 2)


def _legend_rows(layers: list[Layer], width: float) -> list[list[tuple[Layer, float]]]:
    rows: list[list[tuple[Layer, float]]] = []
    row: list[tuple[Layer, float]] = []
    used = 0.0
    for layer in layers:
        w = 22 + 6 + text_width(str(getattr(layer, "label", "")), LEGEND_PX) + 16
        if row and used + w > width:
            rows.append(row)
            row, used = [], 0.0
        row.append((layer, w))
        used += w
    return [*rows, row] if row else rows


def _legend(rows: list[list[tuple[Layer, float]]], top: float, width: float) -> str:
    out = ['<g class="legend">']
    for r, row in enumerate(rows):
        total = sum(w for _, w in row) - 16
        x = max((width - total) / 2, 10.0)
        y = top + r * LEGEND_PX * 1.6 + LEGEND_PX * 0.8
        for layer, w in row:
            label = str(getattr(layer, "label", ""))
            out.append(
                f'<g class="entry"{attr(data_label=label)}>{swatch(layer, x, y)}'
                f'<text x="{x + 28:.1f}" y="{y + LEGEND_PX * 0.35:.1f}" '
                f'font-size="{LEGEND_PX}">{escape(label)}</text></g>'
            )
            x += w
    out.append("</g>")
    return "".join(out)


def _colour_bar(chart: Chart, x: float, top: float, h: float, width: float, uid: str) -> str:
    cs = chart.colour_scale
    assert cs is not None
    gid = f"{uid}-scale"
    stops = np.linspace(0.0, 1.0, 9)
    colours = viridis(stops)
    grad = "".join(  # from the bottom (lo) up
        f'<stop offset="{s:.3f}" stop-color="{c}"/>' for s, c in zip(stops, colours, strict=True)
    )
    out = [
        f'<g class="colour-scale"><defs><linearGradient id="{gid}" x1="0" y1="1" x2="0" y2="0">'
        f"{grad}</linearGradient></defs>",
        f'<rect x="{x:.1f}" y="{top:.1f}" width="14" height="{h:.1f}" fill="url(#{gid})" '
        'stroke="#000000" stroke-width="0.6"/>',
    ]
    scale = Scale(cs.lo, cs.hi if cs.hi > cs.lo else cs.lo + 1.0, top, h, flip=True)
    ticks, decimals = nice_ticks(cs.lo, cs.hi, 5)
    for v in ticks:
        y = scale.one(float(v))
        out.append(
            f'<path d="M{x + 14:.1f},{y:.1f}h4" stroke="#000000" stroke-width="0.8"/>'
            f'<text class="ctick" x="{x + 20:.1f}" y="{y + TICK_PX * 0.35:.1f}" '
            f'font-size="{TICK_PX}">{escape(tick_text(float(v), decimals))}</text>'
        )
    cx, cy = width - 8 - LABEL_PX * 0.4, top + h / 2
    out.append(
        f'<text class="clabel" x="{cx:.1f}" y="{cy:.1f}" text-anchor="middle" '
        f'transform="rotate(90 {cx:.1f} {cy:.1f})" font-size="{LABEL_PX}">'
        f"{escape(cs.label)}</text></g>"
    )
    return "".join(out)
