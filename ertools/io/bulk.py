"""The fast path: pose topics decoded chunk by chunk with :mod:`ertools.io.decode.fast`.

Per format, the messages of the requested connections are located from the file's own index
(ROS1 index-data records, MCAP message-index records, rosbag2 sqlite rows), in the same order
the reference reader yields them; only chunks that overlap the time window and hold one of
the connections are read, and one uncompressed chunk at a time is held in memory. Anything
the decoders do not handle returns None, and the caller falls back to rosbags (logged at
INFO, visible with ``-v``).
"""

from __future__ import annotations

import logging
from collections.abc import Iterator, Sequence
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ertools.arrays import I64
from ertools.errors import BagError
from ertools.io import pipeline
from ertools.io.bagfile import BagFile
from ertools.io.decode.fast import FAST_TYPES, Decoded, LayoutMismatchError, decode, to_batch
from ertools.io.decode.posebatch import PoseBatch, concat_batches
from ertools.io.decode.uniform import Rows, decode_uniform
from ertools.io.mcap.index import McapIndex
from ertools.io.model import TF_TYPES, Conn
from ertools.io.pipeline import (
    Group,
    Located,
    Run,
    ascending,
    joined,
    prefetched,
)
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
    """Collects per-chunk decoded rows into one batch in the reference order.

    Types with one pose per message are written straight into preallocated arrays at their
    reference positions (no concatenation, no sort); TF messages, which may hold several
    transforms, are collected and ordered at the end.
    """

    def __init__(self, msgtype: str, count: int | None) -> None:
        self.multi = msgtype in TF_TYPES or count is None
        # sqlite rows of several storage files come file by file: merged by time at the end
        self.by_time = count is None
        n = 0 if self.multi or count is None else count
        self.t_record = np.empty(n, dtype=np.int64)
        self.t_header = np.empty(n, dtype=np.int64)
        self.xyz = np.empty((n, 3))
        self.quat = np.empty((n, 4))
        self.frame_idx = np.zeros(n, dtype=np.int32)
        self.child_idx = np.zeros(n, dtype=np.int32)
        self.frames: dict[str, int] = {"": 0}
        self.parts: list[tuple[I64, PoseBatch]] = []

    def run_slice(self, pos: I64) -> slice | None:
        """The rows at ``pos`` as a slice when they are consecutive and ascending (one
        connection read in order): written as a block, or decoded in place."""
        if self.multi or not len(pos):
            return None
        if int(pos[-1]) - int(pos[0]) == len(pos) - 1 and ascending(pos):
            return slice(int(pos[0]), int(pos[-1]) + 1)
        return None

    def rows(self, at: slice) -> Rows:
        """Where a decoder may write the rows ``at`` itself."""
        return Rows(self.t_header[at], self.xyz[at], self.quat[at])

    def wrote(self, at: slice, t_record: I64, dec: Decoded) -> None:
        """Rows ``at`` were decoded in place (see :meth:`rows`): their record times and
        frame names (types without a header are timed by record time, as in ``to_batch``)."""
        self.t_record[at] = t_record
        if not dec.has_header:
            self.t_header[at] = t_record
        self.frame_idx[at] = self.frames.setdefault(dec.frame_text or "", len(self.frames))
        self.child_idx[at] = self.frames.setdefault(dec.child_text or "", len(self.frames))

    def add(self, pos: I64, batch: PoseBatch) -> None:
        """Decoded rows and the reference position of the message of each row."""
        if self.multi:
            self.parts.append((pos, batch))
            return
        remap = np.array(
            [self.frames.setdefault(f, len(self.frames)) for f in batch.frames], np.int32
        )
        run = self.run_slice(pos)
        # consecutive rows are written as a block (a copy, not a scatter)
        at: slice | I64 = run if run is not None else pos
        self.t_record[at] = batch.t_record
        self.t_header[at] = batch.t_header
        self.xyz[at] = batch.xyz
        self.quat[at] = batch.quat_xyzw
        self.frame_idx[at] = remap[batch.frame_idx]
        self.child_idx[at] = remap[batch.child_idx]

    def result(self) -> PoseBatch:
        if not self.multi:
            return PoseBatch(
                self.t_record,
                self.t_header,
                self.xyz,
                self.quat,
                self.frame_idx,
                self.child_idx,
                tuple(self.frames),
            )
        if not self.parts:
            return PoseBatch.empty()
        batch = concat_batches([p[1] for p in self.parts])
        pos = np.concatenate([p[0] for p in self.parts])
        if len(pos) > 1 and np.any(pos[1:] < pos[:-1]):
            batch = batch.take(np.argsort(pos, kind="stable"))
        t = batch.t_record
        if self.by_time and len(t) > 1 and np.any(t[1:] < t[:-1]):
            batch = batch.take(np.argsort(t, kind="stable"))
        return batch


def mcap_index(bag: BagFile) -> McapIndex | None:
    """The MCAP index of a standalone MCAP file or of a rosbag2-mcap directory's storage
    files (decompressed when the bag is compressed file by file), None for other formats."""
    if bag.format == "rosbag2-mcap":
        return McapIndex([f for f in readable_files(bag.path) if f.suffix == ".mcap"])
    return McapIndex.of(bag)


