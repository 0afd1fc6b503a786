"""The fast path: pose topics decoded chunk by chunk with :mod:`ertools.io.decode.fast`.

Per format, the messages of the requested connections are located from the file's own index
(ROS1 index-data records, MCAP message-index records, rosbag2 sqlite rows), in the same order
the reference reader yields them; only chunks that overlap the time window and hold one of
the connections are read, and one uncompressed chunk at a time is held in memory. Anything
the decoders do not handle returns None, and the caller falls back to rosbags (logged at
INFO, visible with ``-v``).
"""

from __future__ import annotations

import contextlib
import logging
from collections.abc import Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TYPE_CHECKING, Any, cast

import numpy as np
import numpy.typing as npt

from ertools.arrays import I32, I64, U8, Bool
from ertools.errors import BagError
from ertools.io import pipeline
from ertools.io.bagfile import BagFile
from ertools.io.decode.fast import FAST_TYPES, LayoutMismatchError, decode, gather, to_batch
from ertools.io.decode.posebatch import PoseBatch, concat_batches
from ertools.io.decode.uniform import (
    Layout,
    Rows,
    decoded,
    empty_rows,
    layout_of,
    same_structure,
    write_rows,
)
from ertools.io.mcap.index import McapIndex
from ertools.io.model import TF_TYPES, Conn
from ertools.io.pipeline import (
    Group,
    Located,
    LocatedMany,
    Request,
    Run,
    ascending,
    group_positions,
    joined,
    prefetched,
)
from ertools.io.ros1.layout import cat_arrays
from ertools.io.ros1.runs import chunk_group, ros1_runs
from ertools.io.rosbag2.metadata import readable_files, sqlite_rows
from ertools.progress import current

if TYPE_CHECKING:
    # the readers call this module: their classes are annotations here, never imported
    from ertools.io.files import McapFile
    from ertools.io.ros1.index import Ros1Bag
    from ertools.progress import Reporter

log = logging.getLogger("ertools.io.bulk")


