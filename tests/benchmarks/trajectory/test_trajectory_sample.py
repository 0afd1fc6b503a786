"""`score trajectory` on the generated robot log vs the generator's independent answers."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import ertools.benchmarks.trajectory.logs as tr
from ertools.benchmarks.trajectory.sample import GT_TOPIC, ROBOT_TOPIC, expected_scores, truth_at
from ertools.cli.main import main
from ertools.io.reader import read_poses
from tests.benchmarks.trajectory.trajectory_helpers import (
    read_back,
    score_trajectory,
    write_gt,
    yaw,
)
from tests.helpers.stderr_text import error_messages

KEYS = ("compared", "gaps", "tracking_lost", "uncovered")
ERRORS = ("position_error", "orientation_error", "rmse", "median", "max")


def check(result: dict[str, Any], expected: dict[str, Any], answers: dict[str, Any]) -> None:
    for k in KEYS:
        assert result[k] == expected[k], k  # counts are exact
    tol = answers["tolerance"]["errors"]["abs"]  # 1e-9: same arrays, summation order differs
    for k in ERRORS:
        assert result[k] == pytest.approx(expected[k], abs=tol), k


@pytest.mark.parametrize("association", ["hold", "nearest", "linear"])
def test_each_association_without_offset(robotlog: dict[str, Any], association: str) -> None:
    r = score_trajectory(robotlog["robot"], [robotlog["dir"]], association=association)
    answers = robotlog["answers"]
    check(r.to_dict(), answers["expected"]["offset_0"][association], answers)
    assert r.to_dict()["gt_files"] == [str(p) for p in robotlog["gt"]]


@pytest.mark.parametrize("association", ["hold", "nearest", "linear"])
def test_each_association_with_the_true_offset(robotlog: dict[str, Any], association: str) -> None:
    answers = robotlog["answers"]
    offset = repr(answers["truth"]["offset_s"])  # --offset S: seconds, read back exactly
    r = score_trajectory(robotlog["robot"], robotlog["gt"], association=association, offset=offset)
    check(r.to_dict(), answers["expected"]["offset_true"][association], answers)
    assert r.to_dict()["offset"] == pytest.approx(answers["truth"]["offset_s"], abs=1e-9)


def test_clock_audit_recovers_the_generator_offset(robotlog: dict[str, Any]) -> None:
    answers = robotlog["answers"]
    r = score_trajectory(robotlog["robot"], robotlog["gt"])
    audit = r.to_dict()["clock_audit"]
    truth = answers["truth"]["offset_s"]
    # Tolerance from the answers file (10 ms, justified there).
    assert audit["estimated_offset"] == pytest.approx(
        truth, abs=answers["tolerance"]["offset_s"]["abs"]
    )
    assert 0 < audit["uncertainty"] < 0.05
    assert audit["applied"] is False and r.to_dict()["offset"] == 0.0
    # Not applied: the audit says so, loudly.
    assert any("clock audit" in w and "--apply-offset" in w for w in r.warnings)


def test_apply_offset_scores_with_the_estimate(robotlog: dict[str, Any]) -> None:
    answers = robotlog["answers"]
    d = score_trajectory(robotlog["robot"], robotlog["gt"], offset="auto", apply_offset=True)
    d = d.to_dict()
    assert d["offset"] == d["clock_audit"]["estimated_offset"]
    assert d["clock_audit"]["applied"] is True
    # Within 10 ms of the true offset the score is within a few mm of the true-offset score:
    # at <= 0.5 m/s a 10 ms shift moves the GT by <= 5 mm.
    true_score = answers["expected"]["offset_true"]["linear"]["position_error"]
    assert d["position_error"] == pytest.approx(true_score, abs=0.005)


def test_cli_json_has_the_documented_keys(
    robot_cli: list[str], robotlog: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> None:
    assert main([*robot_cli, "--association", "hold", "--format", "json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in (*ERRORS[:2], "rmse", "median", "max", "compared", "gaps", "tracking_lost"):
        assert key in out
    for key in ("gt_files", "association", "offset"):
        assert key in out
    check(out, robotlog["answers"]["expected"]["offset_0"]["hold"], robotlog["answers"])
    assert out["association"] == "hold"


@pytest.mark.slow
def test_cli_yaml_and_plots(
    robot_cli: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main([*robot_cli, "--offset", "-0.35", "--plot", str(tmp_path / "figs")]) == 0
    cap = capsys.readouterr()
    data = yaml.safe_load(cap.out)
    assert data["offset"] == -0.35
    assert "differs from 2015: association linear" in cap.err
    assert sorted(p.name for p in (tmp_path / "figs").iterdir()) == [
        "trajectory_error.png",
        "trajectory_paths.png",
        "trajectory_yaw_error.png",
    ]


def test_apply_offset_needs_auto(robot_cli: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    assert main([*robot_cli, "--apply-offset"]) == 2
    assert "--apply-offset needs --offset auto" in capsys.readouterr().err


def _one_error_line(err: str) -> str:
    lines = error_messages(err)
    assert len(lines) == 1, err
    assert "Traceback" not in err
    return lines[0]


@pytest.mark.slow
def test_robot_log_not_covered_by_gt(
    robotlog: dict[str, Any], capsys: pytest.CaptureFixture[str]
) -> None:
    robot, gt0 = robotlog["robot"], robotlog["gt"][0]
    args = ["score", "trajectory", str(robot), str(gt0), "--offset", "-0.35"]
    assert main(args) == 1
    line = _one_error_line(capsys.readouterr().err)
    assert "lie outside the GT" in line and "--allow-partial" in line

    # --allow-partial scores the covered part; expected by a plain loop on arrays read back
    # with rosbags (not ertools.io).
    assert main([*args, "--allow-partial", "--format", "json"]) == 0
    out = json.loads(capsys.readouterr().out)
    rt, rxyz, rq = read_back(robot, ROBOT_TOPIC)
    gt_t, gt_xyz, gt_q = read_back(gt0, GT_TOPIC)
    offset = robotlog["answers"]["truth"]["offset_ns"]
    exp = expected_scores(
        rt, rxyz, [yaw(q) for q in rq], gt_t, gt_xyz, gt_q, "linear", offset, 100_000_000
    )
    assert out["uncovered"] == sum(1 for t in rt if t + offset > gt_t[-1]) > 0
    check(out, exp, robotlog["answers"])
    assert out["partial"] is True


@pytest.mark.slow
def test_overlapping_gt_files(
    robotlog: dict[str, Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A copy of file 1 and an extra logger bridging the split gap, both overlapping."""

    gt0, gt1 = robotlog["gt"]
    copy = tmp_path / "copy" / gt1.name
    copy.parent.mkdir()
    shutil.copyfile(gt1, copy)
    # A second logger recording the same marker set around the split gap, noiseless truth.
    t_end0 = read_back(gt0, GT_TOPIC)[0][-1]
    t_bridge = np.arange(t_end0 - 2_000_000_000, t_end0 + 3_000_000_000, 8_333_333)
    bridge = write_gt(tmp_path / "bridge.bag", t_bridge, truth_at(t_bridge)[0], GT_TOPIC)

    args = ["score", "trajectory", str(robotlog["robot"]), str(gt0), str(gt1), str(copy)]
    assert main([*args, str(bridge), "--offset", "-0.35", "--format", "json"]) == 0
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    assert "overlap in time" in cap.err

    # Expected: all GT samples merged by time (stable), exact duplicates of the copy once.
    rt, rxyz, rq = read_back(robotlog["robot"], ROBOT_TOPIC)
    merged: list[tuple[int, int, list[float], list[float]]] = []
    for i, f in enumerate((gt0, gt1, copy, bridge)):
        t, x, q = read_back(f, GT_TOPIC)
        merged += [(tt, i, xx, qq) for tt, xx, qq in zip(t, x, q, strict=True)]
    merged.sort(key=lambda r: r[0])
    dedup: list[tuple[int, int, list[float], list[float]]] = []
    for row in merged:
        if dedup and row[0] == dedup[-1][0] and row[2] == dedup[-1][2] and row[3] == dedup[-1][3]:
            continue
        dedup.append(row)
    exp = expected_scores(
        rt,
        rxyz,
        [yaw(q) for q in rq],
        [r[0] for r in dedup],
        [r[2] for r in dedup],
        [r[3] for r in dedup],
        "linear",
        robotlog["answers"]["truth"]["offset_ns"],
        100_000_000,
    )
    check(out, exp, robotlog["answers"])
    # The bridge fills the split gap: fewer gaps than with the two split files alone.
    assert out["gaps"] < robotlog["answers"]["expected"]["offset_true"]["linear"]["gaps"]
    assert len(out["gt_files"]) == 4