def _label(bag: BagFile, conns: Sequence[Conn]) -> str:
    topic = conns[0].topic if conns else "?"
    return f"reading {topic} from {bag.path.name}"


def _mcap_runs(
    bag: BagFile,
    conns: Sequence[Conn],
    lo: int | None,
    hi: int | None,
    progress: Reporter | None = None,
) -> Located | None:
    index = mcap_index(bag)
    if index is None:
        return None
    plan = index.plan(conns, lo, hi)
    count, load, weights = index.run_loader(plan)
    compressed = any(c.compression for chunks in plan.chunks for c in chunks)

    def load_run(k: int, scratch: list[Any]) -> Run:
        pos, buf, start, length = load(k, scratch)
        return pos, buf, start, length, plan.t_record[pos]

    runs = prefetched(
        count,
        load_run,
        parallel=compressed,
        progress=progress,
        weights=weights,
        label=_label(bag, conns),
    )
    return Located(len(plan.t_record), runs)


def _sqlite_runs(
    bag: BagFile, conns: Sequence[Conn], lo: int | None, hi: int | None
) -> Located | None:
    batches = sqlite_rows(bag.path, conns, lo, hi)
    if batches is None:
        return None

    def runs() -> Iterator[Run]:
        done = 0
        for buf, start, length, t_rec in batches:
            yield np.arange(done, done + len(start), dtype=np.int64), buf, start, length, t_rec
            done += len(start)

    return Located(None, runs())


def _scanned_runs(bag: BagFile, conns: Sequence[Conn], lo: int | None, hi: int | None) -> Located:
    """Messages of an MCAP file its indexes do not cover, read record by record: the runs
    of copied message bytes the scan gives, so the same decoders apply."""
    runs = list(cast("McapFile", bag).scanned_runs(conns, lo, hi))  # only scanned MCAP files
    count = sum(len(r[0]) for r in runs)
    return Located(count, iter([r[:5] for r in runs]))


def locate(
    bag: BagFile,
    conns: Sequence[Conn],
    start_ns: int | None,
    end_ns: int | None,
    progress: Reporter | None = None,
) -> Located | None:
    """The messages of ``conns`` with record time in [start_ns, end_ns], or None when the
    format has no bulk access (then the caller reads per message).

    ROS1 and MCAP reads report the bytes of each group of chunks to ``progress`` (default:
    the reporter made current by :func:`ertools.progress.reporting`, if any).

    Raises:
        LayoutMismatchError: the file lacks the index records the bulk path needs.
    """
    if progress is None:
        progress = current()
    if bag.format in ("ros1", "ros1-active"):
        return ros1_runs(cast("Ros1Bag", bag), conns, start_ns, end_ns, progress)
    if bag.format == "rosbag2-sqlite3":
        return _sqlite_runs(bag, conns, start_ns, end_ns)
    if getattr(bag, "scanned", False):
        return _scanned_runs(bag, conns, start_ns, end_ns)
    if bag.format in ("mcap", "rosbag2-mcap"):
        return _mcap_runs(bag, conns, start_ns, end_ns, progress)
    return None


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


def try_fast_batch(
    bag: BagFile, conns: Sequence[Conn], start_ns: int | None, end_ns: int | None
) -> PoseBatch | None:
    """Pose rows of ``conns`` decoded in bulk, or None when the fast path does not apply."""
    types = {c.msgtype for c in conns}
    encodings = {c.encoding for c in conns}
    if len(types) != 1 or len(encodings) != 1 or next(iter(types)) not in FAST_TYPES:
        log.info(
            "%s: %s decoded per message by rosbags (no bulk decoder)",
            bag.path,
            ", ".join(sorted(types)),
        )
        return None
    msgtype = next(iter(types))
    cdr = conns[0].encoding == "cdr"
    try:
        found = locate(bag, conns, start_ns, end_ns)
        if found is not None:
            # Decoded here, not on the loading threads: its many small NumPy calls hold the
            # GIL, and two threads decoding were slower than one (measured).
            out = _Assembler(msgtype, found.count)
            for pos, buf, start, length, t_rec in found.runs:
                # The usual case, consecutive rows: decoded straight into the result.
                at = out.run_slice(pos)
                into = out.rows(at) if at is not None else None
                dec = decode_uniform(msgtype, cdr, buf, start, length, into=into)
                if dec is not None and at is not None:
                    out.wrote(at, t_rec, dec)
                    continue
                if dec is None:
                    dec = decode(msgtype, cdr, buf, start, length)
                out.add(pos[dec.msg_index], to_batch(buf, dec, t_rec))
            return out.result()
    except LayoutMismatchError as err:
        log.info(
            "%s: %s on %s not in the standard layout (%s); decoding per message",
            bag.path,
            msgtype,
            conns[0].topic,
            err,
        )
        return None
    log.info("%s: no bulk reader for %s files; decoding per message", bag.path, bag.format)
    return None
