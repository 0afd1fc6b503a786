"""`ertools export BAG COPY_OF_BAG` (issue 25, item 10): every message is recorded twice; each
pose is written once, as `score` uses it once, and the note says how many were dropped."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from ertools.benchmarks.common.hygiene import drop_duplicates
from ertools.cli.main import main
from ertools.streams import PoseStream

ROOT = Path(__file__).resolve().parents[2]
BAG = ROOT / "sample_bags" / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
TOPIC = "/fbm3w/robot_at_work/pose"


def test_a_bag_given_with_its_copy_writes_each_pose_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    copy = tmp_path / "copy.bag"
    shutil.copyfile(BAG, copy)
    one, two = tmp_path / "one.tum", tmp_path / "two.tum"
    assert main(["export", str(BAG), "--topic", TOPIC, "-o", str(one)]) == 0
    capsys.readouterr()
    assert main(["export", str(BAG), str(copy), "--topic", TOPIC, "-o", str(two)]) == 0
    err = capsys.readouterr().err
    poses = [line for line in one.read_text().splitlines() if not line.startswith("#")]
    assert len(poses) > 1000  # the sample's mocap stream, not a trivial case
    assert two.read_text() == one.read_text()
    assert f"{len(poses)} pose(s) recorded twice" in err


def test_a_real_repeat_with_a_fresh_stamp_is_kept(tmp_path: Path) -> None:
    """Only identical stamp and pose go: the hygiene rule `score` uses (a repeated pose with a
    new stamp is Motive's tracking-loss repeat, not a copy)."""

    t = np.array([0, 10, 10, 20], dtype=np.int64)
    xyz = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 0], [1, 0, 0]], dtype=np.float64)
    quat = np.tile([0.0, 0.0, 0.0, 1.0], (4, 1))
    stream = PoseStream(t_ns=t, xyz=xyz, quat_xyzw=quat, frame_id="world", source="x")
    kept, dropped = drop_duplicates(stream)
    assert dropped == 1 and kept.t_ns.tolist() == [0, 10, 20]
