"""The figures of an object perception benchmark (items placed on a table, the robot answers
each item's class, instance and pose): the answers' qualities as colours, each answer joined
to its ground truth on the table, and the three figures of a result.

Lengths in mm, angles in radians here (degrees on the charts' axes).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ertools.benchmarks import registry
from ertools.views import units
from ertools.views.chart import Arrows, Axis, Bars, Chart, Layer, Line, Scatter, Text
from ertools.views.spec import ChartSpec

# Colours by answer quality (colour-blind safe pairs).
RIGHT = "#1b9e77"
WRONG_INSTANCE = "#e6ab02"
WRONG_CLASS = "#d95f02"
NONE = "#999999"
QUALITIES = (
    (RIGHT, "class and instance right"),
    (WRONG_INSTANCE, "instance wrong"),
    (WRONG_CLASS, "class wrong"),
    (NONE, "no answer / not scored"),
)
MM = units.factor("length", "m")
ARROW = 0.04  # metres: heading arrows a few cm long on a ~1 m table
EMPTY = np.empty(0)

Pose2 = tuple[float, float, float]
#: One item on the table chart: its number, ground truth (x, y, yaw), the answer (None: none
#: to draw) and the answer's colour.
Placed = tuple[int, Pose2, Pose2 | None, str]


def quality(answered: bool, class_ok: bool | None, instance_ok: bool | None) -> str:
    """The colour of an answer's quality (:data:`QUALITIES`)."""
    if not answered:
        return NONE
    if not class_ok:
        return WRONG_CLASS
    return RIGHT if instance_ok else WRONG_INSTANCE


def errors_chart(
    unit: str, ticks: Sequence[int], rows: Sequence[tuple[int, float, float]]
) -> Chart:
    """Translation error (left, mm, logarithmic beyond 10 mm) and theta error (right, deg)
    per ``unit`` (run, goal); ``rows``: (number, translation error in m, |theta error| in
    degrees) of those that have errors, ``ticks``: every number."""
    xs = np.array([k for k, _, _ in rows], dtype=float)
    trans_mm = np.array([t * MM for _, t, _ in rows])
    theta = np.array([d for _, _, d in rows])
    width = 0.4
    top = max(180.0 * 1.05, *theta) if any(t > 20 for t in theta) else 20.0
    return Chart(
        (
            Bars(xs - width / 2, trans_mm, width, ("#7570b3",), units.label("|dxy|", "length")),
            Bars(
                xs + width / 2,
                theta,
                width,
                ("#e7298a",),
                units.label("|dtheta|", "angle"),
                side="right",
            ),
        ),
        x=Axis(unit, ticks=tuple((float(k), str(k)) for k in ticks)),
        y=Axis(units.label("translation error", "length"), include_zero=True, symlog=10.0),
        right=Axis(units.label("theta error", "angle"), limits=(0.0, top)),
        grid="y",
    )


def _arrow(x: float, y: float, yaw: float, colour: str) -> Arrows:
    hx, hy = (x + ARROW * math.cos(yaw)) * MM, (y + ARROW * math.sin(yaw)) * MM
    return Arrows(np.array([x * MM]), np.array([y * MM]), np.array([hx]), np.array([hy]), colour)


def table_chart(placed: Sequence[Placed], under: Sequence[Layer] = ()) -> Chart:
    """Each item's ground truth (black) and answer (coloured, joined to the truth) in the
    table frame, headings as arrows; the table's axes red (x) and green (y), then ``under``
    (drawn below the items)."""
    layers: list[Layer] = [
        Line(np.array([0.0, 100.0]), np.zeros(2), "#ff0000", 2.0),
        Line(np.zeros(2), np.array([0.0, 100.0]), "#008000", 2.0),
        *under,
    ]
    for index, (x, y, yaw), answer, colour in placed:
        layers += [
            _arrow(x, y, yaw, "#000000"),
            Text(x * MM, y * MM, str(index), offset=(4.0, 4.0)),
        ]
        if answer is None:
            continue
        ax, ay, at = answer
        layers += [
            Line(np.array([x, ax]) * MM, np.array([y, ay]) * MM, colour, 0.6, "dotted"),
            _arrow(ax, ay, at, colour),
            Scatter(np.array([ax * MM]), np.array([ay * MM]), colour, marker="x", size=4.5),
        ]
    if placed:
        xy = np.array([truth[:2] for _, truth, _, _ in placed]) * MM
        layers.append(Scatter(xy[:, 0], xy[:, 1], "#000000", size=3.0, label="ground truth"))
        layers.append(Scatter(EMPTY, EMPTY, RIGHT, marker="x", size=4.5, label="answer"))
    return Chart(
        tuple(layers),
        x=Axis(units.label("x in the table frame", "length")),
        y=Axis(units.label("y in the table frame", "length")),
        equal_aspect=True,
    )


def table_figures(
    result: Any, unit: str, charts: tuple[Callable[[Any], Chart], ...]
) -> list[ChartSpec]:
    """The three figures of a result: ``charts`` draw its pose score per ``unit`` (run,
    goal), its translation and theta errors, and its table."""
    label = registry.get(result.name).title
    scores, errors, table = charts
    return [
        ChartSpec(
            f"{result.name}_pose_scores",
            f"{label}: pose score per {unit}",
            lambda size: scores(result),
        ),
        ChartSpec(
            f"{result.name}_errors",
            f"{label}: translation and theta errors",
            lambda size: errors(result),
        ),
        ChartSpec(
            f"{result.name}_table",
            f"{label}: ground truth (black) vs answers on the table",
            lambda size: table(result),
            (7.0, 7.0),
        ),
    ]
