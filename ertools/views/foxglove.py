"""Foxglove messages built from arrays, collected by topic for one MCAP file.

The well-known schemas (``foxglove.PoseInFrame``, ``foxglove.SceneUpdate``, ``foxglove.Log``...)
come from ``foxglove-schemas-protobuf``, the classes Foxglove generates from its own ``.proto``
files: the schema written into the file is their descriptor, so it is Foxglove's schema
exactly. Values Foxglove has no schema for (per-pose errors, per-run scores) go to JSON topics
with a small JSON schema of ertools' own, which Foxglove's Plot and Raw Messages panels read.
Nothing here touches a file (:mod:`ertools.report.foxglove.mcapout` does).
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt
from foxglove_schemas_protobuf.ArrowPrimitive_pb2 import ArrowPrimitive
from foxglove_schemas_protobuf.LinePrimitive_pb2 import LinePrimitive
from foxglove_schemas_protobuf.Log_pb2 import Log
from foxglove_schemas_protobuf.Point3_pb2 import Point3
from foxglove_schemas_protobuf.PoseInFrame_pb2 import PoseInFrame
from foxglove_schemas_protobuf.PosesInFrame_pb2 import PosesInFrame
from foxglove_schemas_protobuf.SceneEntity_pb2 import SceneEntity
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from foxglove_schemas_protobuf.TextPrimitive_pb2 import TextPrimitive
from google.protobuf.message import Message

from ertools.arrays import F64, I64
from ertools.fidelity import differs_line
from ertools.frozen_dataclass import frozen_dataclass
from ertools.serialize import jsonable

WORLD = "world"  # the mocap frame every pose of a 2015 benchmark is in

# Colours of the 3D panel: GT / target green, robot blue, errors red, labels white.
GREEN = (0.2, 0.8, 0.3, 1.0)
BLUE = (0.25, 0.5, 1.0, 1.0)
RED = (1.0, 0.3, 0.25, 1.0)
GREY = (0.7, 0.7, 0.7, 1.0)
WHITE = (1.0, 1.0, 1.0, 1.0)

# Log levels of foxglove.Log (its enum, by name).
INFO, WARNING, ERROR = Log.Level.INFO, Log.Level.WARNING, Log.Level.ERROR


@frozen_dataclass
class Channel:
    """One topic's schema: name, schema encoding and bytes, message encoding."""

    schema_name: str
    schema_encoding: str
    schema_data: bytes
    message_encoding: str


@dataclass
class Collected:
    """Messages for one file: ``(log time, topic, bytes)`` in the order added, and channels.

    A builder (mutable on purpose): the per-benchmark content functions add to it, the MCAP
    writer sorts it by time once.
    """

    messages: list[tuple[int, str, bytes]] = field(default_factory=list)
    channels: dict[str, Channel] = field(default_factory=dict)
    metadata: dict[str, str] = field(default_factory=dict)

    def _channel(self, topic: str, channel: Channel) -> None:
        known = self.channels.setdefault(topic, channel)
        if known.schema_name != channel.schema_name:
            raise ValueError(f"{topic}: {channel.schema_name} after {known.schema_name}")

    def proto(self, topic: str, t_ns: int, message: Message) -> None:
        """A protobuf message (a Foxglove well-known schema) logged at ``t_ns``."""
        desc = message.DESCRIPTOR
        self._channel(topic, Channel(desc.full_name, "protobuf", descriptor_set(desc), "protobuf"))
        self.messages.append((int(t_ns), topic, message.SerializeToString()))

    def json(self, topic: str, t_ns: int, schema: JsonSchema, data: Mapping[str, Any]) -> None:
        """A JSON message of one of ertools' own schemas logged at ``t_ns``."""
        self._channel(topic, schema.channel)
        text = json.dumps(jsonable(dict(data)), allow_nan=False, separators=(",", ":"))
        self.messages.append((int(t_ns), topic, text.encode("utf-8")))

    @property
    def first_ns(self) -> int:
        """The earliest log time so far (0 when empty): where file-wide notes are logged."""
        return min((t for t, _, _ in self.messages), default=0)


