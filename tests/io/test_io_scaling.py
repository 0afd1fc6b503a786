"""Reading a file costs work in proportion to what it holds: no check of a connection, chunk or
record that compares it with every other one (finding 11 of issue 36: the duplicate-connection
check of ROS1 indexes was quadratic, `info` took 285 s at 100,000 connections).

Time is not measured (it depends on the machine and its load): the work is counted as the
Python function calls made (``sys.setprofile``, generator steps included), which a loop over
connections inside a loop over connections multiplies. Four times the connections (or chunks)
must cost at most six times the calls: linear work gives four, n log n a little more, a
quadratic check sixteen.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from ertools import caches
from ertools.io.info import describe
from ertools.io.messages import read_messages
from ertools.io.summary import summary as bag_summary
from tests.io.hostile_files import (
    McapChannel,
    McapChunk,
    Ros1Chunk,
    Ros1Conn,
    mcap_file,
    ros1_bag,
    string_payload,
    u32,
)

pytestmark = pytest.mark.slow

T0 = 1_448_020_800 * 10**9
SMALL, LARGE = 400, 1600
MAX_RATIO = 6.0


def calls(work: Callable[[], Any]) -> int:
    count = 0

    def profile(_frame: Any, event: str, _arg: Any) -> None:
        nonlocal count
        if event == "call":
            count += 1

    caches.clear()  # a scan kept from an earlier read would hide its cost
    sys.setprofile(profile)
    try:
        work()
    finally:
        sys.setprofile(None)
    return count


def _cdr(text: str) -> bytes:
    raw = text.encode() + b"\0"
    return b"\x00\x01\x00\x00" + u32(len(raw)) + raw


def many(tmp_path: Path, fmt: str, n: int, shape: str) -> Path:
    """A file with ``n`` connections (``shape`` "connections": one message each, 100 to a
    chunk; "one-chunk": all in one chunk) or ``n`` chunks (``shape`` "chunks": one
    connection, one message per chunk)."""
    if shape in ("connections", "one-chunk"):
        owners = list(range(n))
        per_chunk = 100 if shape == "connections" else n
    else:
        owners = [0] * n
        per_chunk = 1
    msgs = [(cid, T0 + i * 1000) for i, cid in enumerate(owners)]
    groups = [msgs[a : a + per_chunk] for a in range(0, n, per_chunk)]
    topics = sorted(set(owners))
    if fmt.startswith("ros1"):
        conns = [Ros1Conn(c, f"/t{c}") for c in topics]
        chunks = [Ros1Chunk([(c, t, string_payload("x")) for c, t in g]) for g in groups]
        name = "b.bag.active" if fmt == "ros1-active" else "b.bag"
        path = ros1_bag(tmp_path / f"{n}{shape}{name}", conns, chunks)
        if fmt == "ros1-active":
            # a recording not closed: index position 0 in the bag header, read by a scan
            data = bytearray(path.read_bytes())
            at = data.index(b"index_pos=") + len(b"index_pos=")
            data[at : at + 8] = bytes(8)
            path.write_bytes(bytes(data))
        return path
    channels = [McapChannel(c + 1, f"/t{c}") for c in topics]
    mchunks = [McapChunk([(c + 1, t, _cdr("x")) for c, t in g], "zstd") for g in groups]
    return mcap_file(tmp_path / f"{n}{shape}.mcap", channels, mchunks)


READS: dict[str, Callable[[Path], Any]] = {
    "info": describe,
    "info --check": lambda p: describe(p, check=True),
    "summary": lambda p: bag_summary(p, exact=True),
    "read one topic": lambda p: read_messages(p, "/t0"),
}


@pytest.mark.parametrize("read", list(READS))
@pytest.mark.parametrize("shape", ["connections", "one-chunk", "chunks"])
@pytest.mark.parametrize("fmt", ["ros1", "ros1-active", "mcap"])
def test_work_grows_linearly(tmp_path: Path, fmt: str, shape: str, read: str) -> None:
    small = many(tmp_path, fmt, SMALL, shape)
    large = many(tmp_path, fmt, LARGE, shape)
    work = READS[read]
    # the same answer at both sizes, so the count is of the same work
    assert len(describe(large).summary.topics) == (1 if shape == "chunks" else LARGE)
    ratio = calls(lambda: work(large)) / calls(lambda: work(small))
    assert ratio <= MAX_RATIO, f"{LARGE // SMALL}x the {shape}: {ratio:.1f}x the calls"
