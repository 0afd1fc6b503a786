"""Round trips: tiny bags written with rosbags/mcap writers read back exactly, every format."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag1 import Writer

from ertools.errors import BagError, TopicError
from ertools.io.messages import read_messages
from ertools.io.model import PoseSource
from ertools.io.reader import (
    read_benchmark_states,
    read_pose_source,
    read_poses,
    read_states,
    read_tf,
)
from ertools.io.reader import topics as bag_topics
from ertools.io.summary import summary as bag_summary
from ertools.states import Machine
from tests.helpers.bagmaker import Spec, bag_name, write
from tests.helpers.scene import DT, T0, Scene, make_scene

POSE = "/fbm3w/robot_at_work/pose"


def test_pose_stamped_exact(scene: Scene, scene_bag: tuple[str, Path]) -> None:
    _, path = scene_bag
    s = read_poses(path, POSE)
    # Values went through float64 serialization unchanged: exact equality.
    np.testing.assert_array_equal(s.t_ns, scene.t_hdr)
    np.testing.assert_array_equal(s.xyz, scene.xyz)
    np.testing.assert_array_equal(s.quat_xyzw, scene.quat)
    assert s.frame_id == "world"
    rec = read_poses(path, POSE, time_source="record")
    np.testing.assert_array_equal(rec.t_ns, scene.t_rec)


def test_pose2d_record_time_and_yaw(scene: Scene, scene_bag: tuple[str, Path]) -> None:
    _, path = scene_bag
    s = read_poses(path, "/fbm3w/robot_at_work/pose2d")
    np.testing.assert_array_equal(s.t_ns, scene.t_rec + 100)
    np.testing.assert_array_equal(s.xyz[:, :2], scene.xyz[:, :2])
    assert np.all(s.xyz[:, 2] == 0.0)
    # yaw -> quaternion -> yaw round trip: a few ulp of atan2/sin/cos.
    np.testing.assert_allclose(s.yaw, scene.yaw, atol=1e-12)


@pytest.mark.parametrize("topic", ["/fbm3w/tfs", "/odom"])
def test_transform_and_odometry(scene: Scene, scene_bag: tuple[str, Path], topic: str) -> None:
    _, path = scene_bag
    s = read_poses(path, topic)
    np.testing.assert_array_equal(s.t_ns, scene.t_hdr)
    np.testing.assert_array_equal(s.xyz, scene.xyz)
    np.testing.assert_array_equal(s.quat_xyzw, scene.quat)
    assert s.child_frame_id == ("robot_at_work" if topic == "/fbm3w/tfs" else "base_link")


def test_tf_direct_and_chain(scene: Scene, scene_bag: tuple[str, Path]) -> None:
    _, path = scene_bag
    direct = read_tf(path, "world", "/robot_at_work")
    np.testing.assert_array_equal(direct.t_ns, scene.t_hdr)
    np.testing.assert_array_equal(direct.xyz, scene.xyz)
    # map is (1, 2, 0) in world, identity rotation, published every 12th sample from the
    # first to sample 48: map -> robot = robot - (1, 2, 0) where both links exist.
    chain = read_tf(path, "map", "robot_at_work")
    first_map, last_map = scene.t_rec[0], scene.t_rec[48]
    inside = (scene.t_hdr >= first_map) & (scene.t_hdr <= last_map)
    np.testing.assert_array_equal(chain.t_ns, scene.t_hdr[inside])
    # Composition through scipy: rounding of a few 1e-16.
    np.testing.assert_allclose(chain.xyz, scene.xyz[inside] - [1, 2, 0], atol=1e-12)
    np.testing.assert_allclose(
        np.abs(np.sum(chain.quat_xyzw * scene.quat[inside], axis=1)), 1, atol=1e-12
    )


@pytest.mark.slow_cases("rosbag2-mcap")
def test_states_decode_from_stored_definitions(scene: Scene, scene_bag: tuple[str, Path]) -> None:
    _, path = scene_bag
    states = read_benchmark_states(path, "fbm3w")
    assert states.client is None
    assert states.bmbox is not None and states.refbox is not None
    assert states.bmbox.machine is Machine.BMBOX
    idx = np.arange(0, scene.n, 12)
    np.testing.assert_array_equal(states.bmbox.t_ns, scene.t_rec[idx])
    np.testing.assert_array_equal(states.bmbox.state, idx // 12)
    assert states.bmbox.payload == tuple(f"payload {i}" for i in idx)
    np.testing.assert_array_equal(states.refbox.t_ns, scene.t_rec[idx] + 1)


@pytest.mark.slow_cases("rosbag2-mcap", "rosbag2-sqlite3")
def test_window_and_messages(scene: Scene, scene_bag: tuple[str, Path]) -> None:
    _, path = scene_bag
    lo, hi = int(scene.t_rec[10]), int(scene.t_rec[20])
    rec = read_poses(path, POSE, time_source="record", start_ns=lo, end_ns=hi)
    np.testing.assert_array_equal(rec.t_ns, scene.t_rec[10:21])  # both ends inclusive
    hdr = read_poses(path, POSE, start_ns=int(scene.t_hdr[5]), end_ns=int(scene.t_hdr[7]))
    np.testing.assert_array_equal(hdr.xyz, scene.xyz[5:8])
    msgs = read_messages(path, "/chatter")
    assert msgs == []
    raw = read_messages(path, "/fbm3w/bmbox_state", start_ns=lo, end_ns=hi)
    assert [m.t_ns for m in raw] == [int(scene.t_rec[12])]
    assert raw[0].msg.payload == "payload 12"


def test_topics(scene_bag: tuple[str, Path]) -> None:
    _, path = scene_bag
    found = bag_topics(path)
    assert found[POSE] == "geometry_msgs/PoseStamped"
    assert found["/tf"] == "tf2_msgs/TFMessage"
    assert found["/fbm3w/bmbox_state"] == "rockin_scoring/BmBoxState"
    assert len(found) == 8  # 9 connections, /tf has two


def test_unknown_topic_lists_pose_topics(scene_bag: tuple[str, Path]) -> None:
    _, path = scene_bag
    with pytest.raises(TopicError) as err:
        read_poses(path, "/nope")
    text = str(err.value)
    assert "/nope" in text and POSE in text and "/odom" in text and "/chatter" not in text
    with pytest.raises(TopicError, match="not a pose type"):
        read_poses(path, "/chatter")


@pytest.mark.slow
@pytest.mark.parametrize("fmt", ["ros1", "mcap-cdr", "rosbag2-sqlite3"])
def test_split_files_merge_in_time_order(
    tmp_path: Path, fmt: str, caplog: pytest.LogCaptureFixture
) -> None:
    a, b = make_scene(30, seed=2), make_scene(30, seed=3)
    # second file starts where the first ends: shift its times by 30 samples
    shifted = Spec(
        b.spec.conns,
        [
            (c, t + 30 * DT, {**v, **({"stamp": v["stamp"] + 30 * DT} if "stamp" in v else {})})
            for c, t, v in b.spec.msgs
        ],
    )
    p1 = write(bag_name(tmp_path, fmt, "one"), fmt, a.spec)
    p2 = write(bag_name(tmp_path, fmt, "two"), fmt, shifted)
    with caplog.at_level(logging.WARNING, logger="ertools"):
        s = read_poses([p2, p1], POSE, time_source="record")
    np.testing.assert_array_equal(s.t_ns, np.concatenate([a.t_rec, b.t_rec + 30 * DT]))
    np.testing.assert_array_equal(s.xyz, np.concatenate([a.xyz, b.xyz]))
    assert "out of time order" in caplog.text
    # overlapping files: sorted and reported
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="ertools"):
        s2 = read_poses([p1, p1], POSE, time_source="record")
    assert "overlap" in caplog.text
    np.testing.assert_array_equal(s2.t_ns, np.repeat(a.t_rec, 2))


def test_missing_and_broken_files(tmp_path: Path, scene: Scene) -> None:
    with pytest.raises(BagError, match="no such file"):
        read_poses(tmp_path / "missing.bag", POSE)
    empty = tmp_path / "empty.bag"
    empty.write_bytes(b"")
    with pytest.raises(BagError, match="empty"):
        bag_summary(empty)
    junk = tmp_path / "junk.bag"
    junk.write_bytes(np.random.default_rng(0).bytes(5000))
    with pytest.raises(BagError, match="not a ROS1 bag"):
        bag_topics(junk)
    good = write(tmp_path / "good.bag", "ros1", scene.spec)
    cut = tmp_path / "cut.bag"
    cut.write_bytes(good.read_bytes()[: good.stat().st_size // 2])
    with pytest.raises(BagError) as err:
        read_poses(cut, POSE)
    assert "cut.bag" in str(err.value)


def test_no_stored_definition(tmp_path: Path) -> None:
    path = tmp_path / "nodef.bag"
    with Writer(path) as w:
        c = w.add_connection(
            "/fbm1h/bmbox_state", "rockin_scoring/msg/BmBoxState", msgdef="", md5sum="0" * 32
        )
        w.write(c, T0, b"\x02\x00\x00\x00\x00")
    with pytest.raises(BagError, match="no stored message definition"):
        read_states(path, "/fbm1h/bmbox_state")


def test_pose_source(scene: Scene, scene_bag: tuple[str, Path]) -> None:
    _, path = scene_bag
    by_topic = read_pose_source(path, PoseSource(topic=POSE))
    by_tf = read_pose_source(path, PoseSource(frame="robot_at_work"))
    np.testing.assert_array_equal(by_topic.xyz, by_tf.xyz)
    assert by_tf.start_ns > T0
