"""The layout of a ROS1 bag: its connections, chunks and index-data entries, read from the
index section at the end of the file, or rebuilt by scanning every record when there is no
usable index (``.bag.active`` files, truncated copies).

:class:`ertools.io.ros1.index.Ros1Bag` reads messages through a layout;
:mod:`ertools.io.ros1.check` checks one against the records.
"""

from __future__ import annotations

import functools
import logging
import os
import struct
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from struct import error as struct_error
from typing import BinaryIO

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64, U8
from ertools.caches import register
from ertools.errors import BagError
from ertools.inputs import open_regular
from ertools.io.decode.fast import read_at
from ertools.io.inflate import Allowance, inflate
from ertools.io.model import Conn, short_msgtype
from ertools.io.ros1.chunk_infos import read_chunk_infos
from ertools.io.ros1.records import (
    MAGIC_LEN,
    OP_BAG_HEADER,
    OP_CHUNK,
    OP_CHUNK_INFO,
    OP_CONNECTION,
    OP_INDEX,
    OP_MSG,
    RecordError,
    chunk_info,
    connection_fields,
    parse_fields,
    read_record,
    time_ns,
    u32,
    u64,
)

log = logging.getLogger("ertools.io.ros1.layout")


INDEX_DTYPE = np.dtype([("sec", "<u4"), ("nsec", "<u4"), ("off", "<u4")])
# The message-data record header rosbag and rosbags write: conn (4), op (1), time (8) fields.
MSG_HEADER_LEN = 4 + len("conn=") + 4 + 4 + len("op=") + 1 + 4 + len("time=") + 8
U32 = struct.Struct("<I")
OP_AT = (0, 13, 17, 30)  # where the op field can sit in a standard message-record header


def op_word(buf: U8, pos: I64) -> npt.NDArray[np.uint64]:
    return read_at(buf, pos, np.dtype("<u8"))


OP_MSG_WORD = int.from_bytes(b"\x04\x00\x00\x00op=\x02", "little")


@dataclass
class Ros1Chunk:
    """One chunk: where it is, its time span and per-connection counts.

    ``entries`` (conn -> (record times, offsets in the uncompressed chunk)) is filled when the
    index-data records after the chunk are read (or by a scan); ``compression``, ``data_pos``,
    ``data_len`` and ``size`` (its declared uncompressed size) when its record header is.
    """

    pos: int
    start_ns: int
    end_ns: int
    counts: dict[int, int]
    compression: str = ""
    data_pos: int = -1
    data_len: int = -1
    entries: dict[int, tuple[I64, I64]] | None = None
    size: int = -1


@dataclass
class Ros1Layout:
    """The index of a ROS1 bag (read or rebuilt by a scan)."""

    path: Path
    size: int
    indexed: bool
    conns: list[Conn]
    chunks: list[Ros1Chunk]
    problems: list[str] = field(default_factory=list)


def conn_record(cid: int, topic: str, fields: dict[str, bytes]) -> Conn:
    def text(name: str) -> str:
        return fields.get(name, b"").decode("utf-8", "replace")

    return Conn(
        cid,
        topic or text("topic"),
        short_msgtype(text("type")),
        text("message_definition"),
        "msg" if text("message_definition") else "",
        "ros1",
        text("latching") not in ("", "0"),
        text("md5sum"),
    )


def entries_from_index(data: bytes | memoryview) -> tuple[I64, I64]:
    arr = np.frombuffer(data, dtype=INDEX_DTYPE)
    # Computed in place: fresh memory is slow to fault in, and an hour's entries are 5 MB.
    t = np.multiply(arr["sec"], 1_000_000_000, dtype=np.int64)
    np.add(t, arr["nsec"], out=t)
    return t, arr["off"].astype(np.int64)


def cat_arrays(parts: list[I64]) -> I64:
    """Arrays end to end; one array as it is (no copy of an hour's entries)."""
    return parts[0] if len(parts) == 1 else np.concatenate(parts)


