"""HNF's script (``fbm2_navigation.py``), statement by statement (docs/hnf.md).

Versions: ``2bb8a41`` (rockin-robot-challenge/rsbb, 2019: l. 52-239), ``00e3106``
(Enri2077/rsbb, December 2017 to May 2018: the same plus the ``manual_operation`` field and
its saves), ``f594ff1`` (4 November to 15 December 2017; ``e4769fe`` changed a log message
only: no attempt limit, no prompt, the poses always dumped) and ``069fd1d`` (2-4 November
2017: the inline lookup loop, no ``fabs``).

The team transform is ``Timeline.files["transform"]``: the (translation, rotation) pair the
script read (``markerset_to_robot_transform``; ``marker_to_robot_transform`` before
``00e3106``).
"""

from __future__ import annotations

from math import atan2, cos, fabs, sin, sqrt

from tests.helpers.rsbb_replay.helper import Pose2D, pose2d_from_tf_concatenation
from tests.helpers.rsbb_replay.py2 import dump_none, dump_pose2d, euler_yaw, to_sec
from tests.helpers.rsbb_replay.tf2 import TfError
from tests.helpers.rsbb_replay.world import GoalObject, ManualOperationObject, World

VERSIONS = ("069fd1d", "f594ff1", "00e3106", "2bb8a41")

PROMPT = (
    "The position of the robot markerset could not be acquired!\nTry again or skip the "
    "waypoint? type 's' for skip, anything else to try again"
)


def _dump(pose: Pose2D | None) -> str:
    return dump_none() if pose is None else dump_pose2d(pose.x, pose.y, pose.theta)


def _inline_lookup(
    w: World, seg: dict[str, object], transform: list[list[float]], waypoint: list[float]
) -> Pose2D | None:
    """069fd1d's lookup loop (no attempt limit; the poses dumped only when acquired)."""
    acquired = False
    robot_pose = None
    while not acquired and w.is_benchmark_running():
        try:
            now = w.now("lookup", "/robot", 1.0)
            w.wait_for_transform("/testbed_origin", "/robot_markerset", now, 1.0)
            w.lookup_transform("/testbed_origin", "/robot_markerset", now)  # unused
            w.send_transform(transform[0], transform[1], now, "/robot", "/robot_markerset")
            w.wait_for_transform("/testbed_origin", "/robot", now, 1.0)
            (rx, ry, _), rotation = w.lookup_transform("/testbed_origin", "/robot", 0)
            robot_pose = Pose2D(rx, ry, euler_yaw(rotation))
            target_pose = Pose2D(*waypoint)
            seg["target_pose"] = _dump(target_pose)
            seg["robot_pose"] = _dump(robot_pose)
            acquired = True
        except TfError:
            acquired = False
    return robot_pose if acquired else None


def execute(w: World, version: str = "2bb8a41") -> None:
    """``BenchmarkObject.execute`` of HNF at ``version``."""
    assert version in VERSIONS
    start_benchmark_time = w.now()
    starting_robot_pose = Pose2D(*w.params["starting_pose"])
    del starting_robot_pose  # read and never used
    waypoints = w.params["waypoints"]
    goal_timeout = w.params["goal_timeout"]
    N = len(waypoints)
    i = 0
    sum_d = 0.0
    sum_sin = 0.0
    sum_cos = 0.0
    execution_time = 0
    timed_out_waypoints = 0
    reached_waypoints = 0
    transform = w.tl.files["transform"]
    while w.is_benchmark_running() and i < N:
        key = "segment_%i" % (i + 1)
        w.score[key] = {}
        goal = GoalObject(waypoints[i], goal_timeout)
        w.request_goal(goal)
        start_segment_time = w.now()
        w.score[key]["start_segment_time[s]"] = to_sec(start_segment_time - start_benchmark_time)
        w.save_and_publish_score()
        w.wait_goal_result()
        end_segment_time = w.now()
        w.score[key]["end_segment_time[s]"] = to_sec(end_segment_time - start_benchmark_time)
        w.save_and_publish_score()
        segment_time = end_segment_time - start_segment_time
        execution_time += segment_time
        w.score[key]["segment_time[s]"] = to_sec(segment_time)
        w.save_and_publish_score()
        w.score[key]["timeout"] = goal.has_timed_out()
        w.score[key]["completed"] = goal.has_been_completed()
        if goal.has_timed_out():
            timed_out_waypoints += 1
        elif goal.has_been_completed():
            reached_waypoints += 1
            w.score[key]["result"] = goal.get_result()
        w.save_and_publish_score()

        if version == "069fd1d":
            robot_pose = _inline_lookup(w, w.score[key], transform, waypoints[i])
            target_pose = Pose2D(*waypoints[i])
        else:
            target_pose = Pose2D(*waypoints[i])
            robot_pose = pose2d_from_tf_concatenation(
                w,
                "/robot",
                transform[0],
                transform[1],
                "/robot_markerset",
                "/testbed_origin",
                max_failed_attempts=None if version == "f594ff1" else 5,
            )
            while version in ("00e3106", "2bb8a41") and robot_pose is None:
                mo3 = ManualOperationObject(PROMPT)
                w.request_manual_operation(mo3)
                if mo3.has_been_completed():
                    if version == "00e3106":
                        w.score[key]["manual_operation"] = mo3.get_result()
                        w.save_and_publish_score()
                    if mo3.get_result() == "s":
                        break
                elif version == "00e3106":
                    w.score[key]["manual_operation"] = "not executed"
                if version == "00e3106":
                    w.save_and_publish_score()
                if not w.is_benchmark_running():
                    return
                robot_pose = pose2d_from_tf_concatenation(
                    w,
                    "/robot",
                    transform[0],
                    transform[1],
                    "/robot_markerset",
                    "/testbed_origin",
                    max_failed_attempts=5,
                )
            w.score[key]["target_pose"] = _dump(target_pose)
            w.score[key]["robot_pose"] = _dump(robot_pose)

        if robot_pose is not None:
            rp, tp = robot_pose, target_pose
            d_error = sqrt((rp.x - tp.x) ** 2 + (rp.y - tp.y) ** 2)
            sum_d = sum_d + d_error
            sin_error = sin(fabs(rp.theta - tp.theta))
            sum_sin += sin_error
            cos_error = cos(fabs(rp.theta - tp.theta))
            sum_cos += cos_error
            w.score[key]["distance_error"] = d_error
            if version == "069fd1d":
                w.score[key]["orientation_error"] = atan2(sin_error, cos_error)
            else:
                w.score[key]["orientation_error"] = atan2(fabs(sin_error), cos_error)
        w.save_and_publish_score()
        i += 1

    if reached_waypoints > 0:
        position_accuracy = sum_d / reached_waypoints
        if version == "069fd1d":
            orientation_accuracy = atan2(sum_sin, sum_cos)
        else:
            orientation_accuracy = atan2(fabs(sum_sin), sum_cos)
    else:
        position_accuracy = None
        orientation_accuracy = None
    w.score["reached_waypoints"] = reached_waypoints
    w.score["timed_out_waypoints"] = timed_out_waypoints
    w.score["execution_time[s]"] = to_sec(execution_time)
    w.score["position_accuracy[m]"] = position_accuracy
    w.score["orientation_accuracy[rad]"] = orientation_accuracy
    w.save_and_publish_score()
