"""The FBM2@Home figures draw what the result holds."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ertools.benchmarks.fbm2h.benchmark import compute
from ertools.benchmarks.fbm2h.segments import ReachedMoments
from ertools.configs.goal import GoalList
from ertools.configs.transform import identity_transform
from ertools.report.figures import figure_specs, save_figures
from ertools.streams import PoseStream

S = 1_000_000_000


def _result() -> object:
    t = np.arange(0, 3 * S + 1, S // 10, dtype=np.int64)
    x = t / S  # 1 m/s along x
    xyz = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (t.size, 1))
    marker = PoseStream(t, xyz, quat, "world", "robot_at_home", "test")
    goal = GoalList(((1.0, 0.1, 0.0), (2.0, 0.0, math.pi / 2)), (0.0, 0.0, 0.0), source="g")
    moments = ReachedMoments("timing", np.array([0, S]), np.array([S, 2 * S]), ("", ""))
    return compute(goal, identity_transform(), marker, moments)


def test_path_and_errors_figures(tmp_path: Path) -> None:
    result = _result()
    specs = figure_specs(result)
    assert [s.name for s in specs] == ["fbm2h_path", "fbm2h_errors"]
    fig = Figure()
    ax = fig.add_subplot()
    specs[0].draw(ax)
    # The path line is the GT path: x from 0 to 3 m on y = 0.
    line = ax.lines[0].get_xydata()
    assert np.allclose(line[0], [0.0, 0.0])
    assert np.allclose(line[-1], [3.0, 0.0])
    fig2 = Figure()
    ax2 = fig2.add_subplot()
    specs[1].draw(ax2)
    # Distance bars in mm (every length of the report): 0.1 m = 100 mm at waypoint 0 (robot
    # at (1, 0)), 0 at waypoint 1.
    heights = [p.get_height() for p in ax2.patches]
    assert np.allclose(heights, [0.1 * 1000.0, 0.0])
    assert ax2.get_ylabel() == "distance error (mm)"
    paths = save_figures(specs, tmp_path)
    assert all(p.stat().st_size > 1000 for p in paths)