def joined_entries(parts: list[bytes | tuple[I64, I64]]) -> tuple[I64, I64]:
    """(times, offsets) of one connection's entries over several chunks."""
    if all(isinstance(p, bytes) for p in parts):
        return entries_from_index(b"".join(p for p in parts if isinstance(p, bytes)))
    pairs = [entries_from_index(p) if isinstance(p, bytes) else p for p in parts]
    return np.concatenate([p[0] for p in pairs]), np.concatenate([p[1] for p in pairs])


@functools.lru_cache(maxsize=4096)
def index_header(header: bytes) -> tuple[int, int, int, int] | None:
    """(op, ver, conn, count) of an index-data record header, None when malformed. Cached:
    an hour bag repeats the same few headers (one per connection and usual count)."""
    try:
        fields = parse_fields(header)
        return fields["op"][0], u32(fields, "ver"), u32(fields, "conn"), u32(fields, "count")
    except (RecordError, KeyError, IndexError, struct_error):
        return None


# Layouts rebuilt by a scan, by the file's identity: the scan walks every record (seconds for
# an hour-long ``.active`` file) and one command opens a file several times (its summary, its
# states, its poses). A file that grew or changed has another key.
_SCANNED: dict[tuple[str, int, int, int, int], Ros1Layout] = {}
register(_SCANNED.clear)
# Layouts read from an index, by the file's identity too: a command reads a file's index for
# its summary and again to read it (2.3 ms for the GT hour's 192 chunk infos, parsed record by
# record in Python). Each caller gets a copy (:func:`_fresh`): readers fill in the chunks they
# read (where their data lies), and a reader counts the chunk headers it reads itself.
_INDEXED: dict[tuple[str, int, int, int, int], Ros1Layout] = {}
register(_INDEXED.clear)
# Indexed layouts kept at most (a few files a command; an 8-hour bag's is ~1,500 chunks)
MAX_INDEXED = 16


def read_layout(path: Path) -> Ros1Layout:
    """The index of the bag at ``path``; scans when the index is missing or damaged (either
    is kept per file version, :mod:`ertools.caches`; an index read is handed out as a copy).

    Raises:
        BagError: not even the bag header is readable.
    """
    with open_regular(path) as f:
        st = os.fstat(f.fileno())
        key = (str(path), st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)
        indexed = _INDEXED.get(key)
        if indexed is not None:
            return _fresh(indexed)
        found = _SCANNED.get(key)
        if found is None:
            try:
                found = _read_layout(f, path, st.st_size)
            except BagError as err:
                if err.path is not None:
                    raise
                raise BagError(err.message, path=path) from err
            if not found.indexed:
                # one version per path (a recording's file grows: only its latest scan is
                # worth keeping) and a few files at most (an hour's entries are ~20 MB)
                for old in [k for k in _SCANNED if k[0] == key[0]]:
                    del _SCANNED[old]
                if len(_SCANNED) >= 4:
                    _SCANNED.clear()
                _SCANNED[key] = found
            else:
                if len(_INDEXED) >= MAX_INDEXED:
                    _INDEXED.clear()
                _INDEXED[key] = _fresh(found)
    return found


def _fresh(layout: Ros1Layout) -> Ros1Layout:
    """A copy of an indexed layout as :func:`_read_layout` makes it: its chunks as the index
    gives them, nothing read from their records yet (the counts are never modified: shared)."""
    return Ros1Layout(
        layout.path,
        layout.size,
        layout.indexed,
        list(layout.conns),
        [Ros1Chunk(c.pos, c.start_ns, c.end_ns, c.counts) for c in layout.chunks],
        list(layout.problems),
    )


