"""One open bag file of any format: its connections and its raw messages in record-time order.

This is the general (per-message) path. The bulk NumPy decoders in :mod:`ertools.io.fastdecode`
read the same files through :mod:`ertools.io.ros1_index` and :mod:`ertools.io.mcap_index`; this
module is the reference they are tested against and the fallback for every other type.

Order of messages (the reference order): by record time; ties keep the order of the
connections as listed by the file, then file order (rosbags' heap merge for ROS1 and rosbag2;
the ``mcap`` library's (log time, chunk, position) order for MCAP).
"""

from __future__ import annotations

import logging
from collections.abc import Iterator, Sequence
from contextlib import AbstractContextManager
from pathlib import Path
from types import TracebackType
from typing import Any

from ertools.errors import BagError
from ertools.io.formats import detect_format
from ertools.io.model import Conn, short_msgtype

log = logging.getLogger("ertools.io.files")

RawRecord = tuple[Conn, int, bytes]

INT64_MAX = (1 << 63) - 1


class BagFile(AbstractContextManager["BagFile"]):
    """An open bag: ``connections`` and :meth:`raw` messages. Use as a context manager."""

    path: Path
    format: str
    connections: tuple[Conn, ...]

    def raw(
        self, conns: Sequence[Conn], start_ns: int | None = None, end_ns: int | None = None
    ) -> Iterator[RawRecord]:
        """(conn, record time ns, raw bytes) of ``conns`` in [start_ns, end_ns], time-ordered."""
        raise NotImplementedError

    def close(self) -> None:
        """Release the file."""

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def topic_conns(self, topic: str) -> list[Conn]:
        """The connections of one topic, in file order."""
        return [c for c in self.connections if c.topic == topic]


def _conn_from_rosbags(c: Any) -> Conn:
    from rosbags.interfaces import ConnectionExtRosbag1, MessageDefinitionFormat

    fmt = {MessageDefinitionFormat.MSG: "msg", MessageDefinitionFormat.IDL: "idl"}.get(
        c.msgdef.format, ""
    )
    if isinstance(c.ext, ConnectionExtRosbag1):
        encoding = "ros1"
        latching = bool(c.ext.latching)
    else:
        encoding = "ros1" if c.ext.serialization_format == "ros1" else "cdr"
        latching = any(
            getattr(q.durability, "name", "") == "TRANSIENT_LOCAL"
            for q in c.ext.offered_qos_profiles
        )
    return Conn(
        int(c.id),
        str(c.topic),
        short_msgtype(str(c.msgtype)),
        str(c.msgdef.data),
        fmt,
        encoding,
        latching,
        str(c.digest),
    )


class RosbagsFile(BagFile):
    """ROS1 and rosbag2 through rosbags' readers (builds rosbags' per-message index)."""

    def __init__(self, path: Path, fmt: str) -> None:
        self.path = path
        self.format = fmt
        try:
            if fmt == "ros1":
                from rosbags.rosbag1 import Reader as Reader1

                self._reader: Any = Reader1(path)
            else:
                from rosbags.rosbag2 import Reader as Reader2

                self._reader = Reader2(path)
            self._reader.open()
        except Exception as err:
            # rosbags raises assorted errors (ReaderError, struct.error, AssertionError...) on
            # damaged files; all of them mean the same thing to a user.
            raise BagError(
                f"unreadable {fmt} bag ({type(err).__name__}: {err})", path=path
            ) from err
        self._rb_conns = {int(c.id): c for c in self._reader.connections}
        self.connections = tuple(_conn_from_rosbags(c) for c in self._reader.connections)

    def raw(
        self, conns: Sequence[Conn], start_ns: int | None = None, end_ns: int | None = None
    ) -> Iterator[RawRecord]:
        if not conns:
            return
        by_id = {c.id: c for c in conns}
        rb = [self._rb_conns[c.id] for c in conns]
        stop = None if end_ns is None else end_ns + 1
        try:
            for c, t, data in self._reader.messages(connections=rb, start=start_ns, stop=stop):
                yield by_id[int(c.id)], int(t), bytes(data)
        except Exception as err:
            raise BagError(
                f"damaged message data ({type(err).__name__}: {err})", path=self.path
            ) from err

    def close(self) -> None:
        if self._reader is not None:
            self._reader.close()
            self._reader = None


def _conn_from_channel(channel: Any, schema: Any) -> Conn:
    name = schema.name if schema is not None else ""
    enc = schema.encoding if schema is not None else ""
    data = schema.data.decode("utf-8", "replace") if schema is not None else ""
    return Conn(
        int(channel.id),
        channel.topic,
        short_msgtype(name),
        data,
        "idl" if enc == "ros2idl" else ("msg" if data else ""),
        "ros1" if channel.message_encoding == "ros1" else "cdr",
        "transient_local" in channel.metadata.get("offered_qos_profiles", ""),
        "",
    )


# What the mcap library raises on damaged or cut-short files.
def mcap_errors() -> tuple[type[BaseException], ...]:
    import struct

    import zstandard
    from mcap.exceptions import McapError

    # lz4 raises RuntimeError on corrupt chunks, zstandard its own ZstdError (found by
    # fuzzing: it escaped as a traceback); absurd record lengths can MemoryError.
    return (
        McapError,
        ValueError,
        EOFError,
        OSError,
        struct.error,
        KeyError,
        RuntimeError,
        MemoryError,
        OverflowError,  # a length near 2**64 handed to read() or a buffer
        zstandard.ZstdError,
    )


