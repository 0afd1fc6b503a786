"""The bulk decoder agrees bit for bit with rosbags' per-message deserialization."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Writer

from ertools.io.bulk import bulk_states
from ertools.io.decode.typestore import Deserializer
from ertools.io.files import open_bag
from ertools.io.model import POSE_TYPES
from ertools.io.reader import read_poses, read_states, read_tf
from ertools.io.reader import topics as bag_topics
from ertools.io.summary import summary
from tests.helpers.fastpath import (
    POSE_TOPICS,
    REAL_BAG,
    assert_same,
    fast_batch,
    reference_bag,
    reference_batch,
    sample_bags,
)


@pytest.mark.slow_cases("rosbag2-mcap-/odom", "rosbag2-mcap-/tf", "rosbag2-sqlite3-/odom")
@pytest.mark.parametrize("topic", POSE_TOPICS)
def test_fast_equals_rosbags(scene_bag: tuple[str, Path], topic: str) -> None:
    _fmt, path = scene_bag
    assert_same(fast_batch(path, topic), reference_batch(path, topic))


@pytest.mark.slow
def test_fast_equals_rosbags_onsample_bags() -> None:
    bags = sample_bags()
    if not bags:
        pytest.skip("sample_bags/ is empty (run `make samples`)")
    checked = 0
    for path in bags:
        for topic in summary(path).topics:
            if topic.msgtype in POSE_TYPES and topic.count:
                assert_same(fast_batch(path, topic.name), reference_batch(path, topic.name))
                checked += 1
    assert checked > 0


@pytest.mark.slow
@pytest.mark.real
def test_fast_equals_rosbags_on_real_bag() -> None:
    if not REAL_BAG.exists():
        pytest.skip("../shared/real_bags not present")
    for topic in ("/fbm2h/robot_at_home/pose", "/fbm2h/robot_at_home/pose2d", "/tf"):
        assert_same(fast_batch(REAL_BAG, topic), reference_batch(REAL_BAG, topic))


@pytest.mark.slow
@pytest.mark.real
def test_real_bag_end_to_end() -> None:
    """Topics, counts, start/end and first pose, checked against rosbags' AnyReader directly."""
    if not REAL_BAG.exists():
        pytest.skip("../shared/real_bags not present")

    with AnyReader([REAL_BAG]) as reader:
        start, end = reader.start_time, reader.end_time - 1  # rosbags' end is exclusive
        conns = [c for c in reader.connections if c.topic == "/fbm2h/robot_at_home/pose"]
        _, t_first, raw = next(reader.messages(connections=conns))
        first = reader.deserialize(raw, conns[0].msgtype)
    found = bag_topics(REAL_BAG)
    assert found == {
        "/fbm2h/map": "nav_msgs/OccupancyGrid",
        "/fbm2h/map_metadata": "nav_msgs/MapMetaData",
        "/fbm2h/robot_at_home/pose": "geometry_msgs/PoseStamped",
        "/fbm2h/robot_at_home/pose2d": "geometry_msgs/Pose2D",
        "/rosout": "rosgraph_msgs/Log",
        "/tf": "tf2_msgs/TFMessage",
    }
    s = summary(REAL_BAG)
    assert (s.start_ns, s.end_ns) == (start, end)
    pose = read_poses(REAL_BAG, "/fbm2h/robot_at_home/pose")
    rec = read_poses(REAL_BAG, "/fbm2h/robot_at_home/pose", time_source="record")
    assert len(pose) == 6887 and rec.t_ns[0] == t_first
    p, q = first.pose.position, first.pose.orientation
    assert pose.t_ns[0] == first.header.stamp.sec * 10**9 + first.header.stamp.nanosec
    np.testing.assert_array_equal(pose.xyz[0], [p.x, p.y, p.z])
    np.testing.assert_array_equal(pose.quat_xyzw[0], [q.x, q.y, q.z, q.w])
    assert pose.frame_id == first.header.frame_id == "world"
    assert len(read_poses(REAL_BAG, "/fbm2h/robot_at_home/pose2d")) == 6887
    tf = read_tf(REAL_BAG, "world", "robot_at_home")
    assert len(tf) == 6887
    np.testing.assert_array_equal(tf.xyz[0], pose.xyz[0])  # the mocap node publishes both
    static = read_tf(REAL_BAG, "world", "map")
    assert len(static) == 573


STATE_TOPICS = ("/fbm3w/bmbox_state", "/fbm3w/refbox_state")


def reference_states(path: Path, topic: str) -> tuple[list[int], list[int], list[str]]:
    """States deserialized one by one by rosbags' own readers."""

    with reference_bag(path) as bag:
        conns = bag.topic_conns(topic)
        deser = Deserializer(conns, path)
        msgs = [(t, deser(raw, c)) for c, t, raw in bag.raw(conns)]
    return [t for t, _ in msgs], [m.state for _, m in msgs], [m.payload for _, m in msgs]


@pytest.mark.parametrize("topic", STATE_TOPICS)
def test_bulk_states_equal_rosbags(scene_bag: tuple[str, Path], topic: str) -> None:
    _fmt, path = scene_bag
    with open_bag(path) as bag:
        bulk = bulk_states(bag, bag.topic_conns(topic))
    assert bulk is not None, "bulk state decoder did not apply"
    t, state, payload = reference_states(path, topic)
    assert bulk[0].tolist() == t and bulk[1].tolist() == state and bulk[2] == payload


@pytest.mark.slow
def test_bulk_states_on_sample_and_real_bags() -> None:
    bags = sample_bags()
    if not bags:
        pytest.skip("sample_bags/ is empty (run `make samples`)")
    checked = 0
    for path in bags:
        for topic in summary(path).topics:
            if topic.msgtype.startswith("rockin_scoring/") and topic.count:
                with open_bag(path) as bag:
                    bulk = bulk_states(bag, bag.topic_conns(topic.name))
                assert bulk is not None
                t, state, payload = reference_states(path, topic.name)
                assert bulk[0].tolist() == t and bulk[1].tolist() == state and bulk[2] == payload
                checked += 1
    assert checked > 0


def test_other_state_layout_falls_back(tmp_path: Path) -> None:
    """A state type with an extra field is still read, through rosbags."""

    path = tmp_path / "odd.bag"
    definition = "uint8 state\nstring payload\nuint32 extra\n"
    with Writer(path) as w:
        c = w.add_connection(
            "/fbm1h/bmbox_state",
            "rockin_scoring/msg/BmBoxState",
            msgdef=definition,
            md5sum="0" * 32,
        )
        for i in range(3):
            payload = f"p{i}".encode()
            raw = (
                bytes([i])
                + len(payload).to_bytes(4, "little")
                + payload
                + (7).to_bytes(4, "little")
            )
            w.write(c, 10**18 + i, raw)
    s = read_states(path, "/fbm1h/bmbox_state")
    assert s.state.tolist() == [0, 1, 2] and s.payload == ("p0", "p1", "p2")
