"""Every pose type everywhere a pose topic is accepted, in every format: values back exactly
as written (the generator's ground truth) and bit for bit what rosbags' deserializer gives.

PoseWithCovarianceStamped (nav2's ``/amcl_pose``, robot_localization's outputs) carries its
pose between the header and a 36-float covariance; the test bags fill that covariance with
values unlike any pose, so a decoder reading the wrong 56 bytes cannot pass.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader

from ertools.benchmarks.trajectory.logs import read_robot
from ertools.cli.main import main
from ertools.errors import TopicError
from ertools.io.decode.fast import decode
from ertools.io.decode.uniform import decode_uniform, layout_of
from ertools.io.info import describe
from ertools.io.model import POSE_TYPES, PoseSource, short_msgtype
from ertools.io.reader import read_pose_source, read_poses
from ertools.io.reader import topics as bag_topics
from ertools.io.summary import summary as bag_summary
from tests.helpers.bagmaker import FORMATS, Spec, bag_name, write
from tests.helpers.fastpath import assert_same, fast_batch, reference_batch

pytestmark = pytest.mark.slow

T0 = 1_700_000_000_000_000_000
N = 40
# topic -> (type, child frame written, frame written)
TOPICS = {
    "/ps": ("geometry_msgs/PoseStamped", "", "map"),
    "/amcl_pose": ("geometry_msgs/PoseWithCovarianceStamped", "", "map"),
    "/tfs": ("geometry_msgs/TransformStamped", "base_link", "map"),
    "/odom": ("nav_msgs/Odometry", "base_link", "odom"),
    "/p2d": ("geometry_msgs/Pose2D", "", ""),
    "/tf2": ("tf2_msgs/TFMessage", "base_link", "map"),
    "/tf1": ("tf/tfMessage", "base_link", "map"),
}


def truth(seed: int = 7) -> tuple[Spec, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    t_rec = T0 + np.arange(N, dtype=np.int64) * 50_000_000 + rng.integers(0, 1000, N)
    t_hdr = t_rec - 1_000_000 - rng.integers(0, 1000, N)
    xyz = rng.normal(size=(N, 3))
    yaw = rng.uniform(-np.pi, np.pi, N)
    quat = np.stack([np.zeros(N), np.zeros(N), np.sin(yaw / 2), np.cos(yaw / 2)], axis=1)
    s = Spec()
    for topic, (msgtype, child, frame) in TOPICS.items():
        c = s.conn(topic, msgtype)
        for i in range(N):
            v = dict(stamp=int(t_hdr[i]), frame=frame, child=child, xyz=xyz[i], q=quat[i])
            if msgtype == "geometry_msgs/Pose2D":
                s.add(c, int(t_rec[i]), x=xyz[i, 0], y=xyz[i, 1], theta=yaw[i])
            elif msgtype.endswith(("TFMessage", "tfMessage")):
                s.add(c, int(t_rec[i]), transforms=[v])
            else:
                s.add(c, int(t_rec[i]), **v)
    return s, t_rec, t_hdr, xyz, quat


@pytest.fixture(scope="module", params=FORMATS)
def typed_bag(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Path:
    fmt = str(request.param)
    spec = truth()[0]
    return write(bag_name(tmp_path_factory.mktemp(fmt), fmt), fmt, spec, chunk_bytes=3000)


@pytest.mark.parametrize("topic", sorted(TOPICS))
def test_every_pose_type_reads_back_exactly(typed_bag: Path, topic: str) -> None:
    _, t_rec, t_hdr, xyz, quat = truth()
    msgtype, child, frame = TOPICS[topic]
    assert bag_topics(typed_bag)[topic] == msgtype
    s = read_poses(typed_bag, topic)
    if msgtype == "geometry_msgs/Pose2D":
        np.testing.assert_array_equal(s.t_ns, t_rec)  # no header: always the record time
        np.testing.assert_array_equal(s.xyz[:, :2], xyz[:, :2])
        # yaw -> quaternion: sin/cos of half the yaw, a few ulp
        np.testing.assert_allclose(s.quat_xyzw, quat, atol=1e-15)
    else:
        np.testing.assert_array_equal(s.t_ns, t_hdr)
        np.testing.assert_array_equal(s.xyz, xyz)
        np.testing.assert_array_equal(s.quat_xyzw, quat)
        assert (s.frame_id, s.child_frame_id) == (frame, child)
    rec = read_poses(typed_bag, topic, time_source="record")
    np.testing.assert_array_equal(rec.t_ns, t_rec)
    # A window of the middle 10 samples (on the record time) keeps exactly those.
    part = read_poses(
        typed_bag, topic, time_source="record", start_ns=int(t_rec[10]), end_ns=int(t_rec[19])
    )
    np.testing.assert_array_equal(part.t_ns, t_rec[10:20])
    src = read_pose_source(typed_bag, PoseSource(topic=topic, time_source="record"))
    np.testing.assert_array_equal(src.xyz, rec.xyz)


@pytest.mark.parametrize("topic", sorted(TOPICS))
def test_fast_path_equals_rosbags_for_every_type(typed_bag: Path, topic: str) -> None:
    assert_same(fast_batch(typed_bag, topic), reference_batch(typed_bag, topic))


def test_pose_types_list_the_covariance_pose() -> None:
    assert "geometry_msgs/PoseWithCovarianceStamped" in POSE_TYPES
    assert set(POSE_TYPES) == {t for t, _c, _f in TOPICS.values()}


# --- the one-gather decoder's layout, worked out from the serialization rules -----------------

POSE = (1.5, -2.25, 0.125, 0.0, 0.0, 0.6, 0.8)


def ros1_pwcs(seq: int, sec: int, nsec: int, frame: bytes, cov0: float) -> bytes:
    # ROS1: seq, stamp (u32, u32), frame_id (u32 length + bytes), pose 7 x f64, covariance
    # 36 x f64; nothing is aligned.
    cov = [cov0 + k for k in range(36)]
    head = struct.pack("<IIII", seq, sec, nsec, len(frame)) + frame
    return head + struct.pack("<7d", *POSE) + struct.pack("<36d", *cov)


def cdr_pwcs(sec: int, nsec: int, frame: bytes, cov0: float) -> bytes:
    # CDR: encapsulation header, stamp (i32, u32), frame_id with its NUL, padding to 8
    # (counted after the header), pose, covariance.
    body = struct.pack("<iiI", sec, nsec, len(frame) + 1) + frame + b"\x00"
    body += b"\x00" * (-len(body) % 8)
    cov = [cov0 + k for k in range(36)]
    return b"\x00\x01\x00\x00" + body + struct.pack("<7d", *POSE) + struct.pack("<36d", *cov)


@pytest.mark.parametrize("cdr", [False, True])
def test_pwcs_layout_by_hand(cdr: bool) -> None:
    t = "geometry_msgs/PoseWithCovarianceStamped"
    raws = [
        cdr_pwcs(10 + i, 20 + i, b"world", 100.0 * i)
        if cdr
        else ros1_pwcs(i, 10 + i, 20 + i, b"world", 100.0 * i)
        for i in range(3)
    ]
    lay = layout_of(t, cdr, raws[0])
    assert lay is not None
    if cdr:
        # after the 4-byte header: stamp 8, length 4, "world\0" 6 = 18, padded to 24
        assert lay.size == 4 + 24 + 56 + 288
        assert lay.values_at == 4 + 24
        assert lay.fixed == ((0, 4), (12, 28))  # CDR header; frame length, text, padding
    else:
        assert lay.size == 16 + 5 + 56 + 288
        assert lay.values_at == 21
        assert lay.fixed == ((12, 21),)  # frame length and text; covariance varies
    buf = np.frombuffer(b"".join(raws), dtype=np.uint8)
    start = np.arange(3, dtype=np.int64) * len(raws[0])
    length = np.full(3, len(raws[0]), dtype=np.int64)
    for dec in (decode_uniform(t, cdr, buf, start, length), decode(t, cdr, buf, start, length)):
        assert dec is not None
        np.testing.assert_array_equal(
            dec.t_header, [(10 + i) * 1_000_000_000 + 20 + i for i in range(3)]
        )
        np.testing.assert_array_equal(dec.xyz, np.tile(POSE[:3], (3, 1)))
        np.testing.assert_array_equal(dec.quat_xyzw, np.tile(POSE[3:], (3, 1)))


# --- the commands' pose topic options ----------------------------------------------------------


@pytest.mark.parametrize("topic", sorted(TOPICS))
def test_trajectory_robot_topic_accepts_every_type(typed_bag: Path, topic: str) -> None:
    _, t_rec, t_hdr, xyz, _quat = truth()
    rec = read_robot(str(typed_bag), topic, "record")
    np.testing.assert_array_equal(rec.t_ns, t_rec)
    np.testing.assert_array_equal(rec.xyz[:, :2], xyz[:, :2])
    if TOPICS[topic][0] == "geometry_msgs/Pose2D":
        with pytest.raises(TopicError, match="no header stamp; give --robot-time-source record"):
            read_robot(str(typed_bag), topic, "header")
    else:
        np.testing.assert_array_equal(read_robot(str(typed_bag), topic, "header").t_ns, t_hdr)


def test_noise_topic_option_takes_a_covariance_pose(
    typed_bag: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["noise", str(typed_bag), "--topic", "/amcl_pose", "--format", "json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0
    assert out["samples"] == N


# --- the summary against the official readers -------------------------------------------------


def official_summary(path: Path) -> tuple[dict[str, tuple[str, int, int, int]], int, int]:
    """topic -> (type, count, first, last) and the bag's (start, end) by the official reader
    of the format: rosbags for ROS1 and rosbag2, the mcap library for bare MCAP files."""

    topics: dict[str, tuple[str, int, int, int]] = {}
    if path.suffix == ".mcap":
        with path.open("rb") as f:
            reader = make_reader(f)
            summary = reader.get_summary()
            assert summary is not None and summary.statistics is not None
            stats = summary.statistics
            times: dict[int, list[int]] = {}
            for _schema, channel, message in reader.iter_messages():
                times.setdefault(channel.id, []).append(message.log_time)
            for cid, channel in summary.channels.items():
                schema = summary.schemas[channel.schema_id]
                ts = times.get(cid, [])
                assert stats.channel_message_counts.get(cid, 0) == len(ts)
                topics[channel.topic] = (short_msgtype(schema.name), len(ts), min(ts), max(ts))
            return topics, stats.message_start_time, stats.message_end_time

    with AnyReader([path]) as reader:
        seen: dict[str, list[int]] = {}
        for conn, t, _raw in reader.messages():
            seen.setdefault(conn.topic, []).append(t)
        for conn in reader.connections:
            ts = seen[conn.topic]
            topics[conn.topic] = (short_msgtype(conn.msgtype), len(ts), min(ts), max(ts))
        return topics, reader.start_time, reader.end_time - 1  # rosbags' end is exclusive


def test_summary_matches_the_official_reader(typed_bag: Path) -> None:
    path = typed_bag
    topics, start, end = official_summary(path)
    exact = describe(path).summary
    assert (exact.start_ns, exact.end_ns) == (start, end)
    assert exact.message_count == sum(v[1] for v in topics.values())
    assert {t.name: (t.msgtype, t.count, t.first_ns, t.last_ns) for t in exact.topics} == topics
    quick = bag_summary(path)  # from the chunk bounds: bag start and end still exact
    assert (quick.start_ns, quick.end_ns) == (start, end)
    assert {t.name: (t.msgtype, t.count) for t in quick.topics} == {
        k: v[:2] for k, v in topics.items()
    }


def test_trajectory_robot_topic_of_several_tf_bodies_is_refused(tmp_path: Path) -> None:
    s = Spec()
    c = s.conn("/tf", "tf2_msgs/TFMessage")
    for i in range(3):
        tfs = [
            dict(stamp=T0 + i, frame="map", child=child, xyz=(i, 0, 0), q=(0, 0, 0, 1))
            for child in ("base_link", "arm")
        ]
        s.add(c, T0 + i, transforms=tfs)
    path = write(tmp_path / "tf.bag", "ros1", s)
    with pytest.raises(TopicError, match=r"several frames \(map -> arm, map -> base_link\)"):
        read_robot(str(path), "/tf", "header")
