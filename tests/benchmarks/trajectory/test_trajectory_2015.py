"""`score trajectory --2015` and each 2015 option vs the 2015 script's arithmetic.

``node_2015.score_2015`` re-implements rockin_trajectory_benchmark.py with per-pose loops (see
its docstring); here it is fed the same data ertools reads (the bags read back with rosbags,
or the generated streams) and every field it computes is compared with ertools' output.

Tolerance 1e-12: both sides compute the same per-pose terms up to a rounding or two (~1e-16
each); the 2015 script sums one pose at a time, NumPy pairwise, which over <= 1000 terms of
size <= pi moves a mean or an atan2 of the sums by < 1e-13.
"""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from ertools.benchmarks.trajectory.association import _yaws, yaw_tf
from ertools.benchmarks.trajectory.comparison import score_streams
from ertools.benchmarks.trajectory.config import TrajectoryConfig
from ertools.cli.main import main
from ertools.errors import ClockError
from ertools.geometry import yaw_from_quat
from ertools.simulator.writer import BagWriter
from ertools.streams import PoseStream
from tests.benchmarks.trajectory.node_2015 import EndOfBagError, Pose, score_2015, tf_yaw
from tests.benchmarks.trajectory.trajectory_helpers import read_back, write_gt, write_robot
from tests.helpers.stderr_text import error_messages

TOL = 1e-12
ROOT = Path(__file__).resolve().parents[3]
SAMPLE = ROOT / "sample_bags" / "robotlog"
ROBOT_BAG = SAMPLE / "FBM2H_201511201200_homer.bag"
ROBOT_TOPIC = "/rockin/homer/marker_pose"
GT_TOPIC = "/fbm2h/robot_at_home/pose"
EPOCH = 1_448_020_800 * 1_000_000_000  # 2015-11-20T12:00:00Z
MS = 1_000_000


def _poses(path: Path, topic: str, shift_ns: int = 0) -> list[Pose]:
    t, xyz, quat = read_back(path, topic)
    return [(s + shift_ns, p, q) for s, p, q in zip(t, xyz, quat, strict=True)]


def _gt_files_by_start() -> list[list[Pose]]:
    """The GT split files as the 2015 script opened them: sorted by the bag's start time."""

    files = sorted(SAMPLE.glob("log_*.bag"))
    starts = {}
    for f in files:
        with AnyReader([f]) as reader:
            starts[f] = reader.start_time
    return [_poses(f, GT_TOPIC) for f in sorted(files, key=lambda f: starts[f])]


def _cli_json(args: list[str], capsys: pytest.CaptureFixture[str]) -> dict[str, Any]:
    assert main(["score", "trajectory", *args, "--format", "json"]) == 0
    out: dict[str, Any] = json.loads(capsys.readouterr().out)
    return out


def assert_same(ours: dict[str, Any], node: Any) -> None:
    """Every field the 2015 script computes, field for field."""
    assert ours["compared"] == node.n
    assert ours["tracking_lost"] == node.tracking_lost
    assert ours["gaps_compared"] == node.gap_compared
    assert ours["before_gt"] == node.never_happen
    assert ours["gaps"] == 0 and ours["uncovered"] == 0
    assert ours["position_error"] == pytest.approx(node.position_error, abs=TOL, rel=0)
    assert ours["orientation_error_2015"] == pytest.approx(node.orientation_error, abs=TOL, rel=0)


# --- the sample bags ---------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("offset_s", [0.0, -0.35])
def test_2015_on_the_sample_bags_equals_the_2015_script(
    offset_s: float, capsys: pytest.CaptureFixture[str]
) -> None:
    # The 2015 script had no offset: the -0.35 s case feeds it the robot stamps shifted.
    robot = _poses(ROBOT_BAG, ROBOT_TOPIC, shift_ns=round(offset_s * 1e9))
    node = score_2015(robot, _gt_files_by_start())
    ours = _cli_json([str(ROBOT_BAG), str(SAMPLE), "--2015", "--offset", str(offset_s)], capsys)
    assert_same(ours, node)
    # The sample has GT gaps, tracking losses and yaw crossing +-pi: none of this is vacuous.
    assert node.gap_compared > 0 and node.tracking_lost > 0
    assert ours["association"] == "hold" and ours["ties"] == "before"
    assert ours["gap_poses"] == "compare" and ours["before_gt_poses"] == "first"


