"""`score trajectory --association nearest --t-max-diff S` gives evo_ape's pairs and numbers.

evo (MichaelGrupp/evo, a test dependency) is run as its command line, `evo_ape ... --save_results
res.zip`, under a scratch HOME (it writes ~/.evo/settings.json) with MPLBACKEND=Agg; its stats
(full precision, stats.json) and its error array (one entry per pair) are the reference:

- evo's own test data (../shared/evo_testdata): the ROS1 bag (ORB-SLAM vs groundtruth), the TUM
  pair and the KITTI pair (paired by index, no --t-max-diff needed);
- a ROS 2 MCAP written here with the project's writer: header stamps in simulation time (~928 s),
  record times on the wall clock, as a navigation bag recorded from a simulator.

Tolerance: the pair count is exact; rmse, mean and max to 1e-6 m (the issue's), though the same
pairs give the same distances up to summation order (~1e-15 relative).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ertools.benchmarks.trajectory.association import evo_matches
from ertools.cli.main import main
from ertools.geometry import quat_from_yaw
from ertools.simulator.writer import BagWriter

REPO = Path(__file__).resolve().parents[3]
EVO_DATA = REPO.parent / "shared" / "evo_testdata"
BIN = Path(sys.executable).parent
TOL = 1e-6
NS = 1_000_000_000


def _evo_data(name: str) -> Path:
    path = EVO_DATA / name
    if not path.exists():
        pytest.skip(f"n/a: {path} absent (evo's test data, see ../shared/evo_testdata/README.md)")
    return path


def evo_ape(tmp_path: Path, *args: str) -> tuple[int, dict[str, float]]:
    """evo_ape's number of pairs and its statistics (translation part, no alignment)."""
    exe = BIN / "evo_ape"
    if not exe.exists():
        pytest.skip("n/a: evo_ape not installed (the dev extra installs it)")
    home = tmp_path / "evo_home"
    home.mkdir(exist_ok=True)
    res = tmp_path / f"evo_{len(list(tmp_path.glob('evo_*.zip')))}.zip"
    env = {**os.environ, "HOME": str(home), "MPLBACKEND": "Agg"}
    subprocess.run(
        [str(exe), *args, "--save_results", str(res), "--no_warnings"],
        check=True,
        env=env,
        capture_output=True,
        timeout=120,
    )
    with zipfile.ZipFile(res) as z:
        stats = json.loads(z.read("stats.json"))
        with z.open("error_array.npy") as f:
            errors = np.load(f)
    return len(errors), stats


def ertools_json(capsys: pytest.CaptureFixture[str], *argv: str) -> dict[str, Any]:
    # evo's numbers are the subject, not the intervals: no Monte Carlo draws
    code = main(["score", "trajectory", *argv, "--format", "json", "--draws", "0"])
    out = capsys.readouterr()
    assert code == 0, out.err
    result: dict[str, Any] = json.loads(out.out)
    return result


def assert_same(ours: dict[str, Any], n: int, stats: dict[str, float]) -> None:
    assert ours["compared"] == n
    assert abs(ours["rmse"] - stats["rmse"]) < TOL
    assert abs(ours["position_error"] - stats["mean"]) < TOL
    assert abs(ours["max"] - stats["max"]) < TOL


EVO_LINE = ("--association", "nearest", "--t-max-diff", "0.01")


@pytest.mark.slow
@pytest.mark.parametrize(
    ("gt", "robot"),
    [("groundtruth", "ORB-SLAM"), ("ORB-SLAM", "groundtruth"), ("groundtruth", "S-PTAM")],
    ids=["robot-shorter", "gt-shorter", "s-ptam"],
)
def test_ros1_bag_as_evo_ape_bag(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], gt: str, robot: str
) -> None:
    """evo starts from the trajectory with fewer poses: the robot's (ORB-SLAM, 8362 poses
    against 12765), or the GT's when the roles are swapped."""
    bag = _evo_data("ROS_example.bag")
    n, stats = evo_ape(tmp_path, "bag", str(bag), gt, robot)
    ours = ertools_json(capsys, str(bag), "--robot-topic", robot, "--gt-topic", gt, *EVO_LINE)
    assert_same(ours, n, stats)
    # Every robot pose is either in one of evo's pairs or said to be left out.
    assert ours["compared"] + ours["unpaired"] + ours["uncovered"] == ours["robot_poses"]


