"""HOPF's script (``fbm1_objects_perception.py``), statement by statement (docs/hopf.md).

Versions: ``2bb8a41`` (rockin-robot-challenge/rsbb, 2019: l. 51-316), ``00e3106``
(Enri2077/rsbb, December 2017 to May 2018: the same plus the ``manual_operation_N`` fields and
their saves) and ``b5d91f4`` (Enri2077/rsbb, November 2017: items from the config, no attempt
limit, ``break`` on a failed lookup, the score's goal written after the goal, the truth's class
and instance recorded as the answer's).

The random draw of the item is the log's: the world's manual operation requests name it, so
the replay takes the item whose text the first manual operation of each goal carries
(``Timeline.files["items_order"]``: the item ids in order) and removes it as the script did.
"""

from __future__ import annotations

from math import pi, pow, sqrt
from typing import Any

from tests.helpers.rsbb_replay.helper import Pose2D, pose2d_from_tf_concatenation
from tests.helpers.rsbb_replay.py2 import to_sec
from tests.helpers.rsbb_replay.world import GoalObject, ManualOperationObject, World

VERSIONS = ("b5d91f4", "00e3106", "2bb8a41")


def _draw(w: World, items: list[dict[str, Any]]) -> dict[str, Any]:
    """``random.choice(items)``: the item the log shows next."""
    if not items:
        raise IndexError("Cannot choose from an empty sequence")  # fewer items than goals
    order: list[int] = w.tl.files["items_order"]
    if not order:
        return items[0]  # a draw the log does not show: the iteration ends before its request
    wanted = order.pop(0)
    return next(i for i in items if i["id"] == wanted)


def _place_text(item: dict[str, Any]) -> str:
    return "Place the positioner and the %s (id: %d, instance: %s) on the table" % (
        item["description"],
        item["id"],
        item["instance"],
    )


def _stopped(w: World) -> bool:
    """The scripts' ``if not self.is_benchmark_running(): ...print...; return`` test."""
    return not w.is_benchmark_running()


