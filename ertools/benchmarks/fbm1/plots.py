"""FBM1 figures: per-run errors and scores, ground truth vs answered poses on the table.

Each figure is a :class:`~ertools.views.chart.Chart` (lengths in mm, angles in degrees);
reports write it as SVG (:mod:`ertools.report.svg`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ertools.benchmarks import registry
from ertools.views import units
from ertools.views.chart import (
    Arrows,
    Axis,
    Bars,
    Chart,
    Layer,
    Line,
    RefLine,
    Scatter,
    Text,
)
from ertools.views.spec import ChartSpec

# Colours by answer quality (colour-blind safe pairs).
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


def _colour(run: Any) -> str:
    if run.answer is None:
        return _NONE
    if not run.class_ok:
        return _WRONG_CLASS
    return _RIGHT if run.instance_ok else _WRONG_INSTANCE


def _quality_key() -> list[Layer]:
    """Legend entries of the answer qualities (layers that draw nothing)."""
    return [Bars(_EMPTY, _EMPTY, colours=(c,), label=text) for c, text in _QUALITIES]


def scores_chart(result: Any) -> Chart:
    """Pose score per run, coloured by the answer's quality; the mean dashed."""
    runs = result.runs
    xs = np.array([r.index for r in runs], dtype=float)
    scores = np.array([r.pose_score if r.pose_score is not None else 0.0 for r in runs])
    layers: list[Layer] = [Bars(xs, scores, 0.8, tuple(_colour(r) for r in runs))]
    layers += [
        Text(float(r.index), 0.02, r.status, offset=(0.0, 3.0), anchor="middle")
        for r in runs
        if r.status in ("failed", "aborted")
    ]
    if result.totals.pose_score is not None:
        layers.append(RefLine(result.totals.pose_score, "y", "#000000", label="mean"))
    layers += _quality_key()
    low = min(0.0, *scores) - 0.05 if len(scores) else -0.05
    return Chart(
        tuple(layers),
        x=Axis("run", ticks=tuple((float(x), str(int(x))) for x in xs)),
        y=Axis("pose score (1 - t/2 - r/2)", limits=(low, 1.05)),
        grid="y",
    )


def errors_chart(result: Any) -> Chart:
    """Translation error (left, mm, logarithmic beyond 10 mm) and theta error (right, deg)."""
    runs = [r for r in result.runs if r.errors is not None]
    xs = np.array([r.index for r in runs], dtype=float)
    trans_mm = np.array([r.errors.trans_error_m * MM for r in runs])
    theta = np.array([abs(r.errors.theta_error_deg) for r in runs])
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
        x=Axis("run", ticks=tuple((float(r.index), str(r.index)) for r in result.runs)),
        y=Axis(units.label("translation error", "length"), include_zero=True, symlog=10.0),
        right=Axis(units.label("theta error", "angle"), limits=(0.0, top)),
        grid="y",
    )


def _arrow(x0: float, y0: float, x1: float, y1: float, colour: str) -> Arrows:
    return Arrows(np.array([x0]), np.array([y0]), np.array([x1]), np.array([y1]), colour)


def _heading(x: float, y: float, yaw: float) -> tuple[float, float]:
    return (x + ARROW * math.cos(yaw)) * MM, (y + ARROW * math.sin(yaw)) * MM


def table_chart(result: Any) -> Chart:
    """Ground truth (black, with the board's position) and each answer (coloured by its
    quality, joined to its ground truth) on the table, headings as arrows; the table frame's
    axes red (x) and green (y)."""
    layers: list[Layer] = [
        Line(np.array([0.0, 100.0]), np.zeros(2), "#ff0000", 2.0),
        Line(np.zeros(2), np.array([0.0, 100.0]), "#008000", 2.0),
    ]
    gts = [(r, r.gt) for r in result.runs if r.gt is not None]
    if gts:
        board = np.array([g.board_xy for _, g in gts], dtype=float) * MM
        layers.append(Scatter(board[:, 0], board[:, 1], "#bbbbbb", marker="s", label="board"))
    for r, g in gts:
        hx, hy = _heading(g.x, g.y, g.yaw)
        layers.append(_arrow(g.x * MM, g.y * MM, hx, hy, "#000000"))
        layers.append(Text(g.x * MM, g.y * MM, str(r.index), offset=(4.0, 4.0)))
        a = r.answer
        if a is None:
            continue
        colour = _colour(r)
        hx, hy = _heading(a.x, a.y, math.radians(a.theta_deg))
        layers += [
            Line(np.array([g.x, a.x]) * MM, np.array([g.y, a.y]) * MM, colour, 0.6, "dotted"),
            _arrow(a.x * MM, a.y * MM, hx, hy, colour),
            Scatter(np.array([a.x * MM]), np.array([a.y * MM]), colour, marker="x", size=4.5),
        ]
    if gts:
        xy = np.array([(g.x, g.y) for _, g in gts]) * MM
        layers.append(Scatter(xy[:, 0], xy[:, 1], "#000000", size=3.0, label="ground truth"))
        layers.append(Scatter(_EMPTY, _EMPTY, _RIGHT, marker="x", size=4.5, label="answer"))
    return Chart(
        tuple(layers),
        x=Axis(units.label("x in the table frame", "length")),
        y=Axis(units.label("y in the table frame", "length")),
        equal_aspect=True,
    )


def figure_specs(result: Any) -> list[ChartSpec]:
    """The FBM1 figures of a result (``Fbm1Result``)."""
    label = registry.get(result.name).title
    return [
        ChartSpec(
            f"{result.name}_pose_scores",
            f"{label}: pose score per run",
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
