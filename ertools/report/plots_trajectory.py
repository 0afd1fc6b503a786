"""Figures of a trajectory result: the error over time and the two paths overlaid.

Each drawing function takes a matplotlib ``Axes`` and the result; nothing global is touched.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ertools.benchmarks.trajectory.association import GAP, TRACKING_LOST, UNCOVERED
from ertools.report import units
from ertools.report.figures import FigureSpec, size_of, thin_path, thin_series

if TYPE_CHECKING:
    from ertools.benchmarks.trajectory.result import TrajectoryResult


def draw_error_over_time(ax: Any, result: TrajectoryResult) -> None:
    """Position error (mm) per robot pose; gaps and tracking losses marked on the time axis."""

    m = result.matched
    if len(m.t_ns) == 0:
        return
    t = (m.t_ns - m.t_ns[0]) / 1e9
    mm = units.factor("length", "m")
    shown = thin_series(t, m.position_error, size_of(ax)[0])
    ax.plot(t[shown], m.position_error[shown] * mm, lw=0.8, color="C0", label="position error")
    for code, color, label in (
        (GAP, "C1", "GT gap"),
        (TRACKING_LOST, "C3", "tracking lost"),
        (UNCOVERED, "0.5", "no GT"),
    ):
        sel = m.status == code
        if sel.any():
            ax.plot(t[sel], np.zeros(int(sel.sum())), "|", ms=10, color=color, label=label)
    if result.metrics is not None:
        ax.axhline(
            result.metrics.position_error * mm,
            color="C2",
            lw=0.8,
            ls="--",
            label=f"mean {result.metrics.position_error * mm:.1f} mm",
        )
    ax.set_xlabel(units.label("time since the first robot pose", "time"))
    ax.set_ylabel(units.label("position error", "length"))
    ax.legend(loc="upper right", fontsize="small")
    ax.grid(True, alpha=0.3)


def draw_paths(ax: Any, result: TrajectoryResult) -> None:
    """The robot's estimate and the GT, seen from above (drawn in metres, read in mm)."""
    gt = thin_path(result.gt_path.xyz, size_of(ax))
    ax.plot(gt[:, 0], gt[:, 1], lw=1.0, color="0.4", label="ground truth")
    r = thin_path(result.robot.xyz, size_of(ax))
    ax.plot(r[:, 0], r[:, 1], ".", ms=2.5, color="C0", label="robot estimate")
    units.set_axis(ax, "x", "x", "length", "m")
    units.set_axis(ax, "y", "y", "length", "m")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(loc="best", fontsize="small")
    ax.grid(True, alpha=0.3)


def draw_yaw_error(ax: Any, result: TrajectoryResult) -> None:
    """Wrapped yaw error (degrees) per robot pose."""
    m = result.matched
    if len(m.t_ns) == 0:
        return
    t = (m.t_ns - m.t_ns[0]) / 1e9
    shown = thin_series(t, m.yaw_error, size_of(ax)[0])
    ax.plot(t[shown], m.yaw_error[shown] * units.factor("angle", "rad"), lw=0.8, color="C4")
    ax.set_xlabel(units.label("time since the first robot pose", "time"))
    ax.set_ylabel(units.label("|yaw error|", "angle"))
    ax.grid(True, alpha=0.3)


def figure_specs(result: TrajectoryResult) -> list[FigureSpec]:
    """The figures of ``ertools score trajectory --plot DIR``."""
    off = result.offset_ns / 1e9
    return [
        FigureSpec(
            "trajectory_error",
            f"Robot vs GT position error ({result.config.association}, offset {off:+.3f} s)",
            lambda ax: draw_error_over_time(ax, result),
            (8.0, 4.0),
        ),
        FigureSpec("trajectory_paths", "Robot estimate and GT", lambda ax: draw_paths(ax, result)),
        FigureSpec(
            "trajectory_yaw_error",
            "Robot vs GT yaw error",
            lambda ax: draw_yaw_error(ax, result),
            (8.0, 3.5),
        ),
    ]
