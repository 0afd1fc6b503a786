"""MCAP files read record by record, and the choice between that and the indexes.

The specification makes the summary section, its statistics, its repeated channels and
schemas, chunk indexes and message indexes all optional, and lets messages, channels and
schemas sit outside chunks. The indexed fast path (:mod:`ertools.io.mcap.index`) is exact
only when the summary has chunk indexes with message indexes, knows every channel those
indexes name, and nothing else in the data section holds a message. :func:`mcap_layout` checks
that from the summary alone plus the few bytes the chunk indexes do not cover (the header, the
data-end record, loose schemas and channels, attachments, metadata): no chunk is read. Every
other file is read by :func:`scan_mcap`, one record after another (chunks decompressed), which
is exact for any layout the specification allows and for files cut short.
"""

from __future__ import annotations

import contextlib
import mmap
import os
import struct
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ertools.arrays import I64, U8
from ertools.caches import register
from ertools.errors import BagError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.inputs import open_regular
from ertools.io import budget, mapguard
from ertools.io.decode.fast import read_at
from ertools.io.inflate import Allowance
from ertools.io.mcap.bodies import CHUNK_HEAD, U64, CutError, channel, chunk_shaped, schema
from ertools.io.mcap.crc import crc32
from ertools.io.mcap.summary import decompress, read_summary

MAGIC = b"\x89MCAP0\r\n"
OP_HEADER = 0x01
OP_FOOTER = 0x02
OP_SCHEMA = 0x03
OP_CHANNEL = 0x04
OP_MESSAGE = 0x05
OP_CHUNK = 0x06
OP_DATA_END = 0x0F
FOOTER_SIZE = 1 + 8 + 8 + 8 + 4
_FOOTER_HEAD = bytes([OP_FOOTER]) + (FOOTER_SIZE - 9).to_bytes(8, "little")

# What the summary-only check of a file and the record scan report as the index used.
INDEXED = "summary+message-indexes"
SCAN = "scan"

_HEAD = struct.Struct("<BQ")
MESSAGE_FIXED = 2 + 4 + 8 + 8


# One run of kept message payloads: (bytes, data starts, data lengths, message ordinals).
PayloadRun = tuple[U8, I64, I64, I64]


@frozen_dataclass(eq=False)
class McapRecords:
    """What a record-by-record read of an MCAP file found.

    Attributes:
        schemas: schema id -> ``mcap.records.Schema`` (first record of each id).
        channels: channel id -> ``mcap.records.Channel``.
        channel_id: channel of every message, in file order (int64).
        log_time: log time of every message, in file order (int64 ns).
        payloads: the data of the messages of the channels asked for, as runs of
            (bytes, starts, lengths, ordinals into ``channel_id``), in file order.
        compressions: chunk compressions met (``none`` for uncompressed chunks).
        complete: the file ends with its footer and magic.
        problem: why the read stopped early ("" when it read to the end).
        chunk_starts: where the chunk records of the data section start.
    """

    schemas: dict[int, Any]
    channels: dict[int, Any]
    channel_id: I64
    log_time: I64
    payloads: list[PayloadRun]
    compressions: frozenset[str]
    complete: bool
    problem: str
    chunk_starts: frozenset[int] = frozenset()


@dataclass
class _Sink:
    keep: frozenset[int]
    check_crc: bool
    path: Path
    schemas: dict[int, Any] = field(default_factory=dict)
    channels: dict[int, Any] = field(default_factory=dict)
    cids: list[I64] = field(default_factory=list)
    times: list[I64] = field(default_factory=list)
    count: int = 0
    payloads: list[PayloadRun] = field(default_factory=list)
    compressions: set[str] = field(default_factory=set)
    footer: bool = False
    chunks: int = 0
    chunk_at: list[int] = field(default_factory=list)
    data_end: bool = False
    allowance: Allowance = field(default_factory=lambda: Allowance(0, ""))

    def messages(self, buf: U8, at: I64) -> None:
        """Message records starting at ``at`` (vectorised)."""
        if not len(at):
            return
        if self.data_end:
            # the summary section holds no messages: a damaged record (a channel's op code)
            raise BagError(
                "a message record after the data section's end (damaged)", path=self.path
            )
        length = read_at(buf, at + 1, np.dtype("<u8")).astype(np.int64)
        if int(length.min()) < MESSAGE_FIXED:
            raise CutError
        cids = read_at(buf, at + 9, np.dtype("<u2")).astype(np.int64)
        times = read_at(buf, at + 15, np.dtype("<u8"))
        if int(times.max()) > np.iinfo(np.int64).max:
            # beyond the year 2262: a damaged record, not a time (times are int64 ns here on)
            raise BagError(f"a message log time {int(times.max())} out of range", path=self.path)
        self.cids.append(cids)
        self.times.append(times.astype(np.int64))
        if self.keep:
            mine = np.flatnonzero(np.isin(cids, list(self.keep)))
            if len(mine):
                start = at[mine] + 9 + MESSAGE_FIXED
                size = length[mine] - MESSAGE_FIXED
                # only the kept bytes are copied, not the chunk or window around them
                base = np.zeros(len(mine), dtype=np.int64)
                np.cumsum(size[:-1], out=base[1:])
                idx = np.repeat(start - base, size) + np.arange(int(size.sum()), dtype=np.int64)
                self.payloads.append((buf[idx], base, size, mine + self.count))
        self.count += len(at)


