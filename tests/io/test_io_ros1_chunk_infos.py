"""A ROS1 index's chunk-info records read in one pass (``read_chunk_infos``): the values the
format specification puts in them, or None for anything but the one layout, and bags read the
same through it as record by record."""

from __future__ import annotations

import io
import struct
from pathlib import Path
from typing import Any

import pytest

from ertools import caches
from ertools.io.ros1 import layout
from ertools.io.ros1.chunk_infos import read_chunk_infos
from tests.helpers.bagmaker import Spec, write
from tests.helpers.fastpath import REAL_BAG

# rosbag (C++) writes a header's fields from a std::map, by name; rosbags in this order
ROSBAG_ORDER = (b"chunk_pos", b"count", b"end_time", b"op", b"start_time", b"ver")
ROSBAGS_ORDER = (b"op", b"ver", b"chunk_pos", b"start_time", b"end_time", b"count")
PREFIX = 4096  # bytes before the index section: the chunks' positions lie in them
S = 1_000_000_000


def field(name: bytes, value: bytes) -> bytes:
    return struct.pack("<I", len(name) + 1 + len(value)) + name + b"=" + value


def record(
    chunk_pos: int,
    start_ns: int,
    end_ns: int,
    counts: dict[int, int],
    *,
    order: tuple[bytes, ...] = ROSBAGS_ORDER,
    values: dict[bytes, bytes] | None = None,
    extra: bytes = b"",
    data_extra: bytes = b"",
) -> bytes:
    """A chunk-info record as the bag format 2.0 specification lays it out (op 0x06)."""
    given = {
        b"op": b"\x06",
        b"ver": struct.pack("<I", 1),
        b"chunk_pos": struct.pack("<Q", chunk_pos),
        b"start_time": struct.pack("<II", *divmod(start_ns, S)),
        b"end_time": struct.pack("<II", *divmod(end_ns, S)),
        b"count": struct.pack("<I", len(counts)),
        **(values or {}),
    }
    header = b"".join(field(name, given[name]) for name in order) + extra
    data = b"".join(struct.pack("<II", c, n) for c, n in counts.items()) + data_extra
    return struct.pack("<I", len(header)) + header + struct.pack("<I", len(data)) + data


CHUNKS: list[tuple[int, int, int, dict[int, int]]] = [
    (13, 1_448_013_600 * S, 1_448_013_600 * S + 999_999_999, {0: 120, 1: 12, 2: 1}),
    (900, 1_448_013_601 * S + 5, 1_448_013_602 * S, {}),
    (1700, 1_448_013_602 * S + 7, 1_448_013_603 * S + 1, {2: 7, 0: 119}),
    (4095, (2**32 - 1) * S + 999_999_999, (2**32 - 1) * S + 999_999_999, {7: 2**32 - 1}),
]


def read(section: bytes, count: int = len(CHUNKS)) -> Any:
    raw = bytes(PREFIX) + section
    return read_chunk_infos(io.BytesIO(raw), PREFIX, len(raw), count)


@pytest.mark.parametrize("order", [ROSBAG_ORDER, ROSBAGS_ORDER])
def test_the_records_of_one_layout_give_their_values(order: tuple[bytes, ...]) -> None:
    section = b"".join(record(*c, order=order) for c in CHUNKS)
    got = read(section)
    assert got == CHUNKS
    # connection order as written (a dict's), not sorted
    assert [list(c[3]) for c in got] == [list(c[3]) for c in CHUNKS]


def test_only_the_records_counted_are_read() -> None:
    section = b"".join(record(*c) for c in CHUNKS)
    assert read(section, 2) == CHUNKS[:2]
    assert read(section, 0) is None


def _every(**how: Any) -> bytes:
    """Every record of :data:`CHUNKS` written with the same oddity."""
    return b"".join(record(*c, **how) for c in CHUNKS)


def _cut_count(chunk_pos: int, start_ns: int, end_ns: int, counts: dict[int, int]) -> bytes:
    """A record whose header ends two bytes into the count's value, its field still saying
    ``count=`` and four bytes (what follows is the data's length)."""
    whole = record(chunk_pos, start_ns, end_ns, counts)
    (hlen,) = struct.unpack_from("<I", whole)
    header = whole[4 : 4 + hlen - 2]
    return struct.pack("<I", len(header)) + header + whole[4 + hlen :]


