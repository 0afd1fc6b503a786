"""``score trajectory --2015`` against rockin_trajectory_benchmark.py's loop as written
(``script2015.py``), over generated bag sets, one per path of the script: GT gaps, robot poses
before the GT, tracking lost, exact ties, yaw across +-pi, GT split into consecutive,
interleaved and re-recorded (duplicate) files, a GT file outside the robot bag's span (2015
did not chain it), the GT running out (2015: exit 6) and no GT file overlapping (exit 4).

The bags are written with the samples' writer and read back with rosbags (not ertools.io).
Tolerance 1e-12 relative: the same terms, summed one at a time by the script and pairwise by
NumPy over <= 200 terms.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from ertools.cli.main import main
from ertools.simulator.writer import BagWriter
from tests.benchmarks.trajectory.script2015 import Bag, PoseStamped, Run, Time, run_2015
from tests.helpers.stderr_text import error_messages

S = 1_000_000_000
MS = 1_000_000
T0 = 1_448_020_800 * S
ROBOT_TOPIC = "/rockin/homer/marker_pose"
GT_TOPIC = "/airlab/robot/pose"
REL = 1e-12


@dataclass(frozen=True)
class Case:
    name: str
    exit_2015: int = 0


CASES = (
    Case("plain"),
    Case("gap"),
    Case("before"),
    Case("lost"),
    Case("ties"),
    Case("yaw"),
    Case("consecutive"),
    Case("interleaved"),
    Case("duplicate"),
    Case("outside"),
    Case("after", exit_2015=6),
    Case("none", exit_2015=4),
)


def _quat(yaw: np.ndarray) -> np.ndarray:
    return np.column_stack([np.zeros((len(yaw), 2)), np.sin(yaw / 2), np.cos(yaw / 2)])


def _truth(t_ns: np.ndarray, wrap: bool = False) -> tuple[np.ndarray, np.ndarray]:
    s = (t_ns - T0) / S
    xyz = np.column_stack([0.3 * s, 0.5 * np.sin(0.4 * s), np.full(len(s), 0.2)])
    yaw = (2.9 + 0.08 * s) if wrap else 0.3 * np.sin(0.5 * s)
    return xyz, np.angle(np.exp(1j * yaw))


def _write_gt(path: Path, t: np.ndarray, xyz: np.ndarray, yaw: np.ndarray) -> None:
    with BagWriter(path, "ros1") as bag:
        bag.write_pose_stamped(GT_TOPIC, t + 300_000, t, "world", xyz, _quat(yaw))


def _bags(case: Case, folder: Path) -> tuple[Path, Path]:
    """The robot bag and the GT folder of a case."""
    rng = np.random.default_rng(len(case.name) * 7 + 3)
    gt_dir = folder / "mocap"
    gt_dir.mkdir()
    t = T0 + np.arange(0, 10_000, 10, dtype=np.int64) * MS  # 100 Hz for 10 s
    t = t + rng.integers(-1_000_000, 1_000_000, len(t))  # jitter, still increasing
    xyz, yaw = _truth(t, wrap=case.name == "yaw")
    xyz = xyz + rng.normal(0, 5e-4, xyz.shape)
    if case.name == "gap":
        keep = (t < T0 + 4 * S) | (t > T0 + 4_500 * MS)
        t, xyz, yaw = t[keep], xyz[keep], yaw[keep]
    if case.name == "lost":
        at = (t > T0 + 5 * S) & (t < T0 + 5_300 * MS)
        xyz[at] = xyz[np.argmax(at) - 1]  # Motive repeating the last pose
    robot_t = T0 + np.arange(1_000, 9_000, 100, dtype=np.int64) * MS
    robot_t = robot_t + rng.integers(0, 9 * MS, len(robot_t))
    if case.name == "before":
        robot_t = robot_t - 1_300 * MS  # starts 0.3 s before the GT
    if case.name == "after":
        robot_t = robot_t + 1_400 * MS  # ends 0.4 s after the GT
    if case.name == "ties":
        robot_t[::3] = t[np.searchsorted(t, robot_t[::3])]
    files: list[tuple[str, np.ndarray]] = []
    n = len(t)
    if case.name == "consecutive":
        files = [("a", np.arange(0, n // 2)), ("b", np.arange(n // 2, n))]
    elif case.name == "interleaved":  # two loggers taking turns over the middle 4 s
        files = [("a", np.arange(0, n * 7 // 10, 1)), ("b", np.arange(n * 3 // 10, n))]
        files[0] = (
            "a",
            np.concatenate([files[0][1][: n * 3 // 10], files[0][1][n * 3 // 10 :: 2]]),
        )
        files[1] = (
            "b",
            np.concatenate([files[1][1][1 : n * 4 // 10 : 2], files[1][1][n * 4 // 10 :]]),
        )
    elif case.name == "duplicate":
        files = [("a", np.arange(0, n * 6 // 10)), ("b", np.arange(n * 4 // 10, n))]
    else:
        files = [("a", np.arange(n))]
    for name, idx in files:
        _write_gt(gt_dir / f"gt_{name}.bag", t[idx], xyz[idx], yaw[idx])
    if case.name == "outside":  # a GT file that ends 2 s before the robot log starts
        early = t[:50] - 5 * S
        _write_gt(gt_dir / "gt_0_early.bag", early, xyz[:50] + 1.0, yaw[:50])
    if case.name == "none":
        for p in gt_dir.iterdir():
            p.unlink()
        _write_gt(gt_dir / "gt_far.bag", t - 60 * S, xyz, yaw)
    r_xyz, r_yaw = _truth(robot_t, wrap=case.name == "yaw")
    r_xyz = r_xyz + rng.normal(0, 0.01, r_xyz.shape)
    r_yaw = r_yaw + rng.normal(0, 0.05, len(r_yaw))
    robot = folder / "robot.bag"
    with BagWriter(robot, "ros1") as bag:
        bag.write_pose_stamped(
            ROBOT_TOPIC, robot_t + 20 * MS, robot_t, "world", r_xyz, _quat(r_yaw)
        )
    return robot, gt_dir


def _read(path: Path) -> Bag:
    msgs = []
    with AnyReader([path]) as reader:
        for conn, t, raw in reader.messages():
            m = reader.deserialize(raw, conn.msgtype)
            st = m.header.stamp
            p, q = m.pose.position, m.pose.orientation
            pose = PoseStamped(Time(st.sec, st.nanosec), (p.x, p.y, p.z), (q.x, q.y, q.z, q.w))
            msgs.append((conn.topic, pose, t))
    return Bag(path.name, msgs)


@pytest.fixture(scope="module", params=CASES, ids=[c.name for c in CASES])
def logged(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Any:
    case: Case = request.param
    robot, gt_dir = _bags(case, tmp_path_factory.mktemp(case.name))
    script = run_2015(
        _read(robot), [_read(p) for p in sorted(gt_dir.iterdir())], ROBOT_TOPIC, GT_TOPIC
    )
    return case, robot, gt_dir, script


def _cli(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, Any, str]:
    code = main(["score", "trajectory", *args, "--format", "json"])
    cap = capsys.readouterr()
    return code, json.loads(cap.out) if cap.out.strip() else None, cap.err


def test_each_case_takes_its_path(logged: Any) -> None:
    """Not vacuous: every case drives the script where it is meant to."""
    case, _, _, script = logged
    run: Run = script
    assert run.exit_code == case.exit_2015
    lines = run.out
    expect = {
        "gap": lambda: run.compared_across_gaps > 0,
        "before": lambda: any("never happen" in s for s in lines),
        "lost": lambda: any("ignoring pose" in s for s in lines),
        "interleaved": lambda: any("out of order" in s for s in lines),
        "duplicate": lambda: any("out of order" in s for s in lines),
    }
    if case.name in expect:
        assert expect[case.name]()


def test_2015_equals_the_script(logged: Any, capsys: pytest.CaptureFixture[str]) -> None:
    case, robot, gt_dir, run = logged
    code, out, err = _cli([str(robot), str(gt_dir), "--2015"], capsys)
    if run.exit_code:
        # 2015 gave no score (exit 4: no GT file, exit 6: GT ran out): neither does ertools.
        assert code == 1 and out is None
        assert err.startswith("ertools: error:") and len(error_messages(err)) == 1
        return
    assert code == 0, err
    e = run.error
    assert out["compared"] == e.n
    assert out["position_error"] == pytest.approx(e.get_position_error(), rel=REL)
    assert out["orientation_error_2015"] == pytest.approx(e.get_orientation_error(), rel=REL)
    assert out["tracking_lost"] == sum("ignoring pose" in s for s in run.out)
    assert out["before_gt"] == sum("never happen" in s for s in run.out)
    assert out["gaps_compared"] == run.compared_across_gaps
    assert out["gaps"] == 0 and out["uncovered"] == 0
    if case.name == "yaw":
        # Some yaw differences crossed +-pi: 2015's unwrapped value is not the wrapped one.
        assert abs(out["orientation_error"] - out["orientation_error_2015"]) > 1e-3


def test_the_default_scores_every_log_2015_scored(
    logged: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    case, robot, gt_dir, run = logged
    code, out, err = _cli([str(robot), str(gt_dir)], capsys)
    if run.exit_code:
        assert code == 1 and out is None
        return
    if case.name == "before":
        # Robot poses before the GT: an error naming --before-gt first and --allow-partial.
        assert code == 1 and "--before-gt first" in err
        code, out, err = _cli([str(robot), str(gt_dir), "--allow-partial"], capsys)
    assert code == 0, err
    assert out["position_error"] is not None and out["compared"] > 0
    assert math.isfinite(out["position_error"])
