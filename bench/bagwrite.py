"""Fast, vectorised writers for the benchmark's hour-long bags (ROS1 v2.0 and MCAP).

rosbags' writer serializes one message at a time (minutes for 1.3 M messages); here every
message of a topic is built at once from a template serialized by rosbags (so the layout is
rosbags'), with the changing fields (seq, stamp, floats) written in with NumPy. The ROS1 file
is laid out as rosbag record writes it: bag header padded to 4096 bytes, chunks of ~768 KiB
(connection records in the chunk before a connection's first message), index-data records
after each chunk, then connection and chunk-info records. ``run.py`` checks that rosbags reads
every file back identically.
"""

from __future__ import annotations

import bz2
import itertools
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np
import numpy.typing as npt

U8 = npt.NDArray[np.uint8]
I64 = npt.NDArray[np.int64]
F64 = npt.NDArray[np.float64]

CHUNK_BYTES = 768 * 1024


@dataclass
class Topic:
    """All messages of one connection: record times and serialized bytes (fixed size)."""

    name: str
    msgtype: str  # pkg/Type
    msgdef: str
    md5: str
    t_ns: I64
    data: U8  # (N, L)
    callerid: str = "/mocap_node"
    latching: bool = False


def typestore(ros1: bool) -> Any:
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    if ros1:
        ts.register(
            get_types_from_msg(
                "geometry_msgs/TransformStamped[] transforms\n", "tf2_msgs/msg/TFMessage"
            )
        )
    return ts


def _template(ts: Any, msgtype: str, frame: str, child: str, ros1: bool) -> tuple[bytes, int, int]:
    """(bytes of one message, offset of the stamp (-1: none), offset of the trailing floats)."""
    T = ts.types
    long = msgtype.replace("/", "/msg/")
    time = T["builtin_interfaces/msg/Time"](sec=0x11111111, nanosec=0x22222222)
    header = (
        T["std_msgs/msg/Header"](seq=0x33333333, stamp=time, frame_id=frame)
        if ros1
        else T["std_msgs/msg/Header"](stamp=time, frame_id=frame)
    )
    pose = T["geometry_msgs/msg/Pose"](
        T["geometry_msgs/msg/Point"](1.0, 2.0, 3.0),
        T["geometry_msgs/msg/Quaternion"](0.0, 0.0, 0.0, 1.0),
    )
    tfs = T["geometry_msgs/msg/TransformStamped"](
        header=header,
        child_frame_id=child,
        transform=T["geometry_msgs/msg/Transform"](
            T["geometry_msgs/msg/Vector3"](1.0, 2.0, 3.0),
            T["geometry_msgs/msg/Quaternion"](0.0, 0.0, 0.0, 1.0),
        ),
    )
    if msgtype == "geometry_msgs/PoseStamped":
        msg = T[long](header=header, pose=pose)
    elif msgtype == "geometry_msgs/Pose2D":
        msg = T[long](x=1.0, y=2.0, theta=3.0)
    elif msgtype == "tf2_msgs/TFMessage":
        msg = T[long](transforms=[tfs])
    else:
        raise ValueError(msgtype)
    raw = bytes(ts.serialize_ros1(msg, long) if ros1 else ts.serialize_cdr(msg, long))
    stamp = raw.find(struct.pack("<II", 0x11111111, 0x22222222))
    nfloat = 3 if msgtype == "geometry_msgs/Pose2D" else 7
    return raw, stamp, len(raw) - 8 * nfloat


