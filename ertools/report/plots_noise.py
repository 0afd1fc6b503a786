"""Mocap noise figure: the distribution of the distance between consecutive measurements."""

from __future__ import annotations

from typing import Any

import numpy as np

from ertools.report import units
from ertools.report.figures import FigureSpec

MM = units.factor("length", "m")


def draw_histogram(result: Any, ax: Any) -> None:
    """Histogram in the 2015 tool's bins; epsilon, percentiles and the suggested d_min."""
    d = np.asarray(result.distances) * MM
    if d.size:
        top = max(float(np.max(d)), result.suggested_d_min * MM) * 1.05
        bins = np.arange(0.0, top + result.bin * MM, result.bin * MM)
        ax.hist(
            d,
            bins=bins,
            color="tab:blue",
            alpha=0.8,
            label=f"{d.size} differing pairs ({result.lost} lost)",
        )
        ax.axvline(
            result.epsilon * MM,
            color="black",
            lw=1.2,
            label=f"epsilon {result.epsilon * MM:.3f} mm",
        )
        for key, style in (("95", "--"), ("99", ":")):
            v = result.percentiles[key] * MM
            ax.axvline(v, color="0.4", ls=style, lw=1, label=f"p{key} {v:.3f} mm")
        ax.axvline(
            result.suggested_d_min * MM,
            color="tab:red",
            lw=1.5,
            label=f"suggested d_min {result.suggested_d_min * MM:.3f} mm ({result.c:g} eps)",
        )
    ax.set_xlabel(units.label("distance between consecutive measurements", "length"))
    ax.set_ylabel("pairs")
    ax.grid(True, lw=0.3)
    ax.legend(loc="best", fontsize="small")


def figure_specs(result: Any) -> list[FigureSpec]:
    scope = "stationary phases" if result.stationary else "whole recording"
    return [
        FigureSpec(
            "noise",
            f"Mocap noise ({scope}, {result.samples} samples)",
            lambda ax: draw_histogram(result, ax),
        )
    ]
