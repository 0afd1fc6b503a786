"""HNF's numbers by hand, and bad input.

A noiseless marker set stands still at (1.5, 0.2, 0.3) turned 0.5 rad; the team transform puts
the robot 0.1 m ahead of it, turned a quarter turn: the robot stands at
(1.5 + 0.1 cos 0.5, 0.2 + 0.1 sin 0.5) with yaw 0.5 + pi/2. Goal 1 is reached, goal 2 times out,
goal 3 is reached; the script looks the robot up 10 ms after each.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from ertools.benchmarks.hnf import declare
from ertools.benchmarks.hnf.pipeline import find_runs, load, score_runs
from ertools.errors import ConfigError, UsageError
from ertools.simulator.mocap import frame_times, simulate_mocap
from ertools.simulator.rsbb import write_rsbb_run
from ertools.simulator.rsbb_scenario import Body, Broadcast, Goal, RsbbScenario, Save, still_pose
from tests.helpers.inprocess import run as ertools
from tests.helpers.rsbb_replay.scenarios import QUIET, T0, at

pytestmark = pytest.mark.slow  # writes a run bag

YAW = 0.5
Q = math.sin(math.pi / 4)
WAYPOINTS = [[1.6, 0.3, 2.0], [2.0, 0.0, -2.5], [1.0, 1.0, 0.0]]
ROBOT = (1.5 + 0.1 * math.cos(YAW), 0.2 + 0.1 * math.sin(YAW), YAW + math.pi / 2)


def _bag(folder: Path) -> Path:
    t = frame_times(T0, 40.0)
    xyz, quat = still_pose(t, (1.5, 0.2, 0.3), (0.0, 0.0, math.sin(YAW / 2), math.cos(YAW / 2)))
    body = Body(
        "robot_markerset", simulate_mocap(t, xyz, quat, rng=np.random.default_rng(0), noise=QUIET)
    )
    team = ((0.1, 0.0, 0.0), (0.0, 0.0, Q, Q))
    sc = RsbbScenario(
        code="HNF",
        team="homer",
        run=2,
        season="2019",
        t_connect_ns=at(0.5),
        t_start_ns=at(2.0),
        t_end_ns=at(31.0),
        end="end",
        t_disconnect_ns=at(32.0),
        goals=tuple(
            Goal(at(r), at(r + 1), at(e), yaml.dump(w, default_flow_style=None), o)
            for r, e, w, o in (
                (3.0, 10.0, WAYPOINTS[0], "result"),
                (11.0, 20.0, WAYPOINTS[1], "timeout"),
                (21.0, 30.0, WAYPOINTS[2], "result"),
            )
        ),
        broadcasts=tuple(
            Broadcast(at(s), "/robot", "/robot_markerset", *team) for s in (10.01, 20.01, 30.01)
        ),
        saves=(Save(at(31.0), {"reached_waypoints": 2}),),
        params={"starting_pose": [0, 0, 0], "waypoints": WAYPOINTS, "goal_timeout": 120},
        bodies=(body,),
    )
    paths = write_rsbb_run(folder, sc)
    tdir = folder / "rsbb_etc" / "transforms"
    tdir.mkdir(parents=True)
    (tdir / "transform-homer.yaml").write_text(
        "markerset_to_robot_transform: !!python/tuple\n"
        f"- [0.1, 0.0, 0.0]\n- [0.0, 0.0, {Q!r}, {Q!r}]\n",
        encoding="utf-8",
    )
    return paths.bag


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _bag(tmp_path_factory.mktemp("hand"))


def _score(bag: Path, **values: object) -> object:
    options = declare.make_options({"draws": 0, **values})
    logs = load([bag], options)
    return score_runs(logs, find_runs(logs, options), options)


def _by_hand() -> tuple[list[float], list[float], list[float]]:
    d = [math.hypot(ROBOT[0] - w[0], ROBOT[1] - w[1]) for w in WAYPOINTS]
    raw = [ROBOT[2] - w[2] for w in WAYPOINTS]
    wrapped = [math.atan2(math.sin(a), math.cos(a)) for a in raw]
    return d, raw, wrapped


def test_default_reading_by_hand(bag: Path) -> None:
    r = _score(bag)
    d, _, wrapped = _by_hand()
    score = r.score  # type: ignore[attr-defined]
    for k in range(3):
        seg = score[f"segment_{k + 1}"]
        assert seg["robot_pose"] == pytest.approx(
            {"x": ROBOT[0], "y": ROBOT[1], "theta": ROBOT[2]}, abs=1e-12
        )
        assert seg["distance_error"] == pytest.approx(d[k], abs=1e-12)
        assert seg["orientation_error"] == pytest.approx(abs(wrapped[k]), abs=1e-12)
    # goal 2 (3.3 rad off unwrapped, 1.7 wrapped) timed out: outside the accuracies
    assert score["position_accuracy[m]"] == pytest.approx((d[0] + d[2]) / 2, abs=1e-12)
    s = math.sin(abs(wrapped[0])) + math.sin(abs(wrapped[2]))
    c = math.cos(abs(wrapped[0])) + math.cos(abs(wrapped[2]))
    assert score["orientation_accuracy[rad]"] == pytest.approx(math.atan2(s, c), abs=1e-12)
    assert score["execution_time[s]"] == pytest.approx(6.0 + 8.0 + 8.0, abs=1e-12)
    assert (score["reached_waypoints"], score["timed_out_waypoints"]) == (2, 1)
    assert score["segment_1"]["start_segment_time[s]"] == 2.0
    assert score["segment_1"]["result"] is None  # the empty result string: yaml.load("") is None


def test_2019_by_hand(bag: Path) -> None:
    r = _score(bag, rules="2019")
    d, raw, _ = _by_hand()
    score = r.score  # type: ignore[attr-defined]
    # every pose summed (the timed-out one too), two completed goals divide
    assert score["position_accuracy[m]"] == pytest.approx(sum(d) / 2, abs=1e-12)
    s = sum(math.sin(abs(a)) for a in raw)
    c = sum(math.cos(abs(a)) for a in raw)
    assert score["orientation_accuracy[rad]"] == pytest.approx(math.atan2(abs(s), c), abs=1e-12)
    assert score["segment_2"]["orientation_error"] == pytest.approx(
        math.atan2(abs(math.sin(abs(raw[1]))), math.cos(abs(raw[1]))), abs=1e-12
    )
    assert score["segment_3"]["target_pose"] == (
        "!!python/object/new:geometry_msgs.msg._Pose2D.Pose2D\nstate: [1.0, 1.0, 0.0]\n"
    )


def test_the_cli_prints_the_score_form_and_says_what_differs(bag: Path) -> None:
    ran = ertools(["score", "hnf", str(bag), "--draws", "50"])
    assert ran.code == 0, ran.stderr
    assert yaml.safe_load(ran.stdout)["reached_waypoints"] == 2
    err = ran.stderr
    assert "transform-homer.yaml found in the RSBB layout" in err
    assert "differs from 2019:" in err and "[hnf.divisor]" in err
    assert "--divisor 2019 restores 2019" in err
    assert "interval: position_accuracy[m]" in err
    # the live score and the result file hold a stub: the comparison says they differ
    assert "live score (/rsbb/current_benchmark_result):" in err
    json_run = ertools(["score", "hnf", str(bag), "--rules", "2019", "--format", "json"])
    assert json_run.code == 0 and '"segment_1"' in json_run.stdout


def test_each_option_restores_its_rule(bag: Path) -> None:
    """The four options of the reading's rules together print what --rules 2019 prints."""
    rules = ertools(["score", "hnf", str(bag), "--rules", "2019", "--draws", "0"])
    each = ertools(
        [
            "score",
            "hnf",
            str(bag),
            "--draws",
            "0",
            "--orientation-2019",
            "--divisor",
            "2019",
            "--gt-gaps",
            "interpolate",
            "--score-format",
            "2019",
        ]
    )
    assert rules.code == each.code == 0 and each.stdout == rules.stdout
    assert "differs from 2019" not in each.stderr


