"""A figure as data: typed layers on one pair of axes, drawn by :mod:`ertools.report.svg` (the
reports' vector figures, written straight from the arrays) or by matplotlib
(:mod:`ertools.report.chart_mpl`, for a PNG or PDF a user asks for, and for notebooks).

A plot module builds a :class:`Chart` from a result and the figure's size in inches (the size
decides how far paths are thinned: :mod:`ertools.views.thinning`); it never draws.
Values are in the unit shown (mm, deg, s: :mod:`ertools.views.units`), so both renderers
print the ticks as they are. Colours are CSS colours; :data:`COLOURS` names the report's
palette (matplotlib's ``tab:`` colours, so PNG and SVG figures read the same).
"""

from __future__ import annotations

from dataclasses import field
from typing import Literal

import numpy as np
import numpy.typing as npt

from ertools.frozen_dataclass import frozen_dataclass

FloatArray = npt.NDArray[np.float64]

PIXELS_PER_INCH = 110  # the reports' PNGs were 110 dpi: the same pixel size for each figure

COLOURS = {
    "blue": "#1f77b4",
    "orange": "#ff7f0e",
    "green": "#2ca02c",
    "red": "#d62728",
    "purple": "#9467bd",
    "brown": "#8c564b",
    "pink": "#e377c2",
    "grey": "#7f7f7f",
    "olive": "#bcbd22",
    "cyan": "#17becf",
}
# One colour per series, in turn (matplotlib's default cycle: C0, C1, ...).
CYCLE = tuple(COLOURS.values())

Dash = Literal["solid", "dashed", "dotted"]
Marker = Literal["o", "s", "^", "x", "|"]
Side = Literal["left", "right"]


def floats(values: object) -> FloatArray:
    """``values`` as a 1-D float64 array (None -> NaN)."""
    array = np.asarray(values, dtype=object if _has_none(values) else float)
    if array.dtype == object:
        array = np.array([np.nan if v is None else float(v) for v in array.ravel()])
    return np.asarray(array, dtype=np.float64).ravel()


def _has_none(values: object) -> bool:
    return isinstance(values, list | tuple) and any(v is None for v in values)


@frozen_dataclass
class Line:
    """A polyline through (x, y); a NaN in either breaks it. ``marker`` draws each vertex."""

    x: FloatArray
    y: FloatArray
    colour: str = COLOURS["blue"]
    width: float = 1.0
    dash: Dash = "solid"
    label: str | None = None
    marker: Marker | None = None
    marker_size: float = 3.0
    side: Side = "left"


@frozen_dataclass
class Scatter:
    """Markers at (x, y), one colour or coloured by ``values`` on the chart's colour scale."""

    x: FloatArray
    y: FloatArray
    colour: str = COLOURS["blue"]
    values: FloatArray | None = None
    marker: Marker = "o"
    size: float = 3.0  # radius in pixels
    label: str | None = None
    side: Side = "left"


@frozen_dataclass
class Arrows:
    """Arrows from (x0, y0) to (x1, y1), in data units (a heading drawn as a short arrow)."""

    x0: FloatArray
    y0: FloatArray
    x1: FloatArray
    y1: FloatArray
    colour: str = COLOURS["blue"]
    width: float = 1.2
    label: str | None = None


@frozen_dataclass
class Span:
    """A shaded span over the whole height (``axis="x"``: lo <= x <= hi) or the whole width
    (``axis="y"``) of the axes: a gap in the data, an interval of time, a tolerance."""

    lo: float
    hi: float
    axis: Literal["x", "y"] = "x"
    colour: str = COLOURS["grey"]
    opacity: float = 0.25
    label: str | None = None
    side: Side = "left"


@frozen_dataclass
class Band:
    """A shaded band between ``lo(x)`` and ``hi(x)`` (a confidence band); NaN breaks it."""

    x: FloatArray
    lo: FloatArray
    hi: FloatArray
    colour: str = COLOURS["blue"]
    opacity: float = 0.25
    label: str | None = None
    side: Side = "left"


@frozen_dataclass
class ErrorBars:
    """A value with its interval at each point: a marker at (x, y) and a bar from ``lo`` to
    ``hi`` (absolute bounds, not offsets) along ``axis`` (``"y"``: vertical bars); a NaN bound
    draws no bar on that side, a NaN value no marker."""

    x: FloatArray
    y: FloatArray
    lo: FloatArray
    hi: FloatArray
    axis: Literal["x", "y"] = "y"
    colour: str = COLOURS["blue"]
    width: float = 1.2
    cap: float = 4.0  # half-width of the caps, in pixels
    marker: Marker | None = "o"
    marker_size: float = 3.0
    label: str | None = None
    side: Side = "left"


