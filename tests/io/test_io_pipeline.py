"""The loading pipeline: chunk groups read, and decompressed ahead on worker threads.

The scene bags are small (one group of chunks by default), so these tests shrink the group
size until every read goes through several groups (on the worker threads and their rotating
buffers for the compressed formats, in turn for the others), and compare the result bit for
bit with rosbags.
"""

from __future__ import annotations

import mmap
import os
import shutil
import struct
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader

from ertools.errors import BagError, ErtoolsError
from ertools.io import bulk, pipeline
from ertools.io.files import open_bag
from ertools.io.mcap.index import _in_order
from ertools.io.reader import read_poses
from ertools.io.ros1 import runs as ros1_runs
from tests.helpers.bagmaker import Spec, bag_name, write
from tests.helpers.fastpath import POSE_TOPICS, assert_same, fast_batch, reference_batch
from tests.helpers.scene import Scene


@pytest.fixture
def small_groups(monkeypatch: pytest.MonkeyPatch) -> None:
    # ~3 chunks of 2000 bytes per group: the scene's bags span 20-60 groups.
    monkeypatch.setattr(pipeline, "GROUP_BYTES", 6000)
    monkeypatch.setattr(pipeline, "workers", lambda: 2)


@pytest.mark.parametrize("topic", POSE_TOPICS)
def test_many_groups_on_worker_threads_equal_rosbags(
    scene_bag: tuple[str, Path], topic: str, small_groups: None
) -> None:
    _fmt, path = scene_bag
    assert_same(fast_batch(path, topic), reference_batch(path, topic))


@pytest.mark.slow_cases("rosbag2-mcap", "rosbag2-sqlite3")
def test_many_groups_with_a_window_equal_rosbags(
    scene_bag: tuple[str, Path], small_groups: None
) -> None:
    _fmt, path = scene_bag
    ref = reference_batch(path, "/fbm3w/robot_at_work/pose")
    lo, hi = int(ref.t_record[7]), int(ref.t_record[33])
    assert_same(
        fast_batch(path, "/fbm3w/robot_at_work/pose", lo, hi),
        reference_batch(path, "/fbm3w/robot_at_work/pose", lo, hi),
    )


