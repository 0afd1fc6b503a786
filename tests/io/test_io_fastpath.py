"""The bulk decoder agrees bit for bit with rosbags' per-message deserialization."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ertools.io.bulk import try_fast_batch
from ertools.io.files import RosbagsFile, open_bag
from ertools.io.posebatch import PoseBatch
from ertools.io.reader import slow_pose_batch

POSE_TOPICS = (
    "/fbm3w/robot_at_work/pose",
    "/fbm3w/robot_at_work/pose2d",
    "/tf",
    "/fbm3w/tfs",
    "/odom",
)


def reference_batch(
    path: Path, topic: str, lo: int | None = None, hi: int | None = None
) -> PoseBatch:
    """rosbags' own reader and deserializer (rosbag1/rosbag2 Reader) or mcap + rosbags."""
    from ertools.io.formats import detect_format

    fmt = detect_format(path)
    bag = RosbagsFile(path, fmt) if fmt != "mcap" else open_bag(path)
    with bag:
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
