"""Figures of a trajectory result: the error over time and the two paths overlaid.

Each figure is a :class:`~ertools.views.chart.Chart` (lengths in mm, angles in degrees, time
in seconds), built for its size (series and paths thinned to its pixels); reports write it as
SVG (:mod:`ertools.report.svg`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ertools.benchmarks.common import gaps
from ertools.benchmarks.trajectory.association import GAP, TRACKING_LOST, UNCOVERED
from ertools.views import units
from ertools.views.chart import COLOURS, Axis, Chart, Layer, Line, RefLine, Scatter
from ertools.views.spec import ChartSpec
from ertools.views.thinning import thin_path, thin_series

if TYPE_CHECKING:
    from ertools.benchmarks.trajectory.result import TrajectoryResult

MM = units.factor("length", "m")
DEG = units.factor("angle", "rad")
TIME_AXIS = units.label("time since the first robot pose", "time")


def error_chart(result: TrajectoryResult, size: tuple[float, float]) -> Chart:
    """Position error (mm) per robot pose; gaps and tracking losses marked on the time axis,
    the robot poses' invalid spans (result.validity) shaded behind."""
    m = result.matched
    layers: list[Layer] = []
    if len(m.t_ns):
        t = (m.t_ns - m.t_ns[0]) / 1e9
        shown = thin_series(t, m.position_error, size[0])
        err = m.position_error[shown] * MM
        if result.validity is not None:
            layers += gaps.time_spans(result.validity.spans, int(m.t_ns[0]))
        layers.append(Line(t[shown], err, COLOURS["blue"], 0.8, label="position error"))
        for code, colour, label in (
            (GAP, COLOURS["orange"], "GT gap"),
            (TRACKING_LOST, COLOURS["red"], "tracking lost"),
            (UNCOVERED, "#808080", "no GT"),
        ):
            sel = m.status == code
            if sel.any():
                at = t[sel]
                layers.append(
                    Scatter(at, np.zeros(len(at)), colour, marker="|", size=6, label=label)
                )
        if result.metrics is not None:
            mean = result.metrics.position_error * MM
            layers.append(RefLine(mean, "y", COLOURS["green"], 0.8, label=f"mean {mean:.1f} mm"))
    return Chart(
        tuple(layers),
        x=Axis(TIME_AXIS),
        y=Axis(units.label("position error", "length")),
        note=None if layers else "no robot pose matched",
    )


def paths_chart(result: TrajectoryResult, size: tuple[float, float]) -> Chart:
    """The robot's estimate and the GT, seen from above (mm)."""
    gt = thin_path(result.gt_path.xyz, size) * MM
    robot = thin_path(result.robot.xyz, size) * MM
    return Chart(
        (
            Line(gt[:, 0], gt[:, 1], "#666666", 1.0, label="ground truth"),
            Scatter(robot[:, 0], robot[:, 1], COLOURS["blue"], size=1.3, label="robot estimate"),
        ),
        x=Axis(units.label("x", "length")),
        y=Axis(units.label("y", "length")),
        equal_aspect=True,
    )


def yaw_chart(result: TrajectoryResult, size: tuple[float, float]) -> Chart:
    """Wrapped yaw error (degrees) per robot pose."""
    m = result.matched
    layers: list[Layer] = []
    if len(m.t_ns):
        t = (m.t_ns - m.t_ns[0]) / 1e9
        shown = thin_series(t, m.yaw_error, size[0])
        if result.validity is not None:
            layers += gaps.time_spans(result.validity.spans, int(m.t_ns[0]))
        layers.append(Line(t[shown], m.yaw_error[shown] * DEG, COLOURS["purple"], 0.8))
    return Chart(
        tuple(layers),
        x=Axis(TIME_AXIS),
        y=Axis(units.label("|yaw error|", "angle")),
        legend=False,
        note=None if layers else "no robot pose matched",
    )


def validity_note(result: TrajectoryResult) -> str:
    """``; 97.3% of robot poses valid`` and the unscoreable verdict, for the error title."""
    if result.validity is None:
        return ""
    note = f"; {result.validity.valid_fraction:.1%} of robot poses valid"
    if result.unscoreable:
        note += f"; unscoreable: {result.unscoreable_reason}"
    return note


def figure_specs(result: TrajectoryResult) -> list[ChartSpec]:
    """The figures of ``ertools score trajectory --plot DIR``."""
    off = result.offset_ns / 1e9
    return [
        ChartSpec(
            "trajectory_error",
            f"Robot vs GT position error ({result.config.association}, offset {off:+.3f} s)"
            + validity_note(result),
            lambda size: error_chart(result, size),
            (8.0, 4.0),
        ),
        ChartSpec(
            "trajectory_paths", "Robot estimate and GT", lambda size: paths_chart(result, size)
        ),
        ChartSpec(
            "trajectory_yaw_error",
            "Robot vs GT yaw error",
            lambda size: yaw_chart(result, size),
            (8.0, 3.5),
        ),
    ]
