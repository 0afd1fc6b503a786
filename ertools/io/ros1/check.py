"""``ertools info --check`` for ROS1 bags: every record read, the index checked against them.

A ROS1 bag says the same things twice: the records themselves (chunks holding connection and
message records) and the index written after them (index-data records after each chunk: the
time and offset of each message of one connection; connection and chunk-info records at the
end: each chunk's position, time span and per-connection counts). Readers trust the index
(rosbag, rosbags and ertools' fast path plan their reads from it), so a flipped byte there
moves a bag's start or end, or a message's time, without any error. :func:`check_ros1` reads
every record and reports each disagreement between the two as one line.

The message records of a chunk are found with the index-data offsets as hints: the records
they point at are parsed vectorised (the standard 38-byte header with its ``op``, ``conn``
and ``time`` fields in any order), consecutive records that tile the chunk are taken as a
run, and only what lies between runs (connection records, messages the index misses,
odd headers) is walked record by record.
"""

from __future__ import annotations

import os
import struct
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, BinaryIO

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64, U8
from ertools.errors import BagError
from ertools.inputs import open_regular
from ertools.io import budget
from ertools.io.decode.fast import gather
from ertools.io.inflate import Allowance
from ertools.io.ros1 import records
from ertools.io.ros1.layout import (
    Ros1Chunk,
    Ros1Layout,
    chunk_head,
    conn_record,
    decompress,
    entries_from_index,
    scan_layout,
)
from ertools.io.ros1.records import (
    MAGIC_LEN,
    OP_BAG_HEADER,
    OP_CHUNK,
    OP_CHUNK_INFO,
    OP_CONNECTION,
    OP_INDEX,
    OP_MSG,
)
from ertools.timeutil import iso_utc

if TYPE_CHECKING:
    from ertools.io.model import Conn
    from ertools.progress import Reporter


# Disagreements reported per bag; past this the rest are counted in one last line (a bag whose
# index is wrong throughout would otherwise print one line per chunk and connection).
MAX_LINES = 100

_HEADER_LEN = 38  # op (4 + 4), conn (4 + 9), time (4 + 13): a message record's usual header
# The three fields of a standard message header: (length-prefixed bytes that must match,
# where the value starts, value length).
_FIELDS = {
    "op": (b"\x04\x00\x00\x00op=\x02", 8, 0),
    "conn": (b"\x09\x00\x00\x00conn=", 9, 4),
    "time": (b"\x0d\x00\x00\x00time=", 9, 8),
}
_ORDERS = (
    ("op", "conn", "time"),
    ("op", "time", "conn"),
    ("conn", "op", "time"),
    ("conn", "time", "op"),
    ("time", "op", "conn"),
    ("time", "conn", "op"),
)


def _size(name: str) -> int:
    return len(_FIELDS[name][0]) + _FIELDS[name][2]


@dataclass
class ChunkRecords:
    """The records found inside one chunk: message offsets, connections and times, plus the
    connection records (id -> (topic, type, md5)) and what could not be read."""

    msg_off: I64
    msg_conn: I64
    msg_time: I64
    conns: dict[int, tuple[str, str, str]] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)


