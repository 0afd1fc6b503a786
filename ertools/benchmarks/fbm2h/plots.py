"""FBM2@Home figures: the robot's path with the waypoints, and the per-waypoint errors.

Each figure is a :class:`~ertools.views.chart.Chart` (lengths in mm, angles in degrees),
built for its size (the path thinned to its pixels); reports write it as SVG.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ertools.benchmarks.common import gaps
from ertools.views import units
from ertools.views.chart import (
    COLOURS,
    Axis,
    Chart,
    Layer,
    Line,
    Scatter,
    Text,
)
from ertools.views.spec import ChartSpec
from ertools.views.thinning import thin_path
from ertools.views.waypoints import pose_errors_chart, pose_layers

MM = units.factor("length", "m")
PATH_SIZE = (7.0, 6.0)


def path_chart(result: Any, size: tuple[float, float] = PATH_SIZE) -> Chart:
    """Path on the testbed frame, waypoints with target headings, reached poses, the GT's
    gaps on the path (:mod:`ertools.benchmarks.common.gaps`)."""
    layers: list[Layer] = []
    path = thin_path(np.asarray(result.path_xyyaw, dtype=float).reshape(-1, 3), size)
    if len(path):
        layers.append(
            Line(path[:, 0] * MM, path[:, 1] * MM, "#8c8c8c", 1.0, label="robot path (GT)")
        )
    targets = np.array([s.target for s in result.segments], dtype=float).reshape(-1, 3)
    layers += pose_layers(targets, COLOURS["blue"], "waypoint (target heading)", "o")
    reached = np.array(
        [s.robot for s in result.segments if s.robot is not None], dtype=float
    ).reshape(-1, 3)
    if len(reached):
        layers += pose_layers(reached, COLOURS["red"], "robot when reached", "x")
    layers += [
        Text(s.target[0] * MM, s.target[1] * MM, str(s.index), COLOURS["blue"], offset=(7.0, 7.0))
        for s in result.segments
    ]
    if result.goal.starting_pose is not None:
        sx, sy, _ = result.goal.starting_pose
        layers.append(
            Scatter(
                np.array([sx * MM]),
                np.array([sy * MM]),
                COLOURS["green"],
                marker="s",
                size=4.0,
                label="starting pose",
            )
        )
    layers += gaps.path_layers((g for s in result.segments for g in s.gaps), MM)
    return Chart(
        tuple(layers),
        x=Axis(units.label("x in the testbed frame", "length")),
        y=Axis(units.label("y in the testbed frame", "length")),
        equal_aspect=True,
    )


def errors_chart(result: Any) -> Chart:
    """Distance error (bars, left axis) and orientation error (right axis) per waypoint;
    dashed: the accuracies the benchmark counts against."""
    segments = result.segments
    return pose_errors_chart(
        [s.index for s in segments],
        [s.distance_error for s in segments],
        [s.orientation_error for s in segments],
        (result.position_accuracy, result.orientation_accuracy),
        ["no score"] * len(segments),
        "waypoint",
    )


def path_title(result: Any) -> str:
    """The path figure's title: the reached method, the GT's valid fraction over the driven
    segments and each segment's where below 100%, the unscoreable verdict."""
    title = f"FBM2@Home path and waypoints (reached: {result.reached_method})"
    pooled = gaps.pooled_fraction(s.validity for s in result.segments)
    if pooled is not None:
        title += f"; GT {pooled:.1%} valid"
        partial = [
            f"{s.index}: {s.validity.valid_fraction:.1%}"
            for s in result.segments
            if s.validity is not None and s.validity.valid_fraction < 1.0
        ]
        if partial:
            title += f" (waypoint {', '.join(partial)})"
    reason = result.unscoreable_reason
    if reason is not None:
        title += f"; unscoreable: {reason}"
    return title


def figure_specs(result: Any) -> list[ChartSpec]:
    """The path and the errors figures of an ``Fbm2hResult``."""
    mode = "2015 orientation" if result.orientation_2015 else "orientation wrapped to [0, pi]"
    return [
        ChartSpec(
            "fbm2h_path",
            path_title(result),
            lambda size: path_chart(result, size),
            PATH_SIZE,
        ),
        ChartSpec(
            "fbm2h_errors",
            f"Errors per waypoint (dashed: accuracy; {mode})",
            lambda size: errors_chart(result),
            (7.0, 4.5),
        ),
    ]
