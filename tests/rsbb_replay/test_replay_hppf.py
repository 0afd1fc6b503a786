"""The HPPF replay on hand-built runs: each quirk of docs/hppf.md with its number worked out here.

The cap (``actor_markerset``) stands at (1.0, 2.0) throughout. Goal k (0-based) starts 20k s
after T0: first manual operation done at +2 s, check lookup at +3 s, goal from +5 s to +9 s,
ground-truth lookup 10 ms after the goal.
"""

from __future__ import annotations

import pytest

from tests.helpers.rsbb_replay import hppf
from tests.helpers.rsbb_replay.hand import MS, T0, S, body, still
from tests.helpers.rsbb_replay.world import TGoal, Timeline, TManual, World, run_script


def _timeline(people: list[str], order: list[str]) -> Timeline:
    tl = Timeline(t_ready_ns=T0 + S, params={"people": list(people), "goal_timeout": 120.0})
    tl.files["people_order"] = list(order)
    body(tl.tf, "actor_markerset", still((1.0, 2.0, 1.7)))
    return tl


def _goal(
    tl: Timeline, base: int, answer: str | None, outcome: str = "result", gt: bool = True
) -> None:
    tl.manual.append(TManual(base + 2 * S))
    tl.lookups.setdefault("person", []).append(base + 3 * S)
    tl.goals.append(TGoal(base + 5 * S, base + 9 * S, outcome, answer))
    if gt and outcome == "result":
        tl.lookups["person"].append(base + 9 * S + 10 * MS)


def _run(tl: Timeline) -> tuple[dict[str, object], str | None]:
    result = run_script(World(tl), hppf.execute)
    return result.score, result.crashed


def test_recognition_distance_and_the_percentage_text() -> None:
    tl = _timeline(["Joe", "Peter", "Alice"], ["Peter", "Joe", "Alice"])
    _goal(tl, T0, "{x: 1.3, y: 2.4, theta: 0.0, person_name: peter}")  # 0.5 m off, lower case
    _goal(tl, T0 + 20 * S, "{x: 1.0, y: 2.0, theta: 0.0, person_name: Jim}")  # wrong name
    _goal(tl, T0 + 40 * S, None, "timeout")
    score, crashed = _run(tl)
    assert crashed is None
    g0, g1, g2 = score["goal_0"], score["goal_1"], score["goal_2"]
    assert g0["detected"] is True and g0["recognized"] is True
    assert g0["position_error"] == pytest.approx(0.5, abs=1e-15)
    assert g0["ground-truth person position"] == "(1.00, 2.00)"
    assert g0["robot-estimated person position"] == "(1.30, 2.40)"
    assert g0["segment_time [s]"] == 4.0
    assert g1["recognized"] is False and g1["position_error"] == 0.0
    assert g2 == {"segment_time [s]": 4.0, "timeout": True, "completed": False, "detected": False}
    assert score["Recognized persons"] == 1
    assert score["% Recognized persons"] == "33.33%"  # str(round(1 / 3.0 * 100, 2)) + '%'
    assert score["Distance error"] == pytest.approx((0.5 + 0.0) / 2, abs=1e-15)
    assert score["execution_time"] == 12.0


def test_three_of_five_is_sixty_point_zero_percent() -> None:
    people = ["A", "B", "C", "D", "E"]
    tl = _timeline(people, people)
    for k, name in enumerate(people):
        answer = "{x: 1.0, y: 2.0, theta: 0, person_name: %s}" % (name if k < 3 else "nobody")
        _goal(tl, T0 + 20 * k * S, answer)
    score, _ = _run(tl)
    assert score["Recognized persons"] == 3
    assert score["% Recognized persons"] == "60.0%"


def test_a_completed_goal_without_ground_truth_is_restarted() -> None:
    # Goal 0 completes at +9 s but its three 1 s lookups fail: its 4 s are taken back, the
    # person goes back, and goal_0 is played again (the next draw: Joe) from +20 s.
    tl = _timeline(["Joe", "Peter"], ["Peter", "Joe", "Peter"])
    _goal(tl, T0, "{x: 5.0, y: 5.0, theta: 0.0, person_name: Peter}", gt=False)
    _goal(tl, T0 + 20 * S, "{x: 1.0, y: 2.5, theta: 0.0, person_name: Joe}")
    _goal(tl, T0 + 40 * S, "{x: 1.0, y: 2.0, theta: 0.0, person_name: Peter}")
    score, crashed = _run(tl)
    assert crashed is None
    assert score["goal_0"]["robot-estimated person position"] == "(1.00, 2.50)"  # Joe's goal
    assert score["goal_0"]["position_error"] == 0.5
    assert score["Recognized persons"] == 2 and score["% Recognized persons"] == "100.0%"
    assert score["Distance error"] == 0.25
    assert score["execution_time"] == 8.0  # the restarted goal's 4 s taken back


def test_an_answer_without_theta_kills_the_script() -> None:
    tl = _timeline(["Joe"], ["Joe"])
    _goal(tl, T0, "{x: 1.0, y: 2.0, person_name: Joe}")
    score, crashed = _run(tl)
    assert crashed is not None and crashed.startswith("KeyError")
    assert score == {"goal_0": {"segment_time [s]": 4.0}}  # the last save
