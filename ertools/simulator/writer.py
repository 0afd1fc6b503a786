"""Write one simulated log in any supported format: ROS1 bag, rosbag2 (mcap/sqlite3), MCAP.

`BagWriter` is the only place the simulator touches a file. Scenario modules hand it whole
arrays (one call per topic and per stretch of time); it serialises fixed-layout messages
(PoseStamped, Pose2D, one-transform TFMessage) in bulk with NumPy
(:mod:`ertools.simulator.packing`), buffers everything, and on
close writes all messages **sorted by record time** (stable, so equal times keep call order),
as ``rosbag record`` did. Nothing in it reads a clock or a random source: the same calls give
the same bytes.

Formats (``fmt``):

- ``"ros1"``: ROS1 ``.bag`` v2.0 via ``rosbags.rosbag1.Writer``; ``compression`` None (the 2015
  default), ``"bz2"`` or ``"lz4"``. Types from the ROS1 Noetic store plus ``tf2_msgs/TFMessage``
  (missing from that store) and the three ``rockin_scoring`` state messages. Connections carry
  a ``callerid`` (the publishing node, as the 2015 recorder stored it); the same topic may
  have several connections with different caller ids (``/tf``: mocap node and ``world_map``).
- ``"rosbag2-mcap"`` / ``"rosbag2-sqlite3"``: a rosbag2 directory via
  ``rosbags.rosbag2.Writer`` (version 9); ``compression="zstd"`` gives zstd MCAP chunks.
- ``"mcap"``: a standalone ``.mcap`` (profile ``ros2``, schema ``ros2msg``, CDR messages) via
  the ``mcap`` library; ``compression`` None, ``"zstd"`` or ``"lz4"``.

ROS 2 formats use the ROS 2 Humble store (no ``Header.seq``; ``/rosout`` becomes
``rcl_interfaces/msg/Log``, the type a ROS 2 recorder would store). Connections with the same
topic and type are merged there (ROS 2 has no caller ids in bags).

Example::

    with BagWriter(path, "ros1") as bag:
        bag.write_pose_stamped("/fbm3w/robot_at_work/pose", t_rec, t_hdr, "world", xyz, quat,
                               callerid="/fbm3w/mocap_node")
        bag.write_state(Machine.BMBOX, "/fbm3w/bmbox_state", t_ns, BmBoxState.READY, "")

Size: one body at 120 Hz (PoseStamped + Pose2D + /tf) costs ~370 bytes per frame in an
uncompressed ROS1 bag (~45 kB/s, ~2.6 MB per minute, like the real 2015 bag): keep the mocap
part of a scenario under ~50 s per body, or use ``compression="lz4"``/``"bz2"``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from ertools.arrays import I64, U8
from ertools.errors import UsageError
from ertools.frozen_dataclass import frozen_dataclass
from ertools.simulator.packing import (
    Field,
    as_bytes,
    broadcast_rows,
    pack_messages,
    rosbags_name,
    split_time,
    typestore,
)
from ertools.states import MSG_TYPES, Machine

BagFormat = Literal["ros1", "rosbag2-mcap", "rosbag2-sqlite3", "mcap"]
FORMATS: tuple[BagFormat, ...] = ("ros1", "rosbag2-mcap", "rosbag2-sqlite3", "mcap")


# rosgraph_msgs/Log levels (ROS1) and their rcl_interfaces/Log equivalents (ROS 2).
LOG_LEVELS_ROS1 = {"DEBUG": 1, "INFO": 2, "WARN": 4, "ERROR": 8, "FATAL": 16}
_LOG_LEVELS_ROS2 = {"DEBUG": 10, "INFO": 20, "WARN": 30, "ERROR": 40, "FATAL": 50}


# --------------------------------------------------------------------------- the writer


@frozen_dataclass
class Connection:
    """A handle returned by :meth:`BagWriter.connection`."""

    index: int
    topic: str
    msgtype: str


@dataclass
class _Batch:
    conn: int
    t_ns: I64
    rows: U8 | list[bytes]


class BagWriter:
    """Buffer simulated messages and write them as one log (see the module docstring).

    Args:
        path: the ``.bag`` / ``.mcap`` file, or the rosbag2 directory. Must not exist.
        fmt: ``"ros1"``, ``"rosbag2-mcap"``, ``"rosbag2-sqlite3"`` or ``"mcap"``.
        compression: per format (see the module docstring); None = uncompressed.
        chunk_size: chunk threshold in bytes (ROS1 and MCAP).
    """

    def __init__(
        self,
        path: Path | str,
        fmt: BagFormat = "ros1",
        *,
        compression: str | None = None,
        chunk_size: int = 768 * 1024,
    ) -> None:
        if fmt not in FORMATS:
            raise UsageError(f"unknown bag format {fmt!r}; use one of {', '.join(FORMATS)}")
        allowed = {
            "ros1": (None, "bz2", "lz4"),
            "rosbag2-mcap": (None, "zstd"),
            "rosbag2-sqlite3": (None,),
            "mcap": (None, "zstd", "lz4"),
        }[fmt]
        if compression not in allowed:
            raise UsageError(f"compression {compression!r} not possible for {fmt}: use {allowed}")
        self.path = Path(path)
        if self.path.exists():
            raise UsageError(f"{self.path} exists already; the simulator never overwrites")
        self.fmt: BagFormat = fmt
        self.compression = compression
        self.chunk_size = chunk_size
        self.ros2 = fmt != "ros1"
        self.typestore = typestore(self.ros2)
        self._conns: list[tuple[str, str, str | None, bool]] = []
        self._conn_index: dict[tuple[str, str, str | None], int] = {}
        self._batches: list[_Batch] = []
        self._seq: dict[int, int] = {}
        self._closed = False

    # -- context manager

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if exc_type is None:
            self.close()

    # -- generic API

    def msgclass(self, msgtype: str) -> Any:
        """The rosbags dataclass of a type in this store (``pkg/Type`` or ``pkg/msg/Type``)."""
        return self.typestore.types[rosbags_name(msgtype)]

    def connection(
        self, topic: str, msgtype: str, *, callerid: str | None = None, latching: bool = False
    ) -> Connection:
        """Declare (or look up) a connection; ROS 2 formats ignore ``callerid``."""
        mt = rosbags_name(msgtype)
        if mt not in self.typestore.types:
            raise UsageError(f"message type {msgtype} is not in the {self.fmt} type store")
        key = (topic, mt, None if self.ros2 else callerid)
        if key not in self._conn_index:
            self._conn_index[key] = len(self._conns)
            self._conns.append((topic, mt, key[2], latching))
        return Connection(self._conn_index[key], topic, mt)

    def write(self, conn: Connection, t_record_ns: int, msg: Any) -> None:
        """Write one message object (a rosbags dataclass) at record time ``t_record_ns``."""
        data = self.serialize(msg, conn.msgtype)
        self._batches.append(_Batch(conn.index, np.array([t_record_ns], np.int64), [data]))

    def write_many(self, conn: Connection, t_record_ns: npt.ArrayLike, msgs: Sequence[Any]) -> None:
        """Write several message objects (one per record time)."""
        t = np.asarray(t_record_ns, dtype=np.int64).reshape(-1)
        if t.size != len(msgs):
            raise UsageError(f"{conn.topic}: {t.size} times for {len(msgs)} messages")
        rows = [self.serialize(m, conn.msgtype) for m in msgs]
        self._batches.append(_Batch(conn.index, t, rows))

    def write_raw(
        self, conn: Connection, t_record_ns: npt.ArrayLike, rows: U8 | list[bytes]
    ) -> None:
        """Write already serialised messages (an (N, size) byte array or a list of bytes)."""
        t = np.asarray(t_record_ns, dtype=np.int64).reshape(-1)
        if t.size != len(rows):
            raise UsageError(f"{conn.topic}: {t.size} times for {len(rows)} messages")
        self._batches.append(_Batch(conn.index, t, rows))

    def serialize(self, msg: Any, msgtype: str) -> bytes:
        """Serialise one message in this writer's encoding (ROS1 or CDR)."""
        if self.ros2:
            return bytes(self.typestore.serialize_cdr(msg, msgtype))
        return bytes(self.typestore.serialize_ros1(msg, msgtype))

    def _next_seq(self, conn: Connection, n: int) -> I64:
        """Header.seq values: per connection, counting from 0 as roscpp did."""
        start = self._seq.get(conn.index, 0)
        self._seq[conn.index] = start + n
        return np.arange(start, start + n, dtype=np.int64)

    def _header(self, conn: Connection | None, t_header_ns: I64, frame_id: str) -> list[Field]:
        sec, nsec = split_time(t_header_ns)
        n = t_header_ns.size
        if self.ros2:
            return [("i4", sec), ("u4", nsec), ("str", frame_id)]
        seq = self._next_seq(conn, n) if conn is not None else np.zeros(n, np.int64)
        return [("u4", seq), ("u4", sec), ("u4", nsec), ("str", frame_id)]

    # -- bulk helpers for the fixed-layout mocap messages

    def write_pose_stamped(
        self,
        topic: str,
        t_record_ns: npt.ArrayLike,
        t_header_ns: npt.ArrayLike,
        frame_id: str,
        xyz: npt.ArrayLike,
        quat_xyzw: npt.ArrayLike,
        *,
        callerid: str | None = None,
    ) -> Connection:
        """geometry_msgs/PoseStamped, one per row (scalars broadcast); Header.seq counts up."""
        t_rec, t_hdr, xyz_a, quat_a = broadcast_rows(t_record_ns, t_header_ns, xyz, quat_xyzw)
        conn = self.connection(topic, "geometry_msgs/PoseStamped", callerid=callerid)
        fields = [*self._header(conn, t_hdr, frame_id), ("f8", np.hstack([xyz_a, quat_a]))]
        self.write_raw(conn, t_rec, pack_messages(t_rec.size, fields, cdr=self.ros2))
        return conn

    def write_pose2d(
        self,
        topic: str,
        t_record_ns: npt.ArrayLike,
        x: npt.ArrayLike,
        y: npt.ArrayLike,
        theta: npt.ArrayLike,
        *,
        callerid: str | None = None,
    ) -> Connection:
        """geometry_msgs/Pose2D (no header: readers use the record time)."""
        t_rec = np.asarray(t_record_ns, dtype=np.int64).reshape(-1)
        n = t_rec.size
        cols = np.column_stack(
            [np.broadcast_to(np.asarray(v, dtype=np.float64), (n,)) for v in (x, y, theta)]
        )
        conn = self.connection(topic, "geometry_msgs/Pose2D", callerid=callerid)
        self.write_raw(conn, t_rec, pack_messages(n, [("f8", cols)], cdr=self.ros2))
        return conn

    def write_tf(
        self,
        t_record_ns: npt.ArrayLike,
        t_header_ns: npt.ArrayLike,
        parent: str,
        child: str,
        xyz: npt.ArrayLike,
        quat_xyzw: npt.ArrayLike,
        *,
        topic: str = "/tf",
        callerid: str | None = None,
    ) -> Connection:
        """tf2_msgs/TFMessage holding one ``parent -> child`` transform per message.

        Header.seq is 0 as in the 2015 bags (tf broadcasters did not count).
        """
        t_rec, t_hdr, xyz_a, quat_a = broadcast_rows(t_record_ns, t_header_ns, xyz, quat_xyzw)
        conn = self.connection(topic, "tf2_msgs/TFMessage", callerid=callerid)
        fields: list[Field] = [
            ("u4", np.ones(t_rec.size, np.int64)),
            *self._header(None, t_hdr, parent),
            ("str", child),
            ("f8", np.hstack([xyz_a, quat_a])),
        ]
        self.write_raw(conn, t_rec, pack_messages(t_rec.size, fields, cdr=self.ros2))
        return conn

    # -- message-object helpers for the sparse topics

    def write_state(
        self,
        machine: Machine,
        topic: str,
        t_ns: npt.ArrayLike,
        state: int | Sequence[int],
        payload: str | Sequence[str],
        *,
        callerid: str | None = None,
    ) -> Connection:
        """rockin_scoring/<Machine>State messages (state code + payload), one per time."""
        t = np.asarray(t_ns, dtype=np.int64).reshape(-1)
        n = t.size
        states = [int(state)] * n if isinstance(state, int) else [int(s) for s in state]
        payloads = [payload] * n if isinstance(payload, str) else list(payload)
        if len(states) != n or len(payloads) != n:
            raise UsageError(f"{topic}: {n} times, {len(states)} states, {len(payloads)} payloads")
        conn = self.connection(topic, MSG_TYPES[machine], callerid=callerid)
        cls = self.msgclass(MSG_TYPES[machine])
        rows = [
            self.serialize(cls(state=s, payload=p), conn.msgtype)
            for s, p in zip(states, payloads, strict=True)
        ]
        self.write_raw(conn, t, rows)
        return conn

    def write_string(
        self,
        topic: str,
        t_ns: npt.ArrayLike,
        text: str | Sequence[str],
        *,
        callerid: str | None = None,
    ) -> Connection:
        """std_msgs/String messages."""
        t = np.asarray(t_ns, dtype=np.int64).reshape(-1)
        texts = [text] * t.size if isinstance(text, str) else list(text)
        conn = self.connection(topic, "std_msgs/String", callerid=callerid)
        cls = self.msgclass("std_msgs/String")
        self.write_raw(conn, t, [self.serialize(cls(data=s), conn.msgtype) for s in texts])
        return conn

    def write_log(
        self,
        t_record_ns: int,
        t_header_ns: int,
        node: str,
        text: str,
        *,
        level: str = "INFO",
        file: str = "",
        function: str = "",
        line: int = 0,
        topics: Sequence[str] = ("/rosout",),
        callerid: str | None = None,
    ) -> Connection:
        """One /rosout line (rosgraph_msgs/Log in ROS1, rcl_interfaces/msg/Log in ROS 2).

        ``callerid`` defaults to ``node`` (in 2015 each node had its own /rosout connection).
        """
        sec, nsec = (int(v) for v in split_time(t_header_ns))
        if self.ros2:
            conn = self.connection("/rosout", "rcl_interfaces/msg/Log")
            stamp = self.msgclass("builtin_interfaces/Time")(sec=sec, nanosec=nsec)
            msg = self.msgclass("rcl_interfaces/msg/Log")(
                stamp=stamp,
                level=_LOG_LEVELS_ROS2[level],
                name=node.lstrip("/").replace("/", "."),
                msg=text,
                file=file,
                function=function,
                line=line,
            )
        else:
            conn = self.connection(
                "/rosout", "rosgraph_msgs/Log", callerid=callerid or node, latching=True
            )
            seq = int(self._next_seq(conn, 1)[0])
            msg = self.msgclass("rosgraph_msgs/Log")(
                header=self._header_obj(t_header_ns, "", seq),
                level=LOG_LEVELS_ROS1[level],
                name=node,
                msg=text,
                file=file,
                function=function,
                line=line,
                topics=list(topics),
            )
        self.write(conn, t_record_ns, msg)
        return conn

    def _header_obj(self, t_ns: int, frame_id: str, seq: int = 0) -> Any:
        sec, nsec = (int(v) for v in split_time(t_ns))
        stamp = self.msgclass("builtin_interfaces/Time")(sec=sec, nanosec=nsec)
        cls = self.msgclass("std_msgs/Header")
        if self.ros2:
            return cls(stamp=stamp, frame_id=frame_id)
        return cls(seq=seq, stamp=stamp, frame_id=frame_id)

    def write_map(
        self,
        namespace: str,
        t_record_ns: int,
        t_load_ns: int,
        occupancy: npt.NDArray[np.int8],
        *,
        resolution: float = 0.1,
        origin_xyz: tuple[float, float, float] = (0.0, 0.0, 0.0),
        origin_quat_xyzw: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0),
        frame_id: str = "map",
        callerid: str | None = None,
    ) -> tuple[Connection, Connection]:
        """``/<ns>/map`` (nav_msgs/OccupancyGrid) and ``/<ns>/map_metadata``, latched, once.

        ``occupancy`` is (height, width) int8 (-1 unknown, 0 free, 100 occupied), row 0 at the
        origin, as map_server published it.
        """
        ns = "/" + namespace.strip("/")
        caller = callerid or f"{ns}/map_server"
        grid = np.asarray(occupancy, dtype=np.int8)
        height, width = grid.shape
        sec, nsec = (int(v) for v in split_time(t_load_ns))
        pose = self.msgclass("geometry_msgs/Pose")(
            position=self.msgclass("geometry_msgs/Point")(*map(float, origin_xyz)),
            orientation=self.msgclass("geometry_msgs/Quaternion")(*map(float, origin_quat_xyzw)),
        )
        info = self.msgclass("nav_msgs/MapMetaData")(
            map_load_time=self.msgclass("builtin_interfaces/Time")(sec=sec, nanosec=nsec),
            resolution=float(np.float32(resolution)),
            width=int(width),
            height=int(height),
            origin=pose,
        )
        grid_msg = self.msgclass("nav_msgs/OccupancyGrid")(
            header=self._header_obj(t_load_ns, frame_id),
            info=info,
            data=grid.reshape(-1).copy(),
        )
        c_map = self.connection(
            f"{ns}/map", "nav_msgs/OccupancyGrid", callerid=caller, latching=True
        )
        c_meta = self.connection(
            f"{ns}/map_metadata", "nav_msgs/MapMetaData", callerid=caller, latching=True
        )
        self.write(c_map, t_record_ns, grid_msg)
        self.write(c_meta, t_record_ns, info)
        return c_map, c_meta

    # -- output

    @property
    def message_count(self) -> int:
        """Messages buffered so far."""
        return sum(int(b.t_ns.size) for b in self._batches)

    def close(self) -> None:
        """Sort every buffered message by record time and write the file."""
        if self._closed:
            return
        self._closed = True
        order, times, conns, rows = self._merged()
        self.path.parent.mkdir(parents=True, exist_ok=True)
        if self.fmt == "ros1":
            self._write_ros1(order, times, conns, rows)
        elif self.fmt == "mcap":
            self._write_mcap(order, times, conns, rows)
        else:
            self._write_rosbag2(order, times, conns, rows)

    def _merged(self) -> tuple[npt.NDArray[np.intp], I64, npt.NDArray[np.int64], list[Any]]:
        if not self._batches:
            raise UsageError(f"{self.path}: no messages were written")
        times = np.concatenate([b.t_ns for b in self._batches])
        conns = np.concatenate([np.full(b.t_ns.size, b.conn, np.int64) for b in self._batches])
        rows: list[Any] = []
        for b in self._batches:
            rows.extend(b.rows)
        if np.any(times < 0):
            raise UsageError(f"{self.path}: negative record time")
        order = np.argsort(times, kind="stable")
        return order, times, conns, rows

    def _used_conns(self, conns: npt.NDArray[np.int64]) -> list[int]:
        """Connections in the order of their first message (as a recorder meets them)."""
        _, first = np.unique(conns, return_index=True)
        return [int(conns[i]) for i in np.sort(first)]

    def _write_ros1(
        self, order: npt.NDArray[np.intp], times: I64, conns: npt.NDArray[np.int64], rows: list[Any]
    ) -> None:
        from rosbags.rosbag1 import Writer  # lazy: rosbags, 100 ms

        writer = Writer(self.path)
        writer.chunk_threshold = self.chunk_size
        if self.compression is not None:
            writer.set_compression(Writer.CompressionFormat[self.compression.upper()])
        sorted_conns = conns[order]
        handles: dict[int, Any] = {}
        with writer:
            for ci in self._used_conns(sorted_conns):
                topic, mt, callerid, latching = self._conns[ci]
                handles[ci] = writer.add_connection(
                    topic,
                    mt,
                    typestore=self.typestore,
                    callerid=callerid,
                    latching=1 if latching else 0,
                )
            write = writer.write
            for i in order.tolist():
                write(handles[int(conns[i])], int(times[i]), as_bytes(rows[i]))

    def _write_rosbag2(
        self, order: npt.NDArray[np.intp], times: I64, conns: npt.NDArray[np.int64], rows: list[Any]
    ) -> None:
        from rosbags.rosbag2 import StoragePlugin, Writer  # lazy: rosbags, 100 ms
        from rosbags.rosbag2.enums import CompressionFormat, CompressionMode  # lazy: 100 ms

        plugin = StoragePlugin.MCAP if self.fmt == "rosbag2-mcap" else StoragePlugin.SQLITE3
        writer = Writer(self.path, version=9, storage_plugin=plugin)
        if self.compression == "zstd":
            writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
        sorted_conns = conns[order]
        handles: dict[int, Any] = {}
        with writer:
            for ci in self._used_conns(sorted_conns):
                topic, mt, _, _ = self._conns[ci]
                handles[ci] = writer.add_connection(topic, mt, typestore=self.typestore)
            write = writer.write
            for i in order.tolist():
                write(handles[int(conns[i])], int(times[i]), as_bytes(rows[i]))

    def _write_mcap(
        self, order: npt.NDArray[np.intp], times: I64, conns: npt.NDArray[np.int64], rows: list[Any]
    ) -> None:
        from mcap.writer import CompressionType, Writer  # lazy: mcap, 100 ms

        ctype = {
            None: CompressionType.NONE,
            "zstd": CompressionType.ZSTD,
            "lz4": CompressionType.LZ4,
        }[self.compression]
        sorted_conns = conns[order]
        with self.path.open("xb") as fh:
            writer = Writer(fh, chunk_size=self.chunk_size, compression=ctype)
            writer.start(profile="ros2", library="ertools-samples")
            schemas: dict[str, int] = {}
            channels: dict[int, int] = {}
            for ci in self._used_conns(sorted_conns):
                topic, mt, _, _ = self._conns[ci]
                if mt not in schemas:
                    text, _ = self.typestore.generate_msgdef(mt, ros_version=2)
                    schemas[mt] = writer.register_schema(
                        name=mt, encoding="ros2msg", data=text.encode()
                    )
                channels[ci] = writer.register_channel(
                    topic=topic, message_encoding="cdr", schema_id=schemas[mt]
                )
            seq: dict[int, int] = {}
            for i in order.tolist():
                ci = int(conns[i])
                t = int(times[i])
                s = seq.get(ci, 0)
                seq[ci] = s + 1
                writer.add_message(
                    channel_id=channels[ci],
                    log_time=t,
                    data=as_bytes(rows[i]),
                    publish_time=t,
                    sequence=s,
                )
            writer.finish()  # type: ignore[no-untyped-call]
