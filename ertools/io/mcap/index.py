"""MCAP files read through their summary section: chunk indexes and message indexes.

Opening reads the footer and the summary section only (schemas, channels, chunk indexes,
statistics). Messages of some channels are located from the message-index records that follow
each chunk, read for every chunk overlapping the window before any chunk data, so the
reference order (log time, then chunk, then position, as the ``mcap`` library yields them) is
known up front; then the chunks are decompressed one at a time.
"""

from __future__ import annotations

import logging
import os
import struct
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, BinaryIO

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64, U8, fresh_concat, fresh_repeat
from ertools.errors import BagError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.inputs import open_regular
from ertools.io import pipeline
from ertools.io.bagfile import BagFile
from ertools.io.decode.fast import LayoutMismatchError
from ertools.io.decode.fast import read_at as read_fields
from ertools.io.inflate import check_declared, inflate_into
from ertools.io.mcap.crc import crc32
from ertools.io.mcap.records import McapRecords
from ertools.io.mcap.scan import SCAN, mcap_layout, scan_mcap
from ertools.io.mcap.summary import decompress, file_size, read_summary
from ertools.io.model import Conn
from ertools.io.pipeline import (
    Group,
    Request,
    Run,
    group_positions,
    in_window,
    pread,
    read_at,
    scratch_view,
    window,
)

if TYPE_CHECKING:
    from ertools.progress import Reporter

log = logging.getLogger("ertools.io.mcap.index")


OP_MESSAGE = 0x05
OP_CHUNK = 0x06
OP_MESSAGE_INDEX = 0x07
MESSAGE_FIXED = 2 + 4 + 8 + 8  # channel id, sequence, log time, publish time
PAIR = np.dtype([("t", "<u8"), ("off", "<u8")])


def _check_counts(path: Path, summary: Any, planned: dict[int, int]) -> None:
    """A whole-file read finds as many messages of each channel in the message indexes as the
    statistics count (when they add up): a message index whose array length was damaged to
    fewer entries (the rest then reads as padding, which the specification allows) would
    drop messages without a word."""
    stats = summary.statistics
    if stats is None or not stats.channel_message_counts:
        return
    counts = stats.channel_message_counts
    if sum(counts.values()) != stats.message_count:
        return  # damaged statistics: not a measure of anything
    for cid, n in planned.items():
        if n != counts.get(cid, 0):
            raise BagError(
                f"the message indexes hold {n} messages of channel {cid}, the statistics "
                f"{counts.get(cid, 0)} (damaged index)",
                path=path,
            )


def _in_order(*keys: I64) -> bool:
    """Whether rows are already sorted by ``keys`` (the first the most significant)."""
    if len(keys[0]) < 2:
        return True
    undecided = np.ones(len(keys[0]) - 1, dtype=bool)
    for k in keys:
        step = k[1:] - k[:-1]
        if np.any(undecided & (step < 0)):
            return False
        undecided &= step == 0
        if not undecided.any():
            return True
    return True


@frozen_dataclass(eq=False)
class McapPlan:
    """Messages located from the message indexes, in the reference order."""

    t_record: I64
    offset: I64
    key: I64  # file << 32 | chunk index
    chunks: list[list[Any]]
    channel: npt.NDArray[np.uint16]

    def by_key(self) -> dict[int, slice | I64]:
        """The messages of each chunk (by key): a slice of the plan when its messages are in
        chunk order (one channel logged in time order), else their positions."""
        key = self.key
        if not len(key):
            return {}
        if bool(np.all(key[1:] >= key[:-1])):
            cuts = np.flatnonzero(key[1:] != key[:-1]) + 1
            starts = [0, *cuts.tolist()]
            ends = [*cuts.tolist(), len(key)]
            return {int(key[a]): slice(a, b) for a, b in zip(starts, ends, strict=True)}
        return dict(group_positions(key))


