"""The messages of some connections of a ROS1 bag, located through its index and loaded a
group of chunks at a time: whole chunks read (and decompressed) on worker threads, or, where
the wanted records are sparse, only the pages that hold them.

The ROS1 part of :func:`ertools.io.bulk.locate`; ``Ros1Bag.raw`` (:mod:`ertools.io.ros1.index`)
reads through it too.
"""

from __future__ import annotations

import itertools
import mmap
import os
from collections.abc import Iterator, Sequence
from io import BufferedReader
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64, U8, Bool
from ertools.errors import BagError
from ertools.io import pipeline
from ertools.io.decode.fast import gather
from ertools.io.pipeline import (
    Group,
    LocatedMany,
    Request,
    Run,
    group_positions,
    joined,
    keep,
    pread,
    prefetched,
    read_at,
    scratch_view,
)
from ertools.io.ros1.entries import Ints, Selection, Words
from ertools.io.ros1.layout import (
    MSG_HEADER_LEN,
    OP_AT,
    OP_MSG_WORD,
    Ros1Chunk,
    Ros1Layout,
    cat_arrays,
    decompress,
    value_offsets,
)

if TYPE_CHECKING:
    from ertools.progress import Reporter


class IndexedBag(Protocol):
    """What this module reads of an open ROS1 bag (:class:`ertools.io.ros1.index.Ros1Bag`,
    which calls it: a protocol rather than that class keeps the two modules acyclic)."""

    path: Path
    layout: Ros1Layout

    @property
    def file(self) -> BufferedReader: ...

    def select_many(self, requests: Sequence[Request]) -> list[Selection]: ...

    def checked_spans(
        self, buf: U8, offsets: I64, t_ns: I64, conn: I64, where: str
    ) -> tuple[I64, I64]: ...


# A message record's head as rosbag writes it: header length, the 38-byte header (conn, op
# and time fields), data length.
HEAD = 4 + MSG_HEADER_LEN + 4


class Ros1Records:
    """The message records of one run: where each starts in the group's bytes, the chunk it
    lies in, and the time and connection its index entry gives (see :class:`Records`).

    ``cuts`` are the run positions where each chunk's messages begin, ``ends`` where each of
    those chunks ends in the buffer.
    """

    def __init__(
        self,
        bag: IndexedBag,
        buf: U8,
        offsets: I64,
        cuts: I64,
        ends: I64,
        t_ns: I64,
        conn: I64,
        where: str,
        words: Words | None = None,
    ) -> None:
        self.bag, self.buf, self.where, self.words = bag, buf, where, words
        self.offsets, self.cuts, self.ends, self.t_ns, self.conn = offsets, cuts, ends, t_ns, conn
        self._limit: I64 | None = None
        self._spans: tuple[I64, I64] | None = None
        self._head: tuple[int, int, int] | None = None
        self._head_known = False

    @property
    def limit(self) -> I64:
        """Where each message's chunk ends in the buffer."""
        if self._limit is None:
            counts = np.diff(np.append(self.cuts, len(self.offsets)))
            self._limit = np.repeat(self.ends, counts)
        return self._limit

    def spans(self) -> tuple[I64, I64]:
        if self._spans is None:
            if np.any(self.offsets + 8 > self.limit):
                raise BagError(f"index points outside its chunk {self.where}")
            # each record checked to carry its index entry's time and connection
            start, length = self.bag.checked_spans(
                self.buf, self.offsets, self.t_ns, self.conn, self.where
            )
            if np.any(start + length > self.limit):
                raise BagError(f"message record runs past the end of its chunk {self.where}")
            self._spans = start, length
        return self._spans

    def _head_fields(self) -> tuple[int, int, int] | None:
        """(op, conn value, time value) offsets in the first record's header when it is the
        standard 38-byte one, else None."""
        if not self._head_known:
            self._head_known = True
            first = int(self.offsets[0])
            if first >= 0 and first + HEAD <= len(self.buf):
                header = bytes(self.buf[first + 4 : first + 4 + MSG_HEADER_LEN])
                word = OP_MSG_WORD.to_bytes(8, "little")
                op_at = next((at for at in OP_AT if header[at : at + 8] == word), None)
                fields = value_offsets(self.buf, first + 4)
                if op_at is not None and fields is not None:
                    self._head = (op_at, *fields)
        return self._head

    def size_hint(self, i: int) -> int | None:
        at = int(self.offsets[i])
        if at < 0 or at + HEAD > len(self.buf):
            return None
        if int.from_bytes(self.buf[at : at + 4].tobytes(), "little") != MSG_HEADER_LEN:
            return None
        return int.from_bytes(self.buf[at + HEAD - 4 : at + HEAD].tobytes(), "little")

    def _inside(self, idx: I64 | None, width: int, member: Bool | None) -> bool:
        """Whether the records ``idx`` (where ``member``), ``width`` bytes each, end inside
        their chunks."""
        if idx is None and member is None:
            # one maximum per chunk, not a limit per message
            last = np.maximum.reduceat(self.offsets, self.cuts) + width
            return bool(np.all(last <= self.ends))
        off = self.offsets if idx is None else self.offsets[idx]
        limit = self.limit if idx is None else self.limit[idx]
        inside = off + width <= limit
        return bool(np.all(inside if member is None else inside | ~member))

    def rows(
        self, idx: I64 | None, size: int, conn: int, member: Bool | None = None
    ) -> tuple[U8, int] | None:
        off = self.offsets if idx is None else self.offsets[idx]
        n = len(off)
        width = HEAD + size
        # records do not overlap: more rows than the buffer holds is no usual layout (offsets
        # are never negative, and a record inside its chunk is inside the buffer; the rows
        # of other messages than ``member`` only need to be)
        if not n or n * width > len(self.buf):
            return None
        if member is not None and int(off.max()) + width > len(self.buf):
            return None
        head = self._head_fields()
        if head is None or not self._inside(idx, width, member):
            return None
        op_at, conn_at, time_at = head
        rows = gather(self.buf, off, width)

        def col(at: int, kind: str) -> npt.NDArray[Any]:
            return np.ndarray((n,), kind, buffer=rows, offset=at, strides=(width,))

        ok = col(0, "<u4") == MSG_HEADER_LEN
        ok &= col(4 + op_at, "<u8") == OP_MSG_WORD
        ok &= col(HEAD - 4, "<u4") == size
        ok &= col(4 + conn_at, "<u4") == conn
        if self.words is not None:
            # the time field's bytes against the index entry's, as stored
            ok &= col(4 + time_at, "<u8") == (self.words if idx is None else self.words[idx])
        else:
            t = np.multiply(col(4 + time_at, "<u4"), 1_000_000_000, dtype=np.int64)
            t += col(8 + time_at, "<u4")
            ok &= t == (self.t_ns if idx is None else self.t_ns[idx])
        if member is not None:
            ok |= ~member
        return (rows, HEAD) if bool(ok.all()) else None


