"""HGMF's script (``fbm6_grasping_manipulation.py`` at 2bb8a41, l. 56-274), statement by
statement (docs/hgmf.md), with its module-level ``object_grasped`` and
``object_height_reference`` and the 10 Hz timer's callback.

The random draws are the log's: ``Timeline.files["objects_order"]`` (the object ids in the
order the goals name them) and ``Timeline.files["targets"]`` (each goal's final target, as
its payload carries it; the script's redraws closer than 5 cm to the object are not logged,
so the replay starts from the logged target and checks the 5 cm rule holds for it).
"""

from __future__ import annotations

from math import sqrt
from typing import Any

from tests.helpers.rsbb_replay.helper import pose2d_from_tf_concatenation
from tests.helpers.rsbb_replay.py2 import to_sec
from tests.helpers.rsbb_replay.tf2 import TfError
from tests.helpers.rsbb_replay.world import GoalObject, ManualOperationObject, World

VERSIONS = ("2bb8a41",)


class _Globals:
    """The script module's globals."""

    def __init__(self) -> None:
        self.object_grasped = False
        self.object_height_reference: Any = 0.0


def _timer_callback(w: World, g: _Globals) -> None:
    try:
        now = w.now("timer")
        w.wait_for_transform("/table_origin", "/actor_markerset", now, 0.1)
        (_, _, current_object_height), _ = w.lookup_transform(
            "/table_origin", "/actor_markerset", 0
        )
        if current_object_height > (g.object_height_reference + 0.03):
            g.object_grasped = True
    except TfError:
        return


def _lookup(w: World) -> tuple[Any, Any]:
    result: tuple[Any, Any] = pose2d_from_tf_concatenation(
        w,
        "/object",
        (0, 0, 0),
        (0, 0, 0, 1),
        "/actor_markerset",
        "/table_origin",
        max_failed_attempts=3,
        with_height=True,
    )
    return result


def execute(w: World, version: str = "2bb8a41") -> None:
    """``BenchmarkObject.execute`` of HGMF."""
    assert version in VERSIONS
    g = _Globals()
    objects = w.params["objects"]
    N = len(objects)
    table_size = w.params["table_size"]
    min_x = 0.15
    min_y = 0.15
    max_x = table_size["x"] - 0.15
    max_y = table_size["y"] - 0.15
    i = 0
    objects_grasped_sum = 0
    goals_completed_sum = 0
    distance_error_sum = 0
    execution_time = 0
    while w.is_benchmark_running() and (i < N):
        if not objects:
            raise IndexError("Cannot choose from an empty sequence")
        order: list[int] = w.tl.files["objects_order"]
        wanted = order.pop(0) if order else objects[0]["id"]  # unlogged: ends before the goal
        obj = next(o for o in objects if o["id"] == wanted)
        objects.remove(obj)
        w.score["goal_%i" % i] = {}
        g.object_grasped = False
        targets: list[tuple[float, float]] = w.tl.files["targets"]
        target_x, target_y = targets.pop(0) if targets else (min_x, min_y)
        assert min_x <= target_x <= max_x and min_y <= target_y <= max_y
        mo1 = ManualOperationObject(
            "Place the %s on the table, with MoCap markers attached." % obj["description"]
        )
        w.request_manual_operation(mo1)
        if not w.is_benchmark_running():
            return
        object_pose_mocap, g.object_height_reference = _lookup(w)
        while object_pose_mocap is None:
            mo2 = ManualOperationObject(
                "Could not get the %s's pose. Make sure it's inside the designated area with a "
                "markerset attached." % obj["description"]
            )
            w.request_manual_operation(mo2)
            if not w.is_benchmark_running():
                return
            object_pose_mocap, g.object_height_reference = _lookup(w)
        distance_from_target = sqrt(
            (object_pose_mocap.x - target_x) ** 2 + (object_pose_mocap.y - target_y) ** 2
        )
        assert distance_from_target >= 0.05, "the logged target is one the script redrew"
        goal = GoalObject([target_x, target_y, obj["id"]], w.params["goal_timeout"])
        w.request_goal(goal)
        start_time = w.now()
        timer = w.start_timer(0.1, lambda: _timer_callback(w, g))
        w.wait_goal_result()
        end_time = w.now()
        timer.shutdown()
        segment_time = end_time - start_time
        execution_time += segment_time
        w.score["goal_%i" % i]["segment_time [s]"] = to_sec(segment_time)
        w.save_and_publish_score()
        w.score["goal_%i" % i]["timeout"] = goal.has_timed_out()
        w.score["goal_%i" % i]["completed"] = goal.has_been_completed()
        if goal.has_been_completed():
            goals_completed_sum += 1
            if g.object_grasped:
                objects_grasped_sum += 1
            object_pose_mocap = _lookup(w)[0]
            if object_pose_mocap is None:
                execution_time -= segment_time
                objects.append(obj)
                continue
            x_err = target_x - object_pose_mocap.x
            y_err = target_y - object_pose_mocap.y
            distance_error = sqrt(x_err**2 + y_err**2)
            distance_error_sum += distance_error
            s = w.score["goal_%i" % i]
            s["Object grasped"] = g.object_grasped
            s["Distance error"] = distance_error
            s["Target object position"] = "(%.2f, %.2f)" % (target_x, target_y)
            s["Measured object position"] = "(%.2f, %.2f)" % (
                object_pose_mocap.x,
                object_pose_mocap.y,
            )
            s["Object type"] = "%s (id %d)" % (obj["description"], obj["id"])
            w.score["Objects grasped"] = str(objects_grasped_sum) + " out of " + str(N)
            w.score["Avg distance error"] = distance_error_sum / goals_completed_sum
        else:
            w.score["goal_%i" % i]["result"] = "Not completed"
        w.score["execution_time"] = to_sec(execution_time)
        w.save_and_publish_score()
        if not w.is_benchmark_running():
            return
        i += 1