@pytest.mark.slow
def test_robot_record_time(
    robotlog: dict[str, Any], robot_cli: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    # The generator's robot recorder stores each pose 2 ms after its stamp (robotlog.py).
    assert (
        main([*robot_cli, "--robot-time", "record", "--offset", "-0.35", "--format", "json"]) == 0
    )
    out = json.loads(capsys.readouterr().out)
    rt, rxyz, rq = read_back(robotlog["robot"], ROBOT_TOPIC)
    gt_t: list[int] = []
    gt_x: list[list[float]] = []
    gt_q: list[list[float]] = []
    for f in robotlog["gt"]:
        t, x, q = read_back(f, GT_TOPIC)
        gt_t += t
        gt_x += x
        gt_q += q
    exp = expected_scores(
        [t + 2_000_000 for t in rt],
        rxyz,
        [yaw(q) for q in rq],
        gt_t,
        gt_x,
        gt_q,
        "linear",
        -350_000_000,
        100_000_000,
    )
    check(out, exp, robotlog["answers"])


@pytest.mark.slow
def test_gt_read_is_one_read_equal_to_the_whole_cut(
    robotlog: dict[str, Any],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    gt0, gt1 = robotlog["gt"]
    copy = tmp_path / gt1.name
    shutil.copyfile(gt1, copy)
    files = [str(gt0), str(gt1), str(copy)]
    whole = read_poses(files, GT_TOPIC)
    # A span inside the GT (both ends cut): read_gt must return exactly the poses of the
    # whole read whose stamps fall in [lo, hi], overlapping files merged alike.
    n = len(whole)
    lo, hi = int(whole.t_ns[n // 4]), int(whole.t_ns[3 * n // 4])
    keep = (whole.t_ns >= lo) & (whole.t_ns <= hi)
    calls: list[tuple[int | None, int | None]] = []

    def counting(*args: Any, **kwargs: Any) -> Any:
        calls.append((kwargs.get("start_ns"), kwargs.get("end_ns")))
        return read_poses(*args, **kwargs)

    monkeypatch.setattr(tr, "read_poses", counting)  # the reader read_gt calls
    cut = tr.read_gt(files, GT_TOPIC, lo, hi)
    # A span of hours (an hour-long robot log): still one read, not 10-minute windows that
    # each re-read a minute of chunks at both ends; it holds every pose.
    hour = 3600 * 1_000_000_000
    first, last = int(whole.t_ns[0]), int(whole.t_ns[-1])
    long = tr.read_gt(files, GT_TOPIC, first - hour, last + hour)
    monkeypatch.undo()
    assert calls == [(lo, hi), (first - hour, last + hour)]
    assert np.array_equal(long.t_ns, whole.t_ns) and np.array_equal(long.xyz, whole.xyz)
    assert 0 < len(cut) < n
    assert np.array_equal(cut.t_ns, whole.t_ns[keep])
    assert np.array_equal(cut.xyz, whole.xyz[keep])
    assert np.array_equal(cut.quat_xyzw, whole.quat_xyzw[keep])

    # Through the CLI: the reader's warnings (the files overlap) appear once each.
    capsys.readouterr()
    args = ["score", "trajectory", str(robotlog["robot"]), *files, "--offset", "-0.35"]
    assert main(args) == 0
    err = capsys.readouterr().err
    logged = [ln for ln in err.splitlines() if ln.startswith("ertools: warning:")]
    assert logged and len(logged) == len(set(logged))
