"""One open bag file of any format: its connections and its raw messages in record-time order.

This is the general (per-message) path. The bulk NumPy decoders in :mod:`ertools.io.decode.fast`
read the same files through :mod:`ertools.io.ros1.index` and :mod:`ertools.io.mcap.index`; this
module is the reference they are tested against and the fallback for every other type.

Order of messages (the reference order): by record time; ties keep the order of the
connections as listed by the file, then file order (rosbags' heap merge for ROS1 and rosbag2;
the ``mcap`` library's (log time, chunk, position) order for MCAP).
"""

from __future__ import annotations

import contextlib
import dataclasses
import heapq
import logging
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ertools.errors import BagError
from ertools.io.bagfile import BagFile, RawRecord
from ertools.io.decode.fast import LayoutMismatchError
from ertools.io.formats import detect_format
from ertools.io.inflate import inflate_message
from ertools.io.model import Conn, short_msgtype
from ertools.io.ros1.index import Ros1Bag
from ertools.io.rosbag2.metadata import (
    message_compression,
    read_metadata,
    readable_dir,
    readable_files,
)

log = logging.getLogger("ertools.io.files")

# (reference positions, bytes, data starts, data lengths, log times, channel ids)
ScannedRun = tuple[Any, Any, Any, Any, Any, Any]


def _conn_from_rosbags(c: Any) -> Conn:
    from rosbags.interfaces import (  # lazy: rosbags, 100 ms
        ConnectionExtRosbag1,
        MessageDefinitionFormat,
    )

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
    """ROS1 and rosbag2 through rosbags' readers (builds rosbags' per-message index).

    Messages of a rosbag2 bag compressed one by one reach this class compressed (rosbags
    reads a copy of the metadata without the compression: :func:`readable_dir`) and are
    decompressed here, within the budget (rosbags' own decompression trusts the size a zstd
    frame states, however large)."""

    def __init__(self, path: Path, fmt: str) -> None:
        self.path = path
        self.format = fmt
        self._inflate: str | None = None
        try:
            if fmt != "ros1":
                self._inflate = message_compression(read_metadata(path))
            if fmt == "ros1":
                from rosbags.rosbag1 import Reader as Reader1  # lazy: rosbags, 100 ms

                self._reader: Any = Reader1(path)
            else:
                from rosbags.rosbag2 import Reader as Reader2  # lazy: rosbags, 100 ms

                # A bag compressed file by file: the copies every other reader reads.
                self._reader = Reader2(readable_dir(path))
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
                if self._inflate is not None:
                    where = f"of {c.topic} at {t} ns"
                    data = inflate_message(self._inflate, bytes(data), where)
                yield by_id[int(c.id)], int(t), bytes(data)
        except BagError as err:
            raise BagError(err.message, path=self.path) from err
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


