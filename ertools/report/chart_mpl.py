"""A :class:`~ertools.views.chart.Chart` drawn on a matplotlib ``Axes``: for the PNG and PDF
files a user asks for (``--plot fig.png``), and for notebooks (:func:`ertools.api.figures`).
The reports' own figures are SVG written by :mod:`ertools.report.svg`; both show the same
layers, labels and legend."""

from __future__ import annotations

from typing import Any

import numpy as np

from ertools.views.chart import (
    Arrows,
    Band,
    Bars,
    Chart,
    ErrorBars,
    Layer,
    Line,
    Rects,
    RefLine,
    Scatter,
    Span,
    Text,
    floats,
)

_LS = {"solid": "-", "dashed": "--", "dotted": ":"}


def draw(chart: Chart, ax: Any) -> None:
    """Draw every layer of ``chart`` on ``ax`` (and a twin axes for its right scale)."""
    right = ax.twinx() if chart.right is not None else None
    mappable = None
    for layer in chart.layers:
        target = right if right is not None and getattr(layer, "side", "left") == "right" else ax
        mappable = _layer(target, layer, chart) or mappable
    if mappable is not None and chart.colour_scale is not None:
        ax.figure.colorbar(mappable, ax=ax, label=chart.colour_scale.label, shrink=0.8)
    ax.set_xlabel(chart.x.label, color=chart.x.colour)
    ax.set_ylabel(chart.y.label, color=chart.y.colour)
    for axis, spec in ((ax.xaxis, chart.x), (ax.yaxis, chart.y)):
        if spec.ticks is not None:
            axis.set_ticks([v for v, _ in spec.ticks], [t for _, t in spec.ticks])
    if chart.y.symlog is not None:
        ax.set_yscale("symlog", linthresh=chart.y.symlog)
    if chart.x.limits is not None:
        ax.set_xlim(*chart.x.limits)
    if chart.y.limits is not None:
        ax.set_ylim(*chart.y.limits)
    if right is not None and chart.right is not None:
        right.set_ylabel(chart.right.label, color=chart.right.colour)
    if chart.equal_aspect:
        ax.set_aspect("equal", adjustable="datalim")
    if chart.grid != "none":
        ax.grid(True, axis=chart.grid, lw=0.3)
    if chart.note:
        ax.text(0.5, 0.5, chart.note, ha="center", va="center", transform=ax.transAxes)
    if chart.legend:
        handles, labels = ax.get_legend_handles_labels()
        if right is not None:
            more = right.get_legend_handles_labels()
            handles, labels = handles + more[0], labels + more[1]
        # in the chart's order, as the SVG lists them (matplotlib groups them by kind)
        order = [getattr(layer, "label", None) for layer in chart.layers]
        pairs = sorted(zip(handles, labels, strict=True), key=lambda p: order.index(p[1]))
        if pairs:
            ax.legend(*zip(*pairs, strict=True), loc="best", fontsize="small")


def _layer(ax: Any, layer: Layer, chart: Chart) -> Any:
    label = getattr(layer, "label", None)
    match layer:
        case Line():
            ax.plot(
                floats(layer.x),
                floats(layer.y),
                color=layer.colour,
                lw=layer.width,
                ls=_LS[layer.dash],
                marker=layer.marker,
                ms=layer.marker_size * 1.5,
                label=label,
            )
        case Scatter():
            size = (layer.size * 1.4) ** 2
            if layer.values is not None and chart.colour_scale is not None:
                cs = chart.colour_scale
                return ax.scatter(
                    floats(layer.x),
                    floats(layer.y),
                    c=floats(layer.values),
                    cmap="viridis",
                    vmin=cs.lo,
                    vmax=cs.hi,
                    marker=layer.marker,
                    s=size,
                    zorder=3,
                    label=label,
                )
            ax.scatter(
                floats(layer.x),
                floats(layer.y),
                color=layer.colour,
                marker=layer.marker,
                s=size,
                zorder=3,
                label=label,
            )
        case Arrows():
            x0, y0 = floats(layer.x0), floats(layer.y0)
            ax.quiver(
                x0,
                y0,
                floats(layer.x1) - x0,
                floats(layer.y1) - y0,
                color=layer.colour,
                angles="xy",
                scale_units="xy",
                scale=1.0,
                width=0.005,
                zorder=3,
                label=label,
            )
        case Span():
            span = ax.axvspan if layer.axis == "x" else ax.axhspan
            span(layer.lo, layer.hi, color=layer.colour, alpha=layer.opacity, lw=0, label=label)
        case Band():
            ax.fill_between(
                floats(layer.x),
                floats(layer.lo),
                floats(layer.hi),
                color=layer.colour,
                alpha=layer.opacity,
                lw=0,
                label=label,
            )
        case ErrorBars():
            y, lo, hi = floats(layer.y), floats(layer.lo), floats(layer.hi)
            value = y if layer.axis == "y" else floats(layer.x)
            err = np.vstack([value - lo, hi - value])
            ax.errorbar(
                floats(layer.x),
                y,
                yerr=err if layer.axis == "y" else None,
                xerr=err if layer.axis == "x" else None,
                fmt=layer.marker or "none",
                color=layer.colour,
                elinewidth=layer.width,
                capsize=layer.cap,
                ms=layer.marker_size * 1.5,
                label=label,
            )
        case Bars():
            x = floats(layer.x)
            ax.bar(
                x,
                np.nan_to_num(floats(layer.height)),
                width=layer.width,
                color=[layer.colours[i % len(layer.colours)] for i in range(len(x))],
                label=label,
            )
        case Rects():
            x0, y0 = floats(layer.x0), floats(layer.y0)
            ax.bar(
                x0,
                floats(layer.y1) - y0,
                width=floats(layer.x1) - x0,
                bottom=y0,
                align="edge",
                color="none" if layer.hatch else layer.colour,
                edgecolor=layer.edge or ("#444444" if layer.hatch else "none"),
                hatch="///" if layer.hatch else None,
                linewidth=0.4,
                label=label,
            )
        case RefLine():
            style = {
                "color": layer.colour,
                "lw": layer.width,
                "ls": _LS[layer.dash],
                "label": label,
            }
            if layer.axis == "x":
                if layer.lo is None or layer.hi is None:
                    ax.axvline(layer.value, **style)
                else:
                    ax.vlines(layer.value, layer.lo, layer.hi, **style)
            elif layer.lo is None or layer.hi is None:
                ax.axhline(layer.value, **style)
            else:
                ax.hlines(layer.value, layer.lo, layer.hi, **style)
        case Text():
            ax.annotate(
                layer.text,
                (layer.x, layer.y),
                textcoords="offset points",
                xytext=layer.offset,
                ha={"start": "left", "middle": "center", "end": "right"}[layer.anchor],
                va="bottom",
                color=layer.colour,
                fontsize="small",
            )
    return None
