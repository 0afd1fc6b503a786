"""The bulk decoder agrees bit for bit with rosbags' per-message deserialization."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Writer

import ertools.io as eio
from ertools.io import summary
from ertools.io.bagfile import BagFile, RawRecord
from ertools.io.bulk import try_fast_batch
from ertools.io.decode.posebatch import PoseBatch
from ertools.io.decode.typestore import Deserializer
from ertools.io.files import RosbagsFile, open_bag
from ertools.io.formats import detect_format, find_bags
from ertools.io.model import POSE_TYPES, Conn
from ertools.io.reader import _bulk_states, slow_pose_batch

POSE_TOPICS = (
    "/fbm3w/robot_at_work/pose",
    "/fbm3w/robot_at_work/pose2d",
    "/tf",
    "/fbm3w/tfs",
    "/odom",
)


class LibraryMcap(BagFile):
    """A standalone MCAP file whose messages the ``mcap`` library reads (ertools reads them
    through its own indexes: the reference stays independent of them). A file ertools reads
    record by record (no usable index) is read so here too."""

    def __init__(self, path: Path) -> None:
        self.inner = open_bag(path)
        self.path, self.format = path, "mcap"
        self.connections = self.inner.connections

    def raw(
        self, conns: Sequence[Conn], start_ns: int | None = None, end_ns: int | None = None
    ) -> Iterator[RawRecord]:
        if getattr(self.inner, "scanned", False):
            yield from self.inner.raw(conns, start_ns, end_ns)
            return
        by_id = {c.id: c for c in conns}
        with self.path.open("rb") as f:
            for _schema, channel, message in make_reader(f).iter_messages(
                topics=sorted({c.topic for c in conns}),
                starting_at=start_ns,
                ending_at=end_ns,
                log_time_order=True,
            ):
                if channel.id in by_id:
                    yield by_id[channel.id], int(message.log_time), bytes(message.data)

    def close(self) -> None:
        self.inner.close()


def _reference_bag(path: Path) -> BagFile:
    fmt = detect_format(path)
    if fmt == "mcap":
        return LibraryMcap(path)
    return RosbagsFile(path, fmt) if fmt != "ros1-active" else open_bag(path)


def reference_batch(
    path: Path, topic: str, lo: int | None = None, hi: int | None = None
) -> PoseBatch:
    """rosbags' own reader and deserializer (rosbag1/rosbag2 Reader), or for files rosbags
    does not open their per-message raw records deserialized by rosbags: standalone MCAP
    read by the ``mcap`` library, unindexed .bag.active by ertools' scan."""

    with _reference_bag(path) as bag:
        return slow_pose_batch(bag, bag.topic_conns(topic), lo, hi)


def assert_same(fast: PoseBatch, ref: PoseBatch) -> None:
    assert len(fast) == len(ref)
    np.testing.assert_array_equal(fast.t_record, ref.t_record)
    np.testing.assert_array_equal(fast.t_header, ref.t_header)
    # Bit for bit: compare the float64 bit patterns, not values within a tolerance.
    np.testing.assert_array_equal(fast.xyz.view(np.int64), ref.xyz.view(np.int64))
    np.testing.assert_array_equal(fast.quat_xyzw.view(np.int64), ref.quat_xyzw.view(np.int64))
    np.testing.assert_array_equal(fast.frame_names(), ref.frame_names())
    np.testing.assert_array_equal(fast.child_names(), ref.child_names())


def fast_batch(path: Path, topic: str, lo: int | None = None, hi: int | None = None) -> PoseBatch:
    with open_bag(path) as bag:
        batch = try_fast_batch(bag, bag.topic_conns(topic), lo, hi)
    assert batch is not None, f"fast path did not apply to {path}:{topic}"
    return batch


@pytest.mark.parametrize("topic", POSE_TOPICS)
def test_fast_equals_rosbags(scene_bag: tuple[str, Path], topic: str) -> None:
    _fmt, path = scene_bag
    assert_same(fast_batch(path, topic), reference_batch(path, topic))


REPO = Path(__file__).resolve().parents[2]
REAL_BAG = REPO / ".." / "shared" / "real_bags" / "log_fbm2h_mocap_2015-10-23-16-15-40_0.bag"


def _sample_bags() -> list[Path]:
    folder = REPO / "sample_bags"
    return list(find_bags([folder]).bags) if folder.is_dir() else []


