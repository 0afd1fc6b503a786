"""The fast path: pose topics decoded chunk by chunk with :mod:`ertools.io.fastdecode`.

Per format, the messages of the requested connections are located from the file's own index
(ROS1 index-data records, MCAP message-index records, rosbag2 sqlite rows), in the same order
the reference reader yields them; only chunks that overlap the time window and hold one of
the connections are read, and one uncompressed chunk at a time is held in memory. Anything
the decoders do not handle returns None, and the caller falls back to rosbags (logged at
INFO, visible with ``-v``).
"""

from __future__ import annotations

import logging
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from ertools.errors import BagError
from ertools.io.fastdecode import FAST_TYPES, Decoded, LayoutMismatchError, decode, to_batch
from ertools.io.files import BagFile
from ertools.io.model import TF_TYPES, Conn
from ertools.io.posebatch import PoseBatch, concat_batches

log = logging.getLogger("ertools.io.bulk")

# Uncompressed bytes decoded in one go (chunks are ~768 KiB): large enough that the per-call
# overhead of NumPy vanishes, small enough to keep memory bounded.
GROUP_BYTES = 4 * 1024 * 1024

I64 = npt.NDArray[np.int64]
U8 = npt.NDArray[np.uint8]


class _Assembler:
    """Collects per-chunk decoded rows into one batch in the reference order.

    Types with one pose per message are written straight into preallocated arrays at their
    reference positions (no concatenation, no sort); TF messages, which may hold several
    transforms, are collected and ordered at the end.
    """

    def __init__(self, msgtype: str, t_record: I64) -> None:
        self.t_record = t_record
        self.multi = msgtype in TF_TYPES
        n = 0 if self.multi else len(t_record)
        self.t_header = np.empty(n, dtype=np.int64)
        self.xyz = np.empty((n, 3))
        self.quat = np.empty((n, 4))
        self.frame_idx = np.zeros(n, dtype=np.int32)
        self.child_idx = np.zeros(n, dtype=np.int32)
        self.frames: dict[str, int] = {"": 0}
        self.parts: list[tuple[I64, PoseBatch]] = []

    def add(self, pos: I64, buf: U8, dec: Decoded) -> None:
        """Rows decoded from messages at reference positions ``pos``."""
        batch = to_batch(buf, dec, self.t_record[pos])
        if self.multi:
            self.parts.append((pos[dec.msg_index], batch))
            return
        remap = np.array(
            [self.frames.setdefault(f, len(self.frames)) for f in batch.frames], np.int32
        )
        self.t_header[pos] = batch.t_header
        self.xyz[pos] = batch.xyz
        self.quat[pos] = batch.quat_xyzw
        self.frame_idx[pos] = remap[batch.frame_idx]
        self.child_idx[pos] = remap[batch.child_idx]

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
        return batch


def _groups(keys: I64) -> list[tuple[int, I64]]:
    """(key, positions) for each distinct key, positions ascending (one sort, not N scans)."""
    if len(keys) == 0:
        return []
    order = np.argsort(keys, kind="stable")
    sorted_keys = keys[order]
    cuts = np.flatnonzero(sorted_keys[1:] != sorted_keys[:-1]) + 1
    starts = np.concatenate([[0], cuts])
    ends = np.concatenate([cuts, [len(keys)]])
    return [(int(sorted_keys[a]), order[a:b]) for a, b in zip(starts, ends, strict=True)]


def _ros1(
    bag: BagFile, conns: Sequence[Conn], msgtype: str, lo: int | None, hi: int | None
) -> PoseBatch:
    from ertools.io.ros1_index import Ros1Bag

    assert isinstance(bag, Ros1Bag)
    touched, chunk_of, _rank, t_of, off_of = bag.select(conns, lo, hi)
    out = _Assembler(msgtype, t_of)
    groups = dict(_groups(chunk_of))
    # Several chunks are decoded together (fewer NumPy calls per message), up to GROUP_BYTES
    # of uncompressed data at a time so memory stays bounded.
    batch: list[int] = []
    size = 0
    for i, ci in enumerate(touched):
        batch.append(ci)
        size += max(bag.layout.chunks[ci].data_len, 0) * (
            1 if bag.layout.chunks[ci].compression == "none" else 4
        )
        if size < GROUP_BYTES and i + 1 < len(touched):
            continue
        chunks = [bag.layout.chunks[c] for c in batch]
        datas = bag.chunks_bytes(chunks)
        base = np.cumsum([0] + [len(d) for d in datas])
        buf = np.frombuffer(b"".join(datas) if len(datas) > 1 else datas[0], dtype=np.uint8)
        sel = np.concatenate([groups[c] for c in batch])
        which = np.concatenate([np.full(len(groups[c]), k) for k, c in enumerate(batch)])
        where = f"in {bag.path} in chunks at bytes {chunks[0].pos}..{chunks[-1].pos}"
        offsets = off_of[sel]
        if np.any(offsets + 8 > (base[1:] - base[:-1])[which]):
            raise BagError(f"index points outside its chunk {where}")
        start, length = bag.spans(buf, offsets + base[which], where)
        if np.any(start + length > base[which + 1]):
            raise BagError(f"message record runs past the end of its chunk {where}")
        out.add(sel, buf, decode(msgtype, False, buf, start, length))
        batch, size = [], 0
    return out.result()


def _mcap(
    bag: BagFile, conns: Sequence[Conn], msgtype: str, lo: int | None, hi: int | None
) -> PoseBatch | None:
    from ertools.io.mcap_index import McapIndex

    index = McapIndex.of(bag)
    if index is None:
        return None
    cdr = conns[0].encoding == "cdr"
    plan = index.plan(conns, lo, hi)
    out = _Assembler(msgtype, plan.t_record)
    for pos, buf, start, length in index.chunks_of(plan):
        out.add(pos, buf, decode(msgtype, cdr, buf, start, length))
    return out.result()


def _sqlite(
    bag: BagFile, conns: Sequence[Conn], msgtype: str, lo: int | None, hi: int | None
) -> PoseBatch | None:
    from ertools.io.rosbag2 import sqlite_rows

    batches = sqlite_rows(bag.path, conns, lo, hi)
    if batches is None:
        return None
    parts = [
        to_batch(buf, decode(msgtype, conns[0].encoding == "cdr", buf, start, length), t_rec)
        for buf, start, length, t_rec in batches
    ]
    batch = concat_batches(parts)
    t = batch.t_record
    if len(t) > 1 and np.any(t[1:] < t[:-1]):  # several storage files: merge by time
        batch = batch.take(np.argsort(t, kind="stable"))
    return batch


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
    try:
        if bag.format in ("ros1", "ros1-active"):
            return _ros1(bag, conns, msgtype, start_ns, end_ns)
        if bag.format == "rosbag2-sqlite3":
            result = _sqlite(bag, conns, msgtype, start_ns, end_ns)
            if result is not None:
                return result
        if bag.format in ("mcap", "rosbag2-mcap"):
            result = _mcap(bag, conns, msgtype, start_ns, end_ns)
            if result is not None:
                return result
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
