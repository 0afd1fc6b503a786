"""Write tiny bags of every format with rosbags' writers (and ``mcap`` for standalone MCAP).

Messages are given as plain values; each writer builds them with the typestore of its format
(ROS1 Noetic or ROS2 Humble plus the 2015 custom types), so the files hold real stored
definitions, as the 2015 loggers wrote them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from mcap.writer import CompressionType
from mcap.writer import Writer as McapWriter
from rosbags.rosbag1 import Writer
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from ertools.states import MSG_DEFINITIONS, MSG_TYPES

FORMATS = (
    "ros1",
    "ros1-lz4",
    "ros1-bz2",
    "rosbag2-sqlite3",
    "rosbag2-mcap",
    "mcap-cdr",
    "mcap-ros1",
)

TF_MSG = "geometry_msgs/TransformStamped[] transforms\n"


def typestore(ros1: bool) -> Any:
    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    extra: dict[str, Any] = {}
    for machine, name in MSG_TYPES.items():
        extra.update(get_types_from_msg(MSG_DEFINITIONS[machine], name.replace("/", "/msg/")))
    extra.update(get_types_from_msg(TF_MSG, "tf/msg/tfMessage"))
    if ros1:
        extra.update(get_types_from_msg(TF_MSG, "tf2_msgs/msg/TFMessage"))
    ts.register(extra)
    return ts


@dataclass
class Spec:
    """Connections (topic, type, callerid) and messages (connection index, t_ns, value)."""

    conns: list[tuple[str, str, str]] = field(default_factory=list)
    msgs: list[tuple[int, int, dict[str, Any]]] = field(default_factory=list)

    def conn(self, topic: str, msgtype: str, callerid: str = "/node") -> int:
        self.conns.append((topic, msgtype, callerid))
        return len(self.conns) - 1

    def add(self, conn: int, t_ns: int, **value: Any) -> None:
        self.msgs.append((conn, t_ns, value))


def _time(ts: Any, ns: int) -> Any:
    return ts.types["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)


def _header(ts: Any, ros1: bool, stamp_ns: int, frame: str, seq: int) -> Any:
    h = ts.types["std_msgs/msg/Header"]
    if ros1:
        return h(seq=seq, stamp=_time(ts, stamp_ns), frame_id=frame)
    return h(stamp=_time(ts, stamp_ns), frame_id=frame)


def _pose(ts: Any, xyz: Any, q: Any) -> Any:
    T = ts.types
    return T["geometry_msgs/msg/Pose"](
        position=T["geometry_msgs/msg/Point"](*map(float, xyz)),
        orientation=T["geometry_msgs/msg/Quaternion"](*map(float, q)),
    )


def _tfs(ts: Any, ros1: bool, v: dict[str, Any], seq: int) -> Any:
    T = ts.types
    return T["geometry_msgs/msg/TransformStamped"](
        header=_header(ts, ros1, v["stamp"], v["frame"], seq),
        child_frame_id=v["child"],
        transform=T["geometry_msgs/msg/Transform"](
            translation=T["geometry_msgs/msg/Vector3"](*map(float, v["xyz"])),
            rotation=T["geometry_msgs/msg/Quaternion"](*map(float, v["q"])),
        ),
    )


def build(ts: Any, ros1: bool, msgtype: str, v: dict[str, Any], seq: int) -> Any:
    """A message object of ``msgtype`` (``pkg/Type``) from plain values."""
    T = ts.types
    long = msgtype.replace("/", "/msg/")
    if msgtype == "geometry_msgs/PoseStamped":
        return T[long](
            header=_header(ts, ros1, v["stamp"], v["frame"], seq), pose=_pose(ts, v["xyz"], v["q"])
        )
    if msgtype == "geometry_msgs/Pose2D":
        return T[long](x=float(v["x"]), y=float(v["y"]), theta=float(v["theta"]))
    if msgtype == "geometry_msgs/TransformStamped":
        return _tfs(ts, ros1, v, seq)
    if msgtype in ("tf2_msgs/TFMessage", "tf/tfMessage"):
        return T[long](transforms=[_tfs(ts, ros1, x, seq) for x in v["transforms"]])
    if msgtype == "geometry_msgs/PoseWithCovarianceStamped":
        # A covariance unlike any pose value: a decoder reading the wrong 56 bytes shows.
        cov = np.linspace(-1e3, 1e3, 36) + seq
        return T[long](
            header=_header(ts, ros1, v["stamp"], v["frame"], seq),
            pose=T["geometry_msgs/msg/PoseWithCovariance"](
                pose=_pose(ts, v["xyz"], v["q"]), covariance=cov
            ),
        )
    if msgtype == "nav_msgs/Odometry":
        cov = np.arange(36, dtype=np.float64)
        return T[long](
            header=_header(ts, ros1, v["stamp"], v["frame"], seq),
            child_frame_id=v["child"],
            pose=T["geometry_msgs/msg/PoseWithCovariance"](
                pose=_pose(ts, v["xyz"], v["q"]), covariance=cov
            ),
            twist=T["geometry_msgs/msg/TwistWithCovariance"](
                twist=T["geometry_msgs/msg/Twist"](
                    linear=T["geometry_msgs/msg/Vector3"](1.0, 2.0, 3.0),
                    angular=T["geometry_msgs/msg/Vector3"](4.0, 5.0, 6.0),
                ),
                covariance=cov,
            ),
        )
    if msgtype.startswith("rockin_scoring/"):
        return T[long](state=int(v["state"]), payload=str(v["payload"]))
    if msgtype == "std_msgs/String":
        return T[long](data=str(v["data"]))
    raise ValueError(msgtype)


def write(
    path: Path, fmt: str, spec: Spec, chunk_bytes: int | None = None, **mcap_options: Any
) -> Path:
    """Write ``spec`` as ``fmt`` (see FORMATS) at ``path``; returns the bag path.

    ``mcap_options`` go to the ``mcap`` Writer of standalone MCAP files (``use_statistics``,
    ``repeat_channels``, ``use_chunking``, ``index_types``, ``compression``...)."""
    ros1 = fmt.startswith("ros1") or fmt == "mcap-ros1"
    ts = typestore(ros1)
    if fmt.startswith("ros1"):
        w = Writer(path)
        if fmt != "ros1":
            w.set_compression(Writer.CompressionFormat[fmt.split("-")[1].upper()])
        if chunk_bytes is not None:
            w.chunk_threshold = chunk_bytes
        with w:
            conns = [
                w.add_connection(t, ty.replace("/", "/msg/"), typestore=ts, callerid=c)
                for t, ty, c in spec.conns
            ]
            for seq, (ci, t_ns, v) in enumerate(spec.msgs):
                msg = build(ts, True, spec.conns[ci][1], v, seq)
                w.write(conns[ci], t_ns, ts.serialize_ros1(msg, conns[ci].msgtype))
        return path
    if fmt.startswith("rosbag2"):
        plugin = StoragePlugin.SQLITE3 if fmt.endswith("sqlite3") else StoragePlugin.MCAP
        with Writer2(path, version=9, storage_plugin=plugin) as w2:
            conns2 = {}
            for i, (t, ty, _c) in enumerate(spec.conns):
                # rosbag2 has one connection per topic; a second ROS1-style connection of a
                # topic reuses it.
                prior = next((j for j, x in enumerate(spec.conns[:i]) if x[0] == t), None)
                conns2[i] = (
                    conns2[prior]
                    if prior is not None
                    else w2.add_connection(t, ty.replace("/", "/msg/"), typestore=ts)
                )
            for seq, (ci, t_ns, v) in enumerate(spec.msgs):
                msg = build(ts, False, spec.conns[ci][1], v, seq)
                w2.write(conns2[ci], t_ns, ts.serialize_cdr(msg, conns2[ci].msgtype))
        return path

    with path.open("wb") as f:
        options = {"compression": CompressionType.LZ4, **mcap_options}
        mw = McapWriter(f, chunk_size=chunk_bytes or 1024 * 1024, **options)
        mw.start(profile="ros1" if ros1 else "ros2", library="ertools-tests")
        schema_ids: dict[str, int] = {}
        channels = []
        for t, ty, _c in spec.conns:
            long = ty.replace("/", "/msg/")
            if ty not in schema_ids:
                text = ts.generate_msgdef(long, ros_version=1 if ros1 else 2)[0]
                schema_ids[ty] = mw.register_schema(
                    name=ty if ros1 else long,
                    encoding="ros1msg" if ros1 else "ros2msg",
                    data=text.encode(),
                )
            channels.append(
                mw.register_channel(
                    topic=t, message_encoding="ros1" if ros1 else "cdr", schema_id=schema_ids[ty]
                )
            )
        for seq, (ci, t_ns, v) in enumerate(spec.msgs):
            ty = spec.conns[ci][1]
            msg = build(ts, ros1, ty, v, seq)
            long = ty.replace("/", "/msg/")
            data = ts.serialize_ros1(msg, long) if ros1 else ts.serialize_cdr(msg, long)
            mw.add_message(channels[ci], log_time=t_ns, data=data, publish_time=t_ns, sequence=seq)
        mw.finish()
    return path


def bag_name(tmp_path: Path, fmt: str, stem: str = "b") -> Path:
    if fmt.startswith("ros1"):
        return tmp_path / f"{stem}.bag"
    if fmt.startswith("rosbag2"):
        return tmp_path / f"{stem}_{fmt}"
    return tmp_path / f"{stem}.mcap"
