"""The FBM2@Home figures draw what the result holds."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

from ertools.benchmarks.fbm2h.goal import GoalList
from ertools.benchmarks.fbm2h.pipeline import compute
from ertools.benchmarks.fbm2h.runs import ReachedMoments
from ertools.configs.transform import identity_transform
from ertools.report.figures import figure_specs, save_figures
from ertools.streams import PoseStream
from tests.helpers import svg_figure

pytestmark = pytest.mark.slow

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
    # A report writes both as SVG, without matplotlib.
    paths = save_figures(specs, tmp_path, None)
    assert [p.name for p in paths] == ["fbm2h_path.svg", "fbm2h_errors.svg"]
    path_fig = svg_figure.read(paths[0])
    # Read in mm like every length of the report.
    assert path_fig.texts("xlabel") == ["x in the testbed frame (mm)"]
    assert path_fig.texts("ylabel") == ["y in the testbed frame (mm)"]
    # The path line is the GT path: x from 0 to 3 m on y = 0, read back through the ticks
    # (to the 0.1 px the file is written at: ~1 mm here).
    line, count = path_fig.polyline("robot path (GT)")
    assert count == len(line) >= 2
    assert np.allclose(line[0], [0.0, 0.0], atol=2.0)
    assert np.allclose(line[-1], [3000.0, 0.0], atol=2.0)
    assert np.allclose(line[:, 1], 0.0, atol=2.0)
    # Both waypoints are marked and numbered, each with its heading arrow.
    assert len(path_fig.series("waypoint (target heading)").findall("s:circle", svg_figure.NS)) == 2
    assert [t for t in path_fig.texts("label")] == ["0", "1"]
    assert "starting pose" in path_fig.labels()

    errors = svg_figure.read(paths[1])
    # Distance bars in mm (every length of the report): 0.1 m = 100 mm at waypoint 0 (robot
    # at (1, 0)), 0 at waypoint 1; orientation errors on their own scale, in degrees.
    assert errors.texts("ylabel") == ["distance error (mm)"]
    assert errors.texts("rlabel") == ["orientation error (deg)"]
    bars = errors.series("distance error").findall("s:rect", svg_figure.NS)
    ay, _ = errors.scale("y")
    heights = [abs(ay) * float(b.get("height", "nan")) for b in bars]
    assert np.allclose(heights, [100.0, 0.0], atol=1.0)

    # matplotlib draws the same charts (PNG on request, notebooks).
    fig = Figure()
    ax = fig.add_subplot()
    specs[1].draw(ax)
    heights = [p.get_height() for p in ax.patches]
    assert np.allclose(heights, [0.1 * 1000.0, 0.0])
    assert ax.get_ylabel() == "distance error (mm)"
    pngs = save_figures(specs, tmp_path / "png")
    assert all(p.suffix == ".png" and p.stat().st_size > 1000 for p in pngs)


def test_path_figure_draws_the_gt_gaps(tmp_path: Path) -> None:
    # GT at 10 Hz on y = 0.2 x^2 (x = 1 m/s * t), identity transform (the robot is the marker
    # set); the frames at 1.3, 1.4 and 1.5 s removed: a 0.4 s gap inside segment 1 (1 s ... 2 s)
    t = np.arange(0, 3 * S + 1, S // 10, dtype=np.int64)
    t = t[(t < 1.25 * S) | (t > 1.55 * S)]
    x = t / S
    xyz = np.column_stack([x, 0.2 * x**2, np.zeros_like(x)])
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (t.size, 1))
    marker = PoseStream(t, xyz, quat, "world", "robot_at_home", "test")
    goal = GoalList(((1.0, 0.2, 0.0), (2.0, 0.8, 0.0)), (0.0, 0.0, 0.0), source="g")
    moments = ReachedMoments("timing", np.array([0, S]), np.array([S, 2 * S]), ("", ""))
    result = compute(goal, identity_transform(), marker, moments)
    (spec, _) = figure_specs(result)
    (path,) = save_figures([spec], tmp_path, None)
    fig = svg_figure.read(path)
    xy, n = fig.polyline("GT gap")
    # from the last sample before the hole (1.2 s) to the first after it (1.6 s), in mm; the
    # figure is written to 0.1 px, a pixel is ~5 mm here
    tol = max(abs(fig.scale("x")[0]), abs(fig.scale("y")[0]))
    assert n == 2
    assert np.allclose(xy, [[1200.0, 0.2 * 1.2**2 * 1000], [1600.0, 0.2 * 1.6**2 * 1000]], atol=tol)
    # segment 1's window (1 s ... 2 s) holds 8 of its 11 frames; segment 0's 11 all arrived
    title = " ".join(fig.texts("title"))
    assert title.endswith(f"GT {19 / 22:.1%} valid (waypoint 1: {8 / 11:.1%})")
    # matplotlib draws it too (a --plot .png)
    (png,) = save_figures([spec], tmp_path / "png")
    assert png.stat().st_size > 1000
