"""HOPF figures: pose score per goal, the errors, ground truth vs answers on the table.

Each figure is a :class:`~ertools.views.chart.Chart` (lengths in mm, angles in degrees).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ertools.benchmarks import registry
from ertools.views import units
from ertools.views.chart import Arrows, Axis, Bars, Chart, Layer, Line, RefLine, Scatter, Text
from ertools.views.spec import ChartSpec

_RIGHT = "#1b9e77"
_WRONG_INSTANCE = "#e6ab02"
_WRONG_CLASS = "#d95f02"
_NONE = "#999999"
_QUALITIES = (
    (_RIGHT, "class and instance right"),
    (_WRONG_INSTANCE, "instance wrong"),
    (_WRONG_CLASS, "class wrong"),
    (_NONE, "no answer / not scored"),
)
MM = units.factor("length", "m")
ARROW = 0.04  # metres: heading arrows a few cm long on a ~1 m table
_EMPTY = np.empty(0)


def _colour(goal: Any) -> str:
    if goal.answer is None or goal.terms is None:
        return _NONE
    if not goal.class_ok:
        return _WRONG_CLASS
    return _RIGHT if goal.instance_ok else _WRONG_INSTANCE


def _key() -> list[Layer]:
    """Legend entries (square markers: an empty bar layer would lose its colour)."""
    return [Scatter(_EMPTY, _EMPTY, c, marker="s", label=text) for c, text in _QUALITIES]


def scores_chart(result: Any) -> Chart:
    """Pose score per goal (0 where none), coloured by the answer's quality; each goal's
    status below; the total dashed."""
    goals = result.goals
    xs = np.array([g.index for g in goals], dtype=float)
    scores = np.array([g.terms[5] if g.terms is not None else 0.0 for g in goals])
    layers: list[Layer] = [Bars(xs, scores, 0.8, tuple(_colour(g) for g in goals))]
    layers += [
        Text(float(g.index), 0.02, g.status, offset=(0.0, 3.0), anchor="middle")
        for g in goals
        if g.status != "scored"
    ]
    if result.pose_score is not None:
        layers.append(RefLine(result.pose_score, "y", "#000000", label="pose_score"))
    layers += _key()
    low = min(0.0, *scores) - 0.05 if len(scores) else -0.05
    return Chart(
        tuple(layers),
        x=Axis("goal", ticks=tuple((float(x), str(int(x))) for x in xs)),
        y=Axis("pose score (1 - t/2 - r/2)", limits=(low, 1.05)),
        grid="y",
    )


def errors_chart(result: Any) -> Chart:
    """Translation error (left, mm, logarithmic beyond 10 mm) and theta error (right, deg)."""
    goals = [g for g in result.goals if g.terms is not None and math.isfinite(g.terms[0])]
    xs = np.array([g.index for g in goals], dtype=float)
    trans = np.array([math.hypot(g.terms[0], g.terms[1]) * MM for g in goals])
    theta = np.array([abs(math.degrees(g.terms[2])) for g in goals])
    width = 0.4
    top = max(180.0 * 1.05, *theta) if any(t > 20 for t in theta) else 20.0
    return Chart(
        (
            Bars(xs - width / 2, trans, width, ("#7570b3",), units.label("|dxy|", "length")),
            Bars(
                xs + width / 2,
                theta,
                width,
                ("#e7298a",),
                units.label("|dtheta|", "angle"),
                side="right",
            ),
        ),
        x=Axis("goal", ticks=tuple((float(g.index), str(g.index)) for g in result.goals)),
        y=Axis(units.label("translation error", "length"), include_zero=True, symlog=10.0),
        right=Axis(units.label("theta error", "angle"), limits=(0.0, top)),
        grid="y",
    )


def _arrow(x: float, y: float, yaw: float, colour: str) -> Arrows:
    hx, hy = x + ARROW * math.cos(yaw), y + ARROW * math.sin(yaw)
    return Arrows(
        np.array([x * MM]), np.array([y * MM]), np.array([hx * MM]), np.array([hy * MM]), colour
    )


def table_chart(result: Any) -> Chart:
    """Each goal's ground truth (black) and answer (coloured by its quality, joined to the
    truth) in the table frame, headings as arrows; the table's axes red (x) and green (y)."""
    layers: list[Layer] = [
        Line(np.array([0.0, 100.0]), np.zeros(2), "#ff0000", 2.0),
        Line(np.zeros(2), np.array([0.0, 100.0]), "#008000", 2.0),
    ]
    truths = [(g, g.truth.pose) for g in result.goals if g.truth is not None and g.truth.pose]
    for g, (x, y, yaw) in truths:
        layers += [
            _arrow(x, y, yaw, "#000000"),
            Text(x * MM, y * MM, str(g.index), offset=(4.0, 4.0)),
        ]
        a = g.answer
        if a is None or a.pose is None or not all(math.isfinite(v) for v in a.pose):
            continue
        colour = _colour(g)
        ax, ay, at = a.pose
        layers += [
            Line(np.array([x, ax]) * MM, np.array([y, ay]) * MM, colour, 0.6, "dotted"),
            _arrow(ax, ay, at, colour),
            Scatter(np.array([ax * MM]), np.array([ay * MM]), colour, marker="x", size=4.5),
        ]
    if truths:
        xy = np.array([p[:2] for _, p in truths]) * MM
        layers.append(Scatter(xy[:, 0], xy[:, 1], "#000000", size=3.0, label="ground truth"))
        layers.append(Scatter(_EMPTY, _EMPTY, _RIGHT, marker="x", size=4.5, label="answer"))
    return Chart(
        tuple(layers),
        x=Axis(units.label("x in the table frame", "length")),
        y=Axis(units.label("y in the table frame", "length")),
        equal_aspect=True,
    )


def figure_specs(result: Any) -> list[ChartSpec]:
    """The HOPF figures of a result (``HopfResult``)."""
    label = registry.get(result.name).title
    return [
        ChartSpec(
            f"{result.name}_pose_scores",
            f"{label}: pose score per goal",
            lambda size: scores_chart(result),
        ),
        ChartSpec(
            f"{result.name}_errors",
            f"{label}: translation and theta errors",
            lambda size: errors_chart(result),
        ),
        ChartSpec(
            f"{result.name}_table",
            f"{label}: ground truth (black) vs answers on the table",
            lambda size: table_chart(result),
            (7.0, 7.0),
        ),
    ]