def _standard(buf: U8, offs: I64) -> tuple[npt.NDArray[np.bool_], I64, I64, I64]:
    """(is a standard message record, conn, time ns, record end) of the records at ``offs``;
    values are 0 where the record is not a standard message record."""
    n = len(buf)
    k = len(offs)
    ok = np.zeros(k, dtype=bool)
    conn = np.zeros(k, dtype=np.int64)
    t = np.zeros(k, dtype=np.int64)
    end = np.zeros(k, dtype=np.int64)
    fits = np.flatnonzero((offs >= 0) & (offs + 8 + _HEADER_LEN <= n))
    if not len(fits):
        return ok, conn, t, end

    rows = gather(buf, offs[fits], 8 + _HEADER_LEN)  # header length, header, data length
    todo = np.flatnonzero(rows[:, :4].view("<u4")[:, 0] == _HEADER_LEN)
    for order in _ORDERS:
        if not len(todo):
            break
        sub = rows[todo]
        at = 4
        match = np.ones(len(todo), dtype=bool)
        where: dict[str, int] = {}
        for name in order:
            prefix, value_at, _ = _FIELDS[name]
            pattern = np.frombuffer(prefix, dtype=np.uint8)
            match &= np.all(sub[:, at : at + len(prefix)] == pattern, axis=1)
            where[name] = at + value_at
            at += _size(name)
        hit = todo[match]
        if not len(hit):
            continue
        r = rows[hit]
        c_at, t_at = where["conn"], where["time"]
        idx = fits[hit]
        ok[idx] = True
        conn[idx] = np.ascontiguousarray(r[:, c_at : c_at + 4]).view("<u4")[:, 0]
        sec = np.ascontiguousarray(r[:, t_at : t_at + 4]).view("<u4")[:, 0].astype(np.int64)
        nsec = np.ascontiguousarray(r[:, t_at + 4 : t_at + 8]).view("<u4")[:, 0]
        t[idx] = sec * 1_000_000_000 + nsec
        dlen = np.ascontiguousarray(r[:, 4 + _HEADER_LEN :]).view("<u4")[:, 0]
        end[idx] = offs[idx] + 8 + _HEADER_LEN + dlen
        todo = todo[~match]
    ok &= end <= n
    return ok, conn, t, end


def chunk_records(buf: U8, hints: I64, base: int) -> ChunkRecords:
    """Every record of one uncompressed chunk (``base``: the chunk data's byte in the file,
    for messages). ``hints`` are offsets the index says hold message records."""
    n = len(buf)
    hints = np.unique(hints[(hints >= 0) & (hints < n)])
    ok, conn, t, end = _standard(buf, hints)
    # A hint continues a run when it is a standard record and the next hint starts where it
    # ends; a run from hint k goes to the first hint that does not continue it.
    chained = ok.copy()
    chained[:-1] &= end[:-1] == hints[1:]
    chained[-1:] = False
    breaks = np.flatnonzero(~chained)
    offs: list[I64] = []
    conns: list[I64] = []
    times: list[I64] = []
    out = ChunkRecords(np.empty(0, np.int64), np.empty(0, np.int64), np.empty(0, np.int64))
    raw: bytes | None = None  # made only when a record is walked by hand
    pos = 0
    while pos < n:
        k = int(np.searchsorted(hints, pos))
        if k < len(hints) and hints[k] == pos and ok[k]:
            j = int(breaks[np.searchsorted(breaks, k)])
            # the run ends at hint j, or just before it when j is not a standard record
            # (then it starts where hint j - 1 ends, and is walked by hand next)
            stop = j + 1 if ok[j] else j
            offs.append(hints[k:stop])
            conns.append(conn[k:stop])
            times.append(t[k:stop])
            pos = int(end[stop - 1])
            continue
        if raw is None:
            raw = buf.tobytes()
        if pos + 8 > n:
            out.problems.append(f"{n - pos} stray bytes at the end of the chunk (offset {pos})")
            break
        hlen = int.from_bytes(raw[pos : pos + 4], "little")
        if pos + 8 + hlen > n:
            out.problems.append(f"record header cut off at chunk offset {pos}")
            break
        try:
            fields = records.parse_fields(raw[pos + 4 : pos + 4 + hlen], pos + 4)
            op = fields["op"][0]
        except (records.RecordError, KeyError, IndexError) as err:
            out.problems.append(f"unreadable record header at chunk offset {pos} ({err})")
            break
        dlen = int.from_bytes(raw[pos + 4 + hlen : pos + 8 + hlen], "little")
        dpos = pos + 8 + hlen
        if dpos + dlen > n:
            out.problems.append(f"record data cut off at chunk offset {pos}")
            break
        try:
            if op == OP_MSG:
                cid, when = (
                    records.u32(fields, "conn"),
                    records.time_ns(fields, "time"),
                )  # both, or neither
                offs.append(np.array([pos], dtype=np.int64))
                conns.append(np.array([cid], dtype=np.int64))
                times.append(np.array([when], dtype=np.int64))
            elif op == OP_CONNECTION:
                cf = records.parse_fields(raw[dpos : dpos + dlen], base + dpos)
                topic = fields.get("topic", cf.get("topic", b""))
                out.conns[records.u32(fields, "conn")] = _conn_text(topic, cf)
            else:
                out.problems.append(f"record of op {op} inside the chunk at offset {pos}")
        except (records.RecordError, KeyError, IndexError, struct.error) as err:
            out.problems.append(f"unreadable record at chunk offset {pos} ({err})")
        pos = dpos + dlen
    if offs:
        out.msg_off = np.concatenate(offs)
        out.msg_conn = np.concatenate(conns)
        out.msg_time = np.concatenate(times)
    return out