def _read_layout(f: BinaryIO, path: Path, size: int) -> Ros1Layout:
    """:func:`read_layout` of the open file ``f`` (``size`` bytes)."""
    try:
        head, _ = read_record(f, MAGIC_LEN, size)
        if head.op != OP_BAG_HEADER:
            raise RecordError("first record is not the bag header", MAGIC_LEN)
        index_pos = u64(head.fields, "index_pos")
        conn_count = u32(head.fields, "conn_count")
        chunk_count = u32(head.fields, "chunk_count")
    except (RecordError, KeyError, struct_error) as err:
        raise BagError(f"unreadable ROS1 bag header ({err}); not a bag?", path=path) from err
    if index_pos == 0:
        return scan_layout(f, path, size, head.end, "not indexed (recording not closed)")
    if head.end == index_pos == size and conn_count == 0 and chunk_count == 0:
        # What a recorder leaves when nothing arrived: the header, then an empty index
        # (nothing between them; records there would mean a damaged header: scanned).
        return Ros1Layout(path, size, True, [], [])
    if index_pos >= size:
        return scan_layout(
            f,
            path,
            size,
            head.end,
            f"truncated: the index at byte {index_pos} lies past the end ({size} bytes)",
        )
    try:
        conns: list[Conn] = []
        ids: set[int] = set()
        pos = index_pos
        for _ in range(conn_count):
            rec, data = read_record(f, pos, size, with_data=True)
            if rec.op != OP_CONNECTION:
                raise RecordError("expected a connection record", pos)
            cid, topic, fields = connection_fields(rec, data)
            if cid in ids:
                # a damaged id: one connection's messages would be read as another's
                raise RecordError(f"two connection records with id {cid}", pos)
            ids.add(cid)
            conns.append(conn_record(cid, topic, fields))
            pos = rec.end
        if chunk_count == 0 and conn_count and index_pos > head.end:
            # records between the header and the index, but no chunk to find them by
            raise RecordError("the bag header counts no chunks before its index", MAGIC_LEN)
        found = read_chunk_infos(f, pos, size, chunk_count)
        if found is not None:
            return Ros1Layout(path, size, True, conns, [Ros1Chunk(*info) for info in found])
        chunks = []
        for _ in range(chunk_count):
            rec, data = read_record(f, pos, size, with_data=True)
            if rec.op != OP_CHUNK_INFO:
                raise RecordError("expected a chunk-info record", pos)
            cpos, start, end, counts = chunk_info(rec, data)
            if cpos >= size:
                raise RecordError(f"chunk position {cpos} past the end of the file", pos)
            chunks.append(Ros1Chunk(cpos, start, end, counts))
            pos = rec.end
    except (RecordError, KeyError, struct_error, IndexError) as err:
        return scan_layout(f, path, size, head.end, f"damaged index ({err})")
    return Ros1Layout(path, size, True, conns, chunks)


def chunk_head(fields: dict[str, bytes]) -> tuple[str, int]:
    """(compression, declared uncompressed size; -1 when not stated) of a chunk record."""
    compression = fields.get("compression", b"none").decode("ascii", "replace")
    size = u32(fields, "size") if len(fields.get("size", b"")) >= 4 else -1
    return compression, size


def decompress(compression: str, data: bytes, size: int, where: str) -> bytes:
    """Uncompressed chunk bytes, never more than the ``size`` the chunk record declares
    (:func:`ertools.io.inflate.inflate`: within the budget, or a BagError)."""
    if compression not in ("none", "bz2", "lz4"):  # what the ROS1 format defines
        raise BagError(f"unsupported chunk compression {compression!r} {where}")
    if compression != "none" and size < 0:
        raise BagError(f"damaged {compression} chunk {where}: its record states no size")
    out: bytes = inflate(compression, data, size, where)
    return out


def _walk_chunk(buf: bytes, base: int) -> Iterator[tuple[int, dict[str, bytes], int, int]]:
    """(offset, header fields, data offset, data length) of each record inside a chunk."""
    pos = 0
    n = len(buf)
    while pos + 4 <= n:
        hlen = int.from_bytes(buf[pos : pos + 4], "little")
        if pos + 8 + hlen > n:
            raise RecordError("record cut off inside chunk", base + pos)
        fields = parse_fields(buf[pos + 4 : pos + 4 + hlen], base + pos + 4)
        dlen = int.from_bytes(buf[pos + 4 + hlen : pos + 8 + hlen], "little")
        dpos = pos + 8 + hlen
        if dpos + dlen > n:
            raise RecordError("record data cut off inside chunk", base + pos)
        yield pos, fields, dpos, dlen
        pos = dpos + dlen


