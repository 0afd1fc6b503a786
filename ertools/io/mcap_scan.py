"""MCAP files read record by record, and the choice between that and the indexes.

The specification makes the summary section, its statistics, its repeated channels and
schemas, chunk indexes and message indexes all optional, and lets messages, channels and
schemas sit outside chunks. The indexed fast path (:mod:`ertools.io.mcap_index`) is exact
only when the summary has chunk indexes with message indexes, knows every channel those
indexes name, and nothing else in the data section holds a message. :func:`mcap_layout` checks
that from the summary alone plus the few bytes the chunk indexes do not cover (the header, the
data-end record, loose schemas and channels, attachments, metadata): no chunk is read. Every
other file is read by :func:`scan_mcap`, one record after another (chunks decompressed), which
is exact for any layout the specification allows and for files cut short.
"""

from __future__ import annotations

import logging
import mmap
import os
import struct
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.errors import BagError

log = logging.getLogger("ertools.io.mcap_scan")

I64 = npt.NDArray[np.int64]

MAGIC = b"\x89MCAP0\r\n"
OP_FOOTER = 0x02
OP_SCHEMA = 0x03
OP_CHANNEL = 0x04
OP_MESSAGE = 0x05
OP_CHUNK = 0x06
OP_DATA_END = 0x0F
FOOTER_SIZE = 1 + 8 + 8 + 8 + 4

# What the summary-only check of a file and the record scan report as the index used.
INDEXED = "summary+message-indexes"
SCAN = "scan"

_HEAD = struct.Struct("<BQ")
_MESSAGE = struct.Struct("<HIQ")  # channel id, sequence, log time (publish time follows)
_CHUNK = struct.Struct("<QQQII")  # start, end, uncompressed size, crc, compression length
_U16 = struct.Struct("<H")
_U32 = struct.Struct("<I")
_U64 = struct.Struct("<Q")
MESSAGE_FIXED = 2 + 4 + 8 + 8


class _CutError(Exception):
    """A record runs past the end of what holds it (file or chunk)."""


@dataclass(frozen=True, eq=False)
class McapRecords:
    """What a record-by-record read of an MCAP file found.

    Attributes:
        schemas: schema id -> ``mcap.records.Schema`` (first record of each id).
        channels: channel id -> ``mcap.records.Channel``.
        channel_id: channel of every message, in file order (int64).
        log_time: log time of every message, in file order (int64 ns).
        payloads: every message's data in file order, when asked for (else empty).
        compressions: chunk compressions met (``none`` for uncompressed chunks).
        complete: the file ends with its footer and magic.
        problem: why the read stopped early ("" when it read to the end).
    """

    schemas: dict[int, Any]
    channels: dict[int, Any]
    channel_id: I64
    log_time: I64
    payloads: list[bytes]
    compressions: frozenset[str]
    complete: bool
    problem: str


@dataclass
class _Sink:
    keep_data: bool
    check_crc: bool
    path: Path
    schemas: dict[int, Any] = field(default_factory=dict)
    channels: dict[int, Any] = field(default_factory=dict)
    cids: list[int] = field(default_factory=list)
    times: list[int] = field(default_factory=list)
    payloads: list[bytes] = field(default_factory=list)
    compressions: set[str] = field(default_factory=set)
    footer: bool = False
    chunks: int = 0


def _string(buf: Any, at: int, end: int) -> tuple[str, int]:
    (n,) = _U32.unpack_from(buf, at)
    at += 4
    if at + n > end:
        raise _CutError
    return bytes(buf[at : at + n]).decode("utf-8"), at + n


def _schema(buf: Any, at: int, end: int) -> Any:
    from mcap.records import Schema

    (sid,) = _U16.unpack_from(buf, at)
    name, at = _string(buf, at + 2, end)
    encoding, at = _string(buf, at, end)
    (n,) = _U32.unpack_from(buf, at)
    if at + 4 + n > end:
        raise _CutError
    return Schema(id=sid, name=name, encoding=encoding, data=bytes(buf[at + 4 : at + 4 + n]))


def _channel(buf: Any, at: int, end: int) -> Any:
    from mcap.records import Channel

    cid, sid = struct.unpack_from("<HH", buf, at)
    topic, at = _string(buf, at + 4, end)
    encoding, at = _string(buf, at, end)
    (n,) = _U32.unpack_from(buf, at)
    at += 4
    stop = at + n
    if stop > end:
        raise _CutError
    metadata = {}
    while at < stop:
        key, at = _string(buf, at, stop)
        value, at = _string(buf, at, stop)
        metadata[key] = value
    return Channel(id=cid, schema_id=sid, topic=topic, message_encoding=encoding, metadata=metadata)