def _conn_text(topic: bytes, fields: dict[str, bytes]) -> tuple[str, str, str]:
    def text(b: bytes) -> str:
        return b.decode("utf-8", "replace")

    return text(topic), text(fields.get("type", b"")), text(fields.get("md5sum", b""))


@dataclass
class _Chunk:
    pos: int
    compression: str
    size: int  # declared uncompressed
    data_pos: int
    data_len: int
    index: dict[int, tuple[I64, I64]] = field(default_factory=dict)  # conn -> (times, offsets)


def _chunk_data(f: BinaryIO, path: Path, pos: int, data_pos: int, data_len: int) -> bytes:
    """A chunk's stored bytes, read when it is checked (one chunk held at a time)."""
    if data_len > budget.MAX_CHUNK_BYTES:
        raise BagError(
            budget.over_budget(
                f"chunk at byte {pos}",
                f"{data_len} bytes stored",
                budget.MAX_CHUNK_BYTES,
                "MAX_CHUNK_BYTES",
            ),
            path=path,
        )
    return os.pread(f.fileno(), data_len, data_pos)


def _ns(t: int) -> str:
    return f"{t // 1_000_000_000}.{t % 1_000_000_000:09d} ({iso_utc(t)})"


def _first(mask: npt.NDArray[np.bool_], values: I64) -> int:
    return int(values[np.flatnonzero(mask)[0]])


class _Report:
    def __init__(self) -> None:
        self.lines: list[str] = []
        self.dropped = 0

    def add(self, line: str) -> None:
        if len(self.lines) < MAX_LINES:
            self.lines.append(line)
        else:
            self.dropped += 1

    def result(self) -> list[str]:
        if self.dropped:
            return [*self.lines, f"... and {self.dropped} more disagreements"]
        return self.lines


def check_ros1(path: Path, progress: Reporter | None = None) -> list[str]:
    """Every disagreement between a ROS1 bag's index and its records, one line each (empty
    when the bag is consistent).

    ``progress`` gets the bytes of the file as its records are read, then the bytes of the
    chunks as they are decompressed and checked.

    Raises:
        BagError: the bag header itself is unreadable (not a bag).
    """
    size = path.stat().st_size
    with open_regular(path) as f:
        return _check(f, path, size, progress)


