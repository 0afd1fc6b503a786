"""The HNF replay on hand-built runs: each quirk of docs/hnf.md with its number worked out here."""

from __future__ import annotations

from math import atan2, cos, pi, sin

import pytest

from tests.helpers.rsbb_replay import hnf
from tests.helpers.rsbb_replay.hand import MS, T0, S, body, steps, still
from tests.helpers.rsbb_replay.py2 import dump_none, dump_pose2d
from tests.helpers.rsbb_replay.world import TGoal, Timeline, TManual, World, run_script

IDENTITY = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
PARAMS = {"starting_pose": [0.0, 0.0, 0.0], "goal_timeout": 120.0}


def _timeline(waypoints: list[list[float]], **kw: object) -> Timeline:
    tl = Timeline(t_ready_ns=T0 + S, params={**PARAMS, "waypoints": waypoints})
    tl.files["transform"] = IDENTITY
    for key, value in kw.items():
        setattr(tl, key, value)
    return tl


def _run(tl: Timeline, version: str = "2bb8a41") -> dict[str, object]:
    result = run_script(World(tl), lambda w: hnf.execute(w, version))
    assert result.crashed is None
    return result.score


def test_two_waypoints_reached() -> None:
    # Goal k runs from 10k+2 s to 10k+8 s after T0; the robot stands at (1.3, 0.4, 0) then at
    # (0, 1, pi); the script looks it up 10 ms after each result.
    tl = _timeline([[1, 0, 0], [0.0, 1.0, 3.0]])
    body(
        tl.tf,
        "robot_markerset",
        steps((T0, (1.3, 0.4, 0.0), 0.0), (T0 + 9 * S, (0.0, 1.0, 0.0), pi)),
    )
    tl.goals = [
        TGoal(T0 + 2 * S, T0 + 8 * S, "result", "{}"),
        TGoal(T0 + 12 * S, T0 + 18 * S, "result", "done"),
    ]
    tl.lookups = {"robot": [T0 + 8 * S + 10 * MS, T0 + 18 * S + 10 * MS]}
    score = _run(tl)
    seg1, seg2 = score["segment_1"], score["segment_2"]
    assert seg1["start_segment_time[s]"] == 1.0 and seg1["end_segment_time[s]"] == 7.0
    assert seg1["segment_time[s]"] == 6.0 and seg2["segment_time[s]"] == 6.0
    assert seg1["timeout"] is False and seg1["completed"] is True and seg1["result"] == {}
    assert seg2["result"] == "done"
    assert seg1["target_pose"] == dump_pose2d(1, 0, 0)
    assert (
        seg1["robot_pose"]
        == "!!python/object/new:geometry_msgs.msg._Pose2D.Pose2D\nstate: [1.3, 0.4, 0.0]\n"
    )
    assert seg2["robot_pose"] == dump_pose2d(0.0, 1.0, pi)
    assert seg1["distance_error"] == pytest.approx(0.5, abs=1e-15)  # a 0.3-0.4-0.5 triangle
    assert seg1["orientation_error"] == 0.0
    # |pi - 3| < pi: nothing to wrap, per segment or in total
    assert seg2["distance_error"] == 0.0
    assert seg2["orientation_error"] == pytest.approx(pi - 3.0, abs=1e-15)
    assert score["reached_waypoints"] == 2 and score["timed_out_waypoints"] == 0
    assert score["execution_time[s]"] == 12.0
    assert score["position_accuracy[m]"] == pytest.approx(0.25, abs=1e-15)
    expected = atan2(abs(0.0 + sin(pi - 3.0)), 1.0 + cos(pi - 3.0))  # = (pi - 3) / 2
    assert score["orientation_accuracy[rad]"] == pytest.approx(expected, abs=1e-15)
    assert expected == pytest.approx(0.0707963267948966, abs=1e-15)


def test_unwrapped_angles_cancel_in_the_total() -> None:
    # Robot yaw pi for a waypoint at -3.0: |pi + 3| = 6.14 rad; sin = -sin(3) cancels the first
    # segment's sin(0.1). Per segment the error is right (pi - 3 = 0.1416), the total is not.
    tl = _timeline([[0.0, 0.0, 0.1], [0.0, 1.0, -3.0]])
    body(
        tl.tf,
        "robot_markerset",
        steps((T0, (0.0, 0.0, 0.0), 0.0), (T0 + 9 * S, (0.0, 1.0, 0.0), pi)),
    )
    tl.goals = [
        TGoal(T0 + 2 * S, T0 + 8 * S, "result", "{}"),
        TGoal(T0 + 12 * S, T0 + 18 * S, "result", "{}"),
    ]
    tl.lookups = {"robot": [T0 + 8 * S + 10 * MS, T0 + 18 * S + 10 * MS]}
    score = _run(tl)
    assert score["segment_2"]["orientation_error"] == pytest.approx(pi - 3.0, abs=1e-15)
    total = atan2(abs(sin(0.1) + sin(pi + 3.0)), cos(0.1) + cos(pi + 3.0))
    assert score["orientation_accuracy[rad]"] == pytest.approx(total, abs=1e-15)
    assert total == pytest.approx(0.0207963267948967, abs=1e-15)  # the wrapped mean is 0.1208
    # before f594ff1 there was no fabs: the second segment's error is negative
    score_069 = _run(_rebuilt(tl), "069fd1d")
    assert score_069["segment_2"]["orientation_error"] == pytest.approx(-(pi - 3.0), abs=1e-15)