class _Assembler:
    """Collects a read's decoded rows into one batch in the reference order.

    With the message count known up front (ROS1, MCAP), rows are written straight into
    preallocated arrays at their messages' reference positions (no concatenation, no sort).
    Messages decoded field by field that give other than one row (a TF message with several
    transforms) are collected apart and merged with the others at the end, as are all rows of
    a read whose count is unknown (sqlite rows of several storage files, merged by time).
    """

    def __init__(self, msgtype: str, count: int | None, times: I64 | None = None) -> None:
        self.tf = msgtype in TF_TYPES
        self.by_time = count is None
        n = 0 if count is None else count
        # the record times in the reference order, when the index gave them: not copied
        self.times_known = times is not None and len(times) == n
        self.t_record = times if times is not None and self.times_known else np.empty(n, np.int64)
        # a type without a header is timed by its record times: no array of its own
        self.headless = msgtype == "geometry_msgs/Pose2D"
        self.t_header = np.empty(0 if self.headless else n, dtype=np.int64)
        self.xyz = np.empty((n, 3))
        self.quat = np.empty((n, 4))
        # Frame codes: while every row written has the same (frame, child) pair (a logger's
        # topic), the arrays are not written (zeroed memory never touched costs no memory)
        # and the batch gets the pair broadcast; a second pair writes them out.
        self.frame_idx = np.zeros(n, dtype=np.int32)
        self.child_idx = np.zeros(n, dtype=np.int32)
        self.pair: tuple[int, int] | None = None
        self.pairs_written = False
        # which messages have their row in the arrays (only tracked for TF, which may have
        # rows elsewhere, in parts)
        self.filled = np.zeros(n if self.tf else 0, dtype=bool)
        self.frames: dict[str, int] = {"": 0}
        self.parts: list[tuple[I64, PoseBatch]] = []

    @property
    def direct(self) -> bool:
        """Whether one-row-per-message decoders write into the arrays (count known)."""
        return not self.by_time

    def code(self, name: str | None) -> int:
        return self.frames.setdefault(name or "", len(self.frames))

    def at(self, pos: I64, consecutive: bool = False) -> slice | I64:
        """The rows of messages ``pos``: a slice when consecutive and ascending (one
        connection read in order: written as a block, or decoded in place)."""
        span = len(pos) and int(pos[-1]) - int(pos[0]) == len(pos) - 1
        if span and (consecutive or ascending(pos)):
            return slice(int(pos[0]), int(pos[-1]) + 1)
        return pos

    def write(
        self,
        pos: I64,
        t_record: I64,
        lay: Layout,
        rows: U8,
        skip: int,
        consecutive: bool = False,
    ) -> None:
        """Rows in layout ``lay`` (checked) of the messages ``pos`` (``consecutive``: known to
        be a range) decoded into place."""
        if not self.direct:
            tmp = empty_rows(len(pos))
            write_rows(rows, skip, lay, tmp)
            self.parts.append((pos, to_batch(rows, decoded(lay, tmp), t_record)))
            return
        at = self.at(pos, consecutive)
        if isinstance(at, slice) and not self.headless:
            write_rows(rows, skip, lay, Rows(self.t_header[at], self.xyz[at], self.quat[at]))
        elif isinstance(at, slice):
            stamps = np.empty(len(pos), np.int64)  # (none: zeros written, unused)
            write_rows(rows, skip, lay, Rows(stamps, self.xyz[at], self.quat[at]))
        else:
            tmp = empty_rows(len(pos))
            write_rows(rows, skip, lay, tmp)
            if not self.headless:
                self.t_header[at] = tmp.t_header
            _scatter(self.xyz, at, tmp.xyz)
            _scatter(self.quat, at, tmp.quat)
        if not self.times_known:
            self.t_record[at] = t_record
        if lay.stamp is None and not self.headless:
            self.t_header[at] = t_record  # no header: timed by record time, as in to_batch
        self._codes(at, self.code(lay.frame), self.code(lay.child))
        if self.tf:
            self.filled[at] = True

    def _codes(self, at: slice | I64, frame: int | I32, child: int | I32) -> None:
        """Frame codes of rows ``at`` (see ``pair`` in ``__init__``)."""
        if not self.pairs_written:
            pair = (_single(frame), _single(child))
            if pair[0] is not None and pair[1] is not None:
                if self.pair is None:
                    self.pair = (pair[0], pair[1])
                if self.pair == pair:
                    return
            if self.pair is not None:
                self.frame_idx[...] = self.pair[0]
                self.child_idx[...] = self.pair[1]
            self.pairs_written = True
        self.frame_idx[at] = frame
        self.child_idx[at] = child

    def unfilled(self, pos: I64) -> None:
        """Messages ``pos`` have no row yet (written over afterwards, or left out)."""
        if self.tf:
            self.filled[pos] = False

    def add(self, pos: I64, batch: PoseBatch, one_each: bool) -> None:
        """Decoded rows and the reference position of the message of each row (``one_each``:
        every message has exactly one row)."""
        if not len(pos):
            return
        if not self.direct or not one_each:
            self.parts.append((pos, batch))
            return
        remap = np.array([self.code(f) for f in batch.frames], np.int32)
        at = self.at(pos)
        if not self.times_known:
            self.t_record[at] = batch.t_record
        if not self.headless:
            self.t_header[at] = batch.t_header
        self.xyz[at] = batch.xyz
        self.quat[at] = batch.quat_xyzw
        self._codes(at, remap[batch.frame_idx], remap[batch.child_idx])
        if self.tf:
            self.filled[at] = True

    def _arrays(self) -> PoseBatch:
        frame_idx, child_idx = self.frame_idx, self.child_idx
        if not self.pairs_written and self.pair is not None:
            n = len(self.t_record)
            frame_idx = np.broadcast_to(np.int32(self.pair[0]), (n,))
            child_idx = np.broadcast_to(np.int32(self.pair[1]), (n,))
        return PoseBatch(
            self.t_record,
            self.t_record if self.headless else self.t_header,
            self.xyz,
            self.quat,
            frame_idx,
            child_idx,
            tuple(self.frames),
        )

    def result(self) -> PoseBatch:
        if not self.parts:
            if self.tf and not bool(self.filled.all()):
                return self._arrays().take(np.flatnonzero(self.filled))
            return self._arrays()
        done = np.flatnonzero(self.filled) if self.tf else np.empty(0, np.int64)
        parts = [*self.parts, (done, self._arrays().take(done))] if len(done) else self.parts
        batch = concat_batches([p[1] for p in parts])
        pos = np.concatenate([p[0] for p in parts])
        if len(pos) > 1 and np.any(pos[1:] < pos[:-1]):
            batch = batch.take(np.argsort(pos, kind="stable"))
        t = batch.t_record
        if self.by_time and len(t) > 1 and np.any(t[1:] < t[:-1]):
            batch = batch.take(np.argsort(t, kind="stable"))
        return batch


