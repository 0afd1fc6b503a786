"""ROS1 bags read through their own index: connections, chunk infos and index-data records.

Opening costs a few reads at the end of the file (the index section), whatever the bag's size;
no per-message Python objects are made. Bags without a usable index (``.bag.active`` files
still being recorded, truncated copies) are scanned record by record instead, and say so in
``problems``.
"""

from __future__ import annotations

import contextlib
import logging
import mmap
from collections.abc import Collection, Iterator, Sequence
from io import BufferedReader
from pathlib import Path
from struct import error as struct_error
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64, U8
from ertools.errors import BagError
from ertools.inputs import open_regular
from ertools.io import budget, mapguard
from ertools.io.bagfile import BagFile, RawRecord
from ertools.io.decode.fast import LayoutMismatchError, gather, read_at
from ertools.io.inflate import Allowance
from ertools.io.model import Conn
from ertools.io.pipeline import Request, window
from ertools.io.ros1.entries import Ints, Selection, connection_entries, ordered
from ertools.io.ros1.layout import (
    INDEX_DTYPE,
    MSG_HEADER_LEN,
    OP_AT,
    OP_MSG_WORD,
    U32,
    Ros1Chunk,
    Ros1Layout,
    chunk_head,
    decompress,
    entries_from_index,
    fields_before,
    index_header,
    nonzero_counts,
    op_word,
    read_layout,
    value_offsets,
)
from ertools.io.ros1.records import (
    MAGIC_LEN,
    OP_CHUNK,
    OP_CONNECTION,
    OP_INDEX,
    OP_MSG,
    Record,
    RecordError,
    parse_fields,
    read_record,
)
from ertools.io.ros1.runs import ros1_runs
from ertools.progress import current

if TYPE_CHECKING:
    from ertools.progress import Reporter

log = logging.getLogger("ertools.io.ros1.index")


def _first_record(bag: Ros1Bag) -> int:
    """Where the records after the bag header start."""
    try:
        head, _ = read_record(bag.file, MAGIC_LEN, bag.layout.size)
    except RecordError as err:
        raise BagError(f"unreadable ROS1 bag header ({err})", path=bag.path) from err
    return head.end


def _standard_spans(buf: U8, offsets: I64) -> tuple[I64, I64] | None:
    """(data start, data length) when every record has the standard 38-byte header with its op
    field where the first one has it (a writer's usual output): three gathers and two
    checks. None when any record differs (the caller then looks at each kind)."""

    n = len(buf)
    if int(offsets.max()) + 8 + MSG_HEADER_LEN > n:
        return None
    if not bool(np.all(read_at(buf, offsets, np.dtype("<u4")) == MSG_HEADER_LEN)):
        return None
    first = next((at for at in OP_AT if op_word(buf, offsets[:1] + 4 + at)[0] == OP_MSG_WORD), None)
    if first is None or not bool(np.all(op_word(buf, offsets + 4 + first) == OP_MSG_WORD)):
        return None
    start = offsets + (8 + MSG_HEADER_LEN)
    length = read_at(buf, start - 4, np.dtype("<u4")).astype(np.int64)
    if int((start + length).max()) > n:
        return None
    return start, length