def _check(f: BinaryIO, path: Path, size: int, progress: Reporter | None) -> list[str]:
    rep = _Report()
    try:
        head, _ = records.read_record(f, MAGIC_LEN, size)
        if head.op != OP_BAG_HEADER:
            raise records.RecordError("first record is not the bag header", MAGIC_LEN)
        index_pos = records.u64(head.fields, "index_pos")
        conn_count = records.u32(head.fields, "conn_count")
        chunk_count = records.u32(head.fields, "chunk_count")
    except (records.RecordError, KeyError, struct.error) as err:
        raise BagError(f"unreadable ROS1 bag header ({err}); not a bag?", path=path) from err
    chunks: list[_Chunk] = []
    index_conns: dict[int, tuple[str, str, str]] = {}
    infos: list[tuple[int, int, int, int, dict[int, int]]] = []  # record pos, chunk pos, ...
    first_index_record = -1
    pos = head.end
    if progress is not None:
        progress.task(f"reading {path.name}", size, "B")
        progress.advance(pos)
    allowance = Allowance(size, str(path))
    while pos < size:
        try:
            rec, data = records.read_record(
                f, pos, size, with_data=True, lazy_ops=frozenset({OP_CHUNK})
            )
        except records.RecordError as err:
            rep.add(f"unreadable record at byte {pos} ({err}); nothing after it was checked")
            break
        except BagError as err:
            raise BagError(err.message, path=path) from err
        try:
            if rec.op == OP_CHUNK:
                compression, usize = chunk_head(rec.fields)
                if compression != "none":
                    allowance.add(usize, f"at byte {pos}")
                chunks.append(_Chunk(pos, compression, usize, rec.data_pos, rec.data_len))
            elif rec.op == OP_INDEX:
                cid, count = records.u32(rec.fields, "conn"), records.u32(rec.fields, "count")
                if records.u32(rec.fields, "ver") != 1 or len(data) != 12 * count:
                    rep.add(f"index data at byte {pos}: version or size disagrees with count")
                elif not chunks:
                    rep.add(f"index data at byte {pos} before any chunk")
                else:
                    chunks[-1].index[cid] = entries_from_index(data)
            elif rec.op == OP_CONNECTION:
                cid, topic, cf = records.connection_fields(rec, data)
                index_conns[cid] = _conn_text(topic.encode(), cf)
                if first_index_record < 0:
                    first_index_record = pos
            elif rec.op == OP_CHUNK_INFO:
                infos.append((pos, *records.chunk_info(rec, data)))
                if first_index_record < 0:
                    first_index_record = pos
            elif rec.op == OP_MSG:
                rep.add(f"message record at byte {pos} outside any chunk")
            else:
                rep.add(f"record of unknown op {rec.op} at byte {pos}")
        except (records.RecordError, KeyError, IndexError, struct.error) as err:
            rep.add(f"unreadable record of op {rec.op} at byte {pos} ({err})")
        if progress is not None:  # one call per top-level record: chunks, not messages
            progress.advance(rec.end - pos)
        pos = rec.end

    # The bag header against the index section.
    if first_index_record >= 0 and index_pos != first_index_record:
        rep.add(
            f"bag header: index_pos {index_pos}, but the index records start at byte "
            f"{first_index_record}"
        )
    elif first_index_record < 0 and index_pos != size and (conn_count or chunk_count):
        rep.add(f"bag header: index_pos {index_pos}, but there are no index records")
    if conn_count != len(index_conns):
        rep.add(f"bag header: conn_count {conn_count}, connection records {len(index_conns)}")
    if chunk_count != len(infos):
        rep.add(f"bag header: chunk_count {chunk_count}, chunk-info records {len(infos)}")

    info_of = {cpos: (ipos, start, end, counts) for ipos, cpos, start, end, counts in infos}
    chunk_at = {c.pos for c in chunks}
    for ipos, cpos, _s, _e, _c in infos:
        if cpos not in chunk_at:
            rep.add(f"chunk info at byte {ipos} points at byte {cpos}, where no chunk starts")
    if len(chunks) != len(infos):
        rep.add(f"{len(chunks)} chunk records, {len(infos)} chunk-info records")

    used: set[int] = set()
    if progress is not None:
        progress.task(f"checking chunks of {path.name}", sum(c.data_len for c in chunks), "B")
    for chunk in chunks:
        if progress is not None:
            progress.advance(chunk.data_len)
        where = f"chunk at byte {chunk.pos}"
        data = _chunk_data(f, path, chunk.pos, chunk.data_pos, chunk.data_len)
        try:
            buf = np.frombuffer(
                decompress(chunk.compression, data, chunk.size, f"at byte {chunk.pos}"), np.uint8
            )
        except BagError as err:
            rep.add(f"{where}: {err.message}")
            continue
        hints = (
            np.concatenate([off for _t, off in chunk.index.values()])
            if chunk.index
            else np.empty(0, np.int64)
        )
        recs = chunk_records(buf, hints, chunk.data_pos)
        for problem in recs.problems:
            rep.add(f"{where}: {problem}")
        for cid, text in recs.conns.items():
            known = index_conns.get(cid)
            if known is None:
                rep.add(
                    f"{where}: connection {cid} ({text[0]}) has no connection record in the index"
                )
            elif known != text:
                rep.add(
                    f"{where}: connection {cid} is {'/'.join(text[:2])} here, "
                    f"{'/'.join(known[:2])} in the index"
                )
        _compare_chunk(rep, where, chunk, recs, info_of.get(chunk.pos))
        used.update(int(c) for c in np.unique(recs.msg_conn))
    for cid in sorted(used - set(index_conns)):
        rep.add(f"messages of connection {cid} but no connection record in the index")
    return rep.result()


