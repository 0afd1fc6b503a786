"""``--rules 2019``/``2017``/``f594ff1``/``069fd1d`` against the replays of the script
(``rsbb_replay.hnf``, statement by statement from each commit), field for field, on simulated
runs covering goals reached, timed out (also before the robot started), a mocap dropout with
the referee's "try again" and skip, a referee stop during a goal and during the lookup, the
global timeout, a short gap tf interpolates across, and a waypoint repeated with integers.

Each run is written with the replay's own saves as its live score and result file, so the
comparison the package prints is checked too: every field the same.

Tolerance 1e-12: the lookups' moments are in the log (the broadcasts) and both sides compute
the same tf2 arithmetic (interpolation, unnormalised products); what differs is the order of
floating-point operations in NumPy and in the replay's Python (a few ulps of values below
10 m and 2 pi).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest

from ertools.benchmarks.hnf import declare
from ertools.benchmarks.hnf.pipeline import find_runs, load, score_runs
from ertools.rsbb.score import flatten
from ertools.simulator.mocap import TrackingLoss
from tests.benchmarks.hnf.hnf_runs import HnfRun, goal, lookups, prompt, write_run
from tests.helpers.rsbb_replay.scenarios import at

pytestmark = pytest.mark.slow  # each run is written twice and replayed (~2 s)

TOL = 1e-12
WAYPOINTS = [[1.0, 0.0, 3.0], [2, 1, -3], [1.5, -0.5, 0.2], [1, 1, 3.1], [1, 1, 3.1]]


def _score(run: HnfRun, rules: str, **more: Any) -> Any:
    options = declare.make_options({"rules": rules, "draws": 0, **more})
    logs = load([run.bag], options)
    return score_runs(logs, find_runs(logs, options), options)


_NUMBER = re.compile(r"-?\d+\.\d+(?:e[-+]\d+)?")


def _same_text(mine: str, theirs: str, key: str) -> None:
    """The script's pose dumps hold each float's repr: the text around the numbers must be
    the same, the numbers within TOL (their last digit follows the order of operations)."""
    assert _NUMBER.sub("#", mine) == _NUMBER.sub("#", theirs), (key, mine, theirs)
    a = [float(x) for x in _NUMBER.findall(mine)]
    b = [float(x) for x in _NUMBER.findall(theirs)]
    assert a == pytest.approx(b, abs=TOL, rel=0), key


def _same(ours: dict[str, Any], theirs: dict[str, Any]) -> None:
    a, b = flatten(ours), flatten(theirs)
    assert list(a) == list(b), f"keys differ: {sorted(set(a) ^ set(b))}"
    for key, value in b.items():
        mine = a[key]
        if isinstance(value, float) and not isinstance(value, bool):
            assert isinstance(mine, float), key
            assert mine == pytest.approx(value, abs=TOL, rel=0), key
        elif isinstance(value, str) and value.startswith("!!python/object/new:"):
            assert isinstance(mine, str), key
            _same_text(mine, value, key)
        else:
            assert type(mine) is type(value) and mine == value, (key, mine, value)


def _check(run: HnfRun, rules: str) -> Any:
    assert run.replay.crashed is None and not run.replay.never_returned
    result = _score(run, rules)
    _same(result.score, run.replay.score)
    # the live score and the result file are the replay's saves: nothing differs
    c = result.comparison
    assert c.live_t_ns is not None and c.file is not None
    assert c.differing("live") == () and c.differing("file") == (), c.summary()
    return result


@pytest.fixture(scope="module")
def prompted(tmp_path_factory: pytest.TempPathFactory) -> dict[str, HnfRun]:
    """Goals reached, timed out, timed out before the start; a dropout with a retry and a
    skip; a 0.3 s gap under one lookup (tf interpolates); the script ends the run."""
    spec: dict[str, Any] = dict(
        waypoints=WAYPOINTS,
        goals=(
            goal(3, 4, 10, WAYPOINTS[0], "result", "{reached: 1}"),
            goal(11, 12, 21, WAYPOINTS[1], "timeout"),
            goal(22, None, 22.5, WAYPOINTS[2], "timeout"),
            goal(32, 33, 40, WAYPOINTS[3], "result", "{}"),
            goal(48, 49, 55, WAYPOINTS[4], "result", "done"),
        ),
        # goal 3: five failed attempts (22.5-27.5 s), "again", one more failure, then 31.4 s;
        # goal 4: five failures (40-45 s) during a dropout, then "s"
        manual=(prompt(27.52, 30.0, "again"), prompt(45.1, 47.0, "s")),
        broadcasts=lookups(10.01, 21.15, 31.4, 55.01),
        losses=(TrackingLoss(at(20.95), 0, 36), TrackingLoss(at(39.8), 0, 900)),
        end=("end", 56.0),
    )
    folder = tmp_path_factory.mktemp("prompted")
    return {
        v: write_run(folder / v, version=v, **spec)  # type: ignore[arg-type]
        for v in ("2bb8a41", "00e3106")
    }


def test_2019_prompted_run(prompted: dict[str, HnfRun]) -> None:
    result = _check(prompted["2bb8a41"], "2019")
    seg = result.score
    assert seg["segment_3"]["timeout"] is True and seg["segment_3"]["segment_time[s]"] == 0.0
    assert seg["segment_4"]["robot_pose"] == "null\n...\n"
    assert seg["reached_waypoints"] == 3 and seg["timed_out_waypoints"] == 2
    # four poses summed (goals 1, 2, 3, 5), three completed goals divide
    assert result.position_accuracy == pytest.approx(
        sum(seg[f"segment_{k}"]["distance_error"] for k in (1, 2, 3, 5)) / 3, abs=TOL
    )


def test_2017_prompted_run(prompted: dict[str, HnfRun]) -> None:
    result = _check(prompted["00e3106"], "2017")
    assert result.score["segment_3"]["manual_operation"] == "again"
    assert result.score["segment_4"]["manual_operation"] == "s"


def test_default_reading_of_the_prompted_run(prompted: dict[str, HnfRun]) -> None:
    run = prompted["2bb8a41"]
    ours = _score(run, "ertools")
    theirs = run.replay.score
    # the 0.3 s gap under goal 2's lookup: not measured (tf interpolated across it)
    assert (
        "distance_error" in theirs["segment_2"] and "distance_error" not in ours.score["segment_2"]
    )
    # accuracies over the completed goals with a pose: 1 and 5 (4 was skipped)
    d = [theirs[f"segment_{k}"]["distance_error"] for k in (1, 5)]
    assert ours.position_accuracy == pytest.approx(sum(d) / 2, abs=TOL)
    keys = {dev.rule.key for dev in ours.deviations}  # type: ignore[attr-defined]
    assert {"hnf.divisor", "hnf.skipped-waypoints", "hnf.gt-gaps", "hnf.score-format"} <= keys
    assert ours.score["segment_1"]["robot_pose"].keys() == {"x", "y", "theta"}
    # the reading's options one by one bring the script's numbers back
    back = _score(run, "ertools", divisor="2019", gt_gaps="interpolate", orientation_2019=True)
    assert back.position_accuracy == pytest.approx(theirs["position_accuracy[m]"], abs=TOL)
    assert back.orientation_accuracy == pytest.approx(theirs["orientation_accuracy[rad]"], abs=TOL)


@pytest.mark.parametrize("version,rules", [("2bb8a41", "2019"), ("00e3106", "2017")])
def test_referee_stop_during_a_goal(tmp_path: Path, version: str, rules: str) -> None:
    run = write_run(
        tmp_path,
        waypoints=WAYPOINTS,
        goals=(
            goal(3, 4, 10, WAYPOINTS[0]),
            goal(11, 12, None, WAYPOINTS[1], "stopped"),
        ),
        broadcasts=lookups(10.01),
        end=("stop", 15.0),
        version=version,
    )
    result = _check(run, rules)
    assert result.score["segment_2"]["timeout"] is None and "reached_waypoints" not in result.score
    ours = _score(run, "ertools")
    assert ours.score["reached_waypoints"] == 1  # totals over what was scored (hnf.stopped-runs)


@pytest.mark.parametrize("version,rules", [("2bb8a41", "2019"), ("00e3106", "2017")])
def test_referee_stop_during_the_prompt(tmp_path: Path, version: str, rules: str) -> None:
    run = write_run(
        tmp_path,
        waypoints=WAYPOINTS,
        goals=(goal(3, 4, 10, WAYPOINTS[0]), goal(11, 12, 20, WAYPOINTS[1])),
        manual=(prompt(25.1, None),),
        broadcasts=lookups(10.01),
        losses=(TrackingLoss(at(19.5), 0, 1200),),
        end=("stop", 26.0),
        version=version,
    )
    result = _check(run, rules)
    if version == "00e3106":
        assert result.score["segment_2"]["manual_operation"] == "not executed"


def test_global_timeout(tmp_path: Path) -> None:
    run = write_run(
        tmp_path,
        waypoints=WAYPOINTS,
        goals=(
            goal(3, 4, 10, WAYPOINTS[0]),
            goal(11, 12, 20, WAYPOINTS[1]),
            goal(21, 22, None, WAYPOINTS[2], "stopped"),
        ),
        broadcasts=lookups(10.01, 20.01),
        end=("global_timeout", 30.0),
    )
    _check(run, "2019")


@pytest.mark.parametrize("version", ["f594ff1", "069fd1d"])
def test_november_2017_scripts(tmp_path: Path, version: str) -> None:
    """No attempt limit (the lookup retried through a 3 s dropout), no prompt; a stop during
    the last lookup still writes the totals; 069fd1d's orientation errors keep their sign."""
    # the robot's yaw at 10 s is 0.29 rad: 3.29 rad from -3.0, beyond pi unwrapped
    waypoints = [[1.0, 0.0, -3.0], *WAYPOINTS[1:]]
    run = write_run(
        tmp_path,
        waypoints=waypoints,
        goals=(
            goal(3, 4, 10, waypoints[0]),
            goal(11, 12, 21, waypoints[1], "timeout"),
            goal(25, 26, 33, waypoints[2]),
        ),
        broadcasts=lookups(10.01, 24.3),
        losses=(TrackingLoss(at(20.9), 0, 400), TrackingLoss(at(32.5), 0, 2000)),
        end=("stop", 37.0),
        version=version,
    )
    result = _check(run, version)
    assert "position_accuracy[m]" in result.score
    if version == "069fd1d":
        assert "robot_pose" not in result.score["segment_3"]
        assert result.score["segment_1"]["orientation_error"] < 0  # no fabs: atan2(sin, cos)
    else:
        assert result.score["segment_3"]["robot_pose"] == "null\n...\n"
