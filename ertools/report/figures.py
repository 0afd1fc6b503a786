"""Figures as data: a benchmark says what to draw, this module decides where it goes.

A figure is either a :class:`~ertools.views.chart.Chart` built from the result (written as
SVG by :mod:`ertools.report.svg`, without matplotlib: the reports' figures) or, for the
figures not converted yet, a function drawing on a matplotlib ``Axes``. A chart is drawn by
matplotlib too when a user asks for a PNG or PDF (``--plot fig.png``). Nothing here selects a
backend or uses pyplot, so importing ertools never changes matplotlib's global state.
"""

from __future__ import annotations

import textwrap
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from importlib import import_module
from pathlib import Path
from typing import Any

import numpy as np

from ertools.atomic import replacing, write_text
from ertools.benchmarks import registry
from ertools.report import chart_mpl, svg
from ertools.views.chart import Chart

# Results that are not a registered benchmark's -> ``module:function`` giving their figures
# (a benchmark names its own: :attr:`ertools.benchmarks.base.Benchmark.figures`).
OTHER_FIGURES: dict[str, str] = {"noise": "ertools.report.plots_noise:figure_specs"}


@dataclass(frozen=True)
class FigureSpec:
    """One figure: a file stem, a title, a size and a function drawing on one Axes; for a
    figure built as a :class:`Chart`, ``chart`` builds it for a size in inches (``draw`` then
    draws that chart: :func:`chart_spec`)."""

    name: str
    title: str
    draw: Callable[[Any], None]
    size: tuple[float, float] = (7.0, 5.0)
    chart: Callable[[tuple[float, float]], Chart] | None = None


def chart_spec(
    name: str,
    title: str,
    build: Callable[[tuple[float, float]], Chart],
    size: tuple[float, float] = (7.0, 5.0),
) -> FigureSpec:
    """A figure given as a :class:`Chart` (built for the figure's size in inches, which
    decides how far its paths are thinned)."""
    return FigureSpec(
        name, title, lambda ax: chart_mpl.draw(build(size_of(ax)), ax), size, chart=build
    )


def figure_specs(result: Any) -> list[FigureSpec]:
    """The figures of a result, from the function its benchmark declares."""
    name = str(result.name)
    target = registry.get(name).figures if name in registry.names() else OTHER_FIGURES.get(name)
    if not target:
        return []
    module_name, _, function = target.partition(":")
    specs: list[FigureSpec] = getattr(import_module(module_name), function)(result)
    return specs


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


DPI = svg.PIXELS_PER_INCH  # the pixels a figure has: what paths are thinned to
# zlib level of the PNGs: 6 (matplotlib's) spends ~4x the time of 1 for files ~15 % smaller
# on these flat-coloured plots (measured in docs/performance.md).
PNG_COMPRESS_LEVEL = 3
_local = threading.local()


def _canvas_figure(size: tuple[float, float]) -> Any:
    """This thread's figure of ``size`` inches, cleared, with its Agg canvas (created on first
    use; never pyplot, so no global state and no GUI backend)."""
    # lazy: matplotlib only when a figure is drawn (~0.3 s to import)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

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
    that each of them inherits it. The reports' figures are SVG charts
    (no matplotlib since issue 29); one tiny chart is rendered so that the writer's code
    paths ran once before the fork."""
    svg.render(Chart((), note="0"), (1.0, 1.0), "0")


def _write_png(fig: Any, path: Path) -> None:
    # lazy: matplotlib only when a figure is drawn (~0.3 s to import)
    from matplotlib.image import imsave

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
    from matplotlib.figure import Figure  # lazy: matplotlib only when a figure is drawn

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
    """The size in inches of the figure ``ax`` is drawn in (what :func:`thin_path` and
    :func:`thin_series` thin to)."""
    width, height = ax.figure.get_size_inches()
    return float(width), float(height)


def thin_path(xy: Any, size: tuple[float, float], *, cells_per_pixel: float = 2.0) -> Any:
    """The vertices of the polyline ``xy`` (N x 2 or more columns) that change the cell of a
    grid finer than the figure's pixels: what the figure can show of it.

    A point is kept when its cell (``cells_per_pixel`` per pixel of a ``size``-inch figure,
    over the data's own span) differs from the previous point's, so every cell the line
    passes through is still visited in the same order; the first and last points, the lowest
    and highest of each axis and both ends of a break (NaN) stay, so the axes' limits are the
    same and the line drawn from the kept points lies within a cell of the full one. A robot
    driving slowly keeps one sample in several; noise that flips a standing robot between
    two cells keeps its flips (the full line draws them too). Extra columns (a heading)
    follow their point.
    """
    xy = np.asarray(xy)
    if len(xy) < 3:
        return xy
    pts = xy[:, :2].astype(float, copy=False)
    finite = np.isfinite(pts).all(axis=1)
    if not finite.any():
        return xy
    lo = np.min(pts[finite], axis=0)
    span = np.max(pts[finite], axis=0) - lo
    cells = np.asarray(size, dtype=float) * DPI * cells_per_pixel
    step = np.where(span > 0, span / cells, 1.0)
    with np.errstate(invalid="ignore"):
        cell = np.floor((pts - lo) / step)
    changed = np.ones(len(pts), dtype=bool)
    changed[1:] = (cell[1:] != cell[:-1]).any(axis=1)  # NaN (a break in the line) is kept
    changed[:-1] |= ~finite[1:]  # and so is the point that ends the piece before it
    changed[-1] = True
    for column in (0, 1):  # the extremes exactly, not within a cell: the axes' limits
        changed[np.nanargmin(pts[:, column])] = changed[np.nanargmax(pts[:, column])] = True
    return xy[changed]


def thin_series(t: Any, y: Any, width: float, *, columns_per_pixel: float = 1.0) -> Any:
    """Indices of the samples of the series ``y(t)`` (``t`` ascending) that draw it in a
    ``width``-inch axis: per pixel column its first, last, lowest and highest sample, in
    time order (min/max decimation: every spike and the envelope stay as drawn in full)."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    n = len(t)
    columns = max(int(width * DPI * columns_per_pixel), 1)
    if n <= 4 * columns:
        return np.arange(n)
    span = t[-1] - t[0]
    if span <= 0:
        return np.arange(n)
    col = np.minimum(((t - t[0]) / span * columns).astype(np.int64), columns - 1)
    starts = np.flatnonzero(np.r_[True, col[1:] != col[:-1]])
    ends = np.r_[starts[1:], n] - 1
    finite = np.isfinite(y)
    which = np.repeat(np.arange(len(starts)), np.diff(np.r_[starts, n]))
    # the first lowest and first highest sample of each column: a stable sort by (column,
    # value) puts them first in their column
    by_low = np.lexsort((np.where(finite, y, np.inf), which))
    by_high = np.lexsort((np.where(finite, -y, np.inf), which))
    breaks = np.flatnonzero(~finite)  # gaps in the line stay where they are, with their ends
    around = np.clip(np.concatenate([breaks - 1, breaks, breaks + 1]), 0, n - 1)
    keep = np.unique(np.concatenate([starts, ends, by_low[starts], by_high[starts], around]))
    return keep