def _single(codes: int | I32) -> int | None:
    """The one value of ``codes`` (every row the same), else None."""
    if isinstance(codes, int):
        return codes
    if len(codes) and bool(np.all(codes == codes[0])):
        return int(codes[0])
    return None


def _scatter(dst: npt.NDArray[np.float64], at: I64, src: npt.NDArray[np.float64]) -> None:
    """``dst[at] = src`` for (n, k) float64 rows, a row at a time rather than a value."""
    k = dst.shape[1]
    block = np.dtype((np.void, 8 * k))
    if dst.flags.c_contiguous and src.flags.c_contiguous:
        dst.view(block).reshape(len(dst))[at] = src.view(block).reshape(len(src))
    else:
        dst[at] = src


class KnownSpans:
    """Messages whose data spans are known already (sqlite rows, a scan's copied records)."""

    def __init__(self, buf: U8, start: I64, length: I64) -> None:
        self.buf, self.start, self.length = buf, start, length

    def spans(self) -> tuple[I64, I64]:
        return self.start, self.length

    def size_hint(self, i: int) -> int | None:
        return int(self.length[i])

    def rows(
        self, idx: I64 | None, size: int, conn: int, member: Bool | None = None
    ) -> tuple[U8, int] | None:
        start = self.start if idx is None else self.start[idx]
        length = self.length if idx is None else self.length[idx]
        same = length == size
        if not len(start) or not bool(np.all(same if member is None else same | ~member)):
            return None
        if int(start.min()) < 0 or int(start.max()) + size > len(self.buf):
            return None
        return gather(self.buf, start, size), 0


# Messages of one run decoded by their own layout in at most this many classes (connection,
# then data length); past it the run is decoded field by field.
MAX_CLASSES = 16


