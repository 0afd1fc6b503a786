"""A GT topic whose frame_id changes mid-log: recorded by the reader, warned by the scorer."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ertools.benchmarks.trajectory.comparison import score_streams
from ertools.benchmarks.trajectory.config import TrajectoryConfig
from ertools.geometry import quat_from_yaw
from ertools.io.reader import read_poses
from ertools.simulator.writer import BagWriter
from ertools.streams import PoseStream

S = 1_000_000_000
T0 = 1_448_013_600 * S
TOPIC = "/fbm2h/robot_at_home/pose"


def _gt_file(path: Path, t: np.ndarray, frame: str) -> Path:
    xyz = np.column_stack([np.linspace(0, 1, len(t)), np.zeros(len(t)), np.zeros(len(t))])
    with BagWriter(path, "ros1") as bag:
        bag.write_pose_stamped(TOPIC, t, t, frame, xyz, quat_from_yaw(np.zeros(len(t))))
    return path


def test_split_gt_files_in_different_frames(tmp_path: Path) -> None:
    # The logger's second file was written after the mocap was re-published in "map".
    t = T0 + np.arange(0, 2 * 120) * 8_333_333
    a = _gt_file(tmp_path / "gt_0.bag", t[:120], "world")
    b = _gt_file(tmp_path / "gt_1.bag", t[120:], "map")
    gt = read_poses([a, b], TOPIC)
    assert [(c.t_ns, c.old, c.new) for c in gt.frame_changes] == [(int(t[120]), "world", "map")]
    robot = PoseStream(t[10:200:12], gt.xyz[10:200:12], gt.quat_xyzw[10:200:12])
    result = score_streams(robot, gt, TrajectoryConfig())
    lines = [w for w in result.warnings if "frame names change" in w]
    assert len(lines) == 1 and "frame_id 'world' -> 'map'" in lines[0]


def test_consistent_frames_give_no_warning(tmp_path: Path) -> None:
    t = T0 + np.arange(0, 120) * 8_333_333
    gt = read_poses(_gt_file(tmp_path / "gt.bag", t, "world"), TOPIC)
    assert gt.frame_changes == ()
    robot = PoseStream(t[::12], gt.xyz[::12], gt.quat_xyzw[::12])
    assert not [w for w in score_streams(robot, gt, TrajectoryConfig()).warnings if "frame" in w]