@pytest.mark.slow
def test_the_default_differs_from_2015_on_the_sample_and_says_so(
    capsys: pytest.CaptureFixture[str],
) -> None:
    node = score_2015(_poses(ROBOT_BAG, ROBOT_TOPIC), _gt_files_by_start())
    assert main(["score", "trajectory", str(ROBOT_BAG), str(SAMPLE), "--format", "json"]) == 0
    cap = capsys.readouterr()
    ours = json.loads(cap.out)
    # 13 gap poses not compared, linear instead of hold: a different score, by > 1 mm.
    assert ours["compared"] == node.n - node.gap_compared
    assert abs(ours["position_error"] - node.position_error) > 1e-3
    assert "--gaps compare restores 2015 [trajectory.gaps]" in cap.err
    assert "--association hold restores 2015 [trajectory.association]" in cap.err
    assert "[trajectory.yaw-wrap]" in cap.err


@pytest.mark.slow
def test_gaps_compare_alone_on_the_sample(capsys: pytest.CaptureFixture[str]) -> None:
    """--association hold --gaps compare: the sample has no exact tie and no pose before the
    GT, so these two options alone already give the 2015 numbers."""
    node = score_2015(_poses(ROBOT_BAG, ROBOT_TOPIC), _gt_files_by_start())
    ours = _cli_json(
        [str(ROBOT_BAG), str(SAMPLE), "--association", "hold", "--gaps", "compare"], capsys
    )
    assert_same(ours, node)
    assert ours["deviations"] == [d for d in ours["deviations"] if "trajectory.yaw-wrap" in d]


# --- simulated edge cases -----------------------------------------------------------------------


def _stream(t_ns: list[int], xyz: list[list[float]], quat: list[list[float]]) -> PoseStream:
    return PoseStream(
        np.asarray(t_ns, dtype=np.int64),
        np.asarray(xyz, dtype=np.float64),
        np.asarray(quat, dtype=np.float64),
    )


def _quat(yaw: float, scale: float = 1.0) -> list[float]:
    return [0.0, 0.0, scale * math.sin(yaw / 2), scale * math.cos(yaw / 2)]


def _run(robot: list[Pose], gt: list[Pose], **cfg: Any) -> Any:
    def stream(p: list[Pose]) -> PoseStream:
        return _stream([a for a, _, _ in p], [list(b) for _, b, _ in p], [list(c) for *_, c in p])

    return score_streams(stream(robot), stream(gt), TrajectoryConfig.of_2015(**cfg))


def _both(robot: list[Pose], gt: list[Pose], **cfg: Any) -> tuple[dict[str, Any], Any]:
    return _run(robot, gt, **cfg).to_dict(), score_2015(robot, [gt])


def _gt(t_ms: list[float], x: list[float], yaw: list[float] | None = None) -> list[Pose]:
    yaw = yaw or [0.0] * len(t_ms)
    return [
        (EPOCH + round(t * MS), (xi, 0.5 * xi, 0.1), _quat(a))
        for t, xi, a in zip(t_ms, x, yaw, strict=True)
    ]


def test_robot_poses_in_a_gt_gap_are_compared_with_the_held_pose() -> None:
    # 120 Hz GT with a 600 ms hole after 200 ms: robot poses inside it get the pose before it.
    t = [i * 1000 / 120 for i in range(25)] + [800 + i * 1000 / 120 for i in range(30)]
    gt = _gt(t, [0.01 * i for i in range(len(t))])
    robot = _gt([50.0, 250.0, 400.0, 790.0, 850.0], [0.0] * 5)
    ours, node = _both(robot, gt)
    assert_same(ours, node)
    assert node.gap_compared == 3 and ours["gaps_compared"] == 3  # 250, 400 and 790 ms
    result = _run(robot, gt)
    matched = result.matched
    rows = result.tables()["samples"]
    assert [r["in_gt_gap"] for r in rows] == [False, True, True, True, False]
    assert {r["status"] for r in rows} == {"compared"}
    held = np.asarray(gt[24][1])  # the last GT pose before the hole
    assert np.array_equal(matched.gt_xyz[1:4], np.tile(held, (3, 1)))
    assert matched.position_error[1:4] == pytest.approx([math.dist((0.0, 0.0, 0.1), held)] * 3)


