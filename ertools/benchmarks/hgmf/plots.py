"""HGMF figures: the object's path on the table with the targets and the measured positions,
and its height over the table with each goal's grasp threshold.

Each figure is a :class:`~ertools.views.chart.Chart` (lengths in mm, times in s), built for
its size (the path thinned to its pixels); reports write it as SVG.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ertools.benchmarks.hgmf.config import GRASP_RISE_M
from ertools.views import units
from ertools.views.chart import COLOURS, Axis, Chart, Layer, Line, RefLine, Scatter, Span, Text
from ertools.views.spec import ChartSpec
from ertools.views.thinning import thin_path, thin_series

MM = units.factor("length", "m")
TABLE_SIZE = (7.0, 6.0)
HEIGHT_SIZE = (7.0, 4.0)


def table_chart(result: Any, size: tuple[float, float] = TABLE_SIZE) -> Chart:
    """The object's path in the table's frame, each goal's target and measured position."""
    _, xyz = result.track
    layers: list[Layer] = []
    path = thin_path(np.asarray(xyz, dtype=float)[:, :2].reshape(-1, 2), size)
    if len(path):
        layers.append(Line(path[:, 0] * MM, path[:, 1] * MM, "#8c8c8c", 1.0, label="object (GT)"))
    shown = [g for g in result.goals if g.attempt.target is not None]
    if shown:
        targets = np.array([g.attempt.target for g in shown], dtype=float) * MM
        layers.append(
            Scatter(targets[:, 0], targets[:, 1], COLOURS["blue"], size=5.0, label="target")
        )
        layers += [
            Text(x, y, f"goal_{g.attempt.index}", COLOURS["blue"], offset=(7.0, 7.0))
            for g, (x, y) in zip(shown, targets.tolist(), strict=True)
        ]
    placed = np.array(
        [g.position for g in result.goals if g.position is not None], dtype=float
    ).reshape(-1, 2)
    if len(placed):
        layers.append(
            Scatter(
                placed[:, 0] * MM,
                placed[:, 1] * MM,
                COLOURS["red"],
                marker="x",
                size=5.0,
                label="object after the goal",
            )
        )
    return Chart(
        tuple(layers),
        x=Axis(units.label("x in the table's frame", "length")),
        y=Axis(units.label("y in the table's frame", "length")),
        equal_aspect=True,
    )


def height_chart(result: Any, size: tuple[float, float] = HEIGHT_SIZE) -> Chart:
    """The object's height over the table (s from the start); each goal's span shaded and its
    grasp threshold (the height before it + 3 cm) drawn over it."""
    t, xyz = result.track
    secs = (np.asarray(t, dtype=np.int64) - result.t_start_ns) / 1e9
    z = np.asarray(xyz, dtype=float).reshape(-1, 3)[:, 2]
    layers: list[Layer] = []
    for g in result.goals:
        a = g.attempt
        lo, hi = (
            (a.times.start_ns - result.t_start_ns) / 1e9,
            (a.times.end_ns - result.t_start_ns) / 1e9,
        )
        layers.append(Span(lo, hi, colour=COLOURS["green"] if g.grasped else COLOURS["grey"]))
        layers.append(RefLine((g.z_ref + GRASP_RISE_M) * MM, "y", COLOURS["red"], lo=lo, hi=hi))
    if len(secs):
        keep = thin_series(secs, z, size[0])
        layers.append(Line(secs[keep], z[keep] * MM, COLOURS["blue"], 1.0, label="object height"))
    return Chart(
        tuple(layers),
        x=Axis("time from the benchmark's start (s)"),
        y=Axis(units.label("height over the table", "length")),
        grid="y",
    )


def figure_specs(result: Any) -> list[ChartSpec]:
    """The table and the height figures of an ``HgmfResult``."""
    return [
        ChartSpec(
            "hgmf_table",
            "HGMF: the object on the table, targets and measured positions",
            lambda size: table_chart(result, size),
            TABLE_SIZE,
        ),
        ChartSpec(
            "hgmf_height",
            "HGMF: the object's height (green: a grasp; red: the height before the goal + 3 cm)",
            lambda size: height_chart(result, size),
            HEIGHT_SIZE,
        ),
    ]