class McapIndex:
    """Chunk-level access to one or more MCAP files (a rosbag2 directory may hold several)."""

    def __init__(self, files: list[Path], by_id: bool = False) -> None:
        """``by_id``: a request's connections are the file's channels (a standalone MCAP
        file), so a request wants exactly their ids; otherwise (rosbag2, one connection per
        topic over several files) it wants every channel on their topics."""
        self.files = files
        self.by_id = by_id

    @staticmethod
    def of(bag: BagFile) -> McapIndex | None:
        """The index of a standalone MCAP file, None for other formats (a rosbag2-mcap
        directory's files come from :func:`ertools.io.bulk.mcap_index`, which knows how
        the directory stores them)."""
        if bag.format == "mcap":
            return McapIndex([bag.path], by_id=True)
        return None

    def plan(self, conns: Sequence[Conn], lo: int | None, hi: int | None) -> McapPlan:
        """Locate the messages of ``conns`` in [lo, hi]: one request of :meth:`plan_many`."""
        return self.plan_many([Request(tuple(conns), lo, hi)])[0]

    def plan_many(self, requests: Sequence[Request]) -> list[McapPlan]:
        """Locate the messages of each request (connections, log-time window) from the message
        indexes, each in its reference order, reading every message index once (no chunk data).

        Raises:
            BagError: damaged index.
            LayoutMismatchError: a file's indexes do not answer for every message (no summary,
                no message indexes, channels only inside chunks...): the caller falls back.
        """
        lo, hi = window(requests)
        # per request: file, chunk idx, chunk offset, t, off, channel of each run of entries
        sels: list[list[tuple[int, int, int, I64, I64, int]]] = [[] for _ in requests]
        chunks_per_file: list[list[Any]] = []
        for fi, path in enumerate(self.files):
            layout = mcap_layout(path)
            if layout.index == SCAN:
                raise LayoutMismatchError(f"MCAP file {path.name}: {layout.why}")
            summary: Any = layout.summary
            with open_regular(path) as f:
                # channel -> the requests that want it
                wants: dict[int, list[int]] = {}
                for ri, req in enumerate(requests):
                    topics = {c.topic for c in req.conns}
                    ids = {c.id for c in req.conns}
                    for cid, ch in layout.channels.items():
                        if (cid in ids) if self.by_id else (ch.topic in topics):
                            wants.setdefault(cid, []).append(ri)
                chunks = summary.chunk_indexes
                chunks_per_file.append(chunks)
                total_size = file_size(f)
                planned = dict.fromkeys(wants, 0)  # messages per channel, for the statistics
                for ci, chunk in enumerate(chunks):
                    if lo is not None and chunk.message_end_time < lo:
                        continue
                    if hi is not None and chunk.message_start_time > hi:
                        continue
                    if not 0 <= chunk.chunk_start_offset < total_size:
                        raise BagError(
                            f"chunk index gives a chunk at byte {chunk.chunk_start_offset}, "
                            "outside the file",
                            path=path,
                        )
                    if any(c not in summary.channels for c in chunk.message_index_offsets):
                        # a damaged channel id: the messages it stood for would be skipped
                        raise BagError(
                            f"chunk index of the chunk at byte {chunk.chunk_start_offset} "
                            "names a channel the summary section does not declare",
                            path=path,
                        )
                    wanted = [c for c in wants if c in chunk.message_index_offsets]
                    if not wanted:
                        if chunk.message_index_length == 0 and chunk.uncompressed_size:
                            raise LayoutMismatchError("MCAP chunk without message indexes")
                        continue
                    for cid in wanted:
                        offset = chunk.message_index_offsets[cid]
                        t, off = self._message_index(f, path, offset, cid, total_size, padded=False)
                        planned[cid] = planned.get(cid, 0) + len(t)
                        for ri in wants[cid]:
                            keep = in_window(t, requests[ri].lo, requests[ri].hi)
                            tk, ok = (t, off) if keep is None else (t[keep], off[keep])
                            if len(tk):
                                start = int(chunk.chunk_start_offset)
                                sels[ri].append((fi, ci, start, tk, ok, cid))
            if lo is None and hi is None:
                _check_counts(path, summary, planned)
        return [_ordered(s, chunks_per_file) for s in sels]

    def all_chunks(self) -> list[tuple[Path, Any]]:
        """(file, chunk index record) of every chunk, in file order."""
        out: list[tuple[Path, Any]] = []
        for path in self.files:
            with open_regular(path) as f:
                summary = read_summary(f, path)
            if summary is not None:
                out.extend((path, c) for c in summary.chunk_indexes)
        return out

    def run_loader(
        self, plans: Sequence[McapPlan]
    ) -> tuple[int, Callable[[int, list[Any]], list[Run | None]], list[int]]:
        """(number of groups, load, bytes) where ``load(k, scratch)`` decompresses the k-th
        group of chunks (up to ``GROUP_BYTES`` uncompressed; the chunks any plan needs) into
        ``scratch`` and gives each plan's :class:`Run` of its messages in it (None when it
        has none there), and ``bytes[k]`` is what that group reads from the file (its chunks'
        compressed sizes, for progress). ``load`` may run on a worker thread (it opens the
        file itself)."""
        rows_of = [p.by_key() for p in plans]
        keys = sorted({k for rows in rows_of for k in rows})
        # a plan of one channel gives its runs that id broadcast (no array per run)
        single = [
            int(p.channel[0])
            if len(p.channel) and bool(np.all(p.channel == p.channel[0]))
            else None
            for p in plans
        ]
        chunks_of = plans[0].chunks if plans else []
        todo: list[list[int]] = []
        size = 0
        for key in keys:
            if not todo or size >= pipeline.GROUP_BYTES:
                todo.append([])
                size = 0
            todo[-1].append(key)
            size += int(chunks_of[key >> 32][key & 0xFFFFFFFF].uncompressed_size)

        def chunk_of(key: int) -> tuple[Path, Any]:
            return self.files[key >> 32], chunks_of[key >> 32][key & 0xFFFFFFFF]

        def load(k: int, scratch: list[Any]) -> list[Run | None]:
            part = todo[k]
            buf, base, sizes = self._group_bytes([chunk_of(key) for key in part], scratch)
            path, first = chunk_of(part[0])
            where = f"in {path} in chunks from byte {first.chunk_start_offset}"
            out: list[Run | None] = []
            for plan, rows_by_key, one in zip(plans, rows_of, single, strict=True):
                mine = [(i, rows_by_key[key]) for i, key in enumerate(part) if key in rows_by_key]
                if not mine:
                    out.append(None)
                    continue
                counts = [_count(r) for _i, r in mine]
                which = np.repeat(np.array([i for i, _r in mine], dtype=np.int64), counts)
                sel: slice | I64
                first, last = mine[0][1], mine[-1][1]
                if all(isinstance(r, slice) for _i, r in mine):
                    # one range of the plan (its chunks' slices follow each other)
                    assert isinstance(first, slice) and isinstance(last, slice)
                    sel = slice(first.start, last.stop)
                    rows = np.arange(first.start, last.stop, dtype=np.int64)
                else:
                    rows = np.concatenate([_positions(r) for _i, r in mine])
                    sel = rows
                offsets = plan.offset[sel]
                # a record inside its chunk: no earlier (here), no later (its end, checked
                # with the record)
                if len(offsets) and int(offsets.min()) < 0:
                    raise BagError(f"message index points outside its chunk {where}")
                t = plan.t_record[sel]
                channel = (
                    plan.channel[sel].astype(np.int64)
                    if one is None
                    else np.broadcast_to(np.int64(one), t.shape)
                )
                limit = base[which] + sizes[which]
                records = McapRecords(buf, offsets + base[which], limit, t, channel, where)
                consecutive = isinstance(sel, slice)
                out.append(Run(rows, buf, t, channel, records, consecutive=consecutive))
            return out

        weights = [sum(int(chunk_of(key)[1].compressed_size) for key in part) for part in todo]
        return len(todo), load, weights

    def messages(
        self, conns: Sequence[Conn], lo: int | None, hi: int | None
    ) -> list[tuple[int, int, int, bytes]]:
        """(file index, channel id, log time, data) of every message ``conns`` want (see
        ``by_id``) in [lo, hi], in the reference order: the per-message path, through the same
        bounded chunk loads as the fast path (the ``mcap`` library's own decompression trusts
        a zstd frame's stated size, however large).

        Raises:
            BagError: damaged index or chunk, or a chunk over the budget.
            LayoutMismatchError: as :meth:`plan`.
        """
        plan = self.plan(conns, lo, hi)
        count, load, _weights = self.run_loader([plan])
        n = len(plan.t_record)
        data: list[bytes] = [b""] * n
        channel = np.zeros(n, dtype=np.int64)
        scratch: list[Any] = []
        for k in range(count):
            run = load(k, scratch)[0]
            if run is None:
                continue
            start, length = run.spans()
            rows, buf = run.pos, run.buf
            # a record's channel id follows its op code and length
            channel[rows] = read_fields(buf, start - MESSAGE_FIXED, np.dtype("<u2"))
            for row, a, m in zip(rows.tolist(), start.tolist(), length.tolist(), strict=True):
                data[row] = bytes(buf[a : a + m])
        files = (plan.key >> 32).tolist()
        times, channels = plan.t_record.tolist(), channel.tolist()
        return list(zip(files, channels, times, data, strict=True))

    @staticmethod
    def _group_bytes(chunks: list[tuple[Path, Any]], scratch: list[Any]) -> Group:
        """The records of several chunks end to end in ``scratch``: uncompressed chunks are
        read straight into it, compressed ones decompressed and copied in."""
        if any(chunk.compression for _path, chunk in chunks):
            return McapIndex._inflated_group(chunks, scratch)
        for path, chunk in chunks:
            # sizes from the summary are checked before they size a buffer (a flipped high
            # bit made an int64 overflow); the chunk record itself is checked below
            if int(chunk.uncompressed_size) != int(chunk.compressed_size):
                raise BagError(
                    f"uncompressed chunk with compressed size {chunk.compressed_size} != "
                    f"uncompressed size {chunk.uncompressed_size} in the summary's chunk index",
                    path=path,
                )
            if int(chunk.uncompressed_size) > path.stat().st_size:
                raise BagError(
                    f"chunk index gives a chunk of {chunk.uncompressed_size} bytes, more than "
                    "the file holds",
                    path=path,
                )
        sizes = np.array([int(c.uncompressed_size) for _p, c in chunks], dtype=np.int64)
        base = np.zeros(len(chunks), dtype=np.int64)
        np.cumsum(sizes[:-1], out=base[1:])
        view = scratch_view(scratch, int(sizes.sum()))
        for (path, chunk), b, n in zip(chunks, base.tolist(), sizes.tolist(), strict=True):
            where = f"in {path} at byte {chunk.chunk_start_offset}"
            with open_regular(path) as f:
                compression, at, nbytes, usize, crc = McapIndex._chunk_head(f.fileno(), path, chunk)
                if compression or nbytes != n or usize != n:
                    raise BagError(f"chunk record disagrees with the summary's index {where}")
                if read_at(f.fileno(), view[b : b + n], at) != n:
                    raise BagError(f"chunk cut off by end of file {where}")
                # a flipped bit in a pose's bytes reads as another pose: the CRC finds it
                if crc and crc32(view[b : b + n]) != crc:
                    raise BagError(f"chunk fails its CRC check (damaged) {where}")
        return np.frombuffer(view, dtype=np.uint8), base, sizes

    @staticmethod
    def _inflated_group(chunks: list[tuple[Path, Any]], scratch: list[Any]) -> Group:
        """Compressed chunks decompressed end to end into ``scratch``, each checked against
        its size and CRC. zstd chunks inflate straight into the reused buffer: a fresh
        output object per chunk cost more CPU than the decompression itself (page faults
        on new memory, then a copy), which is what pays for the CRC check."""
        raw = [McapIndex._chunk_raw(path, chunk) for path, chunk in chunks]
        sizes = np.array([usize for _c, _d, usize, _crc in raw], dtype=np.int64)
        base = np.zeros(len(chunks), dtype=np.int64)
        np.cumsum(sizes[:-1], out=base[1:])
        view = scratch_view(scratch, int(sizes.sum()))
        out = np.frombuffer(view, dtype=np.uint8)
        for (path, chunk), (compression, data, usize, crc), b in zip(
            chunks, raw, base.tolist(), strict=True
        ):
            where = f"in {path} at byte {chunk.chunk_start_offset}"
            part = view[b : b + usize]
            inflate_into(compression, data, part, where, "MCAP chunk")
            if crc and crc32(part) != crc:
                raise BagError(f"chunk fails its CRC check (damaged) {where}")
        return out, base, sizes

    @staticmethod
    def inflated_bytes(path: Path, chunk: Any) -> bytes:
        """A chunk's records, decompressed (and its size checked)."""
        where = f"in {path} at byte {chunk.chunk_start_offset}"
        compression, data, usize, crc = McapIndex._chunk_raw(path, chunk)
        out: bytes = decompress(compression, data, usize, where)
        # lz4 and zstd frames as MCAP writers make them carry no checksum of their own: a
        # damaged compressed chunk inflates to other bytes without an error (fuzzing: poses
        # changed, records lost). The chunk's CRC (0: not computed) finds it.
        if crc and crc32(out) != crc:
            raise BagError(f"chunk fails its CRC check (damaged) {where}")
        return out

    @staticmethod
    def _message_index(
        f: BinaryIO,
        path: Path,
        pos: int,
        cid: int,
        size: int | None = None,
        padded: bool = True,
    ) -> tuple[I64, I64]:
        """(log times, record offsets) of one message-index record.

        Raises:
            BagError: damaged record.
            LayoutMismatchError: (``padded`` False) the record is longer than its array. The
                specification lets writers pad records, but so does a damaged array length
                look (fewer entries, the rest taken for padding): a read or count that
                trusts the index then goes record by record instead (only padded files pay).
        """
        if size is None:
            size = file_size(f)
        if not 0 <= pos < size:
            raise BagError(f"message index offset {pos} outside the file ({size} bytes)", path=path)
        f.seek(pos)
        head = f.read(1 + 8 + 2 + 4)
        if len(head) < 15 or head[0] != OP_MESSAGE_INDEX:
            raise BagError(f"no message index at byte {pos}", path=path)
        _, length, channel, nbytes = struct.unpack("<BQHI", head)
        # the array must lie inside its record (a damaged array length would read the next
        # records as (time, offset) pairs); the record may be longer: the specification
        # lets writers pad records
        if channel != cid or nbytes % 16 or length < 6 + nbytes or pos + 15 + nbytes > size:
            raise BagError(f"damaged message index at byte {pos}", path=path)
        if not padded and length != 6 + nbytes:
            raise LayoutMismatchError(f"a message index at byte {pos} with padding")
        data = f.read(nbytes)
        if len(data) != nbytes:
            raise BagError(f"message index at byte {pos} cut off by end of file", path=path)
        arr = np.frombuffer(data, dtype=PAIR)
        return arr["t"].astype(np.int64), arr["off"].astype(np.int64)

    @staticmethod
    def _chunk_bytes(path: Path, chunk: Any) -> U8:
        return np.frombuffer(McapIndex.inflated_bytes(path, chunk), dtype=np.uint8)

    @staticmethod
    def _chunk_raw(path: Path, chunk: Any) -> tuple[str, bytes, int, int]:
        """(compression, compressed records, uncompressed size, CRC) of a chunk record."""
        where = f"in {path} at byte {chunk.chunk_start_offset}"
        with open_regular(path) as f:
            compression, at, nbytes, usize, crc = McapIndex._chunk_head(f.fileno(), path, chunk)
            data = pread(f.fileno(), nbytes, at)
        if len(data) != nbytes:
            raise BagError(f"chunk cut off by end of file {where}")
        return compression, data, usize, crc

    @staticmethod
    def _chunk_head(fd: int, path: Path, chunk: Any) -> tuple[str, int, int, int, int]:
        """(compression, where the records start, their stored size, uncompressed size, CRC)
        of a chunk record, from its header (positional reads: may run on a loading thread)."""
        where = f"in {path} at byte {chunk.chunk_start_offset}"
        size = os.fstat(fd).st_size
        start = int(chunk.chunk_start_offset)
        if not 0 <= start < size:
            raise BagError(f"chunk offset outside the file ({size} bytes) {where}")
        head = pread(fd, 1 + 8 + 8 + 8 + 8 + 4 + 4, start)
        if len(head) < 41 or head[0] != OP_CHUNK:
            raise BagError(f"no chunk record {where}")
        _, _rlen, _t0, _t1, usize, crc, clen = struct.unpack("<BQQQQII", head)
        if start + 41 + clen + 8 > size:
            raise BagError(f"damaged chunk record {where}")
        tail = pread(fd, clen + 8, start + 41)
        compression = tail[:clen].decode("ascii", "replace")
        (nbytes,) = struct.unpack("<Q", tail[clen:])
        at = start + 41 + clen + 8
        if at + nbytes > size:
            raise BagError(
                f"damaged chunk record: its {nbytes} stored bytes run past the end of the "
                f"file {where}"
            )
        if not compression and nbytes != usize:
            raise BagError(
                f"damaged chunk record: uncompressed, yet {nbytes} bytes stored for {usize} {where}"
            )
        check_declared(max(usize, nbytes), where, "MCAP chunk")
        return compression, at, int(nbytes), int(usize), int(crc)

    @staticmethod
    def _spans(buf: U8, off: I64, where: str) -> tuple[I64, I64]:
        if len(off) and (int(off.min()) < 0 or int(off.max()) + 9 + MESSAGE_FIXED > len(buf)):
            raise BagError(f"message index points outside its chunk {where}")
        if np.any(buf[off] != OP_MESSAGE):
            raise BagError(f"message index points at a record that is no message {where}")
        rlen = read_fields(buf, off + 1, np.dtype("<u8")).astype(np.int64)
        start = off + 9 + MESSAGE_FIXED
        length = rlen - MESSAGE_FIXED
        if len(off) and (int((start + length).max()) > len(buf) or int(length.min()) < 0):
            raise BagError(f"message record cut off inside its chunk {where}")
        return start, length


