"""FBM3@Work figures: each run's path in its run frame, the runs' errors, the d_min sweep.

Each figure is a :class:`~ertools.views.chart.Chart` in millimetres, built for its size
(paths thinned to its pixels); reports write it as SVG (:mod:`ertools.report.svg`).
"""

from __future__ import annotations

from functools import partial
from typing import Any

import numpy as np

from ertools.benchmarks.common import gaps
from ertools.views import units
from ertools.views.chart import (
    COLOURS,
    CYCLE,
    Axis,
    Bars,
    Chart,
    ColourScale,
    Layer,
    Line,
    RefLine,
    Scatter,
    Text,
)
from ertools.views.spec import ChartSpec
from ertools.views.thinning import thin_path

MM = units.factor("length", "m")
RUN_SIZE = (8.0, 5.5)
VECTORS = 25  # about this many "compared with" vectors per run: enough to read, few to clutter


def run_chart(run: Any, size: tuple[float, float] = RUN_SIZE) -> Chart:
    """Target and measured path in the run frame (mm); kept samples coloured by their error,
    a few of them joined to the target point they are compared with; the GT's gaps on the
    path (:mod:`ertools.benchmarks.common.gaps`)."""
    score = run.score
    layers: list[Layer] = []
    if run.target_dense is not None:
        t = thin_path(np.asarray(run.target_dense) * MM, size)
        layers.append(Line(t[:, 0], t[:, 1], "#000000", 1.2, label=f"target ({run.spec})"))
    if run.frame_xy is not None:
        m = thin_path(np.asarray(run.frame_xy) * MM, size)
        layers.append(Line(m[:, 0], m[:, 1], "#a6a6a6", 0.6, label="measured (every sample)"))
    scale = None
    if score is not None:
        k = np.asarray(score.kept_frame) * MM
        errors = np.asarray(score.errors) * MM
        if len(errors):
            scale = ColourScale(
                units.label("error", "length"), float(np.min(errors)), float(np.max(errors))
            )
        layers.append(
            Scatter(
                k[:, 0],
                k[:, 1],
                values=errors,
                size=2.5,
                label=f"kept samples ({len(k)}, d_min {run.d_min * MM:g} mm)",
            )
        )
        # a few error vectors: each kept point is compared with the target at its l/L;
        # one line broken by NaN rows draws them all
        step = max(1, len(k) // VECTORS)
        tg = np.asarray(score.target) * MM
        i = np.arange(step, len(k), step)
        vectors = np.full((len(i), 3, 2), np.nan)
        vectors[:, 0], vectors[:, 1] = k[i, :2], tg[i, :2]
        flat = vectors.reshape(-1, 2)
        layers.append(
            Line(flat[:, 0], flat[:, 1], COLOURS["red"], 0.6, label="compared with target(l/L)")
        )
        layers.append(
            Scatter(np.zeros(1), np.zeros(1), COLOURS["green"], marker="s", size=4, label="start")
        )
        if run.reference_xy is not None:
            ref = score.frame.to_frame(np.asarray([run.reference_xy])) * MM
            layers.append(
                Scatter(
                    ref[:, 0], ref[:, 1], COLOURS["red"], marker="^", size=4.5, label="reference"
                )
            )
    layers += gaps.path_layers(run.gaps, MM)
    return Chart(
        tuple(layers),
        x=Axis(
            units.label("x in the run frame", "length")
            + ": origin at the start, x along reference -> start"
        ),
        y=Axis(units.label("y in the run frame", "length")),
        equal_aspect=True,
        colour_scale=scale,
        note=None if layers else "no path for this run",
    )


def runs_chart(result: Any) -> Chart:
    """distance_error per run (mm); the best run highlighted, unscored runs labelled, each
    run's GT valid fraction under its value, each shape's floor dotted over its bar."""
    best = result.best_run
    idx = np.array([r.index for r in result.runs], dtype=float)
    values = np.array([(r.distance_error or 0.0) * MM for r in result.runs])
    colours = tuple(COLOURS["green"] if r.index == best else COLOURS["blue"] for r in result.runs)
    layers: list[Layer] = [Bars(idx, values, 0.8, colours)]
    for x, v, r in zip(idx, values, result.runs, strict=True):
        if r.distance_error is None:
            text = f"{r.spec}\n{r.status}"
        else:
            text = f"{r.spec}\n{r.distance_error * MM:.2f}"
        if r.validity is not None:
            text += f"\n{r.validity.valid_fraction:.1%} valid"
        layers.append(Text(float(x), float(v), text, offset=(0.0, 3.0), anchor="middle"))
        floor = getattr(r, "shape_floor", None)
        if floor:
            layers.append(
                RefLine(floor * MM, "y", "#4d4d4d", 1.0, "dotted", lo=x - 0.4, hi=x + 0.4)
            )
    return Chart(
        tuple(layers),
        x=Axis("run", ticks=tuple((float(i), str(int(i))) for i in idx)),
        y=Axis(units.label("distance_error", "length"), include_zero=True),
        grid="y",
        legend=False,
    )


def sweep_chart(result: Any) -> Chart:
    """distance_error of each run over d_min; the d_min used and the one the noise suggests."""
    d = np.asarray(result.sweep_values, dtype=float) * MM
    layers: list[Layer] = []
    for n, r in enumerate(result.runs):
        if r.sweep:
            ys = np.array([np.nan if e is None else e * MM for _, e in r.sweep])
            colour = CYCLE[n % len(CYCLE)]
            layers.append(Line(d, ys, colour, 1.5, label=f"run {r.index} ({r.spec})", marker="o"))
    layers.append(RefLine(result.d_min * MM, "x", "#4d4d4d", 1.0, "dashed", "d_min used"))
    noise = result.noise
    if noise is not None and np.isfinite(noise.suggested_d_min):
        layers.append(
            RefLine(
                noise.suggested_d_min * MM,
                "x",
                COLOURS["red"],
                1.0,
                "dotted",
                f"suggested ({noise.c:g} eps)",
            )
        )
    return Chart(
        tuple(layers),
        x=Axis(units.label("d_min", "length")),
        y=Axis(units.label("distance_error", "length")),
    )


def run_title(run: Any) -> str:
    """``FBM3@Work run 1 (line): distance_error 4.210 mm; GT 97.3% valid`` or, for a run the
    valid data cannot score, ``...: unscoreable: <reason>``."""
    head = f"FBM3@Work run {run.index} ({run.spec})"
    valid = gaps.valid_text(run.validity)
    if run.score is None:
        return f"{head}: unscoreable: {run.unscoreable_reason}" + (f"; {valid}" if valid else "")
    return f"{head}: distance_error {run.distance_error * MM:.3f} mm" + (
        f"; {valid}" if valid else ""
    )


def figure_specs(result: Any) -> list[ChartSpec]:
    """One figure per scored or unscoreable run (its path and gaps), the runs' bar chart, and
    the sweep when there is one."""
    specs = [
        ChartSpec(f"fbm3w_run{r.index}", run_title(r), partial(run_chart, r), RUN_SIZE)
        for r in result.runs
        if r.score is not None or (r.status == "unscoreable" and r.frame_xy is not None)
    ]
    specs.append(
        ChartSpec("fbm3w_runs", "FBM3@Work distance_error per run", lambda size: runs_chart(result))
    )
    if result.sweep_values:
        specs.append(
            ChartSpec(
                "fbm3w_d_min_sweep", "distance_error over d_min", lambda size: sweep_chart(result)
            )
        )
    return specs
