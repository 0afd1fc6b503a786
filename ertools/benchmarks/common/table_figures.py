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
from ertools.views.chart import Arrows, Axis, Chart, Layer, Line, Scatter, Text
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