def _count(rows: slice | I64) -> int:
    return rows.stop - rows.start if isinstance(rows, slice) else len(rows)


def _positions(rows: slice | I64) -> I64:
    return np.arange(rows.start, rows.stop, dtype=np.int64) if isinstance(rows, slice) else rows


def _ordered(sels: list[tuple[int, int, int, I64, I64, int]], chunks: list[list[Any]]) -> McapPlan:
    """One request's located messages in the mcap library's order: log time, then file,
    chunk position, record position."""
    if not sels:
        e = np.empty(0, np.int64)
        return McapPlan(e, e, e, chunks, np.empty(0, np.uint16))
    # (into memory that comes in huge pages: an hour's columns are a few MB each)
    t_all = fresh_concat([s[3] for s in sels], np.int64)
    off_all = fresh_concat([s[4] for s in sels], np.int64)
    # file, chunk and chunk offset of every row: one fill per chunk, not an array per chunk
    counts = np.array([len(s[3]) for s in sels], dtype=np.int64)
    key = fresh_repeat([(s[0] << 32) + s[1] for s in sels], counts.tolist(), np.int64)
    channel = fresh_repeat([s[5] for s in sels], counts.tolist(), np.uint16)
    # One channel logged in time order is in that order already: no sort (times that
    # strictly increase need no other key).
    if bool(np.all(t_all[1:] > t_all[:-1])):
        return McapPlan(t_all, off_all, key, chunks, channel)
    file_all = key >> 32
    cstart_all = np.repeat(np.array([s[2] for s in sels], dtype=np.int64), counts)
    if _in_order(t_all, file_all, cstart_all, off_all):
        return McapPlan(t_all, off_all, key, chunks, channel)
    order = np.lexsort((off_all, cstart_all, file_all, t_all))
    return McapPlan(t_all[order], off_all[order], key[order], chunks, channel[order])