def _other_layouts() -> dict[str, bytes]:
    first, *rest = CHUNKS
    tail = b"".join(record(*c) for c in rest)
    return {
        "version 2": _every(values={b"ver": struct.pack("<I", 2)}),
        "another op": _every(values={b"op": b"\x05"}),
        "an extra field": _every(extra=field(b"x", b"1")),
        "a longer value": _every(values={b"ver": struct.pack("<Q", 1)}),
        "a field twice": _every(order=(*ROSBAGS_ORDER[:-1], b"ver", b"count")),
        "a missing field": _every(order=ROSBAGS_ORDER[1:]),
        "a field without '='": _every(extra=struct.pack("<I", 2) + b"ab"),
        "a field cut off": _every(extra=struct.pack("<I", 9) + b"ab"),
        "the count cut off by the header's end": b"".join(_cut_count(*c) for c in CHUNKS),
        "data longer than its count": _every(data_extra=bytes(8)),
        "two field orders": record(*first) + b"".join(record(*c, order=ROSBAG_ORDER) for c in rest),
        "another value in a fixed place": record(*first)
        + record(*CHUNKS[1], values={b"ver": struct.pack("<I", 3)})
        + b"".join(record(*c) for c in CHUNKS[2:]),
        "cut short": (record(*first) + tail)[:-1],
        "a chunk past the end": record(PREFIX + 10**6, *first[1:]) + tail,
        "a later chunk past the end": record(*first) + record(10**9, *CHUNKS[1][1:]) + tail,
    }


@pytest.mark.parametrize("how", sorted(_other_layouts()))
def test_any_other_layout_is_left_to_the_record_parser(how: str) -> None:
    section = _other_layouts()[how]
    assert read(section) is None


def test_more_records_counted_than_written_is_left_to_the_record_parser() -> None:
    section = b"".join(record(*c) for c in CHUNKS)
    assert read(section, len(CHUNKS) + 1) is None


def _layouts(path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[Any, Any, bool]:
    """``path``'s layout with the one-pass read and without it, and whether it was taken."""
    taken: list[bool] = []

    def spy(*args: Any) -> Any:
        got = read_chunk_infos(*args)
        taken.append(got is not None)
        return got

    caches.clear()
    with monkeypatch.context() as mp:
        mp.setattr(layout, "read_chunk_infos", spy)
        fast = layout.read_layout(path)
    caches.clear()
    with monkeypatch.context() as mp:
        mp.setattr(layout, "read_chunk_infos", lambda *args: None)
        slow = layout.read_layout(path)
    caches.clear()
    return fast, slow, any(taken)


def _chunks(lay: Any) -> list[tuple[int, int, int, list[tuple[int, int]]]]:
    return [(c.pos, c.start_ns, c.end_ns, list(c.counts.items())) for c in lay.chunks]


@pytest.mark.parametrize("fmt", ["ros1", "ros1-lz4", "ros1-bz2"])
def test_a_bag_reads_the_same_either_way(
    tmp_path: Path, fmt: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    spec = Spec()
    pose = spec.conn("/gt/pose", "geometry_msgs/PoseStamped")
    flat = spec.conn("/gt/pose2d", "geometry_msgs/Pose2D")
    late = spec.conn("/robot/pose", "geometry_msgs/PoseStamped", "/robot")
    t0 = 1_448_013_600 * S
    for i in range(600):
        t = t0 + i * (S // 120)
        spec.add(pose, t, stamp=t, frame="world", xyz=(i, 0, 0), q=(0, 0, 0, 1))
        spec.add(flat, t + 1, x=float(i), y=0.0, theta=0.0)
        if i > 300 and i % 12 == 0:
            spec.add(late, t + 2, stamp=t, frame="map", xyz=(0, i, 0), q=(0, 0, 0, 1))
    path = write(tmp_path / "three.bag", fmt, spec, chunk_bytes=4096)
    fast, slow, taken = _layouts(path, monkeypatch)
    assert taken and len(fast.chunks) > 10
    assert _chunks(fast) == _chunks(slow)
    assert (fast.indexed, fast.problems, fast.conns) == (slow.indexed, slow.problems, slow.conns)
    # the counts are the messages written to each connection
    totals: dict[int, int] = {}
    for chunk in fast.chunks:
        for cid, n in chunk.counts.items():
            totals[cid] = totals.get(cid, 0) + n
    assert sorted(totals.values()) == sorted([600, 600, len(range(312, 600, 12))])


def test_the_real_2015_bag_reads_the_same_either_way(monkeypatch: pytest.MonkeyPatch) -> None:
    if not REAL_BAG.is_file():
        pytest.skip(f"n/a: {REAL_BAG} not present")
    fast, slow, taken = _layouts(REAL_BAG, monkeypatch)
    assert taken and _chunks(fast) == _chunks(slow) and fast.problems == slow.problems == []


def test_a_damaged_chunk_info_is_named_as_before(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    spec = Spec()
    pose = spec.conn("/gt/pose", "geometry_msgs/PoseStamped")
    for i in range(200):
        t = 1_448_013_600 * S + i * (S // 120)
        spec.add(pose, t, stamp=t, frame="world", xyz=(i, 0, 0), q=(0, 0, 0, 1))
    path = write(tmp_path / "b.bag", "ros1", spec, chunk_bytes=2048)
    raw = bytearray(path.read_bytes())
    at = raw.rfind(b"chunk_pos=") + len(b"chunk_pos=")  # the last chunk info's position
    struct.pack_into("<Q", raw, at, len(raw) + 100)
    path.write_bytes(bytes(raw))
    fast, slow, taken = _layouts(path, monkeypatch)
    assert not taken
    assert not fast.indexed and fast.problems == slow.problems
    assert "past the end of the file" in fast.problems[0]
    assert _chunks(fast) == _chunks(slow)