class McapFile(BagFile):
    """A standalone MCAP file (ROS 2 ``cdr`` or ``ros1`` message encoding) via ``mcap``.

    A file without a summary section (a recorder that was killed, a file cut short) is read
    as far as its records are complete, like a ROS1 ``.bag.active``: ``unfinished`` is True
    and a warning says so.
    """

    def __init__(self, path: Path) -> None:
        from mcap.reader import make_reader

        self.path = path
        self.format = "mcap"
        self.unfinished = False
        self._scanned: list[tuple[int, int, int, bytes]] = []  # log time, position, channel, data
        self._f = path.open("rb")
        from ertools.io.mcap_index import read_summary

        unreadable: tuple[type[BaseException], ...] = (BagError, *mcap_errors())
        try:
            self._reader = make_reader(self._f)
            summary = read_summary(self._f, path)  # parsed once, reused by the bulk reader
        except unreadable:
            summary = None
        if summary is None:
            self.connections = self._scan()
            return
        self.connections = tuple(
            _conn_from_channel(
                summary.channels[cid], summary.schemas.get(summary.channels[cid].schema_id)
            )
            for cid in sorted(summary.channels)
        )

    def _scan(self) -> tuple[Conn, ...]:
        """Read every complete record of an unfinished file (no summary to seek with)."""
        from mcap.records import Channel, Message, Schema
        from mcap.stream_reader import CRCValidationError, StreamReader

        self.unfinished = True
        schemas: dict[int, Any] = {}
        conns: dict[int, Conn] = {}
        self._f.seek(0)
        # CRCs checked: lz4 and zstd chunks inflate damaged bytes without an error of their own
        reader = StreamReader(self._f, skip_magic=False, emit_chunks=False, validate_crcs=True)
        where = "the end"
        try:
            for i, record in enumerate(reader.records):
                if isinstance(record, Schema):
                    schemas[record.id] = record
                elif isinstance(record, Channel):
                    conns.setdefault(
                        record.id, _conn_from_channel(record, schemas.get(record.schema_id))
                    )
                elif isinstance(record, Message):
                    if record.log_time > INT64_MAX:
                        # beyond 2262: a damaged record (times are int64 ns from here on)
                        raise ValueError(f"message log time {record.log_time} out of range")
                    self._scanned.append(
                        (record.log_time, i, record.channel_id, bytes(record.data))
                    )
        except CRCValidationError as err:
            # a damaged chunk or data section, not the end of an unfinished recording
            at = self._f.tell()
            self._f.close()
            raise BagError(
                f"MCAP data fails its CRC check before byte {at} (damaged file)", path=self.path
            ) from err
        except mcap_errors() as err:
            where = f"byte {self._f.tell()} ({type(err).__name__})"
        if not conns:
            self._f.close()
            raise BagError(
                f"unreadable MCAP file: no summary section and no complete channel record "
                f"before {where}",
                path=self.path,
            )
        log.warning(
            "%s: MCAP file has no summary section (recording not finished, or cut short); "
            "read the %d complete messages up to %s",
            self.path,
            len(self._scanned),
            where,
        )
        self._scanned.sort(key=lambda m: (m[0], m[1]))
        return tuple(conns[c] for c in sorted(conns))

    def raw(
        self, conns: Sequence[Conn], start_ns: int | None = None, end_ns: int | None = None
    ) -> Iterator[RawRecord]:
        by_id = {c.id: c for c in conns}
        if not by_id:
            return
        if self.unfinished:
            for t, _i, cid, data in self._scanned:
                conn = by_id.get(cid)
                if conn is None:
                    continue
                if (start_ns is None or t >= start_ns) and (end_ns is None or t <= end_ns):
                    yield conn, int(t), data
            return
        topics = sorted({c.topic for c in conns})
        try:
            for _schema, channel, message in self._reader.iter_messages(
                topics=topics,
                starting_at=start_ns,
                ending_at=end_ns,
                log_time_order=True,
            ):
                conn = by_id.get(channel.id)
                if conn is not None:
                    if message.log_time > INT64_MAX:
                        raise ValueError(f"message log time {message.log_time} out of range")
                    yield conn, int(message.log_time), bytes(message.data)
        except mcap_errors() as err:
            raise BagError(
                f"damaged MCAP data ({type(err).__name__}: {err})", path=self.path
            ) from err

    def close(self) -> None:
        self._f.close()


def open_bag(path: str | Path) -> BagFile:
    """Open one bag of any format for per-message reading.

    Raises:
        BagError: missing, empty, unrecognised, truncated or otherwise unreadable file.
    """
    p = Path(path)
    fmt = detect_format(p)
    if fmt == "mcap":
        return McapFile(p)
    if fmt == "ros1-active":
        fmt = "ros1"
    if fmt == "ros1":
        from ertools.io.ros1_index import Ros1Bag

        return Ros1Bag(p)
    return RosbagsFile(p, fmt)
