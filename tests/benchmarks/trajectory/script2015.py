"""rockin_trajectory_benchmark.py (2015), its trajectory part ported statement by statement.

Read in Enri2077/rockin_offline_trajectory_benchmark (commit 0c5b6ec, line numbers as counted
in that copy): ``get_pose_time`` and ``pose_equal_position`` (l. 21-27), ``interpolate``
(l. 44-45: returns p1), ``seek_mocap_pose_at`` (l. 50-74), ``DualIterator`` (l. 78-93:
``itertools.chain.from_iterable`` of the files' message iterators), ``Error`` (l. 96-138), the
GT file selection (l. 179-194: every bag whose ``rosbag info`` span overlaps the robot bag's;
none: exit 4), their order (l. 209: sorted by start) and the trajectory loop (l. 255-279:
exit 6 when the GT runs out). Where the script called ROS, the port does what ROS did:
``rospy.Time`` compares (secs, nsecs) exactly and ``to_sec()`` is ``float(secs) +
float(nsecs) / 1e9``; ``rosbag.Bag.read_messages(topic)`` yields ``(topic, msg, t)`` by record
time; ``tf.transformations.euler_from_quaternion`` is ``node_2015.tf_yaw``. ``output()``
appends the line to a list instead of a file.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

from tests.benchmarks.trajectory.node_2015 import tf_yaw

NS = 1_000_000_000


@dataclass(frozen=True, order=True)
class Time:
    """rospy.Time: compared as (secs, nsecs)."""

    secs: int
    nsecs: int

    @classmethod
    def of(cls, t_ns: int) -> Time:
        return cls(t_ns // NS, t_ns % NS)

    def to_sec(self) -> float:
        return float(self.secs) + float(self.nsecs) / 1e9


@dataclass(frozen=True)
class PoseStamped:
    stamp: Time
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]


@dataclass
class Bag:
    """What the script used of a bag: ``rosbag info`` start/end (record times, all topics)
    and ``read_messages(topic)``."""

    name: str
    messages: list[tuple[str, PoseStamped, int]]  # (topic, msg, record time ns), any order

    def info(self) -> dict[str, float]:
        t = [m[2] for m in self.messages]
        return {"start": Time.of(min(t)).to_sec(), "end": Time.of(max(t)).to_sec()}

    def read_messages(self, topic: str) -> Iterator[tuple[str, PoseStamped, int]]:
        return iter(sorted((m for m in self.messages if m[0] == topic), key=lambda m: m[2]))


class EndOfBag(Exception):  # noqa: N818 (the 2015 name)
    pass


def get_pose_time(pose: PoseStamped) -> Time:
    return pose.stamp


def pose_equal_position(p1: PoseStamped, p2: PoseStamped) -> bool:
    return (
        p1.position[0] == p2.position[0]
        and p1.position[1] == p2.position[1]
        and p1.position[2] == p2.position[2]
    )


def interpolate(robot_pose: Any, mocap_pose_1: Any, mocap_pose_2: Any) -> Any:
    return mocap_pose_1


@dataclass
class Script:
    """One run of the script: its output lines and, at the end, its exit code."""

    out: list[str] = field(default_factory=list)

    def output(self, s: str) -> None:
        self.out.append(s)

    def seek_mocap_pose_at(
        self, t: Time, dual_iterator: DualIterator
    ) -> tuple[PoseStamped, PoseStamped]:
        try:
            mocap_pose_1, mocap_pose_2 = dual_iterator.current()
            t1 = get_pose_time(mocap_pose_1).to_sec()
            t2 = get_pose_time(mocap_pose_2).to_sec()
            while get_pose_time(mocap_pose_2) < t:
                mocap_pose_1, mocap_pose_2 = dual_iterator.next()
                t1 = get_pose_time(mocap_pose_1).to_sec()
                t2 = get_pose_time(mocap_pose_2).to_sec()
                if t2 - t1 > 0.1:
                    self.output("[WARNING] consecutive mocap poses very distant in time")
                if t1 > t2:
                    self.output("[WARNING] poses out of order: result may be invalid.")
        except StopIteration:
            raise EndOfBag from None
        if not (t1 <= t.to_sec() <= t2):
            self.output("[ERROR] ... This should never happen.")
        return mocap_pose_1, mocap_pose_2


class DualIterator:
    def __init__(self, iterable_list: Sequence[Iterator[tuple[str, PoseStamped, int]]]) -> None:
        self.iterator = itertools.chain.from_iterable(iterable_list)
        _, self.i1, _ = next(self.iterator)
        _, self.i2, _ = next(self.iterator)

    def next(self) -> tuple[PoseStamped, PoseStamped]:
        self.i1 = self.i2
        _, self.i2, _ = next(self.iterator)
        return self.i1, self.i2

    def current(self) -> tuple[PoseStamped, PoseStamped]:
        return self.i1, self.i2


class Error:
    def __init__(self) -> None:
        self.n = 0
        self.sum_d = 0.0
        self.sum_sin = 0.0
        self.sum_cos = 0.0

    def update(self, robot_pose: PoseStamped, mocap_pose: PoseStamped) -> None:
        rp = robot_pose.position
        mp = mocap_pose.position
        r_theta = tf_yaw(robot_pose.orientation)
        m_theta = tf_yaw(mocap_pose.orientation)
        self.n = self.n + 1
        self.sum_d = self.sum_d + math.sqrt(
            (rp[0] - mp[0]) ** 2 + (rp[1] - mp[1]) ** 2 + (rp[2] - mp[2]) ** 2
        )
        self.sum_sin = self.sum_sin + math.sin(math.fabs(r_theta - m_theta))
        self.sum_cos = self.sum_cos + math.cos(math.fabs(r_theta - m_theta))

    def get_position_error(self) -> float | None:
        return self.sum_d / self.n if self.n > 0 else None

    def get_orientation_error(self) -> float | None:
        return math.atan2(self.sum_sin, self.sum_cos) if self.n > 0 else None


@dataclass
class Run:
    exit_code: int
    error: Error | None
    out: list[str]
    compared_across_gaps: int  # compared robot poses whose pair is > 0.1 s apart (to_sec)


def run_2015(robot_bag: Bag, mocap_bags: Sequence[Bag], robot_topic: str, mocap_topic: str) -> Run:
    """The script from its bag checks to the trajectory error (its waypoints part, reading an
    empty ``waypoints`` list, is skipped: no robot bag here has ``/roah_rsbb/reached_waypoint``)."""
    script = Script()
    robot_bag_info = robot_bag.info()
    robot_bag_start = robot_bag_info["start"]
    robot_bag_end = robot_bag_info["end"]
    mocap_bags_list = []
    for b in mocap_bags:  # os.listdir order; the sort below makes it irrelevant
        mocap_bag_info = b.info()
        if mocap_bag_info["start"] <= robot_bag_end and mocap_bag_info["end"] >= robot_bag_start:
            mocap_bags_list.append(b)
    if len(mocap_bags_list) == 0:
        return Run(4, None, script.out, 0)
    mocap_bags_list = sorted(mocap_bags_list, key=lambda bag: bag.info()["start"])

    mocap_messages_list = [b.read_messages(mocap_topic) for b in mocap_bags_list]
    mocap_bag_iterator = DualIterator(mocap_messages_list)
    trajectory_error = Error()
    across = 0
    for _, robot_pose, _ in robot_bag.read_messages(robot_topic):
        try:
            mocap_pose_1, mocap_pose_2 = script.seek_mocap_pose_at(
                get_pose_time(robot_pose), mocap_bag_iterator
            )
            if pose_equal_position(mocap_pose_1, mocap_pose_2):
                script.output("[INFO] ignoring pose (tracking was lost)")
                continue
        except EndOfBag:
            script.output("[ERROR] mocap bags are missing")
            return Run(6, None, script.out, across)
        mocap_pose = interpolate(robot_pose, mocap_pose_1, mocap_pose_2)
        span = get_pose_time(mocap_pose_2).to_sec() - get_pose_time(mocap_pose_1).to_sec()
        across += span > 0.1
        trajectory_error.update(robot_pose, mocap_pose)
    return Run(0, trajectory_error, script.out, across)
