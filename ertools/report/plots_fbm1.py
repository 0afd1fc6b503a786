"""FBM1 figures: per-run errors and scores, ground truth vs answered poses on the table.

Each draw function takes a matplotlib ``Axes``; nothing here imports pyplot.
"""

from __future__ import annotations

import math
from typing import Any

from ertools.benchmarks import registry
from ertools.report import units
from ertools.report.figures import FigureSpec

# Colours by answer quality (colour-blind safe pairs).
_RIGHT = "#1b9e77"
_WRONG_INSTANCE = "#e6ab02"
_WRONG_CLASS = "#d95f02"
_NONE = "#999999"


def _colour(run: Any) -> str:
    if run.answer is None:
        return _NONE
    if not run.class_ok:
        return _WRONG_CLASS
    return _RIGHT if run.instance_ok else _WRONG_INSTANCE


def _legend(ax: Any) -> None:
    # lazy: matplotlib only when a figure is drawn (~0.3 s to import)
    from matplotlib.patches import Patch

    ax.legend(
        handles=[
            Patch(color=_RIGHT, label="class and instance right"),
            Patch(color=_WRONG_INSTANCE, label="instance wrong"),
            Patch(color=_WRONG_CLASS, label="class wrong"),
            Patch(color=_NONE, label="no answer / not scored"),
        ],
        fontsize="small",
        loc="best",
    )


def _draw_scores(result: Any) -> Any:
    def draw(ax: Any) -> None:
        runs = result.runs
        xs = [r.index for r in runs]
        scores = [r.pose_score if r.pose_score is not None else 0.0 for r in runs]
        ax.bar(xs, scores, color=[_colour(r) for r in runs])
        for r in runs:
            if r.status in ("failed", "aborted"):
                ax.text(r.index, 0.02, r.status, rotation=90, ha="center", va="bottom")
        if result.totals.pose_score is not None:
            ax.axhline(result.totals.pose_score, color="k", lw=1, ls="--", label="mean")
        ax.set_xlabel("run")
        ax.set_ylabel("pose score (1 - t/2 - r/2)")
        ax.set_xticks(xs)
        ax.set_ylim(min(0.0, *scores) - 0.05, 1.05)
        _legend(ax)

    return draw


def _draw_errors(result: Any) -> Any:
    def draw(ax: Any) -> None:
        runs = [r for r in result.runs if r.errors is not None]
        xs = [r.index for r in runs]
        trans_mm = [r.errors.trans_error_m * units.factor("length", "m") for r in runs]
        theta = [abs(r.errors.theta_error_deg) for r in runs]
        width = 0.4
        ax.bar(
            [x - width / 2 for x in xs],
            trans_mm,
            width,
            color="#7570b3",
            label=units.label("|dxy|", "length"),
        )
        ax.set_xlabel("run")
        ax.set_ylabel(units.label("translation error", "length"))
        ax.set_yscale("symlog", linthresh=10.0)
        ax.set_xticks([r.index for r in result.runs])
        twin = ax.twinx()
        twin.bar(
            [x + width / 2 for x in xs],
            theta,
            width,
            color="#e7298a",
            label=units.label("|dtheta|", "angle"),
        )
        twin.set_ylabel(units.label("theta error", "angle"))
        twin.set_ylim(0, max([180.0 * 1.05, *theta]) if any(t > 20 for t in theta) else 20.0)
        lines = ax.get_legend_handles_labels()
        more = twin.get_legend_handles_labels()
        ax.legend(lines[0] + more[0], lines[1] + more[1], fontsize="small", loc="upper left")

    return draw


def _draw_table(result: Any) -> Any:
    def draw(ax: Any) -> None:
        arrow = 0.04  # metres: heading arrows a few cm long on a ~1 m table
        for r in result.runs:
            g = r.gt
            if g is None:
                continue
            ax.plot(*g.board_xy, marker="s", ms=5, color="#bbbbbb", ls="none")
            ax.annotate(
                "",
                xy=(g.x + arrow * math.cos(g.yaw), g.y + arrow * math.sin(g.yaw)),
                xytext=(g.x, g.y),
                arrowprops={"arrowstyle": "->", "color": "k", "lw": 1.2},
            )
            ax.plot(g.x, g.y, "o", color="k", ms=4)
            ax.text(g.x, g.y, f" {r.index}", fontsize="small", va="bottom")
            a = r.answer
            if a is None:
                continue
            th = math.radians(a.theta_deg)
            colour = _colour(r)
            ax.plot(a.x, a.y, "x", color=colour, ms=7, mew=2)
            ax.annotate(
                "",
                xy=(a.x + arrow * math.cos(th), a.y + arrow * math.sin(th)),
                xytext=(a.x, a.y),
                arrowprops={"arrowstyle": "->", "color": colour, "lw": 1.2},
            )
            ax.plot([g.x, a.x], [g.y, a.y], color=colour, lw=0.6, ls=":")
        ax.plot([0, 0.1], [0, 0], color="r", lw=2)
        ax.plot([0, 0], [0, 0.1], color="g", lw=2)
        ax.set_aspect("equal", adjustable="datalim")
        # Drawn in metres (the results' unit), read in mm like every length of the report.
        units.set_axis(ax, "x", "x in the table frame", "length", "m")
        units.set_axis(ax, "y", "y in the table frame", "length", "m")
        ax.grid(True, lw=0.3)
        # lazy: matplotlib only when a figure is drawn (~0.3 s to import)
        from matplotlib.lines import Line2D

        ax.legend(
            handles=[
                Line2D([], [], marker="o", color="k", ls="none", label="ground truth"),
                Line2D([], [], marker="x", color=_RIGHT, ls="none", mew=2, label="answer"),
                Line2D([], [], marker="s", color="#bbbbbb", ls="none", label="board"),
            ],
            fontsize="small",
            loc="best",
        )

    return draw


def figure_specs(result: Any) -> list[FigureSpec]:
    """The FBM1 figures of a result (``Fbm1Result``)."""
    label = registry.get(result.name).title
    return [
        FigureSpec(
            f"{result.name}_pose_scores", f"{label}: pose score per run", _draw_scores(result)
        ),
        FigureSpec(
            f"{result.name}_errors",
            f"{label}: translation and theta errors",
            _draw_errors(result),
        ),
        FigureSpec(
            f"{result.name}_table",
            f"{label}: ground truth (black) vs answers on the table",
            _draw_table(result),
            size=(7.0, 7.0),
        ),
    ]
