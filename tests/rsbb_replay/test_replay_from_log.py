"""The replays driven by a run bag (``fromlog``): simulated runs whose every moment is known.

The robot's marker set stands at (1.5, 0, 0.3) (noiseless mocap); the team transform is the
identity; goal 1 (waypoint (1, 0, 0)) runs from 4 s to its result at 10 s, goal 2 ((2, 0, 0))
from 12 s to its timeout at 21 s; the script looks the robot up 10 ms after each. By hand:
both segments 0.5 m off, one waypoint reached: position_accuracy = (0.5 + 0.5) / 1. The other
benchmarks: one goal each, numbers in their tests.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from ertools.simulator.rsbb import write_rsbb_run
from ertools.simulator.rsbb_scenario import Broadcast, Goal, ManualOperation, Save
from tests.helpers.rsbb_replay import hgmf, hnf, hopf, hpff, hppf
from tests.helpers.rsbb_replay.fromlog import timeline_from_bag
from tests.helpers.rsbb_replay.py2 import dump_pose2d
from tests.helpers.rsbb_replay.scenarios import MS, at, hnf_scenario, still_body
from tests.helpers.rsbb_replay.world import World, run_script

pytestmark = pytest.mark.slow  # writes and reads a run bag (~0.6 s)

WAYPOINTS = [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]
PARAMS = {"starting_pose": [0.0, 0.0, 0.0], "waypoints": WAYPOINTS, "goal_timeout": 120.0}


def _scenario() -> object:
    identity = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    return replace(
        hnf_scenario(),
        t_end_ns=at(22.0),
        t_disconnect_ns=at(25.0),
        manual_operations=(),
        goals=(
            Goal(at(3.0), at(4.0), at(10.0), "[1.0, 0.0, 0.0]\n", "result", "{}"),
            Goal(at(11.0), at(12.0), at(21.0), "[2.0, 0.0, 0.0]\n", "timeout"),
        ),
        broadcasts=(
            Broadcast(at(10.01), "/robot", "/robot_markerset", *identity),
            Broadcast(at(21.01), "/robot", "/robot_markerset", *identity),
        ),
        saves=(Save(at(22.0), {}),),
        params=PARAMS,
        bodies=(still_body("robot_markerset", (1.5, 0.0, 0.3), seconds=30.0),),
    )


def test_hnf_replayed_from_its_bag(tmp_path: Path) -> None:
    paths = write_rsbb_run(tmp_path, _scenario())  # type: ignore[arg-type]
    transform = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
    tl = timeline_from_bag(paths.bag, PARAMS, {"transform": transform}, team="teamA")
    assert tl.t_ready_ns == at(2.0) and tl.stop_ns is None
    assert tl.lookups == {"robot": [at(10.01), at(21.01)]}
    result = run_script(World(tl), hnf.execute)
    assert result.crashed is None
    score = result.score
    seg1, seg2 = score["segment_1"], score["segment_2"]
    # the script's moments are the RefBox's: started 4 s and 12 s, ended 10 s and 21 s
    assert seg1["start_segment_time[s]"] == 2.0 and seg1["segment_time[s]"] == 6.0
    assert seg2["segment_time[s]"] == 9.0 and seg2["timeout"] is True
    assert seg1["target_pose"] == dump_pose2d(1.0, 0.0, 0.0)
    assert seg1["robot_pose"].startswith(
        "!!python/object/new:geometry_msgs.msg._Pose2D.Pose2D\nstate: [1.5"
    )
    assert seg1["distance_error"] == pytest.approx(0.5, abs=1e-12)
    assert seg2["distance_error"] == pytest.approx(0.5, abs=1e-12)
    assert seg1["orientation_error"] == pytest.approx(0.0, abs=1e-12)
    assert score["reached_waypoints"] == 1 and score["timed_out_waypoints"] == 1
    assert score["execution_time[s]"] == 15.0
    assert score["position_accuracy[m]"] == pytest.approx(1.0, abs=1e-12)
    assert score["orientation_accuracy[rad]"] == pytest.approx(0.0, abs=1e-12)


def _one_goal_run(code: str, bodies: tuple, manual: tuple, broadcasts: tuple, goal: Goal) -> object:  # type: ignore[type-arg]
    """A run of ``code`` with one goal and its manual operations, stopped at 15 s while the
    next goal's first manual operation waits."""
    return replace(
        hnf_scenario(),
        code=code,
        t_end_ns=at(15.0),
        end="stop",
        t_disconnect_ns=at(16.0),
        manual_operations=manual,
        goals=(goal,),
        broadcasts=broadcasts,
        saves=(Save(at(15.0), {}),),
        params={},
        bodies=bodies,
    )


IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def test_hopf_replayed_from_its_bag(tmp_path: Path) -> None:
    # the item 0.1 m ahead of the positioner at (0.5, 0.6): (0.6, 0.6); answered (0.6, 0.7)
    item = {
        "id": 1,
        "class": "a",
        "instance": "i1",
        "description": "thing 1",
        "trans": [0.1, 0.0, 0.0],
        "rot": [0.0, 0.0, 0.0, 1.0],
    }
    place = "Place the positioner and the thing 1 (id: 1, instance: i1) on the table"
    sc = _one_goal_run(
        "HOPF",
        (
            still_body("table_origin", (0.0, 0.0, 0.0), 20.0),
            still_body("positioner_origin", (0.5, 0.6, 0.0), 20.0),
        ),
        (
            ManualOperation(at(2.5), at(3.0), place),
            ManualOperation(at(4.0), at(5.0), "Remove the positioner"),
            ManualOperation(
                at(11.0),
                None,
                place.replace("thing 1 (id: 1, instance: i1)", "thing 2 (id: 2, instance: i2)"),
            ),
        ),
        (
            Broadcast(
                at(3.01), "/item", "/positioner_origin", (0.1, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)
            ),
        ),
        Goal(
            at(5.5),
            at(6.0),
            at(10.0),
            "{}\n",
            "result",
            "{x: 0.6, y: 0.7, theta: 0.0, class: a, instance: i1}",
        ),
    )
    paths = write_rsbb_run(tmp_path, sc)  # type: ignore[arg-type]
    params = {"table_size": {"x": 1.0, "y": 1.5}, "goal_timeout": 120}
    item2 = {**item, "id": 2, "instance": "i2", "description": "thing 2"}
    tl = timeline_from_bag(paths.bag, params, {"items": [item, item2]})
    assert tl.files["items_order"] == [1, 2]
    result = run_script(World(tl), hopf.execute)
    assert result.crashed is None
    g1 = result.score["goal_1"]
    assert g1["item_acquired"]["pose"] == pytest.approx([0.6, 0.6, 0.0], abs=1e-12)
    assert g1["partial_score"]["pose_score"] == pytest.approx(1 - 0.1 / 2, abs=1e-12)
    assert result.score["class_accuracy"] == 1.0 and result.score["execution_time"] == 4.0
    assert result.score["goal_2"] == {}


def test_hppf_replayed_from_its_bag(tmp_path: Path) -> None:
    enter = (
        "Joe should enter the target area wearing a cap with MoCap markers, and place "
        "him/herself in an arbitrary position."
    )
    sc = _one_goal_run(
        "HPPF",
        (still_body("actor_markerset", (1.0, 2.0, 1.7), 20.0),),
        (
            ManualOperation(at(2.5), at(3.0), enter),
            ManualOperation(at(11.0), None, enter.replace("Joe", "Ann")),
        ),
        (
            Broadcast(at(3.01), "/person", "/actor_markerset", *IDENTITY),
            Broadcast(at(10.01), "/person", "/actor_markerset", *IDENTITY),
        ),
        Goal(
            at(5.5),
            at(6.0),
            at(10.0),
            "{}\n",
            "result",
            "{x: 1.3, y: 2.4, theta: 0, person_name: JOE}",
        ),
    )
    paths = write_rsbb_run(tmp_path, sc)  # type: ignore[arg-type]
    tl = timeline_from_bag(paths.bag, {"people": ["Joe", "Ann"], "goal_timeout": 120.0}, {})
    assert tl.files["people_order"] == ["Joe", "Ann"]
    result = run_script(World(tl), hppf.execute)
    assert result.score["goal_0"]["position_error"] == pytest.approx(0.5, abs=1e-12)
    assert result.score["% Recognized persons"] == "50.0%"
    assert result.score["goal_1"] == {}