class _Decoder:
    """Decodes the runs of one read into its :class:`_Assembler`, class by class.

    A class is the messages of one connection in a run (a topic recorded by one logger has
    one frame name, so one layout): its records are gathered with one gather each (record
    head and message data), checked (the record's own head, and the bytes every message of
    the layout must share) and its stamps and poses copied out as strided columns. A class
    that does not fit (lengths that vary, other frame names, several transforms per TF
    message, a record in an unusual layout) goes the general way: checked spans, then one
    layout per data length, and field by field for what still differs.
    """

    def __init__(self, msgtype: str, cdr: bool, ids: Sequence[int], out: _Assembler) -> None:
        self.msgtype, self.cdr, self.out = msgtype, cdr, out
        self.ids = list(dict.fromkeys(ids))  # the read's connections, each once
        self.layouts: dict[tuple[int, int], Layout] = {}

    def _layout(
        self, key: tuple[int, int], rows: U8, skip: int, member: Bool | None = None, first: int = 0
    ) -> Layout | None:
        """The layout of the rows' messages (the one of ``key`` seen before, or learnt from
        row ``first``), None when some row (where ``member``) does not share it."""
        lay = self.layouts.get(key)
        if lay is not None and same_structure(rows, skip, lay, member):
            return lay
        lay = layout_of(self.msgtype, self.cdr, rows[first, skip:].tobytes())
        if lay is None or lay.size != rows.shape[1] - skip:
            return None
        if not same_structure(rows, skip, lay, member):
            return None
        self.layouts[key] = lay
        return lay

    def run(self, run: Run) -> None:
        conn = run.conn
        if not len(conn):
            return
        if int(conn[0]) == int(conn[-1]) and bool(np.all(conn == conn[0])):
            if not self.fast(run, int(conn[0]), None):
                self.general(run, np.arange(len(conn), dtype=np.int64))
            return
        if len(self.ids) > MAX_CLASSES:
            self.general(run, np.arange(len(conn), dtype=np.int64))
            return
        # one pass per connection of the read (a few), cheaper than sorting by connection
        masks = [(cid, conn == cid) for cid in self.ids]
        classes = [(cid, np.flatnonzero(m), m) for cid, m in masks if bool(m.any())]
        if sum(len(c[1]) for c in classes) != len(conn):
            self.general(run, np.arange(len(conn), dtype=np.int64))  # ids of other readers
            return
        big = max(range(len(classes)), key=lambda k: len(classes[k][1]))
        if self.out.direct and 2 * len(classes[big][1]) >= len(conn):
            # The connection of most messages (a mocap body's /tf beside a 10 Hz static
            # transform) is decoded with the rows of every message, as if all were its own,
            # so its values go out as one block; the few others are then decoded on their own
            # and overwrite their rows.
            cid, idx, member = classes[big]
            if self.fast(run, cid, None, member, int(idx[0])):
                self.out.unfilled(run.pos[~member])
                del classes[big]
        rest = []
        for cid, idx, _m in classes:
            if not self.fast(run, cid, idx):
                rest.append(idx)
        if rest:
            self.general(run, cat_arrays(rest) if len(rest) == 1 else np.sort(np.concatenate(rest)))

    def fast(
        self,
        run: Run,
        cid: int,
        idx: I64 | None,
        member: Bool | None = None,
        first: int | None = None,
    ) -> bool:
        """One class (messages ``idx`` of connection ``cid``; None: the whole run, or those
        where ``member`` is, the first at ``first``) by one gather of its records; False when
        it does not fit."""
        if first is None:
            first = 0 if idx is None else int(idx[0])
        known = self.layouts.get((cid, -1))
        got = None if known is None else run.records.rows(idx, known.size, cid, member)
        if got is None:
            # first seen, or its messages changed length (another frame name)
            size = run.records.size_hint(first)
            if size is None or (known is not None and size == known.size):
                return False
            got = run.records.rows(idx, size, cid, member)
        if got is None:
            return False
        rows, skip = got
        row = first if idx is None else 0
        found = self._layout((cid, -1), rows, skip, member, row)
        if found is None:
            return False
        pos = run.pos if idx is None else run.pos[idx]
        t_rec = run.t_record if idx is None else run.t_record[idx]
        self.out.write(pos, t_rec, found, rows, skip, idx is None and run.consecutive)
        return True

    def general(self, run: Run, idx: I64) -> None:
        """Messages ``idx`` of a run from their checked spans: one layout per data length
        where the messages share it, field by field otherwise."""
        start, length = run.spans()
        start, length = start[idx], length[idx]
        lengths = group_positions(length)
        if len(lengths) <= MAX_CLASSES:
            rest = []
            for size, sub in lengths:
                if size <= 0 or int(start[sub].min()) < 0:
                    rest.append(sub)
                    continue
                rows = gather(run.buf, start[sub], size)
                lay = self._layout((-1, size), rows, 0)
                if lay is None:
                    rest.append(sub)
                    continue
                self.out.write(run.pos[idx[sub]], run.t_record[idx[sub]], lay, rows, 0)
            if not rest:
                return
            sub = np.sort(np.concatenate(rest))
            idx, start, length = idx[sub], start[sub], length[sub]
        dec = decode(self.msgtype, self.cdr, run.buf, start, length)
        one_each = len(dec.msg_index) == len(idx) and bool(
            np.all(dec.msg_index == np.arange(len(idx)))
        )
        t_rec = run.t_record[idx]
        self.out.add(run.pos[idx][dec.msg_index], to_batch(run.buf, dec, t_rec), one_each)


def mcap_index(bag: BagFile) -> McapIndex | None:
    """The MCAP index of a standalone MCAP file or of a rosbag2-mcap directory's storage
    files (decompressed when the bag is compressed file by file), None for other formats."""
    if bag.format == "rosbag2-mcap":
        return McapIndex([f for f in readable_files(bag.path) if f.suffix == ".mcap"])
    return McapIndex.of(bag)


def _mcap_runs(
    bag: BagFile, requests: Sequence[Request], progress: Reporter | None = None
) -> LocatedMany | None:
    index = mcap_index(bag)
    if index is None:
        return None
    plans = index.plan_many(requests)
    count, load, weights = index.run_loader(plans)
    compressed = any(c.compression for plan in plans for chunks in plan.chunks for c in chunks)
    topics = list(dict.fromkeys(c.topic for r in requests for c in r.conns))
    runs = prefetched(
        count,
        load,
        parallel=compressed,
        progress=progress,
        weights=weights,
        label=f"reading {', '.join(topics) or '?'} from {bag.path.name}",
    )
    return LocatedMany([len(p.t_record) for p in plans], runs, [p.t_record for p in plans])


def _one_by_one(count: int, located: Iterator[tuple[int, Run]]) -> Iterator[list[Run | None]]:
    """Runs of several requests read one request after the other, as :class:`LocatedMany`
    gives them (the other requests None)."""
    for i, run in located:
        out: list[Run | None] = [None] * count
        out[i] = run
        yield out


