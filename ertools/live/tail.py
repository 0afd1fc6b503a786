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
from io import BytesIO
from pathlib import Path

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
        with open(path, "rb") as f:
            f.seek(0, 2)
            if f.tell() < 2 * len(MAGIC):
                return False
            f.seek(-len(MAGIC), 2)
            return f.read(len(MAGIC)) == MAGIC
    except OSError:
        return False


@dataclass(frozen=True)
class TailMessage:
    topic: str
    log_time_ns: int
    data: bytes


@dataclass
class McapTail:
    """Incremental reader of one MCAP file (see the module doc)."""

    path: Path
    offset: int = 0
    channels: dict[int, str] = field(default_factory=dict)
    finished: bool = False
    corrupt: str = ""

    def poll(self, *, keep_data: bool = False) -> list[TailMessage]:
        """Messages of the records completed since the last poll (data kept on request)."""
        from mcap.data_stream import ReadDataStream
        from mcap.records import Channel, Chunk, Message
        from mcap.stream_reader import breakup_chunk

        out: list[TailMessage] = []
        if self.finished or self.corrupt:
            return out
        with open(self.path, "rb") as f:
            f.seek(self.offset)
            data = f.read()
        pos = 0
        if self.offset == 0:
            if len(data) < len(MAGIC):
                return out
            if data[: len(MAGIC)] != MAGIC:
                self.corrupt = "not an MCAP file (bad magic)"
                return out
            pos = len(MAGIC)
        while pos + _RECORD_HEAD.size <= len(data):
            opcode, length = _RECORD_HEAD.unpack_from(data, pos)
            if length > MAX_RECORD:
                self.corrupt = f"record of {length} bytes at offset {self.offset + pos}"
                break
            end = pos + _RECORD_HEAD.size + length
            if end > len(data):
                break  # still being written (or cut short by a crash)
            content = data[pos + _RECORD_HEAD.size : end]
            records: list[object] = []
            if opcode == OP_CHUNK:
                try:
                    chunk = Chunk.read(ReadDataStream(BytesIO(content)))
                    records = list(breakup_chunk(chunk))
                except Exception as err:  # a corrupt chunk: stop here, say where
                    self.corrupt = f"unreadable chunk at offset {self.offset + pos}: {err}"
                    break
            elif opcode == OP_CHANNEL:
                records = [Channel.read(ReadDataStream(BytesIO(content)))]
            elif opcode == OP_MESSAGE:
                records = [Message.read(ReadDataStream(BytesIO(content)), length)]
            elif opcode == OP_FOOTER:
                self.finished = True
            for rec in records:
                if isinstance(rec, Channel):
                    self.channels[rec.id] = rec.topic
                elif isinstance(rec, Message):
                    out.append(
                        TailMessage(
                            self.channels.get(rec.channel_id, f"<channel {rec.channel_id}>"),
                            int(rec.log_time),
                            bytes(rec.data) if keep_data else b"",
                        )
                    )
            pos = end
            if self.finished:
                break
        self.offset += pos
        return out


@dataclass(frozen=True)
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
