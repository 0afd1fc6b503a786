"""Trajectory validity and the unscoreable verdict: a 10 Hz robot log 1 cm beside a 120 Hz GT
with a hole cut by hand; which robot poses fall in it follows from the stamps alone."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ertools.benchmarks.trajectory.comparison import score_streams
from ertools.benchmarks.trajectory.config import SETTINGS_2015, TrajectoryConfig
from ertools.benchmarks.trajectory.validity import MIN_VALID_FRACTION
from ertools.cli.main import main
from ertools.geometry import quat_from_yaw
from ertools.report.figures import figure_specs, render
from ertools.streams import PoseStream
from tests.helpers import svg_figure

T0 = 1_448_013_600 * 1_000_000_000
S = 1_000_000_000


def _streams(hole_s: tuple[float, float]) -> tuple[PoseStream, PoseStream]:
    """GT at 120 Hz over 10 s without the samples strictly inside ``hole_s``; the robot at 10 Hz
    (0.0 ... 9.9 s), 1 cm to the GT's left."""
    t_gt = T0 + np.round(np.arange(1201) * S / 120).astype(np.int64)
    keep = ~((t_gt > T0 + hole_s[0] * S) & (t_gt < T0 + hole_s[1] * S))
    t_gt = t_gt[keep]
    x_gt = 0.3 * (t_gt - T0) / S
    gt = PoseStream(
        t_gt,
        np.column_stack([x_gt, np.zeros_like(x_gt), np.zeros_like(x_gt)]),
        quat_from_yaw(np.zeros(len(t_gt))),
        "world",
        "body",
        "gt",
    )
    t_r = T0 + np.arange(100, dtype=np.int64) * (S // 10)
    x_r = 0.3 * (t_r - T0) / S
    robot = PoseStream(
        t_r,
        np.column_stack([x_r, np.full_like(x_r, 0.01), np.zeros_like(x_r)]),
        quat_from_yaw(np.zeros(100)),
        "map",
        "robot",
        "robot",
    )
    return robot, gt


def test_a_short_hole_is_counted_and_scored() -> None:
    robot, gt = _streams((1.05, 3.05))  # robot poses 1.1 ... 3.0 s: 20 in the hole
    result = score_streams(robot, gt, TrajectoryConfig())
    d = result.to_dict()
    assert d["compared"] == 80
    assert d["valid_fraction"] == 0.8
    assert d["invalid_samples"] == {"gap": 20}
    assert d["position_error"] == pytest.approx(0.01, abs=1e-12)
    assert "status" not in d and "unscoreable_reason" not in d
    assert result.validity_lines() == ["validity: trajectory 80.0% valid (1 gap 2.10 s at 1.00 s)"]


def test_a_long_hole_is_unscoreable_unless_2015() -> None:
    robot, gt = _streams((1.05, 7.05))  # 60 of the 100 robot poses in the hole
    assert MIN_VALID_FRACTION > 40 / 100
    result = score_streams(robot, gt, TrajectoryConfig())
    d = result.to_dict()
    assert d["position_error"] is None and d["rmse"] is None
    assert d["status"] == "unscoreable"
    assert d["unscoreable_reason"] == (
        "only 40 of the 100 robot poses inside the GT have a valid GT pose (60 gap); at least "
        "50% are needed"
    )
    assert not result.nothing_scored and result.failures == ()
    assert any("[trajectory.unscoreable]" in str(x) for x in result.deviations)
    assert result.validity_lines()[0].endswith(f"unscoreable: {d['unscoreable_reason']}")
    assert result.tables()["summary"][0]["status"] == "unscoreable"
    # the 2015 script averaged what it had: the same pairs, a warning
    scored = score_streams(robot, gt, TrajectoryConfig(unscoreable="2015")).to_dict()
    assert scored["position_error"] == pytest.approx(0.01, abs=1e-12)
    assert scored["compared"] == 40 and "status" not in scored
    assert any(
        w.startswith("2015 scored this comparison from 40 valid pair(s)")
        for w in scored["warnings"]
    )
    assert SETTINGS_2015["unscoreable"] == "2015"
    # --2015 compares the hole's poses against the held GT pose: scored, the gap still counted
    held = score_streams(robot, gt, TrajectoryConfig.of_2015()).to_dict()
    assert held["compared"] == 100
    assert held["invalid_samples"] == {"gap": 60}
    assert held["position_error"] is not None


@pytest.mark.slow
def test_the_score_command_prints_validity(
    robotlog: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["score", "trajectory", str(robotlog["robot"]), str(robotlog["dir"]), "--format", "json"]
    assert main(args) == 0
    out, err = capsys.readouterr()
    data = json.loads(out)
    (line,) = [x for x in err.splitlines() if x.startswith("ertools: validity: ")]
    assert line.startswith(f"ertools: validity: trajectory {data['valid_fraction']:.1%} valid")
    assert data["valid_fraction"] == pytest.approx(data["compared"] / data["robot_poses"], abs=1e-6)
    # well covered: --unscoreable 2015 changes no number
    assert main([*args, "--unscoreable", "2015"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert again["position_error"] == data["position_error"]


@pytest.mark.slow
def test_the_error_figures_shade_the_hole(tmp_path: Path) -> None:
    robot, gt = _streams((1.05, 3.05))
    result = score_streams(robot, gt, TrajectoryConfig())
    specs = {s.name: s for s in figure_specs(result)}
    assert specs["trajectory_error"].title.endswith("; 80.0% of robot poses valid")
    for name in ("trajectory_error", "trajectory_yaw_error"):
        render(specs[name], tmp_path / f"{name}.svg")
        fig = svg_figure.read(tmp_path / f"{name}.svg")
        (rect,) = fig.series("GT gap span").findall("s:rect", svg_figure.NS)
        a, b = fig.scale("x")
        lo = a * float(rect.get("x", "nan")) + b
        hi = a * (float(rect.get("x", "nan")) + float(rect.get("width", "nan"))) + b
        # from the last robot pose with GT before the hole (1.0 s after the first robot pose)
        # to the first after it (3.1 s), to the 0.1 px the file is written at
        assert (lo, hi) == pytest.approx((1.0, 3.1), abs=abs(a))
        render(specs[name], tmp_path / f"{name}.png")  # matplotlib draws it too
        assert (tmp_path / f"{name}.png").stat().st_size > 1000
