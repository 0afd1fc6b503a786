"""Every bad input of issue 5: one line on stderr, exit status 1 (2 for usage)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml

from ertools.cli.main import main
from tests.helpers.stderr_text import error_messages


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["score", "fbm2h", *argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def _timing(tmp_path: Path, seconds: list[float]) -> Path:
    path = tmp_path / "timing.yaml"
    entries = [{f"p{i}": s} for i, s in enumerate(seconds)]
    path.write_text(yaml.safe_dump({"reached_waypoint_timing": entries}))
    return path


def _sample_seconds(sample: Any) -> list[float]:
    entries = yaml.safe_load(sample.timing.read_text())["reached_waypoint_timing"]
    return [float(next(iter(e.values()))) for e in entries]


def _one_error_line(err: str, *needles: str) -> None:
    lines = error_messages(err)
    assert len(lines) == 1, err
    assert "Traceback" not in err
    for needle in needles:
        assert needle in lines[0], lines[0]


@pytest.mark.slow_cases("not-increasing")
@pytest.mark.parametrize(
    ("edit", "needle"),
    [
        (lambda p: [p[0], p[2], p[1], *p[3:]], "times must increase"),
        (lambda p: [*p[:-1], p[-1] + 3600.0], "outside the bag"),
        (lambda p: p[:-1], "5 waypoints"),
        (lambda p: [*p, p[-1] + 0.5], "5 waypoints"),
    ],
    ids=["not-increasing", "outside-bag", "too-few", "too-many"],
)
def test_bad_timing_file(
    fbm2h_sample: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str], edit: Any, needle: str
) -> None:
    timing = _timing(tmp_path, edit(_sample_seconds(fbm2h_sample)))
    code, out, err = _run(
        capsys,
        str(fbm2h_sample.bag),
        "--goal",
        str(fbm2h_sample.goal),
        "--reached",
        "timing",
        str(timing),
    )
    assert code == 1 and out == ""
    _one_error_line(err, needle)


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        (
            {"robot_info": "x", "robot_to_marker_transform": [[0, 0, 0], [0, 0, 0, 1]]},
            "no marker_to_robot_transform (Listing 11)",
        ),
        ({"marker_to_robot_transform": [[0, 0], [0, 0, 0, 1]]}, "list of 3 numbers"),
        ({"marker_to_robot_transform": [[0, 0, 0], [0, 0, 0.3, 0.8]]}, "not 1"),
        (
            {
                "marker_to_robot_transform": [[0, 0, 0], [0, 0, 0, 1]],
                "robot_to_marker_transform": [[0.5, 0, 0], [0, 0, 0, 1]],
            },
            "not the inverse",
        ),
        # A rosparam pose dump is read (issue 26), but this one has no orientation.
        ({"pose": {"position": {"x": 0}}}, "'orientation' (x, y, z, w)"),
    ],
    ids=["missing", "short-translation", "quaternion-norm", "inconsistent", "pose-dump"],
)
def test_bad_transform_file(
    fbm2h_sample: Any,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    content: Any,
    needle: str,
) -> None:
    path = tmp_path / "transform-bad.yaml"
    path.write_text(yaml.safe_dump(content))
    code, out, err = _run(capsys, str(fbm2h_sample.bag), "--transform", str(path))
    assert code == 1 and out == ""
    _one_error_line(err, needle, str(path))


def test_team_file_missing(
    fbm2h_sample: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = _run(
        capsys, str(fbm2h_sample.bag), "--team", "nobody", "--transforms", str(tmp_path)
    )
    assert code == 1
    _one_error_line(err, "transform-nobody.yaml", "not found")


def test_no_gt_near_reached_moment(
    fbm2h_sample: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Move the end of segment 2 into the simulated tracking gap: 3 repeated frames (25 ms)
    # then 18 dropped frames (150 ms) from `at`; its middle is 100 ms after `at`, 75 ms from
    # the nearest sample on either side, so --max-gap 0.05 s finds no GT there.
    loss = fbm2h_sample.answers["generator"]["parameters"]["tracking_loss"]
    first = fbm2h_sample.answers["truth"]["bag_first_ns"] / 1e9
    seconds = _sample_seconds(fbm2h_sample)
    seconds[3] = loss["at"] + 0.100 - first
    timing = _timing(tmp_path, seconds)
    code, out, err = _run(
        capsys,
        str(fbm2h_sample.bag),
        "--goal",
        str(fbm2h_sample.goal),
        "--transform",
        str(fbm2h_sample.transform),
        "--reached",
        "timing",
        str(timing),
        "--gt-tolerance",
        "0.05",
    )
    assert code == 1
    _one_error_line(err, "segment 2", "no ground truth within --gt-tolerance 0.05 s")
    result = yaml.safe_load(out)
    assert result["details"]["segments_details"][2]["dinstance_error"] is None
    assert result["position_accuracy"] is None
    assert result["details"]["segments_details"][1]["dinstance_error"] is not None


def test_more_waypoints_than_segments(
    fbm2h_sample: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    goal = yaml.safe_load(fbm2h_sample.goal.read_text())
    goal["goal"]["waypoints"].append([0.0, 0.0, 0.0])
    del goal["goal"]["num_waypoints"]
    path = tmp_path / "goal6.yaml"
    path.write_text(yaml.safe_dump(goal))
    code, _, err = _run(capsys, str(fbm2h_sample.bag), "--goal", str(path))
    assert code == 1
    _one_error_line(err, "5 reached moments (states) for 6 waypoints")


@pytest.mark.parametrize(
    ("goal", "needle"),
    [
        ({"goal": {"waypoints": [[0.0, 1.0]]}}, "expected [x, y, theta]"),
        ({"goal": {"starting_pose": [0, 0, 0]}}, "missing key 'goal.waypoints'"),
        ({"goal": {"waypoints": [[0, 0, 0]], "num_waypoints": 3}}, "num_waypoints is 3"),
    ],
    ids=["short-waypoint", "no-waypoints", "num-waypoints"],
)
def test_bad_goal_file(
    fbm2h_sample: Any,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    goal: Any,
    needle: str,
) -> None:
    path = tmp_path / "goal.yaml"
    path.write_text(yaml.safe_dump(goal))
    code, _, err = _run(capsys, str(fbm2h_sample.bag), "--goal", str(path))
    assert code == 1
    _one_error_line(err, needle)


@pytest.mark.parametrize(
    "reached", [["timing"], ["sometimes"], ["auto", "x.yaml"]], ids=["no-file", "bad", "extra"]
)
def test_bad_reached_is_usage_error(
    fbm2h_sample: Any, capsys: pytest.CaptureFixture[str], reached: list[str]
) -> None:
    code, _, err = _run(capsys, str(fbm2h_sample.bag), "--reached", *reached)
    assert code == 2
    _one_error_line(err, "--reached")


def test_missing_bag(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = _run(capsys, str(tmp_path / "none.bag"))
    assert code == 1
    _one_error_line(err, "none.bag")


def test_goal_differing_from_the_logged_one_warns(
    fbm2h_sample: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    goal = yaml.safe_load(fbm2h_sample.goal.read_text())
    goal["goal"]["waypoints"][0] = [0.0, 0.0, 0.0]
    path = tmp_path / "goal.yaml"
    path.write_text(yaml.safe_dump(goal))
    code, out, err = _run(
        capsys,
        str(fbm2h_sample.bag),
        "--goal",
        str(path),
        "--transform",
        str(fbm2h_sample.transform),
    )
    assert code == 0
    assert "differs from the one the BmBox sent" in err
    # Scored against the file: waypoint 0 is now the origin, the robot stopped at truth's pose.
    seg0 = yaml.safe_load(out)["details"]["segments_details"][0]
    x, y, _ = fbm2h_sample.answers["truth"]["stop_poses"][0]
    assert seg0["dinstance_error"] == pytest.approx((x**2 + y**2) ** 0.5, abs=0.002)
