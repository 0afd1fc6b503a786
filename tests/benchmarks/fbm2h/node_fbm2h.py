"""``scripts/fbm2h`` at 50b173b (2015-11-30), the FBM2@Home node of RoCKIn 2015, replayed.

rockin-robot-challenge/benchmark_and_scoring_fbm, read at the commit (``git show
50b173b:scripts/fbm2h``); line numbers are that file's. The same file (blob 9abe295) is the
node of the Lisbon 2016 second local competition (40ba68b) and of the Lisbon 2017 major
tournament (89dfa75); its arithmetic is 0e7a367's (2015-11-20, competition day one), which
50b173b only made retry a tf lookup that timed out (line 152). The BmBox is
``tests/helpers/bmbox2015.py``. This is ``main()`` (15-252) statement by statement:

- ``N = len(waypoints)``, ``i = 0`` (39-40): segments 0 to N-1;
- ``benchmark.WaitClient()`` (94); ``while benchmark.Running() and not benchmark.Timeout() and
  i < N`` (97);
- ``SendGoal`` (100-103), ``start_segment_time = time.time()`` (108), ``WaitResult()`` (112),
  ``end_segment_time = time.time()`` and ``segment_time`` (121-122);
- the pose (127-155): ``now = rospy.Time.now()``, the team's ``marker_to_robot_transform``
  broadcast as ``actual_robot`` under ``robot_at_home`` stamped ``now``, then
  ``lookupTransform('/world', '/actual_robot', rospy.Time(0))``: the latest common time of the
  chain, ``now`` itself (the mocap has samples past it once ``waitForTransform`` returned), so
  the marker pose tf interpolates at ``now`` (linear, SLERP) composed with the transform, its
  yaw by ``euler_from_quaternion``;
- ``if benchmark.Timeout() and not benchmark.Running()`` (158-164): never true (one payload is
  not both strings), so ``refbox_timeout`` is always False and nothing is skipped;
- ``if benchmark.Timeout(): timeouts = timeouts + 1`` (168-173), the segment's ``timeout``;
- the ``not benchmark.Running()`` check commented out (175-179): a stopped segment is scored
  like any other;
- the errors and the sums (202-214), ``execution_time += segment_time`` (217), ``i = i + 1``
  (221);
- ``position_accuracy = sum_d / N`` and ``orientation_accuracy = atan2(sum_sin, sum_cos)``
  (225-226), ``timeout_segments`` the count (235).

So every segment whose ``WaitResult()`` returned is scored at the moment it returned, whatever
ended it (the Client's result, a RefBox ``reason: timeout`` or ``reason: stop``, the log's
end); the loop then ends on a timeout or a stop.

The node's clock and poses come from the log: ``time.time()`` and ``rospy.Time.now()`` after a
call are the record time of the BmBox message that ended it (``tests/helpers/bmbox2015.py``); tf is
the logged ``world -> robot_at_home`` transforms by their stamps, interpolated with scipy (past
the last stamp, a log that ends there: the last one, the closest the log gets). Nothing here
imports ertools.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from tests.helpers.bmbox2015 import Blocked, BmBoxReplay


@dataclass
class TfPoses:
    """``world -> robot_at_home`` as tf held it: stamps (ns), positions, quaternions."""

    t_ns: np.ndarray
    xyz: np.ndarray
    quat: np.ndarray

    def at(self, t: int) -> tuple[np.ndarray, Rotation]:
        """tf's lookup at ``t``: linear between the samples around it, SLERP for rotation."""
        j = int(np.searchsorted(self.t_ns, t, side="right")) - 1
        if self.t_ns[j] == t or j == len(self.t_ns) - 1:
            return self.xyz[j], Rotation.from_quat(self.quat[j])
        f = (t - self.t_ns[j]) / (self.t_ns[j + 1] - self.t_ns[j])
        rot = Slerp([0.0, 1.0], Rotation.from_quat(self.quat[j : j + 2]))([f])[0]
        return self.xyz[j] + f * (self.xyz[j + 1] - self.xyz[j]), rot


@dataclass
class Score2015:
    position_accuracy: float
    orientation_accuracy: float
    execution_time: float
    timeout_segments: int
    details: dict[int, dict[str, Any]] = field(default_factory=dict)
    cut: bool = False


def fbm2h_node(
    benchmark: BmBoxReplay,
    tf: TfPoses,
    waypoints: Sequence[Sequence[float]],
    marker_to_robot_transform: tuple[Sequence[float], Sequence[float]],
) -> Score2015:
    """scripts/fbm2h's main() at 50b173b, from ``WaitClient()`` to the score."""
    r_mr = Rotation.from_quat(list(marker_to_robot_transform[1]))
    N = len(waypoints)
    i = 0
    sum_d = 0.0
    sum_sin = 0.0
    sum_cos = 0.0
    execution_time = 0.0
    timeouts = 0
    segments_detail: dict[int, dict[str, Any]] = {}
    try:
        benchmark.WaitClient()
        while benchmark.Running() and not benchmark.Timeout() and i < N:
            benchmark.SendGoal()
            segments_detail[i] = {}
            start_segment_time = benchmark.now  # time.time()
            segments_detail[i]["start_segment_time"] = start_segment_time
            result_yaml = benchmark.WaitResult()
            segments_detail[i]["result_payload"] = result_yaml
            end_segment_time = benchmark.now  # time.time()
            # Seconds as the node's float subtraction would give them, from the log's clock.
            segment_time = (end_segment_time - start_segment_time) / 1e9
            segments_detail[i]["end_segment_time"] = end_segment_time
            segments_detail[i]["segment_time"] = segment_time

            now = benchmark.now  # rospy.Time.now()
            p_m, r_m = tf.at(now)
            p_r = p_m + r_m.apply(list(marker_to_robot_transform[0]))
            robot_theta = float((r_m * r_mr).as_euler("xyz")[2])  # euler_from_quaternion
            robot_pose = (float(p_r[0]), float(p_r[1]), robot_theta)
            target_pose = tuple(waypoints[i])
            segments_detail[i]["target_pose"] = target_pose
            segments_detail[i]["robot_pose"] = robot_pose

            if benchmark.Timeout() and not benchmark.Running():
                segments_detail[i]["refbox_timeout"] = True
                execution_time = execution_time + segment_time
                continue
            segments_detail[i]["refbox_timeout"] = False

            if benchmark.Timeout():
                timeouts = timeouts + 1
                segments_detail[i]["timeout"] = True
            else:
                segments_detail[i]["timeout"] = False

            rp = robot_pose
            tp = target_pose
            d_error = math.sqrt((rp[0] - tp[0]) ** 2 + (rp[1] - tp[1]) ** 2)
            sum_d = sum_d + d_error
            sin_error = math.sin(math.fabs(rp[2] - tp[2]))
            sum_sin = sum_sin + sin_error
            cos_error = math.cos(math.fabs(rp[2] - tp[2]))
            sum_cos = sum_cos + cos_error
            segments_detail[i]["dinstance_error"] = d_error
            segments_detail[i]["orientation_error"] = math.atan2(sin_error, cos_error)
            execution_time = execution_time + segment_time
            i = i + 1
    except Blocked:
        pass  # the log ended with the node waiting: the score of what it had (bmbox2015)

    return Score2015(
        position_accuracy=sum_d / N,
        orientation_accuracy=math.atan2(sum_sin, sum_cos),
        execution_time=execution_time,
        timeout_segments=timeouts,
        details=segments_detail,
        cut=benchmark.cut_at is not None,
    )