def test_prefetched_keeps_order_and_never_reuses_a_held_buffer(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(pipeline, "workers", lambda: 2)
    held: list[int] = []

    def load(k: int, scratch: list[bytearray]) -> tuple[int, memoryview]:
        # Slow, uneven loads so later groups finish first if the order were not kept.
        time.sleep(0.002 * ((k * 7) % 3))
        view = pipeline.scratch_view(scratch, 64)
        view[:] = bytes([k % 256]) * 64
        return k, view

    for k, view in pipeline.prefetched(25, load):
        held.append(k)
        time.sleep(0.003)  # workers fill later groups meanwhile
        # The buffer handed out is still the caller's: nobody wrote into it.
        assert bytes(view) == bytes([k % 256]) * 64
    assert held == list(range(25))


@pytest.mark.parametrize("parallel", [False, True])
def test_prefetched_with_hold_keeps_the_groups_before_valid(
    monkeypatch: pytest.MonkeyPatch, parallel: bool
) -> None:
    """With ``hold``, the ``hold`` groups before the one held are not written over either."""
    monkeypatch.setattr(pipeline, "workers", lambda: 2)

    def load(k: int, scratch: list[bytearray]) -> tuple[int, memoryview]:
        time.sleep(0.001 * ((k * 5) % 3))
        view = pipeline.scratch_view(scratch, 32)
        view[:] = bytes([k % 256]) * 32
        return k, view

    held: list[tuple[int, memoryview]] = []
    for k, view in pipeline.prefetched(20, load, parallel=parallel, hold=2):
        held.append((k, view))
        time.sleep(0.002)
        for j, old in held[-3:]:
            assert bytes(old) == bytes([j % 256]) * 32
    assert [k for k, _v in held] == list(range(20))


def _lane_groups(
    count: int, slots: int, written: list[int]
) -> Iterator[list[tuple[int, int, bytearray] | None]]:
    """Groups of ``count`` items, each item (group, lane, the group's buffer); the buffers
    rotate over ``slots`` as prefetched's do (a load writes its group's number into them)."""
    buffers = [bytearray(8) for _ in range(slots)]
    for k in range(12):
        buf = buffers[k % slots]
        buf[:] = bytes([k]) * 8
        written.append(k)
        yield [None if (k + i) % 5 == 4 else (k, i, buf) for i in range(count)]


def test_lanes_decode_every_item_in_group_order_and_never_on_a_reused_buffer(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(pipeline, "workers", lambda: 2)
    seen: dict[int, list[int]] = {i: [] for i in range(3)}
    written: list[int] = []

    def decode(i: int, item: tuple[int, int, bytearray]) -> None:
        k, lane, buf = item
        assert lane == i
        time.sleep(0.001 * ((k * 3 + i) % 4))  # lanes fall behind one another
        assert bytes(buf) == bytes([k]) * 8  # its group's bytes, not a later load's
        seen[i].append(k)

    groups = _lane_groups(3, pipeline.LANE_HOLD + 1, written)
    pipeline.decoded_in_lanes(groups, decode, 3)
    for i, ks in seen.items():
        assert ks == [k for k in range(12) if (k + i) % 5 != 4]
    assert written == list(range(12))
    assert not [t for t in threading.enumerate() if t.name.startswith("ertools-lane")]


@pytest.mark.parametrize(
    ("failing", "first"),
    [
        ({(5, 0), (3, 2)}, (3, 2)),  # an earlier group's error on a later lane
        ({(3, 1), (3, 0)}, (3, 0)),  # one group: the first lane's
        ({(8, 2)}, (8, 2)),
    ],
)
def test_lanes_raise_the_error_one_thread_meets_first(
    monkeypatch: pytest.MonkeyPatch, failing: set[tuple[int, int]], first: tuple[int, int]
) -> None:
    monkeypatch.setattr(pipeline, "workers", lambda: 2)

    def decode(i: int, item: tuple[int, int, bytearray]) -> None:
        k = item[0]
        time.sleep(0.001 * ((k + 2 * i) % 3))
        if (k, i) in failing:
            raise BagError(f"group {k} lane {i}")

    with pytest.raises(BagError, match=f"group {first[0]} lane {first[1]}$"):
        pipeline.decoded_in_lanes(_lane_groups(3, pipeline.LANE_HOLD + 1, []), decode, 3)
    assert not [t for t in threading.enumerate() if t.name.startswith("ertools-lane")]


def test_lanes_raise_a_load_error_after_the_errors_of_earlier_groups(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(pipeline, "workers", lambda: 2)

    def groups() -> Iterator[list[int | None]]:
        for k in range(10):
            if k == 6:
                raise BagError("load of group 6")
            yield [k, k]

    def decode_at(bad: int) -> Callable[[int, int], None]:
        def decode(i: int, k: int) -> None:
            if (k, i) == (bad, 1):
                raise BagError(f"decode of group {k}")

        return decode

    with pytest.raises(BagError, match="load of group 6"):
        pipeline.decoded_in_lanes(groups(), decode_at(99), 2)
    with pytest.raises(BagError, match="decode of group 4"):
        pipeline.decoded_in_lanes(groups(), decode_at(4), 2)


def test_worker_error_reaches_the_caller_as_itself(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(pipeline, "workers", lambda: 2)

    def load(k: int, scratch: list[bytearray]) -> int:
        if k == 5:
            raise BagError("corrupt lz4 chunk at byte 1234")
        return k

    got = []
    with pytest.raises(BagError, match="byte 1234"):
        for k in pipeline.prefetched(12, load):
            got.append(k)
    assert got == [0, 1, 2, 3, 4]
    # No loading thread is left behind.
    assert not [t for t in threading.enumerate() if t.name.startswith("ertools-load")]


@pytest.mark.slow
@pytest.mark.parametrize("fmt", ["ros1", "ros1-lz4", "ros1-bz2", "mcap-cdr"])
def test_damaged_chunk_read_on_a_worker_is_one_ertools_error(
    tmp_path: Path, scene: Scene, fmt: str, small_groups: None
) -> None:
    good = write(bag_name(tmp_path, fmt, "good"), fmt, scene.spec, chunk_bytes=2000)
    rng = np.random.default_rng(5)
    raised = 0
    for k in range(8):
        path = tmp_path / f"case{k}{good.suffix}"
        shutil.copy(good, path)
        data = bytearray(path.read_bytes())
        # Damage the second half, read by the workers after several groups went well.
        for at in rng.integers(len(data) // 2, len(data), 6):
            data[int(at)] ^= 0x5A
        path.write_bytes(bytes(data))
        try:
            read_poses(path, "/fbm3w/robot_at_work/pose")
        except ErtoolsError as err:
            assert str(err)
            raised += 1
    assert raised  # some damage must have been found (not all flips hit unread bytes)


def test_positional_read_without_pread(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Where the system has neither preadv nor pread (Windows): seek + read under a lock."""
    path = tmp_path / "f.bin"
    payload = bytes(range(256)) * 40
    path.write_bytes(payload)
    monkeypatch.delattr(os, "preadv", raising=False)
    monkeypatch.delattr(os, "pread", raising=False)
    fd = os.open(path, os.O_RDONLY)
    try:
        into = memoryview(bytearray(100))
        assert pipeline.read_at(fd, into, 1000) == 100
        assert bytes(into) == payload[1000:1100]
        assert pipeline.pread(fd, 50, len(payload) - 20) == payload[-20:]  # short at the end
    finally:
        os.close(fd)


def test_in_order_is_lexicographic() -> None:
    a = np.array([1, 1, 2, 2, 2])
    assert _in_order(a, np.array([0, 1, 0, 0, 1]))
    assert not _in_order(a, np.array([1, 0, 0, 0, 1]))  # tie on a, b decreases
    assert _in_order(a, np.array([5, 4, 0, 0, 1]), np.array([0, 0, 0, 0, 0])) is False
    assert _in_order(np.array([3, 2]), np.array([0, 0])) is False
    assert _in_order(np.array([7]))


def test_load_all_chunks_counts_every_uncompressed_byte(
    scene_bag: tuple[str, Path], small_groups: None
) -> None:
    fmt, path = scene_bag
    if fmt.startswith("rosbag2-sqlite") or fmt == "rosbag2-mcap":
        pytest.skip("n/a: chunk floor measured on single-file ROS1 and MCAP")

    with open_bag(path) as bag:
        total = bulk.load_all_chunks(bag)
    if fmt.startswith("ros1"):
        expected = _ros1_sizes(path)
    else:
        with path.open("rb") as f:
            summary = make_reader(f).get_summary()
        assert summary is not None
        expected = sum(c.uncompressed_size for c in summary.chunk_indexes)
    assert total == expected


def _ros1_sizes(path: Path) -> int:
    """Sum of the ``size`` field of every chunk record, walked record by record."""

    data = path.read_bytes()
    pos, total = 13, 0
    while pos + 4 <= len(data):
        (hlen,) = struct.unpack_from("<I", data, pos)
        header = data[pos + 4 : pos + 4 + hlen]
        (dlen,) = struct.unpack_from("<I", data, pos + 4 + hlen)
        fields = {}
        at = 0
        while at < len(header):
            (n,) = struct.unpack_from("<I", header, at)
            name, _, value = header[at + 4 : at + 4 + n].partition(b"=")
            fields[name] = value
            at += 4 + n
        if fields.get(b"op") == b"\x05":
            total += struct.unpack("<I", fields[b"size"])[0]
        pos += 8 + hlen + dlen
    return total


def test_default_groups_equal_small_groups(scene_bag: tuple[str, Path]) -> None:
    """The group size changes nothing but speed."""
    _fmt, path = scene_bag
    whole = fast_batch(path, "/fbm3w/robot_at_work/pose")
    mp = pytest.MonkeyPatch()
    try:
        mp.setattr(pipeline, "GROUP_BYTES", 2500)
        mp.setattr(pipeline, "workers", lambda: 2)
        assert_same(fast_batch(path, "/fbm3w/robot_at_work/pose"), whole)
    finally:
        mp.undo()


def _pose_between_blobs(tmp_path: Path, blob_bytes: int) -> Path:
    s = Spec()
    pose = s.conn("/robot/pose", "geometry_msgs/PoseStamped")
    blob = s.conn("/robot/camera", "std_msgs/String")
    t0 = 1_445_609_740_000_000_000
    for i in range(120):
        t = t0 + i * 100_000_000
        s.add(pose, t, stamp=t - 1000, frame="map", xyz=(0.1 * i, 0.2, 0.0), q=(0, 0, 0, 1))
        s.add(blob, t + 50_000_000, data="x" * blob_bytes)
    return write(tmp_path / f"blobs{blob_bytes}.bag", "ros1", s, chunk_bytes=200_000)


@pytest.mark.parametrize(("blob_bytes", "mapped"), [(40_000, True), (200, False)])
def test_pose_topic_between_big_messages_is_read_in_place(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, blob_bytes: int, mapped: bool
) -> None:
    """Records far apart (a pose topic between camera frames) are read through a map of
    their chunks, close together with the chunks: the same values as rosbags either way."""
    path = _pose_between_blobs(tmp_path, blob_bytes)
    calls: list[int] = []
    real = ros1_runs.mapped_group

    def spy(bag: object, chunks: list[object], scratch: list[object]) -> object:
        calls.append(len(chunks))
        return real(bag, chunks, scratch)

    monkeypatch.setattr(ros1_runs, "mapped_group", spy)
    monkeypatch.setattr(pipeline, "GROUP_BYTES", 30_000)  # several groups (and maps released)
    monkeypatch.setattr(pipeline, "workers", lambda: 2)
    assert_same(fast_batch(path, "/robot/pose"), reference_batch(path, "/robot/pose"))
    assert bool(calls) is mapped
    if mapped:
        assert len(calls) > 1


def test_a_reused_slot_releases_its_map(tmp_path: Path) -> None:
    path = tmp_path / "f.bin"
    path.write_bytes(b"\0" * 100_000)
    with path.open("rb") as f:
        mm = mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ)
    slot: list[object] = []
    pipeline.keep(slot, mm, path)
    assert slot[1] is mm and not mm.closed
    pipeline.scratch_view(slot, 10)  # the slot is reused for a plain read
    assert mm.closed and len(slot) == 1
