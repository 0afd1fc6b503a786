"""What the figures of a navigation benchmark draw: poses with their headings (the waypoints,
the robot where it was measured) and the errors per waypoint (the distance error in bars on
the left axis, mm, the orientation error on the right, deg, dashed lines at the accuracies
they are counted against, and a word where a waypoint has no error)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ertools.views import units
from ertools.views.chart import COLOURS, Arrows, Axis, Bars, Chart, Layer, RefLine, Scatter, Text

MM = units.factor("length", "m")
DEG = units.factor("angle", "rad")
ARROW = 0.25  # metres: the length of a heading arrow


def pose_layers(xyt: np.ndarray, colour: str, label: str, marker: Any) -> list[Layer]:
    """Markers at the (x, y, heading) rows, in mm, and an arrow along each heading."""
    x, y = xyt[:, 0] * MM, xyt[:, 1] * MM
    return [
        Scatter(x, y, colour, marker=marker, size=5.0, label=label),
        Arrows(
            x, y, x + np.cos(xyt[:, 2]) * ARROW * MM, y + np.sin(xyt[:, 2]) * ARROW * MM, colour
        ),
    ]


def pose_errors_chart(
    numbers: Sequence[int],
    distance: Sequence[float | None],
    orientation: Sequence[float | None],
    accuracies: tuple[float | None, float | None],
    unscored: Sequence[str],
    what: str,
) -> Chart:
    """Each waypoint's errors in metres and radians (None: none) at its number on the x axis
    (``what``: ``waypoint``, ``segment``); ``accuracies`` the position and orientation
    accuracy (None: not computed); ``unscored`` the word shown where a distance is None (or NaN)."""
    idx = np.array(numbers, dtype=float)
    dist = np.array([np.nan if v is None else v for v in distance], dtype=float)
    ori = np.array([np.nan if v is None else v for v in orientation], dtype=float)
    blue, orange = COLOURS["blue"], COLOURS["orange"]
    layers: list[Layer] = [
        Bars(idx - 0.2, dist * MM, 0.4, (blue,), "distance error"),
        Bars(idx + 0.2, ori * DEG, 0.4, (orange,), "orientation error", side="right"),
    ]
    position, heading = accuracies
    if position is not None:
        layers.append(RefLine(position * MM, "y", blue, label="position accuracy"))
    if heading is not None:
        layers.append(
            RefLine(heading * DEG, "y", orange, label="orientation accuracy", side="right")
        )
    layers += [
        Text(float(i), 0.0, word, COLOURS["red"], offset=(0.0, 3.0), anchor="middle")
        for i, missing, word in zip(idx, np.isnan(dist), unscored, strict=True)
        if missing
    ]
    return Chart(
        tuple(layers),
        x=Axis(what, ticks=tuple((float(i), str(int(i))) for i in idx)),
        y=Axis(units.label("distance error", "length"), colour=blue, include_zero=True),
        right=Axis(units.label("orientation error", "angle"), colour=orange, include_zero=True),
        grid="y",
    )
