"""`score trajectory BAG` with the robot and GT topics in one bag (evo's `bag` mode).

The generated robot log and its two GT files are read back with rosbags (not ertools.io) and
written again as one bag holding both topics, and as a robot bag plus one GT bag: the same
messages, header stamps and record times. Expected scores: the generator's answers (a plain
per-pose loop, ``expected.offset_0``), and the two-bag score of the same data.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.rosbag1 import Reader

from ertools.benchmarks.trajectory.association import COMPARED
from ertools.benchmarks.trajectory.sample import GT_TOPIC, ROBOT_TOPIC
from ertools.cli.main import main
from ertools.geometry import quat_from_yaw
from ertools.simulator.writer import BagWriter
from tests.benchmarks.trajectory.test_trajectory_sample import check
from tests.benchmarks.trajectory.trajectory_helpers import read_back, score_trajectory
from tests.helpers.stderr_text import error_messages

pytestmark = pytest.mark.slow

FORMATS = {"ros1": "bag", "mcap": "mcap"}


def _data(robotlog: dict[str, Any]) -> dict[str, np.ndarray]:
    rt, rxyz, rq = read_back(robotlog["robot"], ROBOT_TOPIC)
    parts = [read_back(p, GT_TOPIC) for p in robotlog["gt"]]
    return {
        "rt": np.array(rt, np.int64),
        "rxyz": np.array(rxyz),
        "rq": np.array(rq),
        "gt": np.array([t for p in parts for t in p[0]], np.int64),
        "gxyz": np.array([x for p in parts for x in p[1]]),
        "gq": np.array([q for p in parts for q in p[2]]),
    }


def _write(path: Path, fmt: str, d: dict[str, np.ndarray], *, robot: bool, gt: bool) -> Path:
    with BagWriter(path, fmt) as bag:  # type: ignore[arg-type]
        if robot:  # the robot's recorder: 2 ms after its stamps (as the generator)
            bag.write_pose_stamped(
                ROBOT_TOPIC, d["rt"] + 2_000_000, d["rt"], "world", d["rxyz"], d["rq"]
            )
        if gt:  # the GT logger: 0.3 ms after the mocap stamps
            bag.write_pose_stamped(
                GT_TOPIC, d["gt"] + 300_000, d["gt"], "world", d["gxyz"], d["gq"]
            )
    return path


@pytest.fixture(scope="module", params=sorted(FORMATS))
def bags(
    request: pytest.FixtureRequest,
    robotlog: dict[str, Any],
    tmp_path_factory: pytest.TempPathFactory,
) -> dict[str, Path]:
    fmt = request.param
    d = _data(robotlog)
    out = tmp_path_factory.mktemp(f"onebag_{fmt}")
    ext = FORMATS[fmt]
    return {
        "both": _write(out / f"both.{ext}", fmt, d, robot=True, gt=True),
        "robot": _write(out / f"robot.{ext}", fmt, d, robot=True, gt=False),
        "gt": _write(out / f"gt.{ext}", fmt, d, robot=False, gt=True),
    }


# The keys that do not name files: every number and count of the score.
NAMING = {"gt_files", "robot_file", "warnings"}


@pytest.mark.parametrize("association", ["hold", "nearest", "linear"])
def test_one_bag_equals_the_answers_and_the_two_bag_score(
    bags: dict[str, Path], robotlog: dict[str, Any], association: str
) -> None:
    one = score_trajectory(bags["both"], [], association=association).to_dict()
    check(one, robotlog["answers"]["expected"]["offset_0"][association], robotlog["answers"])
    assert one["gt_files"] == [str(bags["both"])]
    assert one["robot_topic"] == ROBOT_TOPIC and one["gt_topic"] == GT_TOPIC  # both guessed
    two = score_trajectory(bags["robot"], [bags["gt"]], association=association).to_dict()
    assert {k: v for k, v in one.items() if k not in NAMING} == {
        k: v for k, v in two.items() if k not in NAMING
    }
    # The same file given as its own GT path is the same mode.
    same = score_trajectory(bags["both"], [bags["both"]], association=association).to_dict()
    assert same == one


def test_cli_one_bag(
    bags: dict[str, Path], robotlog: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["score", "trajectory", str(bags["both"]), "--robot-topic", ROBOT_TOPIC]
    assert main([*argv, "--gt-topic", GT_TOPIC, "--format", "json", "--association", "hold"]) == 0
    out = json.loads(capsys.readouterr().out)
    check(out, robotlog["answers"]["expected"]["offset_0"]["hold"], robotlog["answers"])


def _one_error(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    assert main(["score", "trajectory", *argv]) == 1
    err = capsys.readouterr().err
    lines = error_messages(err)
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


def test_one_bag_without_the_gt_topic(
    bags: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    robot = str(bags["robot"])
    line = _one_error([robot], capsys)
    assert robot in line and "no GT_PATH given" in line and "GT_PATH" in line
    # it reads as a sentence: where the GT was looked for, and why there
    assert "the GT is read from the robot log itself, no GT_PATH given, but" in line
    line = _one_error([robot, "--gt-topic", GT_TOPIC], capsys)
    assert f"GT topic {GT_TOPIC} is not in the robot log {robot}" in line
    line = _one_error([robot, robot, "--gt-topic", GT_TOPIC], capsys)
    assert "the robot log itself" in line


def test_one_bag_with_a_wrong_gt_topic_names_the_topics_there(
    bags: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    line = _one_error([str(bags["both"]), "--gt-topic", "/nope/pose"], capsys)
    assert "/nope/pose" in line and GT_TOPIC in line
    line = _one_error([str(bags["both"]), "--gt-topic", ROBOT_TOPIC], capsys)
    assert "is the robot topic" in line


def test_one_bag_with_two_gt_candidates_asks_for_the_topic(
    tmp_path: Path, robotlog: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> None:
    d = _data(robotlog)
    path = tmp_path / "three.bag"
    with BagWriter(path, "ros1") as bag:
        bag.write_pose_stamped(ROBOT_TOPIC, d["rt"], d["rt"], "world", d["rxyz"], d["rq"])
        for topic in (GT_TOPIC, "/other/pose"):
            bag.write_pose_stamped(
                topic, d["gt"], d["gt"], "world", d["gxyz"], quat_from_yaw(0.0 * d["gt"])
            )
    line = _one_error([str(path)], capsys)
    assert "give --gt-topic" in line and GT_TOPIC in line and "/other/pose" in line


def test_one_bag_agrees_with_evo_bag_mode(bags: dict[str, Path]) -> None:
    """evo (an independent implementation, dev extra) reads both topics from the same bag.

    evo's default association (nearest stamp within 0.01 s) keeps the poses ertools leaves out
    (GT gaps, tracking lost); on the poses ertools compared with ``--association nearest`` its
    APE (translation, no alignment) is ertools' position error to 1e-9 m.
    """
    if bags["both"].suffix != ".bag":
        pytest.skip("n/a: evo reads ROS1 bags and rosbag2 folders, not plain MCAP files")
    pytest.importorskip("evo", reason="evo is in the dev extra: `make test` installs it")
    # lazy: evo is the dev extra's (importorskip above) and takes ~1 s to import
    from evo.core import metrics, sync
    from evo.tools import file_interface

    with Reader(bags["both"]) as reader:
        ref = file_interface.read_bag_trajectory(reader, GT_TOPIC)
        est = file_interface.read_bag_trajectory(reader, ROBOT_TOPIC)
    ref, est = sync.associate_trajectories(ref, est)
    ape = metrics.APE(metrics.PoseRelation.translation_part)
    ape.process_data((ref, est))
    r = score_trajectory(bags["both"], [], association="nearest")
    assert len(ape.error) > r.compared  # evo also pairs the gap and tracking-lost poses
    compared_s = r.matched.t_ns[r.matched.status == COMPARED] / 1e9
    # Robot stamps are ~100 ms apart: 10 us picks each one out of evo's float seconds (whose
    # resolution at epoch 1.4e9 s is 0.24 us).
    near = np.abs(est.timestamps[:, None] - compared_s[None, :]).min(axis=1)
    scored = near < 1e-5
    assert int(scored.sum()) == r.compared
    assert r.metrics is not None
    errors = ape.error[scored]
    assert float(np.mean(errors)) == pytest.approx(r.metrics.position_error, abs=1e-9)
    assert float(np.max(errors)) == pytest.approx(r.metrics.max, abs=1e-9)


def test_export_pair_from_one_bag_equals_the_two_bag_export(
    bags: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`ertools export ROBOT_BAG --out-dir DIR` with the GT topic in the robot bag: the pair
    written is the two-bag pair (the GT read from the same bag, the same scored pairs)."""
    common = ["--robot-topic", ROBOT_TOPIC, "--gt-topic", GT_TOPIC, "--matched"]
    one, two = tmp_path / "one", tmp_path / "two"
    assert main(["export", str(bags["both"]), "--out-dir", str(one), *common]) == 0
    assert (
        main(["export", str(bags["robot"]), str(bags["gt"]), "--out-dir", str(two), *common]) == 0
    )
    capsys.readouterr()
    for name in ("robot.tum", "gt.tum"):
        assert (one / name).read_text() == (two / name).read_text() != ""