def test_yaw_across_pi_uses_the_unwrapped_difference() -> None:
    gt = _gt([0, 10, 20, 30, 40], [0.0, 0.1, 0.2, 0.3, 0.4], [3.1, 3.12, -3.13, -3.11, -3.1])
    robot = _gt([15.0, 25.0, 35.0], [0.05, 0.15, 0.25], [-3.13, 3.13, -3.10])
    ours, node = _both(robot, gt)
    assert_same(ours, node)
    # By hand: held GT yaws 3.12, -3.13, -3.11; |robot - gt| not wrapped.
    d = [abs(-3.13 - 3.12), abs(3.13 + 3.13), abs(-3.10 + 3.11)]
    by_hand = math.atan2(sum(map(math.sin, d)), sum(map(math.cos, d)))
    assert ours["orientation_error_2015"] == pytest.approx(by_hand, abs=1e-12)
    # ertools' own field wraps: 0.033, 0.023, 0.01 rad.
    wrapped = [abs(math.remainder(x, 2 * math.pi)) for x in d]
    assert ours["orientation_error"] == pytest.approx(
        math.atan2(sum(map(math.sin, wrapped)), sum(map(math.cos, wrapped))), abs=1e-12
    )


def test_exact_stamp_ties_take_the_gt_pose_before() -> None:
    gt = _gt([0, 10, 20, 30, 40], [0.0, 1.0, 2.0, 3.0, 4.0])
    robot = _gt([0.0, 10.0, 30.0, 40.0], [0.0] * 4)  # ties at the first and the last sample too
    ours, node = _both(robot, gt)
    assert_same(ours, node)
    # Held: GT[0] (first pair), GT[0], GT[2], GT[3]: x = 0, 0, 2, 3 (y = x/2, z equal).
    xs = [0.0, 0.0, 2.0, 3.0]
    assert ours["position_error"] == pytest.approx(sum(x * math.sqrt(1.25) for x in xs) / 4)


def test_robot_poses_before_the_first_gt_pose_are_compared_with_it() -> None:
    gt = _gt([100, 110, 120, 130], [1.0, 1.1, 1.2, 1.3])
    robot = _gt([50.0, 90.0, 105.0, 125.0], [0.0] * 4)
    ours, node = _both(robot, gt)
    assert_same(ours, node)
    assert node.never_happen == 2 and ours["before_gt"] == 2


def test_tracking_lost_on_the_first_pair_before_the_gt() -> None:
    # Motive repeating the first pose: the 2015 pair (GT[0], GT[1]) is equal, the early robot
    # pose is skipped, not compared.
    gt = _gt([100, 110, 120, 130], [1.0, 1.0, 1.2, 1.3])
    robot = _gt([50.0, 110.0, 125.0], [0.0] * 3)
    ours, node = _both(robot, gt)
    assert_same(ours, node)
    assert node.tracking_lost == 2  # 50 (pair 0-1) and the tie at 110 (pair 0-1)


def test_non_unit_quaternions_take_tf_s_normalised_yaw() -> None:
    # tf normalises inside quaternion_matrix; a yaw formula that does not differs by ~1e-4 here.
    gt = [(EPOCH + i * 10 * MS, (0.01 * i, 0.0, 0.0), _quat(0.3 * i, 1.02)) for i in range(5)]
    robot = [(EPOCH + 15 * MS, (0.1, 0.0, 0.0), _quat(2.0, 0.97))]
    ours, node = _both(robot, gt)
    assert_same(ours, node)
    assert node.orientation_error == pytest.approx(abs(2.0 - 0.3), abs=1e-12)


