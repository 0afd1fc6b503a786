"""Values that parse but cannot be (issue 36, findings 4 and 5): a goal's theta in degrees, a
pose at 1e300 m, a 1 m spike of one mocap frame. A physically impossible pose is invalid like
a NaN one: left out of every number, counted in the validity, said in a warning; no NumPy
RuntimeWarning reaches stderr (each command here runs with RuntimeWarning as an error).

Expected scores come from the same log with the offending message removed (written by
rosbags, not by ertools): a pose left out as invalid must score exactly as a pose never
recorded."""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from ertools.caches import clear as clear_caches
from ertools.cli.main import main
from tests.e2e.edited_bags import edited_copy, poses_between
from tests.helpers.stderr_text import error_messages

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "sample_bags"
FBM3W = SAMPLES / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
FBM3W_TOPIC = "/fbm3w/robot_at_work/pose"
FBM2H = SAMPLES / "fbm2h" / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"
FBM2H_TOPIC = "/fbm2h/robot_at_home/pose"
FBM2H_GOAL = SAMPLES / "fbm2h" / "fbm2h_goal.yaml"
FBM2H_TRANSFORM = SAMPLES / "fbm2h" / "transform-simbot.yaml"
FBM1H = SAMPLES / "fbm1h" / "log_fbm1h_2015-11-20-12-00-00_0.bag"
FBM1H_ITEMS = SAMPLES / "fbm1h" / "fbm1h.yaml"
BOARD_TOPIC = "/fbm1h/ref_board/pose"
ROBOT = SAMPLES / "robotlog" / "FBM2H_201511201200_homer.bag"
ROBOT_TOPIC = "/rockin/homer/marker_pose"
GT = sorted((SAMPLES / "robotlog").glob("log_fbm2h_mocap_*.bag"))


@dataclass(frozen=True)
class Result:
    code: int
    out: str
    err: str

    def json(self) -> Any:
        return json.loads(self.out)


def strict(argv: list[str], capsys: pytest.CaptureFixture[str]) -> Result:
    """``ertools ARGV`` with every RuntimeWarning (NumPy's overflow and invalid values) an
    error: one would end as "unexpected RuntimeWarning ... this is a bug", exit 1."""
    capsys.readouterr()
    clear_caches()
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        code = main(argv)
    got = capsys.readouterr()
    assert "Traceback" not in got.err and "this is a bug" not in got.err, got.err
    return Result(code, got.out, got.err)


def moved(at: int, to: Any) -> Any:
    """An edit moving pose number ``at`` (``to``: its position -> the new one)."""
    return lambda k, p: to(p) if k == at else p


def dropped(at: int) -> Any:
    return lambda k, p: None if k == at else p


