"""One MCAP log file being written, crash-safe to the last flush.

An MCAP file is a header, then chunks (each followed by its message indexes), then a summary
and a footer written when the file is closed. A file cut short (kill -9, power loss) lacks the
summary but every chunk before the cut is complete and readable by a sequential reader. So the
recorder closes a chunk and flushes it to the operating system at least every
``flush_interval_s``: a crash loses at most that much data. The kernel keeps what was flushed
even if the process is killed; only a power loss needs ``fsync``, which is optional because it
costs a disk round trip per flush.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import IO, Any

from ertools._version import __version__
from ertools.atomic import hold
from ertools.errors import BagError
from ertools.live.rosmsg import MESSAGE_ENCODING, SCHEMA_ENCODING, Ros2Serializer

COMPRESSIONS = ("zstd", "lz4", "none")


def log_file_name(name: str, start_s: float, index: int) -> str:
    """rosbag record's split naming: ``log_<name>_<YYYY-MM-DD-HH-MM-SS>_<n>.mcap``.

    As with ``rosbag record --split``, the stamp is the local time the recording started and
    stays the same for every split; only ``n`` counts up.
    """
    stamp = time.strftime("%Y-%m-%d-%H-%M-%S", time.localtime(start_s))
    return f"log_{name}_{stamp}_{index}.mcap"


class LogFile:
    """An open MCAP file with ROS 2 channels created on first use."""

    def __init__(
        self,
        path: Path,
        serializer: Ros2Serializer,
        *,
        compression: str = "zstd",
        fsync: bool = False,
        chunk_size: int = 256 * 1024,
    ) -> None:
        from mcap.writer import CompressionType, Writer  # lazy: mcap, 100 ms

        if compression not in COMPRESSIONS:
            raise ValueError(f"compression {compression!r} not in {COMPRESSIONS}")
        kind = {
            "zstd": CompressionType.ZSTD,
            "lz4": CompressionType.LZ4,
            "none": CompressionType.NONE,
        }[compression]
        self.path = path
        self._serializer = serializer
        self._fsync = fsync
        try:
            # "xb": never overwrite a file (two recorders started in the same second).
            self._stream: IO[bytes] = open(path, "xb")  # noqa: SIM115 - closed in close()
        except OSError as err:
            raise BagError(f"cannot create log file: {err.strerror or err}", path=path) from err
        # held from the first byte to the last (and released however the recorder ends):
        # `record --recover` refuses a file locked so (ertools.live.recover)
        hold(self._stream.fileno())
        self._writer: Any = Writer(self._stream, chunk_size=chunk_size, compression=kind)
        self._writer.start(profile="ros2", library=f"ertools {__version__} record")
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self.messages = 0
        self.closed = False

    def channel(self, topic: str, typename: str) -> int:
        """The channel ID of ``topic`` (registered with its schema on first use)."""
        cid = self._channels.get(topic)
        if cid is None:
            sid = self._schemas.get(typename)
            if sid is None:
                sid = self._writer.register_schema(
                    name=typename, encoding=SCHEMA_ENCODING, data=self._serializer.schema(typename)
                )
                self._schemas[typename] = sid
            cid = self._writer.register_channel(
                topic=topic, message_encoding=MESSAGE_ENCODING, schema_id=sid
            )
            self._channels[topic] = cid
        return int(cid)

    def write(self, channel_id: int, t_ns: int, data: bytes) -> None:
        self._writer.add_message(channel_id=channel_id, log_time=t_ns, data=data, publish_time=t_ns)
        self.messages += 1

    def add_metadata(self, name: str, data: dict[str, str]) -> None:
        self._writer.add_metadata(name, data)
        self.flush()

    def flush(self) -> None:
        """Close the chunk in progress and hand everything to the OS (and disk with fsync)."""
        if hasattr(self._writer, "flush"):  # mcap >= 1.6
            self._writer.flush()
        else:  # older mcap: the same steps through the private chunk finaliser
            self._writer._Writer__finalize_chunk()
            self._stream.flush()
        if self._fsync:
            os.fsync(self._stream.fileno())

    @property
    def size(self) -> int:
        return self._stream.tell()

    def close(self, final_metadata: dict[str, dict[str, str]] | None = None) -> None:
        """Write the final metadata, the summary and the footer."""
        if self.closed:
            return
        for name, data in (final_metadata or {}).items():
            self._writer.add_metadata(name, data)
        self._writer.finish()
        self._stream.flush()
        if self._fsync:
            os.fsync(self._stream.fileno())
        self._stream.close()
        self.closed = True