def test_a_robot_pose_after_the_last_gt_pose_aborts_as_in_2015() -> None:
    gt = _gt([0, 10, 20], [0.0, 0.1, 0.2])
    robot = _gt([5.0, 25.0], [0.0, 0.0])
    with pytest.raises(EndOfBagError):
        score_2015(robot, [gt])
    with pytest.raises(ClockError, match="outside the GT"):
        _both(robot, gt)


def _random_case(seed: int) -> tuple[list[Pose], list[Pose]]:
    """~120 Hz GT with jitter, holes, tracking losses and a yaw walking across +-pi; 10 Hz
    robot with some stamps on GT samples, some before the GT, quaternions off unit norm."""
    rng = np.random.default_rng(seed)
    n = 1200
    dt = np.full(n - 1, 1e9 / 120) + rng.normal(0, 2e5, n - 1)
    for at in rng.choice(n - 1, 3, replace=False):
        dt[at] += rng.uniform(0.2e9, 1.5e9)  # GT holes
    t = EPOCH + np.concatenate([[0], np.cumsum(np.round(dt))]).astype(np.int64)
    xyz = np.cumsum(rng.normal(0, 0.004, (n, 3)), axis=0)
    yaw = np.cumsum(rng.normal(0, 0.05, n)) + 3.0
    for at in rng.choice(n - 30, 6, replace=False):
        xyz[at + 1 : at + 1 + rng.integers(5, 25)] = xyz[at]  # Motive repeats the last pose
    scale = 1 + rng.normal(0, 1e-3, n)
    gt = [(int(t[i]), xyz[i].tolist(), _quat(float(yaw[i]), float(scale[i]))) for i in range(n)]
    rt = np.arange(t[0] - 250 * MS, t[-1] - MS, 100 * MS, dtype=np.int64)
    rt += rng.integers(0, 50 * MS, len(rt))
    rt = np.unique(rt)
    hits = rng.choice(n, 15, replace=False)
    rt = np.unique(np.concatenate([rt[rt < t[-1]], t[hits]]))  # exact ties
    at = np.clip(np.searchsorted(t, rt), 0, n - 1)
    rxyz = xyz[at] + rng.normal(0, 0.02, (len(rt), 3))
    ryaw = yaw[at] + rng.normal(0, 0.1, len(rt))
    robot = [
        (int(rt[i]), rxyz[i].tolist(), _quat(float(ryaw[i]), 1 + 1e-3 * float(rng.normal())))
        for i in range(len(rt))
    ]
    return robot, gt


@pytest.mark.slow_cases("3")
@pytest.mark.parametrize("seed", range(8))
def test_random_cases_equal_the_2015_script(seed: int) -> None:
    robot, gt = _random_case(seed)
    ours, node = _both(robot, gt)
    assert_same(ours, node)
    assert node.gap_compared and node.tracking_lost and node.never_happen
    assert any(abs(tf_yaw(q)) > 3.0 for _, _, q in robot)  # yaws near +-pi


# --- each option on its own, through the CLI, by hand -------------------------------------------
# GT x = 0, 0.1, 0.2, 0.3, 0.8, 0.9 m at 0, 100, 200, 300, 800, 900 ms (a 500 ms hole), the
# robot at x = 0 at -50 (before the GT), 100 (tie), 250, 500 (in the hole), 900 ms (tie at the
# last sample): each robot pose's error is the x of the GT pose it is compared with.


@pytest.fixture()
def hand(tmp_path: Path) -> list[str]:
    gt_ms = np.array([0, 100, 200, 300, 800, 900])
    gt_x = gt_ms / 1000.0
    gt = write_gt(
        tmp_path / "gt.bag",
        EPOCH + gt_ms * MS,
        np.column_stack([gt_x, np.zeros((6, 2))]),
        GT_TOPIC,
    )
    robot_ms = np.array([-50, 100, 250, 500, 900])
    robot = write_robot(
        tmp_path / "robot.bag", EPOCH + robot_ms * MS, np.zeros((5, 3)), ROBOT_TOPIC
    )
    return [str(robot), str(gt)]


