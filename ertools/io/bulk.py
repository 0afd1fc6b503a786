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

from ertools.io.fastdecode import FAST_TYPES, LayoutMismatchError, decode, to_batch
from ertools.io.files import BagFile
from ertools.io.model import Conn
from ertools.io.posebatch import PoseBatch, concat_batches

log = logging.getLogger("ertools.io.bulk")

I64 = npt.NDArray[np.int64]


def _ordered(parts: list[tuple[I64, PoseBatch]]) -> PoseBatch:
    """Join per-chunk batches and put rows back in the reference order.

    Each part carries, per row, the position of its message in the reference order; TF rows of
    one message keep their order (stable sort).
    """
    if not parts:
        return PoseBatch.empty()
    batch = concat_batches([p[1] for p in parts])
    pos = np.concatenate([p[0] for p in parts])
    if len(pos) > 1 and np.any(pos[1:] < pos[:-1]):
        batch = batch.take(np.argsort(pos, kind="stable"))
    return batch


def _ros1(
    bag: BagFile, conns: Sequence[Conn], msgtype: str, lo: int | None, hi: int | None
) -> PoseBatch:
    from ertools.io.ros1_index import Ros1Bag

    assert isinstance(bag, Ros1Bag)
    touched, chunk_of, _rank, t_of, off_of = bag.select(conns, lo, hi)
    parts = []
    for ci in touched:
        sel = np.flatnonzero(chunk_of == ci)
        chunk = bag.layout.chunks[ci]
        buf = np.frombuffer(bag.chunk_bytes(chunk), dtype=np.uint8)
        start, length = bag.spans(buf, off_of[sel], f"in {bag.path} at byte {chunk.pos}")
        dec = decode(msgtype, False, buf, start, length)
        batch = to_batch(buf, dec, t_of[sel])
        parts.append((sel[dec.msg_index], batch))
    return _ordered(parts)


def _mcap(
    bag: BagFile, conns: Sequence[Conn], msgtype: str, lo: int | None, hi: int | None
) -> PoseBatch | None:
    from ertools.io.mcap_index import McapIndex

    index = McapIndex.of(bag)
    if index is None:
        return None
    cdr = conns[0].encoding == "cdr"
    parts = []
    for sel, buf, start, length, t_rec in index.message_runs(conns, lo, hi):
        dec = decode(msgtype, cdr, buf, start, length)
        parts.append((sel[dec.msg_index], to_batch(buf, dec, t_rec)))
    return _ordered(parts)


def _sqlite(
    bag: BagFile, conns: Sequence[Conn], msgtype: str, lo: int | None, hi: int | None
) -> PoseBatch | None:
    from ertools.io.rosbag2 import sqlite_rows

    batches = sqlite_rows(bag.path, conns, lo, hi)
    if batches is None:
        return None
    parts = []
    done = 0
    for buf, start, length, t_rec in batches:
        dec = decode(msgtype, conns[0].encoding == "cdr", buf, start, length)
        parts.append((done + dec.msg_index, to_batch(buf, dec, t_rec)))
        done += len(start)
    batch = concat_batches([p[1] for p in parts])
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
