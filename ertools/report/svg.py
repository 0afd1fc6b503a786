"""A :class:`~ertools.report.chart.Chart` as an SVG document, written straight from its arrays.

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

Text widths are estimated (0.6 em per character of DejaVu Sans, the font the report names
first), which is all the layout needs: labels are never measured to the pixel.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from html import escape

import numpy as np

from ertools.report.chart import (
    Arrows,
    Band,
    Bars,
    Chart,
    ErrorBars,
    FloatArray,
    Layer,
    Line,
    RefLine,
    Scatter,
    Span,
    Text,
    floats,
    viridis,
)

PIXELS_PER_INCH = 110  # the reports' PNGs were 110 dpi: the same pixel size for each figure
FONT = "DejaVu Sans, Verdana, Arial, sans-serif"
TICK_PX, LABEL_PX, TITLE_PX, LEGEND_PX = 11.0, 12.0, 13.0, 11.0
CHAR_EM = 0.6
MARGIN = 0.05  # of the data's span, on each side (matplotlib's default)
_DASHES = {"solid": "", "dashed": "5,3", "dotted": "1.5,2.5"}


def text_width(text: str, px: float) -> float:
    """Estimated width of ``text`` at ``px`` pixels."""
    return len(text) * px * CHAR_EM


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
    decimals = max(0, -math.floor(math.log10(step) + 1e-9))
    if round(step / 10.0 ** math.floor(math.log10(step) + 1e-9), 6) == 2.5:
        decimals += 1
    return ticks, decimals


def tick_text(value: float, decimals: int) -> str:
    text = f"{value:.{decimals}f}" if abs(value) < 1e7 else f"{value:.6g}"
    return "0" if text.lstrip("-").strip("0.") == "" else text


@dataclass
class _Scale:
    """Data -> pixel along one axis (``flip``: y grows upwards)."""

    lo: float
    hi: float
    start: float
    length: float
    flip: bool = False

    def __call__(self, v: FloatArray) -> FloatArray:
        f = (np.asarray(v, dtype=float) - self.lo) / (self.hi - self.lo)
        return self.start + (1.0 - f if self.flip else f) * self.length

    def one(self, v: float) -> float:
        return float(self(np.asarray([v]))[0])


def _extent(layers: tuple[Layer, ...], axis: str, side: str) -> list[FloatArray]:
    """Every value ``layers`` put on ``axis`` (``"x"`` or ``"y"`` of ``side``)."""
    out: list[FloatArray] = []
    for layer in layers:
        if axis == "y" and getattr(layer, "side", "left") != side:
            continue
        match layer:
            case Line() | Scatter():
                out.append(floats(layer.x if axis == "x" else layer.y))
            case Arrows():
                out += (
                    [floats(layer.x0), floats(layer.x1)]
                    if axis == "x"
                    else [
                        floats(layer.y0),
                        floats(layer.y1),
                    ]
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


def _attr(**attrs: object) -> str:
    return "".join(
        f' {k.rstrip("_").replace("_", "-")}="{escape(str(v))}"'
        for k, v in attrs.items()
        if v is not None and v != ""
    )


def _points(px: FloatArray, py: FloatArray) -> tuple[str, int]:
    """SVG path data of a polyline broken at NaN, and its number of vertices."""
    ok = np.isfinite(px) & np.isfinite(py)
    if not ok.any():
        return "", 0
    idx = np.flatnonzero(ok)
    starts = np.ones(len(idx), dtype=bool)
    starts[1:] = np.diff(idx) > 1
    parts = []
    for i, x, y, s in zip(idx, px[idx], py[idx], starts, strict=True):
        del i
        parts.append(f"{'M' if s else 'L'}{x:.1f},{y:.1f}")
    return "".join(parts), len(idx)


def _marker(kind: str, x: float, y: float, r: float, colour: str, cls: str = "marker") -> str:
    if kind == "o":
        return f'<circle class="{cls}" cx="{x:.1f}" cy="{y:.1f}" r="{r:.1f}" fill="{colour}"/>'
    if kind == "s":
        return (
            f'<rect class="{cls}" x="{x - r:.1f}" y="{y - r:.1f}" width="{2 * r:.1f}" '
            f'height="{2 * r:.1f}" fill="{colour}"/>'
        )
    if kind == "^":
        return (
            f'<path class="{cls}" d="M{x:.1f},{y - r * 1.2:.1f}L{x + r:.1f},{y + r * 0.8:.1f}'
            f'L{x - r:.1f},{y + r * 0.8:.1f}Z" fill="{colour}"/>'
        )
    if kind == "x":
        return (
            f'<path class="{cls}" d="M{x - r:.1f},{y - r:.1f}L{x + r:.1f},{y + r:.1f}'
            f'M{x - r:.1f},{y + r:.1f}L{x + r:.1f},{y - r:.1f}" stroke="{colour}" '
            'stroke-width="1.5" fill="none"/>'
        )
    return (  # "|": a tick on the axis
        f'<path class="{cls}" d="M{x:.1f},{y - r:.1f}L{x:.1f},{y + r:.1f}" stroke="{colour}" '
        'stroke-width="1.2" fill="none"/>'
    )


def _arrow(x0: float, y0: float, x1: float, y1: float, colour: str, width: float) -> str:
    dx, dy = x1 - x0, y1 - y0
    n = math.hypot(dx, dy)
    if not (math.isfinite(n) and n > 0):
        return ""
    ux, uy = dx / n, dy / n
    head = min(7.0, n * 0.6)
    bx, by = x1 - ux * head, y1 - uy * head
    hw = head * 0.45
    return (
        f'<path class="arrow" d="M{x0:.1f},{y0:.1f}L{bx:.1f},{by:.1f}" stroke="{colour}" '
        f'stroke-width="{width}" fill="none"/>'
        f'<path class="arrow-head" d="M{x1:.1f},{y1:.1f}L{bx - uy * hw:.1f},{by + ux * hw:.1f}'
        f'L{bx + uy * hw:.1f},{by - ux * hw:.1f}Z" fill="{colour}"/>'
    )


def _layer(layer: Layer, sx: _Scale, sy: _Scale, box: tuple[float, float, float, float],
           scale: tuple[float, float] | None) -> str:  # fmt: skip
    """The SVG of one layer inside the axes ``box`` (x, y, width, height)."""
    bx, by, bw, bh = box
    out: list[str] = []
    match layer:
        case Line():
            d, n = _points(sx(floats(layer.x)), sy(floats(layer.y)))
            dash = _DASHES[layer.dash]
            out.append(
                f'<path class="line" data-points="{n}"'
                + _attr(d=d, stroke=layer.colour, stroke_width=layer.width, stroke_dasharray=dash)
                + ' fill="none" stroke-linejoin="round"/>'
            )
            if layer.marker is not None:
                px, py = sx(floats(layer.x)), sy(floats(layer.y))
                ok = np.isfinite(px) & np.isfinite(py)
                out += [
                    _marker(layer.marker, x, y, layer.marker_size, layer.colour)
                    for x, y in zip(px[ok], py[ok], strict=True)
                ]
        case Scatter():
            px, py = sx(floats(layer.x)), sy(floats(layer.y))
            ok = np.isfinite(px) & np.isfinite(py)
            if layer.values is not None and scale is not None:
                frac = (floats(layer.values) - scale[0]) / ((scale[1] - scale[0]) or 1.0)
                colours = viridis(frac)
            else:
                colours = [layer.colour] * len(px)
            out += [
                _marker(layer.marker, float(px[i]), float(py[i]), layer.size, colours[i])
                for i in np.flatnonzero(ok)
            ]
        case Arrows():
            x0, y0 = sx(floats(layer.x0)), sy(floats(layer.y0))
            x1, y1 = sx(floats(layer.x1)), sy(floats(layer.y1))
            out += [
                _arrow(float(a), float(b), float(c), float(d), layer.colour, layer.width)
                for a, b, c, d in zip(x0, y0, x1, y1, strict=True)
            ]
        case Span():
            if layer.axis == "x":
                a, b = sorted((sx.one(layer.lo), sx.one(layer.hi)))
                rect = (a, by, b - a, bh)
            else:
                a, b = sorted((sy.one(layer.lo), sy.one(layer.hi)))
                rect = (bx, a, bw, b - a)
            out.append(
                '<rect class="span"'
                + _attr(
                    x=f"{rect[0]:.1f}",
                    y=f"{rect[1]:.1f}",
                    width=f"{max(rect[2], 0.5):.1f}",
                    height=f"{max(rect[3], 0.5):.1f}",
                    fill=layer.colour,
                    fill_opacity=layer.opacity,
                )
                + "/>"
            )
        case Band():
            x, lo, hi = floats(layer.x), floats(layer.lo), floats(layer.hi)
            ok = np.isfinite(x) & np.isfinite(lo) & np.isfinite(hi)
            # one closed polygon per unbroken piece: along hi, back along lo
            pieces = np.split(
                np.flatnonzero(ok), np.flatnonzero(np.diff(np.flatnonzero(ok)) > 1) + 1
            )
            for piece in pieces:
                if len(piece) < 2:
                    continue
                px = sx(np.r_[x[piece], x[piece][::-1]])
                py = sy(np.r_[hi[piece], lo[piece][::-1]])
                d, _ = _points(px, py)
                fill = _attr(d=d + "Z", fill=layer.colour, fill_opacity=layer.opacity)
                out.append(f'<path class="band"{fill}/>')
        case ErrorBars():
            px, py = sx(floats(layer.x)), sy(floats(layer.y))
            if layer.axis == "y":
                plo, phi = sy(floats(layer.lo)), sy(floats(layer.hi))
            else:
                plo, phi = sx(floats(layer.lo)), sx(floats(layer.hi))
            c, w = layer.cap, layer.width
            for x, y, lo_, hi_ in zip(
                px.tolist(), py.tolist(), plo.tolist(), phi.tolist(), strict=True
            ):
                segs: list[str] = []
                for end in (lo_, hi_):
                    if not math.isfinite(end):
                        continue
                    if layer.axis == "y":
                        if math.isfinite(x) and math.isfinite(y):
                            segs.append(f"M{x:.1f},{y:.1f}L{x:.1f},{end:.1f}")
                        segs.append(f"M{x - c:.1f},{end:.1f}L{x + c:.1f},{end:.1f}")
                    else:
                        if math.isfinite(x) and math.isfinite(y):
                            segs.append(f"M{x:.1f},{y:.1f}L{end:.1f},{y:.1f}")
                        segs.append(f"M{end:.1f},{y - c:.1f}L{end:.1f},{y + c:.1f}")
                if segs and math.isfinite(x if layer.axis == "y" else y):
                    out.append(
                        '<path class="errorbar"'
                        + _attr(d="".join(segs), stroke=layer.colour, stroke_width=w)
                        + ' fill="none"/>'
                    )
                if layer.marker is not None and math.isfinite(x) and math.isfinite(y):
                    out.append(_marker(layer.marker, x, y, layer.marker_size, layer.colour))
        case Bars():
            bx_, h = floats(layer.x), floats(layer.height)
            left, right = sx(bx_ - layer.width / 2), sx(bx_ + layer.width / 2)
            top, base = sy(h), sy.one(0.0)
            for i in np.flatnonzero(np.isfinite(h) & np.isfinite(bx_)):
                colour = layer.colours[i % len(layer.colours)]
                ya, yb = sorted((float(top[i]), base))
                out.append(
                    '<rect class="bar"'
                    + _attr(
                        x=f"{left[i]:.1f}",
                        y=f"{ya:.1f}",
                        width=f"{right[i] - left[i]:.1f}",
                        height=f"{max(yb - ya, 0.0):.1f}",
                        fill=colour,
                    )
                    + "/>"
                )
        case RefLine():
            if layer.axis == "x":
                v = sx.one(layer.value)
                a = by + bh if layer.lo is None else sy.one(layer.lo)
                b = by if layer.hi is None else sy.one(layer.hi)
                d = f"M{v:.1f},{a:.1f}L{v:.1f},{b:.1f}"
            else:
                v = sy.one(layer.value)
                a = bx if layer.lo is None else sx.one(layer.lo)
                b = bx + bw if layer.hi is None else sx.one(layer.hi)
                d = f"M{a:.1f},{v:.1f}L{b:.1f},{v:.1f}"
            out.append(
                '<path class="refline"'
                + _attr(
                    d=d,
                    stroke=layer.colour,
                    stroke_width=layer.width,
                    stroke_dasharray=_DASHES[layer.dash],
                )
                + ' fill="none"/>'
            )
        case Text():
            tx = sx.one(layer.x) + layer.offset[0]
            ty = sy.one(layer.y) - layer.offset[1]
            if math.isfinite(tx) and math.isfinite(ty):
                lines = layer.text.split("\n")
                spans = "".join(
                    f'<tspan x="{tx:.1f}" dy="{0 if i == 0 else TICK_PX * 1.15:.1f}">'
                    f"{escape(t)}</tspan>"
                    for i, t in enumerate(lines)
                )
                ty -= (len(lines) - 1) * TICK_PX * 1.15
                out.append(
                    f'<text class="label" x="{tx:.1f}" y="{ty:.1f}"'
                    + _attr(fill=layer.colour, text_anchor=layer.anchor)
                    + f' font-size="{TICK_PX}">{spans}</text>'
                )
    label = getattr(layer, "label", None)
    return f'<g class="series"{_attr(data_label=label)}>{"".join(out)}</g>'


def _swatch(layer: Layer, x: float, y: float) -> str:
    """The legend's sample of ``layer``: 22 px wide, centred on ``y``."""
    colour = getattr(layer, "colour", None) or layer.colours[0]  # type: ignore[union-attr]
    match layer:
        case Line() | RefLine():
            dash = _DASHES[layer.dash]
            s = (
                f'<path d="M{x:.1f},{y:.1f}L{x + 22:.1f},{y:.1f}"'
                + _attr(stroke=colour, stroke_width=max(layer.width, 1.0), stroke_dasharray=dash)
                + "/>"
            )
            if isinstance(layer, Line) and layer.marker is not None:
                s += _marker(layer.marker, x + 11, y, layer.marker_size, colour, "swatch")
            return s
        case Scatter():
            c = colour if layer.values is None else viridis(np.asarray([0.6]))[0]
            return _marker(layer.marker, x + 11, y, max(layer.size, 3.0), c, "swatch")
        case Arrows():
            return _arrow(x, y, x + 22, y, colour, layer.width)
        case ErrorBars():
            s = (
                f'<path d="M{x + 11:.1f},{y - 6:.1f}L{x + 11:.1f},{y + 6:.1f}'
                f"M{x + 7:.1f},{y - 6:.1f}L{x + 15:.1f},{y - 6:.1f}"
                f'M{x + 7:.1f},{y + 6:.1f}L{x + 15:.1f},{y + 6:.1f}"'
                + _attr(stroke=colour, stroke_width=layer.width)
                + ' fill="none"/>'
            )
            if layer.marker is not None:
                s += _marker(layer.marker, x + 11, y, layer.marker_size, colour, "swatch")
            return s
        case Text():
            return ""
    opacity = getattr(layer, "opacity", 1.0)
    return (
        f'<rect x="{x:.1f}" y="{y - 5:.1f}" width="22" height="10"'
        + _attr(fill=colour, fill_opacity=opacity)
        + "/>"
    )