def _scanned_chunk(
    pos: int,
    compression: str,
    data_pos: int,
    data_len: int,
    per: dict[int, tuple[list[int], list[int]]],
) -> Ros1Chunk:
    entries = {
        cid: (np.array(ts, dtype=np.int64), np.array(offs, dtype=np.int64))
        for cid, (ts, offs) in per.items()
    }
    times = [t for t, _ in entries.values() if len(t)]
    return Ros1Chunk(
        pos,
        min(int(t.min()) for t in times) if times else 0,
        max(int(t.max()) for t in times) if times else 0,
        {cid: len(t) for cid, (t, _) in entries.items()},
        compression,
        data_pos,
        data_len,
        entries,
    )


def scan_layout(f: BinaryIO, path: Path, size: int, pos: int, why: str) -> Ros1Layout:
    """Rebuild the index by walking every record (and every record inside every chunk).

    A recorder writes the chunk it is filling straight into the file, after a chunk header
    whose size is only set when the chunk is closed; in an ``.active`` file those messages
    appear as records outside any chunk. They are gathered into a pseudo-chunk (uncompressed,
    covering that stretch of the file) so they are read like the others.
    """
    log.info("%s: %s; scanning the whole file", path, why)
    problems = [why]
    conns: dict[int, Conn] = {}
    chunks: list[Ros1Chunk] = []
    loose: dict[int, tuple[list[int], list[int]]] = {}
    loose_start = loose_end = -1
    allowance = Allowance(size, str(path))

    def flush() -> None:
        nonlocal loose, loose_start
        if loose:
            chunks.append(
                _scanned_chunk(loose_start, "none", loose_start, loose_end - loose_start, loose)
            )
        loose, loose_start = {}, -1

    while pos < size:
        try:
            rec, data = read_record(f, pos, size, with_data=True)
        except RecordError as err:
            problems.append(f"truncated: last record incomplete ({err}); read up to byte {pos}")
            break
        if rec.op in (OP_MSG, OP_CONNECTION):
            try:
                if rec.op == OP_MSG:
                    cid, t = u32(rec.fields, "conn"), time_ns(rec.fields, "time")
                    if loose_start < 0:
                        loose_start = rec.pos
                    ts, offs = loose.setdefault(cid, ([], []))
                    ts.append(t)
                    offs.append(rec.pos - loose_start)
                    loose_end = rec.end
                else:
                    cid, topic, cfields = connection_fields(rec, data)
                    conns.setdefault(cid, conn_record(cid, topic, cfields))
            except (RecordError, KeyError, struct_error, IndexError) as err:
                problems.append(f"damaged record at byte {pos} ({err}); scan stopped there")
                break
        elif rec.op == OP_CHUNK:
            flush()
            compression, usize = chunk_head(rec.fields)
            if compression != "none":
                allowance.add(usize, f"at byte {pos}")
            try:
                buf = decompress(compression, data, usize, f"at byte {pos}")
                per: dict[int, tuple[list[int], list[int]]] = {}
                for off, fields, dpos, dlen in _walk_chunk(buf, rec.data_pos):
                    op = fields["op"][0]
                    if op == OP_CONNECTION:
                        cid = u32(fields, "conn")
                        cfields = parse_fields(buf[dpos : dpos + dlen])
                        # strict, as for the index's connection records: a name that is not
                        # UTF-8 is damage, never a topic or type with replacement characters
                        topic = fields.get("topic", b"").decode("utf-8")
                        cfields.get("type", b"").decode("utf-8")
                        conns.setdefault(cid, conn_record(cid, topic, cfields))
                    elif op == OP_MSG:
                        ts, offs = per.setdefault(u32(fields, "conn"), ([], []))
                        ts.append(time_ns(fields, "time"))
                        offs.append(off)
            except (
                BagError,
                RecordError,
                KeyError,
                IndexError,
                struct_error,
                UnicodeDecodeError,
            ) as err:
                problems.append(f"corrupt chunk at byte {pos} skipped ({err})")
                pos = rec.end
                continue
            if per:
                found = _scanned_chunk(pos, compression, rec.data_pos, rec.data_len, per)
                found.size = usize
                chunks.append(found)
        elif rec.op in (OP_INDEX, OP_CHUNK_INFO):
            flush()
        else:
            problems.append(f"unknown record op {rec.op} at byte {pos}")
        pos = rec.end
    flush()
    return Ros1Layout(
        path, size, False, sorted(conns.values(), key=lambda c: c.id), chunks, problems
    )


