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
    Axis,
    Chart,
    Layer,
    Line,
    Text,
)
from ertools.views.spec import ChartSpec
from ertools.views.thinning import thin_path
from ertools.views.waypoints import pose_errors_chart, pose_layers

MM = units.factor("length", "m")
PATH_SIZE = (7.0, 6.0)


def path_chart(result: Any, size: tuple[float, float] = PATH_SIZE) -> Chart:
    """The marker set's track on the testbed floor, the waypoints, the measured robot poses."""
    layers: list[Layer] = []
    track = thin_path(np.asarray(result.track[1], dtype=float).reshape(-1, 2), size)
    if len(track):
        layers.append(
            Line(track[:, 0] * MM, track[:, 1] * MM, "#8c8c8c", 1.0, label="marker set (mocap)")
        )
    targets = np.array([[float(v) for v in w] for w in result.waypoints]).reshape(-1, 3)
    layers += pose_layers(targets, COLOURS["blue"], "waypoint (target heading)", "o")
    robot = np.array([s.robot for s in result.segments if s.measured], dtype=float).reshape(-1, 3)
    if len(robot):
        layers += pose_layers(robot, COLOURS["red"], "robot at the script's lookup", "x")
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
    segments = result.segments
    return pose_errors_chart(
        [s.index + 1 for s in segments],
        [s.distance_error for s in segments],
        [s.orientation_error for s in segments],
        (result.position_accuracy, result.orientation_accuracy),
        [s.status for s in segments],
        "segment",
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
