"""evo, an independent implementation, agrees with `ertools score trajectory` on ertools' exports.

evo (MichaelGrupp/evo, a test-only dependency) reads the TUM files with its own parser,
associates with its own code and computes APE (translation part, no alignment: the distance
between the paired positions). Its mean, RMSE, median and max must be ertools'
position_error, rmse, median and max:

- on the scored pairs (`--matched`), for every association, to 1e-9 m: evo pairs the two files
  one to one (equal stamps), so only summation order differs (~1e-16 relative);
- on the raw streams with evo's defaults (nearest stamp within 0.01 s) against
  `--association nearest`, to 1e-9 m, where ertools leaves no pose out (a clean synthetic log)
  and, on the sample log, once the poses ertools leaves out (GT gaps, tracking lost) are set
  aside;
- evo's interpolation sync against `--association linear` only to 1e-6 m: evo interpolates on
  float seconds, which resolve an epoch stamp to 2.4e-7 s (x 0.3 m/s = 7e-8 m).
"""

from __future__ import annotations

import json
from decimal import Decimal
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ertools.cli.main import main

pytest.importorskip("evo", reason="evo is in the dev extra: `make test` installs it")

from evo.core import metrics, sync
from evo.core.sync_method import SyncMethod
from evo.tools import file_interface

from tests.helpers.bagmaker import Spec, write

pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[2]
ROBOTLOG = REPO / "sample_bags/robotlog"
ROBOT_BAG = ROBOTLOG / "FBM2H_201511201200_homer.bag"
ROBOT_TOPIC = "/rockin/homer/marker_pose"
GT_TOPIC = "/fbm2h/robot_at_home/pose"
TOL = 1e-9  # metres; see the module docstring
STATS = {"mean": "position_error", "rmse": "rmse", "median": "median", "max": "max"}


def ertools_score(
    capsys: pytest.CaptureFixture[str], robot: Path, gt: Path, *extra: str
) -> dict[str, Any]:
    argv = ["score", "trajectory", str(robot), str(gt), "--format", "json", *extra]
    code = main(argv)
    out = capsys.readouterr().out
    assert code == 0
    result: dict[str, Any] = json.loads(out)
    return result


def stamps_ns(tum: Path) -> list[int]:
    """The stamps of a TUM file in int ns, parsed as decimals (exact)."""
    return [int(Decimal(line.split()[0]) * 10**9) for line in tum.read_text().splitlines()]


def export(robot: Path, gt: Path, out: Path, *extra: str) -> tuple[Path, Path]:
    assert main(["export", str(robot), str(gt), "--out-dir", str(out), *extra]) == 0
    return out / "gt.tum", out / "robot.tum"


def evo_ape(
    gt_file: Path, robot_file: Path, method: SyncMethod = SyncMethod.nearest_time
) -> tuple[metrics.APE, Any]:
    """evo's APE, translation part, no alignment, with evo's default max_diff (0.01 s)."""
    ref = file_interface.read_tum_trajectory_file(gt_file)
    est = file_interface.read_tum_trajectory_file(robot_file)
    ref, est = sync.associate_trajectories(ref, est, sync_method=method)
    ape = metrics.APE(metrics.PoseRelation.translation_part)
    ape.process_data((ref, est))
    return ape, est


def assert_same_stats(ape: metrics.APE, score: dict[str, Any], tol: float = TOL) -> None:
    stats = ape.get_all_statistics()
    assert len(ape.error) == score["compared"]
    for evo_key, ertools_key in STATS.items():
        assert stats[evo_key] == pytest.approx(score[ertools_key], abs=tol), evo_key


