"""A read's runs decoded into pose rows, class by class (the decoding half of
:mod:`ertools.io.bulk`).

A class is one connection's messages in a run: a logger writes each topic with one frame
name, so one layout. Its records are gathered once each (record head and message data), the
heads checked by the format that located them (:class:`ertools.io.pipeline.Records`), the
message bytes against the connection's layout (:mod:`ertools.io.decode.uniform`), and stamps
and poses copied out as strided columns into the read's result arrays (:class:`Assembler`).
What does not fit goes the general way: checked spans, one layout per data length, and the
field decoder (:mod:`ertools.io.decode.fast`) for the rest.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from ertools.arrays import I32, I64, U8, Bool, fresh
from ertools.io.decode.fast import decode, gather, to_batch
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
from ertools.io.model import TF_TYPES
from ertools.io.pipeline import Run, ascending, group_positions


class Assembler:
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
        self.t_record = times if times is not None and self.times_known else fresh(n, np.int64)
        # a type without a header is timed by its record times: no array of its own
        self.headless = msgtype == "geometry_msgs/Pose2D"
        self.t_header = fresh(0 if self.headless else n, np.int64)
        self.xyz = fresh(3 * n, np.float64).reshape(n, 3)
        self.quat = fresh(4 * n, np.float64).reshape(n, 4)
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
        # Two runs of one read may be written at once (a lone request on two lanes): their
        # rows go to places of their own, the frame codes and parts they share under a lock.
        self.lock = threading.Lock()

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
            with self.lock:
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
        with self.lock:
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
            with self.lock:
                self.parts.append((pos, batch))
            return
        with self.lock:
            remap = np.array([self.code(f) for f in batch.frames], np.int32)
        at = self.at(pos)
        if not self.times_known:
            self.t_record[at] = batch.t_record
        if not self.headless:
            self.t_header[at] = batch.t_header
        self.xyz[at] = batch.xyz
        self.quat[at] = batch.quat_xyzw
        with self.lock:
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


class Decoder:
    """Decodes the runs of one read into its :class:`Assembler`, class by class.

    A class is the messages of one connection in a run (a topic recorded by one logger has
    one frame name, so one layout): its records are gathered with one gather each (record
    head and message data), checked (the record's own head, and the bytes every message of
    the layout must share) and its stamps and poses copied out as strided columns. A class
    that does not fit (lengths that vary, other frame names, several transforms per TF
    message, a record in an unusual layout) goes the general way: checked spans, then one
    layout per data length, and field by field for what still differs.
    """

    def __init__(self, msgtype: str, cdr: bool, ids: Sequence[int], out: Assembler) -> None:
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
        # (one connection's ids come broadcast from one value: nothing to compare)
        if int(conn[0]) == int(conn[-1]) and (
            conn.strides == (0,) or bool(np.all(conn == conn[0]))
        ):
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
            self.general(run, rest[0] if len(rest) == 1 else np.sort(np.concatenate(rest)))

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