# Bytes searched for record starts at a time: bounded memory for the candidate arrays.
WINDOW = 4 << 20
# Message records read one by one in a row before the rest of the stretch is read in bulk:
# a few big records (chunks between their message indexes) are cheaper one at a time.
RUN_TO_BULK = 16


def _chain(buf: U8, pos: int, stop: int, end: int) -> tuple[I64, int]:
    """Starts of the records that follow each other from ``pos`` (a record start) within
    ``buf[pos:stop]``, and where the chain leaves that stretch; vectorised.

    Candidates are the bytes holding a known opcode (0x01-0x0F) followed by a length under
    1 TiB that stays inside ``end``; each points at the candidate after it. The true records
    are those reached from ``pos``, listed with pointer doubling (tables of 2^k-th
    successors): O(n log n) NumPy work for n candidates, not a Python step per record. The
    chain ends at a record of an unknown opcode, which the caller steps over.
    """
    last = min(stop, end - 9 + 1)
    if last <= pos + 1:
        return np.empty(0, np.int64), pos
    head = buf[pos:last]
    mask = np.less(head - np.uint8(1), np.uint8(0x0F))
    for k in (6, 7, 8):  # the three high bytes of the little-endian length
        mask &= buf[pos + k : last + k] == 0
    cand = pos + np.flatnonzero(mask)
    if not len(cand) or cand[0] != pos:
        return np.empty(0, np.int64), pos
    nxt = cand + 9 + read_at(buf, cand + 1, np.dtype("<u8")).astype(np.int64)
    ok = nxt <= end
    if not ok[0]:
        return np.empty(0, np.int64), pos
    cand, nxt = cand[ok], nxt[ok]
    n = len(cand)
    at = np.searchsorted(cand, nxt)
    hit = at < n
    hit[hit] = cand[at[hit]] == nxt[hit]
    jumps = [np.append(np.where(hit & (nxt < stop), at, n), n)]
    while (1 << len(jumps)) <= n:
        j = jumps[-1]
        jumps.append(j[j])
    # the k-th record after the first, for k < 2^(b+1), from those for k < 2^b: one gather
    # per level, O(n) in all
    path = np.zeros(1, dtype=np.int64)
    for j in jumps:
        if path[-1] == n:
            break
        path = np.concatenate([path, j[path]])
    found = path[: int(np.searchsorted(path, n))]
    return cand[found], int(nxt[found[-1]])


def _walk(buf: Any, pos: int, end: int, sink: _Sink, top: bool) -> int:
    """Read the records in ``buf[pos:end]``, chunks included; returns where it stopped.

    Records are read one at a time until messages come in a row; then the rest of the
    stretch (up to ``WINDOW`` bytes) is read in bulk from the chain of record starts, its
    messages as arrays and its few other records (schemas, channels, chunks) one by one.
    """
    head = _HEAD.unpack_from
    run = 0
    while pos < end:
        if run >= RUN_TO_BULK:
            starts, after = _chain(buf, pos, min(end, pos + WINDOW), end)
            if len(starts) > 1:
                ops = buf[starts]
                other = np.flatnonzero(ops != OP_MESSAGE)
                done = 0
                for i in other.tolist():
                    sink.messages(buf, starts[done:i])
                    done = i + 1
                    rec_end = int(starts[i + 1]) if i + 1 < len(starts) else after
                    if _record(buf, int(ops[i]), int(starts[i]) + 9, rec_end, sink, top):
                        return rec_end
                sink.messages(buf, starts[done:])
                pos = after
                continue
            run = 0
        if pos + 9 > end:
            raise CutError
        op, n = head(buf, pos)
        body: int = pos + 9
        stop: int = body + n
        if stop > end or stop < body:
            raise CutError
        if op == OP_MESSAGE:
            sink.messages(buf, np.array([pos], dtype=np.int64))
            run += 1
        else:
            run = 0
            if _record(buf, op, body, stop, sink, top):
                return stop
        pos = stop
    return pos