def _label(requests: Sequence[Request], path: Path) -> str:
    topics = list(dict.fromkeys(c.topic for r in requests for c in r.conns))
    return f"reading {', '.join(topics) if topics else '?'} from {path.name}"


class _Plan:
    """One request's located messages, cut into the runs of each group of chunks."""

    def __init__(self, request: Request, sel: Selection) -> None:
        _touched, chunk_of, self.rank_of, self.t_of, self.off_of, self.words = sel
        self.ids = np.array([c.id for c in request.conns], dtype=np.int64)
        # Messages in chunk order (one connection, or several in time order over
        # time-ordered chunks: the usual case) are sliced per group, not gathered.
        self.sorted = bool(np.all(chunk_of[1:] >= chunk_of[:-1]))
        self.ranges: dict[int, tuple[int, int]] = {}
        self.counts: dict[int, int] = {}
        if not len(chunk_of):
            return
        if self.sorted:
            cuts = np.flatnonzero(chunk_of[1:] != chunk_of[:-1]) + 1
            starts = np.concatenate([[0], cuts]).astype(np.int64)
            ends = np.concatenate([cuts, [len(chunk_of)]]).astype(np.int64)
            keys = chunk_of[starts].tolist()
            self.ranges = {
                ci: (a, b) for ci, a, b in zip(keys, starts.tolist(), ends.tolist(), strict=True)
            }
            self.counts = {ci: b - a for ci, (a, b) in self.ranges.items()}
        else:
            self.groups = dict(group_positions(chunk_of.astype(np.int64)))
            self.counts = {ci: len(rows) for ci, rows in self.groups.items()}

    def _conn(self, rank: Ints) -> I64:
        """Connection ids of messages of these ranks (one connection: no per-message array)."""
        if len(self.ids) == 1:
            return np.broadcast_to(self.ids[0], rank.shape)
        return self.ids[rank.astype(np.intp)]

    def run(
        self, bag: IndexedBag, batch: list[int], buf: U8, base: I64, sizes: I64, where: str
    ) -> Run | None:
        """The run of this request's messages in the group of chunks ``batch`` (loaded into
        ``buf``, chunk i at ``base[i]``, ``sizes[i]`` bytes long)."""
        present = [i for i, c in enumerate(batch) if c in self.counts]
        if not present:
            return None
        counts = [self.counts[batch[i]] for i in present]
        sel: I64
        if self.sorted:
            a, b = self.ranges[batch[present[0]]][0], self.ranges[batch[present[-1]]][1]
            sel = np.arange(a, b, dtype=np.int64)
            rel, t, rank = self.off_of[a:b], self.t_of[a:b], self.rank_of[a:b]
            words = None if self.words is None else self.words[a:b]
        else:
            sel = cat_arrays([self.groups[batch[i]] for i in present])
            rel, t, rank = self.off_of[sel], self.t_of[sel], self.rank_of[sel]
            words = None if self.words is None else self.words[sel]
        # offsets into the buffer, one chunk's messages at a time (a few chunks per group)
        offsets = rel.astype(np.int64)
        cuts = np.zeros(len(present), dtype=np.int64)
        np.cumsum(counts[:-1], out=cuts[1:])
        for k, i in enumerate(present):
            if base[i]:
                offsets[cuts[k] : cuts[k] + counts[k]] += base[i]
        ends = base[present] + sizes[present]
        conn = self._conn(rank)
        records = Ros1Records(bag, buf, offsets, cuts, ends, t, conn, where, words)
        return Run(sel, buf, t, conn, records, consecutive=self.sorted)


