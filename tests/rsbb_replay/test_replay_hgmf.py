"""The HGMF replay on hand-built runs: each quirk of docs/hgmf.md with its number worked out here.

The table's marker set is the testbed origin. Goal k (0-based) starts 20k s after T0: first
manual operation done at +2 s, reference lookup at +3 s, goal from +5 s to +10 s, final lookup
10 ms later. The grasp checks run at +5.1, +5.2 ... s (the 10 Hz timer).
"""

from __future__ import annotations

import pytest

from tests.helpers.rsbb_replay import hgmf
from tests.helpers.rsbb_replay.hand import MS, T0, S, body, steps, still
from tests.helpers.rsbb_replay.world import TGoal, Timeline, TManual, World, run_script

OBJECTS = [{"id": 1, "description": "Brick"}, {"id": 2, "description": "Cube"}]
PARAMS = {"objects": OBJECTS, "table_size": {"x": 1.0, "y": 1.5}, "goal_timeout": 120.0}


def _timeline(order: list[int], targets: list[tuple[float, float]], pieces: tuple) -> Timeline:  # type: ignore[type-arg]
    tl = Timeline(t_ready_ns=T0 + S, params={**PARAMS, "objects": [dict(o) for o in OBJECTS]})
    tl.files.update(objects_order=list(order), targets=list(targets))
    body(tl.tf, "table_origin", still((0.0, 0.0, 0.0)))
    body(tl.tf, "actor_markerset", steps(*pieces))
    return tl


def _goal(tl: Timeline, base: int, outcome: str = "result", final: bool = True) -> None:
    tl.manual.append(TManual(base + 2 * S))
    tl.lookups.setdefault("object", []).append(base + 3 * S)
    tl.goals.append(TGoal(base + 5 * S, base + 10 * S, outcome, "{}"))
    if final and outcome == "result":
        tl.lookups["object"].append(base + 10 * S + 10 * MS)


def test_a_grasp_is_a_rise_of_more_than_three_centimetres() -> None:
    # Brick: lifted to 8 cm at +6 s, put down at (0.7, 0.9) at +8 s: grasped, 5 cm from the
    # target (0.75, 0.9). Cube: raised to exactly 3 cm (not more), put down at (0.3, 0.3)
    # for a target (0.3, 0.4): not grasped, 0.1 m.
    b = T0 + 20 * S
    tl = _timeline(
        [1, 2],
        [(0.75, 0.9), (0.3, 0.4)],
        (
            (T0, (0.3, 0.4, 0.0), 0.0),
            (T0 + 6 * S, (0.3, 0.4, 0.08), 0.0),
            (T0 + 8 * S, (0.7, 0.9, 0.0), 0.0),
            (b + 6 * S, (0.7, 0.9, 0.03), 0.0),
            (b + 8 * S, (0.3, 0.3, 0.0), 0.0),
        ),
    )
    _goal(tl, T0)
    _goal(tl, b)
    result = run_script(World(tl), hgmf.execute)
    assert result.crashed is None
    g0, g1 = result.score["goal_0"], result.score["goal_1"]
    assert g0["Object grasped"] is True and g1["Object grasped"] is False
    assert g0["Distance error"] == pytest.approx(0.05, abs=1e-15)
    assert g1["Distance error"] == pytest.approx(0.1, abs=1e-15)
    assert g0["Target object position"] == "(0.75, 0.90)"
    assert g0["Measured object position"] == "(0.70, 0.90)"
    assert g0["Object type"] == "Brick (id 1)" and g1["Object type"] == "Cube (id 2)"
    assert g0["segment_time [s]"] == 5.0
    assert result.score["Objects grasped"] == "1 out of 2"
    assert result.score["Avg distance error"] == pytest.approx((0.05 + 0.1) / 2, abs=1e-15)
    assert result.score["execution_time"] == 10.0


def test_a_restarted_goal_still_counts_in_the_divisor_and_the_grasps() -> None:
    # Goal 0 (Brick) is grasped and completed, but its final lookup fails (3 s): restarted; the
    # Brick again (+20 s): not grasped, 0.1 m. Avg = 0.1 / 2 goals completed; 1 grasp counted.
    b = T0 + 20 * S
    tl = _timeline(
        [1, 1],
        [(0.75, 0.9), (0.3, 0.4)],
        (
            (T0, (0.3, 0.4, 0.0), 0.0),
            (T0 + 6 * S, (0.3, 0.4, 0.08), 0.0),
            (T0 + 8 * S, (0.3, 0.3, 0.0), 0.0),
        ),
    )
    _goal(tl, T0, final=False)
    _goal(tl, b)
    tl.manual.append(TManual(None))  # the Cube's first manual operation, then the stop
    tl.stop_ns = T0 + 40 * S
    result = run_script(World(tl), hgmf.execute)
    assert result.crashed is None
    assert result.score["goal_0"]["Object grasped"] is False
    assert result.score["Objects grasped"] == "1 out of 2"
    assert result.score["Avg distance error"] == pytest.approx(0.1 / 2, abs=1e-15)
    assert result.score["execution_time"] == 5.0  # the restarted goal's 5 s taken back
    assert result.score["goal_1"] == {}


def test_a_goal_not_completed() -> None:
    tl = _timeline([1, 2], [(0.75, 0.9), (0.3, 0.6)], ((T0, (0.3, 0.4, 0.0), 0.0),))
    _goal(tl, T0, "timeout")
    _goal(tl, T0 + 20 * S, "timeout")
    score = run_script(World(tl), hgmf.execute).score
    assert score["goal_0"] == {
        "segment_time [s]": 5.0,
        "timeout": True,
        "completed": False,
        "result": "Not completed",
    }
    assert "Avg distance error" not in score and score["execution_time"] == 10.0
