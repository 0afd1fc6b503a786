"""HOPF figures: pose score per goal, the errors, ground truth vs answers on the table.

Each figure is a :class:`~ertools.views.chart.Chart` (lengths in mm, angles in degrees).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ertools.benchmarks.common.table_figures import (
    EMPTY,
    QUALITIES,
    Placed,
    errors_chart,
    quality,
    table_chart,
    table_figures,
)
from ertools.views.chart import Axis, Bars, Chart, Layer, RefLine, Scatter, Text
from ertools.views.spec import ChartSpec


def _colour(goal: Any) -> str:
    answered = goal.answer is not None and goal.terms is not None
    return quality(answered, goal.class_ok, goal.instance_ok)


def _key() -> list[Layer]:
    """Legend entries (square markers: an empty bar layer would lose its colour)."""
    return [Scatter(EMPTY, EMPTY, c, marker="s", label=text) for c, text in QUALITIES]


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


def _errors(result: Any) -> Chart:
    rows = [
        (g.index, math.hypot(g.terms[0], g.terms[1]), abs(math.degrees(g.terms[2])))
        for g in result.goals
        if g.terms is not None and math.isfinite(g.terms[0])
    ]
    return errors_chart("goal", [g.index for g in result.goals], rows)


def _table(result: Any) -> Chart:
    """Each goal's ground truth and answer on the table (an answer with a value that is not
    finite is not drawn)."""
    placed: list[Placed] = []
    for g in result.goals:
        if g.truth is None or not g.truth.pose:
            continue
        a = g.answer
        drawn = a is not None and a.pose is not None and all(math.isfinite(v) for v in a.pose)
        placed.append((g.index, g.truth.pose, a.pose if drawn else None, _colour(g)))
    return table_chart(placed)


def figure_specs(result: Any) -> list[ChartSpec]:
    """The HOPF figures of a result (``HopfResult``)."""
    return table_figures(result, "goal", (scores_chart, _errors, _table))