def ros1_runs(
    bag: IndexedBag, requests: Sequence[Request], progress: Reporter | None = None, hold: int = 0
) -> LocatedMany:
    """The messages of each request, located in one pass over the index and loaded in one
    pass over the chunks any of them touches (each group's runs valid until ``hold + 1``
    more are asked for)."""
    sels = bag.select_many(requests)
    plans = [_Plan(req, sel) for req, sel in zip(requests, sels, strict=True)]
    per_chunk: dict[int, int] = {}
    for plan in plans:
        for ci, n in plan.counts.items():
            per_chunk[ci] = per_chunk.get(ci, 0) + n
    touched = sorted(per_chunk)
    sparse = sparse_chunks(bag, touched, per_chunk)

    def batches() -> Iterator[list[int]]:
        # Several chunks are decoded together (fewer NumPy calls per message), up to
        # pipeline.GROUP_BYTES of uncompressed data at a time so memory stays bounded; a sparse
        # chunk counts the pages its records touch, not its size.
        batch: list[int] = []
        size = 0
        for i, ci in enumerate(touched):
            if batch and (ci in sparse) != (batch[0] in sparse):
                yield batch  # sparse and dense chunks are loaded differently
                batch, size = [], 0
            batch.append(ci)
            chunk = bag.layout.chunks[ci]
            if ci in sparse:
                size += sparse[ci]
            else:
                size += max(chunk.data_len, 0) * (1 if chunk.compression == "none" else 4)
            if size >= pipeline.GROUP_BYTES or i + 1 == len(touched):
                yield batch
                batch, size = [], 0

    todo = list(batches())

    def load_runs(k: int, scratch: list[Any]) -> list[Run | None]:
        batch = todo[k]
        chunks = [bag.layout.chunks[c] for c in batch]
        if batch[0] in sparse:
            buf, base, sizes = mapped_group(bag, chunks, scratch)
        elif mappable(bag, chunks):
            buf, base, sizes = populated_group(bag, chunks, scratch)
        else:
            buf, base, sizes = chunk_group(bag, chunks, scratch)
        where = f"in {bag.path} in chunks at bytes {chunks[0].pos}..{chunks[-1].pos}"
        return [plan.run(bag, batch, buf, base, sizes, where) for plan in plans]

    compressed = any(bag.layout.chunks[ci].compression != "none" for ci in touched)
    weights = [sum(max(bag.layout.chunks[c].data_len, 0) for c in batch) for batch in todo]
    runs = prefetched(
        len(todo),
        load_runs,
        parallel=compressed,
        progress=progress,
        weights=weights,
        label=_label(requests, bag.path),
        hold=hold,
    )
    return LocatedMany([len(s[3]) for s in sels], runs, [s[3] for s in sels], len(todo))


# Wanted records further apart than this on average are read in place (mapped) rather than
# with their whole chunks: a pose topic next to camera images then costs its own messages (a
# page or two each), not the images. Measured on an hour of 10 Hz poses between 16 KiB images:
# 0.09 s mapped against 0.155 s reading the chunks, page cache warm (0.58 s against 0.49 s
# cold: read-ahead favours whole chunks). Much closer together, every page holds a wanted
# record and mapping only adds page faults.
SPARSE_GAP = 12 * 1024


def sparse_chunks(bag: IndexedBag, touched: list[int], counts: dict[int, int]) -> dict[int, int]:
    """Uncompressed chunks whose wanted records are sparse -> bytes of the pages they touch
    (``counts``: wanted records per chunk)."""
    out = {}
    page = mmap.PAGESIZE
    for ci in touched:
        chunk = bag.layout.chunks[ci]
        count = counts[ci]
        if chunk.compression == "none" and chunk.data_len >= SPARSE_GAP * count:
            out[ci] = count * 2 * page  # a record touches one or two pages
    return out