def _record(buf: Any, op: int, body: int, stop: int, sink: _Sink, top: bool) -> bool:
    """One record other than a message; True when it is the footer (the end of the file)."""
    if op == OP_CHANNEL:
        ch = channel(buf, body, stop)
        sink.channels.setdefault(ch.id, ch)
    elif op == OP_SCHEMA:
        sc = schema(buf, body, stop)
        if sc.id:
            sink.schemas.setdefault(sc.id, sc)
    elif op == OP_CHUNK:
        if top:
            sink.chunk_at.append(body - 9)
        _chunk(buf, body, stop, sink)
    elif op == OP_FOOTER and top:
        sink.footer = True
        return True
    elif op == OP_DATA_END and top:
        sink.data_end = True
    elif top and not OP_HEADER <= op <= OP_DATA_END and chunk_shaped(buf, body, stop):
        # The specification has readers skip a record of an unknown op code; one shaped
        # exactly like a chunk is a chunk whose op code is damaged (found by fuzzing, with the
        # summary that would have named it damaged too): skipping it drops its messages.
        raise BagError(
            f"damaged MCAP file: the record at byte {body - 9} has an unknown op code "
            f"(0x{op:02x}) and the shape of a chunk: a damaged op code, which would drop the "
            "chunk's messages",
            path=sink.path,
        )
    return False


def _chunk(buf: Any, at: int, end: int, sink: _Sink) -> None:
    _t0, _t1, usize, crc, clen = CHUNK_HEAD.unpack_from(buf, at)
    at += CHUNK_HEAD.size
    compression = bytes(buf[at : at + clen]).decode("ascii", "replace")
    (nbytes,) = U64.unpack_from(buf, at + clen)
    at += clen + 8
    if at + nbytes > end:
        raise CutError
    where = f"in {sink.path} at byte {at}"
    if compression:
        sink.allowance.add(usize, f"at byte {at}", "MCAP chunk")
    stored = buf[at : at + nbytes]
    # an uncompressed chunk is read in place (no copy); the decompressors take any buffer
    inner = stored if compression == "" else decompress(compression, stored, usize, where)
    if len(inner) != usize:
        raise BagError(f"chunk decompresses to {len(inner)} bytes, not {usize}, {where}")
    if sink.check_crc and crc and crc32(inner) != crc:
        raise BagError(f"corrupt MCAP chunk {where}: CRC mismatch")
    sink.compressions.add(compression or "none")
    sink.chunks += 1
    records = np.frombuffer(inner, dtype=np.uint8)
    if _walk(records, 0, len(records), sink, top=False) != len(records):
        raise CutError