def outside_chunk_info(
    chunks: Sequence[Ros1Chunk], cid: int, t: I64, where: Sequence[tuple[int, int]]
) -> str | None:
    """Why the index-data times ``t`` of one connection (``where``: (chunk, count) of each
    run of them, in order) do not all lie in their chunk's chunk-info [start, end], or None.

    One min and one max per chunk (two passes over the times, no per-message gather): the
    reads were planned from those spans, so a time outside one means the index contradicts
    itself and a window may have skipped a chunk it needed.
    """
    counts = np.array([w[1] for w in where], dtype=np.int64)
    nonempty = counts > 0
    if not len(t) or not nonempty.any():
        return None
    cis = np.array([w[0] for w in where], dtype=np.int64)[nonempty]
    at = (np.cumsum(counts) - counts)[nonempty]
    lo = np.minimum.reduceat(t, at)
    hi = np.maximum.reduceat(t, at)
    start = np.array([chunks[i].start_ns for i in cis.tolist()], dtype=np.int64)
    end = np.array([chunks[i].end_ns for i in cis.tolist()], dtype=np.int64)
    bad = np.flatnonzero((lo < start) | (hi > end))
    if not len(bad):
        return None
    k = int(bad[0])
    chunk = chunks[int(cis[k])]
    return (
        f"index data of connection {cid} after the chunk at byte {chunk.pos} holds record "
        f"times {int(lo[k])}..{int(hi[k])} ns outside its chunk info's "
        f"{chunk.start_ns}..{chunk.end_ns} ns ({len(bad)} chunk(s) so)"
    )


def value_offsets(buf: U8, head: int) -> tuple[int, int] | None:
    """(conn value, time value) offsets in the 38-byte message header at ``head``."""
    try:
        fields = bytes(buf[head : head + MSG_HEADER_LEN])
        pos, found = 0, {}
        while pos < len(fields):
            (n,) = U32.unpack_from(fields, pos)
            name = fields[pos + 4 : pos + 4 + n].split(b"=", 1)[0]
            found[name] = pos + 4 + len(name) + 1
            pos += 4 + n
    except struct_error:
        return None
    if b"conn" not in found or b"time" not in found:
        return None
    return found[b"conn"], found[b"time"]


def fields_before(buf: U8, data: int) -> tuple[int, int] | None:
    """(conn, time ns) of the message record whose data starts at ``data``, from its header
    (found by the standard 38-byte length; None when the header is not there or lacks them)."""
    head = data - 4 - MSG_HEADER_LEN
    if head < 4:
        return None
    try:
        (hlen,) = U32.unpack(bytes(buf[head - 4 : head]))
        if hlen != MSG_HEADER_LEN:
            return None
        fields = parse_fields(bytes(buf[head : head + MSG_HEADER_LEN]))
        return u32(fields, "conn"), time_ns(fields, "time")
    except (RecordError, KeyError, struct_error):
        return None


def nonzero_counts(counts: dict[int, int]) -> dict[int, int]:
    return {cid: n for cid, n in counts.items() if n}
