"""`ertools export` on bad input: one `ertools: error:` line, the right exit status, no file."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from ertools.cli.main import main
from tests.helpers.stderr_text import error_messages

REPO = Path(__file__).resolve().parents[2]
ROBOTLOG = REPO / "sample_bags/robotlog"
ROBOT_BAG = ROBOTLOG / "FBM2H_201511201200_homer.bag"
GT_BAG = ROBOTLOG / "log_fbm2h_mocap_2015-11-20-11-59-59_0.bag"
GT_TOPIC = "/fbm2h/robot_at_home/pose"


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
    code = main(["export", *argv])
    err = capsys.readouterr().err
    return code, err


def one_error(err: str) -> str:
    lines = error_messages(err)
    assert len(lines) == 1, err
    assert "Traceback" not in err
    return lines[0]


def test_missing_topic_names_the_pose_topics(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "x.tum"
    code, err = run(capsys, str(GT_BAG), "--topic", "/nope", "-o", str(out))
    assert code == 1
    line = one_error(err)
    assert "/nope" in line and GT_TOPIC in line
    assert not out.exists()


def test_unknown_tf_frame(capsys: pytest.CaptureFixture[str]) -> None:
    code, err = run(capsys, str(GT_BAG), "--tf", "world:nobody")
    assert code == 1
    assert "nobody" in one_error(err)


def test_missing_bag(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, err = run(capsys, str(tmp_path / "absent.bag"), "--topic", GT_TOPIC)
    assert code == 1
    assert "absent.bag" in one_error(err)


def test_refuses_to_overwrite_an_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = tmp_path / "gt.bag"
    shutil.copy(GT_BAG, bag)
    before = bag.read_bytes()
    code, err = run(capsys, str(bag), "--topic", GT_TOPIC, "-o", str(bag))
    assert code == 2
    assert "never overwrites its inputs" in one_error(err)
    # --times and the pair files are outputs too
    code, err = run(
        capsys, str(bag), "--topic", GT_TOPIC, "--format", "kitti", "-o", str(tmp_path / "k"),
        "--times", str(bag),
    )  # fmt: skip
    assert code == 2 and "never overwrites" in one_error(err)
    robot = tmp_path / "robot.tum"
    robot.write_text("not a bag\n")
    code, err = run(capsys, str(robot), str(bag), "--out-dir", str(tmp_path))
    assert code == 2 and "never overwrites" in one_error(err)
    assert bag.read_bytes() == before
    assert robot.read_text() == "not a bag\n"


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        ([str(GT_BAG)], "give --topic TOPIC or --tf PARENT:CHILD"),
        ([str(GT_BAG), "--topic", GT_TOPIC, "--tf", "world:a"], "not allowed with"),
        ([str(GT_BAG), "--tf", "world"], "PARENT:CHILD"),
        ([str(GT_BAG), "--tf", "world:a", "--time-source", "record"], "is for --topic"),
        ([str(GT_BAG), "--topic", GT_TOPIC, "--times", "t.txt"], "--times is for --format kitti"),
        ([str(GT_BAG), "--topic", GT_TOPIC, "--format", "kitti", "--times", "t.txt"], "needs -o"),
        ([str(GT_BAG), "--topic", GT_TOPIC, "--matched"], "--matched: pair options"),
        ([str(GT_BAG), "--topic", GT_TOPIC, "--association", "hold"], "need --out-dir"),
        ([str(ROBOT_BAG), str(ROBOTLOG), "--out-dir", "d", "--topic", GT_TOPIC], "one pose"),
        ([str(ROBOT_BAG), str(ROBOTLOG), "--out-dir", "d", "--format", "kitti"], "add --matched"),
        ([str(ROBOT_BAG), str(ROBOTLOG), "--out-dir", "d", "--apply-offset"], "--offset auto"),
        ([str(GT_BAG), "--topic", GT_TOPIC, "--format", "g2o"], "invalid choice"),
    ],
)
def test_usage_errors(
    argv: list[str], needle: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = [str(tmp_path / a) if a in ("d", "t.txt") else a for a in argv]
    code, err = run(capsys, *argv)
    assert code == 2
    assert needle in one_error(err)
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_pair_errors_are_the_scores(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, err = run(
        capsys, str(ROBOT_BAG), str(ROBOTLOG), "--out-dir", str(tmp_path), "--gt-topic", "/x"
    )
    assert code == 1
    assert "GT topic /x" in one_error(err)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_pair_kitti_matched_rows_and_times(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """KITTI pairs: row i of both files is one scored pair; the times files are equal."""
    code, err = run(
        capsys, str(ROBOT_BAG), str(ROBOTLOG), "--out-dir", str(tmp_path), "--format", "kitti",
        "--matched",
    )  # fmt: skip
    assert code == 0, err
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["gt.kitti", "gt_times.txt", "robot.kitti", "robot_times.txt"]
    robot = np.loadtxt(tmp_path / "robot.kitti").reshape(-1, 3, 4)
    gt = np.loadtxt(tmp_path / "gt.kitti").reshape(-1, 3, 4)
    assert robot.shape == gt.shape
    times = (tmp_path / "robot_times.txt").read_text()
    assert times == (tmp_path / "gt_times.txt").read_text()
    assert times.startswith("0.000000000\n")
    # evo_ape kitti's mean (translation, no alignment) is the mean row distance
    code = main(["score", "trajectory", str(ROBOT_BAG), str(ROBOTLOG), "--format", "json"])
    score = json.loads(capsys.readouterr().out)
    assert code == 0
    assert len(robot) == score["compared"]
    d = np.linalg.norm(robot[:, :, 3] - gt[:, :, 3], axis=1)
    assert float(d.mean()) == pytest.approx(score["position_error"], abs=1e-12)