def render(chart: Chart, size: tuple[float, float], title: str = "", *, uid: str = "f") -> str:
    """The SVG document of ``chart`` in a ``size``-inch figure (at :data:`PIXELS_PER_INCH`),
    ``title`` above the axes; ``uid`` prefixes the ids inside (clip paths, gradients), for
    documents that hold several charts."""
    return _document(*_body(chart, size, title, uid))


def _document(body: str, width: float, height: float) -> str:
    return (
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

    xlim = _limits(_extent(layers, "x", "left"), chart.x.include_zero, MARGIN)
    ylim = _limits(_extent(layers, "y", "left"), chart.y.include_zero, chart_margin(chart))
    rlim = (
        _limits(_extent(layers, "y", "right"), chart.right.include_zero, chart_margin(chart))
        if chart.right is not None
        else None
    )
    # Horizontal budget: y tick labels and label on the left; right scale or colour bar.
    left = right = 0.0
    for _ in range(2):  # tick labels depend on the limits, the limits (aspect) on the box
        plot_h = height - top - bottom
        yt, yd = _ticks(chart.y, ylim, plot_h, 45)
        left = 10 + (LABEL_PX * 1.5 if chart.y.label else 0) + _labels_width(yt, yd, chart.y) + 6
        right = 16.0
        if chart.right is not None and rlim is not None:
            rt, rd = _ticks(chart.right, rlim, plot_h, 45)
            right = 10 + LABEL_PX * 1.5 + _labels_width(rt, rd, chart.right) + 6
        if chart.colour_scale is not None:
            cs = chart.colour_scale
            ct, cd = nice_ticks(cs.lo, cs.hi, 5)
            right = 16 + 14 + 6 + max(text_width(tick_text(v, cd), TICK_PX) for v in ct) + 10
            right += LABEL_PX * 1.5
        plot_w = width - left - right
        if chart.equal_aspect:
            xlim, ylim = _equal(xlim, ylim, plot_w, plot_h)
    box = (left, top, plot_w, plot_h)
    sx = _Scale(xlim[0], xlim[1], left, plot_w)
    sy = _Scale(ylim[0], ylim[1], top, plot_h, flip=True)
    sr = _Scale(rlim[0], rlim[1], top, plot_h, flip=True) if rlim is not None else sy

    out: list[str] = [f'<rect width="{width:.0f}" height="{height:.0f}" fill="#ffffff"/>']
    clip = f"{uid}-axes"
    out.append(
        f'<defs><clipPath id="{clip}"><rect x="{left:.1f}" y="{top:.1f}" '
        f'width="{plot_w:.1f}" height="{plot_h:.1f}"/></clipPath></defs>'
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
        out.append(_layer(layer, sx, ys, box, scale))
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
            f'font-size="{LABEL_PX}"{_attr(fill=chart.x.colour)}>{escape(chart.x.label)}</text>'
        )
    if chart.y.label:
        cx, cy = 8 + LABEL_PX, top + plot_h / 2
        out.append(
            f'<text class="ylabel" x="{cx:.1f}" y="{cy:.1f}" text-anchor="middle" '
            f'transform="rotate(-90 {cx:.1f} {cy:.1f})" font-size="{LABEL_PX}"'
            f"{_attr(fill=chart.y.colour)}>{escape(chart.y.label)}</text>"
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
            f"{_attr(fill=chart.right.colour)}>{escape(chart.right.label)}</text>"
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


def chart_margin(chart: Chart) -> float:
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
    values, decimals = nice_ticks(lim[0], lim[1], max(int(length / spacing), 2))
    return [(float(v), tick_text(float(v), decimals)) for v in values], decimals


def _labels_width(ticks: list[tuple[float, str]], decimals: int, axis: object) -> float:
    del decimals, axis
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
                f'<g class="entry"{_attr(data_label=label)}>{_swatch(layer, x, y)}'
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
    scale = _Scale(cs.lo, cs.hi if cs.hi > cs.lo else cs.lo + 1.0, top, h, flip=True)
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