def _sqlite_runs(bag: BagFile, requests: Sequence[Request]) -> LocatedMany | None:
    found = [sqlite_rows(bag.path, r.conns, r.lo, r.hi) for r in requests]
    if any(f is None for f in found):
        return None

    def runs() -> Iterator[tuple[int, Run]]:
        for i, (req, batches) in enumerate(zip(requests, found, strict=True)):
            assert batches is not None
            cid = req.conns[0].id if req.conns else 0  # rosbag2: one connection per topic
            done = 0
            for buf, start, length, t_rec in batches:
                pos = np.arange(done, done + len(start), dtype=np.int64)
                conn = np.full(len(start), cid, dtype=np.int64)
                yield i, Run(pos, buf, t_rec, conn, KnownSpans(buf, start, length))
                done += len(start)

    return LocatedMany([None] * len(requests), _one_by_one(len(requests), runs()))


def _scanned_runs(bag: BagFile, requests: Sequence[Request]) -> LocatedMany:
    """Messages of an MCAP file its indexes do not cover, read record by record: the runs
    of copied message bytes the scan gives, so the same decoders apply."""
    mcap = cast("McapFile", bag)  # only scanned MCAP files
    every = [list(mcap.scanned_runs(r.conns, r.lo, r.hi)) for r in requests]

    def runs() -> Iterator[tuple[int, Run]]:
        for i, found in enumerate(every):
            for pos, buf, start, length, t_rec, cid in found:
                yield i, Run(pos, buf, t_rec, cid, KnownSpans(buf, start, length))

    counts: list[int | None] = [sum(len(r[0]) for r in found) for found in every]
    return LocatedMany(counts, _one_by_one(len(requests), runs()))


def locate_many(
    bag: BagFile, requests: Sequence[Request], progress: Reporter | None = None
) -> LocatedMany | None:
    """The messages of each request (connections, record-time window), located in one pass
    over the file's index and loaded in one pass over the chunks any of them touches; None
    when the format has no bulk access (then the caller reads per message).

    ROS1 and MCAP reads report the bytes of each group of chunks to ``progress`` (default:
    the reporter made current by :func:`ertools.progress.reporting`, if any).

    Raises:
        LayoutMismatchError: the file lacks the index records the bulk path needs.
    """
    if progress is None:
        progress = current()
    if bag.format in ("ros1", "ros1-active"):
        return ros1_runs(cast("Ros1Bag", bag), requests, progress)
    if bag.format == "rosbag2-sqlite3":
        return _sqlite_runs(bag, requests)
    if getattr(bag, "scanned", False):
        return _scanned_runs(bag, requests)
    if bag.format in ("mcap", "rosbag2-mcap"):
        return _mcap_runs(bag, requests, progress)
    return None


def locate(
    bag: BagFile,
    conns: Sequence[Conn],
    start_ns: int | None,
    end_ns: int | None,
    progress: Reporter | None = None,
) -> Located | None:
    """The messages of ``conns`` with record time in [start_ns, end_ns]: one request of
    :func:`locate_many`."""
    found = locate_many(bag, [Request(tuple(conns), start_ns, end_ns)], progress)
    return None if found is None else found.only(0)


def load_all_chunks(bag: BagFile, progress: Reporter | None = None) -> int:
    """Uncompressed bytes of every chunk of a ROS1 or MCAP file, loaded through the same
    pipeline as a topic read but not decoded: the floor of any read of that file (what the
    benchmark compares the extraction with on compressed files). The bytes read from the
    file (compressed) are reported to ``progress`` group by group."""
    total = 0
    if bag.format in ("ros1", "ros1-active"):
        ros1 = cast("Ros1Bag", bag)
        chunks = ros1.layout.chunks
        for chunk in chunks:
            if chunk.data_pos < 0:
                ros1.chunk_record(chunk)
        step = max(
            1, pipeline.GROUP_BYTES // max(1, max((c.data_len for c in chunks), default=1) * 4)
        )
        todo = [chunks[i : i + step] for i in range(0, len(chunks), step)]

        def load(k: int, scratch: list[Any]) -> Group:
            return chunk_group(ros1, todo[k], scratch)

        weights = [sum(c.data_len for c in part) for part in todo]
        label = f"reading {bag.path.name}"
        for _buf, _base, sizes in prefetched(
            len(todo), load, progress=progress, weights=weights, label=label
        ):
            total += int(sizes.sum())
        return total
    index = mcap_index(bag)
    if index is None:
        raise BagError(f"no chunks to load in a {bag.format} file", path=bag.path)
    jobs = index.all_chunks()
    step = 4

    def load_mcap(k: int, scratch: list[Any]) -> Group:
        part = jobs[k * step : (k + 1) * step]
        return joined([index.inflated_bytes(path, chunk) for path, chunk in part], scratch)

    count = (len(jobs) + step - 1) // step
    weights = [
        sum(int(c.compressed_size) for _p, c in jobs[k * step : (k + 1) * step])
        for k in range(count)
    ]
    label = f"reading {bag.path.name}"
    for buf, _base, _sizes in prefetched(
        count, load_mcap, progress=progress, weights=weights, label=label
    ):
        total += len(buf)
    return total


