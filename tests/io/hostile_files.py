"""Hostile files built byte by byte: ROS1 bags and MCAP files whose records say what a test
needs (many connections, a chunk that inflates past its declared size, a huge honest chunk),
written from the format specifications (http://wiki.ros.org/Bags/Format/2.0 and
https://mcap.dev/spec) without any ertools code, so what ertools reads is checked against
what was written.

Compressed streams are made cheap: bz2 and zstd streams of zeros are compressed once and
repeated (both formats allow streams and frames end to end), so a "gigabyte" costs a few
kilobytes to build and nothing to hold.
"""

from __future__ import annotations

import bz2
import functools
import struct
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import lz4.frame
import zstandard

STRING_DEF = "string data\n"
STRING_MD5 = "992ce8a1687cec8c8bd883ec73ca41d1"


def u32(v: int) -> bytes:
    return struct.pack("<I", v)


def u64(v: int) -> bytes:
    return struct.pack("<Q", v)


def stamp(ns: int) -> bytes:
    return struct.pack("<II", ns // 1_000_000_000, ns % 1_000_000_000)


def header(fields: dict[str, bytes]) -> bytes:
    out = b""
    for name, value in fields.items():
        item = name.encode() + b"=" + value
        out += u32(len(item)) + item
    return out


def record(fields: dict[str, bytes], data: bytes) -> bytes:
    head = header(fields)
    return u32(len(head)) + head + u32(len(data)) + data


def string_payload(text: str) -> bytes:
    raw = text.encode()
    return u32(len(raw)) + raw


@dataclass
class Ros1Conn:
    cid: int
    topic: str
    msgtype: str = "std_msgs/String"
    definition: str = STRING_DEF
    md5: str = STRING_MD5

    def record(self) -> bytes:
        data = header(
            {
                "topic": self.topic.encode(),
                "type": self.msgtype.encode(),
                "md5sum": self.md5.encode(),
                "message_definition": self.definition.encode(),
            }
        )
        return record({"op": b"\x07", "conn": u32(self.cid), "topic": self.topic.encode()}, data)


def message_record(cid: int, t_ns: int, payload: bytes) -> bytes:
    # conn, op, time: the standard 38-byte message header rosbag writes
    return record({"conn": u32(cid), "op": b"\x02", "time": stamp(t_ns)}, payload)


@dataclass
class Ros1Chunk:
    """Messages (conn, t_ns, payload) of one chunk; ``compress`` turns its records into the
    stored bytes and ``declared`` overrides the ``size`` field (default: the true size)."""

    messages: list[tuple[int, int, bytes]]
    compression: str = "none"
    compress: Callable[[bytes], bytes] | None = None
    declared: int | None = None
    extra_conns: list[int] = field(default_factory=list)


def ros1_bag(path: Path, conns: Sequence[Ros1Conn], chunks: Sequence[Ros1Chunk]) -> Path:
    """An indexed ROS1 v2.0 bag: each chunk holds the connection records of the connections
    it first uses, then its messages; the index-data records follow each chunk; connection
    and chunk-info records end the file."""
    by_id = {c.cid: c for c in conns}
    seen: set[int] = set()
    body = b""
    infos: list[tuple[int, int, int, dict[int, int]]] = []
    start = 13 + 4096  # the magic, then a bag header record padded to 4096 bytes as rosbag does
    for chunk in chunks:
        inner = b""
        entries: dict[int, list[tuple[int, int]]] = {}
        for cid in [*chunk.extra_conns, *(m[0] for m in chunk.messages)]:
            if cid not in seen:
                seen.add(cid)
                inner += by_id[cid].record()
        for cid, t, payload in chunk.messages:
            entries.setdefault(cid, []).append((t, len(inner)))
            inner += message_record(cid, t, payload)
        stored = chunk.compress(inner) if chunk.compress else inner
        size = len(inner) if chunk.declared is None else chunk.declared
        pos = start + len(body)
        body += record(
            {"op": b"\x05", "compression": chunk.compression.encode(), "size": u32(size)}, stored
        )
        for cid, items in entries.items():
            data = b"".join(stamp(t) + u32(off) for t, off in items)
            body += record(
                {"op": b"\x04", "ver": u32(1), "conn": u32(cid), "count": u32(len(items))}, data
            )
        times = [m[1] for m in chunk.messages] or [0]
        counts = {cid: len(items) for cid, items in entries.items()}
        infos.append((pos, min(times), max(times), counts))
    index_pos = start + len(body)
    index = b"".join(c.record() for c in conns)
    for pos, t0, t1, counts in infos:
        data = b"".join(u32(cid) + u32(n) for cid, n in counts.items())
        index += record(
            {
                "op": b"\x06",
                "ver": u32(1),
                "chunk_pos": u64(pos),
                "start_time": stamp(t0),
                "end_time": stamp(t1),
                "count": u32(len(counts)),
            },
            data,
        )
    head = header(
        {
            "op": b"\x03",
            "index_pos": u64(index_pos),
            "conn_count": u32(len(conns)),
            "chunk_count": u32(len(chunks)),
        }
    )
    pad = 4096 - 8 - len(head)
    bag_header = u32(len(head)) + head + u32(pad) + b" " * pad
    path.write_bytes(b"#ROSBAG V2.0\n" + bag_header + body + index)
    return path


@functools.cache
def bz2_zeros(n: int) -> bytes:
    """One bz2 stream of ``n`` zero bytes."""
    return bz2.compress(bytes(n))


@functools.cache
def zstd_zeros(n: int) -> bytes:
    """One zstd frame of ``n`` zero bytes (its header states the size)."""
    return zstandard.ZstdCompressor().compress(bytes(n))


def bz2_bomb(extra_bytes: int, step: int = 8 << 20) -> Callable[[bytes], bytes]:
    """A chunk compressor: the true records, then ``extra_bytes`` of zeros in more bz2
    streams (a reader that decompresses every stream gets them all)."""

    def compress(inner: bytes) -> bytes:
        return bz2.compress(inner) + bz2_zeros(step) * (extra_bytes // step)

    return compress


# --- MCAP (https://mcap.dev/spec): records are op (u8), length (u64), body --------------------

MCAP_MAGIC = b"\x89MCAP0\r\n"


def _mrec(op: int, body: bytes) -> bytes:
    return bytes([op]) + u64(len(body)) + body


def _mstr(text: str | bytes) -> bytes:
    raw = text.encode() if isinstance(text, str) else text
    return u32(len(raw)) + raw


def mcap_message(channel: int, t_ns: int, data: bytes, seq: int = 0) -> bytes:
    return _mrec(0x05, struct.pack("<HIQQ", channel, seq, t_ns, t_ns) + data)


@dataclass
class McapChannel:
    cid: int
    topic: str
    schema_name: str = "std_msgs/msg/String"
    schema: str = "string data\n"


@dataclass
class McapChunk:
    """Messages (channel, t_ns, data) of one chunk, stored as ``compression`` says; ``size``
    overrides the declared uncompressed size; ``zeros`` (channel, t_ns, n) adds one last
    message of n zero bytes, built as zstd frames of zeros (cheap however large)."""

    messages: list[tuple[int, int, bytes]]
    compression: str = ""
    size: int | None = None
    zeros: tuple[int, int, int] | None = None


def zstd_of(data: bytes) -> bytes:
    return zstandard.ZstdCompressor().compress(data)


def mcap_file(path: Path, channels: Sequence[McapChannel], chunks: Sequence[McapChunk]) -> Path:
    """An indexed MCAP file: header, schemas and channels, chunks each followed by their
    message indexes, data end, then a summary (schemas, channels, chunk indexes, statistics)
    and the footer. Chunk CRCs are 0 (not computed), which the specification allows."""
    out = MCAP_MAGIC + _mrec(0x01, _mstr("ros2") + _mstr("ertools-tests"))
    defs = b""
    for ch in channels:
        defs += _mrec(
            0x03,
            struct.pack("<H", ch.cid) + _mstr(ch.schema_name) + _mstr("ros2msg") + _mstr(ch.schema),
        )
        defs += _mrec(
            0x04,
            struct.pack("<HH", ch.cid, ch.cid) + _mstr(ch.topic) + _mstr("cdr") + u32(0),
        )
    out += defs
    indexes = b""
    counts: dict[int, int] = {}
    times: list[int] = []
    for chunk in chunks:
        records = b""
        entries: dict[int, list[tuple[int, int]]] = {}
        for cid, t, data in chunk.messages:
            entries.setdefault(cid, []).append((t, len(records)))
            records += mcap_message(cid, t, data)
            counts[cid] = counts.get(cid, 0) + 1
            times.append(t)
        true_size = len(records)
        ts = [m[1] for m in chunk.messages]
        if chunk.zeros is not None:
            assert chunk.compression == "zstd"
            cid, t, n = chunk.zeros
            entries.setdefault(cid, []).append((t, len(records)))
            counts[cid] = counts.get(cid, 0) + 1
            times.append(t)
            ts.append(t)
            records += _mrec(0x05, b"")[:1] + u64(22 + n) + struct.pack("<HIQQ", cid, 0, t, t)
            true_size = len(records) + n
        size = true_size if chunk.size is None else chunk.size
        if chunk.zeros is not None:
            stored = zstd_frame(records, chunk.zeros[2])
        elif chunk.compression == "zstd":
            stored = zstd_of(records)
        elif chunk.compression == "lz4":
            stored = lz4.frame.compress(records)
        else:
            stored = records
        ts = ts or [0]
        start = len(out)
        out += _mrec(
            0x06,
            struct.pack("<QQQI", min(ts), max(ts), size, 0)
            + _mstr(chunk.compression)
            + u64(len(stored))
            + stored,
        )
        chunk_len = len(out) - start
        offsets = {}
        mi_start = len(out)
        for cid, items in entries.items():
            offsets[cid] = len(out)
            pairs = b"".join(struct.pack("<QQ", t, off) for t, off in items)
            out += _mrec(0x07, struct.pack("<H", cid) + u32(len(pairs)) + pairs)
        offset_map = b"".join(struct.pack("<HQ", c, o) for c, o in offsets.items())
        indexes += _mrec(
            0x08,
            struct.pack("<QQQQ", min(ts), max(ts), start, chunk_len)
            + u32(len(offset_map))
            + offset_map
            + u64(len(out) - mi_start)
            + _mstr(chunk.compression)
            + struct.pack("<QQ", len(stored), size),
        )
    out += _mrec(0x0F, u32(0))
    summary_start = len(out)
    count_map = b"".join(struct.pack("<HQ", c, n) for c, n in counts.items())
    stats = _mrec(
        0x0B,
        struct.pack(
            "<QHIIIIQQ",
            sum(counts.values()),
            len(channels),
            len(channels),
            0,
            0,
            len(chunks),
            min(times or [0]),
            max(times or [0]),
        )
        + u32(len(count_map))
        + count_map,
    )
    out += defs + indexes + stats
    out += _mrec(0x02, struct.pack("<QQI", summary_start, 0, 0))
    path.write_bytes(out + MCAP_MAGIC)
    return path


ZSTD_BLOCK = 128 << 10  # the largest block a zstd frame may hold


def zstd_frame(head: bytes, zeros: int) -> bytes:
    """One zstd frame holding ``head`` then ``zeros`` zero bytes, its header stating the
    whole size, written block by block (RFC 8878): ``head`` in raw blocks, the zeros in RLE
    blocks of 128 KiB, 4 bytes each, so a gigabyte costs 32 KiB."""

    def block(kind: int, size: int, content: bytes, last: bool) -> bytes:
        return (int(last) | kind << 1 | size << 3).to_bytes(3, "little") + content

    blocks = []
    for at in range(0, len(head), ZSTD_BLOCK):
        part = head[at : at + ZSTD_BLOCK]
        blocks.append((0, len(part), part))
    for at in range(0, zeros, ZSTD_BLOCK):
        blocks.append((1, min(ZSTD_BLOCK, zeros - at), b"\0"))
    body = b"".join(
        block(kind, size, content, i == len(blocks) - 1)
        for i, (kind, size, content) in enumerate(blocks)
    )
    # magic; descriptor: an 8-byte content size, no single segment, no checksum; a window of
    # 2^(10+7) = 128 KiB
    return b"\x28\xb5\x2f\xfd" + bytes([0xC0, 7 << 3]) + u64(len(head) + zeros) + body