def scan_mcap(
    path: Path, *, keep: frozenset[int] = frozenset(), check_crc: bool = True
) -> McapRecords:
    """Every record of an MCAP file in turn, chunks decompressed, as far as they are whole;
    the bytes of the messages of the channels in ``keep`` are copied out.

    A read without ``keep`` is kept for the file's version (device, inode, size, modification
    time): opening a file, summarising it and listing its channels share one read. Chunk CRCs
    are checked by default: lz4 and zstd inflate a damaged chunk into other messages without
    an error of their own (found by fuzzing).

    Raises:
        BagError: not an MCAP file (no magic), or a corrupt compressed chunk.
    """
    with open_regular(path) as f:
        st = os.fstat(f.fileno())
        key = (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)
        if not keep and check_crc and key in _SCANS:
            return _SCANS[key]
        size = st.st_size
        if size < len(MAGIC):
            raise BagError("truncated: the file ends inside its magic", path=path)
        mm = mmap.mmap(f.fileno(), size, access=mmap.ACCESS_READ)
        mapguard.watch(mm, path)
    try:
        found = _scan(np.frombuffer(mm, dtype=np.uint8), path, keep, check_crc)
    finally:
        # everything handed out is a copy; a view still alive (an exception's frames) keeps
        # the map until it goes
        mapguard.unwatch(mm)
        with contextlib.suppress(BufferError):
            mm.close()
    summary = mcap_layout(path).summary
    if found.complete and summary is not None:
        # The summary (its CRC checked) indexes chunks where the records read in turn found
        # none: a chunk's op code is damaged, and skipping it as an unknown record, as the
        # specification has readers do, would silently drop its messages.
        lost = sorted(
            {int(c.chunk_start_offset) for c in summary.chunk_indexes} - found.chunk_starts
        )
        if lost:
            raise BagError(
                f"damaged MCAP file: the summary indexes a chunk at byte {lost[0]}, where the "
                "records hold no chunk",
                path=path,
            )
    if not keep and check_crc:
        if len(_SCANS) >= 4:  # 16 bytes a message: a few hour-long files at most
            _SCANS.clear()
        _SCANS[key] = found
    return found


_SCANS: dict[tuple[int, int, int, int], McapRecords] = {}
register(_SCANS.clear)


def _scan(buf: U8, path: Path, keep: frozenset[int], check_crc: bool) -> McapRecords:
    size = len(buf)
    if buf[: len(MAGIC)].tobytes() != MAGIC:
        raise BagError("no MCAP magic at the start", path=path)
    sink = _Sink(keep, check_crc, path, allowance=Allowance(size, str(path)))
    end = size - len(MAGIC) if buf[size - len(MAGIC) :].tobytes() == MAGIC else size
    foot = size - len(MAGIC) - FOOTER_SIZE
    if end == size and foot > len(MAGIC) and buf[foot : foot + 9].tobytes() == _FOOTER_HEAD:
        # a footer record just before the last 8 bytes: the writer finished the file and only
        # its closing magic is damaged; read it as finished (damage inside is then refused,
        # not taken for a recording cut short)
        end = size - len(MAGIC)
    problem = ""
    try:
        stop = _walk(buf, len(MAGIC), end, sink, top=True)
        if not sink.footer:
            problem = f"truncated: no footer record (the records end at byte {stop})"
        elif stop == size:
            problem = f"truncated inside its closing magic (the footer record ends at byte {stop})"
        elif stop != end:
            # a writer ends the file right after its footer; a recording cut short has none:
            # records after a footer are damage (a chunk's op code read as a footer's), and
            # reading only what comes before would drop the rest without a word
            raise BagError(
                f"damaged MCAP file: a footer record ends at byte {stop}, {size - stop} bytes "
                "before the end of the file",
                path=path,
            )
    except (CutError, struct.error, UnicodeDecodeError) as err:
        why = "a record runs past the end of the file or of its chunk"
        if isinstance(err, UnicodeDecodeError):
            why = "a name that is not UTF-8"
        if end != size:
            # The file ends with its closing magic: its writer finished it, so this is damage
            # inside, not a recording cut short; what follows cannot be trusted or skipped.
            raise BagError(
                f"damaged MCAP file: {why} after {sink.count} whole messages, yet the file "
                "ends with its closing magic (not cut short)",
                path=path,
            ) from err
        problem = f"truncated or damaged after {sink.count} whole messages ({why})"
    e = np.empty(0, np.int64)
    return McapRecords(
        sink.schemas,
        sink.channels,
        np.concatenate(sink.cids) if sink.cids else e,
        np.concatenate(sink.times) if sink.times else e,
        sink.payloads,
        frozenset(sink.compressions),
        sink.footer and not problem,
        problem,
        frozenset(sink.chunk_at),
    )