class Ros1Bag(BagFile):
    """A ROS1 bag read through its index (or a scan): raw messages and chunk access."""

    def __init__(
        self, path: Path, layout: Ros1Layout | None = None, *, strict: bool = True
    ) -> None:
        """Open ``path`` (its index, or a scan). With ``strict`` (reading), a closed bag whose
        index was missing or damaged is refused; summaries pass ``strict=False``."""
        self.path = path
        self.layout = layout if layout is not None else read_layout(path)
        active = path.name.endswith(".active")
        self.format = "ros1-active" if active else "ros1"
        problems = self.layout.problems
        if problems and not active and strict:
            # A closed bag without a sound index was cut short or damaged: reading what is
            # left would give a silently shorter stream.
            raise BagError(
                f"{'; '.join(problems)}; re-copy the file or run `rosbag reindex` on a copy",
                path=path,
            )
        if problems and strict:
            log.warning("%s: %s; reading what the scan found", path, "; ".join(problems))
        self.connections = tuple(self.layout.conns)
        self._inflation = Allowance(self.layout.size, str(path))
        self._f: BufferedReader | None = open_regular(path)
        self._mm: mmap.mmap | None = None

    def _unmap(self) -> None:
        if self._mm is not None:
            # Only bytes copies leave the mapping; should a view be alive, it stays mapped
            # until that view is collected.
            mapguard.unwatch(self._mm)
            with contextlib.suppress(BufferError):
                self._mm.close()
            self._mm = None

    def close(self) -> None:
        self._unmap()
        if self._f is not None:
            self._f.close()
            self._f = None

    @property
    def file(self) -> BufferedReader:
        if self._f is None:
            raise BagError("bag already closed", path=self.path)
        return self._f

    def _where(self, chunk: Ros1Chunk) -> str:
        return f"in {self.path} at byte {chunk.pos}"

    def chunk_record(self, chunk: Ros1Chunk) -> Record:
        """The record header of a chunk (sets its compression and where its data lies)."""
        try:
            rec, _ = read_record(self.file, chunk.pos, self.layout.size)
        except RecordError as err:
            raise BagError(f"damaged chunk record ({err})", path=self.path) from err
        if rec.op != OP_CHUNK:
            raise BagError(f"expected a chunk record at byte {chunk.pos}", path=self.path)
        chunk.compression, chunk.size = chunk_head(rec.fields)
        chunk.data_pos, chunk.data_len = rec.data_pos, rec.data_len
        if rec.data_len > budget.MAX_CHUNK_BYTES:
            raise BagError(
                budget.over_budget(
                    f"chunk at byte {chunk.pos}",
                    f"{rec.data_len} bytes stored",
                    budget.MAX_CHUNK_BYTES,
                    "MAX_CHUNK_BYTES",
                ),
                path=self.path,
            )
        if chunk.compression != "none":
            # each chunk's header is read once: what the chunks read so far may inflate to
            self._inflation.add(chunk.size, f"at byte {chunk.pos}")
        return rec

    def compressions(self) -> list[str]:
        """The compression of every chunk (reads each chunk's record header)."""
        out = []
        for chunk in self.layout.chunks:
            if not chunk.compression:
                self.chunk_record(chunk)
            out.append(chunk.compression)
        return out

    def _mapped(self) -> mmap.mmap:
        """The file mapped read-only: index records are read where they lie, without a
        system call per record (only the pages touched are read)."""
        if self._mm is None:
            self._mm = mmap.mmap(self.file.fileno(), 0, access=mmap.ACCESS_READ)
            mapguard.watch(self._mm, self.path)
        return self._mm

    def _index_data(
        self,
        chunk: Ros1Chunk,
        wanted: Collection[int] | None,
        counts: dict[int, int] | None = None,
        view: memoryview | None = None,
    ) -> dict[int, bytes | memoryview]:
        """conn -> raw (sec, nsec, offset) entries of one chunk, for the ``wanted`` connections
        (all when None), from the index-data records that follow the chunk; ``counts`` gets
        every record's conn -> count (all connections). With ``view`` (of the mapped file),
        the entries are slices of it, not copies."""
        if chunk.data_pos < 0:
            self.chunk_record(chunk)
        mm = self._mapped()
        src = mm if view is None else view
        size = min(len(mm), self.layout.size)
        pos = chunk.data_pos + chunk.data_len
        out: dict[int, bytes | memoryview] = {}
        try:
            for _ in range(len(chunk.counts)):
                if pos + 8 > size:
                    raise RecordError("index data cut off by end of file", pos)
                (hlen,) = U32.unpack_from(mm, pos)
                if pos + 8 + hlen > size:
                    raise RecordError("index data cut off by end of file", pos)
                head = index_header(mm[pos + 4 : pos + 4 + hlen])
                if head is None:
                    raise RecordError("malformed index-data record header", pos)
                op, ver, cid, count = head
                if op != OP_INDEX:
                    raise RecordError("expected an index-data record", pos)
                if ver != 1:
                    raise RecordError("index-data version not 1", pos)
                (dlen,) = U32.unpack_from(mm, pos + 4 + hlen)
                data_pos = pos + 8 + hlen
                if dlen != 12 * count or data_pos + dlen > size:
                    raise RecordError("index-data size disagrees with its count", pos)
                if counts is not None:
                    counts[cid] = counts.get(cid, 0) + count
                if wanted is None or cid in wanted:
                    out[cid] = src[data_pos : data_pos + dlen]
                pos = data_pos + dlen
        except (RecordError, KeyError, struct_error, IndexError) as err:
            raise BagError(
                f"damaged index data after chunk at byte {chunk.pos} ({err})", path=self.path
            ) from err
        return out

    def chunk_entries(self, chunk: Ros1Chunk) -> dict[int, tuple[I64, I64]]:
        """conn -> (record times, record offsets) of one chunk, from its index-data records."""
        if chunk.entries is not None:
            return chunk.entries
        # Not kept on the chunk: an hour bag's index entries are ~20 MB, needed once per read.
        return {cid: entries_from_index(d) for cid, d in self._index_data(chunk, None).items()}

    def chunk_bytes(self, chunk: Ros1Chunk) -> bytes:
        """The uncompressed data of one chunk."""
        if chunk.data_pos < 0:
            self.chunk_record(chunk)
        self.file.seek(chunk.data_pos)
        data = self.file.read(chunk.data_len)
        if len(data) != chunk.data_len:
            raise BagError(f"chunk at byte {chunk.pos} cut off by end of file", path=self.path)
        try:
            return decompress(chunk.compression, data, chunk.size, f"at byte {chunk.pos}")
        except BagError as err:
            raise BagError(err.message, path=self.path) from err

    def select(
        self, conns: Sequence[Conn], start_ns: int | None, end_ns: int | None
    ) -> tuple[list[int], Ints, Ints, I64, Ints]:
        """Messages of ``conns`` in [start_ns, end_ns], in the reference order: one request
        of :meth:`select_many`."""
        return self.select_many([Request(tuple(conns), start_ns, end_ns)])[0][:5]

    def select_many(self, requests: Sequence[Request]) -> list[Selection]:
        """The messages of each request (connections, record-time window), each in its
        reference order, from one pass over the index: (chunk indices touched, chunk index per
        message, conn rank per message, record time per message, record offset per message).

        Only chunks whose span overlaps a request's window and that hold one of the requested
        connections are read.
        """
        if self.layout.indexed:
            # A chunk info naming a connection the bag does not have is damaged: the chunk
            # would silently drop out of the plan of the connection it really holds.
            known = {c.id for c in self.layout.conns}
            unknown = sorted({cid for ch in self.layout.chunks for cid in ch.counts} - known)
            if unknown:
                self._rescan(f"chunk info names connection {unknown[0]}, which the bag lacks")
        wanted = {c.id for r in requests for c in r.conns}
        start_ns, end_ns = window(requests)
        raw: dict[int, list[bytes | memoryview | tuple[I64, I64]]] = {cid: [] for cid in wanted}
        where: dict[int, list[tuple[int, int]]] = {cid: [] for cid in wanted}
        # the entries are sliced out of the mapped file, and copied once, joined per connection
        indexed = any(c.entries is None for c in self.layout.chunks)
        view = memoryview(self._mapped()) if indexed else None
        try:
            damage = self._gather_entries(start_ns, end_ns, wanted, raw, where, view)
            if damage is None:
                entries, damage = connection_entries(raw, where, self.layout)
        finally:
            raw.clear()  # (the slices of the map, before it is closed)
            if view is not None:
                view.release()
            self._unmap()  # the index pages touched would otherwise stay in this process's RSS
        if damage is not None:
            self._rescan(damage)
            return self.select_many(requests)
        return [ordered(r, entries) for r in requests]

    def _gather_entries(
        self,
        start_ns: int | None,
        end_ns: int | None,
        wanted: set[int],
        raw: dict[int, list[bytes | memoryview | tuple[I64, I64]]],
        where: dict[int, list[tuple[int, int]]],
        view: memoryview | None,
    ) -> str | None:
        """Each wanted connection's raw entries into ``raw`` (and (chunk, count) of each into
        ``where``) from the chunks overlapping [start_ns, end_ns]; why the index is damaged,
        or None."""
        for ci, chunk in enumerate(self.layout.chunks):
            if start_ns is not None and chunk.end_ns < start_ns:
                continue
            if end_ns is not None and chunk.start_ns > end_ns:
                continue
            if chunk.entries is not None:  # a scanned bag: entries already decoded
                for cid, entry in chunk.entries.items():
                    if cid in wanted:
                        raw[cid].append(entry)
                        where[cid].append((ci, len(entry[0])))
                continue
            # Every chunk's index-data headers are read, the planned chunks' and the others':
            # their connection ids and counts must be the chunk info's, which chose the chunks
            # (a damaged connection id or count there dropped a chunk from its connection's
            # read, or read another connection's entries, without a word).
            counts: dict[int, int] = {}
            for cid, data in self._index_data(chunk, wanted, counts, view).items():
                raw[cid].append(data)
                where[cid].append((ci, len(data) // INDEX_DTYPE.itemsize))
            if nonzero_counts(counts) != nonzero_counts(chunk.counts):
                return (
                    f"chunk at byte {chunk.pos}: the chunk info and the index data give "
                    "different connections or counts"
                )
        return None

    def _rescan(self, why: str) -> None:
        """Distrust the index from now on: rebuild the layout from the records themselves."""
        log.warning(
            "%s: %s; reading by scanning every record instead of through the index "
            "(`ertools info --check` lists every disagreement; `rosbag reindex` on a copy "
            "repairs the index)",
            self.path,
            why,
        )
        from ertools.io.ros1.check import rebuild_layout  # lazy: 1.5 ms, damaged bags only

        self._unmap()
        layout = rebuild_layout(self.file, self.path, self.layout.size, _first_record(self), why)
        damage = [p for p in layout.problems if p != why]
        if damage:
            # A closed bag (it has an index) whose records do not all read is damaged, not cut
            # short: reading around a skipped chunk would give fewer messages without a word.
            raise BagError(f"damaged bag: {why}, and {damage[0]}", path=self.path)
        self.layout = layout

    def spans(self, buf: U8, offsets: I64, where: str) -> tuple[I64, I64]:
        """(data start, data length) of the message records at ``offsets`` of a chunk.

        Vectorised for the standard 38-byte message header (conn, op, time fields in any
        order), checking its op field; other records (a connection record before the message,
        odd header layouts) are resolved one by one.
        """

        n = len(buf)
        if len(offsets) == 0:
            return offsets.copy(), offsets.copy()
        if offsets.min() < 0 or offsets.max() + 8 > n:
            raise BagError(f"index points outside its chunk {where}")
        fast = _standard_spans(buf, offsets)
        if fast is not None:
            return fast
        hlen = read_at(buf, offsets, np.dtype("<u4")).astype(np.int64)
        dpos = offsets + 8 + hlen
        ok = (hlen == MSG_HEADER_LEN) & (dpos <= n)
        if ok.any():
            head = offsets[ok] + 4
            # The op field (len 4, "op=", 0x02: one 8-byte word) sits after 0, 1 or 2 of the
            # other fields (conn: 13 bytes, time: 17 bytes). A writer puts it at the same place
            # in every record: look there first, elsewhere only for records that differ.
            try:
                first = next(
                    (at for at in OP_AT if op_word(buf, head[:1] + at)[0] == OP_MSG_WORD), 0
                )
                is_msg = op_word(buf, head + first) == OP_MSG_WORD
                for at in OP_AT:
                    rest = np.flatnonzero(~is_msg)
                    if at == first or not len(rest):
                        continue
                    is_msg[rest] = op_word(buf, head[rest] + at) == OP_MSG_WORD
            except LayoutMismatchError as err:
                raise BagError(f"message record cut off inside its chunk {where}") from err
            ok[np.flatnonzero(ok)[~is_msg]] = False
        dlen = np.zeros(len(offsets), dtype=np.int64)
        if ok.any():
            dlen[ok] = read_at(buf, dpos[ok] - 4, np.dtype("<u4"))
        odd = np.flatnonzero(~ok)
        if len(odd):
            raw = buf.tobytes()
            for i in odd:
                dpos[i], dlen[i] = self._resolve(raw, int(offsets[i]), where)
        if (dpos + dlen).max() > n:
            raise BagError(f"message data cut off inside its chunk {where}")
        return dpos, dlen

    def checked_spans(
        self, buf: U8, offsets: I64, t_ns: I64, conn: I64, where: str
    ) -> tuple[I64, I64]:
        """:meth:`spans`, each record also checked to carry the time and connection of its
        index entry (:meth:`check_heads`). Records with the standard 38-byte header laid out
        as the first one's (a writer's usual output) are read with one gather of their
        heads, every field a strided column of it."""
        n = len(offsets)
        head = 4 + MSG_HEADER_LEN + 4  # header length, header, data length
        fields = None
        if n and int(offsets.min()) >= 0 and int(offsets.max()) + head <= len(buf):
            fields = value_offsets(buf, int(offsets[0]) + 4)
        op_at = None
        if fields is not None:
            first = bytes(buf[int(offsets[0]) + 4 : int(offsets[0]) + 4 + MSG_HEADER_LEN])
            op_at = next(
                (at for at in OP_AT if first[at : at + 8] == OP_MSG_WORD.to_bytes(8, "little")),
                None,
            )
        if fields is None or op_at is None:
            start, length = self.spans(buf, offsets, where)
            self.check_heads(buf, start, t_ns, conn, where)
            return start, length

        rows = gather(buf, offsets, head)

        def col(offset: int, kind: str) -> npt.NDArray[Any]:
            return np.ndarray((n,), kind, buffer=rows, offset=offset, strides=(head,))

        conn_at, time_at = fields
        standard = (col(0, "<u4") == MSG_HEADER_LEN) & (col(4 + op_at, "<u8") == OP_MSG_WORD)
        if not bool(standard.all()):
            start, length = self.spans(buf, offsets, where)
            self.check_heads(buf, start, t_ns, conn, where)
            return start, length
        start = offsets + head
        length = col(head - 4, "<u4").astype(np.int64)
        if int((start + length).max()) > len(buf):
            raise BagError(f"message data cut off inside its chunk {where}")
        got_t = np.multiply(col(4 + time_at, "<u4"), 1_000_000_000, dtype=np.int64)
        got_t += col(4 + time_at + 4, "<u4")
        bad = got_t != t_ns
        bad |= col(4 + conn_at, "<u4") != conn
        if bool(bad.any()):
            idx = np.flatnonzero(bad)
            self.check_heads(buf, start[idx], t_ns[idx], conn[idx], where)
        return start, length

    @staticmethod
    def check_heads(buf: U8, start: I64, t_ns: I64, conn: I64, where: str) -> None:
        """Each message record (data at ``start``) carries the time and connection of the
        index entry it was found by, as rosbags asserts: a damaged index entry, or a damaged
        record header, would otherwise give a pose at a wrong time or on a wrong topic.

        The record header is the 38 bytes before each data length; the first record tells
        where its conn and time values sit, every record is read there at once, and only a
        record that disagrees is parsed field by field (a writer may order fields otherwise).
        """

        n = len(start)
        if not n:
            return
        head_at = start - 4 - MSG_HEADER_LEN
        at = value_offsets(buf, int(head_at[0]))
        bad = np.ones(n, dtype=bool)
        if at is not None and int(head_at.min()) >= 0:
            # one gather of the stretch holding both values, read as strided columns
            conn_at, time_at = at
            a = min(conn_at, time_at)
            width = max(conn_at + 4, time_at + 8) - a
            rows = gather(buf, head_at + a, width)

            def col(offset: int) -> npt.NDArray[np.uint32]:
                return np.ndarray((n,), "<u4", buffer=rows, offset=offset - a, strides=(width,))

            got_t = np.multiply(col(time_at), 1_000_000_000, dtype=np.int64)
            got_t += col(time_at + 4)
            bad = got_t != t_ns
            bad |= col(conn_at) != conn
        for i in np.flatnonzero(bad).tolist():
            # the header just before this record's data length, whatever its layout
            found = fields_before(buf, int(start[i]))
            if found is None or found != (int(conn[i]), int(t_ns[i])):
                raise BagError(
                    "message record's connection or time differs from its index entry "
                    f"(damaged index or record) {where}"
                )

    @staticmethod
    def _resolve(buf: bytes, off: int, where: str) -> tuple[int, int]:
        pos = off
        while True:
            if pos + 4 > len(buf):
                raise BagError(f"message record cut off inside its chunk {where}")
            hlen = int.from_bytes(buf[pos : pos + 4], "little")
            try:
                fields = parse_fields(buf[pos + 4 : pos + 4 + hlen], pos + 4)
            except RecordError as err:
                raise BagError(f"damaged message record in chunk {where} ({err})") from err
            dlen = int.from_bytes(buf[pos + 4 + hlen : pos + 8 + hlen], "little")
            op = fields.get("op", b"\x00")[0]
            if op == OP_MSG:
                return pos + 8 + hlen, dlen
            if op != OP_CONNECTION:
                raise BagError(f"index points at a record of op {op}, not a message, {where}")
            pos = pos + 8 + hlen + dlen

    def raw(
        self, conns: Sequence[Conn], start_ns: int | None = None, end_ns: int | None = None
    ) -> Iterator[RawRecord]:
        """Raw messages in the reference order, located in bulk (chunks read a few at a time;
        the requested messages' bytes are held until yielded in order)."""
        if not conns:
            return
        request = Request(tuple(conns), start_ns, end_ns)
        by_id = {c.id: c for c in conns}
        out: list[tuple[int, int, int, bytes]] = []
        for run in ros1_runs(self, [request], current()).only(0).runs:
            start, length = run.spans()
            data = run.buf.tobytes()
            out.extend(
                (p, t, c, data[a : a + n])
                for p, t, c, a, n in zip(
                    run.pos.tolist(),
                    run.t_record.tolist(),
                    run.conn.tolist(),
                    start.tolist(),
                    length.tolist(),
                    strict=True,
                )
            )
        out.sort(key=lambda x: x[0])
        for _p, t, c, data in out:
            yield by_id[c], t, data

    def verify(self, progress: Reporter | None = None) -> None:
        """Decompress every chunk and check that every indexed record is a message record
        (the chunks' bytes reported to ``progress``).

        Raises:
            BagError: the first damaged chunk, with its byte offset.
        """
        if progress is not None:
            total = sum(max(c.data_len, 0) for c in self.layout.chunks)
            progress.task(f"checking {self.path.name}", total, "B")
        for chunk in self.layout.chunks:
            where = self._where(chunk)
            buf = np.frombuffer(self.chunk_bytes(chunk), dtype=np.uint8)
            if progress is not None:
                progress.advance(max(chunk.data_len, 0))
            for cid, (_t, off) in self.chunk_entries(chunk).items():
                try:
                    self.spans(buf, off, where)
                except BagError as err:
                    raise BagError(
                        f"corrupt chunk at byte {chunk.pos}: connection {cid}: {err.message}",
                        path=self.path,
                    ) from err