def _by_conn(conn: I64) -> dict[int, I64]:
    """conn -> the positions of its records, in record order: one sort for all connections
    (a mask per connection was quadratic in a chunk of many connections)."""
    order = np.argsort(conn, kind="stable")
    cids, first, count = np.unique(conn[order], return_index=True, return_counts=True)
    return {
        int(c): order[a : a + n]
        for c, a, n in zip(cids.tolist(), first.tolist(), count.tolist(), strict=True)
    }


def _compare_chunk(
    rep: _Report,
    where: str,
    chunk: _Chunk,
    recs: ChunkRecords,
    info: tuple[int, int, int, dict[int, int]] | None,
) -> None:
    of_conn = _by_conn(recs.msg_conn)
    present = np.fromiter(of_conn, dtype=np.int64, count=len(of_conn))
    if len(recs.msg_time) and info is not None:
        ipos, start, end, counts = info
        lo, hi = int(recs.msg_time.min()), int(recs.msg_time.max())
        if (start, end) != (lo, hi):
            rep.add(
                f"{where}: chunk info (byte {ipos}) says {_ns(start)} to {_ns(end)}; "
                f"its messages span {_ns(lo)} to {_ns(hi)}"
            )
        for cid in sorted(set(counts) | {int(c) for c in present}):
            held = len(of_conn.get(cid, ()))
            if counts.get(cid, 0) != held:
                rep.add(
                    f"{where}: connection {cid}: chunk info counts {counts.get(cid, 0)} "
                    f"messages, the chunk holds {held}"
                )
    elif info is None:
        rep.add(f"{where}: no chunk-info record")
    for cid in sorted(set(chunk.index) | {int(c) for c in present}):
        mine = of_conn.get(cid, np.empty(0, np.int64))
        off, t_rec = recs.msg_off[mine], recs.msg_time[mine]
        t_idx, o_idx = chunk.index.get(cid, (np.empty(0, np.int64), np.empty(0, np.int64)))
        tag = f"{where}: connection {cid}"
        if cid not in chunk.index:
            rep.add(f"{tag}: {len(off)} messages and no index-data record")
            continue
        # index entries against the records at their offsets (records sorted by offset)
        k = np.searchsorted(off, o_idx)
        k_safe = np.minimum(k, max(len(off) - 1, 0))
        hit = (k < len(off)) & (off[k_safe] == o_idx) if len(off) else np.zeros(len(o_idx), bool)
        if not np.all(hit):
            rep.add(
                f"{tag}: {int(np.count_nonzero(~hit))} index entries point at no message "
                f"record of this connection (first: chunk offset {_first(~hit, o_idx)})"
            )
        wrong = hit & (t_rec[k_safe] != t_idx) if len(off) else hit
        if np.any(wrong):
            i = int(np.flatnonzero(wrong)[0])
            rep.add(
                f"{tag}: {int(np.count_nonzero(wrong))} index entries disagree with their "
                f"record's time (first at chunk offset {int(o_idx[i])}: index "
                f"{_ns(int(t_idx[i]))}, record {_ns(int(t_rec[k_safe[i]]))})"
            )
        missed = ~np.isin(off, o_idx)
        if np.any(missed):
            rep.add(
                f"{tag}: {int(np.count_nonzero(missed))} message records not in the index "
                f"data (first at chunk offset {_first(missed, off)})"
            )


def _info_span(rec: records.Record, data: bytes, spans: dict[int, tuple[int, int]]) -> None:
    """The time span a chunk-info record gives its chunk, into ``spans`` (none when the
    record does not read: the rebuild does without it)."""
    try:
        cpos, start, end, _counts = records.chunk_info(rec, data)
    except (records.RecordError, KeyError, IndexError, struct.error):
        return
    spans[cpos] = (start, end)