class McapFile(BagFile):
    """A standalone MCAP file (ROS 2 ``cdr`` or ``ros1`` message encoding) via ``mcap``.

    Read through the summary's indexes when they answer for every message
    (:func:`ertools.io.mcap.scan.mcap_layout`), else record by record (``scanned`` is True,
    and INFO says why): no summary section, chunks without message indexes, channels or
    schemas only inside chunks, messages outside chunks. A file cut short (a recorder that was
    killed) is read as far as its records are complete, like a ROS1 ``.bag.active``:
    ``unfinished`` is True and a warning says so.
    """

    def __init__(self, path: Path) -> None:
        from ertools.io.mcap.scan import SCAN, mcap_layout  # lazy: 5 ms, MCAP files only
        from ertools.io.mcap.summary import mcap_errors  # lazy: 5 ms, MCAP files only

        self.path = path
        self.format = "mcap"
        self.unfinished = False
        self.scanned = False
        try:
            layout = mcap_layout(path)
        except BagError:
            raise
        except mcap_errors() as err:
            raise BagError(f"unreadable MCAP file ({err})", path=path) from err
        if layout.index == SCAN:
            self.connections = self._scan(layout.why)
            return
        self.connections = tuple(
            _conn_from_channel(ch, layout.schemas.get(ch.schema_id))
            for _cid, ch in sorted(layout.channels.items())
        )

    def _scan(self, why: str) -> tuple[Conn, ...]:
        """Read every complete record (the summary's indexes do not answer for them all)."""
        from ertools.io.mcap.scan import scan_mcap  # lazy: 5 ms, MCAP files only

        self.scanned = True
        log.info("%s: %s; reading the file record by record", self.path, why)
        found = scan_mcap(self.path)
        conns = {
            cid: _conn_from_channel(ch, found.schemas.get(ch.schema_id))
            for cid, ch in found.channels.items()
        }
        if not conns and not found.complete:
            raise BagError(
                f"unreadable MCAP file: no complete channel record ({found.problem})",
                path=self.path,
            )
        if found.problem:
            self.unfinished = True
            log.warning(
                "%s: MCAP file %s (%s: recording not finished, or cut short?); read the %d "
                "complete messages",
                self.path,
                found.problem,
                why,
                len(found.log_time),
            )
        return tuple(conns[c] for c in sorted(conns))

    def scanned_runs(
        self, conns: Sequence[Conn], start_ns: int | None, end_ns: int | None
    ) -> Iterator[ScannedRun]:
        """The messages of ``conns`` in [start_ns, end_ns] of a file read record by record, as
        runs of (reference positions, bytes, data starts, data lengths, log times, channel
        ids): one more pass over the records that copies only these messages' bytes."""
        from ertools.io.mcap.scan import scan_mcap  # lazy: 5 ms, MCAP files only

        found = scan_mcap(self.path, keep=frozenset(c.id for c in conns))
        if not found.payloads:
            return
        ordinal = np.concatenate([r[3] for r in found.payloads])
        t = found.log_time[ordinal]
        inside = np.ones(len(t), dtype=bool)
        if start_ns is not None:
            inside &= t >= start_ns
        if end_ns is not None:
            inside &= t <= end_ns
        # the reference order: log time, then position in the file
        order = np.lexsort((ordinal[inside], t[inside]))
        rank = np.empty(len(order), dtype=np.int64)
        rank[order] = np.arange(len(order), dtype=np.int64)
        done = kept = 0
        for buf, start, length, ords in found.payloads:
            mine = inside[done : done + len(ords)]
            n = int(mine.sum())
            if n:
                o = ords[mine]
                cid = found.channel_id[o]
                yield (
                    rank[kept : kept + n],
                    buf,
                    start[mine],
                    length[mine],
                    t[done : done + len(ords)][mine],
                    cid,
                )
            done += len(ords)
            kept += n

    def raw(
        self, conns: Sequence[Conn], start_ns: int | None = None, end_ns: int | None = None
    ) -> Iterator[RawRecord]:
        by_id = {c.id: c for c in conns}
        if not by_id:
            return
        if self.scanned:
            runs = list(self.scanned_runs(conns, start_ns, end_ns))
            if not runs:
                return
            rank = np.concatenate([r[0] for r in runs])
            which = np.concatenate([np.full(len(r[0]), k) for k, r in enumerate(runs)])
            row = np.concatenate([np.arange(len(r[0])) for r in runs])
            order = np.argsort(rank)
            for k, i in zip(which[order].tolist(), row[order].tolist(), strict=True):
                _rank, buf, start, length, t, cid = runs[k]
                a = int(start[i])
                yield by_id[int(cid[i])], int(t[i]), buf[a : a + int(length[i])].tobytes()
            return
        from ertools.io.mcap.index import McapIndex  # lazy: 5 ms, MCAP files only

        try:
            found = McapIndex([self.path], by_id=True).messages(conns, start_ns, end_ns)
        except LayoutMismatchError as err:
            # indexes that do not answer for every message (padded message indexes): the
            # messages are read record by record, as a file without indexes is
            log.info("%s: %s; reading the file record by record", self.path, err)
            self.scanned = True
            yield from self.raw(conns, start_ns, end_ns)
            return
        for _file, cid, t, data in found:
            conn = by_id.get(cid)
            if conn is not None:
                yield conn, t, data


class Rosbag2McapFile(BagFile):
    """A rosbag2 bag with MCAP storage, read as standalone MCAP files are (:class:`McapFile`:
    through their indexes, every chunk within the budget; rosbags' MCAP reader inflates a
    chunk to whatever size its zstd frame states). One connection per topic, as rosbag2
    records them; messages of several files merged by record time, file order on ties."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.format = "rosbag2-mcap"
        info = read_metadata(path)
        self._inflate = message_compression(info)
        self._files: list[McapFile] = []
        for storage in readable_files(path, info):
            if storage.suffix == ".mcap":
                with self._naming(storage):
                    self._files.append(McapFile(storage))
        by_topic: dict[str, Conn] = {}
        for opened in self._files:
            for c in opened.connections:
                by_topic.setdefault(c.topic, c)
        self.connections = tuple(
            dataclasses.replace(c, id=i) for i, c in enumerate(by_topic.values(), start=1)
        )

    def raw(
        self, conns: Sequence[Conn], start_ns: int | None = None, end_ns: int | None = None
    ) -> Iterator[RawRecord]:
        wanted = {c.topic: c for c in conns}
        if not wanted:
            return
        parts = []
        for f in self._files:
            mine = [c for c in f.connections if c.topic in wanted]
            if mine:
                with self._naming(f.path):
                    got = [(wanted[c.topic], t, d) for c, t, d in f.raw(mine, start_ns, end_ns)]
                parts.append(got)
        for conn, t, data in heapq.merge(*parts, key=lambda r: r[1]):
            if self._inflate is not None:
                where = f"of {conn.topic} at {t} ns"
                try:
                    data = inflate_message(self._inflate, data, where)
                except BagError as err:
                    raise BagError(err.message, path=self.path) from err
            yield conn, t, data

    @contextlib.contextmanager
    def _naming(self, file: Path) -> Iterator[None]:
        """An error of one storage file said as the bag's, naming the file."""
        try:
            yield
        except BagError as err:
            raise BagError(f"storage file {file.name}: {err.message}", path=self.path) from err


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
        return Ros1Bag(p)
    if fmt == "rosbag2-mcap":
        return Rosbag2McapFile(p)
    return RosbagsFile(p, fmt)
