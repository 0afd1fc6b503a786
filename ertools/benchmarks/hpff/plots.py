"""HPFF's figures: the following distance over the run with the desired distance and the
range, and the robot's and the person's tracks. Each a :class:`~ertools.views.chart.Chart`."""

from __future__ import annotations

from typing import Any

import numpy as np

from ertools.views import units
from ertools.views.chart import COLOURS, Axis, Chart, Layer, Line, RefLine, Scatter
from ertools.views.spec import ChartSpec
from ertools.views.thinning import thin_path

MM = units.factor("length", "m")
TRACK_SIZE = (7.0, 6.0)


def distance_chart(result: Any) -> Chart:
    """The sampled distance (dots), the samples not measured (red, on the axis), the desired
    distance and the range."""
    s = result.samples
    t = (s.t_ns - result.t_start_ns) / 1e9
    layers: list[Layer] = []
    ok = s.measured
    if ok.any():
        layers.append(
            Line(
                t[ok],
                s.distance[ok] * MM,
                COLOURS["blue"],
                1.0,
                label="following distance",
                marker="o",
                marker_size=2.0,
            )
        )
    if (~ok).any():
        layers.append(
            Scatter(
                t[~ok],
                np.zeros(int((~ok).sum())),
                COLOURS["red"],
                marker="x",
                size=4.0,
                label="not measured",
            )
        )
    layers.append(RefLine(result.desired * MM, "y", COLOURS["green"], label="desired distance"))
    layers.append(RefLine(result.minimum * MM, "y", "#8c8c8c", dash="dashed", label="range"))
    layers.append(RefLine(result.maximum * MM, "y", "#8c8c8c", dash="dashed"))
    return Chart(
        tuple(layers),
        x=Axis(units.label("time from the benchmark's start", "time")),
        y=Axis(units.label("robot-person distance", "length"), include_zero=True),
        grid="y",
    )


def track_chart(result: Any, size: tuple[float, float] = TRACK_SIZE) -> Chart:
    """The robot's and the person's marker sets on the testbed floor."""
    layers: list[Layer] = []
    for (_, xy), colour, label in (
        (result.tracks[0], COLOURS["blue"], "robot marker set"),
        (result.tracks[1], COLOURS["orange"], "person (cap)"),
    ):
        path = thin_path(np.asarray(xy, dtype=float).reshape(-1, 2), size)
        if len(path):
            layers.append(Line(path[:, 0] * MM, path[:, 1] * MM, colour, 1.0, label=label))
    return Chart(
        tuple(layers),
        x=Axis(units.label("x in the testbed frame", "length")),
        y=Axis(units.label("y in the testbed frame", "length")),
        equal_aspect=True,
    )


def figure_specs(result: Any) -> list[ChartSpec]:
    """The distance and the tracks figures of an ``HpffResult``."""
    verdict = "" if result.passed is None else ("; passed" if result.passed else "; failed")
    return [
        ChartSpec(
            "hpff_distance",
            f"HPFF following distance (--rules {result.rules}{verdict})",
            lambda size: distance_chart(result),
            (7.0, 4.5),
        ),
        ChartSpec(
            "hpff_tracks",
            "HPFF robot and person tracks",
            lambda size: track_chart(result, size),
            TRACK_SIZE,
        ),
    ]
