"""HPFF's numbers by hand, and bad input.

Noiseless: the robot's marker set stands at (0, 0, 0.7), the person's cap at (2.5, 0, 1.7)
(level), the team transform the identity: the horizontal distance is 2.5 m, 0.5 m from the
desired 2.0. The goal runs from 3.6 s (the robot's start) to its timeout at 43.0 s: ertools'
grid samples every 0.5 s from 11.6 s to 42.6 s, 63 samples; the robot is lost from 20.0 s for
one second, so the samples at 20.1 s and 20.6 s have no valid robot: 61 measured, 2 failed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from ertools.benchmarks.hpff import declare
from ertools.benchmarks.hpff.pipeline import find_runs, load, score_runs
from ertools.errors import ConfigError, UsageError
from ertools.simulator.mocap import TrackingLoss, frame_times, simulate_mocap
from ertools.simulator.rsbb import write_rsbb_run
from ertools.simulator.rsbb_scenario import Body, Goal, RsbbScenario, Save, still_pose
from tests.helpers.inprocess import run as ertools
from tests.helpers.rsbb_replay.scenarios import QUIET, T0, at

pytestmark = pytest.mark.slow  # writes a run bag


def _body(name: str, xyz: tuple[float, float, float], losses: list[TrackingLoss]) -> Body:
    t = frame_times(T0, 50.0)
    p, q = still_pose(t, xyz, (0.0, 0.0, 0.0, 1.0))
    return Body(
        name, simulate_mocap(t, p, q, rng=np.random.default_rng(0), noise=QUIET, losses=losses)
    )


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("hand")
    params = {
        "min_following_distance": 0.15,
        "max_following_distance": 3.5,
        "desired_following_distance": 2.0,
        "goal_timeout": 40,
    }
    sc = RsbbScenario(
        code="HPFF",
        team="homer",
        run=1,
        season="2019",
        t_connect_ns=at(0.5),
        t_start_ns=at(2.0),
        t_end_ns=at(43.6),
        end="stop",
        t_disconnect_ns=at(44.0),
        goals=(Goal(at(3.0), at(3.6), at(43.0), "{}\n", "timeout"),),
        saves=(Save(at(43.6), {}),),
        params=params,
        bodies=(
            _body("robot_markerset", (0.0, 0.0, 0.7), [TrackingLoss(at(20.0), 0, 120)]),
            _body("actor_markerset", (2.5, 0.0, 1.7), []),
        ),
    )
    paths = write_rsbb_run(root, sc)
    tdir = root / "rsbb_etc" / "transforms"
    tdir.mkdir(parents=True)
    (tdir / "transform-homer.yaml").write_text(
        "markerset_to_robot_transform: !!python/tuple\n- [0, 0, 0]\n- [0, 0, 0, 1]\n",
        encoding="utf-8",
    )
    return paths.bag


def _score(bag: Path, **values: object) -> object:
    options = declare.make_options({"draws": 0, **values})
    logs = load([bag], options)
    return score_runs(logs, find_runs(logs, options), options)


def test_grid_reading_by_hand(bag: Path) -> None:
    r = _score(bag)
    s = r.stats  # type: ignore[attr-defined]
    assert (s.measured, s.failed) == (61, 2)
    assert r.score == {  # type: ignore[attr-defined]
        "Average deviation from desired distance": pytest.approx(0.5, abs=1e-12),
        "Distance covered while following": 0.0,  # the robot stood still: steps of 0 added
        "Benchmark reliability": "96.8%",  # round(100 - 200/63, 1): 96.825... -> 96.8
    }
    assert r.duration_s == pytest.approx(39.4, abs=1e-9) and r.passed  # type: ignore[attr-defined]
    t = (r.samples.t_ns - T0) / 1e9  # type: ignore[attr-defined]
    assert t[0] == pytest.approx(11.6) and t[-1] == pytest.approx(42.6)


def test_the_cap_plane(bag: Path) -> None:
    # a level cap: the robot 2.5 m away in the cap's x-y plane too
    r = _score(bag, distance_plane="actor")
    assert r.score["Average deviation from desired distance"] == pytest.approx(0.5, abs=1e-12)  # type: ignore[attr-defined]


def test_2019_without_lookups(bag: Path) -> None:
    # the log has no /robot broadcast: the script's check never succeeds and nobody answers
    r = _score(bag, rules="2019")
    assert r.score == {}  # type: ignore[attr-defined]


def test_the_cli_and_bad_input(bag: Path, tmp_path: Path) -> None:
    ran = ertools(["score", "hpff", str(bag)])
    assert ran.code == 0, ran.stderr
    assert yaml.safe_load(ran.stdout)["Benchmark reliability"] == "96.8%"
    assert "differs from 2019:" in ran.stderr and "[hpff.sampling]" in ran.stderr
    assert "duration 39.400 s against goal_timeout 40 +- 15 s: passed" in ran.stderr
    config = tmp_path / "HPFF.yaml"
    config.write_text("min_following_distance: 0.15\n", encoding="utf-8")
    bad = ertools(["score", "hpff", str(bag), "--config", str(config)])
    errors = [line for line in bad.stderr.splitlines() if "error" in line]
    assert bad.code == 1 and len(errors) == 1 and "max_following_distance is None" in errors[0]
    clash = ertools(["score", "hpff", str(bag), "--rules", "2019", "--sampling", "grid"])
    assert clash.code == 2 and "--rules 2019 reproduces the script" in clash.stderr
    with pytest.raises(ConfigError, match="max_following_distance"):
        load([bag], declare.make_options({"config": str(config)}))
    with pytest.raises(UsageError, match="give one HPFF run bag"):
        load([bag, bag], declare.make_options({}))