def test_hgmf_replayed_from_its_bag(tmp_path: Path) -> None:
    place = "Place the Brick on the table, with MoCap markers attached."
    sc = _one_goal_run(
        "HGMF",
        (
            still_body("table_origin", (0.0, 0.0, 0.0), 20.0),
            still_body("actor_markerset", (0.7, 0.9, 0.0), 20.0),
        ),
        (
            ManualOperation(at(2.5), at(3.0), place),
            ManualOperation(at(11.0), None, place.replace("Brick", "Cube")),
        ),
        (
            Broadcast(at(3.01), "/object", "/actor_markerset", *IDENTITY),
            Broadcast(at(10.01), "/object", "/actor_markerset", *IDENTITY),
        ),
        Goal(at(5.5), at(6.0), at(10.0), "[0.8, 0.9, 1]\n", "result", "{}"),
    )
    paths = write_rsbb_run(tmp_path, sc)  # type: ignore[arg-type]
    objects = [{"id": 1, "description": "Brick"}, {"id": 2, "description": "Cube"}]
    params = {"objects": objects, "table_size": {"x": 1.0, "y": 1.5}, "goal_timeout": 120.0}
    tl = timeline_from_bag(paths.bag, params, {})
    assert tl.files["objects_order"] == [1] and tl.files["targets"] == [(0.8, 0.9)]
    result = run_script(World(tl), hgmf.execute)
    assert result.crashed is None
    g0 = result.score["goal_0"]
    assert g0["Object grasped"] is False
    assert g0["Distance error"] == pytest.approx(0.1, abs=1e-12)
    assert result.score["Objects grasped"] == "0 out of 2"


def test_hpff_replayed_from_its_bag(tmp_path: Path) -> None:
    # goal_timeout 25 s from the request at 3 s: samples from 3.5 + 8 = 11.5 s every 0.5 s until
    # the timeout at 28 s (33 samples), each a relative and an absolute broadcast; the robot 2 m
    # behind the cap: no deviation, nothing covered (0.0: pairs of equal poses were added).
    samples = [at(11.5) + k * 500 * MS for k in range(33)]
    broadcasts = [Broadcast(at(2.01), "/robot", "/robot_markerset", *IDENTITY)]
    for s in samples:
        broadcasts += [
            Broadcast(s, "/robot", "/robot_markerset", *IDENTITY),
            Broadcast(s + 30 * MS, "/robot", "/robot_markerset", *IDENTITY),
        ]
    sc = replace(
        hnf_scenario(),
        code="HPFF",
        t_end_ns=at(28.1),
        end="stop",
        t_disconnect_ns=at(29.0),
        manual_operations=(),
        goals=(Goal(at(3.0), at(3.5), at(28.0), "{}\n", "timeout"),),
        broadcasts=tuple(broadcasts),
        saves=(Save(at(28.05), {}),),
        params={},
        bodies=(
            still_body("robot_markerset", (0.0, 0.0, 0.0), 35.0),
            still_body("actor_markerset", (2.0, 0.0, 1.7), 35.0),
        ),
    )
    paths = write_rsbb_run(tmp_path, sc)
    params = {
        "min_following_distance": 0.15,
        "max_following_distance": 3.5,
        "desired_following_distance": 2.0,
        "goal_timeout": 25.0,
    }
    transform = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
    tl = timeline_from_bag(paths.bag, params, {"transform": transform})
    assert len(tl.lookups["robot"]) == 67
    result = run_script(World(tl), hpff.execute)
    assert result.crashed is None
    assert result.score == {
        "Average deviation from desired distance": pytest.approx(0.0, abs=1e-12),
        "Distance covered while following": 0.0,
        "Benchmark reliability": "100.0%",
    }
    assert type(result.score["Distance covered while following"]) is float
