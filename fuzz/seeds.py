"""The seed files: small bags of every ROS1 and MCAP layout the fuzzer damages.

Each seed holds a pose topic (``PoseStamped``), ``/tf`` (one ``world -> robot`` transform per
message) and a non-pose topic (``std_msgs/String``), written with rosbags' ROS1 writer and
mcap's writer with small chunks (several chunks per file, so index and chunk-info records
repeat). The bytes are the same on every run: the messages come from a fixed formula.
"""

from __future__ import annotations

from functools import cache
from typing import Any

POSE_TOPIC = "/robot/pose"
TF_TOPIC = "/tf"
TEXT_TOPIC = "/robot/status"
TF_PARENT, TF_CHILD = "world", "robot"
T0_NS = 1_430_000_000_123_456_789  # May 2015, with every ns digit used
N_POSES = 30
CHUNK_BYTES = 1200

# name -> (container, compression, mcap writer options)
SEEDS: dict[str, tuple[str, str, dict[str, Any]]] = {
    "ros1": ("ros1", "none", {}),
    "ros1-bz2": ("ros1", "bz2", {}),
    "ros1-lz4": ("ros1", "lz4", {}),
    "mcap": ("mcap", "none", {}),
    "mcap-lz4": ("mcap", "lz4", {}),
    "mcap-zstd": ("mcap", "zstd", {}),
    "mcap-ros1-lz4": ("mcap-ros1", "lz4", {}),
    "mcap-zstd-nostats": (
        "mcap",
        "zstd",
        {"use_statistics": False, "use_summary_offsets": False},
    ),
    "mcap-lz4-nomsgindex": ("mcap", "lz4", {"index_types": "chunk"}),
    "mcap-nosummary": (
        "mcap",
        "zstd",
        {
            "index_types": "none",
            "use_statistics": False,
            "use_summary_offsets": False,
            "repeat_channels": False,
            "repeat_schemas": False,
        },
    ),
}

TF_MSGDEF = "geometry_msgs/TransformStamped[] transforms\n"


def _typestore(ros1: bool) -> Any:
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    if "tf2_msgs/msg/TFMessage" in ts.types:
        return ts
    ts.register(get_types_from_msg(TF_MSGDEF, "tf2_msgs/msg/TFMessage"))
    return ts


def messages(ts: Any, ros1: bool) -> list[tuple[str, int, Any]]:
    """(topic, record time ns, message) in record-time order."""
    T = ts.types

    def header(stamp: int, frame: str, seq: int) -> Any:
        t = T["builtin_interfaces/msg/Time"](sec=stamp // 10**9, nanosec=stamp % 10**9)
        if ros1:
            return T["std_msgs/msg/Header"](seq=seq, stamp=t, frame_id=frame)
        return T["std_msgs/msg/Header"](stamp=t, frame_id=frame)

    out: list[tuple[str, int, Any]] = []
    for i in range(N_POSES):
        t = T0_NS + i * 33_333_337
        x, y, z = 1.5 + 0.01 * i, -2.25 + 0.003 * i * i, 0.125
        # a unit quaternion that turns with i (yaw), written from its half angle
        import math

        h = 0.05 * i
        q = (0.0, 0.0, math.sin(h), math.cos(h))
        pose = T["geometry_msgs/msg/Pose"](
            position=T["geometry_msgs/msg/Point"](x=x, y=y, z=z),
            orientation=T["geometry_msgs/msg/Quaternion"](x=q[0], y=q[1], z=q[2], w=q[3]),
        )
        out.append(
            (
                POSE_TOPIC,
                t,
                T["geometry_msgs/msg/PoseStamped"](
                    header=header(t - 2_000_001, "map", i), pose=pose
                ),
            )
        )
        tf = T["geometry_msgs/msg/TransformStamped"](
            header=header(t + 1_000, TF_PARENT, i),
            child_frame_id=TF_CHILD,
            transform=T["geometry_msgs/msg/Transform"](
                translation=T["geometry_msgs/msg/Vector3"](x=x + 0.5, y=y, z=z),
                rotation=T["geometry_msgs/msg/Quaternion"](x=q[0], y=q[1], z=q[2], w=q[3]),
            ),
        )
        out.append((TF_TOPIC, t + 5_000, T["tf2_msgs/msg/TFMessage"](transforms=[tf])))
        if i % 3 == 0:
            text = T["std_msgs/msg/String"](data=f"state {i} " + "x" * (i % 7))
            out.append((TEXT_TOPIC, t + 11_000, text))
    return out


TYPES = {
    POSE_TOPIC: "geometry_msgs/msg/PoseStamped",
    TF_TOPIC: "tf2_msgs/msg/TFMessage",
    TEXT_TOPIC: "std_msgs/msg/String",
}


def _ros1(path: Any, compression: str) -> None:
    from rosbags.rosbag1 import Writer

    ts = _typestore(True)
    w = Writer(path)
    if compression != "none":
        w.set_compression(Writer.CompressionFormat[compression.upper()])
    w.chunk_threshold = CHUNK_BYTES
    with w:
        conns = {t: w.add_connection(t, ty, typestore=ts) for t, ty in TYPES.items()}
        for topic, t, msg in messages(ts, True):
            w.write(conns[topic], t, ts.serialize_ros1(msg, TYPES[topic]))


def _mcap(path: Any, container: str, compression: str, opts: dict[str, Any]) -> None:
    from mcap.writer import CompressionType, IndexType, Writer

    ros1 = container == "mcap-ros1"
    ts = _typestore(ros1)
    kw = dict(opts)
    if "index_types" in kw:
        kw["index_types"] = {"chunk": IndexType.CHUNK, "none": IndexType.NONE}[kw["index_types"]]
    with open(path, "wb") as f:
        w = Writer(
            f, chunk_size=CHUNK_BYTES, compression=CompressionType[compression.upper()], **kw
        )
        w.start(profile="ros1" if ros1 else "ros2", library="ertools-fuzz")
        channels = {}
        for topic, ty in TYPES.items():
            text = ts.generate_msgdef(ty, ros_version=1 if ros1 else 2)[0]
            sid = w.register_schema(
                name=ty.replace("/msg/", "/") if ros1 else ty,
                encoding="ros1msg" if ros1 else "ros2msg",
                data=text.encode(),
            )
            channels[topic] = w.register_channel(
                topic=topic, message_encoding="ros1" if ros1 else "cdr", schema_id=sid
            )
        for seq, (topic, t, msg) in enumerate(messages(ts, ros1)):
            ser = ts.serialize_ros1 if ros1 else ts.serialize_cdr
            w.add_message(
                channels[topic],
                log_time=t,
                data=ser(msg, TYPES[topic]),
                publish_time=t,
                sequence=seq,
            )
        w.finish()


@cache
def seed_bytes(name: str) -> bytes:
    """The bytes of one seed file (written once per process into a temporary folder)."""
    import tempfile
    from pathlib import Path

    container, compression, opts = SEEDS[name]
    with tempfile.TemporaryDirectory(prefix="ertools-fuzz-seed-") as tmp:
        path = Path(tmp) / ("seed.bag" if container == "ros1" else "seed.mcap")
        if container == "ros1":
            _ros1(path, compression)
        else:
            _mcap(path, container, compression, opts)
        return path.read_bytes()


def suffix(name: str) -> str:
    return ".bag" if SEEDS[name][0] == "ros1" else ".mcap"
