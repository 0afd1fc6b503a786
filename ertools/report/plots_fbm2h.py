"""FBM2@Home figures: the robot's path with the waypoints, and the per-waypoint errors."""

from __future__ import annotations

from typing import Any

import numpy as np

from ertools.report import units
from ertools.report.figures import FigureSpec, size_of, thin_path

ARROW = 0.25  # metres: length of the heading arrows on the path figure


def _arrows(ax: Any, xyt: np.ndarray, color: str, label: str, marker: str) -> None:
    ax.scatter(xyt[:, 0], xyt[:, 1], color=color, marker=marker, s=60, zorder=3, label=label)
    ax.quiver(
        xyt[:, 0],
        xyt[:, 1],
        np.cos(xyt[:, 2]),
        np.sin(xyt[:, 2]),
        color=color,
        angles="xy",
        scale_units="xy",
        scale=1.0 / ARROW,
        width=0.006,
        zorder=3,
    )


def draw_path(result: Any, ax: Any) -> None:
    """Path on the testbed frame, waypoints with target headings, reached poses."""
    path = thin_path(result.path_xyyaw, size_of(ax))
    if len(path):
        ax.plot(path[:, 0], path[:, 1], color="0.55", lw=1.0, label="robot path (GT)")
    targets = np.array([s.target for s in result.segments], dtype=float)
    _arrows(ax, targets, "tab:blue", "waypoint (target heading)", "o")
    reached = np.array([s.robot for s in result.segments if s.robot is not None], dtype=float)
    if len(reached):
        _arrows(ax, reached, "tab:red", "robot when reached", "x")
    for s in result.segments:
        ax.annotate(
            str(s.index),
            s.target[:2],
            textcoords="offset points",
            xytext=(6, 6),
            color="tab:blue",
        )
    if result.goal.starting_pose is not None:
        sx, sy, _ = result.goal.starting_pose
        ax.scatter([sx], [sy], color="tab:green", marker="s", s=40, label="starting pose")
    ax.set_aspect("equal", adjustable="datalim")
    # Drawn in metres (the results' unit), read in mm like every length of the report.
    units.set_axis(ax, "x", "x in the testbed frame", "length", "m")
    units.set_axis(ax, "y", "y in the testbed frame", "length", "m")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")


def draw_errors(result: Any, ax: Any) -> None:
    """Distance error (bars, left axis) and orientation error (right axis) per waypoint."""
    idx = np.array([s.index for s in result.segments])
    dist = np.array(
        [np.nan if s.distance_error is None else s.distance_error for s in result.segments]
    )
    ori = np.array(
        [np.nan if s.orientation_error is None else s.orientation_error for s in result.segments]
    )
    mm = units.factor("length", "m")
    deg = units.factor("angle", "rad")
    ax.bar(idx - 0.2, dist * mm, width=0.4, color="tab:blue", label="distance error")
    ax.set_xlabel("waypoint")
    ax.set_ylabel(units.label("distance error", "length"), color="tab:blue")
    ax.set_xticks(idx)
    right = ax.twinx()
    right.bar(idx + 0.2, ori * deg, width=0.4, color="tab:orange", label="orientation error")
    right.set_ylabel(units.label("orientation error", "angle"), color="tab:orange")
    if result.position_accuracy is not None:
        ax.axhline(result.position_accuracy * mm, color="tab:blue", ls="--", lw=1)
    if result.orientation_accuracy is not None:
        right.axhline(result.orientation_accuracy * deg, color="tab:orange", ls="--", lw=1)
    for i in idx[np.isnan(dist)]:
        ax.annotate("no score", (i, 0), ha="center", va="bottom", color="tab:red")
    ax.grid(True, axis="y", alpha=0.3)


def figure_specs(result: Any) -> list[FigureSpec]:
    """The path and the errors figures of an ``Fbm2hResult``."""
    mode = "2015 orientation" if result.orientation_2015 else "orientation wrapped to [0, pi]"
    return [
        FigureSpec(
            "fbm2h_path",
            f"FBM2@Home path and waypoints (reached: {result.reached_method})",
            lambda ax: draw_path(result, ax),
            (7.0, 6.0),
        ),
        FigureSpec(
            "fbm2h_errors",
            f"Errors per waypoint (dashed: accuracy; {mode})",
            lambda ax: draw_errors(result, ax),
            (7.0, 4.5),
        ),
    ]
