"""The HOPF replay on hand-built runs: each quirk of docs/hopf.md with its number worked out here.

The table stands at the testbed origin, the positioner at (0.5, 0.6) facing x; every item's
transform puts it 0.1 m ahead of the positioner: the truth is (0.6, 0.6, 0) in the table frame.
"""

from __future__ import annotations

from math import pi

import pytest

from tests.helpers.rsbb_replay import hopf
from tests.helpers.rsbb_replay.hand import MS, T0, S, body, still
from tests.helpers.rsbb_replay.world import TGoal, Timeline, TManual, World, run_script

ITEMS = [
    {
        "id": k,
        "class": "a" if k < 3 else "b",
        "instance": f"i{k}",
        "description": f"thing {k}",
        "trans": [0.1, 0.0, 0.0],
        "rot": [0.0, 0.0, 0.0, 1.0],
    }
    for k in range(1, 12)
]
PARAMS = {"table_size": {"x": 1.0, "y": 1.5}, "goal_timeout": 120}


def _timeline(order: list[int]) -> Timeline:
    tl = Timeline(t_ready_ns=T0 + S, params=dict(PARAMS))
    tl.files.update(items=[dict(i) for i in ITEMS], items_order=list(order))
    body(tl.tf, "table_origin", still((0.0, 0.0, 0.0)))
    body(tl.tf, "positioner_origin", still((0.5, 0.6, 0.0)))
    return tl


def _goal(tl: Timeline, k: int, answer: str | None, outcome: str = "result") -> None:
    """Goal k (0-based): manual operations at 20k+2 s and 20k+4 s, lookup at 20k+3 s, the goal
    from 20k+6 s to 20k+10 s."""
    base = T0 + 20 * k * S
    tl.manual += [TManual(base + 2 * S), TManual(base + 4 * S)]
    tl.lookups.setdefault("item", []).append(base + 3 * S)
    tl.goals.append(TGoal(base + 6 * S, base + 10 * S, outcome, answer))


def _run(tl: Timeline, version: str = "2bb8a41") -> tuple[dict[str, object], str | None]:
    result = run_script(World(tl), lambda w: hopf.execute(w, version))
    return result.score, result.crashed


def test_the_pose_score_goes_negative_unclipped() -> None:
    # 2.5 m off in x and pi/2 off in theta: t = 2.5, r = 0.5, 1 - 1.25 - 0.25 = -0.5
    tl = _timeline([1, 2])
    _goal(tl, 0, "{x: 3.1, y: 0.6, theta: %r, class: a, instance: i1}" % (pi / 2))
    tl.manual.append(TManual(None))  # the referee stops during the second goal's first one
    tl.stop_ns = T0 + 19 * S
    score, crashed = _run(tl)
    assert crashed is None
    part = score["goal_1"]["partial_score"]
    assert part["pose_error_translation_score"] == pytest.approx(2.5, abs=1e-15)
    assert part["pose_error_rotation_score"] == pytest.approx(0.5, abs=1e-15)
    assert part["pose_score"] == pytest.approx(-0.5, abs=1e-15)
    assert score["goal_1"]["item_acquired"]["pose"] == pytest.approx([0.6, 0.6, 0.0], abs=1e-15)
    assert score["goal_1"]["item_received"]["class"] == "a"
    assert part["is_class_correct"] is True and part["is_instance_correct"] is True
    assert score["pose_score"] == pytest.approx(-0.5, abs=1e-15)
    assert score["execution_time"] == 4.0
    # the second iteration began (goal_2 = {}) and returned in its first manual operation
    assert score["goal_2"] == {}


def test_totals_divide_by_the_goals_begun() -> None:
    # goal 1 right (pose score 1), goal 2 timed out, goal 3 interrupted by the stop: / 3
    tl = _timeline([1, 2, 3])
    _goal(tl, 0, "{x: 0.6, y: 0.6, theta: 0.0, class: a, instance: i1}")
    _goal(tl, 1, None, "timeout")
    base = T0 + 40 * S
    tl.manual += [TManual(base + 2 * S), TManual(base + 4 * S)]
    tl.lookups["item"].append(base + 3 * S)
    tl.goals.append(TGoal(base + 6 * S, None, "stopped"))
    tl.stop_ns = base + 8 * S
    score, crashed = _run(tl)
    assert crashed is None
    assert score["goal_2"] == {"timeout": True, "completed": False, "segment_time": 4.0}
    assert score["goal_3"] == {"timeout": None, "completed": False, "segment_time": 2.0}
    assert score["class_accuracy"] == pytest.approx(1 / 3, abs=1e-15)
    assert score["instance_accuracy"] == pytest.approx(1 / 3, abs=1e-15)
    assert score["pose_score"] == pytest.approx(1 / 3, abs=1e-15)
    assert score["execution_time"] == 10.0


