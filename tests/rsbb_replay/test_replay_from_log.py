"""The replays driven by a run bag (``fromlog``): a simulated HNF run whose every moment is known.

The robot's marker set stands at (1.5, 0, 0.3) (noiseless mocap); the team transform is the
identity; goal 1 (waypoint (1, 0, 0)) runs from 4 s to its result at 10 s, goal 2 ((2, 0, 0))
from 12 s to its timeout at 21 s; the script looks the robot up 10 ms after each. By hand:
both segments 0.5 m off, one waypoint reached: position_accuracy = (0.5 + 0.5) / 1.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from ertools.samples.rsbb import write_rsbb_run
from ertools.samples.rsbb_scenario import Broadcast, Goal, Save
from rsbb_replay import hnf
from rsbb_replay.fromlog import timeline_from_bag
from rsbb_replay.py2 import dump_pose2d
from rsbb_replay.scenarios import at, hnf_scenario, still_body
from rsbb_replay.world import World, run_script

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