def build(
    ts: Any,
    msgtype: str,
    stamps_ns: I64,
    values: F64,
    *,
    frame: str = "world",
    child: str = "",
    ros1: bool = True,
) -> U8:
    """(N, L) serialized messages: the template with seq, stamp and floats replaced."""
    raw, stamp_at, float_at = _template(ts, msgtype, frame, child, ros1)
    n = len(stamps_ns)
    out = np.tile(np.frombuffer(raw, dtype=np.uint8), (n, 1))
    if stamp_at >= 0:
        sec = (stamps_ns // 1_000_000_000).astype("<u4")
        nsec = (stamps_ns % 1_000_000_000).astype("<u4")
        out[:, stamp_at : stamp_at + 4] = sec.view(np.uint8).reshape(n, 4)
        out[:, stamp_at + 4 : stamp_at + 8] = nsec.view(np.uint8).reshape(n, 4)
        if ros1:
            seq = np.arange(n, dtype="<u4")
            out[:, stamp_at - 4 : stamp_at] = seq.view(np.uint8).reshape(n, 4)
    floats = np.ascontiguousarray(values, dtype="<f8")
    out[:, float_at:] = floats.view(np.uint8).reshape(n, -1)
    return out


def msgdef(ts: Any, msgtype: str, ros1: bool = True) -> tuple[str, str]:
    text, md5 = ts.generate_msgdef(msgtype.replace("/", "/msg/"), ros_version=1 if ros1 else 2)
    return str(text), str(md5)


# --- ROS1 -------------------------------------------------------------------------------------


def _field(name: str, value: bytes) -> bytes:
    body = name.encode() + b"=" + value
    return struct.pack("<I", len(body)) + body


def _record(fields: list[tuple[str, bytes]], data: bytes) -> bytes:
    header = b"".join(_field(k, v) for k, v in fields)
    return struct.pack("<I", len(header)) + header + struct.pack("<I", len(data)) + data


def _time(ns: int) -> bytes:
    return struct.pack("<II", ns // 1_000_000_000, ns % 1_000_000_000)


def _connection(cid: int, topic: Topic) -> bytes:
    data = b"".join(
        _field(k, v.encode())
        for k, v in (
            ("topic", topic.name),
            ("type", topic.msgtype),
            ("md5sum", topic.md5),
            ("message_definition", topic.msgdef),
            ("callerid", topic.callerid),
            ("latching", "1" if topic.latching else "0"),
        )
    )
    return _record(
        [("op", b"\x07"), ("conn", struct.pack("<I", cid)), ("topic", topic.name.encode())], data
    )


def _msg_records(cid: int, t_ns: I64, data: U8) -> U8:
    """(N, 8 + 38 + L) message-data records of one connection (conn, op, time fields)."""
    n, length = data.shape
    rec = np.dtype(
        [
            ("hlen", "<u4"),
            ("l1", "<u4"), ("k1", "S5"), ("conn", "<u4"),
            ("l2", "<u4"), ("k2", "S3"), ("op", "u1"),
            ("l3", "<u4"), ("k3", "S5"), ("sec", "<u4"), ("nsec", "<u4"),
            ("dlen", "<u4"),
            ("data", "u1", (length,)),
        ]
    )  # fmt: skip
    arr = np.zeros(n, dtype=rec)
    arr["hlen"], arr["l1"], arr["k1"], arr["conn"] = 38, 9, b"conn=", cid
    arr["l2"], arr["k2"], arr["op"] = 4, b"op=", 2
    arr["l3"], arr["k3"] = 13, b"time="
    arr["sec"], arr["nsec"] = t_ns // 1_000_000_000, t_ns % 1_000_000_000
    arr["dlen"], arr["data"] = length, data
    return arr.view(np.uint8).reshape(n, rec.itemsize)


def write_ros1(path: Path, topics: list[Topic], compression: str = "none") -> None:
    """A ROS1 v2.0 bag of ``topics`` (messages interleaved by record time)."""
    conn_of = np.concatenate([np.full(len(t.t_ns), i, np.int64) for i, t in enumerate(topics)])
    t_all = np.concatenate([t.t_ns for t in topics])
    row_of = np.concatenate([np.arange(len(t.t_ns)) for t in topics])
    order = np.lexsort((conn_of, t_all))
    conn_of, t_all, row_of = conn_of[order], t_all[order], row_of[order]
    records = [_msg_records(i, t.t_ns, t.data) for i, t in enumerate(topics)]
    size_of = np.array([r.shape[1] for r in records], dtype=np.int64)[conn_of]
    ends = np.cumsum(size_of)
    # chunk boundaries every ~CHUNK_BYTES of records
    cut = np.searchsorted(ends, np.arange(CHUNK_BYTES, int(ends[-1]) + CHUNK_BYTES, CHUNK_BYTES))
    bounds = np.unique(np.concatenate([[0], np.minimum(cut + 1, len(ends))]))
    seen: set[int] = set()
    chunk_infos: list[tuple[int, int, int, dict[int, int]]] = []
    with path.open("wb") as f:
        f.write(b"#ROSBAG V2.0\n")
        header_pos = f.tell()
        f.write(b"\0" * 4096)
        for a, b in itertools.pairwise(bounds):
            conns = conn_of[a:b]
            prefix = b"".join(
                _connection(int(c), topics[int(c)])
                for c in dict.fromkeys(conns.tolist())
                if c not in seen
            )
            seen.update(conns.tolist())
            sizes = size_of[a:b]
            offs = np.concatenate([[0], np.cumsum(sizes)[:-1]]) + len(prefix)
            body = np.zeros(len(prefix) + int(sizes.sum()), dtype=np.uint8)
            body[: len(prefix)] = np.frombuffer(prefix, dtype=np.uint8)
            for c in np.unique(conns):
                sel = np.flatnonzero(conns == c)
                rec = records[int(c)][row_of[a:b][sel]]
                body[offs[sel][:, None] + np.arange(rec.shape[1])] = rec
            raw = body.tobytes()
            packed = _compress(compression, raw)
            pos = f.tell()
            f.write(
                _record(
                    [
                        ("op", b"\x05"),
                        ("compression", compression.encode()),
                        ("size", struct.pack("<I", len(raw))),
                    ],
                    packed,
                )
            )
            counts: dict[int, int] = {}
            for c in np.unique(conns):
                sel = np.flatnonzero(conns == c)
                t = t_all[a:b][sel]
                idx = np.zeros(len(sel), dtype=[("sec", "<u4"), ("nsec", "<u4"), ("off", "<u4")])
                idx["sec"], idx["nsec"], idx["off"] = (
                    t // 1_000_000_000,
                    t % 1_000_000_000,
                    offs[sel],
                )
                f.write(
                    _record(
                        [
                            ("op", b"\x04"),
                            ("ver", struct.pack("<I", 1)),
                            ("conn", struct.pack("<I", int(c))),
                            ("count", struct.pack("<I", len(sel))),
                        ],
                        idx.tobytes(),
                    )
                )
                counts[int(c)] = len(sel)
            chunk_infos.append((pos, int(t_all[a:b].min()), int(t_all[a:b].max()), counts))
        index_pos = f.tell()
        for i, t in enumerate(topics):
            f.write(_connection(i, t))
        for pos, start, end, counts in chunk_infos:
            data = b"".join(struct.pack("<II", c, n) for c, n in sorted(counts.items()))
            f.write(
                _record(
                    [
                        ("op", b"\x06"),
                        ("ver", struct.pack("<I", 1)),
                        ("chunk_pos", struct.pack("<Q", pos)),
                        ("start_time", _time(start)),
                        ("end_time", _time(end)),
                        ("count", struct.pack("<I", len(counts))),
                    ],
                    data,
                )
            )  # fmt: skip
        _write_header(f, header_pos, index_pos, len(topics), len(chunk_infos))


def _write_header(f: BinaryIO, pos: int, index_pos: int, nconn: int, nchunk: int) -> None:
    fields = [
        ("op", b"\x03"),
        ("index_pos", struct.pack("<Q", index_pos)),
        ("conn_count", struct.pack("<I", nconn)),
        ("chunk_count", struct.pack("<I", nchunk)),
    ]
    header = b"".join(_field(k, v) for k, v in fields)
    pad = 4096 - 4 - len(header) - 4
    f.seek(pos)
    f.write(struct.pack("<I", len(header)) + header + struct.pack("<I", pad) + b" " * pad)


def _compress(compression: str, raw: bytes) -> bytes:
    if compression == "none":
        return raw
    if compression == "bz2":
        return bz2.compress(raw, 9)
    if compression == "lz4":
        import lz4.frame

        return bytes(lz4.frame.compress(raw))
    raise ValueError(compression)


# --- MCAP -------------------------------------------------------------------------------------


def write_mcap(
    path: Path, topics: list[Topic], schemas: dict[str, str], compression: str = "zstd"
) -> None:
    """An MCAP file (ROS 2 profile, CDR) via the ``mcap`` library's writer."""
    from mcap.writer import CompressionType, Writer

    conn_of = np.concatenate([np.full(len(t.t_ns), i, np.int64) for i, t in enumerate(topics)])
    t_all = np.concatenate([t.t_ns for t in topics])
    row_of = np.concatenate([np.arange(len(t.t_ns)) for t in topics])
    order = np.lexsort((conn_of, t_all))
    with path.open("wb") as f:
        w = Writer(f, compression=CompressionType[compression.upper()])
        w.start(profile="ros2", library="ertools-bench")
        sids = {
            ty: w.register_schema(
                name=ty.replace("/", "/msg/"), encoding="ros2msg", data=schemas[ty].encode()
            )
            for ty in {t.msgtype for t in topics}
        }
        cids = [
            w.register_channel(topic=t.name, message_encoding="cdr", schema_id=sids[t.msgtype])
            for t in topics
        ]
        datas = [[bytes(row) for row in t.data] for t in topics]
        for c, t, r in zip(
            conn_of[order].tolist(), t_all[order].tolist(), row_of[order].tolist(), strict=True
        ):
            w.add_message(cids[c], log_time=t, publish_time=t, data=datas[c][r], sequence=r)
        w.finish()
