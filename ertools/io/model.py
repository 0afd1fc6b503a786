"""Plain records the reader layer hands out: summaries, pose sources, state streams,
connections."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ertools.frozen_dataclass import frozen_dataclass

if TYPE_CHECKING:  # annotations only: options hold a PoseSource, and parsers build options
    from ertools.streams import StateStream

# Bag formats :func:`ertools.io.formats.detect_format` tells apart.
FORMATS = ("ros1", "ros1-active", "rosbag2-sqlite3", "rosbag2-mcap", "mcap")

POSE_TYPES = (
    "geometry_msgs/PoseStamped",
    "geometry_msgs/Pose2D",
    "geometry_msgs/TransformStamped",
    "geometry_msgs/PoseWithCovarianceStamped",
    "nav_msgs/Odometry",
    "tf/tfMessage",
    "tf2_msgs/TFMessage",
)
TF_TYPES = ("tf/tfMessage", "tf2_msgs/TFMessage")


@frozen_dataclass
class TopicSummary:
    """One topic of a bag, from the file's index.

    Attributes:
        name: topic name.
        msgtype: ROS type in ``pkg/Type`` form (rosbag2's ``pkg/msg/Type`` is shortened).
        count: number of messages.
        first_ns: record time of the first message (int64 ns), None when the topic is empty.
        last_ns: record time of the last message, None when the topic is empty.
        connections: number of connections (ROS1) or channels (MCAP) carrying the topic.
    """

    name: str
    msgtype: str
    count: int
    first_ns: int | None
    last_ns: int | None
    connections: int


@frozen_dataclass
class BagSummary:
    """What a bag holds, read from its own index (no message data).

    Attributes:
        path: the file or rosbag2 directory.
        format: one of ``ros1``, ``ros1-active``, ``rosbag2-sqlite3``, ``rosbag2-mcap``, ``mcap``.
        version: format version text (``2.0`` for ROS1, the MCAP profile/library, rosbag2's
            metadata version).
        start_ns: record time of the first message (0 for an empty bag).
        end_ns: record time of the last message (0 for an empty bag).
        duration_ns: ``end_ns - start_ns``.
        size_bytes: bytes on disk (all files of a rosbag2 directory).
        compression: ``none``, ``bz2``, ``lz4``, ``zstd`` or a combination like ``lz4/none``.
        message_count: messages in all topics.
        indexed: False when the file had no usable index and was scanned.
        topics: per-topic summaries, sorted by name.
        problems: what is wrong with the file (unindexed, truncated...), one line each.
        index: which of the file's indexes answered (MCAP: ``summary+message-indexes``,
            ``summary`` or ``scan``; ROS1: ``index-records`` or ``scan``; rosbag2:
            ``metadata.yaml``, plus what its MCAP files used).
    """

    path: str
    format: str
    version: str
    start_ns: int
    end_ns: int
    duration_ns: int
    size_bytes: int
    compression: str
    message_count: int
    indexed: bool
    topics: tuple[TopicSummary, ...]
    problems: tuple[str, ...] = ()
    index: str = ""

    def topic(self, name: str) -> TopicSummary | None:
        """The summary of one topic, None when absent."""
        return next((t for t in self.topics if t.name == name), None)


@frozen_dataclass
class PoseSource:
    """Where a pose stream comes from: a pose topic, or a tf frame.

    Attributes:
        topic: a pose topic (PoseStamped, Pose2D, TransformStamped, PoseWithCovarianceStamped,
            Odometry); None to use tf.
        frame: the tf child frame when ``topic`` is None (or ``/tf``).
        parent: the tf parent frame (default ``world``, the mocap frame).
        time_source: ``header`` (message stamp) or ``record`` (bag record time).
    """

    topic: str | None = None
    frame: str | None = None
    parent: str = "world"
    time_source: str = "header"


@frozen_dataclass
class BenchmarkStates:
    """The three state streams of one benchmark namespace; None where a topic is absent."""

    bmbox: StateStream | None
    refbox: StateStream | None
    client: StateStream | None


@frozen_dataclass
class Conn:
    """One connection (ROS1), rosbag2 topic or MCAP channel.

    Attributes:
        id: the file's own id of the connection.
        topic: topic name.
        msgtype: ``pkg/Type``.
        msgdef: stored message definition text ("" when the file has none).
        msgdef_format: ``msg`` or ``idl`` ("" when none).
        encoding: ``ros1`` or ``cdr``.
        latching: True for latched connections (ROS1) / transient-local QoS.
        digest: md5 (ROS1) or type hash, "" when none.
    """

    id: int
    topic: str
    msgtype: str
    msgdef: str
    msgdef_format: str
    encoding: str
    latching: bool = False
    digest: str = ""


def short_msgtype(msgtype: str) -> str:
    """``geometry_msgs/msg/PoseStamped`` -> ``geometry_msgs/PoseStamped``.

    Only ``msg`` is dropped: rosbag2's service events (``pkg/srv/Name_Event``) and action
    topics (``pkg/action/Name_FeedbackMessage``) keep their kind, which is part of the name
    (a ``pkg/Name_Event`` message type is another type, and the definitions are looked up
    by the full name).
    """
    parts = msgtype.split("/")
    if len(parts) == 3 and parts[1] == "msg":
        return f"{parts[0]}/{parts[2]}"
    return msgtype


def long_msgtype(msgtype: str) -> str:
    """``geometry_msgs/PoseStamped`` -> ``geometry_msgs/msg/PoseStamped`` (rosbags' names)."""
    parts = msgtype.split("/")
    if len(parts) == 2:
        return f"{parts[0]}/msg/{parts[1]}"
    return msgtype