def _walk(buf: Any, pos: int, end: int, sink: _Sink, top: bool) -> int:
    """Read the records in ``buf[pos:end]``, chunks included; returns where it stopped.

    A Python step per record: this is the path for layouts the indexes cannot answer, not
    for the usual chunked-and-indexed files.
    """
    head = _HEAD.unpack_from
    message = _MESSAGE.unpack_from
    while pos < end:
        if pos + 9 > end:
            raise _CutError
        op, n = head(buf, pos)
        body: int = pos + 9
        stop: int = body + n
        if stop > end or stop < body:
            raise _CutError
        if op == OP_MESSAGE:
            if n < MESSAGE_FIXED:
                raise _CutError
            cid, _seq, t = message(buf, body)
            sink.cids.append(cid)
            sink.times.append(t)
            if sink.keep_data:
                sink.payloads.append(bytes(buf[body + MESSAGE_FIXED : stop]))
        elif op == OP_CHANNEL:
            ch = _channel(buf, body, stop)
            sink.channels.setdefault(ch.id, ch)
        elif op == OP_SCHEMA:
            sc = _schema(buf, body, stop)
            if sc.id:
                sink.schemas.setdefault(sc.id, sc)
        elif op == OP_CHUNK:
            _chunk(buf, body, stop, sink)
        elif op == OP_FOOTER and top:
            sink.footer = True
            return stop
        pos = stop
    return pos


def _chunk(buf: Any, at: int, end: int, sink: _Sink) -> None:
    from ertools.io.mcap_index import decompress

    _t0, _t1, usize, crc, clen = _CHUNK.unpack_from(buf, at)
    at += _CHUNK.size
    compression = bytes(buf[at : at + clen]).decode("ascii", "replace")
    (nbytes,) = _U64.unpack_from(buf, at + clen)
    at += clen + 8
    if at + nbytes > end or usize > 1000 * max(nbytes, 1) + (1 << 20):
        raise _CutError
    where = f"in {sink.path} at byte {at}"
    inner = decompress(compression, bytes(buf[at : at + nbytes]), usize, where)
    if len(inner) != usize:
        raise BagError(f"chunk decompresses to {len(inner)} bytes, not {usize}, {where}")
    if sink.check_crc and crc and zlib.crc32(inner) != crc:
        raise BagError(f"corrupt MCAP chunk {where}: CRC mismatch")
    sink.compressions.add(compression or "none")
    sink.chunks += 1
    if _walk(inner, 0, len(inner), sink, top=False) != len(inner):
        raise _CutError


def scan_mcap(path: Path, *, keep_data: bool = False, check_crc: bool = False) -> McapRecords:
    """Every record of an MCAP file in turn, chunks decompressed, as far as they are whole.

    Raises:
        BagError: not an MCAP file (no magic), or a corrupt compressed chunk.
    """
    with path.open("rb") as f:
        size = os.fstat(f.fileno()).st_size
        if size < len(MAGIC):
            raise BagError("truncated: the file ends inside its magic", path=path)
        with mmap.mmap(f.fileno(), size, access=mmap.ACCESS_READ) as mm:
            buf = memoryview(mm)
            try:
                return _scan(buf, size, path, keep_data, check_crc)
            finally:
                buf.release()


def _scan(buf: memoryview, size: int, path: Path, keep_data: bool, check_crc: bool) -> McapRecords:
    if bytes(buf[: len(MAGIC)]) != MAGIC:
        raise BagError("no MCAP magic at the start", path=path)
    sink = _Sink(keep_data, check_crc, path)
    end = size - len(MAGIC) if bytes(buf[size - len(MAGIC) :]) == MAGIC else size
    problem = ""
    try:
        stop = _walk(buf, len(MAGIC), end, sink, top=True)
        if not sink.footer:
            problem = f"truncated: no footer record (the records end at byte {stop})"
        elif stop != end or end == size:
            problem = f"bytes after the footer record at byte {stop}"
    except (_CutError, struct.error, UnicodeDecodeError) as err:
        why = "a record runs past the end of the file or of its chunk"
        if isinstance(err, UnicodeDecodeError):
            why = "a name that is not UTF-8"
        done = len(sink.times)
        problem = f"truncated or damaged after {done} whole messages ({why})"
    return McapRecords(
        sink.schemas,
        sink.channels,
        np.asarray(sink.cids, dtype=np.int64),
        np.asarray(sink.times, dtype=np.uint64).astype(np.int64),
        sink.payloads,
        frozenset(sink.compressions),
        sink.footer and not problem,
        problem,
    )


