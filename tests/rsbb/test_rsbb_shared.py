"""The shared RSBB benchmark machinery: side files, tf lookups, Python 2 texts, comparisons.

The tf lookups are checked against the replays' own tf2 buffer (``rsbb_replay.tf2``, written
from tf2's source independently of ``ertools.rsbb.tf``) on a moving, noisy body with a
non-unit team quaternion; the helper's attempts and the comparisons by hand.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from ertools.benchmarks.hnf.config import SCRIPT_FRAMES as HNF_FRAMES
from ertools.errors import ConfigError
from ertools.rsbb.log import check_code, logged_code, read_rsbb_run
from ertools.rsbb.py2 import percent_py2, round_py2, str_py2, to_sec
from ertools.rsbb.results import load_result, parse_live_score
from ertools.rsbb.score import compare_scores, flatten, same_value, score_yaml
from ertools.rsbb.sidefiles import find_side_files, run_place, script_transform
from ertools.rsbb.tf import (
    TfTrack,
    euler_yaw,
    helper_lookup,
    read_tf_tracks,
    script_poses,
)
from ertools.simulator.mocap import MocapNoise, frame_times, simulate_mocap
from ertools.simulator.rsbb import write_rsbb_run
from ertools.simulator.rsbb_scenario import Body, Broadcast
from tests.helpers.inprocess import run as ertools
from tests.helpers.rsbb_replay.fromlog import timeline_from_bag
from tests.helpers.rsbb_replay.py2 import euler_yaw as replay_yaw
from tests.helpers.rsbb_replay.scenarios import MS, T0, at, hnf_scenario
from tests.helpers.rsbb_replay.tf2 import Buffer
from tests.helpers.stderr_text import joined_lines

S = 1_000_000_000
TEAM = ((0.12, -0.05, 0.31), (0.0, 0.0, 0.38, 0.92))  # |q| = 0.9954: broadcast as written


def _moving(name: str, seconds: float, seed: int, losses: tuple = ()) -> Body:  # type: ignore[type-arg]
    t = frame_times(T0, seconds)
    s = (t - T0) / 1e9
    xyz = np.stack([0.5 * s, np.sin(s), 0.2 + 0.01 * s], axis=-1)
    yaw = 0.7 * s  # crosses +-pi several times
    quat = np.stack(
        [0.02 * np.ones_like(s), np.zeros_like(s), np.sin(yaw / 2), np.cos(yaw / 2)], -1
    )
    quat /= np.linalg.norm(quat, axis=-1, keepdims=True)
    noise = MocapNoise()  # noise, header jitter and latency spikes
    pub = simulate_mocap(
        t, xyz, quat, rng=np.random.default_rng(seed), noise=noise, losses=list(losses)
    )
    return Body(name, pub)


@pytest.fixture(scope="module")
def moving_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[int]]:
    moments = [at(2.0) + k * 731 * MS for k in range(20)]
    sc = replace(
        hnf_scenario(),
        t_end_ns=at(22.0),
        t_disconnect_ns=at(23.0),
        manual_operations=(),
        goals=(),
        broadcasts=tuple(Broadcast(t, "/robot", "/robot_markerset", *TEAM) for t in moments),
        bodies=(_moving("robot_markerset", 25.0, 1), _moving("actor_markerset", 25.0, 2)),
    )
    return write_rsbb_run(tmp_path_factory.mktemp("moving"), sc).bag, moments


@pytest.mark.slow
def test_script_poses_are_tf2s_lookups(moving_run: tuple[Path, list[int]]) -> None:
    bag, moments = moving_run
    tracks = read_tf_tracks(bag)
    assert tracks.broadcasts(HNF_FRAMES[0]).tolist() == moments
    robot = tracks.body("robot_markerset")
    actor = tracks.body("actor_markerset")
    t = np.asarray(moments, np.int64)
    absolute = script_poses(robot, t, TEAM)
    relative = script_poses(robot, t, TEAM, reference=actor)
    assert absolute.inside.all() and relative.inside.all()
    tl = timeline_from_bag(bag, {}, {})
    buf: Buffer = tl.tf
    for k, now in enumerate(moments):
        late = now + 200 * MS  # the data around `now` has arrived, none pruned yet
        buf.add("robot_markerset", "robot", now, now, TEAM)  # type: ignore[arg-type]
        (x, y, z), q = buf.lookup("testbed_origin", "robot", now, late)
        assert absolute.xyz[k] == pytest.approx([x, y, z], abs=1e-12)
        assert absolute.quat_xyzw[k] == pytest.approx(q, abs=1e-12)
        assert absolute.theta[k] == pytest.approx(replay_yaw(q), abs=1e-12)
        (x, y, z), q = buf.lookup("actor_markerset", "robot", now, late)
        assert relative.xyz[k] == pytest.approx([x, y, z], abs=1e-12)
        assert relative.theta[k] == pytest.approx(replay_yaw(q), abs=1e-12)
    # the unnormalised team quaternion scales the offset by |q|^2, as tf2's quatRotate does
    n2 = sum(v * v for v in TEAM[1])
    assert abs(n2 - 1.0) > 1e-3


def test_outside_the_samples_is_not_a_pose() -> None:
    track = TfTrack(
        "testbed_origin",
        "b",
        np.array([10, 20, 30], np.int64) * S,
        np.array([10, 20, 30], np.int64) * S + 1,
        np.array([[0.0, 0, 0], [1.0, 0, 0], [3.0, 0, 0]]),
        np.tile([0.0, 0, 0, 1.0], (3, 1)),
    )
    p = script_poses(track, np.array([5, 10, 15, 30, 31], np.int64) * S, ((0, 0, 0), (0, 0, 0, 1)))
    assert p.inside.tolist() == [False, True, True, True, False]
    assert p.x[1:4].tolist() == [0.0, 0.5, 3.0]
    assert p.gap_ns[1:4].tolist() == [0, 10 * S, 0]
    # a wait for data at 15 s returns when the 20 s sample arrived
    assert track.ready_ns(15 * S) == 20 * S + 1 and track.ready_ns(31 * S) is None


def test_euler_yaw_matches_tf_transformations() -> None:
    rng = np.random.default_rng(3)
    q = rng.normal(size=(200, 4)) * rng.uniform(0.5, 2.0, size=(200, 1))  # any norm
    yaws = euler_yaw(q)
    for k in range(200):
        assert yaws[k] == pytest.approx(replay_yaw(tuple(q[k])), abs=1e-12)
    # gimbal lock (a half turn about x) gives 0 as tf.transformations does
    assert euler_yaw(np.array([[1.0, 0.0, 0.0, 0.0]]))[0] == 0.0


def test_helper_attempts_against_the_logged_lookups() -> None:
    stamps = np.array([10_000, 13_200, 20_000], np.int64) * MS
    # a lookup stamped 10 ms after the call succeeds at once
    o = helper_lookup(stamps, 0, 9_990 * MS, attempts=5, timeout_s=1.0, stop_ns=None)
    assert (o.stamp_ns, o.failed, o.next_index) == (10_000 * MS, 0, 1)
    # after a result at 10.1 s the next logged lookup is 13.2 s: three 1 s attempts failed
    o = helper_lookup(stamps, 1, 10_100 * MS, attempts=5, timeout_s=1.0, stop_ns=None)
    assert (o.stamp_ns, o.failed, o.next_index) == (13_200 * MS, 3, 2)
    # five failures: no pose, the clock 5 s later
    o = helper_lookup(stamps, 2, 14_000 * MS, attempts=5, timeout_s=1.0, stop_ns=None)
    assert (o.stamp_ns, o.clock_ns, o.failed) == (None, 19_000 * MS, 5)
    # the benchmark stopped at 15.5 s: the attempt then running was the last
    o = helper_lookup(stamps, 2, 14_000 * MS, attempts=None, timeout_s=1.0, stop_ns=15_500 * MS)
    assert (o.stamp_ns, o.clock_ns, o.failed) == (None, 16_000 * MS, 2)
    # no limit and no stop: until the log ends
    o = helper_lookup(
        stamps, 3, 30_000 * MS, attempts=None, timeout_s=1.0, stop_ns=None, until_ns=32_000 * MS
    )
    assert o.stamp_ns is None and o.failed == 3
    # a lookup stamped up to 50 ms before the inferred clock is still this attempt's
    o = helper_lookup(stamps, 0, 10_040 * MS, attempts=1, timeout_s=1.0, stop_ns=None)
    assert o.stamp_ns == 10_000 * MS and o.clock_ns == 10_040 * MS


def test_python2_numbers_and_texts() -> None:
    assert round_py2(0.125, 2) == 0.13 and round(0.125, 2) == 0.12  # halves away from zero
    assert round_py2(2.675, 2) == 2.67  # 2.67499999... in binary
    assert round_py2(-0.5, 0) == -1.0
    assert (
        str_py2(87.3) == "87.3" and str_py2(100.0) == "100.0" and str_py2(1 / 3) == "0.333333333333"
    )
    assert str_py2(1e16) == "1e+16"
    assert percent_py2(100 - 100 * 1 / 8, 1) == "87.5%"
    assert percent_py2(87.25, 1) == "87.3%"  # 87.25 is exact: a half, rounded up
    assert to_sec(-1) == -1.0 + 999_999_999 / 1e9
    assert to_sec(1_500_000_001) == 1.0 + 500_000_001 / 1e9


def test_score_comparison(tmp_path: Path) -> None:
    paths = write_rsbb_run(tmp_path, hnf_scenario())
    run = read_rsbb_run(paths.bag)
    file = load_result(paths.result)
    recomputed = {"segment_1": {"segment_time[s]": 6.0000004}, "reached_waypoints": 2}
    c = compare_scores(recomputed, run.live, file)
    assert c.live_form == "2019" and not c.live_file_differ
    assert c.differing("live") == () and c.differing("file") == ()
    assert "all 2 fields the same" in c.summary()[0]
    c = compare_scores({"segment_1": {"segment_time[s]": 6.01}, "extra": "60.0%"}, run.live, file)
    keys = {k.key for k in c.differing("live")}
    assert keys == {"segment_1.segment_time[s]", "extra", "reached_waypoints"}
    assert "3 of 3 fields differ" in c.summary()[0]
    # a live score older than the file
    old = parse_live_score(1, "score:\n  reached_waypoints: 1\n")
    c = compare_scores({"reached_waypoints": 2}, old, file)
    assert c.live_form == "2017" and c.live_file_differ == (
        "reached_waypoints",
        "segment_1.segment_time[s]",
    )
    assert compare_scores({"a": 1}, None, None).summary() == [
        "live score (/rsbb/current_benchmark_result): none to compare with",
        "no result file: nothing to compare with",  # not "result file (None)"
    ]


def test_score_leaves_and_yaml() -> None:
    assert flatten({"goal_1": {}, "a": {"b": [1, 2]}, "c": None}) == {
        "goal_1": {},
        "a.b": [1, 2],
        "c": None,
    }
    assert same_value(1, 1.0000001) and not same_value(True, 1) and not same_value("60.0%", "60%")
    assert same_value(float("nan"), float("nan")) and not same_value(None, 0)
    dump = "!!python/object/new:geometry_msgs.msg._Pose2D.Pose2D\nstate: [0.5, 1.2, %r]\n"
    assert same_value(dump % 0.28985748631983493, dump % 0.2898574863198349)
    assert not same_value(dump % 0.28985, dump % 0.28995) and not same_value("1 out of 3", "1 of 3")
    text = score_yaml({"b": np.float64(0.5), "a": {"x": np.int64(2)}, "c": "1 out of 3"})
    assert text == "a:\n  x: 2\nb: 0.5\nc: 1 out of 3\n"


def _touch(path: Path, text: str = "x: 1\n") -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def test_side_files_in_the_layout_and_beside(tmp_path: Path) -> None:
    root = tmp_path / "season"
    bag = _touch(root / "rsbb_logs/HNF/homer/run_2_2019-04-10-14-31-06.bag")
    config = _touch(root / "rsbb_bmbox/scripts/benchmark_configs/HNF.yaml")
    transform = _touch(root / "rsbb_etc/transforms/transform-homer.yaml")
    near = _touch(root / "results/HNF/homer/result_run_2_2019-04-10_14:31:05_WEST(+0100).yaml")
    _touch(root / "results/HNF/homer/result_run_2_2019-04-10_15:31:05_WEST(+0100).yaml")
    _touch(root / "results/HNF/homer/result_run_3_2019-04-10_14:31:05_WEST(+0100).yaml")
    place = run_place(bag)
    assert (place.code, place.team, place.run, place.root) == ("HNF", "homer", 2, root)
    found = find_side_files(bag, "HNF", want=("config", "transform", "result"))
    assert (found.config, found.transform, found.result, found.items) == (
        config,
        transform,
        near,
        None,
    )
    assert len(found.found) == 3 and all("in the RSBB layout" in line for line in found.found)
    # given files win, and are not announced
    mine = _touch(tmp_path / "mine.yaml")
    given = find_side_files(bag, "HNF", want=("config", "transform"), config=mine, team="other")
    assert given.config == mine and given.transform is None and given.found == ()
    # a flat folder: the run's files beside the bag
    flat = tmp_path / "flat"
    fbag = _touch(flat / "run_1_2019-04-10-14-31-06.bag")
    fconf = _touch(flat / "HNF.yaml")
    ftr = _touch(flat / "transform-homer.yaml")
    fres = _touch(flat / "result_run_1_2019-04-10_14:31:00_WEST(+0100).yaml")
    got = find_side_files(fbag, "HNF", want=("config", "transform", "result"), team="homer")
    assert (got.config, got.transform, got.result) == (fconf, ftr, fres)
    assert all("beside the bag" in line for line in got.found)
    # another name, one result file beside it: taken; no team: no transform searched
    other = _touch(flat / "my_run.bag")
    got = find_side_files(other, "HNF", want=("transform", "result"))
    assert got.result == fres and got.transform is None


def test_script_transform_is_read_as_written(tmp_path: Path) -> None:
    good = _touch(
        tmp_path / "transform-a.yaml",
        "team_name: a\nmarkerset_to_robot_transform: !!python/tuple\n"
        "- [0.1, 0, -0.2]\n- [0.0, 0.0, 0.7071, 0.7071]\n",
    )
    assert script_transform(good) == ((0.1, 0.0, -0.2), (0.0, 0.0, 0.7071, 0.7071))
    old = _touch(tmp_path / "old.yaml", "marker_to_robot_transform: [[1, 2, 3], [0, 0, 0, 1]]\n")
    assert script_transform(old)[0] == (1.0, 2.0, 3.0)
    with pytest.raises(ConfigError, match="no markerset_to_robot_transform"):
        script_transform(old, ("markerset_to_robot_transform",))
    bad = _touch(tmp_path / "bad.yaml", "markerset_to_robot_transform: [[1, 2], [0, 0, 0, 1]]\n")
    with pytest.raises(ConfigError, match="expected"):
        script_transform(bad)
    evil = _touch(tmp_path / "evil.yaml", "x: !!python/object/apply:os.system [ls]\n")
    with pytest.raises(ConfigError):
        script_transform(evil)


SAMPLES = Path(__file__).resolve().parents[2] / "sample_bags"


def test_the_live_score_names_the_benchmark(tmp_path: Path) -> None:
    run = read_rsbb_run(write_rsbb_run(tmp_path, hnf_scenario()).bag)
    assert logged_code(run) == "HNF"
    check_code(run, "HNF")
    with pytest.raises(ConfigError, match=r"a HNF run .*not HPFF's: ertools score hnf"):
        check_code(run, "HPFF")
    # no live score, or the result object's placeholder (BenchmarkObjects.py l. 724) before
    # the script's setup: nothing named, nothing refused
    assert logged_code(replace(run, live=())) is None
    info = {"benchmark_info": {"benchmark_code": "undefined"}, "score": {}}
    placeholder = replace(run.live[0], result=info)
    assert logged_code(replace(run, live=(placeholder,))) is None
    check_code(replace(run, live=(placeholder,)), "HPFF")


@pytest.mark.parametrize(
    ("code", "other"),
    [("hnf", "hpff"), ("hpff", "hnf"), ("hopf", "hppf"), ("hppf", "hopf"), ("hgmf", "hnf")],
)
def test_another_benchmarks_bag_outside_the_layout(tmp_path: Path, code: str, other: str) -> None:
    # outside rsbb_logs/<CODE>/ only the bag itself says what it is: one line, exit 1
    sample = next((SAMPLES / other).rglob("run_1_*.bag"))
    bag = tmp_path / sample.name
    bag.write_bytes(sample.read_bytes())
    ran = ertools(["score", code, str(bag)])
    assert ran.code == 1
    assert joined_lines(ran.stderr) == [  # one message, wrapped past 200 characters
        f"ertools: error: {bag}: this bag is a {other.upper()} run (its live score's "
        f"benchmark_info), not {code.upper()}'s: ertools score {other}"
    ]
