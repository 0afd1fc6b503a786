"""ROS 2 messages the recorder writes: PoseStamped, Pose2D and TFMessage, CDR-encoded.

Serialisation and the schema text (the ``ros2msg`` format: the message definition followed by
each dependency after a ``====`` line and ``MSG: pkg/Type``) both come from rosbags' type store,
so the files carry the same definitions ``ros2 bag record`` would write, and any MCAP or ROS 2
tool decodes them.
"""

from __future__ import annotations

import math
from typing import Any

POSE_STAMPED = "geometry_msgs/msg/PoseStamped"
POSE_2D = "geometry_msgs/msg/Pose2D"
TF_MESSAGE = "tf2_msgs/msg/TFMessage"
SCHEMA_ENCODING = "ros2msg"
MESSAGE_ENCODING = "cdr"


def yaw_of(q: tuple[float, float, float, float]) -> float:
    """Yaw of a quaternion (x, y, z, w), as tf's getYaw (ZYX): Pose2D.theta of mocap_optitrack.

    Same formula as :func:`ertools.geometry.yaw_from_quat`, scalar here because the recorder
    handles one body of one frame at a time (and must not import scipy per packet).
    """
    x, y, z, w = q
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


class Ros2Serializer:
    """Builds and serialises the three message types (the type store is loaded once)."""

    def __init__(self) -> None:
        from rosbags.typesys import Stores, get_typestore  # lazy: rosbags, 100 ms

        self._store: Any = get_typestore(Stores.ROS2_HUMBLE)
        t = self._store.types
        self._time = t["builtin_interfaces/msg/Time"]
        self._header = t["std_msgs/msg/Header"]
        self._pose_stamped = t[POSE_STAMPED]
        self._pose = t["geometry_msgs/msg/Pose"]
        self._point = t["geometry_msgs/msg/Point"]
        self._quat = t["geometry_msgs/msg/Quaternion"]
        self._pose2d = t[POSE_2D]
        self._tf = t[TF_MESSAGE]
        self._transform_stamped = t["geometry_msgs/msg/TransformStamped"]
        self._transform = t["geometry_msgs/msg/Transform"]
        self._vector3 = t["geometry_msgs/msg/Vector3"]

    def schema(self, typename: str) -> bytes:
        """The ``ros2msg`` schema text of ``typename`` with its dependencies."""
        text, _ = self._store.generate_msgdef(typename, ros_version=2)
        return str(text).encode("utf-8")

    def _header_of(self, t_ns: int, frame_id: str) -> Any:
        sec, nanosec = divmod(t_ns, 1_000_000_000)
        return self._header(stamp=self._time(sec=sec, nanosec=nanosec), frame_id=frame_id)

    def pose_stamped(
        self,
        t_ns: int,
        frame_id: str,
        xyz: tuple[float, float, float],
        q: tuple[float, float, float, float],
    ) -> bytes:
        msg = self._pose_stamped(
            header=self._header_of(t_ns, frame_id),
            pose=self._pose(
                position=self._point(x=xyz[0], y=xyz[1], z=xyz[2]),
                orientation=self._quat(x=q[0], y=q[1], z=q[2], w=q[3]),
            ),
        )
        return bytes(self._store.serialize_cdr(msg, POSE_STAMPED))

    def pose2d(self, x: float, y: float, theta: float) -> bytes:
        return bytes(self._store.serialize_cdr(self._pose2d(x=x, y=y, theta=theta), POSE_2D))

    def tf(
        self,
        t_ns: int,
        parent: str,
        child: str,
        xyz: tuple[float, float, float],
        q: tuple[float, float, float, float],
    ) -> bytes:
        ts = self._transform_stamped(
            header=self._header_of(t_ns, parent),
            child_frame_id=child,
            transform=self._transform(
                translation=self._vector3(x=xyz[0], y=xyz[1], z=xyz[2]),
                rotation=self._quat(x=q[0], y=q[1], z=q[2], w=q[3]),
            ),
        )
        return bytes(self._store.serialize_cdr(self._tf(transforms=[ts]), TF_MESSAGE))

    def deserialize(self, data: bytes, typename: str) -> Any:
        """Decode a message written by this class (for tests and read-back checks)."""
        return self._store.deserialize_cdr(data, typename)