def rebuild_layout(f: BinaryIO, path: Path, size: int, pos: int, why: str) -> Ros1Layout:
    """The layout of a closed bag rebuilt from its records, for a reader that stopped trusting
    the index: record times and offsets come from the message records themselves; the
    index-data offsets only say where to look first (:func:`chunk_records`), so the cost is
    one decompression per chunk and a few NumPy passes, not a Python step per message.
    Falls back to :func:`ertools.io.ros1.layout.scan_layout` (record by record) for anything
    but chunks, index data and index records at the top level.
    """
    start = pos
    conns: dict[int, Conn] = {}
    found: list[tuple[int, str, int, int, int, list[tuple[I64, I64]]]] = []
    problems = [why]
    allowance = Allowance(size, str(path))
    spans: dict[int, tuple[int, int]] = {}  # chunk position -> the chunk info's time span
    try:
        while pos < size:
            rec, data = records.read_record(
                f, pos, size, with_data=True, lazy_ops=frozenset({OP_CHUNK})
            )
            if rec.op == OP_CHUNK:
                compression, usize = chunk_head(rec.fields)
                if compression != "none":
                    allowance.add(usize, f"at byte {pos}")
                found.append((pos, compression, usize, rec.data_pos, rec.data_len, []))
            elif rec.op == OP_INDEX and found:
                found[-1][5].append(entries_from_index(data[: 12 * (len(data) // 12)]))
            elif rec.op == OP_CONNECTION:
                cid, topic, cf = records.connection_fields(rec, data)
                conns.setdefault(cid, conn_record(cid, topic, cf))
            elif rec.op == OP_CHUNK_INFO:
                _info_span(rec, data, spans)
            else:
                raise records.RecordError(f"record of op {rec.op} outside a chunk", pos)
            pos = rec.end
    except (records.RecordError, KeyError, IndexError, struct.error):
        return scan_layout(f, path, size, start, why)
    chunks = []
    for cpos, compression, usize, data_pos, data_len, hints in found:
        data = _chunk_data(f, path, cpos, data_pos, data_len)
        try:
            buf = np.frombuffer(decompress(compression, data, usize, f"at byte {cpos}"), np.uint8)
        except BagError as err:
            problems.append(f"corrupt chunk at byte {cpos} skipped ({err.message})")
            continue
        hint_t = np.concatenate([h[0] for h in hints]) if hints else np.empty(0, np.int64)
        hint_off = np.concatenate([h[1] for h in hints]) if hints else np.empty(0, np.int64)
        recs = chunk_records(buf, hint_off, data_pos)
        if recs.problems:
            return scan_layout(f, path, size, start, why)
        if len(hint_off) and len(recs.msg_off):
            # A record the index data points at must carry the entry's time (rosbags asserts
            # it). An entry whose time lies outside the span of the chunk's records is the
            # damaged side (the records are read instead); one inside it leaves no way to
            # tell which is damaged, and the records alone would read a damaged time or
            # chunk (lz4 has no checksum here) as sound.
            k = np.minimum(np.searchsorted(recs.msg_off, hint_off), len(recs.msg_off) - 1)
            hit = recs.msg_off[k] == hint_off
            differ = hint_t[hit][recs.msg_time[k[hit]] != hint_t[hit]]
            lo, hi = int(recs.msg_time.min()), int(recs.msg_time.max())
            # the chunk info's span, where it holds every differing entry and not the
            # chunk's records, is a second witness: the records' times are the damage (a
            # damaged lz4 byte repeated into every record's time, found by fuzzing)
            a, b = spans.get(cpos, (hi + 1, lo - 1))
            if np.any((differ >= lo) & (differ <= hi)) or (
                len(differ) and bool(np.all((differ >= a) & (differ <= b))) and (lo < a or hi > b)
            ):
                problems.append(
                    f"chunk at byte {cpos}: a message record's time differs from its index entry"
                )
        for cid, (topic, msgtype, md5) in recs.conns.items():
            fields = {"type": msgtype.encode(), "md5sum": md5.encode()}
            conns.setdefault(cid, conn_record(cid, topic, fields))
        if not len(recs.msg_off):
            continue
        entries = {
            cid: (recs.msg_time[at], recs.msg_off[at])
            for cid, at in _by_conn(recs.msg_conn).items()
        }
        chunks.append(
            Ros1Chunk(
                cpos,
                int(recs.msg_time.min()),
                int(recs.msg_time.max()),
                {cid: len(t) for cid, (t, _o) in entries.items()},
                compression,
                data_pos,
                data_len,
                entries,
                usize,
            )
        )
    return Ros1Layout(
        path, size, False, sorted(conns.values(), key=lambda c: c.id), chunks, problems
    )
