"""Mocap noise figure: the distribution of the distance between consecutive measurements, as
a :class:`~ertools.views.chart.Chart` in mm (reports write it as SVG)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ertools.views import units
from ertools.views.chart import COLOURS, Axis, Bars, Chart, Layer, RefLine
from ertools.views.spec import ChartSpec

MM = units.factor("length", "m")


def histogram_chart(result: Any) -> Chart:
    """Histogram in the 2015 tool's bins; epsilon, percentiles and the suggested d_min."""
    d = np.asarray(result.distances) * MM
    layers: list[Layer] = []
    if d.size:
        top = max(float(np.max(d)), result.suggested_d_min * MM) * 1.05
        width = result.bin * MM
        edges = np.arange(0.0, top + width, width)
        counts, edges = np.histogram(d, bins=edges)
        layers.append(
            Bars(
                (edges[:-1] + edges[1:]) / 2,
                counts.astype(float),
                width,
                (COLOURS["blue"],),
                f"{d.size} differing pairs ({result.lost} lost)",
            )
        )
        eps = result.epsilon * MM
        layers.append(RefLine(eps, "x", "#000000", 1.2, "solid", f"epsilon {eps:.3f} mm"))
        for key, dash in (("95", "dashed"), ("99", "dotted")):
            v = result.percentiles[key] * MM
            layers.append(RefLine(v, "x", "#666666", 1.0, dash, f"p{key} {v:.3f} mm"))  # type: ignore[arg-type]
        s = result.suggested_d_min * MM
        layers.append(
            RefLine(
                s,
                "x",
                COLOURS["red"],
                1.5,
                "solid",
                f"suggested d_min {s:.3f} mm ({result.c:g} eps)",
            )
        )
    return Chart(
        tuple(layers),
        x=Axis(units.label("distance between consecutive measurements", "length")),
        y=Axis("pairs", include_zero=True),
        note=None if layers else "no differing pairs",
    )


def figure_specs(result: Any) -> list[ChartSpec]:
    scope = "stationary phases" if result.stationary else "whole recording"
    return [
        ChartSpec(
            "noise",
            f"Mocap noise ({scope}, {result.samples} samples)",
            lambda size: histogram_chart(result),
        )
    ]
