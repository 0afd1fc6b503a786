"""The scripts' ``Pose2D_from_tf_concatenation`` (the same in the five scripts of 2bb8a41; the
HGMF copy also returns the height), statement by statement.

Per attempt: ``now``; wait for ``original_target`` in ``source`` at ``now``; broadcast
``new_target`` under ``original_target`` at ``now`` with the given transform; wait for it; look
it up at time 0; yaw from tf's Euler angles. A tf error counts a failed attempt. The loop runs
while no pose was acquired and the benchmark runs, and stops after ``max_failed_attempts``
failures (None: no limit).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from tests.helpers.rsbb_replay.py2 import euler_yaw
from tests.helpers.rsbb_replay.tf2 import TfError
from tests.helpers.rsbb_replay.world import World


@dataclass
class Pose2D:
    """``geometry_msgs/Pose2D``."""

    x: Any
    y: Any
    theta: Any


def pose2d_from_tf_concatenation(
    w: World,
    new_target_frame: str,
    translation: Any,
    orientation: Any,
    original_target_frame: str,
    source_frame: str,
    max_failed_attempts: int | None = None,
    timeout: float = 1.0,
    *,
    with_height: bool = False,
) -> Any:
    """The helper; returns the Pose2D or None (``(pose, height)`` with ``with_height``)."""
    attempts = 0
    pose_acquired = False
    pose2d = None
    height = None
    while not pose_acquired and w.is_benchmark_running():
        if max_failed_attempts is not None and attempts >= max_failed_attempts:
            break
        try:
            now = w.now("lookup", new_target_frame, timeout)
            w.wait_for_transform(source_frame, original_target_frame, now, timeout)
            w.send_transform(translation, orientation, now, new_target_frame, original_target_frame)
            w.wait_for_transform(source_frame, new_target_frame, now, timeout)
            (x, y, z), q = w.lookup_transform(source_frame, new_target_frame, 0)
            height = z
            theta = euler_yaw(q)
            pose2d = Pose2D(x, y, theta)
            pose_acquired = True
        except TfError:
            attempts += 1
            pose_acquired = False
    if with_height:
        return pose2d, height
    return pose2d
