"""The one-gather decoder (ertools.io.decode.uniform): layouts worked out by hand from the ROS1 and
CDR serialization rules, exact values back, and a fallback whenever one message differs."""

from __future__ import annotations

import struct
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ertools.io import assemble
from ertools.io.decode.uniform import decode_uniform, layout_of
from tests.helpers.bagmaker import FORMATS, Spec, bag_name, write
from tests.helpers.fastpath import assert_same, fast_batch, reference_batch

POSE = (1.5, -2.25, 0.125, 0.0, 0.0, 0.6, 0.8)


def ros1_pose_stamped(
    seq: int, sec: int, nsec: int, frame: bytes, pose: tuple[float, ...]
) -> bytes:
    # ROS1: seq u32, stamp (u32, u32), frame_id (u32 length + bytes), pose 7 x f64; no padding.
    return struct.pack("<IIII", seq, sec, nsec, len(frame)) + frame + struct.pack("<7d", *pose)


def cdr_pose_stamped(sec: int, nsec: int, frame: bytes, pose: tuple[float, ...]) -> bytes:
    # CDR: 4-byte encapsulation header, then alignment counted from after it: stamp (i32,
    # u32), frame_id (u32 length incl. NUL + bytes + NUL), pad to 8, pose 7 x f64.
    body = struct.pack("<iiI", sec, nsec, len(frame) + 1) + frame + b"\x00"
    body += b"\x00" * (-len(body) % 8)
    return b"\x00\x01\x00\x00" + body + struct.pack("<7d", *pose)


def as_buffer(messages: list[bytes]) -> tuple[Any, Any, Any]:
    lengths = np.array([len(m) for m in messages], dtype=np.int64)
    starts = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)
    return np.frombuffer(b"".join(messages), dtype=np.uint8), starts, lengths


def test_ros1_pose_stamped_layout_by_hand() -> None:
    lay = layout_of("geometry_msgs/PoseStamped", False, ros1_pose_stamped(7, 1, 2, b"world", POSE))
    assert lay is not None
    assert lay.size == 16 + 5 + 56
    assert lay.stamp == (4, 8, "<u4")
    assert lay.values_at == 21 and lay.values == 7
    # Only the frame_id length and text must repeat: seq, stamp and pose vary.
    assert lay.fixed == ((12, 21),)
    assert lay.frame == "world" and lay.child is None


def test_cdr_pose_stamped_layout_by_hand() -> None:
    raw = cdr_pose_stamped(1, 2, b"world", POSE)
    lay = layout_of("geometry_msgs/PoseStamped", True, raw)
    assert lay is not None
    # 4 header + 12 (sec, nsec, length) + 6 ("world\0") = 22 -> 18 after the header, padded
    # to 24 -> pose at byte 28, 56 bytes long.
    assert lay.values_at == 28 and lay.size == 84 == len(raw)
    assert lay.stamp == (4, 8, "<i4")
    assert lay.fixed == ((0, 4), (12, 28))


def test_tf_with_two_transforms_has_no_single_layout() -> None:
    one = struct.pack("<I", 2) + ros1_pose_stamped(0, 1, 2, b"world", POSE)
    assert layout_of("tf2_msgs/TFMessage", False, one) is None


def test_decoded_values_are_exact() -> None:
    n = 40
    rng = np.random.default_rng(3)
    poses = rng.normal(size=(n, 7))
    secs = 1_445_609_740 + np.arange(n)
    nsecs = rng.integers(0, 10**9, n)
    msgs = [
        ros1_pose_stamped(i, int(secs[i]), int(nsecs[i]), b"world", tuple(poses[i]))
        for i in range(n)
    ]
    dec = decode_uniform("geometry_msgs/PoseStamped", False, *as_buffer(msgs))
    assert dec is not None
    np.testing.assert_array_equal(dec.t_header, secs * 10**9 + nsecs)
    np.testing.assert_array_equal(dec.xyz, poses[:, :3])
    np.testing.assert_array_equal(dec.quat_xyzw, poses[:, 3:])
    assert dec.frame_text == "world"


@pytest.mark.parametrize(
    "odd_frame",
    [b"earth", b"map", b"worle"],  # same length, shorter, one byte different at the end
)
def test_one_different_message_means_no_uniform_decode(odd_frame: bytes) -> None:
    msgs = [ros1_pose_stamped(i, 10 + i, 0, b"world", POSE) for i in range(30)]
    msgs[17] = ros1_pose_stamped(17, 27, 0, odd_frame, POSE)
    assert decode_uniform("geometry_msgs/PoseStamped", False, *as_buffer(msgs)) is None


def test_cdr_padding_difference_means_no_uniform_decode() -> None:
    msgs = [cdr_pose_stamped(10 + i, 0, b"world", POSE) for i in range(10)]
    odd = bytearray(msgs[4])
    odd[23] = 0x55  # a padding byte before the pose: not what the first message has
    msgs[4] = bytes(odd)
    assert decode_uniform("geometry_msgs/PoseStamped", True, *as_buffer(msgs)) is None
    assert decode_uniform("geometry_msgs/PoseStamped", True, *as_buffer(msgs[:4])) is not None


@pytest.mark.parametrize("fmt", FORMATS)
def test_topic_with_a_different_frame_midway_matches_rosbags(fmt: str, tmp_path: Path) -> None:
    """A topic whose frame changes midway (same name length, then another length) falls back
    to the field decoder and still gives rosbags' values and names."""
    s = Spec()
    pose = s.conn("/robot/pose", "geometry_msgs/PoseStamped")
    t0 = 1_445_609_740_000_000_000
    for i in range(60):
        frame = "world" if i < 20 else ("earth" if i < 40 else "map")
        xyz = (0.01 * i, -0.02 * i, 0.3)
        s.add(
            pose,
            t0 + i * 8_333_333,
            stamp=t0 + i * 8_333_333 - 1000,
            frame=frame,
            xyz=xyz,
            q=(0.0, 0.0, 0.0, 1.0),
        )
    path = write(bag_name(tmp_path, fmt), fmt, s, chunk_bytes=100_000)
    fast = fast_batch(path, "/robot/pose")
    assert_same(fast, reference_batch(path, "/robot/pose"))
    assert list(fast.frame_names()[[0, 25, 50]]) == ["world", "earth", "map"]


@pytest.mark.slow_cases("ros1-bz2", "ros1-lz4", "ros1", "rosbag2-mcap", "rosbag2-sqlite3")
def test_uniform_decoder_is_used_on_standard_topics(
    scene_bag: tuple[str, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    """On a logger's bag (one frame per topic) the one-gather decoder does the work (each
    connection's records gathered once, head and data), so the fast-path tests against
    rosbags exercise it."""
    used: list[str] = []
    real = assemble.Decoder.fast

    def spy(self: Any, *args: Any, **kwargs: Any) -> Any:
        out = real(self, *args, **kwargs)
        if out:
            used.append(self.msgtype)
        return out

    monkeypatch.setattr(assemble.Decoder, "fast", spy)
    _fmt, path = scene_bag
    for topic in (
        "/fbm3w/robot_at_work/pose",
        "/fbm3w/robot_at_work/pose2d",
        "/fbm3w/tfs",
        "/odom",
    ):
        assert_same(fast_batch(path, topic), reference_batch(path, topic))
    assert {"geometry_msgs/PoseStamped", "geometry_msgs/Pose2D"} <= set(used)
    assert {"geometry_msgs/TransformStamped", "nav_msgs/Odometry"} <= set(used)