def _fast_type(bag: BagFile, conns: Sequence[Conn]) -> str | None:
    """The pose type the bulk decoders read ``conns`` as, None (logged) when they do not."""
    types = {c.msgtype for c in conns}
    encodings = {c.encoding for c in conns}
    if len(types) != 1 or len(encodings) != 1 or next(iter(types)) not in FAST_TYPES:
        log.info(
            "%s: %s decoded per message by rosbags (no bulk decoder)",
            bag.path,
            ", ".join(sorted(types)),
        )
        return None
    return next(iter(types))


def try_fast_batches(bag: BagFile, requests: Sequence[Request]) -> list[PoseBatch | None]:
    """Pose rows of each request decoded in bulk, from one pass over the file; None for a
    request the fast path does not apply to (the caller reads it per message)."""
    out: list[PoseBatch | None] = [None] * len(requests)
    kinds = [_fast_type(bag, r.conns) for r in requests]
    mine = [i for i, k in enumerate(kinds) if k is not None]
    if not mine:
        return out
    try:
        found = locate_many(bag, [requests[i] for i in mine])
    except LayoutMismatchError as err:
        log.info("%s: not read in bulk (%s); decoding per message", bag.path, err)
        return out
    if found is None:
        log.info("%s: no bulk reader for %s files; decoding per message", bag.path, bag.format)
        return out
    times = found.times or [None] * len(mine)
    assemblers = [
        _Assembler(cast(str, kinds[i]), n, t)
        for i, n, t in zip(mine, found.counts, times, strict=True)
    ]
    decoders: list[_Decoder | None] = [
        _Decoder(
            cast(str, kinds[i]),
            requests[i].conns[0].encoding == "cdr",
            [c.id for c in requests[i].conns],
            a,
        )
        for i, a in zip(mine, assemblers, strict=True)
    ]
    failed: list[LayoutMismatchError | None] = [None] * len(mine)

    def decode_run(k: int, run: Run) -> None:
        dec = decoders[k]
        if dec is None or failed[k] is not None:
            return
        try:
            dec.run(run)
        except LayoutMismatchError as err:
            failed[k] = err

    # The requests of a group are decoded side by side, one per thread: NumPy releases the GIL
    # in its loops, and each request has its own decoder and result (the group's bytes are
    # only read). A group's runs are all decoded before the next group is asked for (which
    # may reuse its buffer); errors are raised in request order, as one thread would.
    threads = min(pipeline.workers(), len(mine))
    with contextlib.ExitStack() as stack:
        pool = stack.enter_context(ThreadPoolExecutor(threads)) if threads > 1 else None
        try:
            for runs in found.runs:
                todo = [(k, run) for k, run in enumerate(runs) if run is not None]
                if pool is None or len(todo) < 2:
                    for k, run in todo:
                        decode_run(k, run)
                    continue
                for future in [pool.submit(decode_run, k, run) for k, run in todo]:
                    future.result()
        except LayoutMismatchError as err:
            log.info("%s: not read in bulk (%s); decoding per message", bag.path, err)
            return out
    for k, why in enumerate(failed):
        if why is not None:
            log.info(
                "%s: %s on %s not in the standard layout (%s); decoding per message",
                bag.path,
                kinds[mine[k]],
                requests[mine[k]].conns[0].topic,
                why,
            )
            decoders[k] = None
    for k, i in enumerate(mine):
        if decoders[k] is not None:
            out[i] = assemblers[k].result()
    return out


def try_fast_batch(
    bag: BagFile, conns: Sequence[Conn], start_ns: int | None, end_ns: int | None
) -> PoseBatch | None:
    """Pose rows of ``conns`` decoded in bulk, or None when the fast path does not apply."""
    return try_fast_batches(bag, [Request(tuple(conns), start_ns, end_ns)])[0]
