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


class McapFile(BagFile):
    """A standalone MCAP file (ROS 2 ``cdr`` or ``ros1`` message encoding) via ``mcap``."""

    def __init__(self, path: Path) -> None:
        from mcap.exceptions import McapError
        from mcap.reader import make_reader

        self.path = path
        self.format = "mcap"
        self._f = path.open("rb")
        try:
            self._reader = make_reader(self._f)
            summary = self._reader.get_summary()
            if summary is None:
                raise BagError(
                    "MCAP file has no summary section (unfinished recording?)", path=path
                )
            channels = summary.channels
            schemas = summary.schemas
        except (McapError, ValueError, EOFError, OSError) as err:
            self._f.close()
            raise BagError(
                f"unreadable MCAP file ({type(err).__name__}: {err})", path=path
            ) from err
        except BagError:
            self._f.close()
            raise
        conns = []
        for cid in sorted(channels):
            ch = channels[cid]
            schema = schemas.get(ch.schema_id)
            name = schema.name if schema is not None else ""
            enc = schema.encoding if schema is not None else ""
            data = schema.data.decode("utf-8", "replace") if schema is not None else ""
            conns.append(
                Conn(
                    int(cid),
                    ch.topic,
                    short_msgtype(name),
                    data,
                    "idl" if enc == "ros2idl" else ("msg" if data else ""),
                    "ros1" if ch.message_encoding == "ros1" else "cdr",
                    "transient_local" in ch.metadata.get("offered_qos_profiles", ""),
                    "",
                )
            )
        self.connections = tuple(conns)

    def raw(
        self, conns: Sequence[Conn], start_ns: int | None = None, end_ns: int | None = None
    ) -> Iterator[RawRecord]:
        from mcap.exceptions import McapError

        by_id = {c.id: c for c in conns}
        if not by_id:
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
                    yield conn, int(message.log_time), bytes(message.data)
        except (McapError, ValueError, EOFError, OSError) as err:
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
