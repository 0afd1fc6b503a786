"""HPPF's script (``fbm4_people_perception.py`` at 2bb8a41, l. 50-234), statement by statement
(docs/hppf.md).

The random draws are the log's: ``Timeline.files["people_order"]`` lists the names in the
order the first manual operations of the goals name them (a restarted goal draws again).
"""

from __future__ import annotations

from math import sqrt

from tests.helpers.rsbb_replay.helper import pose2d_from_tf_concatenation
from tests.helpers.rsbb_replay.py2 import py2_round, py2_str, to_sec
from tests.helpers.rsbb_replay.world import GoalObject, ManualOperationObject, World

VERSIONS = ("2bb8a41",)


def _draw(w: World, people: list[str]) -> str:
    if not people:
        raise IndexError("Cannot choose from an empty sequence")
    order: list[str] = w.tl.files["people_order"]
    if not order:
        return people[0]  # a draw the log does not show: the iteration ends before its request
    wanted = order.pop(0)
    assert wanted in people, f"{wanted} is not among the people left ({people})"
    return wanted


def _lookup(w: World) -> object:
    return pose2d_from_tf_concatenation(
        w,
        "/person",
        (0, 0, 0),
        (0, 0, 0, 1),
        "/actor_markerset",
        "/testbed_origin",
        max_failed_attempts=3,
    )


def execute(w: World, version: str = "2bb8a41") -> None:
    """``BenchmarkObject.execute`` of HPPF."""
    assert version in VERSIONS
    people = w.params["people"]
    N = len(people)
    i = 0
    detected_sum = 0
    recognized_sum = 0
    position_error_sum = 0
    execution_time = 0
    while w.is_benchmark_running() and (i < N):
        person = _draw(w, people)
        people.remove(person)
        w.score["goal_%i" % i] = {}
        mo1 = ManualOperationObject(
            "%s should enter the target area wearing a cap with MoCap markers, and place "
            "him/herself in an arbitrary position." % person
        )
        w.request_manual_operation(mo1)
        if not w.is_benchmark_running():
            return
        person_pose_mocap = _lookup(w)
        while person_pose_mocap is None:
            mo2 = ManualOperationObject(
                "Could not get %s's pose. Make sure (s)he is inside the designated area and "
                "wearing the markerset cap." % person
            )
            w.request_manual_operation(mo2)
            if not w.is_benchmark_running():
                return
            person_pose_mocap = _lookup(w)
        goal = GoalObject({}, w.params["goal_timeout"])
        w.request_goal(goal)
        start_time = w.now()
        w.wait_goal_result()
        end_time = w.now()
        segment_time = end_time - start_time
        execution_time += segment_time
        w.score["goal_%i" % i]["segment_time [s]"] = to_sec(segment_time)
        w.save_and_publish_score()
        w.score["goal_%i" % i]["timeout"] = goal.has_timed_out()
        w.score["goal_%i" % i]["completed"] = goal.has_been_completed()
        if goal.has_been_completed():
            person_pose_mocap = _lookup(w)
            if person_pose_mocap is None:
                execution_time -= segment_time
                people.append(person)
                continue
            detected_sum += 1
            result = goal.get_result()
            # the log line formats x, y, theta (%.2f) and person_name: a missing key or a
            # value that is no number raises here
            _ = "%.2f %.2f %.2f %s" % (
                result["x"],
                result["y"],
                result["theta"],
                result["person_name"],
            )
            recognized = result["person_name"].lower() == person.lower()
            if recognized:
                recognized_sum += 1
            x_err = result["x"] - person_pose_mocap.x  # type: ignore[attr-defined]
            y_err = result["y"] - person_pose_mocap.y  # type: ignore[attr-defined]
            position_error = sqrt(x_err**2 + y_err**2)
            position_error_sum += position_error
            g = w.score["goal_%i" % i]
            g["detected"] = True
            g["recognized"] = recognized
            g["position_error"] = position_error
            g["ground-truth person position"] = "(%.2f, %.2f)" % (
                person_pose_mocap.x,  # type: ignore[attr-defined]
                person_pose_mocap.y,  # type: ignore[attr-defined]
            )
            g["robot-estimated person position"] = "(%.2f, %.2f)" % (result["x"], result["y"])
            w.score["Recognized persons"] = recognized_sum
            w.score["% Recognized persons"] = (
                py2_str(py2_round(recognized_sum / float(N) * 100, 2)) + "%"
            )
            w.score["Distance error"] = position_error_sum / detected_sum
        else:
            w.score["goal_%i" % i]["detected"] = False
        w.score["execution_time"] = to_sec(execution_time)
        w.save_and_publish_score()
        if not w.is_benchmark_running():
            return
        i += 1
