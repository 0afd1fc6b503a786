"""A benchmark's figures drawn: it says what to draw (:class:`~ertools.views.spec.ChartSpec`,
a :class:`~ertools.views.chart.Chart` built for a size), this module decides where it goes.

A chart is written as SVG by :mod:`ertools.report.svg`, without matplotlib (the reports'
figures), or drawn by matplotlib when a user asks for a PNG or PDF (``--plot fig.png``). Nothing
here selects a backend or uses pyplot, so importing ertools never changes matplotlib's global
state.
"""

from __future__ import annotations

import textwrap
import threading
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ertools.atomic import replacing, write_text
from ertools.benchmarks import registry
from ertools.benchmarks.base import Reported
from ertools.frozen_dataclass import frozen_dataclass
from ertools.report import chart_mpl, svg
from ertools.views.chart import PIXELS_PER_INCH, Chart
from ertools.views.spec import ChartSpec


@frozen_dataclass
class FigureSpec:
    """One figure: a file stem, a title, a size and a function drawing on one Axes; for a
    figure built as a :class:`Chart`, ``chart`` builds it for a size in inches (``draw`` then
    draws that chart: :func:`drawable`)."""

    name: str
    title: str
    draw: Callable[[Any], None]
    size: tuple[float, float] = (7.0, 5.0)
    chart: Callable[[tuple[float, float]], Chart] | None = None


def drawable(spec: ChartSpec) -> FigureSpec:
    """The figure of a :class:`ChartSpec`: its chart as SVG, or drawn by matplotlib on an Axes
    (built for the size of the Axes' figure)."""
    return FigureSpec(
        spec.name,
        spec.title,
        lambda ax: chart_mpl.draw(spec.build(size_of(ax)), ax),
        spec.size,
        chart=spec.build,
    )


def figure_specs(result: Any) -> list[FigureSpec]:
    """The figures of a result, from the charts its benchmark declares."""
    name = str(result.name)
    specs: Sequence[ChartSpec] = []
    bench = registry.get(name) if name in registry.names() else None
    if isinstance(bench, Reported):
        specs = bench.figures(result)
    return [drawable(spec) for spec in specs]


def save_figures(specs: Sequence[FigureSpec], outdir: Path, fmt: str | None = "png") -> list[Path]:
    """Draw every spec into its own file in ``outdir``; returns the paths written.

    ``fmt=None``: SVG for a chart (no matplotlib), PNG for a figure drawn on an Axes: what
    report folders write."""
    outdir.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    for spec in specs:
        suffix = fmt or ("svg" if spec.chart is not None else "png")
        path = outdir / f"{spec.name}.{suffix}"
        with replacing(path) as tmp:  # a kill leaves the old figure or none, never half
            render(spec, tmp)
        written.append(path)
    return written


def render(spec: FigureSpec, path: Path) -> None:
    """Draw one spec into ``path`` (its suffix picks the format), as ``savefig(dpi=110)`` with
    the constrained layout would, at about half the cost for a PNG (docs/performance.md,
    "Report figures"): the figure is laid out and drawn once instead of twice, on a figure
    and Agg canvas kept per size and thread, so that the text metrics matplotlib caches per
    renderer (every tick label, legend entry and title) carry over from one figure to the
    next. A chart asked for as ``.svg`` is written by :mod:`ertools.report.svg` instead."""
    if spec.chart is not None and path.suffix.lower() == ".svg":
        path.write_text(svg.render(spec.chart(spec.size), spec.size, spec.title), "utf-8")
        return
    fig = _canvas_figure(spec.size)
    try:
        ax = fig.add_subplot()
        spec.draw(ax)
        if spec.title:
            ax.set_title(wrap_title(spec.title, spec.size[0]))
        if path.suffix.lower() == ".png":
            _write_png(fig, path)
        else:  # vector formats lay out for their own renderer: matplotlib's own path
            fig.savefig(path, dpi=DPI)
    finally:
        fig.clear()


DPI = PIXELS_PER_INCH  # the pixels a figure has: what paths are thinned to
# zlib level of the PNGs: 6 (matplotlib's) spends ~4x the time of 1 for files ~15 % smaller
# on these flat-coloured plots (measured in docs/performance.md).
PNG_COMPRESS_LEVEL = 3
_local = threading.local()


def _canvas_figure(size: tuple[float, float]) -> Any:
    """This thread's figure of ``size`` inches, cleared, with its Agg canvas (created on first
    use; never pyplot, so no global state and no GUI backend)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # lazy: matplotlib, 300 ms
    from matplotlib.figure import Figure  # lazy: matplotlib, 300 ms

    figures: dict[tuple[float, float], Any] = getattr(_local, "figures", None) or {}
    _local.figures = figures
    fig = figures.get(size)
    if fig is None:
        fig = Figure(figsize=size, dpi=DPI, layout="constrained")
        FigureCanvasAgg(fig)
        figures[size] = fig
    return fig


def preload() -> None:
    """Import what writing a report's figures needs, without writing anything: for a process
    that forks the scoring processes (the fork server, :mod:`ertools.competition.children`), so
    that each of them inherits it. The reports' figures are SVG charts (no matplotlib); one
    tiny chart is rendered so that the writer's code paths ran once before the fork."""
    svg.render(Chart((), note="0"), (1.0, 1.0), "0")


def _write_png(fig: Any, path: Path) -> None:
    from matplotlib.image import imsave  # lazy: matplotlib, 300 ms

    canvas = fig.canvas
    canvas.draw()  # runs the constrained layout, then renders: one pass
    imsave(
        path,
        np.asarray(canvas.buffer_rgba()),
        format="png",
        dpi=DPI,
        pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL},
    )


def wrap_title(title: str, width_in: float) -> str:
    """``title`` broken into lines that fit a ``width_in``-inch figure, as the SVG writer
    breaks its titles (an unscoreable run's reason is longer than a figure is wide): about 10
    characters per inch at matplotlib's title size and :data:`DPI`."""
    return textwrap.fill(title, max(20, int(width_in * 10))) if title else title


def save_one_file(specs: Sequence[Any], path: Path) -> Path:
    """Every spec as one panel of one figure, stacked top to bottom, in ``path`` (its suffix
    picks the format; an SVG of charts only is written without matplotlib)."""
    if specs and path.suffix.lower() == ".svg" and all(s.chart is not None for s in specs):
        panels = [(s.chart(s.size), s.size, s.title) for s in specs]
        path.parent.mkdir(parents=True, exist_ok=True)
        write_text(path, svg.stack(panels))
        return path
    from matplotlib.figure import Figure  # lazy: matplotlib, 300 ms

    width = max((s.size[0] for s in specs), default=6.0)
    height = sum(s.size[1] for s in specs) or 4.0
    fig = Figure(figsize=(width, height), layout="constrained")
    axes = fig.subplots(max(len(specs), 1), 1, squeeze=False)[:, 0]
    for spec, ax in zip(specs, axes, strict=False):
        spec.draw(ax)
        if spec.title:
            ax.set_title(wrap_title(spec.title, width))
    if not specs:
        axes[0].text(0.5, 0.5, "no figure for this result", ha="center", va="center")
        axes[0].set_axis_off()
    path.parent.mkdir(parents=True, exist_ok=True)
    with replacing(path) as tmp:
        fig.savefig(tmp, dpi=110)
    return path


def size_of(ax: Any) -> tuple[float, float]:
    """The size in inches of the figure ``ax`` is drawn in (what a chart is built for)."""
    width, height = ax.figure.get_size_inches()
    return float(width), float(height)