@dataclass(frozen=True, eq=False)
class McapLayout:
    """Which path reads an MCAP file exactly.

    Attributes:
        summary: the ``mcap`` library's Summary, None without a summary section.
        index: ``summary+message-indexes`` when the indexes answer exactly, ``scan`` otherwise.
        why: what the indexes lack ("" when they answer).
        channels: channel id -> Channel: the summary's plus those outside chunks and summary.
        schemas: schema id -> Schema, likewise.
    """

    summary: Any | None
    index: str
    why: str
    channels: dict[int, Any]
    schemas: dict[int, Any]


_LAYOUTS: dict[tuple[int, int, int, int], McapLayout] = {}


def mcap_layout(path: Path) -> McapLayout:
    """Whether the summary's indexes answer for every message of the file (read once per
    file version; the chunks themselves are not read).

    Raises:
        BagError: the file cannot be opened.
    """
    try:
        st = path.stat()
    except OSError as err:
        raise BagError(f"cannot open: {err.strerror}", path=path) from err
    key = (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)
    found = _LAYOUTS.get(key)
    if found is None:
        found = _layout(path)
        if len(_LAYOUTS) >= 64:
            _LAYOUTS.clear()
        _LAYOUTS[key] = found
    return found


def _scan_layout(summary: Any, why: str) -> McapLayout:
    return McapLayout(summary, SCAN, why, {}, {})


def _layout(path: Path) -> McapLayout:
    from ertools.io.mcap_index import read_summary

    with path.open("rb") as f:
        try:
            summary = read_summary(f, path)
        except BagError as err:
            return _scan_layout(None, f"no readable summary section ({err.message})")
        if summary is None:
            return _scan_layout(None, "no summary section")
        chunks = summary.chunk_indexes
        if any(not c.message_index_offsets and c.uncompressed_size for c in chunks):
            return _scan_layout(summary, "chunks without message indexes")
        size = os.fstat(f.fileno()).st_size
        f.seek(size - len(MAGIC) - FOOTER_SIZE)
        (data_end,) = _U64.unpack_from(f.read(FOOTER_SIZE), 9)
        gaps = _gaps(chunks, data_end)
        if gaps is None:
            return _scan_layout(summary, "chunk indexes that overlap or point outside the data")
        sink = _Sink(False, False, path)
        for a, b in gaps:
            f.seek(a)
            part = f.read(b - a)
            try:
                at = _walk_loose(part, sink)
            except (_CutError, struct.error, UnicodeDecodeError):
                at = -1
            if sink.cids or sink.chunks:
                what = (
                    "chunks the summary does not index"
                    if sink.chunks
                    else "messages outside chunks"
                )
                return _scan_layout(summary, what)
            if at != len(part):
                return _scan_layout(summary, f"records between chunks that do not fit at byte {a}")
    channels = {**sink.channels, **summary.channels}
    schemas = {**sink.schemas, **summary.schemas}
    indexed = {cid for c in chunks for cid in c.message_index_offsets}
    if indexed - set(summary.channels):
        return _scan_layout(summary, "channels written only inside chunks")
    if {c.schema_id for c in channels.values() if c.schema_id} - set(schemas):
        return _scan_layout(summary, "schemas written only inside chunks")
    return McapLayout(summary, INDEXED, "", channels, schemas)


def _walk_loose(part: bytes, sink: _Sink) -> int:
    """Walk records outside the indexed chunks, stopping at the first message or chunk (the
    file is then scanned anyway): never decompresses anything."""
    pos = 0
    while pos < len(part):
        op, n = _HEAD.unpack_from(part, pos)
        stop: int = pos + 9 + n
        if stop > len(part):
            raise _CutError
        if op == OP_MESSAGE:
            sink.cids.append(0)
            return stop
        if op == OP_CHUNK:
            sink.chunks += 1
            return stop
        if op in (OP_SCHEMA, OP_CHANNEL):
            _walk(part, pos, stop, sink, top=False)
        pos = stop
    return pos


def _gaps(chunks: list[Any], data_end: int) -> list[tuple[int, int]] | None:
    """Byte ranges of the data section the chunks and their message indexes leave out, None
    when the chunk indexes overlap or point past the data section."""
    if data_end == 0:
        return None
    start = np.array([int(c.chunk_start_offset) for c in chunks], dtype=np.int64)
    stop = start + np.array(
        [int(c.chunk_length) + int(c.message_index_length) for c in chunks], dtype=np.int64
    )
    order = np.argsort(start, kind="stable")
    start, stop = start[order], stop[order]
    lo = np.concatenate([[len(MAGIC)], stop])
    hi = np.concatenate([start, [data_end]])
    if np.any(hi < lo):
        return None
    keep = hi > lo
    return list(zip(lo[keep].tolist(), hi[keep].tolist(), strict=True))