_DESCRIPTOR_SETS: dict[str, bytes] = {}


def descriptor_set(desc: Any) -> bytes:
    """The ``FileDescriptorSet`` of a message type and every file it imports (MCAP protobuf).

    MCAP's protobuf profile stores the schema as a serialised FileDescriptorSet holding the
    message's file and its dependencies (``google/protobuf/timestamp.proto``...), so that a
    reader can decode without the generated classes.
    """
    name = desc.full_name
    if name not in _DESCRIPTOR_SETS:
        from google.protobuf.descriptor_pb2 import FileDescriptorSet  # lazy: protobuf, 50 ms

        fds = FileDescriptorSet()
        seen: set[str] = set()

        def add(fd: Any) -> None:
            if fd.name in seen:
                return
            seen.add(fd.name)
            for dep in fd.dependencies:
                add(dep)
            fd.CopyToProto(fds.file.add())

        add(desc.file)
        _DESCRIPTOR_SETS[name] = fds.SerializeToString()
    return _DESCRIPTOR_SETS[name]


@frozen_dataclass
class JsonSchema:
    """A JSON schema of ertools' own: a title and ``name -> JSON type`` of its fields.

    Numbers may be null (NaN and "not scored" are null in JSON).
    """

    title: str
    fields: tuple[tuple[str, str], ...]

    @property
    def channel(self) -> Channel:
        props = {
            k: {"type": [v, "null"] if v in ("number", "integer") else v} for k, v in self.fields
        }
        schema = {"title": self.title, "type": "object", "properties": props}
        data = json.dumps(schema, sort_keys=True).encode("utf-8")
        return Channel(self.title, "jsonschema", data, "json")


# --- builders -------------------------------------------------------------------------------


def _stamp(msg: Any, t_ns: int) -> None:
    sec, nsec = divmod(int(t_ns), 1_000_000_000)
    msg.timestamp.seconds = sec
    msg.timestamp.nanos = nsec


def _pose(p: Any, xyz: Sequence[float], q: Sequence[float]) -> None:
    pos, rot = p.position, p.orientation
    pos.x, pos.y, pos.z = float(xyz[0]), float(xyz[1]), float(xyz[2])
    rot.x, rot.y, rot.z, rot.w = float(q[0]), float(q[1]), float(q[2]), float(q[3])


def _color(c: Any, rgba: tuple[float, float, float, float]) -> None:
    c.r, c.g, c.b, c.a = rgba


def yaw_quat(yaw: float) -> tuple[float, float, float, float]:
    """The unit quaternion (x, y, z, w) of a rotation by ``yaw`` about z."""
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


