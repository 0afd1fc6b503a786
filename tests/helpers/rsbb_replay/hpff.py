"""HPFF's script (``fbm5_person_following.py`` at 2bb8a41, l. 50-176), statement by statement
(docs/hpff.md).

The team transform is ``Timeline.files["transform"]`` (the pair the script read).
"""

from __future__ import annotations

from math import sqrt

from tests.helpers.rsbb_replay.helper import pose2d_from_tf_concatenation
from tests.helpers.rsbb_replay.py2 import py2_round, py2_str, to_sec
from tests.helpers.rsbb_replay.world import GoalObject, ManualOperationObject, World

VERSIONS = ("2bb8a41",)


def _relative(w: World, transform: list[list[float]], attempts: int, timeout: float) -> object:
    return pose2d_from_tf_concatenation(
        w,
        "/robot",
        transform[0],
        transform[1],
        "/robot_markerset",
        "/actor_markerset",
        max_failed_attempts=attempts,
        timeout=timeout,
    )


def execute(w: World, version: str = "2bb8a41") -> None:
    """``BenchmarkObject.execute`` of HPFF."""
    assert version in VERSIONS
    MIN_FOLLOWING_DISTANCE = w.params["min_following_distance"]
    MAX_FOLLOWING_DISTANCE = w.params["max_following_distance"]
    DESIRED_FOLLOWING_DISTANCE = w.params["desired_following_distance"]
    transform = w.tl.files["transform"]
    mocap_success_sum = 0
    mocap_failure_sum = 0
    deviation_from_desired_distance_sum = 0
    distance_covered_while_following = 0
    last_absolute_robot_pose = None
    while w.is_benchmark_running():
        w.score = {}
        robot_to_human_pose = _relative(w, transform, 3, 0.5)
        while robot_to_human_pose is None:
            mo = ManualOperationObject(
                "Failed to acquire pose of human or robot. "
                "Make sure they have detectable markersets."
            )
            w.request_manual_operation(mo)
            robot_to_human_pose = _relative(w, transform, 3, 0.5)
        goal = GoalObject({}, w.params["goal_timeout"])
        w.request_goal(goal)
        benchmark_start_time = w.now()
        w.sleep(8.0)
        while (not goal.has_timed_out()) and (not goal._executed):
            sample_start_time = w.now()
            robot_to_human_pose = _relative(w, transform, 1, 0.2)
            absolute_robot_pose = pose2d_from_tf_concatenation(
                w,
                "/robot",
                transform[0],
                transform[1],
                "/robot_markerset",
                "/testbed_origin",
                max_failed_attempts=1,
                timeout=0.2,
            )
            if robot_to_human_pose is not None:
                mocap_success_sum += 1
                rel = robot_to_human_pose
                distance = sqrt(rel.x**2 + rel.y**2)  # type: ignore[attr-defined]
                deviation = abs(distance - DESIRED_FOLLOWING_DISTANCE)
                deviation_from_desired_distance_sum += deviation
                if MIN_FOLLOWING_DISTANCE <= distance <= MAX_FOLLOWING_DISTANCE:  # noqa: SIM102
                    if last_absolute_robot_pose is not None and absolute_robot_pose is not None:
                        x_dist = absolute_robot_pose.x - last_absolute_robot_pose.x  # type: ignore[attr-defined]
                        y_dist = absolute_robot_pose.y - last_absolute_robot_pose.y  # type: ignore[attr-defined]
                        dist = sqrt(x_dist**2 + y_dist**2)
                        distance_covered_while_following += dist
            else:
                mocap_failure_sum += 1
            last_absolute_robot_pose = absolute_robot_pose
            current_time = w.now()
            elapsed_time = current_time - sample_start_time
            remaining_time = 0.5 - to_sec(elapsed_time)
            if remaining_time > 0:
                w.sleep(remaining_time)
            if not w.is_benchmark_running():
                return
        benchmark_end_time = w.now()
        benchmark_duration = to_sec(benchmark_end_time - benchmark_start_time)
        target_duration = w.params["goal_timeout"]
        if benchmark_duration < (target_duration - 15) or benchmark_duration > (
            target_duration + 15
        ):
            w.score["Result"] = "Benchmark failed: finished prematurely or took too long"
            w.save_and_publish_score()
            w.abort_benchmark(message="Benchmark failed! Finished prematurely or took too long")
            return
        if mocap_success_sum > 0:
            w.score["Average deviation from desired distance"] = (
                deviation_from_desired_distance_sum / float(mocap_success_sum)
            )
        w.score["Distance covered while following"] = distance_covered_while_following
        percent_mocap_failures = (
            mocap_failure_sum / float(mocap_success_sum + mocap_failure_sum) * 100
        )
        w.score["Benchmark reliability"] = py2_str(py2_round(100 - percent_mocap_failures, 1)) + "%"
        if percent_mocap_failures > 50:
            w.score["WARNING"] = (
                "%.1f%% of the time, mocap pose acquiring failed. Consider repeating the benchmark."
                % percent_mocap_failures
            )
        w.save_and_publish_score()
        w.abort_benchmark()
        return
