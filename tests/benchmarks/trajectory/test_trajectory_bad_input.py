"""Bad input to `score trajectory`: one clear line on stderr and exit status 1."""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ertools.benchmarks.trajectory.sample import GT_TOPIC, ROBOT_TOPIC
from ertools.cli.main import main
from tests.benchmarks.trajectory.trajectory_helpers import write_gt, write_robot
from tests.helpers.stderr_text import error_messages

T0 = 1_448_013_600 * 1_000_000_000


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Run, expect exit 1 and exactly one error line (no traceback); return the line."""
    assert main(["score", "trajectory", *args]) == 1
    err = capsys.readouterr().err
    lines = error_messages(err)
    assert len(lines) == 1, err
    assert "Traceback" not in err and "unexpected" not in err
    return lines[0]


@pytest.mark.slow
def test_robot_topic_missing(robotlog: dict[str, Any], capsys: pytest.CaptureFixture[str]) -> None:
    line = run(
        [
            str(robotlog["robot"]),
            str(robotlog["dir"]),
            "--robot-topic",
            "/rockin/adams/marker_pose",
        ],
        capsys,
    )
    assert "/rockin/adams/marker_pose" in line and ROBOT_TOPIC in line  # names what is there


@pytest.mark.slow
def test_gt_topic_missing(robotlog: dict[str, Any], capsys: pytest.CaptureFixture[str]) -> None:
    line = run(
        [str(robotlog["robot"]), *map(str, robotlog["gt"]), "--gt-topic", "/nope/pose"], capsys
    )
    assert "/nope/pose" in line and GT_TOPIC in line


def test_gt_not_overlapping(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    t = T0 + np.arange(100, dtype=np.int64) * 100_000_000
    robot = write_robot(tmp_path / "robot.bag", t, np.zeros((100, 3)), ROBOT_TOPIC)
    tg = T0 + 3600 * 10**9 + np.arange(1200, dtype=np.int64) * 8_333_333  # an hour later
    gt = write_gt(tmp_path / "gt.bag", tg, np.zeros((1200, 3)), GT_TOPIC)
    line = run([str(robot), str(gt)], capsys)
    assert "no GT file overlaps the robot log" in line and "gt.bag" in line


def test_non_increasing_robot_stamps(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    t = T0 + np.arange(100, dtype=np.int64) * 100_000_000
    t[40] = t[38]  # the robot's clock stepped back
    robot = write_robot(tmp_path / "robot.bag", t, np.zeros((100, 3)), ROBOT_TOPIC)
    tg = T0 - 10**9 + np.arange(1500, dtype=np.int64) * 8_333_333
    gt = write_gt(tmp_path / "gt.bag", tg, np.zeros((1500, 3)), GT_TOPIC)
    line = run([str(robot), str(gt)], capsys)
    assert "robot stamps do not increase: message 40" in line and "robot.bag" in line


def test_missing_robot_bag(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    line = run([str(tmp_path / "nope.bag"), str(tmp_path)], capsys)
    assert "nope.bag" in line


@pytest.mark.slow
def test_gt_folder_without_bags(
    robotlog: dict[str, Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    line = run([str(robotlog["robot"]), str(tmp_path)], capsys)
    assert "no GT bags found" in line


def test_random_bytes_as_gt(
    robotlog: dict[str, Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    junk = tmp_path / "junk.bag"
    junk.write_bytes(np.random.default_rng(0).bytes(5000))
    line = run([str(robotlog["robot"]), str(junk)], capsys)
    assert "junk.bag" in line


def test_broken_bag_in_a_gt_folder_is_skipped_with_a_warning(
    robotlog: dict[str, Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "gt"
    folder.mkdir()
    for p in robotlog["gt"]:
        shutil.copyfile(p, folder / p.name)
    (folder / "junk.bag").write_bytes(np.random.default_rng(1).bytes(5000))
    args = ["score", "trajectory", str(robotlog["robot"]), str(folder), "--format", "json"]
    assert main(args) == 0
    err = capsys.readouterr().err
    assert "skipped unreadable file in the GT folder" in err and "junk.bag" in err


def test_robot_topic_of_a_non_pose_type(
    robotlog: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> None:
    # The generated robot log also holds /rockin/homer/command (std_msgs/String).
    line = run(
        [str(robotlog["robot"]), str(robotlog["dir"]), "--robot-topic", "/rockin/homer/command"],
        capsys,
    )
    assert "std_msgs/String" in line and "not a pose type" in line