def mappable(bag: IndexedBag, chunks: list[Ros1Chunk]) -> bool:
    """Whether a dense group is read in place through a populated map rather than copied:
    uncompressed chunks in file order of a closed bag, where the system can populate a map.
    An ``.active`` file is being written (its chunks and index may change under a map): it is
    read with positional reads."""
    return (
        bool(MAP_POPULATE)
        and bag.layout.indexed
        and not bag.path.name.endswith(".active")
        and all(c.compression == "none" and c.data_pos >= 0 for c in chunks)
        and all(b.data_pos > a.data_pos for a, b in itertools.pairwise(chunks))
    )


# Linux: a map's page table filled from the page cache when it is made, in one system call
# (9 ms for the 159 MiB GT hour here, against 43 ms for copying its bytes out with `preadv`).
MAP_POPULATE: int = getattr(mmap, "MAP_POPULATE", 0)


def populated_group(bag: IndexedBag, chunks: list[Ros1Chunk], scratch: list[Any]) -> Group:
    """Dense chunks (``mappable``) read in place: the stretch they span mapped read-only and
    populated, so the decoder gathers its records straight from the page cache (no copy of
    the chunks, no fresh buffer, no page fault per page)."""
    return _mapped(bag, chunks, scratch, populate=True)


def mapped_group(bag: IndexedBag, chunks: list[Ros1Chunk], scratch: list[Any]) -> Group:
    """Chunks read in place through a read-only map of the stretch they span: the pages
    holding wanted records are read (with the kernel's usual read-ahead), the rest never."""
    return _mapped(bag, chunks, scratch, populate=False)


def _mapped(
    bag: IndexedBag, chunks: list[Ros1Chunk], scratch: list[Any], *, populate: bool
) -> Group:
    """The chunks' stretch of the file mapped read-only (``populate``: every page at once).

    The map is kept in ``scratch`` and released when that slot is next reused, so the
    process holds one group's pages, not the file's. A file shorter now than its index says
    (cut since it was opened) is refused before it is mapped; one cut while mapped is
    :mod:`ertools.io.mapguard`'s.
    """
    first = chunks[0].data_pos
    end = chunks[-1].data_pos + chunks[-1].data_len
    start = first - first % mmap.ALLOCATIONGRANULARITY
    fd = bag.file.fileno()
    if end > bag.layout.size or end > os.fstat(fd).st_size:
        raise BagError(f"chunks cut off by end of file at byte {first}", path=bag.path)
    if populate and MAP_POPULATE:
        flags = mmap.MAP_SHARED | MAP_POPULATE
        mm = mmap.mmap(fd, end - start, flags=flags, prot=mmap.PROT_READ, offset=start)
    else:
        mm = mmap.mmap(fd, end - start, offset=start, access=mmap.ACCESS_READ)
    keep(scratch, mm, bag.path)
    base = np.array([c.data_pos - start for c in chunks], dtype=np.int64)
    sizes = np.array([c.data_len for c in chunks], dtype=np.int64)
    return np.frombuffer(mm, dtype=np.uint8), base, sizes


def chunk_group(bag: IndexedBag, chunks: list[Ros1Chunk], scratch: list[Any]) -> Group:
    """(bytes, where each chunk's data starts in them, each chunk's size) of ROS1 chunks,
    loaded into ``scratch`` (runs on a loading thread: positional reads only).

    Uncompressed chunks that follow each other in the file are read with one read of the
    stretch they span (the index records between them come along, unused); others are read
    and decompressed one by one and joined.
    """
    fd = bag.file.fileno()
    if all(c.compression == "none" and c.data_pos >= 0 for c in chunks) and all(
        b.data_pos > a.data_pos for a, b in itertools.pairwise(chunks)
    ):
        first = chunks[0].data_pos
        span = chunks[-1].data_pos + chunks[-1].data_len - first
        view = scratch_view(scratch, span)
        if read_at(fd, view, first) != span:
            raise BagError(f"chunks cut off by end of file at byte {first}", path=bag.path)
        base = np.array([c.data_pos - first for c in chunks], dtype=np.int64)
        sizes = np.array([c.data_len for c in chunks], dtype=np.int64)
        return np.frombuffer(view, dtype=np.uint8), base, sizes
    parts = []
    for chunk in chunks:
        where = f"in {bag.path} at byte {chunk.pos}"
        data = pread(fd, chunk.data_len, chunk.data_pos)
        if len(data) != chunk.data_len:
            raise BagError(f"chunk at byte {chunk.pos} cut off by end of file", path=bag.path)
        parts.append(decompress(chunk.compression, data, chunk.size, where))
    return joined(parts, scratch)
