"""Helpers of the trajectory tests: scoring as ``ertools score trajectory`` does, reading bags
back without ertools.io, writing bad bags."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.highlevel import AnyReader

from ertools.benchmarks import registry
from ertools.benchmarks.scoring import score_execution
from ertools.geometry import quat_from_yaw
from ertools.simulator.writer import BagWriter


def score_trajectory(robot: Path, gt_paths: Sequence[Path], **values: Any) -> Any:
    """``ertools score trajectory ROBOT GT...`` with these inputs (by input name): its result."""
    return score_execution(registry.get("trajectory"), [robot, *gt_paths], values).result


def read_back(path: Path, topic: str) -> tuple[list[int], list[list[float]], list[list[float]]]:
    """Header stamps, positions and quaternions of a PoseStamped topic via rosbags directly.

    Independent of ertools.io: the tests compare the scorer with values computed from this.
    """

    t: list[int] = []
    xyz: list[list[float]] = []
    quat: list[list[float]] = []
    with AnyReader([path]) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        for conn, _ts, raw in reader.messages(connections=conns):
            msg = reader.deserialize(raw, conn.msgtype)
            t.append(msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec)
            p, q = msg.pose.position, msg.pose.orientation
            xyz.append([p.x, p.y, p.z])
            quat.append([q.x, q.y, q.z, q.w])
    return t, xyz, quat


def yaw(q: list[float]) -> float:
    x, y, z, w = q
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def write_robot(path: Path, stamps: np.ndarray, xyz: np.ndarray, topic: str) -> Path:
    """A robot log with the given header stamps (record times increase regardless)."""

    rec = np.arange(len(stamps), dtype=np.int64) * 100_000_000 + int(stamps[0])
    with BagWriter(path, "ros1") as bag:
        bag.write_pose_stamped(
            topic, rec, stamps, "world", xyz, quat_from_yaw(np.zeros(len(stamps)))
        )
    return path


def write_gt(path: Path, t: np.ndarray, xyz: np.ndarray, topic: str) -> Path:
    """A GT file with the given header stamps (recorded 0.3 ms later)."""

    with BagWriter(path, "ros1") as bag:
        bag.write_pose_stamped(topic, t + 300_000, t, "world", xyz, quat_from_yaw(np.zeros(len(t))))
    return path
