"""MCAP message records inside a group of chunks: found from their message-index entries and
checked (the reads of :mod:`ertools.io.mcap.index`)."""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64, U8, Bool
from ertools.errors import BagError
from ertools.io.decode.fast import gather
from ertools.io.mcap.scan import MESSAGE_FIXED, OP_MESSAGE

# Op codes a chunk may hold (schema 0x03, channel 0x04, message 0x05), as a lookup table.
RECORD_STARTS = np.zeros(256, dtype=bool)
RECORD_STARTS[[3, 4, 5]] = True


# A message record's head: op code (1), record length (8), channel id (2), sequence (4), log
# time (8).
_HEAD = 1 + 8 + 2 + 4 + 8


def checked_records(buf: U8, off: I64, limit: I64, where: str) -> tuple[I64, I64, I64]:
    """(data start, data length, log time) of the message records at ``off``, each checked
    to be a message record that ends at ``limit`` (its chunk's end) or where another record a
    chunk may hold (schema, channel, message) begins: a damaged record length would give a
    message bytes that are not its own, where the mcap library loses the rest of the chunk.

    The heads are gathered once as raw bytes (one copy per record; a structured dtype
    copies field by field, 4x slower) and the fields read as strided columns of them.
    """
    n = len(off)
    if n and (int(off.min()) < 0 or int(off.max()) + _HEAD > len(buf)):
        raise BagError(f"message index points outside its chunk {where}")
    head = gather(buf, off, _HEAD)
    if np.any(head[:, 0] != OP_MESSAGE):
        raise BagError(f"message index points at a record that is no message {where}")
    rlen = np.ndarray((n,), "<u8", buffer=head, offset=1, strides=(_HEAD,)).astype(np.int64)
    start = off + 9 + MESSAGE_FIXED
    length = rlen - MESSAGE_FIXED
    end = start + length
    if len(off) and (int(length.min()) < 0 or np.any(end > limit)):
        raise BagError(f"message record cut off inside its chunk {where}")
    # the byte after each record (clipped to the buffer: a record ending at its chunk's end,
    # the buffer's last chunk included, needs no next record)
    after = buf[np.minimum(end, len(buf) - 1)]
    if not np.all(RECORD_STARTS[after] | (end == limit)):
        raise BagError(f"message record length runs into no record {where}")
    log_time = np.ndarray((n,), "<u8", buffer=head, offset=15, strides=(_HEAD,))
    return start, length, log_time.astype(np.int64)


class McapRecords:
    """The message records of one run: where each starts in the group's bytes, the end of its
    chunk, and the log time and channel its message index gives (see
    :class:`ertools.io.pipeline.Records`)."""

    def __init__(
        self, buf: U8, offsets: I64, limit: I64, t_ns: I64, channel: I64, where: str
    ) -> None:
        self.buf, self.offsets, self.limit, self.where = buf, offsets, limit, where
        self.t_ns, self.channel = t_ns, channel
        self._spans: tuple[I64, I64] | None = None

    def spans(self) -> tuple[I64, I64]:
        if self._spans is None:
            start, length, log_time = checked_records(
                self.buf, self.offsets, self.limit, self.where
            )
            # The record's own log time must be the index's: a damaged index entry would
            # otherwise give another record's data (or a wrong time) without a word.
            if np.any(log_time != self.t_ns):
                raise BagError(
                    f"message index disagrees with the message records' log times {self.where}"
                )
            self._spans = start, length
        return self._spans

    def size_hint(self, i: int) -> int | None:
        at = int(self.offsets[i])
        if at < 0 or at + 9 > len(self.buf):
            return None
        size = int.from_bytes(self.buf[at + 1 : at + 9].tobytes(), "little") - MESSAGE_FIXED
        return size if 0 <= size <= len(self.buf) else None

    def rows(
        self, idx: I64 | None, size: int, conn: int, member: Bool | None = None
    ) -> tuple[U8, int] | None:
        off = self.offsets if idx is None else self.offsets[idx]
        n = len(off)
        width = _HEAD + 8 + size  # the publish time too
        # records do not overlap: more rows than the buffer holds is no usual layout
        if not n or n * width > len(self.buf) or int(off.min()) < 0:
            return None
        if int(off.max()) + width > len(self.buf):
            return None
        end = off + width
        limit = self.limit if idx is None else self.limit[idx]
        inside = end <= limit
        if not bool(np.all(inside if member is None else inside | ~member)):
            return None
        rows = gather(self.buf, off, width)

        def col(at: int, kind: str) -> npt.NDArray[Any]:
            return np.ndarray((n,), kind, buffer=rows, offset=at, strides=(width,))

        ok = col(0, "u1") == OP_MESSAGE
        ok &= col(1, "<u8") == MESSAGE_FIXED + size
        ok &= col(9, "<u2") == conn
        ok &= col(15, "<i8") == (self.t_ns if idx is None else self.t_ns[idx])
        # as _checked_records: each record ends at its chunk's end or where another begins
        ok &= RECORD_STARTS[self.buf[np.minimum(end, len(self.buf) - 1)]] | (end == limit)
        if member is not None:
            ok |= ~member
        if not bool(ok.all()):
            return None
        return rows, width - size
