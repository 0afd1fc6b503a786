"""HPPF figures: position error per goal (coloured by the name's recognition), and the
people's ground truth vs the answers in the testbed frame."""

from __future__ import annotations

from typing import Any

import numpy as np

from ertools.benchmarks import registry
from ertools.views import units
from ertools.views.chart import Axis, Bars, Chart, Layer, Line, RefLine, Scatter, Text
from ertools.views.spec import ChartSpec

_RIGHT = "#1b9e77"
_WRONG = "#d95f02"
_NONE = "#999999"
MM = units.factor("length", "m")
_EMPTY = np.empty(0)


def _colour(p: Any) -> str:
    if p.recognized is None:
        return _NONE
    return _RIGHT if p.recognized else _WRONG


def errors_chart(result: Any) -> Chart:
    """Position error per pass (mm), green where the name was right, orange where wrong,
    grey without an answer; each pass's status below; the Distance error dashed."""
    passes = result.passes
    xs = np.arange(len(passes), dtype=float)
    errs = np.array([(p.position_error or 0.0) * MM for p in passes])
    layers: list[Layer] = [Bars(xs, errs, 0.8, tuple(_colour(p) for p in passes))]
    layers += [
        Text(float(x), 0.0, p.status, offset=(0.0, 3.0), anchor="middle")
        for x, p in zip(xs, passes, strict=True)
        if p.status != "detected"
    ]
    if result.distance_error is not None:
        layers.append(RefLine(result.distance_error * MM, "y", "#000000", label="Distance error"))
    layers += [
        # legend entries (square markers: an empty bar layer would lose its colour)
        Scatter(_EMPTY, _EMPTY, _RIGHT, marker="s", label="name right"),
        Scatter(_EMPTY, _EMPTY, _WRONG, marker="s", label="name wrong"),
        Scatter(_EMPTY, _EMPTY, _NONE, marker="s", label="no answer / not scored"),
    ]
    ticks = tuple((float(x), f"{p.index}: {p.person}") for x, p in zip(xs, passes, strict=True))
    return Chart(
        tuple(layers),
        x=Axis("goal: person", ticks=ticks),
        y=Axis(units.label("position error", "length"), include_zero=True),
        grid="y",
    )


def area_chart(result: Any) -> Chart:
    """Each detected person's cap (black) and the robot's answer (coloured), joined, in the
    testbed frame."""
    layers: list[Layer] = []
    shown = [p for p in result.passes if p.truth is not None and p.truth.xy is not None]
    for p in shown:
        tx, ty = p.truth.xy
        layers.append(Text(tx * MM, ty * MM, f"{p.index}: {p.person}", offset=(4.0, 4.0)))
        a = p.answer
        if a is None or a.xy is None:
            continue
        colour = _colour(p)
        layers += [
            Line(np.array([tx, a.xy[0]]) * MM, np.array([ty, a.xy[1]]) * MM, colour, 0.6, "dotted"),
            Scatter(np.array([a.xy[0] * MM]), np.array([a.xy[1] * MM]), colour, marker="x"),
        ]
    if shown:
        xy = np.array([p.truth.xy for p in shown]) * MM
        layers.append(Scatter(xy[:, 0], xy[:, 1], "#000000", size=3.0, label="the cap"))
        layers.append(Scatter(_EMPTY, _EMPTY, _RIGHT, marker="x", label="answer"))
    return Chart(
        tuple(layers),
        x=Axis(units.label("x in the testbed frame", "length")),
        y=Axis(units.label("y in the testbed frame", "length")),
        equal_aspect=True,
    )


def figure_specs(result: Any) -> list[ChartSpec]:
    """The HPPF figures of a result (``HppfResult``)."""
    label = registry.get(result.name).title
    return [
        ChartSpec(
            f"{result.name}_position_errors",
            f"{label}: position error per goal",
            lambda size: errors_chart(result),
        ),
        ChartSpec(
            f"{result.name}_area",
            f"{label}: the people (black) vs the answers",
            lambda size: area_chart(result),
            (7.0, 7.0),
        ),
    ]
