"""A path or a series thinned to what a figure of a given size can show: what a plot module
draws of an hour-long log (docs/reports.md, "How the figures are drawn")."""

from __future__ import annotations

from typing import Any

import numpy as np

from ertools.views.chart import PIXELS_PER_INCH


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
    cells = np.asarray(size, dtype=float) * PIXELS_PER_INCH * cells_per_pixel
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
    columns = max(int(width * PIXELS_PER_INCH * columns_per_pixel), 1)
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