@pytest.fixture(scope="module")
def bags(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Each log with one pose made impossible, and with that pose's message removed."""
    root = tmp_path_factory.mktemp("hostile_values")
    # fbm3w: inside run 2 (19.4 to 23.4 s), the best run; fbm2h: while driving segment 1;
    # fbm1h: the board, in run 1's stationary window before its goal at 2.95 s; the GT of the
    # robot log, mid-log
    plans = {
        "fbm3w": (FBM3W, FBM3W_TOPIC, 21.0),
        "fbm2h": (FBM2H, FBM2H_TOPIC, 15.0),
        "fbm1h": (FBM1H, BOARD_TOPIC, 2.7),
        "gt": (GT[0], FBM2H_TOPIC, 10.0),
        "robot": (ROBOT, ROBOT_TOPIC, 10.0),
    }
    out = {}
    for name, (src, topic, at_s) in plans.items():
        at = poses_between(src, topic, at_s, at_s + 0.2)[0]
        edits = {
            "huge": moved(at, lambda p: (1e300, p[1], p[2])),
            "spike": moved(at, lambda p: (p[0] + 1.0, p[1], p[2])),
            "dropped": dropped(at),
        }
        for kind, edit in edits.items():
            out[f"{name}-{kind}"] = edited_copy(
                src, root / f"{name}-{kind}{src.suffix}", topic, edit
            )
    return out


@pytest.mark.parametrize("kind", ["huge", "spike"])
def test_fbm3w_leaves_an_impossible_pose_out(
    kind: str, bags: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    """Before: 1e300 m gave run 2 a distance error of 4.0e297 m, "100.0 % valid", and the best
    run moved to run 0 (exit 0); four RuntimeWarnings and a 771-character warning."""
    argv = ["score", "fbm3w", "--topic", FBM3W_TOPIC, "--format", "json"]
    got = strict([*argv[:2], str(bags[f"fbm3w-{kind}"]), *argv[2:]], capsys)
    ref = strict([*argv[:2], str(bags["fbm3w-dropped"]), *argv[2:]], capsys)
    assert got.code == ref.code == 0, got.err
    score, expected = got.json(), ref.json()
    assert score["best_run"] == expected["best_run"] == 2
    run, exp = score["runs_details"]["2"], expected["runs_details"]["2"]
    assert run["distance_error"] == exp["distance_error"]  # the same samples: the same sums
    assert run["invalid_samples"] == {"far" if kind == "huge" else "jump": 1}
    assert run["valid_fraction"] < 1.0
    assert f"{'far' if kind == 'huge' else 'jump'}" in got.err
    assert "left out as invalid" in got.err
    assert max(len(line) for line in got.err.splitlines()) < 400


@pytest.mark.parametrize("kind", ["huge", "spike"])
def test_fbm2h_leaves_an_impossible_marker_pose_out(
    kind: str, bags: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    tail = ["--goal", str(FBM2H_GOAL), "--transform", str(FBM2H_TRANSFORM), "--format", "json"]
    got = strict(["score", "fbm2h", str(bags[f"fbm2h-{kind}"]), *tail], capsys)
    ref = strict(["score", "fbm2h", str(bags["fbm2h-dropped"]), *tail], capsys)
    assert got.code == ref.code == 0, got.err
    for key in ("position_accuracy", "orientation_accuracy"):
        assert got.json()[key] == ref.json()[key]
    assert "physically impossible" in got.err and "left out as invalid" in got.err


@pytest.mark.parametrize("kind", ["huge", "spike"])
def test_fbm1_leaves_an_impossible_board_pose_out(
    kind: str, bags: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    tail = ["--items", str(FBM1H_ITEMS), "--format", "json"]
    got = strict(["score", "fbm1h", str(bags[f"fbm1h-{kind}"]), *tail], capsys)
    ref = strict(["score", "fbm1h", str(bags["fbm1h-dropped"]), *tail], capsys)
    assert got.code == ref.code == 0, got.err
    assert got.json()["pose_score"] == ref.json()["pose_score"]
    assert ("1 far" if kind == "huge" else "1 jump") in got.err


def test_trajectory_leaves_an_impossible_gt_pose_out(
    bags: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    for kind in ("huge", "spike"):
        gt = [str(bags[f"gt-{kind}"]), *map(str, GT[1:])]
        base = [str(bags["gt-dropped"]), *map(str, GT[1:])]
        got = strict(["score", "trajectory", str(ROBOT), *gt, "--format", "json"], capsys)
        ref = strict(["score", "trajectory", str(ROBOT), *base, "--format", "json"], capsys)
        assert got.code == ref.code == 0, got.err
        assert got.json()["position_error"] == ref.json()["position_error"]
        assert "GT sample(s) with NaN, zero-norm or impossible poses ignored" in got.err


def test_trajectory_keeps_a_robot_estimate_that_jumps(
    bags: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    """A robot's own estimate may jump 1 m (it relocalised): that is its error, scored; only a
    position kilometres away is no estimate."""
    tail = [*map(str, GT), "--format", "json"]
    spike = strict(["score", "trajectory", str(bags["robot-spike"]), *tail], capsys)
    huge = strict(["score", "trajectory", str(bags["robot-huge"]), *tail], capsys)
    ref = strict(["score", "trajectory", str(bags["robot-dropped"]), *tail], capsys)
    assert spike.code == huge.code == ref.code == 0, huge.err
    assert huge.json()["position_error"] == ref.json()["position_error"]
    assert spike.json()["position_error"] > ref.json()["position_error"]
    assert "1 robot pose(s) with NaN, zero-norm or impossible poses ignored" in huge.err


@pytest.mark.parametrize("kind", ["huge", "spike"])
def test_noise_leaves_an_impossible_pose_out(
    kind: str, bags: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    """Before: 1e300 m overflowed (RuntimeWarning) into the noise statistics."""
    tail = ["--topic", FBM3W_TOPIC, "--format", "json"]
    got = strict(["noise", str(bags[f"fbm3w-{kind}"]), *tail], capsys)
    ref = strict(["noise", str(bags["fbm3w-dropped"]), *tail], capsys)
    assert got.code == ref.code == 0, got.err
    assert got.json()["epsilon"] == ref.json()["epsilon"]
    assert "left out as invalid" in got.err


# --- finding 4: angles in degrees where radians are meant -----------------------------------


@pytest.mark.parametrize(
    ("old", "new", "key"),
    [
        ("[0.8, 2.6, 3.141592653589793]", "[0.8, 2.6, 180]", "goal.waypoints[2] theta"),
        ("[-0.6, -0.8, -0.4]", "[-0.6, -0.8, -22.9]", "goal.waypoints[4] theta"),
        ("    [0.0, 0.0, 0.0]", "    [0.0, 0.0, 90]", "goal.starting_pose theta"),
    ],
)
def test_a_goal_theta_in_degrees_is_refused(
    old: str, new: str, key: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Before: theta 180 scored an orientation error of 1.744 rad instead of 0.070, exit 0."""
    goal = tmp_path / "goal.yaml"
    text = FBM2H_GOAL.read_text()
    assert old in text
    goal.write_text(text.replace(old, new, 1))
    got = strict(["score", "fbm2h", str(FBM2H), "--goal", str(goal)], capsys)
    assert got.code == 1
    lines = error_messages(got.err)
    assert len(lines) == 1 and str(goal) in lines[0] and key in lines[0], got.err
    assert "angles are in radians here" in lines[0]


def test_a_goal_theta_of_two_pi_is_read(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A full turn written out is an angle still; only beyond it is a number in degrees."""
    goal = tmp_path / "goal.yaml"
    goal.write_text(FBM2H_GOAL.read_text().replace("3.141592653589793]", "6.283185]", 1))
    got = strict(["score", "fbm2h", str(FBM2H), "--goal", str(goal), "--format", "json"], capsys)
    assert got.code == 0, got.err


def test_a_transform_spread_in_degrees_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    transform = tmp_path / "transform-simbot.yaml"
    transform.write_text(
        FBM2H_TRANSFORM.read_text() + "acquisition_spread:\n  position_std: [0.001, 0.001, 0.001]\n"
        "  rotation_std: [0.5, 0.5, 12.0]\n  samples: 600\n"
    )
    got = strict(["score", "fbm2h", str(FBM2H), "--transform", str(transform)], capsys)
    assert got.code == 1
    line = error_messages(got.err)[0]
    assert (
        str(transform) in line and "acquisition_spread.rotation_std z: 12 is more than pi" in line
    )


# --- finding 6: a score of too few samples ----------------------------------------------------


@pytest.fixture(scope="module")
def short_robot_logs(tmp_path_factory: pytest.TempPathFactory) -> dict[int, Path]:
    """The robot log cut to its poses 100 to 100 + n (10 Hz, all inside the GT)."""
    root = tmp_path_factory.mktemp("short_robot")
    return {
        n: edited_copy(
            ROBOT,
            root / f"robot{n}.bag",
            ROBOT_TOPIC,
            lambda k, p, n=n: p if 100 <= k < 100 + n else None,
        )
        for n in (1, 19, 20)
    }


def test_a_trajectory_of_one_pose_has_no_interval(
    short_robot_logs: dict[int, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    """Before: exit 0 with a tight interval of the mocap noise alone ([132.7, 133.5] mm),
    valid_fraction 1.0 and no warning."""
    got = strict(
        ["score", "trajectory", str(short_robot_logs[1]), *map(str, GT), "--format", "json"], capsys
    )
    assert got.code == 0, got.err
    score = got.json()
    assert score["compared"] == 1
    assert score["position_error_interval"] is None and score["rmse_interval"] is None
    assert score["percentiles"]["p90_interval"] is None
    reason = score["uncertainty"]["withheld"]["position_error"]
    assert reason.startswith("only 1 compared pose(s): an interval needs at least 20")
    assert "the comparison rests on 1 compared pose(s) only (fewer than 30)" in got.err
    assert "no 95% interval (only 1 compared pose(s)" in got.err


def test_twenty_compared_poses_have_an_interval(
    short_robot_logs: dict[int, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    """The clock audit estimates the offset from 20 poses (clocks.MIN_POSES): from there on
    the interval holds the time association too; one pose fewer, none."""
    tail = [*map(str, GT), "--format", "json"]
    few = strict(["score", "trajectory", str(short_robot_logs[19]), *tail], capsys).json()
    enough = strict(["score", "trajectory", str(short_robot_logs[20]), *tail], capsys).json()
    assert few["compared"] == 19 and few["position_error_interval"] is None
    assert enough["compared"] == 20 and enough["position_error_interval"] is not None
    assert "time_association" in enough["uncertainty"]["shares"]["position_error"]
    assert "withheld" not in enough["uncertainty"]


def test_fbm3w_runs_of_few_kept_points_have_no_interval(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """d_min 5 cm keeps 4 to 6 points of each 16-32 cm path: no interval, said per run, and
    none for the best score (run 2's)."""
    got = strict(["score", "fbm3w", str(FBM3W), "--d-min", "0.05", "--format", "json"], capsys)
    assert got.code == 0, got.err
    score = got.json()
    assert score["best_distance_error_interval"] is None
    withheld = score["uncertainty"]["withheld"]
    for k in ("0", "1", "2", "3"):
        run = score["runs_details"][k]
        assert run["kept_samples"] < 10 and run.get("distance_error_interval") is None
        assert withheld[f"runs_details.{k}.distance_error"].startswith(
            f"only {run['kept_samples']} kept path point(s)"
        )
        assert f"run {k} rests on {run['kept_samples']} kept path point(s) only" in got.err
    assert withheld["best_distance_error"] == withheld["runs_details.2.distance_error"]
    # the sample's own d_min keeps 249-427 points: every run has its interval
    plain = strict(["score", "fbm3w", str(FBM3W), "--format", "json"], capsys).json()
    assert plain["best_distance_error_interval"] is not None
    assert "withheld" not in plain["uncertainty"]