def verify_mcap(path: Path, progress: Reporter | None = None) -> None:
    """Decompress every chunk of an MCAP file, check its CRC and its message indexes (a file
    read record by record: every record and every chunk CRC). The chunks' bytes are
    reported to ``progress`` (indexed files; an unindexed one is one scan, unreported).

    Raises:
        BagError: the first damaged chunk, with its byte offset.
    """
    layout = mcap_layout(path)
    if layout.index == SCAN:
        # no indexes to check against: every record read, every chunk's CRC checked
        found = scan_mcap(path, check_crc=True)
        if found.problem:
            raise BagError(found.problem, path=path)
        return
    with open_regular(path) as f:
        summary: Any = layout.summary
        if progress is not None:
            total = sum(int(c.compressed_size) for c in summary.chunk_indexes)
            progress.task(f"checking {path.name}", total, "B")
        for chunk in summary.chunk_indexes:
            if progress is not None:
                progress.advance(int(chunk.compressed_size))
            where = f"in {path} at byte {chunk.chunk_start_offset}"
            f.seek(chunk.chunk_start_offset + 1 + 8 + 8 + 8 + 8)
            (crc,) = struct.unpack("<I", f.read(4))
            buf = McapIndex._chunk_bytes(path, chunk)
            if crc and crc32(buf.tobytes()) != crc:
                raise BagError(f"corrupt MCAP chunk {where}: CRC mismatch")
            for cid, offset in chunk.message_index_offsets.items():
                _t, off = McapIndex._message_index(f, path, offset, cid)
                McapIndex._spans(buf, off, where)
