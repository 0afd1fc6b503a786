"""The HPFF replay on hand-built runs: each quirk of docs/hpff.md with its number worked out here.

The goal is requested 2 s after T0 and the robot starts 1 s later; the script sleeps 8 s, so
sample k starts at T0 + 11 s + k * 0.5 s. A successful relative lookup is logged at the
sample's start and the absolute one 30 ms later; after a failed relative lookup (0.2 s) the
absolute one comes at +200 ms + 1 us.
"""

from __future__ import annotations

from collections.abc import Callable

import pytest

from tests.helpers.rsbb_replay import hpff
from tests.helpers.rsbb_replay.hand import MS, T0, S, body, still
from tests.helpers.rsbb_replay.tf2 import Quat, Vec
from tests.helpers.rsbb_replay.world import TGoal, Timeline, World, run_script

pytestmark = pytest.mark.slow  # runs of several hundred samples: seconds each

REQUEST = T0 + 2 * S
START = T0 + 3 * S
FIRST_SAMPLE = START + 8 * S
HALF = 500 * MS
PARAMS = {
    "min_following_distance": 0.15,
    "max_following_distance": 3.5,
    "desired_following_distance": 2.0,
}


def _timeline(
    goal_timeout: float,
    samples: int,
    fails: set[int],
    robot: Callable[[int], tuple[Vec, Quat]],
    actor: Callable[[int], tuple[Vec, Quat]],
    end: int | None = None,
) -> Timeline:
    tl = Timeline(t_ready_ns=T0 + S, params={**PARAMS, "goal_timeout": goal_timeout})
    tl.files["transform"] = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
    t_end = end if end is not None else REQUEST + round(goal_timeout * S)
    span = t_end + 20 * S
    body(tl.tf, "robot_markerset", robot, end=span)
    body(tl.tf, "actor_markerset", actor, end=span)
    stamps = [T0 + S + 10 * MS]  # the check before the goal
    for k in range(samples):
        s = FIRST_SAMPLE + k * HALF
        stamps += [s + 200 * MS + 1000] if k in fails else [s, s + 30 * MS]
    tl.lookups = {"robot": stamps}
    tl.goals = [TGoal(START, t_end, "timeout" if end is None else "result", "{}")]
    return tl


def test_reliability_is_python_2_text_and_the_distance_stays_an_integer_zero() -> None:
    # goal_timeout 209 s: the timeout at T0 + 211 s ends the loop after 400 samples (the last
    # starts at 210.5 s); 51 failures: 100 - 51/400*100 = 87.25, which Python 2 rounded to 87.3.
    fails = set(range(0, 400, 8)) | {399}
    assert len(fails) == 51
    # the cap 5 m ahead of the robot: always out of range, nothing covered
    tl = _timeline(209.0, 400, fails, still((0.0, 0.0, 0.0)), still((5.0, 0.0, 1.7)))
    result = run_script(World(tl), hpff.execute)
    assert result.crashed is None
    assert result.score == {
        "Average deviation from desired distance": pytest.approx(3.0, abs=1e-15),
        "Distance covered while following": 0,
        "Benchmark reliability": "87.3%",
    }
    assert type(result.score["Distance covered while following"]) is int
    assert result.aborted == ""  # the complete run ends by an abort (a RefBox stop)


