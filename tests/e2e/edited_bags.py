"""Copies of the sample logs with chosen poses edited (rosbags' reader and writer): one pose
moved to 1e300 m, a 1 m spike, poses dropped. Everything else is copied byte for byte."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Writer

# (index of the pose on the topic, its (x, y, z)) -> new (x, y, z), or None to drop the message
Edit = Callable[[int, tuple[float, float, float]], tuple[float, float, float] | None]


def edited_copy(src: Path, dst: Path, topic: str, edit: Edit) -> Path:
    """``src`` with the PoseStamped positions of ``topic`` passed through ``edit``, and the
    same sample's ``pose2d`` and ``/tf`` left alone (a scorer reads the one topic it is told)."""
    with AnyReader([src]) as reader, Writer(dst) as w:
        ts = reader.typestore
        conns = {
            c.id: w.add_connection(
                c.topic, c.msgtype, typestore=ts, callerid=getattr(c.ext, "callerid", None)
            )
            for c in reader.connections
        }
        k = 0
        for c, t, raw in reader.messages():
            if c.topic != topic:
                w.write(conns[c.id], t, raw)
                continue
            msg = reader.deserialize(raw, c.msgtype)
            p = msg.pose.position
            new = edit(k, (p.x, p.y, p.z))
            k += 1
            if new is None:
                continue
            p.x, p.y, p.z = new
            w.write(conns[c.id], t, ts.serialize_ros1(msg, c.msgtype))
    return dst


def poses_between(src: Path, topic: str, start_s: float, end_s: float) -> list[int]:
    """Indices on ``topic`` of the poses recorded from ``start_s`` to ``end_s`` seconds after
    the log's first message."""
    with AnyReader([src]) as reader:
        t0 = reader.start_time
        conns = [c for c in reader.connections if c.topic == topic]
        times = [t for _, t, _ in reader.messages(connections=conns)]
    return [i for i, t in enumerate(times) if start_s <= (t - t0) / 1e9 <= end_s]