@pytest.mark.parametrize(
    ("options", "held_x", "counts"),
    [
        # 2015: -50 -> GT0, tie 100 -> GT0, 250 -> GT2, 500 -> GT3 across the hole, 900 -> GT4;
        # its gap test in float seconds (to_sec) at this epoch: 900 ms - 800 ms is
        # 0.10000014305114746 s > 0.1, so the pair (GT4, GT5) counts as a gap too (0 - 100 ms
        # and 200 - 300 ms give 0.09999990463256836 s)
        (["--2015"], [0.0, 0.0, 0.2, 0.3, 0.8], {"gaps_compared": 2, "before_gt": 1}),
        # hold: the tie takes the sample at t, the hole is skipped, -50 uncovered
        (["--association", "hold", "--allow-partial"], [0.1, 0.2, 0.9], {"gaps": 1}),
        (
            ["--association", "hold", "--ties", "before", "--allow-partial"],
            [0.0, 0.2, 0.8],
            {"gaps": 1},
        ),
        (
            ["--association", "hold", "--gaps", "compare", "--allow-partial"],
            [0.1, 0.2, 0.3, 0.9],
            {"gaps_compared": 1, "uncovered": 1},
        ),
        (["--association", "hold", "--before-gt", "first"], [0.0, 0.1, 0.2, 0.9], {"gaps": 1}),
        # linear across the hole: 500 ms is 0.4 of the way from 300 to 800 ms: 0.5 m
        (["--gaps", "compare", "--allow-partial"], [0.1, 0.25, 0.5, 0.9], {"gaps_compared": 1}),
    ],
)
def test_each_option_by_hand(
    hand: list[str],
    options: list[str],
    held_x: list[float],
    counts: dict[str, int],
    capsys: pytest.CaptureFixture[str],
) -> None:
    ours = _cli_json([*hand, *options], capsys)
    assert ours["compared"] == len(held_x)
    assert ours["position_error"] == pytest.approx(sum(held_x) / len(held_x), abs=1e-12)
    for key, value in counts.items():
        assert ours[key] == value, key


def test_each_default_names_its_option(hand: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    ours = _cli_json([*hand, "--association", "hold", "--allow-partial"], capsys)
    text = "\n".join(ours["deviations"])
    assert "2 robot pose(s) stamped exactly at a GT sample" in text
    assert "--ties before restores 2015 [trajectory.ties]" in text
    assert "--gaps compare restores 2015 [trajectory.gaps]" in text
    assert "1 robot pose(s) before the first GT pose" in text
    assert "--before-gt first restores 2015 [trajectory.before-gt]" in text
    assert not any("[trajectory.association]" in d for d in ours["deviations"])
    ours = _cli_json([*hand, "--2015"], capsys)
    assert ours["deviations"] == []  # zero yaws: nothing crosses +-pi either


def test_uncovered_start_is_a_failure_with_the_covered_part_scored(
    hand: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    """2015 scored this log (the pose before the GT compared with the first GT pose): the
    default prints the covered part's numbers, exit 1, the failure pointing at the options."""
    assert main(["score", "trajectory", *hand, "--association", "hold", "--format", "json"]) == 1
    cap = capsys.readouterr()
    errors = error_messages(cap.err)
    assert len(errors) == 1
    assert "1 lie before the first GT pose" in errors[0] and "--before-gt first" in errors[0]
    out = json.loads(cap.out)
    # hold: tie 100 -> 0.1 (the sample at t), 250 -> 0.2, 900 -> 0.9; 500 in the hole skipped.
    assert out["compared"] == 3 and out["uncovered"] == 1
    assert out["position_error"] == pytest.approx((0.1 + 0.2 + 0.9) / 3, abs=1e-12)
    # After the last GT pose 2015 gave no score (exit 6): still an error alone.
    late = [hand[0], hand[1], "--association", "hold", "--offset", "0.2"]
    assert main(["score", "trajectory", *late]) == 1
    err = capsys.readouterr().err
    assert len(error_messages(err)) == 1
    assert all(ln.startswith(("ertools: error: ", "  ")) for ln in err.strip().splitlines())


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--2015", "--association", "linear"], "--2015 sets --association hold"),
        (["--2015", "--gaps", "skip"], "cannot take --gaps skip"),
        (["--ties", "before"], "--ties before needs --association hold"),
        (["--gt-order", "chain"], "--gt-order chain needs --association hold --ties before"),
        (["--2015", "--gt-order", "time"], "cannot take --gt-order time"),
    ],
)
def test_conflicting_options_are_usage_errors(
    hand: list[str], options: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["score", "trajectory", *hand, *options]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0]