def test_fast_equals_rosbags_on_sample_bags() -> None:
    bags = _sample_bags()
    if not bags:
        pytest.skip("sample_bags/ is empty (run `make samples`)")
    checked = 0
    for path in bags:
        for topic in summary(path).topics:
            if topic.msgtype in POSE_TYPES and topic.count:
                assert_same(fast_batch(path, topic.name), reference_batch(path, topic.name))
                checked += 1
    assert checked > 0


@pytest.mark.real
def test_fast_equals_rosbags_on_real_bag() -> None:
    if not REAL_BAG.exists():
        pytest.skip("../shared/real_bags not present")
    for topic in ("/fbm2h/robot_at_home/pose", "/fbm2h/robot_at_home/pose2d", "/tf"):
        assert_same(fast_batch(REAL_BAG, topic), reference_batch(REAL_BAG, topic))


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
    found = eio.topics(REAL_BAG)
    assert found == {
        "/fbm2h/map": "nav_msgs/OccupancyGrid",
        "/fbm2h/map_metadata": "nav_msgs/MapMetaData",
        "/fbm2h/robot_at_home/pose": "geometry_msgs/PoseStamped",
        "/fbm2h/robot_at_home/pose2d": "geometry_msgs/Pose2D",
        "/rosout": "rosgraph_msgs/Log",
        "/tf": "tf2_msgs/TFMessage",
    }
    s = eio.summary(REAL_BAG)
    assert (s.start_ns, s.end_ns) == (start, end)
    pose = eio.read_poses(REAL_BAG, "/fbm2h/robot_at_home/pose")
    rec = eio.read_poses(REAL_BAG, "/fbm2h/robot_at_home/pose", time_source="record")
    assert len(pose) == 6887 and rec.t_ns[0] == t_first
    p, q = first.pose.position, first.pose.orientation
    assert pose.t_ns[0] == first.header.stamp.sec * 10**9 + first.header.stamp.nanosec
    np.testing.assert_array_equal(pose.xyz[0], [p.x, p.y, p.z])
    np.testing.assert_array_equal(pose.quat_xyzw[0], [q.x, q.y, q.z, q.w])
    assert pose.frame_id == first.header.frame_id == "world"
    assert len(eio.read_poses(REAL_BAG, "/fbm2h/robot_at_home/pose2d")) == 6887
    tf = eio.read_tf(REAL_BAG, "world", "robot_at_home")
    assert len(tf) == 6887
    np.testing.assert_array_equal(tf.xyz[0], pose.xyz[0])  # the mocap node publishes both
    static = eio.read_tf(REAL_BAG, "world", "map")
    assert len(static) == 573


STATE_TOPICS = ("/fbm3w/bmbox_state", "/fbm3w/refbox_state")


def reference_states(path: Path, topic: str) -> tuple[list[int], list[int], list[str]]:
    """States deserialized one by one by rosbags' own readers."""

    with _reference_bag(path) as bag:
        conns = bag.topic_conns(topic)
        deser = Deserializer(conns, path)
        msgs = [(t, deser(raw, c)) for c, t, raw in bag.raw(conns)]
    return [t for t, _ in msgs], [m.state for _, m in msgs], [m.payload for _, m in msgs]


@pytest.mark.parametrize("topic", STATE_TOPICS)
def test_bulk_states_equal_rosbags(scene_bag: tuple[str, Path], topic: str) -> None:
    _fmt, path = scene_bag
    with open_bag(path) as bag:
        bulk = _bulk_states(bag, bag.topic_conns(topic))
    assert bulk is not None, "bulk state decoder did not apply"
    t, state, payload = reference_states(path, topic)
    assert bulk[0].tolist() == t and bulk[1].tolist() == state and bulk[2] == payload


def test_bulk_states_on_sample_and_real_bags() -> None:
    bags = _sample_bags()
    if not bags:
        pytest.skip("sample_bags/ is empty (run `make samples`)")
    checked = 0
    for path in bags:
        for topic in summary(path).topics:
            if topic.msgtype.startswith("rockin_scoring/") and topic.count:
                with open_bag(path) as bag:
                    bulk = _bulk_states(bag, bag.topic_conns(topic.name))
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
    s = eio.read_states(path, "/fbm1h/bmbox_state")
    assert s.state.tolist() == [0, 1, 2] and s.payload == ("p0", "p1", "p2")