@pytest.mark.slow
def test_tum_pair_as_evo_ape_tum(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    gt = _evo_data("freiburg1_xyz-groundtruth.txt")
    robot = _evo_data("freiburg1_xyz-rgbdslam.txt")
    n, stats = evo_ape(tmp_path, "tum", str(gt), str(robot))
    assert_same(ertools_json(capsys, str(robot), str(gt), *EVO_LINE), n, stats)


@pytest.mark.slow
def test_kitti_pair_as_evo_ape_kitti(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    gt = _evo_data("KITTI_00_gt.txt")
    robot = _evo_data("KITTI_00_ORB.txt")
    n, stats = evo_ape(tmp_path, "kitti", str(gt), str(robot))
    ours = ertools_json(capsys, str(robot), str(gt))
    assert_same(ours, n, stats)
    assert any("row by row" in w for w in ours["warnings"])


def test_kitti_counts_must_agree(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    gt = _evo_data("KITTI_00_gt.txt")
    short = tmp_path / "short.txt"
    short.write_text("".join(gt.read_text().splitlines(keepends=True)[:100]))
    code = main(["score", "trajectory", str(short), str(gt)])
    err = capsys.readouterr().err
    assert code == 1
    assert "100 rows" in err and "4541" in err and "Traceback" not in err


def write_sim_bag(
    path: Path, fmt: str = "rosbag2-mcap", topics: tuple[str, ...] = ("/odom", "/amcl_pose")
) -> None:
    """A navigation bag recorded from a simulator: header stamps on the simulation clock
    (from 928 s), record times on the wall clock (2023), the robot (~7 Hz, jittered stamps)
    noisy around the GT (/odom, 30 Hz)."""

    rng = np.random.default_rng(26)
    wall0, sim0 = 1_700_000_000 * NS, 928 * NS
    tg = sim0 + np.arange(0, 40 * NS, NS // 30)
    tr = sim0 + NS // 7 * np.arange(1, 270) + rng.integers(-8_000_000, 8_000_000, 269)

    def at(t: np.ndarray) -> np.ndarray:
        s = (t - sim0) / NS
        return np.column_stack([3 * np.cos(s / 5), 2 * np.sin(s / 5), 0 * s])

    noise = rng.normal(0, 0.05, (len(tr), 3))
    with BagWriter(path, fmt) as bag:  # type: ignore[arg-type]
        if "/odom" in topics:
            bag.write_pose_stamped(
                "/odom",
                tg - sim0 + wall0 + 2_000_000,
                tg,
                "map",
                at(tg),
                quat_from_yaw((tg - sim0) / 5e9),
            )
        if "/amcl_pose" not in topics:
            return
        bag.write_pose_stamped(
            "/amcl_pose",
            tr - sim0 + wall0 + 5_000_000,
            tr,
            "map",
            at(tr) + noise,
            quat_from_yaw((tr - sim0) / 5e9 + 0.1),
        )


@pytest.mark.slow
def test_sim_time_mcap_as_evo_ape_bag2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = tmp_path / "sim"
    write_sim_bag(bag)
    n, stats = evo_ape(tmp_path, "bag2", str(bag), "/odom", "/amcl_pose")
    ours = ertools_json(
        capsys, str(bag), "--robot-topic", "/amcl_pose", "--gt-topic", "/odom", *EVO_LINE
    )
    assert_same(ours, n, stats)
    # The two clocks disagree by far more than the span: the output says which was used.
    said = [w for w in ours["warnings"] if "header stamps and record times differ" in w]
    assert said and "paired by header stamps" in said[0]


@pytest.mark.slow
def test_sim_time_gt_in_another_bag(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Robot and GT in two bags, both in simulation time: the GT file is found by the robot's
    record times (the files' spans), its poses read by header stamps; the pairs are those of
    the one-bag case (evo's association decides them from the stamps alone)."""
    both, robot, gt = tmp_path / "both", tmp_path / "robot", tmp_path / "gt"
    write_sim_bag(both)
    write_sim_bag(robot, topics=("/amcl_pose",))
    write_sim_bag(gt, topics=("/odom",))
    one = ertools_json(
        capsys, str(both), "--robot-topic", "/amcl_pose", "--gt-topic", "/odom", *EVO_LINE
    )
    two = ertools_json(
        capsys, str(robot), str(gt), "--robot-topic", "/amcl_pose", "--gt-topic", "/odom"
    )
    assert two["compared"] == 269  # linear: every robot pose lies within the GT
    two_evo = ertools_json(
        capsys, str(robot), str(gt), "--robot-topic", "/amcl_pose", "--gt-topic", "/odom", *EVO_LINE
    )
    assert two_evo["compared"] == one["compared"]
    assert two_evo["rmse"] == one["rmse"]


def test_sim_time_by_record_time(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--time-source record selects and pairs robot and GT by their record times: the GT's
    are 2 ms and the robot's 5 ms after their header stamps, so every robot pose is still
    within the GT and paired (linear)."""
    bag = tmp_path / "sim"
    write_sim_bag(bag)
    ours = ertools_json(
        capsys,
        str(bag),
        "--robot-topic",
        "/amcl_pose",
        "--gt-topic",
        "/odom",
        "--time-source",
        "record",
    )
    assert ours["compared"] == 269
    said = [w for w in ours["warnings"] if "header stamps and record times differ" in w]
    assert said and "robot record, GT record times" in said[0]


def test_time_source_contradiction(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = tmp_path / "sim"
    write_sim_bag(bag)
    argv = ["score", "trajectory", str(bag), "--robot-topic", "/amcl_pose", "--gt-topic", "/odom"]
    code = main([*argv, "--time-source", "header", "--robot-time-source", "record"])
    assert code == 2
    assert "--time-source header sets the robot's time too" in capsys.readouterr().err


@pytest.mark.slow
def test_t_max_diff_needs_nearest(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = tmp_path / "sim"
    write_sim_bag(bag)
    argv = ["score", "trajectory", str(bag), "--robot-topic", "/amcl_pose", "--gt-topic", "/odom"]
    assert main([*argv, "--association", "linear", "--t-max-diff", "0.01"]) == 2
    assert "needs --association nearest" in capsys.readouterr().err
    # Alone it implies nearest: the same pairs as with it spelt out.
    alone = ertools_json(capsys, *argv[2:], "--t-max-diff", "0.01")
    spelt = ertools_json(capsys, *argv[2:], *EVO_LINE)
    assert alone["association"] == "nearest" and alone["compared"] == spelt["compared"]


@pytest.mark.slow
def test_export_matched_gives_evo_pairs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """`export --matched --t-max-diff` writes evo's pairs: evo_ape on them gives the same
    numbers as evo_ape on the bag itself."""
    bag = _evo_data("ROS_example.bag")
    out = tmp_path / "pair"
    argv = ["export", str(bag), "--robot-topic", "ORB-SLAM", "--gt-topic", "groundtruth"]
    assert main([*argv, *EVO_LINE, "--matched", "--out-dir", str(out)]) == 0
    capsys.readouterr()
    n, stats = evo_ape(tmp_path, "bag", str(bag), "groundtruth", "ORB-SLAM")
    n2, stats2 = evo_ape(tmp_path, "tum", str(out / "gt.tum"), str(out / "robot.tum"))
    assert n2 == n
    for key in ("rmse", "mean", "max"):
        assert abs(stats2[key] - stats[key]) < TOL


def test_evo_matches_is_evos_rule() -> None:
    """The vectorised matcher against evo's own matching_time_indices, on stamps built to hit
    its corner cases: exact ties between two neighbours, differences of exactly max_diff,
    stamps beyond both ends, one long stamp nearest to several short ones."""
    pytest.importorskip("evo", reason="evo is in the dev extra: `make test` installs it")
    # lazy: evo is the dev extra's (importorskip above) and takes ~1 s to import
    from evo.core.sync import matching_time_indices

    rng = np.random.default_rng(5)
    for trial in range(30):
        grid = 0.005 if trial % 2 else 0.0001  # a coarse grid makes ties and exact limits
        long_s = np.sort(np.round(rng.uniform(100.0, 101.0, 80) / grid) * grid)
        short_s = np.sort(np.round(rng.uniform(99.95, 101.05, 40) / grid) * grid)
        for max_diff in (0.01, 0.005, 0.0):
            want = matching_time_indices(short_s, long_s, max_diff)
            got = evo_matches(short_s, long_s, max_diff)
            assert got[0].tolist() == want[0]
            assert got[1].tolist() == want[1]