def _rebuilt(tl: Timeline) -> Timeline:
    """The same timeline again (a world consumes its lists)."""
    fresh = Timeline(t_ready_ns=tl.t_ready_ns, params=tl.params, files=dict(tl.files))
    fresh.tf = tl.tf
    fresh.goals = list(tl.goals)
    fresh.manual = list(tl.manual)
    fresh.stop_ns = tl.stop_ns
    fresh.lookups = {k: list(v) for k, v in tl.lookups.items()}
    return fresh


def test_divisor_is_the_completed_goals_but_sums_take_timeouts_too() -> None:
    # Errors 0.5 (completed), 1.0 (timed out, still looked up), 0.0 (completed): 1.5 / 2.
    tl = _timeline([[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [5.0, 0.0, 0.0]])
    body(
        tl.tf,
        "robot_markerset",
        steps(
            (T0, (1.5, 0.0, 0.0), 0.0),
            (T0 + 9 * S, (3.0, 0.0, 0.0), 0.0),
            (T0 + 19 * S, (5.0, 0.0, 0.0), 0.0),
        ),
    )
    tl.goals = [
        TGoal(T0 + 2 * S, T0 + 8 * S, "result", "{}"),
        TGoal(T0 + 12 * S, T0 + 18 * S, "timeout"),
        TGoal(T0 + 22 * S, T0 + 28 * S, "result", "{}"),
    ]
    tl.lookups = {"robot": [T0 + 8 * S + 10 * MS, T0 + 18 * S + 10 * MS, T0 + 28 * S + 10 * MS]}
    score = _run(tl)
    assert score["segment_2"]["timeout"] is True and score["segment_2"]["completed"] is False
    assert score["segment_2"]["distance_error"] == 1.0
    assert score["reached_waypoints"] == 2 and score["timed_out_waypoints"] == 1
    assert score["position_accuracy[m]"] == (0.5 + 1.0 + 0.0) / 2


def test_a_skipped_waypoint_counts_in_the_divisor() -> None:
    # Goal 1 completes, five 1 s attempts fail (no lookup logged), the referee answers 's';
    # goal 2 scores 0.2: position_accuracy = 0.2 / 2.
    tl = _timeline([[1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    body(tl.tf, "robot_markerset", still((2.2, 0.0, 0.0)))
    tl.goals = [
        TGoal(T0 + 2 * S, T0 + 8 * S, "result", "{}"),
        TGoal(T0 + 22 * S, T0 + 28 * S, "result", "{}"),
    ]
    tl.manual = [TManual(T0 + 15 * S, "s")]
    tl.lookups = {"robot": [T0 + 28 * S + 10 * MS]}
    score = _run(tl)
    assert score["segment_1"]["robot_pose"] == dump_none() == "null\n...\n"
    assert "distance_error" not in score["segment_1"]
    assert score["reached_waypoints"] == 2
    assert score["position_accuracy[m]"] == pytest.approx(0.2 / 2, abs=1e-15)
    # 00e3106 also kept the referee's answer
    score_17 = _run(_rebuilt(tl), "00e3106")
    assert score_17["segment_1"]["manual_operation"] == "s"
    assert {k: v for k, v in score_17["segment_1"].items() if k != "manual_operation"} == score[
        "segment_1"
    ]


def test_a_stop_during_a_goal_leaves_no_totals() -> None:
    tl = _timeline([[1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    body(tl.tf, "robot_markerset", still((1.0, 0.0, 0.0)))
    tl.goals = [TGoal(T0 + 2 * S, T0 + 8 * S, "result", "{}"), TGoal(T0 + 12 * S, None, "stopped")]
    tl.lookups = {"robot": [T0 + 8 * S + 10 * MS]}
    tl.stop_ns = T0 + 15 * S
    score = _run(tl)
    assert score["segment_2"]["timeout"] is None and score["segment_2"]["completed"] is False
    assert score["segment_2"]["segment_time[s]"] == 3.0
    assert "target_pose" not in score["segment_2"]
    assert "position_accuracy[m]" not in score and "reached_waypoints" not in score
    # f594ff1 went on after the failed lookup: the poses dumped (None) and the totals written
    score_nov = _run(_rebuilt(tl), "f594ff1")
    assert score_nov["segment_2"]["robot_pose"] == "null\n...\n"
    assert score_nov["reached_waypoints"] == 1
    assert score_nov["position_accuracy[m]"] == 0.0