def execute(w: World, version: str = "2bb8a41") -> None:
    """``BenchmarkObject.execute`` of HOPF at ``version``."""
    assert version in VERSIONS
    late = version != "b5d91f4"
    mo_fields = version == "00e3106"
    N = 10
    TRANS_ACCURACY = 0.0
    ROT_ACCURACY = 0.0
    # items_with_pose.yaml's "items" (December 2017 on), the config's before
    items = list(w.tl.files["items"]) if late else w.params["items"]
    i = 0
    class_positives = 0.0
    instance_positives = 0.0
    pose_score_sum = 0.0
    execution_time = 0
    max_pose_error = sqrt(
        pow(float(w.params["table_size"]["x"]), 2) + pow(float(w.params["table_size"]["y"]), 2)
    )
    del max_pose_error  # computed and never used (its clip is commented out)
    while w.is_benchmark_running() and (i < N):
        i += 1
        item = _draw(w, items)
        items.remove(item)
        if late:
            w.score["goal_%i" % i] = {}
        mo1 = ManualOperationObject(_place_text(item))
        w.request_manual_operation(mo1)
        if mo_fields:
            w.score["goal_%i" % i]["manual_operation_1"] = (
                mo1.get_result() if mo1.has_been_completed() else "not executed"
            )
            w.save_and_publish_score()
        elif not late:
            w.score["first_manual_operation"] = (
                mo1.get_result() if mo1.has_been_completed() else "not executed"
            )
            w.save_and_publish_score()
        if _stopped(w):
            return
        acquired = pose2d_from_tf_concatenation(
            w,
            "/item",
            item["trans"],
            item["rot"],
            "/positioner_origin",
            "/table_origin",
            max_failed_attempts=3 if late else None,
        )
        if not late and acquired is None:
            break
        while acquired is None:
            mo3 = ManualOperationObject(
                "The position of the positioner could not be acquired!\nPlace in a different "
                "position the positioner and the %s (id: %d, instance: %s) on the table"
                % (item["description"], item["id"], item["instance"])
            )
            w.request_manual_operation(mo3)
            if mo_fields:
                w.score["goal_%i" % i]["manual_operation_3"] = (
                    mo3.get_result() if mo3.has_been_completed() else "not executed"
                )
                w.save_and_publish_score()
            if _stopped(w):
                return
            acquired = pose2d_from_tf_concatenation(
                w,
                "/item",
                item["trans"],
                item["rot"],
                "/positioner_origin",
                "/table_origin",
                max_failed_attempts=3,
            )
        mo2 = ManualOperationObject("Remove the positioner")
        w.request_manual_operation(mo2)
        if mo_fields:
            w.score["goal_%i" % i]["manual_operation_2"] = (
                mo2.get_result() if mo2.has_been_completed() else "not executed"
            )
            w.save_and_publish_score()
        elif not late:
            w.score["first_manual_operation"] = (
                mo2.get_result() if mo2.has_been_completed() else "not executed"
            )
            w.save_and_publish_score()
        if _stopped(w):
            return
        goal = GoalObject({}, w.params["goal_timeout"])
        w.request_goal(goal)
        start_time = w.now()
        w.wait_goal_result()
        end_time = w.now()
        segment_time = end_time - start_time
        execution_time += segment_time
        if not late:
            w.score["goal_%i" % i] = {}
        w.score["goal_%i" % i]["timeout"] = goal.has_timed_out()
        w.score["goal_%i" % i]["completed"] = goal.has_been_completed()
        w.score["goal_%i" % i]["segment_time"] = to_sec(segment_time)
        w.save_and_publish_score()
        if goal.has_been_completed():
            result = goal.get_result()
            answer = Pose2D(result["x"], result["y"], result["theta"])
            # the log line formats x, y, theta (%.2f), class and instance: a missing key or a
            # value that is no number raises here
            _ = "%.2f %.2f %.2f %s %s" % (
                answer.x,
                answer.y,
                answer.theta,
                result["class"],
                result["instance"],
            )
            w.send_transform(
                [answer.x, answer.y, 0], [0.0, 0.0, 0.0, 1.0], w.now(), "result_%d" % i, "origin"
            )
            is_class_correct = result["class"] == item["class"]
            if is_class_correct:
                class_positives += 1
            is_instance_correct = result["instance"] == item["instance"]
            if is_instance_correct:
                instance_positives += 1
            x_err = answer.x - acquired.x
            y_err = answer.y - acquired.y
            w_err = answer.theta - acquired.theta
            if w_err > pi:
                w_err = w_err - 2 * pi
            if w_err < -pi:
                w_err = w_err + 2 * pi
            if abs(x_err) < TRANS_ACCURACY:
                x_err = 0.0
            if abs(y_err) < TRANS_ACCURACY:
                y_err = 0.0
            if abs(w_err) < ROT_ACCURACY:
                w_err = 0.0
            pose_err_trans = sqrt(pow(x_err, 2) + pow(y_err, 2))
            pose_err_rot = abs(w_err) / pi
            if pose_err_rot > 1:
                pose_err_rot = 1.0
            pose_score = 1 - (pose_err_trans / 2) - (pose_err_rot / 2)
            pose_score_sum += pose_score
            g = w.score["goal_%i" % i]
            g["item_acquired"] = {
                "pose": [acquired.x, acquired.y, acquired.theta],
                "pose_units": ["m", "m", "rad"],
                "class": item["class"],
                "instance": item["instance"],
            }
            g["item_received"] = {
                "pose": [answer.x, answer.y, answer.theta],
                "pose_units": ["m", "m", "rad"],
                "class": result["class"] if late else item["class"],
                "instance": result["instance"] if late else item["instance"],
            }
            g["partial_score"] = {
                "pose_score": pose_score,
                "pose_error_translation_score": pose_err_trans,
                "pose_error_translation_score_unit": "pure number",
                "pose_error_rotation_score": pose_err_rot,
                "pose_error_rotation_score_unit": "pure number",
                "pose_error": [x_err, y_err, w_err],
                "pose_error_units": ["m", "m", "rad"],
                "is_class_correct": is_class_correct,
                "is_instance_correct": is_instance_correct,
            }
            w.save_and_publish_score()
        w.score["class_accuracy"] = class_positives / i
        w.score["instance_accuracy"] = instance_positives / i
        w.score["pose_score"] = pose_score_sum / i
        w.score["execution_time"] = to_sec(execution_time)
        w.save_and_publish_score()