def test_another_log_says_what_it_is(tmp_path: Path) -> None:
    fbm2h = Path(__file__).resolve().parents[3] / "sample_bags" / "fbm2h"
    ran = ertools(
        [
            "score",
            "hnf",
            str(fbm2h / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"),
            "--config",
            str(tmp_path / "none.yaml"),
            "--transform",
            str(fbm2h / "transform-simbot.yaml"),
        ]
    )
    errors = [line for line in ran.stderr.splitlines() if "error" in line]
    assert ran.code in (1, 2) and len(errors) == 1 and "Traceback" not in ran.stderr


def test_bad_input_one_line(bag: Path, tmp_path: Path) -> None:
    cases = []
    # a config that is not HNF's
    config = tmp_path / "HNF.yaml"
    config.write_text("waypoints: [[1, 2]]\n", encoding="utf-8")
    cases.append((["--config", str(config)], "waypoint 1 is [1, 2]", 1))
    # a transform that is not one
    transform = tmp_path / "transform-x.yaml"
    transform.write_text("markerset_to_robot_transform: [1, 2]\n", encoding="utf-8")
    cases.append((["--transform", str(transform)], "expected [[x, y, z]", 1))
    # contradicting options
    cases.append((["--rules", "2019", "--divisor", "ertools"], "--rules 2019 reproduces", 2))
    for extra, words, code in cases:
        ran = ertools(["score", "hnf", str(bag), *extra])
        lines = [line for line in ran.stderr.splitlines() if "error" in line]
        assert ran.code == code and len(lines) == 1 and words in lines[0], (extra, ran.stderr)
        assert "Traceback" not in ran.stderr


def test_missing_side_files_and_wrong_bags(tmp_path: Path) -> None:
    flat = tmp_path / "flat"
    flat.mkdir()
    lone = _bag(flat)
    (flat / "rsbb_etc" / "transforms" / "transform-homer.yaml").unlink()
    # a file missing or another benchmark's: exit 1 (ConfigError), not a usage error
    with pytest.raises(ConfigError, match=r"no transform-homer\.yaml"):
        load([lone], declare.make_options({}))
    other = tmp_path / "rsbb_logs" / "HPFF" / "homer" / lone.name
    other.parent.mkdir(parents=True)
    other.write_bytes(lone.read_bytes())
    with pytest.raises(ConfigError, match=r"a HPFF run .*not HNF's: ertools score hpff"):
        load([other], declare.make_options({}))
    with pytest.raises(UsageError, match="give one HNF run bag"):
        load([lone, lone], declare.make_options({}))
    bad = tmp_path / "HNF.yaml"
    bad.write_text("waypoints: {}\n", encoding="utf-8")
    good = tmp_path / "transform.yaml"
    good.write_text("markerset_to_robot_transform: [[0, 0, 0], [0, 0, 0, 1]]\n", encoding="utf-8")
    with pytest.raises(ConfigError, match="no waypoints list"):
        load([lone], declare.make_options({"config": str(bad), "transform": str(good)}))
