"""HNF's figures: the marker set's track with the waypoints and the poses the script measured,
and the errors per segment. Each a :class:`~ertools.views.chart.Chart` (lengths in mm,
angles in degrees), written as SVG by reports and as images by ``--plot``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ertools.views import units
from ertools.views.chart import (
    COLOURS,
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
from ertools.views.thinning import thin_path

ARROW = 0.25  # metres: the heading arrows
MM = units.factor("length", "m")
DEG = units.factor("angle", "rad")
PATH_SIZE = (7.0, 6.0)


def _poses(xyt: np.ndarray, colour: str, label: str, marker: Any) -> list[Layer]:
    x, y = xyt[:, 0] * MM, xyt[:, 1] * MM
    return [
        Scatter(x, y, colour, marker=marker, size=5.0, label=label),
        Arrows(
            x, y, x + np.cos(xyt[:, 2]) * ARROW * MM, y + np.sin(xyt[:, 2]) * ARROW * MM, colour
        ),
    ]


def path_chart(result: Any, size: tuple[float, float] = PATH_SIZE) -> Chart:
    """The marker set's track on the testbed floor, the waypoints, the measured robot poses."""
    layers: list[Layer] = []
    track = thin_path(np.asarray(result.track[1], dtype=float).reshape(-1, 2), size)
    if len(track):
        layers.append(
            Line(track[:, 0] * MM, track[:, 1] * MM, "#8c8c8c", 1.0, label="marker set (mocap)")
        )
    targets = np.array([[float(v) for v in w] for w in result.waypoints]).reshape(-1, 3)
    layers += _poses(targets, COLOURS["blue"], "waypoint (target heading)", "o")
    robot = np.array([s.robot for s in result.segments if s.measured], dtype=float).reshape(-1, 3)
    if len(robot):
        layers += _poses(robot, COLOURS["red"], "robot at the script's lookup", "x")
    layers += [
        Text(float(w[0]) * MM, float(w[1]) * MM, str(k + 1), COLOURS["blue"], offset=(7.0, 7.0))
        for k, w in enumerate(result.waypoints)
    ]
    return Chart(
        tuple(layers),
        x=Axis(units.label("x in the testbed frame", "length")),
        y=Axis(units.label("y in the testbed frame", "length")),
        equal_aspect=True,
    )


def errors_chart(result: Any) -> Chart:
    """Distance (bars, left) and orientation (right) error per segment; dashed: the totals."""
    idx = np.array([s.index + 1 for s in result.segments], dtype=float)
    dist = np.array(
        [np.nan if s.distance_error is None else s.distance_error for s in result.segments]
    )
    ori = np.array(
        [np.nan if s.orientation_error is None else s.orientation_error for s in result.segments]
    )
    blue, orange = COLOURS["blue"], COLOURS["orange"]
    layers: list[Layer] = [
        Bars(idx - 0.2, dist * MM, 0.4, (blue,), "distance error"),
        Bars(idx + 0.2, ori * DEG, 0.4, (orange,), "orientation error", side="right"),
    ]
    if result.position_accuracy is not None:
        layers.append(RefLine(result.position_accuracy * MM, "y", blue, label="position accuracy"))
    if result.orientation_accuracy is not None:
        layers.append(
            RefLine(
                result.orientation_accuracy * DEG,
                "y",
                orange,
                label="orientation accuracy",
                side="right",
            )
        )
    layers += [
        Text(float(i), 0.0, s.status, COLOURS["red"], offset=(0.0, 3.0), anchor="middle")
        for i, s in zip(idx, result.segments, strict=True)
        if s.distance_error is None
    ]
    return Chart(
        tuple(layers),
        x=Axis("segment", ticks=tuple((float(i), str(int(i))) for i in idx)),
        y=Axis(units.label("distance error", "length"), colour=blue, include_zero=True),
        right=Axis(units.label("orientation error", "angle"), colour=orange, include_zero=True),
        grid="y",
    )


def figure_specs(result: Any) -> list[ChartSpec]:
    """The path and the errors figures of an ``HnfResult``."""
    reading = "the 2019 script" if result.rules != "ertools" else "ertools' reading"
    return [
        ChartSpec(
            "hnf_path",
            f"HNF: track, waypoints and measured poses (--rules {result.rules})",
            lambda size: path_chart(result, size),
            PATH_SIZE,
        ),
        ChartSpec(
            "hnf_errors",
            f"HNF errors per segment (dashed: accuracy; {reading})",
            lambda size: errors_chart(result),
            (7.0, 4.5),
        ),
    ]
