"""The marks of an SVG chart: one :class:`~ertools.views.chart.Chart` layer as SVG elements
in pixel coordinates, and its sample in the legend (:mod:`ertools.report.svg` lays out the axes
around them). Each layer is one ``<g class="series">`` whose ``data-label`` is its legend text.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from html import escape

import numpy as np

from ertools.views.chart import (
    Arrows,
    Band,
    Bars,
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

TICK_PX = 11.0  # text beside marks: as large as the tick labels
DASHES = {"solid": "", "dashed": "5,3", "dotted": "1.5,2.5"}


@dataclass
class Scale:
    """Data -> pixel along one axis (``flip``: y grows upwards; ``symlog``: linear within
    +-symlog of zero, logarithmic beyond, as matplotlib's ``symlog`` scale)."""

    lo: float
    hi: float
    start: float
    length: float
    flip: bool = False
    symlog: float | None = None

    def _t(self, v: FloatArray) -> FloatArray:
        if self.symlog is None:
            return v
        out: FloatArray = np.sign(v) * np.log10(1.0 + np.abs(v) / self.symlog)
        return out

    def __call__(self, v: FloatArray) -> FloatArray:
        ends = self._t(np.array([self.lo, self.hi], dtype=np.float64))
        lo, hi = float(ends[0]), float(ends[1])
        f = (self._t(np.asarray(v, dtype=np.float64)) - lo) / (hi - lo)
        out: FloatArray = self.start + (1.0 - f if self.flip else f) * self.length
        return out

    def one(self, v: float) -> float:
        return float(self(np.asarray([v]))[0])


def attr(**attrs: object) -> str:
    return "".join(
        f' {k.rstrip("_").replace("_", "-")}="{escape(str(v))}"'
        for k, v in attrs.items()
        if v is not None and v != ""
    )


def points(px: FloatArray, py: FloatArray) -> tuple[str, int]:
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


def marker(kind: str, x: float, y: float, r: float, colour: str, cls: str = "marker") -> str:
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


def arrow(x0: float, y0: float, x1: float, y1: float, colour: str, width: float) -> str:
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


def layer_svg(
    layer: Layer,
    sx: Scale,
    sy: Scale,
    box: tuple[float, float, float, float],
    scale: tuple[float, float] | None,
    uid: str,
) -> str:
    """The SVG of one layer inside the axes ``box`` (x, y, width, height); ``scale``: the
    colour scale's range; ``uid``: the document's id prefix (its hatch pattern)."""
    bx, by, bw, bh = box
    out: list[str] = []
    match layer:
        case Line():
            d, n = points(sx(floats(layer.x)), sy(floats(layer.y)))
            dash = DASHES[layer.dash]
            out.append(
                f'<path class="line" data-points="{n}"'
                + attr(d=d, stroke=layer.colour, stroke_width=layer.width, stroke_dasharray=dash)
                + ' fill="none" stroke-linejoin="round"/>'
            )
            if layer.marker is not None:
                px, py = sx(floats(layer.x)), sy(floats(layer.y))
                ok = np.isfinite(px) & np.isfinite(py)
                out += [
                    marker(layer.marker, x, y, layer.marker_size, layer.colour)
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
                marker(layer.marker, float(px[i]), float(py[i]), layer.size, colours[i])
                for i in np.flatnonzero(ok)
            ]
        case Arrows():
            x0, y0 = sx(floats(layer.x0)), sy(floats(layer.y0))
            x1, y1 = sx(floats(layer.x1)), sy(floats(layer.y1))
            out += [
                arrow(float(a), float(b), float(c), float(d), layer.colour, layer.width)
                for a, b, c, d in zip(x0, y0, x1, y1, strict=True)
            ]
        case Span():
            scale_, (edge, size) = (sx, (bx, bw)) if layer.axis == "x" else (sy, (by, bh))
            ends = [scale_.one(layer.lo), scale_.one(layer.hi)]
            if any(math.isnan(e) for e in ends):  # no span; an infinite end: the axes' edge
                return '<g class="series"></g>'
            a, b = sorted(min(max(e, edge - 1.0), edge + size + 1.0) for e in ends)
            rect = (a, by, b - a, bh) if layer.axis == "x" else (bx, a, bw, b - a)
            out.append(
                '<rect class="span"'
                + attr(
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
                d, _ = points(px, py)
                fill = attr(d=d + "Z", fill=layer.colour, fill_opacity=layer.opacity)
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
                        + attr(d="".join(segs), stroke=layer.colour, stroke_width=w)
                        + ' fill="none"/>'
                    )
                if layer.marker is not None and math.isfinite(x) and math.isfinite(y):
                    out.append(marker(layer.marker, x, y, layer.marker_size, layer.colour))
        case Bars():
            bx_, h = floats(layer.x), floats(layer.height)
            left, right = sx(bx_ - layer.width / 2), sx(bx_ + layer.width / 2)
            top, base = sy(h), sy.one(0.0)
            for i in np.flatnonzero(np.isfinite(h) & np.isfinite(bx_)):
                colour = layer.colours[i % len(layer.colours)]
                ya, yb = sorted((float(top[i]), base))
                out.append(
                    '<rect class="bar"'
                    + attr(
                        x=f"{left[i]:.1f}",
                        y=f"{ya:.1f}",
                        width=f"{right[i] - left[i]:.1f}",
                        height=f"{max(yb - ya, 0.0):.1f}",
                        fill=colour,
                    )
                    + "/>"
                )
        case Rects():
            x0, x1 = sx(floats(layer.x0)), sx(floats(layer.x1))
            y0, y1 = sy(floats(layer.y0)), sy(floats(layer.y1))
            left, right = np.minimum(x0, x1), np.maximum(x0, x1)
            top, bottom = np.minimum(y0, y1), np.maximum(y0, y1)
            fill = f"url(#{uid}-hatch)" if layer.hatch else layer.colour
            style = attr(fill=fill, stroke=layer.edge, stroke_width=0.5 if layer.edge else None)
            out.append(f"<g{style}>")
            for a, b, c, d in zip(
                left.tolist(), top.tolist(), right.tolist(), bottom.tolist(), strict=True
            ):
                if math.isfinite(a + b + c + d):
                    w = max(c - a, 0.5)  # a state a few ms long is still seen
                    out.append(
                        f'<rect class="rect" x="{a:.1f}" y="{b:.1f}" width="{w:.1f}" '
                        f'height="{d - b:.1f}"/>'
                    )
            out.append("</g>")
        case RefLine():
            if layer.axis == "x":
                v = sx.one(layer.value)
                a = by + bh if layer.lo is None else sy.one(layer.lo)
                b = by if layer.hi is None else sy.one(layer.hi)
            else:
                v = sy.one(layer.value)
                a = bx if layer.lo is None else sx.one(layer.lo)
                b = bx + bw if layer.hi is None else sx.one(layer.hi)
            if not all(math.isfinite(n) for n in (v, a, b)):
                return '<g class="series"></g>'  # a line at no finite value: nothing to draw
            d = (
                f"M{v:.1f},{a:.1f}L{v:.1f},{b:.1f}"
                if layer.axis == "x"
                else f"M{a:.1f},{v:.1f}L{b:.1f},{v:.1f}"
            )
            out.append(
                '<path class="refline"'
                + attr(
                    d=d,
                    stroke=layer.colour,
                    stroke_width=layer.width,
                    stroke_dasharray=DASHES[layer.dash],
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
                    + attr(fill=layer.colour, text_anchor=layer.anchor)
                    + f' font-size="{TICK_PX}">{spans}</text>'
                )
    label = getattr(layer, "label", None)
    return f'<g class="series"{attr(data_label=label)}>{"".join(out)}</g>'


def swatch(layer: Layer, x: float, y: float) -> str:
    """The legend's sample of ``layer``: 22 px wide, centred on ``y``."""
    colour = getattr(layer, "colour", None) or layer.colours[0]  # type: ignore[union-attr]
    match layer:
        case Line() | RefLine():
            dash = DASHES[layer.dash]
            s = (
                f'<path d="M{x:.1f},{y:.1f}L{x + 22:.1f},{y:.1f}"'
                + attr(stroke=colour, stroke_width=max(layer.width, 1.0), stroke_dasharray=dash)
                + "/>"
            )
            if isinstance(layer, Line) and layer.marker is not None:
                s += marker(layer.marker, x + 11, y, layer.marker_size, colour, "swatch")
            return s
        case Scatter():
            c = colour if layer.values is None else viridis(np.asarray([0.6]))[0]
            return marker(layer.marker, x + 11, y, max(layer.size, 3.0), c, "swatch")
        case Arrows():
            return arrow(x, y, x + 22, y, colour, layer.width)
        case ErrorBars():
            s = (
                f'<path d="M{x + 11:.1f},{y - 6:.1f}L{x + 11:.1f},{y + 6:.1f}'
                f"M{x + 7:.1f},{y - 6:.1f}L{x + 15:.1f},{y - 6:.1f}"
                f'M{x + 7:.1f},{y + 6:.1f}L{x + 15:.1f},{y + 6:.1f}"'
                + attr(stroke=colour, stroke_width=layer.width)
                + ' fill="none"/>'
            )
            if layer.marker is not None:
                s += marker(layer.marker, x + 11, y, layer.marker_size, colour, "swatch")
            return s
        case Text():
            return ""
    if isinstance(layer, Rects) and layer.hatch:
        return (
            f'<rect x="{x:.1f}" y="{y - 5:.1f}" width="22" height="10" fill="none"'
            + attr(stroke=layer.edge or colour, stroke_dasharray="2,2")
            + "/>"
        )
    opacity = getattr(layer, "opacity", 1.0)
    return (
        f'<rect x="{x:.1f}" y="{y - 5:.1f}" width="22" height="10"'
        + attr(fill=colour, fill_opacity=opacity)
        + "/>"
    )
