"""Follow an MCAP file while it is written: read only the records completed since last time.

An MCAP file is a sequence of records (opcode u8, length u64, content). A recorder appends whole
chunks, so the bytes after the last complete record are a record still being written (or, after
a crash, one that never will be). :class:`McapTail` remembers the offset of the first record it
has not read yet and, on each :meth:`McapTail.poll`, parses the complete records after it: the
monitor reads the growth of an hour-long file at the cost of the new bytes only. The same walk
reads a file cut short up to its last complete chunk (:func:`read_complete`).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field
from pathlib import Path

from ertools.errors import BagError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.inputs import open_regular
from ertools.io.inflate import inflate

MAGIC = b"\x89MCAP0\r\n"
_RECORD_HEAD = struct.Struct("<BQ")
OP_FOOTER = 0x02
OP_CHANNEL = 0x04
OP_MESSAGE = 0x05
OP_CHUNK = 0x06
# A record longer than this is corruption, not data (the recorder's chunks are ~256 KiB).
MAX_RECORD = 1 << 31


def is_finished(path: Path) -> bool:
    """True when the file ends with MCAP's closing magic (closed cleanly)."""
    try:
        with open_regular(path) as f:
            f.seek(0, 2)
            if f.tell() < 2 * len(MAGIC):
                return False
            f.seek(-len(MAGIC), 2)
            return f.read(len(MAGIC)) == MAGIC
    except OSError:
        return False


@frozen_dataclass
class TailMessage:
    topic: str
    log_time_ns: int
    data: bytes


_U16 = struct.Struct("<H")
_U32 = struct.Struct("<I")
_U64 = struct.Struct("<Q")
_CHUNK_HEAD = struct.Struct("<QQQI")  # start time, end time, uncompressed size, crc
_MESSAGE_HEAD = struct.Struct("<HIQQ")  # channel id, sequence, log time, publish time


def _decompress(compression: str, data: bytes, size: int, where: str) -> bytes:
    # the one bounded decompressor of every reader (the budget of docs/io.md)
    out: bytes = inflate(compression, data, size, where, "MCAP chunk")
    return out


@dataclass
class McapTail:
    """Incremental reader of one MCAP file (see the module doc).

    Records are walked with ``struct`` directly: a monitor that starts next to an hour-long
    file reads its hundreds of thousands of messages once, and building an object per message
    (what ``mcap``'s readers do) would take many seconds.
    """

    path: Path
    offset: int = 0
    channels: dict[int, str] = field(default_factory=dict)
    finished: bool = False
    corrupt: str = ""

    def poll(self, *, keep_data: bool = False, window_ns: int | None = None) -> list[TailMessage]:
        """Messages of the records completed since the last poll.

        Args:
            keep_data: keep each message's serialized data (else ``b""``).
            window_ns: only return messages within this much log time of the newest chunk
                among the new records (the monitor's rate window); channels are always read.
        """
        out: list[TailMessage] = []
        if self.finished or self.corrupt:
            return out
        try:
            with open_regular(self.path) as f:
                f.seek(self.offset)
                data = f.read()
        except OSError:
            return out  # removed or renamed meanwhile: nothing new to read
        pos = 0
        if self.offset == 0:
            if len(data) < len(MAGIC):
                return out
            if data[: len(MAGIC)] != MAGIC:
                self.corrupt = "not an MCAP file (bad magic)"
                return out
            pos = len(MAGIC)
        # Pass 1: complete records only, and the newest chunk end time among them.
        spans: list[tuple[int, int, int]] = []
        newest = 0
        while pos + _RECORD_HEAD.size <= len(data):
            opcode, length = _RECORD_HEAD.unpack_from(data, pos)
            if length > MAX_RECORD:
                self.corrupt = f"record of {length} bytes at offset {self.offset + pos}"
                break
            body = pos + _RECORD_HEAD.size
            if body + length > len(data):
                break  # still being written (or cut short by a crash)
            if opcode == OP_CHUNK and length >= _CHUNK_HEAD.size:
                newest = max(newest, _CHUNK_HEAD.unpack_from(data, body)[1])
            spans.append((opcode, body, body + length))
            pos = body + length
            if opcode == OP_FOOTER:
                self.finished = True
                break
        cutoff = newest - window_ns if window_ns is not None else None
        # Pass 2: channels and messages.
        for opcode, body, end in spans:
            try:
                if opcode == OP_CHUNK:
                    self._chunk(data, body, cutoff, keep_data, out)
                elif opcode == OP_CHANNEL:
                    self._channel(data, body)
                elif opcode == OP_MESSAGE:
                    self._message(data, body, end, cutoff, keep_data, out)
            except (struct.error, ValueError, UnicodeDecodeError, BagError) as err:
                self.corrupt = f"unreadable record at offset {self.offset + body - 9}: {err}"
                pos = body - _RECORD_HEAD.size
                break
        self.offset += pos
        return out

    def _channel(self, data: bytes, pos: int) -> None:
        (cid,) = _U16.unpack_from(data, pos)
        (n,) = _U32.unpack_from(data, pos + 4)
        self.channels[cid] = data[pos + 8 : pos + 8 + n].decode("utf-8")

    def _message(
        self,
        data: bytes,
        pos: int,
        end: int,
        cutoff: int | None,
        keep: bool,
        out: list[TailMessage],
    ) -> None:
        cid, _seq, log_time, _pub = _MESSAGE_HEAD.unpack_from(data, pos)
        if cutoff is not None and log_time < cutoff:
            return
        topic = self.channels.get(cid, f"<channel {cid}>")
        payload = data[pos + _MESSAGE_HEAD.size : end] if keep else b""
        out.append(TailMessage(topic, int(log_time), payload))

    def _chunk(
        self, data: bytes, pos: int, cutoff: int | None, keep: bool, out: list[TailMessage]
    ) -> None:
        _start, end_time, size, _crc = _CHUNK_HEAD.unpack_from(data, pos)
        p = pos + _CHUNK_HEAD.size
        (n,) = _U32.unpack_from(data, p)
        compression = data[p + 4 : p + 4 + n].decode("utf-8")
        p += 4 + n
        (length,) = _U64.unpack_from(data, p)
        p += 8
        where = f"at offset {self.offset + pos}"
        records = _decompress(compression, data[p : p + length], size, where)
        skip_messages = cutoff is not None and end_time < cutoff
        q = 0
        while q + _RECORD_HEAD.size <= len(records):
            opcode, rlen = _RECORD_HEAD.unpack_from(records, q)
            body = q + _RECORD_HEAD.size
            if body + rlen > len(records):
                raise ValueError("record overruns its chunk")
            if opcode == OP_CHANNEL:
                self._channel(records, body)
            elif opcode == OP_MESSAGE and not skip_messages:
                self._message(records, body, body + rlen, cutoff, keep, out)
            q = body + rlen


@frozen_dataclass
class CompleteRead:
    """What :func:`read_complete` found: messages, whether the file was closed, bytes lost."""

    messages: tuple[TailMessage, ...]
    finished: bool
    complete_bytes: int
    size_bytes: int
    problem: str = ""


def read_complete(path: str | Path) -> CompleteRead:
    """Every message of the complete records of ``path`` (a file cut short included)."""
    p = Path(path)
    tail = McapTail(p)
    messages = tail.poll(keep_data=True)
    return CompleteRead(
        messages=tuple(messages),
        finished=tail.finished,
        complete_bytes=tail.offset,
        size_bytes=p.stat().st_size,
        problem=tail.corrupt,
    )
