"""The reference a fast path is checked against: rosbags' (or the mcap library's) per-message
reading of a pose topic, and the bit-for-bit comparison of two pose batches."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np
from mcap.reader import make_reader

from ertools.io.bagfile import BagFile, RawRecord
from ertools.io.bulk import try_fast_batch
from ertools.io.decode.posebatch import PoseBatch
from ertools.io.files import RosbagsFile, open_bag
from ertools.io.formats import detect_format, find_bags
from ertools.io.model import Conn
from ertools.io.reader import slow_pose_batch

REPO = Path(__file__).resolve().parents[2]
REAL_BAG = REPO / ".." / "shared" / "real_bags" / "log_fbm2h_mocap_2015-10-23-16-15-40_0.bag"


def sample_bags() -> list[Path]:
    """Every bag of sample_bags/ (none when the folder is absent)."""
    folder = REPO / "sample_bags"
    return list(find_bags([folder]).bags) if folder.is_dir() else []


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


def reference_bag(path: Path) -> BagFile:
    """The file opened for the reference readers, never through ertools' fast paths."""
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

    with reference_bag(path) as bag:
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