def test_distance_covered_and_the_warning() -> None:
    # goal_timeout 20 s: timeout at T0 + 22 s; samples start at 11.0 ... 21.5 s (22 of them).
    # The robot and the cap walk along y at 0.2 m/s, 2 m apart: every sample in range.
    def robot(t: int) -> tuple[Vec, Quat]:
        return (0.0, 0.2 * (t - T0) / S, 0.0), (0.0, 0.0, 0.0, 1.0)

    def actor(t: int) -> tuple[Vec, Quat]:
        return (2.0, 0.2 * (t - T0) / S, 1.7), (0.0, 0.0, 0.0, 1.0)

    fails = set(range(0, 22, 2))  # 11 failures of 22: 50 %, no warning (it needs > 50)
    tl = _timeline(20.0, 22, fails, robot, actor)
    score = run_script(World(tl), hpff.execute).score
    # pairs (k-1, k) with k a success: k odd, k-1 failed: absolute lookups at
    # s_k + 30 ms and s_(k-1) + 200.001 ms, 0.329999 s apart, 0.2 m/s: 11 pairs.
    assert score["Distance covered while following"] == pytest.approx(
        11 * 0.2 * 0.329999, abs=1e-12
    )
    assert score["Average deviation from desired distance"] == pytest.approx(0.0, abs=1e-12)
    assert score["Benchmark reliability"] == "50.0%"
    assert "WARNING" not in score
    fails = set(range(0, 22, 2)) | {1}  # 12 of 22
    score = run_script(World(_timeline(20.0, 22, fails, robot, actor)), hpff.execute).score
    percent = 12 / 22.0 * 100
    assert (
        score["WARNING"]
        == "%.1f%% of the time, mocap pose acquiring failed. Consider repeating the benchmark."
        % percent
    )
    assert score["WARNING"].startswith("54.5%")
    assert score["Benchmark reliability"] == "45.5%"


def test_a_result_long_before_the_timeout_fails_the_run() -> None:
    # the robot reports a result 100 s after starting: 100 s is outside 300 +- 15 s
    tl = _timeline(
        300.0, 200, set(), still((0.0, 0.0, 0.0)), still((2.0, 0.0, 1.7)), end=START + 100 * S
    )
    result = run_script(World(tl), hpff.execute)
    assert result.score == {"Result": "Benchmark failed: finished prematurely or took too long"}
    assert result.aborted == "Benchmark failed! Finished prematurely or took too long"


def test_the_duration_bounds_are_inclusive() -> None:
    # goal_timeout 25 s: the run passes with 10 s <= duration <= 40 s. A result 10.0 s after
    # the start (at a sample's end: 8 s of sleep + 4 samples) passes, 9.5 s fails.
    for seconds, passes in ((10.0, True), (9.5, False)):
        t_end = START + round(seconds * S)
        tl = _timeline(25.0, 10, set(), still((0.0, 0.0, 0.0)), still((2.0, 0.0, 1.7)), end=t_end)
        score = run_script(World(tl), hpff.execute).score
        assert ("Result" not in score) is passes, seconds
        if passes:
            assert score["Benchmark reliability"] == "100.0%"


def test_no_sample_and_a_passing_duration_divides_by_zero() -> None:
    # goal_timeout 20 s (pass from 5 s): a result 5 s after the start, inside the 8 s sleep;
    # the loop never samples, duration 8 s passes, 0 / 0.0 kills the script: nothing saved.
    tl = _timeline(
        20.0, 0, set(), still((0.0, 0.0, 0.0)), still((2.0, 0.0, 1.7)), end=START + 5 * S
    )
    result = run_script(World(tl), hpff.execute)
    assert result.crashed is not None and result.crashed.startswith("ZeroDivisionError")
    assert result.score == {}


def test_a_stop_while_following_leaves_an_empty_score() -> None:
    tl = _timeline(300.0, 100, set(), still((0.0, 0.0, 0.0)), still((2.0, 0.0, 1.7)))
    tl.stop_ns = FIRST_SAMPLE + 20 * S
    result = run_script(World(tl), hpff.execute)
    assert result.score == {} and result.crashed is None


def test_a_stop_before_the_goal_never_returns() -> None:
    tl = _timeline(300.0, 10, set(), still((0.0, 0.0, 0.0)), still((2.0, 0.0, 1.7)))
    tl.lookups = {"robot": []}  # the first check fails, three times
    tl.stop_ns = T0 + 2 * S
    result = run_script(World(tl), hpff.execute)
    assert result.never_returned and result.score == {}