def test_a_stop_before_the_goal_keeps_the_previous_totals() -> None:
    tl = _timeline([1, 2])
    _goal(tl, 0, "{x: 0.6, y: 0.6, theta: 0.0, class: b, instance: i1}")  # class wrong
    base = T0 + 20 * S
    tl.manual.append(TManual(None))  # stopped during the second goal's first manual operation
    tl.stop_ns = base + 3 * S
    score, _ = _run(tl)
    assert score["class_accuracy"] == 0.0 and score["instance_accuracy"] == 1.0  # / 1, not / 2
    assert score["goal_2"] == {}


def test_one_wrap_step_only() -> None:
    # theta = 4 pi - 0.1: one step leaves 2 pi - 0.1, r clipped to 1; a full wrap gives 0.1 / pi
    tl = _timeline([1])
    _goal(tl, 0, "{x: 0.6, y: 0.6, theta: %r, class: a, instance: i1}" % (4 * pi - 0.1))
    tl.manual.append(TManual(None))
    tl.stop_ns = T0 + 19 * S
    score, _ = _run(tl)
    part = score["goal_1"]["partial_score"]
    assert part["pose_error"][2] == pytest.approx(2 * pi - 0.1, abs=1e-14)
    assert part["pose_error_rotation_score"] == 1.0
    assert part["pose_score"] == pytest.approx(0.5, abs=1e-15)


def test_a_missing_answer_field_kills_the_script() -> None:
    tl = _timeline([1, 2])
    _goal(tl, 0, "{x: 0.6, y: 0.6, theta: 0.0, class: a, instance: i1}")
    _goal(tl, 1, "{x: 0.6, y: 0.6, class: a, instance: i2}")  # no theta
    score, crashed = _run(tl)
    assert crashed is not None and crashed.startswith("KeyError")
    # the result file keeps the last save: goal 2's timeout/completed/segment_time, goal 1's totals
    assert score["goal_2"] == {"timeout": False, "completed": True, "segment_time": 4.0}
    assert score["class_accuracy"] == 1.0 and score["execution_time"] == 4.0


def test_november_2017_recorded_the_truth_as_the_answer() -> None:
    tl = _timeline([1])
    tl.params["items"] = [dict(i) for i in ITEMS]
    _goal(tl, 0, "{x: 0.6, y: 0.6, theta: 0.0, class: b, instance: i9}")
    tl.manual.append(TManual(None))
    tl.stop_ns = T0 + 19 * S
    score, _ = _run(tl, "b5d91f4")
    assert score["goal_1"]["item_received"]["class"] == "a"  # the truth's, not "b"
    assert score["goal_1"]["partial_score"]["is_class_correct"] is False
    # the second goal's first manual operation, interrupted by the stop, wrote last
    assert score["first_manual_operation"] == "not executed"
    # December 2017: the answers, and each manual operation's answer kept
    tl2 = _timeline([1])
    _goal(tl2, 0, "{x: 0.6, y: 0.6, theta: 0.0, class: b, instance: i9}")
    tl2.manual.append(TManual(None))
    tl2.stop_ns = T0 + 19 * S
    score2, _ = _run(tl2, "00e3106")
    assert score2["goal_1"]["item_received"]["class"] == "b"
    assert (
        score2["goal_1"]["manual_operation_1"] == ""
        and score2["goal_1"]["manual_operation_2"] == ""
    )
    assert score2["goal_2"] == {"manual_operation_1": "not executed"}


def test_a_failed_lookup_asks_the_referee_to_move_the_positioner() -> None:
    # three 1 s attempts fail (nothing logged at 2-5 s), manual operation 3, then the lookup
    tl = _timeline([1])
    base = T0
    tl.manual += [TManual(base + 2 * S), TManual(base + 7 * S, "moved"), TManual(base + 9 * S)]
    tl.lookups["item"] = [base + 7 * S + 10 * MS]
    answer = "{x: 0.6, y: 0.6, theta: 0.0, class: a, instance: i1}"
    tl.goals.append(TGoal(base + 11 * S, base + 13 * S, "result", answer))
    tl.manual.append(TManual(None))
    tl.stop_ns = T0 + 19 * S
    score, crashed = _run(tl, "00e3106")
    assert crashed is None
    assert score["goal_1"]["manual_operation_3"] == "moved"
    assert score["goal_1"]["partial_score"]["pose_score"] == 1.0
