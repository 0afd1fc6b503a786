"""``ertools score hpff --rules 2019`` against the replay of the script (``rsbb_replay.hpff``,
statement by statement from 2bb8a41), field for field, on simulated runs: a passing run with
the robot and the cap lost for a while, a result reported early (failed), a referee stop while
sampling, a stop before the goal (the script loops for ever), a check answered by the referee,
mostly failed lookups (the WARNING). Each run's live score and result file are the replay's
own saves: the comparison must find nothing differing.

Tolerance 1e-12 (see tests/benchmarks/hnf/test_hnf_replay.py); the reliability and warning
texts exactly.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from ertools.benchmarks.hpff import declare
from ertools.benchmarks.hpff.pipeline import find_runs, load, score_runs
from ertools.simulator.rsbb_scenario import Goal, ManualOperation
from tests.benchmarks.hpff.hpff_runs import PROMPT, HpffRun, schedule, write_run
from tests.helpers.inprocess import run as ertools
from tests.helpers.rsbb_replay.scenarios import at

pytestmark = pytest.mark.slow  # each run is written twice and replayed (~3 s)

TOL = 1e-12


def _score(run: HpffRun, **values: Any) -> Any:
    options = declare.make_options({"draws": 0, **values})
    logs = load([run.bag], options)
    return score_runs(logs, find_runs(logs, options), options)


def _same(ours: dict[str, Any], theirs: dict[str, Any]) -> None:
    assert list(ours) == list(theirs)
    for key, value in theirs.items():
        mine = ours[key]
        if isinstance(value, float):
            assert isinstance(mine, float) and mine == pytest.approx(value, abs=TOL, rel=0), key
        else:
            assert type(mine) is type(value) and mine == value, (key, mine, value)


def _check(run: HpffRun) -> Any:
    result = _score(run, rules="2019")
    _same(result.score, run.replay.score)
    c = result.comparison
    assert c.differing("live") == () and c.differing("file") == (), c.summary()
    return result


def _timeout_goal(request: float, timeout: float = 40.0) -> Goal:
    return Goal(at(request), at(request + 0.6), at(request + timeout), "{}\n", "timeout")


def test_a_passing_run_with_dropouts(tmp_path: Path) -> None:
    robot_lost = ((20.0, 0.8),)
    person_lost = ((30.0, 1.5),)
    lookups = [2.01, *schedule(3.6, 43.0, robot_lost, person_lost)]
    run = write_run(
        tmp_path,
        goal=_timeout_goal(3.0),
        lookups=lookups,
        end=("stop", 43.6),
        robot_lost=robot_lost,
        person_lost=person_lost,
    )
    assert run.replay.aborted == "" and run.replay.crashed is None
    result = _check(run)
    s = result.stats
    assert s.failed > 0 and s.measured > 50
    assert result.score["Benchmark reliability"].endswith("%")
    assert isinstance(result.score["Distance covered while following"], float)
    # ertools' reading: the grid, horizontally, the RefBox's duration
    ours = _score(run)
    assert ours.passed and ours.duration_s == pytest.approx(40.0 - 0.6, abs=1e-9)
    keys = {d.rule.key for d in ours.deviations}
    assert {"hpff.sampling", "hpff.distance-plane", "hpff.duration-clock"} <= keys
    # the script's sampling and plane, one option each, give its numbers back
    back = ertools(
        [
            "score",
            "hpff",
            str(run.bag),
            "--draws",
            "0",
            "--format",
            "json",
            "--sampling",
            "script",
            "--distance-plane",
            "actor",
            "--duration-clock",
            "script",
        ]
    )
    assert back.code == 0, back.stderr
    _same(json.loads(back.stdout), run.replay.score)


def test_a_result_reported_early_fails(tmp_path: Path) -> None:
    goal = Goal(at(3.0), at(3.6), at(23.0), "{}\n", "result", "{}")
    run = write_run(tmp_path, goal=goal, lookups=[2.01, *schedule(3.6, 23.0)], end=("stop", 23.6))
    result = _check(run)
    assert result.score == {"Result": "Benchmark failed: finished prematurely or took too long"}
    ours = _score(run)
    assert ours.score["Result"] == result.score["Result"] and "Benchmark reliability" in ours.score


def test_a_referee_stop_while_sampling(tmp_path: Path) -> None:
    goal = Goal(at(3.0), at(3.6), None, "{}\n")
    run = write_run(tmp_path, goal=goal, lookups=[2.01, *schedule(3.6, 20.0)], end=("stop", 20.0))
    result = _check(run)
    assert result.score == {}
    ours = _score(run)
    assert ours.score["Result"].startswith("Benchmark failed") and ours.stats.measured > 0


def test_a_stop_before_the_goal_loops_for_ever(tmp_path: Path) -> None:
    run = write_run(
        tmp_path,
        goal=Goal(at(9.0), None, None, "{}\n"),
        lookups=[],
        manual=(ManualOperation(at(3.6), None, PROMPT),),
        end=("stop", 5.0),
    )
    assert run.replay.never_returned
    result = _check(run)
    assert result.score == {} and any("loop for ever" in w for w in result.warnings)


def test_the_referee_answers_the_check(tmp_path: Path) -> None:
    # the check fails three times (2.0-3.5 s), the referee answers at 6 s, then it succeeds
    lookups = [6.01, *schedule(7.6, 47.0)]
    run = write_run(
        tmp_path,
        goal=_timeout_goal(7.0),
        lookups=lookups,
        manual=(ManualOperation(at(3.55), at(6.0), PROMPT, "ok"),),
        end=("stop", 47.6),
    )
    _check(run)


def test_mostly_failed_lookups_warn(tmp_path: Path) -> None:
    person_lost = ((11.0, 25.0),)
    run = write_run(
        tmp_path,
        goal=_timeout_goal(3.0),
        lookups=[2.01, *schedule(3.6, 43.0, (), person_lost)],
        end=("stop", 43.6),
        person_lost=person_lost,
    )
    result = _check(run)
    assert result.score["WARNING"].endswith(
        "% of the time, mocap pose acquiring failed. Consider repeating the benchmark."
    )
