"""summary() from the file's own index, and the scan fallback for unindexed/truncated files."""

from __future__ import annotations

import logging
import struct
from pathlib import Path

import numpy as np
import pytest

from ertools.errors import BagError
from ertools.io.reader import read_poses
from ertools.io.ros1.layout import read_layout
from ertools.io.summary import record_times
from ertools.io.summary import summary as bag_summary
from tests.helpers.bagmaker import write
from tests.helpers.scene import Scene

POSE = "/fbm3w/robot_at_work/pose"


def expected_counts(scene: Scene) -> dict[str, int]:
    counts: dict[str, int] = {}
    for ci, _t, _v in scene.spec.msgs:
        topic = scene.spec.conns[ci][0]
        counts[topic] = counts.get(topic, 0) + 1
    return counts


def test_summary_counts_and_times(scene: Scene, scene_bag: tuple[str, Path]) -> None:
    fmt, path = scene_bag
    s = bag_summary(path, exact=True)
    counts = expected_counts(scene)
    assert s.message_count == sum(counts.values())
    assert {t.name: t.count for t in s.topics if t.count} == counts
    assert s.start_ns == scene.t_rec[0]
    assert s.end_ns == scene.t_rec[-1] + 100  # the last Pose2D is written 100 ns later
    assert s.duration_ns == s.end_ns - s.start_ns
    pose = s.topic(POSE)
    assert pose is not None
    assert (pose.msgtype, pose.first_ns, pose.last_ns) == (
        "geometry_msgs/PoseStamped",
        scene.t_rec[0],
        scene.t_rec[-1],
    )
    tf = s.topic("/tf")
    assert tf is not None
    assert tf.connections == (2 if fmt.startswith("ros1") or fmt.startswith("mcap") else 1)
    assert s.indexed and s.problems == ()
    assert s.size_bytes > 0
    compression = {"ros1-lz4": "lz4", "ros1-bz2": "bz2", "mcap-cdr": "lz4", "mcap-ros1": "lz4"}
    assert s.compression == compression.get(fmt, "none")
    # the quick summary bounds each topic by its chunks: never inside the true span
    quick = bag_summary(path).topic(POSE)
    assert quick is not None and quick.first_ns is not None and quick.last_ns is not None
    assert quick.first_ns <= scene.t_rec[0] and quick.last_ns >= scene.t_rec[-1]
    times = record_times(path)
    np.testing.assert_array_equal(times[POSE], scene.t_rec)


def make_active(good: Path, out: Path) -> Path:
    """A closed bag turned into what a recorder leaves while writing: no index, index_pos 0."""
    data = bytearray(good.read_bytes())
    at = data.index(b"index_pos=") + len(b"index_pos=")
    (index_pos,) = struct.unpack_from("<Q", data, at)
    struct.pack_into("<Q", data, at, 0)
    out.write_bytes(bytes(data[:index_pos]))
    return out


def test_active_bag_is_scanned_and_readable(tmp_path: Path, scene: Scene) -> None:
    good = write(tmp_path / "g.bag", "ros1-lz4", scene.spec, chunk_bytes=2000)
    active = make_active(good, tmp_path / "rec.bag.active")
    s = bag_summary(active)
    assert s.format == "ros1-active" and not s.indexed
    assert any("not indexed" in p for p in s.problems)
    assert s.message_count == sum(expected_counts(scene).values())
    poses = read_poses(active, POSE)
    np.testing.assert_array_equal(poses.xyz, scene.xyz)


def test_truncated_bag(tmp_path: Path, scene: Scene) -> None:
    good = write(tmp_path / "g.bag", "ros1", scene.spec, chunk_bytes=2000)
    data = good.read_bytes()
    cut = tmp_path / "cut.bag"
    cut.write_bytes(data[: int(len(data) * 0.6)])
    s = bag_summary(cut)
    assert not s.indexed
    assert any("truncated" in p for p in s.problems)
    # Some but not all messages survive the cut, counted by the scan.
    assert 0 < s.message_count < sum(expected_counts(scene).values())
    with pytest.raises(BagError, match="truncated"):
        read_poses(cut, POSE)


def test_truncated_mcap(tmp_path: Path, scene: Scene, caplog: pytest.LogCaptureFixture) -> None:
    good = write(tmp_path / "g.mcap", "mcap-cdr", scene.spec, chunk_bytes=2000)
    data = good.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: int(len(data) * 0.5)])
    s = bag_summary(cut)
    assert not s.indexed and s.problems
    assert 0 < s.message_count < sum(expected_counts(scene).values())
    # A recorder killed mid-file leaves no summary: the complete messages are read, with a
    # warning (like a ROS1 .bag.active).
    with caplog.at_level(logging.WARNING, logger="ertools"):
        poses = read_poses(cut, POSE)
    assert "no summary section" in caplog.text
    k = len(poses)
    assert 0 < k < scene.n
    np.testing.assert_array_equal(poses.xyz, scene.xyz[:k])
    np.testing.assert_array_equal(poses.t_ns, scene.t_hdr[:k])


def test_real_bag_summary() -> None:
    real = Path(__file__).resolve().parents[2] / ".." / "shared" / "real_bags"
    path = real / "log_fbm2h_mocap_2015-10-23-16-15-40_0.bag"
    if not path.exists():
        pytest.skip("../shared/real_bags not present")
    s = bag_summary(path, exact=True)
    counts = {t.name: (t.msgtype, t.count, t.connections) for t in s.topics}
    # Figures from the README of ../shared/real_bags.
    assert counts["/fbm2h/robot_at_home/pose"] == ("geometry_msgs/PoseStamped", 6887, 1)
    assert counts["/fbm2h/robot_at_home/pose2d"] == ("geometry_msgs/Pose2D", 6887, 1)
    assert counts["/tf"] == ("tf2_msgs/TFMessage", 6887 + 573, 2)
    assert counts["/fbm2h/map"][1] == 1 and counts["/fbm2h/map_metadata"][1] == 1
    assert counts["/rosout"][1] == 4
    assert s.format == "ros1" and s.compression == "none" and s.indexed
    # 57.6 s long (README)
    assert abs(s.duration_ns / 1e9 - 57.6) < 0.05


def test_active_bag_with_open_chunk(tmp_path: Path, scene: Scene) -> None:
    """The chunk a recorder is filling has a placeholder size of 0 and its records follow it
    outside any chunk: they are read too."""
    good = write(tmp_path / "g.bag", "ros1", scene.spec, chunk_bytes=2000)

    data = bytearray(make_active(good, tmp_path / "tmp.bag.active").read_bytes())
    last = read_layout(good).chunks[-1].pos
    (hlen,) = struct.unpack_from("<I", data, last)
    (dlen,) = struct.unpack_from("<I", data, last + 4 + hlen)
    struct.pack_into("<I", data, last + 4 + hlen, 0)  # the size a recorder leaves: 0
    active = tmp_path / "open.bag.active"
    active.write_bytes(bytes(data[: last + 8 + hlen + dlen]))  # no index records after it
    s = bag_summary(active)
    assert s.format == "ros1-active" and not s.indexed
    assert s.message_count == sum(expected_counts(scene).values())
    np.testing.assert_array_equal(read_poses(active, POSE).xyz, scene.xyz)
