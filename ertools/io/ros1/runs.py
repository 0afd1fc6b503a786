"""The messages of some connections of a ROS1 bag, located through its index and loaded a
group of chunks at a time: whole chunks read (and decompressed) on worker threads, or, where
the wanted records are sparse, only the pages that hold them.

The ROS1 part of :func:`ertools.io.bulk.locate`; ``Ros1Bag.raw`` (:mod:`ertools.io.ros1.index`)
reads through it too.
"""

from __future__ import annotations

import itertools
import mmap
from collections.abc import Iterator, Sequence
from io import BufferedReader
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64, U8
from ertools.errors import BagError
from ertools.io import pipeline
from ertools.io.model import Conn
from ertools.io.pipeline import (
    Group,
    Located,
    Run,
    group_positions,
    joined,
    keep,
    pread,
    prefetched,
    read_at,
    scratch_view,
)
from ertools.io.ros1.layout import Ros1Chunk, Ros1Layout, decompress

if TYPE_CHECKING:
    from ertools.progress import Reporter


class IndexedBag(Protocol):
    """What this module reads of an open ROS1 bag (:class:`ertools.io.ros1.index.Ros1Bag`,
    which calls it: a protocol rather than that class keeps the two modules acyclic)."""

    path: Path
    layout: Ros1Layout

    @property
    def file(self) -> BufferedReader: ...

    def select(
        self, conns: Sequence[Conn], start_ns: int | None, end_ns: int | None
    ) -> tuple[list[int], I64, npt.NDArray[np.integer[Any]], I64, I64]: ...

    def checked_spans(
        self, buf: U8, offsets: I64, t_ns: I64, conn: I64, where: str
    ) -> tuple[I64, I64]: ...


def ros1_runs(
    bag: IndexedBag,
    conns: Sequence[Conn],
    lo: int | None,
    hi: int | None,
    progress: Reporter | None = None,
) -> Located:
    touched, chunk_of, rank_of, t_of, off_of = bag.select(conns, lo, hi)
    conn_of = np.array([c.id for c in conns], dtype=np.int64)[rank_of]

    groups = dict(group_positions(chunk_of))
    sparse = sparse_chunks(bag, touched, groups)

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

    def load_run(k: int, scratch: list[Any]) -> Run:
        batch = todo[k]
        chunks = [bag.layout.chunks[c] for c in batch]
        if batch[0] in sparse:
            buf, base, sizes = mapped_group(bag, chunks, scratch)
        else:
            buf, base, sizes = chunk_group(bag, chunks, scratch)
        sel = np.concatenate([groups[c] for c in batch])
        which = np.concatenate([np.full(len(groups[c]), i) for i, c in enumerate(batch)])
        where = f"in {bag.path} in chunks at bytes {chunks[0].pos}..{chunks[-1].pos}"
        offsets = off_of[sel]
        if np.any(offsets + 8 > sizes[which]):
            raise BagError(f"index points outside its chunk {where}")
        # each record checked to carry its index entry's time and connection
        start, length = bag.checked_spans(
            buf, offsets + base[which], t_of[sel], conn_of[sel], where
        )
        if np.any(start + length > base[which] + sizes[which]):
            raise BagError(f"message record runs past the end of its chunk {where}")
        return sel, buf, start, length, t_of[sel]

    compressed = any(bag.layout.chunks[ci].compression != "none" for ci in touched)
    weights = [sum(max(bag.layout.chunks[c].data_len, 0) for c in batch) for batch in todo]
    runs = prefetched(
        len(todo),
        load_run,
        parallel=compressed,
        progress=progress,
        weights=weights,
        label=f"reading {conns[0].topic if conns else '?'} from {bag.path.name}",
    )
    return Located(len(t_of), runs)


# Wanted records further apart than this on average are read in place (mapped) rather than
# with their whole chunks: a pose topic next to camera images then costs its own messages (a
# page or two each), not the images. Measured on an hour of 10 Hz poses between 16 KiB images:
# 0.09 s mapped against 0.155 s reading the chunks, page cache warm (0.58 s against 0.49 s
# cold: read-ahead favours whole chunks). Much closer together, every page holds a wanted
# record and mapping only adds page faults.
SPARSE_GAP = 12 * 1024


def sparse_chunks(bag: IndexedBag, touched: list[int], groups: dict[int, I64]) -> dict[int, int]:
    """Uncompressed chunks whose wanted records are sparse -> bytes of the pages they touch."""
    out = {}
    page = mmap.PAGESIZE
    for ci in touched:
        chunk = bag.layout.chunks[ci]
        count = len(groups[ci])
        if chunk.compression == "none" and chunk.data_len >= SPARSE_GAP * count:
            out[ci] = count * 2 * page  # a record touches one or two pages
    return out


def mapped_group(bag: IndexedBag, chunks: list[Ros1Chunk], scratch: list[Any]) -> Group:
    """Chunks read in place through a read-only map of the stretch they span: the pages
    holding wanted records are read (with the kernel's usual read-ahead), the rest never.

    The map is kept in ``scratch`` and released when that slot is next reused, so the
    process holds one group's pages, not the file's.
    """
    first = chunks[0].data_pos
    end = chunks[-1].data_pos + chunks[-1].data_len
    start = first - first % mmap.ALLOCATIONGRANULARITY
    if end > bag.layout.size:
        raise BagError(f"chunks cut off by end of file at byte {first}", path=bag.path)
    mm = mmap.mmap(bag.file.fileno(), end - start, offset=start, access=mmap.ACCESS_READ)
    keep(scratch, mm)
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