def every(n: int, limit: int) -> npt.NDArray[np.intp]:
    """Indices of every k-th of ``n`` items, k = ceil(n / limit): at most ``limit`` of them."""
    step = max(1, -(-n // max(1, limit)))
    return np.arange(0, n, step, dtype=np.intp)


def pose_stream(
    out: Collected,
    topic: str,
    t_ns: I64,
    xyz: F64,
    quat_xyzw: F64,
    frame_id: str = WORLD,
) -> None:
    """One ``foxglove.PoseInFrame`` per pose, logged at the pose's time."""
    for t, p, q in zip(t_ns.tolist(), xyz.tolist(), quat_xyzw.tolist(), strict=True):
        msg = PoseInFrame(frame_id=frame_id)
        _stamp(msg, t)
        _pose(msg.pose, p, q)
        out.proto(topic, t, msg)


def pose_path(
    out: Collected, topic: str, t_ns: int, xyz: F64, quat_xyzw: F64, frame_id: str = WORLD
) -> None:
    """One ``foxglove.PosesInFrame`` holding a whole path (the 3D panel draws it as a line)."""
    msg = PosesInFrame(frame_id=frame_id)
    _stamp(msg, t_ns)
    for p, q in zip(xyz.tolist(), quat_xyzw.tolist(), strict=True):
        _pose(msg.poses.add(), p, q)
    out.proto(topic, t_ns, msg)


def log(
    out: Collected,
    t_ns: int,
    level: int,
    message: str,
    name: str = "ertools",
    topic: str = "/ertools/log",
) -> None:
    """A ``foxglove.Log`` line (the Log panel), on ``/ertools/log`` unless told."""
    msg = Log(level=level, message=message, name=name)  # type: ignore[arg-type]
    _stamp(msg, t_ns)
    out.proto(topic, t_ns, msg)


def result_notes(out: Collected, result: Any, name: str) -> None:
    """A result's warnings, deviations and failures as Log lines at the file's first time."""
    t = out.first_ns
    for w in result.warnings:
        log(out, t, WARNING, f"warning: {w}", name)
    for d in result.deviations:
        log(out, t, INFO, differs_line(d), name)
    for f in result.failures:
        log(out, t, ERROR, f"error: {f}", name)


class Scene:
    """One ``foxglove.SceneUpdate``: entities built from arrays, all in one frame."""

    def __init__(self, t_ns: int, frame_id: str = WORLD) -> None:
        self.t_ns = int(t_ns)
        self.frame_id = frame_id
        self.msg = SceneUpdate()

    def entity(self, ident: str, lifetime_ns: int | None = None) -> SceneEntity:
        """A new entity; it stays until replaced, or ``lifetime_ns`` after the update."""
        e: SceneEntity = self.msg.entities.add(id=ident, frame_id=self.frame_id)
        _stamp(e, self.t_ns)
        if lifetime_ns is not None and lifetime_ns > 0:
            e.lifetime.seconds, e.lifetime.nanos = divmod(int(lifetime_ns), 1_000_000_000)
        return e

    @staticmethod
    def line(
        e: SceneEntity,
        points: Iterable[Sequence[float]],
        rgba: tuple[float, float, float, float],
        *,
        pairs: bool = False,
        thickness: float = 3.0,
    ) -> None:
        """A line strip through ``points`` (or separate segments when ``pairs``), pixels wide."""
        kind = LinePrimitive.Type.LINE_LIST if pairs else LinePrimitive.Type.LINE_STRIP
        line = e.lines.add(type=kind, thickness=thickness, scale_invariant=True)
        line.pose.orientation.w = 1.0
        _color(line.color, rgba)
        line.points.extend(Point3(x=float(p[0]), y=float(p[1]), z=float(p[2])) for p in points)

    @staticmethod
    def arrow(
        e: SceneEntity,
        xyz: Sequence[float],
        yaw: float,
        rgba: tuple[float, float, float, float],
        length: float = 0.25,
    ) -> None:
        """An arrow at ``xyz`` pointing along ``yaw`` (a 2D pose: waypoint, answer, GT)."""
        a: ArrowPrimitive = e.arrows.add(
            shaft_length=length * 0.7,
            shaft_diameter=length * 0.08,
            head_length=length * 0.3,
            head_diameter=length * 0.2,
        )
        _pose(a.pose, xyz, yaw_quat(yaw))
        _color(a.color, rgba)

    @staticmethod
    def text(e: SceneEntity, xyz: Sequence[float], text: str, size: float = 14.0) -> None:
        """A label facing the camera, ``size`` pixels high."""
        t: TextPrimitive = e.texts.add(
            billboard=True, font_size=size, scale_invariant=True, text=text
        )
        _pose(t.pose, xyz, (0.0, 0.0, 0.0, 1.0))
        _color(t.color, WHITE)

    def add_to(self, out: Collected, topic: str) -> None:
        if len(self.msg.entities):
            out.proto(topic, self.t_ns, self.msg)


def xyz0(xy: F64, z: float = 0.0) -> F64:
    """(N, 2) plane positions as (N, 3) at height ``z``."""
    pts = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    return np.column_stack([pts, np.full(len(pts), z)])
