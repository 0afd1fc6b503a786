"""FBM3@Work figures: each run's path in its run frame, the runs' errors, the d_min sweep."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ertools.report import units
from ertools.report.figures import FigureSpec, size_of, thin_path

MM = units.factor("length", "m")


def draw_run(run: Any, ax: Any) -> None:
    """Target and measured path in the run frame (mm); kept samples coloured by their error."""
    score = run.score
    if run.target_dense is not None:
        t = thin_path(np.asarray(run.target_dense) * MM, size_of(ax))
        ax.plot(t[:, 0], t[:, 1], color="black", lw=1.2, label=f"target ({run.spec})")
    if run.frame_xy is not None:
        m = thin_path(np.asarray(run.frame_xy) * MM, size_of(ax))
        ax.plot(m[:, 0], m[:, 1], color="0.65", lw=0.6, label="measured (every sample)")
    if score is not None:
        k = score.kept_frame * MM
        dots = ax.scatter(
            k[:, 0],
            k[:, 1],
            c=score.errors * MM,
            cmap="viridis",
            s=7,
            zorder=3,
            label=f"kept samples ({len(k)}, d_min {run.d_min * MM:g} mm)",
        )
        ax.figure.colorbar(dots, ax=ax, label=units.label("error", "length"), shrink=0.8)
        # a few error vectors: each kept point is compared with the target at its l/L
        step = max(1, len(k) // 25)
        tg = score.target * MM
        i = np.arange(step, len(k), step)
        # one line broken by NaN rows: one artist for every vector
        vectors = np.full((len(i), 3, 2), np.nan)
        vectors[:, 0], vectors[:, 1] = k[i, :2], tg[i, :2]
        flat = vectors.reshape(-1, 2)
        ax.plot(flat[:, 0], flat[:, 1], color="tab:red", lw=0.6, label="compared with target(l/L)")
        ax.scatter([0.0], [0.0], marker="s", color="tab:green", s=30, zorder=4, label="start")
        if run.reference_xy is not None:
            ref = score.frame.to_frame(np.asarray([run.reference_xy])) * MM
            ax.scatter(
                ref[:, 0], ref[:, 1], marker="^", color="tab:red", s=30, zorder=4, label="reference"
            )
    ax.set_xlabel(
        units.label("x in the run frame", "length")
        + ": origin at the start, x along reference -> start"
    )
    ax.set_ylabel(units.label("y in the run frame", "length"))
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, lw=0.3)
    ax.legend(loc="best", fontsize="small")


def draw_runs(result: Any, ax: Any) -> None:
    """distance_error per run (mm); the best run highlighted, unscored runs labelled."""
    best = result.best_run
    idx = [r.index for r in result.runs]
    values = [(r.distance_error or 0.0) * MM for r in result.runs]
    colors = ["tab:green" if r.index == best else "tab:blue" for r in result.runs]
    bars = ax.bar(idx, values, color=colors)
    for bar, r in zip(bars, result.runs, strict=True):
        if r.distance_error is None:
            label = f"{r.spec}\n{r.status}"
        else:
            label = f"{r.spec}\n{r.distance_error * MM:.2f}"
        ax.annotate(
            label,
            (bar.get_x() + bar.get_width() / 2, bar.get_height()),
            ha="center",
            va="bottom",
            fontsize="small",
        )
        floor = getattr(r, "shape_floor", None)
        if floor:
            ax.hlines(
                floor * MM,
                bar.get_x(),
                bar.get_x() + bar.get_width(),
                colors="0.3",
                linestyles=":",
                lw=1,
            )
    ax.set_xticks(idx)
    ax.set_xlabel("run")
    ax.set_ylabel(units.label("distance_error", "length"))
    ax.margins(y=0.2)
    ax.grid(True, axis="y", lw=0.3)


def draw_sweep(result: Any, ax: Any) -> None:
    """distance_error of each run over d_min; the d_min used and the one the noise suggests."""
    d = np.asarray(result.sweep_values) * MM
    for r in result.runs:
        ys = [np.nan if e is None else e * MM for _, e in r.sweep]
        if r.sweep:
            ax.plot(d, ys, marker="o", ms=3, label=f"run {r.index} ({r.spec})")
    ax.axvline(result.d_min * MM, color="0.3", ls="--", lw=1, label="d_min used")
    noise = result.noise
    if noise is not None and np.isfinite(noise.suggested_d_min):
        ax.axvline(
            noise.suggested_d_min * MM,
            color="tab:red",
            ls=":",
            lw=1,
            label=f"suggested ({noise.c:g} eps)",
        )
    ax.set_xlabel(units.label("d_min", "length"))
    ax.set_ylabel(units.label("distance_error", "length"))
    ax.grid(True, lw=0.3)
    ax.legend(loc="best", fontsize="small")


def _bind(draw: Callable[[Any, Any], None], item: Any) -> Callable[[Any], None]:
    return lambda ax: draw(item, ax)


def figure_specs(result: Any) -> list[FigureSpec]:
    """One figure per scored run, the runs' bar chart, and the sweep when there is one."""
    specs = [
        FigureSpec(
            f"fbm3w_run{r.index}",
            f"FBM3@Work run {r.index} ({r.spec}): distance_error {r.distance_error * MM:.3f} mm",
            _bind(draw_run, r),
            size=(8.0, 5.5),
        )
        for r in result.runs
        if r.score is not None
    ]
    specs.append(
        FigureSpec(
            "fbm3w_runs", "FBM3@Work distance_error per run", lambda ax: draw_runs(result, ax)
        )
    )
    if result.sweep_values:
        specs.append(
            FigureSpec(
                "fbm3w_d_min_sweep", "distance_error over d_min", lambda ax: draw_sweep(result, ax)
            )
        )
    return specs
