"""The reader layer: every file ertools reads goes through here.

ROS1 bags (indexed and ``.bag.active``), rosbag2 directories (sqlite3, mcap) and standalone
MCAP files, decoded with the message definitions stored in each file. See ``docs/io.md``.
Importing this package imports NumPy only; rosbags and mcap load on first use.
"""

from ertools.io.model import (
    BagSummary,
    BenchmarkStates,
    PoseSource,
    RawMessage,
    TopicSummary,
)
from ertools.io.reader import (
    read_benchmark_states,
    read_messages,
    read_pose_source,
    read_pose_sources,
    read_poses,
    read_states,
    read_tf,
    topics,
)
from ertools.io.summary import summary

__all__ = [
    "BagSummary",
    "BenchmarkStates",
    "PoseSource",
    "RawMessage",
    "TopicSummary",
    "read_benchmark_states",
    "read_messages",
    "read_pose_source",
    "read_pose_sources",
    "read_poses",
    "read_states",
    "read_tf",
    "summary",
    "topics",
]
