"""FBM1 figures: per-run errors and scores, ground truth vs answered poses on the table.

Each figure is a :class:`~ertools.views.chart.Chart` (lengths in mm, angles in degrees);
reports write it as SVG (:mod:`ertools.report.svg`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ertools.benchmarks.common.table_figures import (
    EMPTY,
    MM,
    QUALITIES,
    Placed,
    errors_chart,
    quality,
    table_chart,
    table_figures,
)
from ertools.views.chart import Axis, Bars, Chart, Layer, RefLine, Scatter, Text
from ertools.views.spec import ChartSpec


def _colour(run: Any) -> str:
    return quality(run.answer is not None, run.class_ok, run.instance_ok)


def _quality_key() -> list[Layer]:
    """Legend entries of the answer qualities (layers that draw nothing)."""
    return [Bars(EMPTY, EMPTY, colours=(c,), label=text) for c, text in QUALITIES]


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


def _errors(result: Any) -> Chart:
    rows = [
        (r.index, r.errors.trans_error_m, abs(r.errors.theta_error_deg))
        for r in result.runs
        if r.errors is not None
    ]
    return errors_chart("run", [r.index for r in result.runs], rows)


def _pose(answer: Any) -> tuple[float, float, float]:
    return answer.x, answer.y, math.radians(answer.theta_deg)


def _table(result: Any) -> Chart:
    """Ground truth (black, with the board's position) and each answer (coloured by its
    quality, joined to its ground truth) on the table, headings as arrows."""
    gts = [(r, r.gt) for r in result.runs if r.gt is not None]
    under: list[Layer] = []
    if gts:
        board = np.array([g.board_xy for _, g in gts], dtype=float) * MM
        under.append(Scatter(board[:, 0], board[:, 1], "#bbbbbb", marker="s", label="board"))
    placed: list[Placed] = [
        (
            r.index,
            (g.x, g.y, g.yaw),
            None
            if r.answer is None
            else (r.answer.x, r.answer.y, math.radians(r.answer.theta_deg)),
            _colour(r),
        )
        for r, g in gts
    ]
    return table_chart(placed, under)


def figure_specs(result: Any) -> list[ChartSpec]:
    """The FBM1 figures of a result (``Fbm1Result``)."""
    return table_figures(result, "run", (scores_chart, _errors, _table))