@frozen_dataclass(eq=False)
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
register(_LAYOUTS.clear)


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
    with open_regular(path) as f:
        size = os.fstat(f.fileno()).st_size
        if size < 2 * len(MAGIC) + FOOTER_SIZE or os.pread(f.fileno(), 8, size - 8) != MAGIC:
            # no footer to find a summary with: a recording not finished, or a copy cut short
            return _scan_layout(None, "no summary section (the file does not end with its magic)")
        try:
            summary = read_summary(f, path)
        except BagError as err:
            return _scan_layout(None, f"no readable summary section ({err.message})")
        if summary is None:
            return _scan_layout(None, "no summary section")
        chunks = summary.chunk_indexes
        _check_declared(path, size, chunks)
        if any(not c.message_index_offsets and c.uncompressed_size for c in chunks):
            return _scan_layout(summary, "chunks without message indexes")
        f.seek(size - len(MAGIC) - FOOTER_SIZE)
        (data_end,) = U64.unpack_from(f.read(FOOTER_SIZE), 9)
        gaps = _gaps(chunks, data_end)
        if gaps is None:
            return _scan_layout(summary, "chunk indexes that overlap or point outside the data")
        sink = _Sink(frozenset(), False, path)
        for a, b in gaps:
            try:
                at = _walk_loose(f.fileno(), a, b, sink)
            except (CutError, struct.error, UnicodeDecodeError):
                at = -1
            if sink.count or sink.chunks:
                what = (
                    "chunks the summary does not index"
                    if sink.chunks
                    else "messages outside chunks"
                )
                return _scan_layout(summary, what)
            if at != b:
                return _scan_layout(summary, f"records between chunks that do not fit at byte {a}")
    channels = {**sink.channels, **summary.channels}
    schemas = {**sink.schemas, **summary.schemas}
    indexed = {cid for c in chunks for cid in c.message_index_offsets}
    if indexed - set(summary.channels):
        return _scan_layout(summary, "channels written only inside chunks")
    if {c.schema_id for c in channels.values() if c.schema_id} - set(schemas):
        return _scan_layout(summary, "schemas written only inside chunks")
    return McapLayout(summary, INDEXED, "", channels, schemas)


def _check_declared(path: Path, size: int, chunks: list[Any]) -> None:
    """Refuse a file whose compressed chunks declare more than its size allows
    (:func:`ertools.io.budget.allowance`): each chunk is checked again when it is read."""
    declared = sum(int(c.uncompressed_size) for c in chunks if c.compression)
    if declared > budget.allowance(size):
        raise BagError(
            budget.over_budget(
                f"the chunks of this {size}-byte file",
                f"{declared} bytes uncompressed",
                budget.allowance(size),
                "MAX_INFLATE_PER_BYTE x the file's size + MAX_CHUNK_BYTES",
            ),
            path=path,
        )


def _walk_loose(fd: int, pos: int, end: int, sink: _Sink) -> int:
    """Walk the records in bytes [pos, end) of the file outside the indexed chunks, reading
    only record headers and the schema and channel records; stops at the first message or
    chunk (the file is then read record by record anyway). Returns where it stopped."""
    while pos < end:
        head = os.pread(fd, 9, pos)
        if len(head) < 9:
            raise CutError
        op, n = _HEAD.unpack(head)
        stop: int = pos + 9 + n
        if stop > end:
            raise CutError
        if op == OP_MESSAGE:
            sink.count += 1
            return stop
        if op == OP_CHUNK:
            sink.chunks += 1
            return stop
        if op in (OP_SCHEMA, OP_CHANNEL):
            record = np.frombuffer(os.pread(fd, 9 + n, pos), dtype=np.uint8)
            if len(record) != 9 + n:
                raise CutError
            _walk(record, 0, len(record), sink, top=False)
        pos = stop
    return pos


def _gaps(chunks: list[Any], data_end: int) -> list[tuple[int, int]] | None:
    """Byte ranges of the data section the chunks and their message indexes leave out, None
    when the chunk indexes overlap or point past the data section."""
    if data_end == 0:
        return None
    spans = [
        (int(c.chunk_start_offset), int(c.chunk_length), int(c.message_index_length))
        for c in chunks
    ]
    if any(a + b + m > data_end for a, b, m in spans):
        return None  # (also keeps absurd uint64 values out of int64 arrays)
    start = np.array([a for a, _b, _m in spans], dtype=np.int64)
    stop = start + np.array([b + m for _a, b, m in spans], dtype=np.int64)
    order = np.argsort(start, kind="stable")
    start, stop = start[order], stop[order]
    lo = np.concatenate([[len(MAGIC)], stop])
    hi = np.concatenate([start, [data_end]])
    if np.any(hi < lo):
        return None
    keep = hi > lo
    return list(zip(lo[keep].tolist(), hi[keep].tolist(), strict=True))
