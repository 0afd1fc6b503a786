"""The SVG writer of the reports' figures: charts built by hand, read back from the SVG text
through the scale its own tick labels state (tests/helpers/svg_figure.py), never through the
writer."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from matplotlib.figure import Figure

from ertools.report import chart_mpl, svg
from ertools.views.chart import (
    Arrows,
    Axis,
    Band,
    Bars,
    Chart,
    ColourScale,
    ErrorBars,
    Line,
    Rects,
    RefLine,
    Scatter,
    Span,
    Text,
    viridis,
)
from tests.helpers import svg_figure

NS = svg_figure.NS


def _nums(*values: float) -> np.ndarray:
    return np.array(values, dtype=float)


def test_ticks_are_round_numbers_covering_the_range() -> None:
    ticks, decimals = svg.nice_ticks(0.0, 1.0, 5)
    assert np.allclose(ticks, [0.0, 0.2, 0.4, 0.6, 0.8, 1.0]) and decimals == 1
    ticks, decimals = svg.nice_ticks(-12.0, 1234.0, 5)
    assert np.allclose(ticks, [0, 250, 500, 750, 1000, 1250][:5]) and decimals == 0
    ticks, decimals = svg.nice_ticks(0.0, 0.01, 4)
    assert np.allclose(ticks, [0.0, 0.0025, 0.005, 0.0075, 0.01]) and decimals == 4
    assert [svg.tick_text(v, 1) for v in (-0.0, 0.25, -1.5)] == ["0", "0.2", "-1.5"]


def test_line_is_read_back_in_data_units_with_its_breaks() -> None:
    x = _nums(0, 1, 2, 3, np.nan, 5, 6)
    y = _nums(0, 10, 5, 7, 3, -2, 4)
    chart = Chart((Line(x, y, label="speed"),), x=Axis("t (s)"), y=Axis("v (mm)"))
    fig = svg_figure.read(svg.render(chart, (6.0, 4.0), "A title"))
    assert fig.texts("title") == ["A title"]
    assert fig.texts("xlabel") == ["t (s)"] and fig.texts("ylabel") == ["v (mm)"]
    line, count = fig.polyline("speed")
    assert count == 6  # the NaN vertex is a break, not a point
    assert np.isnan(line[4]).all()  # ...between two pieces
    ax, _ = fig.scale("x")
    keep = np.isfinite(x)
    assert np.allclose(line[~np.isnan(line[:, 0])], np.column_stack([x, y])[keep], atol=abs(ax))


def test_error_bars_span_their_bounds_and_skip_missing_ones() -> None:
    bars = ErrorBars(
        _nums(1, 2, 3), _nums(5, 6, 7), _nums(4, 5.5, np.nan), _nums(6.5, 8, 9), label="score"
    )
    chart = Chart((bars,), x=Axis("run"), y=Axis("error (mm)"))
    fig = svg_figure.read(svg.render(chart, (5.0, 4.0)))
    ay, by = fig.scale("y")
    ax, bx = fig.scale("x")
    paths = fig.series("score").findall("s:path", NS)
    assert len(paths) == 3
    assert len(fig.series("score").findall("s:circle", NS)) == 3  # the values
    for path, lo, hi, x in zip(paths, (4, 5.5, None), (6.5, 8, 9), (1, 2, 3), strict=True):
        ends = {round(ay * float(p[2]) + by, 1) for p in svg_figure.PAIR.findall(path.get("d", ""))}
        xs = [ax * float(p[1]) + bx for p in svg_figure.PAIR.findall(path.get("d", ""))]
        assert hi in ends and (lo is None or lo in ends)
        assert min(xs) < x < max(xs)  # the caps around the value's x
        if lo is None:  # no bar below the value: nothing drawn under y = 7
            assert min(ends) >= 7 - 0.1


def test_spans_bands_reflines_and_bars() -> None:
    chart = Chart(
        (
            Span(2.0, 3.0, "x", label="gap"),
            Band(_nums(0, 5, 10), _nums(1, 2, 3), _nums(2, 4, 6), label="95 % band"),
            RefLine(4.0, "y", label="accuracy"),
            Bars(_nums(1, 9), _nums(5, np.nan), 1.0, label="counts"),
            Text(1.0, 5.0, "a <b> & c", offset=(0, 3)),
        ),
        x=Axis("x"),
        y=Axis("y", include_zero=True),
    )
    fig = svg_figure.read(svg.render(chart, (6.0, 4.0)))
    ax, bx = fig.scale("x")
    ay, _ = fig.scale("y")
    span = fig.series("gap").find("s:rect", NS)
    assert span is not None
    x0 = ax * float(span.get("x", "nan")) + bx
    x1 = ax * (float(span.get("x", "nan")) + float(span.get("width", "nan"))) + bx
    assert np.allclose([x0, x1], [2.0, 3.0], atol=abs(ax))
    band = fig.series("95 % band").find("s:path", NS)
    assert band is not None and band.get("d", "").endswith("Z")
    assert len(svg_figure.PAIR.findall(band.get("d", ""))) == 6
    rects = fig.series("counts").findall("s:rect", NS)
    assert len(rects) == 1  # the NaN bar is not drawn
    assert abs(ay) * float(rects[0].get("height", "nan")) == pytest.approx(5.0, abs=abs(ay))
    assert fig.texts("label") == ["a <b> & c"]  # text, escaped in the file
    legend = [e.get("data-label") for e in fig.root.iter() if e.get("class") == "entry"]
    assert legend == ["gap", "95 % band", "accuracy", "counts"]


def test_equal_aspect_gives_a_unit_the_same_length_on_both_axes() -> None:
    x, y = _nums(0, 100, 100, 0), _nums(0, 0, 10, 10)
    fig = svg_figure.read(svg.render(Chart((Line(x, y),), equal_aspect=True), (5.0, 5.0)))
    (ax, _), (ay, _) = fig.scale("x"), fig.scale("y")
    assert abs(ax) == pytest.approx(abs(ay), rel=0.01)
    plain = svg_figure.read(svg.render(Chart((Line(x, y),)), (5.0, 5.0)))
    assert abs(plain.scale("x")[0]) > 5 * abs(plain.scale("y")[0])


def test_right_scale_and_colour_scale() -> None:
    chart = Chart(
        (
            Bars(_nums(0), _nums(100), 0.4, label="left"),
            Bars(_nums(1), _nums(2), 0.4, label="right", side="right"),
        ),
        y=Axis("mm", include_zero=True),
        right=Axis("deg", include_zero=True),
    )
    fig = svg_figure.read(svg.render(chart, (5.0, 4.0)))
    assert fig.texts("rlabel") == ["deg"]
    ticks = [float(t) for t in fig.texts("rtick")]
    assert max(ticks) >= 2 and max(ticks) < 10  # its own scale, not the left one's
    left = fig.series("left").find("s:rect", NS)
    right = fig.series("right").find("s:rect", NS)
    assert left is not None and right is not None
    # 100 on the left and 2 on the right both reach near the top
    assert abs(float(left.get("height", "0")) - float(right.get("height", "0"))) < 20

    scatter = Scatter(_nums(0, 1, 2), _nums(0, 1, 2), values=_nums(0, 5, 10), label="e")
    coloured = Chart((scatter,), colour_scale=ColourScale("error (mm)", 0.0, 10.0))
    fig = svg_figure.read(svg.render(coloured, (5.0, 4.0)))
    fills = [c.get("fill") for c in fig.series("e").findall("s:circle", NS)]
    assert fills == viridis(_nums(0.0, 0.5, 1.0))
    assert fills[0] == "#440154" and fills[-1] == "#fde725"  # viridis' ends
    assert fig.texts("clabel") == ["error (mm)"]


def test_matplotlib_draws_the_same_layers() -> None:
    chart = Chart(
        (
            Line(_nums(0, 1, 2), _nums(0, 1, 0), label="line"),
            ErrorBars(_nums(1), _nums(1), _nums(0.5), _nums(1.5), label="interval"),
            Span(0.2, 0.4, label="gap"),
        ),
        x=Axis("x (mm)"),
        y=Axis("y (mm)"),
    )
    fig = Figure()
    ax = fig.add_subplot()
    chart_mpl.draw(chart, ax)
    assert ax.get_xlabel() == "x (mm)"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["line", "interval", "gap"]


@pytest.mark.slow
def test_hostile_values_never_reach_the_svg() -> None:
    """Random charts of every layer with NaN, +-inf, empty arrays and values over twelve
    decades: well-formed SVG, and no NaN or infinity in any attribute (a browser would drop
    the element or the whole figure)."""

    rng = np.random.default_rng(29)

    def arr(n: int) -> np.ndarray:
        a = rng.normal(size=n) * 10.0 ** rng.integers(-6, 7)
        u = rng.random(n)
        a[u < 0.1] = np.nan
        a[(u >= 0.1) & (u < 0.15)] = np.inf
        return a

    def one() -> float:
        return float(arr(1)[0])

    for trial in range(300):
        n = int(rng.integers(0, 6))
        layers = [
            Line(arr(n), arr(n), label="l"),
            Scatter(arr(n), arr(n), values=arr(n), label="s"),
            Arrows(arr(n), arr(n), arr(n), arr(n)),
            Span(one(), one(), "x" if trial % 2 else "y", label="span"),
            Band(arr(n), arr(n), arr(n), label="band"),
            ErrorBars(arr(n), arr(n), arr(n), arr(n), label="e"),
            Bars(arr(n), arr(n), label="bars"),
            Rects(arr(n), arr(n), arr(n), arr(n), hatch=bool(trial % 2), label="r"),
            RefLine(one(), "x" if trial % 3 else "y", label="ref"),
            Text(one(), one(), "t"),
        ]
        chart = Chart(
            tuple(layer for layer in layers if rng.random() < 0.5),
            y=Axis("y", symlog=10.0 if trial % 7 == 0 else None),
            right=Axis("r") if trial % 5 == 0 else None,
            equal_aspect=bool(trial % 2),
            colour_scale=ColourScale("c", 0.0, 1.0) if trial % 3 == 0 else None,
        )
        text = svg.render(chart, (4.0, 3.0), "T")
        ET.fromstring(text)
        assert not re.search(r'="[^"]*(nan|inf)[^"]*"', text, re.IGNORECASE), trial