@frozen_dataclass
class Bars:
    """Vertical bars of ``height`` at ``x`` (``width`` in data units); NaN draws no bar."""

    x: FloatArray
    height: FloatArray
    width: float = 0.8
    colours: tuple[str, ...] = (COLOURS["blue"],)  # one, or one per bar
    label: str | None = None
    side: Side = "left"


@frozen_dataclass
class Rects:
    """Rectangles from (x0, y0) to (x1, y1) in data units: the bars of a Gantt chart, a
    state's span on its lane. ``hatch`` fills them with diagonal lines instead (a silence);
    ``edge`` outlines each one."""

    x0: FloatArray
    x1: FloatArray
    y0: FloatArray
    y1: FloatArray
    colour: str = COLOURS["blue"]
    edge: str | None = None
    hatch: bool = False
    label: str | None = None
    side: Side = "left"


@frozen_dataclass
class RefLine:
    """A line across the axes at ``value``: vertical for ``axis="x"``, horizontal for
    ``"y"``; with ``lo``/``hi`` only from ``lo`` to ``hi`` along the other axis."""

    value: float
    axis: Literal["x", "y"] = "y"
    colour: str = "#4d4d4d"
    width: float = 1.0
    dash: Dash = "dashed"
    label: str | None = None
    lo: float | None = None
    hi: float | None = None
    side: Side = "left"


@frozen_dataclass
class Text:
    """A label at a data point, moved by ``offset`` pixels (right, up)."""

    x: float
    y: float
    text: str
    colour: str = "#000000"
    offset: tuple[float, float] = (0.0, 0.0)
    anchor: Literal["start", "middle", "end"] = "start"
    side: Side = "left"


Layer = Line | Scatter | Arrows | Span | Band | ErrorBars | Bars | Rects | RefLine | Text


@frozen_dataclass
class Axis:
    """One axis: its label (with its unit), explicit ticks if any (position, text), and the
    colour of its label (an axis that belongs to one series on a two-scale chart)."""

    label: str = ""
    ticks: tuple[tuple[float, str], ...] | None = None
    colour: str = "#000000"
    include_zero: bool = False  # bars and counts start at zero
    limits: tuple[float, float] | None = None  # fixed, instead of the data's with margins
    symlog: float | None = None  # linear within +-symlog of 0, logarithmic beyond


@frozen_dataclass
class ColourScale:
    """The scale :class:`Scatter` ``values`` are coloured on (viridis), drawn as a bar."""

    label: str
    lo: float
    hi: float


@frozen_dataclass
class Chart:
    """Everything one figure shows, in drawing order."""

    layers: tuple[Layer, ...]
    x: Axis = field(default_factory=Axis)
    y: Axis = field(default_factory=Axis)
    right: Axis | None = None  # a second y scale for layers with ``side="right"``
    equal_aspect: bool = False  # one unit is as long on both axes (maps, paths)
    grid: Literal["both", "x", "y", "none"] = "both"
    legend: bool = True
    colour_scale: ColourScale | None = None
    note: str | None = None  # shown in the middle of empty axes ("no data")


# viridis, 9 stops (matplotlib's table at 0, 1/8, ..., 1), interpolated linearly between them.
VIRIDIS = (
    (0.267004, 0.004874, 0.329415),
    (0.278826, 0.175490, 0.483397),
    (0.229739, 0.322361, 0.545706),
    (0.172719, 0.448791, 0.557885),
    (0.127568, 0.566949, 0.550556),
    (0.157851, 0.683765, 0.501686),
    (0.369214, 0.788888, 0.382914),
    (0.678489, 0.863742, 0.189503),
    (0.993248, 0.906157, 0.143936),
)
_VIRIDIS = np.asarray(VIRIDIS)


def viridis(fraction: FloatArray) -> list[str]:
    """CSS colours of ``fraction`` (0..1, clipped; NaN -> grey) on viridis."""
    raw = np.asarray(fraction, dtype=float).ravel()
    f = np.clip(np.nan_to_num(raw, nan=0.0), 0.0, 1.0)
    pos = f * (len(_VIRIDIS) - 1)
    i = np.minimum(pos.astype(np.int64), len(_VIRIDIS) - 2)
    w = (pos - i)[:, None]
    rgb = np.rint(((1 - w) * _VIRIDIS[i] + w * _VIRIDIS[i + 1]) * 255).astype(np.int64)
    out = [f"#{r:02x}{g:02x}{b:02x}" for r, g, b in rgb]
    for j in np.flatnonzero(~np.isfinite(raw)):
        out[j] = "#999999"
    return out