@pytest.mark.parametrize("association", ["linear", "nearest", "hold"])
def test_matched_pairs_give_ertools_ape(
    association: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    score = ertools_score(capsys, ROBOT_BAG, ROBOTLOG, "--association", association)
    # The sample log leaves poses out (GT gaps, tracking lost): evo must not see them.
    assert score["gaps"] > 0 and score["tracking_lost"] > 0
    gt, robot = export(ROBOT_BAG, ROBOTLOG, tmp_path, "--matched", "--association", association)
    ape, _ = evo_ape(gt, robot)
    assert_same_stats(ape, score)


def test_matched_pairs_with_the_estimated_offset(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    opts = ("--offset", "auto", "--apply-offset")
    score = ertools_score(capsys, ROBOT_BAG, ROBOTLOG, *opts)
    # the sample robot clock runs 0.35 s ahead (sample_bags/README.md)
    assert score["offset"] == pytest.approx(-0.35, abs=0.02)
    gt, robot = export(ROBOT_BAG, ROBOTLOG, tmp_path, "--matched", *opts)
    ape, _ = evo_ape(gt, robot)
    assert_same_stats(ape, score)
    # The matched robot stamps are the robot's own stamps (the raw export, no offset) plus the
    # applied offset, to the nanosecond.
    _, raw = export(ROBOT_BAG, ROBOTLOG, tmp_path / "raw")
    offset_ns = round(score["offset"] * 1e9)
    matched_ns = stamps_ns(robot)
    assert len(matched_ns) == score["compared"]
    assert set(matched_ns) <= {t + offset_ns for t in stamps_ns(raw)}


def test_raw_streams_with_evo_defaults_on_the_sample(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """evo keeps the poses ertools leaves out; without them, evo's default = ertools nearest."""
    score = ertools_score(capsys, ROBOT_BAG, ROBOTLOG, "--association", "nearest")
    gt, robot = export(ROBOT_BAG, ROBOTLOG, tmp_path / "raw")
    ape, est = evo_ape(gt, robot)
    assert len(ape.error) > score["compared"]  # the gap and tracking-lost poses are in
    assert abs(ape.get_statistic(metrics.StatisticsType.mean) - score["position_error"]) > 1e-4
    _, matched_robot = export(
        ROBOT_BAG, ROBOTLOG, tmp_path / "m", "--matched", "--association", "nearest"
    )
    # Same ns stamps, same text, same float in both files: select by equality.
    scored = np.isin(
        est.timestamps, file_interface.read_tum_trajectory_file(matched_robot).timestamps
    )
    assert int(scored.sum()) == score["compared"]
    errors = ape.error[scored]
    assert float(np.mean(errors)) == pytest.approx(score["position_error"], abs=TOL)
    assert float(np.sqrt(np.mean(errors**2))) == pytest.approx(score["rmse"], abs=TOL)
    assert float(np.max(errors)) == pytest.approx(score["max"], abs=TOL)


def _clean_logs(tmp_path: Path) -> tuple[Path, Path]:
    """A 120 Hz GT circle (no repeats, no gaps) and a 10 Hz robot log of it with a bias and
    noise, stamped between GT samples (a random 0-8 ms after the 10 Hz grid)."""
    rng = np.random.default_rng(19)
    t0 = 1_448_020_800_000_000_000
    gt_t = t0 + np.arange(120 * 20, dtype=np.int64) * 8_333_333

    def path(t: np.ndarray) -> np.ndarray:
        a = 0.3 * (t - t0) / 1e9  # 0.3 m/s on a 1 m circle
        return np.stack([np.cos(a), np.sin(a), 0.45 + 0.01 * np.sin(a / 3)], axis=1)

    def quat(t: np.ndarray) -> np.ndarray:
        yaw = 0.3 * (t - t0) / 1e9 + np.pi / 2
        return np.stack([0 * yaw, 0 * yaw, np.sin(yaw / 2), np.cos(yaw / 2)], axis=1)

    rob_t = t0 + 1_000_000_000 + np.arange(170, dtype=np.int64) * 100_000_000
    rob_t = rob_t + rng.integers(0, 8_000_000, len(rob_t))
    gt, robot = Spec(), Spec()
    g = gt.conn(GT_TOPIC, "geometry_msgs/PoseStamped")
    r = robot.conn(ROBOT_TOPIC, "geometry_msgs/PoseStamped")
    for t, p, q in zip(gt_t.tolist(), path(gt_t), quat(gt_t), strict=True):
        gt.add(g, t + 2_000_000, stamp=t, frame="world", xyz=p, q=q)
    noisy = path(rob_t) + np.array([0.012, -0.008, 0.003]) + rng.normal(0, 0.003, (len(rob_t), 3))
    for t, p, q in zip(rob_t.tolist(), noisy, quat(rob_t), strict=True):
        robot.add(r, t + 1_000_000, stamp=t, frame="map", xyz=p, q=q)
    return (
        write(tmp_path / "robot.bag", "ros1", robot),
        write(tmp_path / "gt.bag", "ros1", gt),
    )


def test_raw_streams_with_evo_defaults_equal_nearest(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    robot_bag, gt_bag = _clean_logs(tmp_path)
    score = ertools_score(capsys, robot_bag, gt_bag, "--association", "nearest")
    assert score["compared"] == score["robot_poses"] == 170  # nothing left out
    gt, robot = export(robot_bag, gt_bag, tmp_path / "raw")
    ape, _ = evo_ape(gt, robot)
    assert_same_stats(ape, score)


def test_evo_interpolation_is_linear_to_float_seconds(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    robot_bag, gt_bag = _clean_logs(tmp_path)
    score = ertools_score(capsys, robot_bag, gt_bag, "--association", "linear")
    gt, robot = export(robot_bag, gt_bag, tmp_path / "raw")
    ape, _ = evo_ape(gt, robot, SyncMethod.interpolation)
    assert_same_stats(ape, score, tol=1e-6)
    # and the matched pairs remove the float-seconds interpolation: exact again
    gt_m, robot_m = export(robot_bag, gt_bag, tmp_path / "m", "--matched")
    ape_m, _ = evo_ape(gt_m, robot_m)
    assert_same_stats(ape_m, score)
