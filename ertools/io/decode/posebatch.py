"""Decoded pose messages as arrays, before they become a :class:`PoseStream`.

Both decoders produce a :class:`PoseBatch`: the bulk NumPy one (:mod:`ertools.io.decode.fast`)
and the per-message fallback here (rosbags' deserializer). Tests compare the two field by field.
A TF message with several transforms gives one row per transform, in message order.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from ertools.arrays import F64, I32, I64
from ertools.frozen_dataclass import frozen_dataclass
from ertools.geometry import quat_from_yaw
from ertools.io.model import short_msgtype

STAMPED_TYPES = (
    "geometry_msgs/PoseStamped",
    "geometry_msgs/TransformStamped",
    "geometry_msgs/PoseWithCovarianceStamped",
    "nav_msgs/Odometry",
    "tf/tfMessage",
    "tf2_msgs/TFMessage",
)


@frozen_dataclass(eq=False)
class PoseBatch:
    """Poses of one topic in reading order.

    Attributes:
        t_record: (N,) record (log) time ns.
        t_header: (N,) header stamp ns; equal to ``t_record`` for types with no header.
        xyz: (N, 3) positions.
        quat_xyzw: (N, 4) orientations as stored (not renormalised).
        frame_idx: (N,) index into ``frames`` of each parent frame ("" when none).
        child_idx: (N,) index into ``frames`` of each child frame ("" when none).
        frames: the distinct frame names.
    """

    t_record: I64
    t_header: I64
    xyz: F64
    quat_xyzw: F64
    frame_idx: I32
    child_idx: I32
    frames: tuple[str, ...]

    def __len__(self) -> int:
        return int(self.t_record.shape[0])

    def take(self, index: npt.NDArray[np.intp] | npt.NDArray[np.bool_] | slice) -> PoseBatch:
        return PoseBatch(
            self.t_record[index],
            self.t_header[index],
            self.xyz[index],
            self.quat_xyzw[index],
            self.frame_idx[index],
            self.child_idx[index],
            self.frames,
        )

    def frame_names(self) -> npt.NDArray[np.str_]:
        """(N,) parent frame names."""
        return (
            np.asarray(self.frames, dtype=np.str_)[self.frame_idx]
            if len(self)
            else np.empty(0, np.str_)
        )

    def child_names(self) -> npt.NDArray[np.str_]:
        """(N,) child frame names."""
        return (
            np.asarray(self.frames, dtype=np.str_)[self.child_idx]
            if len(self)
            else np.empty(0, np.str_)
        )

    @staticmethod
    def empty() -> PoseBatch:
        return PoseBatch(
            np.empty(0, np.int64),
            np.empty(0, np.int64),
            np.empty((0, 3)),
            np.empty((0, 4)),
            np.empty(0, np.int32),
            np.empty(0, np.int32),
            ("",),
        )


def concat_batches(batches: Sequence[PoseBatch]) -> PoseBatch:
    """Join batches end to end, unifying their frame tables."""
    batches = [b for b in batches if len(b)]
    if not batches:
        return PoseBatch.empty()
    if len(batches) == 1:
        return batches[0]
    frames: dict[str, int] = {}
    parents = []
    children = []
    for b in batches:
        remap = np.array([frames.setdefault(f, len(frames)) for f in b.frames], dtype=np.int32)
        parents.append(remap[b.frame_idx])
        children.append(remap[b.child_idx])
    return PoseBatch(
        np.concatenate([b.t_record for b in batches]),
        np.concatenate([b.t_header for b in batches]),
        np.concatenate([b.xyz for b in batches]),
        np.concatenate([b.quat_xyzw for b in batches]),
        np.concatenate(parents),
        np.concatenate(children),
        tuple(frames),
    )


def _stamp_ns(stamp: Any) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def batch_from_messages(msgtype: str, records: Sequence[tuple[int, Any]]) -> PoseBatch:
    """The fallback decoder: (record time, rosbags message) pairs of one pose type to arrays.

    Raises:
        ValueError: ``msgtype`` is not a pose type.
    """

    kind = short_msgtype(msgtype)
    t_rec: list[int] = []
    t_hdr: list[int] = []
    vals: list[tuple[float, ...]] = []
    parents: list[str] = []
    children: list[str] = []
    for t, msg in records:
        if kind == "geometry_msgs/PoseStamped":
            p, q = msg.pose.position, msg.pose.orientation
            entries = [(msg.header, "", p, q)]
        elif kind == "geometry_msgs/TransformStamped":
            tr = msg.transform
            entries = [(msg.header, msg.child_frame_id, tr.translation, tr.rotation)]
        elif kind == "nav_msgs/Odometry":
            p, q = msg.pose.pose.position, msg.pose.pose.orientation
            entries = [(msg.header, msg.child_frame_id, p, q)]
        elif kind == "geometry_msgs/PoseWithCovarianceStamped":
            p, q = msg.pose.pose.position, msg.pose.pose.orientation
            entries = [(msg.header, "", p, q)]
        elif kind in ("tf/tfMessage", "tf2_msgs/TFMessage"):
            entries = [
                (x.header, x.child_frame_id, x.transform.translation, x.transform.rotation)
                for x in msg.transforms
            ]
        elif kind == "geometry_msgs/Pose2D":
            t_rec.append(t)
            t_hdr.append(t)
            yaw = float(msg.theta)
            vals.append((float(msg.x), float(msg.y), 0.0, yaw))
            parents.append("")
            children.append("")
            continue
        else:
            raise ValueError(f"{msgtype} is not a pose type")
        for header, child, p, q in entries:
            t_rec.append(t)
            t_hdr.append(_stamp_ns(header.stamp))
            vals.append((p.x, p.y, p.z, q.x, q.y, q.z, q.w))
            parents.append(str(header.frame_id))
            children.append(str(child))
    n = len(t_rec)
    if kind == "geometry_msgs/Pose2D":
        arr = np.array(vals, dtype=np.float64).reshape(n, 4)
        xyz = arr[:, :3].copy()
        quat = quat_from_yaw(arr[:, 3]).reshape(n, 4)
    else:
        arr = np.array(vals, dtype=np.float64).reshape(n, 7)
        xyz = arr[:, :3].copy()
        quat = arr[:, 3:].copy()
    frames: dict[str, int] = {"": 0}
    frame_idx = np.array([frames.setdefault(f, len(frames)) for f in parents], dtype=np.int32)
    child_idx = np.array([frames.setdefault(f, len(frames)) for f in children], dtype=np.int32)
    return PoseBatch(
        np.array(t_rec, dtype=np.int64),
        np.array(t_hdr, dtype=np.int64),
        xyz,
        quat,
        frame_idx,
        child_idx,
        tuple(frames),
    )