def test_2015_options_that_agree_are_accepted(
    hand: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    a = _cli_json([*hand, "--2015"], capsys)
    b = _cli_json([*hand, "--2015", "--association", "hold", "--ties", "before"], capsys)
    assert a["position_error"] == b["position_error"] == pytest.approx(0.26, abs=1e-12)


# --- 2015 behaviours no option restores: said in the deviations --------------------------------


def test_invalid_poses_are_ignored_where_2015_gave_a_nan_score() -> None:
    gt = _gt([0, 10, 20, 30, 40], [0.0, 0.1, 0.2, 0.3, 0.4])
    robot = _gt([15.0, 25.0, 35.0], [0.0] * 3)
    robot[1] = (robot[1][0], (math.nan, 0.0, 0.0), robot[1][2])
    node = score_2015(robot, [gt])
    assert node.position_error is not None and math.isnan(node.position_error)
    r = _run(robot, gt)
    d = math.sqrt(1.25)  # held GT x 0.1 and 0.3, y = x / 2, z equal
    assert r.to_dict()["position_error"] == pytest.approx((0.1 * d + 0.3 * d) / 2, abs=1e-12)
    assert any(dev.endswith("[trajectory.invalid-poses]") for dev in r.deviations)


def test_overlapping_gt_files_are_a_deviation(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    t = EPOCH + np.arange(0, 1000, 10, dtype=np.int64) * MS
    xyz = np.column_stack([np.linspace(0, 1, len(t)), np.zeros((len(t), 2))])
    a = write_gt(tmp_path / "gt_a.bag", t[:60], xyz[:60], GT_TOPIC)
    b = write_gt(tmp_path / "gt_b.bag", t[40:], xyz[40:], GT_TOPIC)  # 20 messages twice
    robot = write_robot(tmp_path / "robot.bag", t[5:95:10] + 5 * MS, np.zeros((9, 3)), ROBOT_TOPIC)
    others_2015 = ["--association", "hold", "--ties", "before", "--gaps", "compare"]
    ours = _cli_json([str(robot), str(a), str(b), *others_2015], capsys)
    assert ours["tracking_lost"] == 0  # the duplicates are used once
    assert any(
        d.startswith("1 pair(s) of GT files overlap")
        and d.endswith("--gt-order chain restores 2015 [trajectory.gt-overlap]")
        for d in ours["deviations"]
    )
    # --2015 chains them (the robot poses all lie after the overlap or before it: same pairs).
    chained = _cli_json([str(robot), str(a), str(b), "--2015"], capsys)
    assert not any("[trajectory.gt-overlap]" in d for d in chained["deviations"])
    assert chained["position_error"] == pytest.approx(ours["position_error"], abs=1e-12)
    node = score_2015(_poses(robot, ROBOT_TOPIC), [_poses(a, GT_TOPIC), _poses(b, GT_TOPIC)])
    assert_same(chained, node)


# --- GT files overlapping in time: 2015 chained them and scanned forward ------------------------
# The peer suite of rockin_offline_trajectory_benchmark, case 6 (tests/test_bags_6.yaml, "the
# two mocap bags overlap"): each message (bag, stamp s, x) written with its record time = its
# stamp (tests/test_bags.py), z = 1, roll = pitch = yaw = 0, frame world.
PEER_6 = (
    ("rockin_mocap_bag_1", 0.05, 1.0, 0.0),
    ("robot_bag", 0.1, 0.0, 0.0),
    ("rockin_mocap_bag_1", 0.15, 1.1, 0.0),
    ("robot_bag", 0.2, 0.1, 0.0),
    ("rockin_mocap_bag_1", 0.35, 1.3, 0.0),
    ("robot_bag", 0.3, 0.2, 0.0),
    ("rockin_mocap_bag_2", 0.25, 1.2, 0.0),
    ("robot_bag", 0.4, 0.3, 0.0),
    ("rockin_mocap_bag_2", 0.45, 1.4, 0.0),
    ("robot_bag", 0.5, 0.4, 0.0),
    ("rockin_mocap_bag_2", 0.55, 1.2, 1.2),
)
PEER_ROBOT_TOPIC = "/rockin/team/marker_pose"
PEER_GT_TOPIC = "/airlab/robot/pose"


def _peer_bags(folder: Path, messages: tuple[tuple[str, float, float, float], ...]) -> Path:
    """The bags of a peer-suite case, as its tests/test_bags.py wrote them."""

    gt_dir = folder / "mocap"
    gt_dir.mkdir()
    for name in dict.fromkeys(m[0] for m in messages):
        rows = [m for m in messages if m[0] == name]
        t = np.array([round(s * 1e9) for _, s, _, _ in rows], dtype=np.int64)
        xyz = np.array([[x, y, 1.0] for _, _, x, y in rows])
        quat = np.tile([0.0, 0.0, 0.0, 1.0], (len(rows), 1))
        robot = name == "robot_bag"
        path = (folder if robot else gt_dir) / f"{name}.bag"
        with BagWriter(path, "ros1") as bag:
            topic = PEER_ROBOT_TOPIC if robot else PEER_GT_TOPIC
            bag.write_pose_stamped(topic, t, t, "world", xyz, quat)
    return gt_dir


def test_peer_case_6_overlapping_gt_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    gt_dir = _peer_bags(tmp_path, PEER_6)
    robot = tmp_path / "robot_bag.bag"
    # By hand, 2015's scan over the chain 0.05, 0.15, 0.35 | 0.25, 0.45, 0.55 (bag 1 starts
    # first): robot 0.1 -> x 1.0, 0.2 -> 1.1, 0.3 -> 1.1 (0.35 >= 0.3), 0.4 -> past 0.35 and
    # 0.25 to 0.45: x 1.2, 0.5 -> 1.4. Distances 1.0, 1.0, 0.9, 0.9, 1.0: 4.8 / 5 = 0.96.
    ours = _cli_json([str(robot), str(gt_dir), "--2015"], capsys)
    assert ours["position_error"] == pytest.approx(0.96, abs=1e-12)
    assert ours["compared"] == 5 and ours["orientation_error_2015"] == 0.0
    files = [
        _poses(gt_dir / "rockin_mocap_bag_1.bag", PEER_GT_TOPIC),
        _poses(gt_dir / "rockin_mocap_bag_2.bag", PEER_GT_TOPIC),
    ]
    assert_same(ours, score_2015(_poses(robot, PEER_ROBOT_TOPIC), files))
    assert any("go back in time at 1 place(s)" in w for w in ours["warnings"])
    # Time order: 1.0, 1.1, 1.2, 1.3, 1.4 held for 0.0 ... 0.4: 1.0 each, said.
    time_order = ["--association", "hold", "--ties", "before", "--gaps", "compare"]
    ours = _cli_json([str(robot), str(gt_dir), *time_order, "--before-gt", "first"], capsys)
    assert ours["position_error"] == pytest.approx(1.0, abs=1e-12)
    assert any("[trajectory.gt-overlap]" in d for d in ours["deviations"])


def _split(gt: list[Pose], how: str) -> list[list[Pose]]:
    """GT files as loggers would have left them, in start order."""
    n = len(gt)
    if how == "overlap":  # two loggers recording the same topic for a while: messages twice
        return [gt[: n * 6 // 10], gt[n * 4 // 10 :]]
    if how == "interleaved":  # two loggers taking turns: a file of even, one of odd frames
        return [gt[0:n:2], gt[1:n:2]]
    return [gt[: n // 3], gt[n // 4 : n * 2 // 3], gt[n // 2 :]]  # three, chained overlaps


@pytest.mark.parametrize("how", ["overlap", "interleaved", "three"])
@pytest.mark.parametrize("seed", range(3))
def test_chained_gt_files_equal_the_2015_scan(seed: int, how: str) -> None:
    robot, gt = _random_case(seed)
    files = _split(gt, how)
    chain = [p for f in files for p in f]
    node = score_2015(robot, files)
    ours = _run(robot, chain).to_dict()
    assert_same(ours, node)
    # Not vacuous: the chain goes back in time.
    assert any(b[0] < a[0] for a, b in itertools.pairwise(chain))
    timed = score_2015(robot, [gt])
    if how == "interleaved":
        # Files holding different samples of the same time: 2015's pairs are not the GT's.
        assert abs(timed.position_error - node.position_error) > 1e-6
    else:
        # A file re-recording messages the other holds: the forward scan, past the jump
        # back, stops where the time-ordered one does.
        assert node.position_error == pytest.approx(timed.position_error, rel=1e-12)


def test_yaw_tf_equals_tf_s_arithmetic() -> None:
    rng = np.random.default_rng(3)
    q = rng.normal(size=(2000, 4)) * rng.uniform(0.5, 2.0, (2000, 1))  # any norm, any pitch
    special = np.array(
        [
            [0.0, 0.0, 0.0, 0.0],  # tf: identity, yaw 0
            [0.0, math.sqrt(0.5), 0.0, math.sqrt(0.5)],  # pitch +90 degrees: tf gives yaw 0
            [0.0, 0.0, 1.0, 1e-17],  # yaw pi
            [0.0, 0.0, -1.0, 1e-17],  # yaw -pi
        ]
    )
    q = np.vstack([q, special])
    ours = yaw_tf(q)
    want = [tf_yaw(row.tolist()) for row in q]
    assert ours == pytest.approx(want, abs=1e-12, rel=0)


def _plain_yaw_tf(q: np.ndarray) -> np.ndarray:
    """yaw_tf as first written, its products inside the one expression."""
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    n = np.einsum("...i,...i->...", q, q)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = 2.0 / n
        m00 = 1.0 - (y * y + z * z) * s
        m10 = (x * y + z * w) * s
    eps = float(np.finfo(np.float64).eps) * 4.0
    flat = (n < eps) | (m00 * m00 + m10 * m10 <= eps * eps)
    return np.asarray(np.where(flat, 0.0, np.arctan2(m10, m00)))


def test_both_yaws_at_once_are_each_to_the_bit() -> None:
    """The association's yaws from shared products are yaw_from_quat's and tf's, bit for bit,
    on quaternions of any norm and pitch, gimbal lock, zero and near-zero ones."""
    rng = np.random.default_rng(5)
    q = rng.normal(size=(5000, 4)) * rng.uniform(1e-3, 1e3, (5000, 1))
    special = np.array(
        [
            [0.0, 0.0, 0.0, 0.0],
            [0.0, math.sqrt(0.5), 0.0, math.sqrt(0.5)],
            [0.0, 0.0, 1.0, 1e-17],
            [0.0, 0.0, -1.0, 1e-17],
            [1e-10, -2e-10, 3e-10, 1e-10],
            [0.5, -0.5, 0.5, -0.5],
        ]
    )
    q = np.vstack([q, special])
    yaw, tf = _yaws(q)
    assert np.array_equal(yaw, yaw_from_quat(q))
    assert np.array_equal(tf, _plain_yaw_tf(q))
    assert np.array_equal(yaw_tf(q), _plain_yaw_tf(q))
    assert np.array_equal(_yaws(q[7])[1], _plain_yaw_tf(q[7]))
