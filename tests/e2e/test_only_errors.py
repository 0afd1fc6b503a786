"""A command with no honest number prints nothing but its errors (issue 19).

When every run, segment or pose fails, stdout stays empty, stderr holds only ``ertools:
error:`` lines (one per failure, naming it), no output file or report is written, exit 1.
When some runs scored, the result is printed with the failed ones as null and their errors
on stderr (still exit 1).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from ertools.cli.main import main
from tests.helpers.stderr_text import joined_lines

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "sample_bags"
FBM3W = SAMPLES / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
FBM2H = SAMPLES / "fbm2h"
FBM1H = SAMPLES / "fbm1h"


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, list[str]]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, [x for x in joined_lines(err) if x.strip()]


def only_errors(out: str, err: list[str], *needles: str) -> None:
    assert out == ""
    assert len(err) == len(needles), err
    for line, needle in zip(err, needles, strict=True):
        assert line.startswith("ertools: error: ") and needle in line, line
        assert "Traceback" not in line


def test_fbm3w_window_without_data(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    # The sample's poses start 0.5 s after its first message: 0.2-0.4 s holds none.
    out_file, report = tmp_path / "score.yaml", tmp_path / "report"
    code, out, err = run(
        capsys, "score", "fbm3w", str(FBM3W), "--run", "line:0.1:0.2:0.4",
        "-o", str(out_file), "--report", str(report),
    )  # fmt: skip
    assert code == 1
    only_errors(out, err, "run 0 (line): 0 pose sample(s) in the path window 0.200-0.400 s")
    assert not out_file.exists() and not report.exists()


def test_fbm3w_partial_result_still_printed(capsys: pytest.CaptureFixture[str]) -> None:
    answers = yaml.safe_load(FBM3W.with_suffix(".answers.yaml").read_text(encoding="utf-8"))
    expected = answers["expected"]["runs_details"]["0"]["distance_error"]
    tol = answers["tolerance"]["distance_error"]["abs"]
    # an empty window, then the sample's first run (reference 1.9 s, path 3.1-7.1 s)
    code, out, err = run(
        capsys, "score", "fbm3w", str(FBM3W), "--run", "line:0.1:0.2:0.4",
        "--run", "line:1.9:3.1:7.1", "--format", "json",
    )  # fmt: skip
    assert code == 1
    runs = json.loads(out)["runs_details"]
    assert runs["0"]["distance_error"] is None and runs["0"]["status"] == "failed"
    assert runs["1"]["distance_error"] == pytest.approx(expected, abs=tol)
    errors = [x for x in err if x.startswith("ertools: error: ")]
    assert len(errors) == 1 and "run 0 (line)" in errors[0]


def test_fbm2h_every_segment_without_ground_truth(capsys: pytest.CaptureFixture[str]) -> None:
    # GT at 120 Hz is never within 1 us of a reached moment (state times on a 100 ms grid)
    code, out, err = run(
        capsys, "score", "fbm2h", str(FBM2H / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"),
        "--goal", str(FBM2H / "fbm2h_goal.yaml"),
        "--transform", str(FBM2H / "transform-simbot.yaml"), "--gt-tolerance", "0.000001",
    )  # fmt: skip
    assert code == 1
    lines = [f"segment {i}: no ground truth within --gt-tolerance" for i in range(5)]
    only_errors(out, err, *lines)
    # the nearest sample is under 1 ms away: said with 3 digits, never "0.000 s"
    assert all("0.000 s away" not in x for x in err)


def test_fbm1_every_run_failed(capsys: pytest.CaptureFixture[str]) -> None:
    names = [f"zz{i}" for i in range(1, 11)]  # ten runs, no such items in the list
    code, out, err = run(
        capsys, "score", "fbm1h", str(FBM1H / "log_fbm1h_2015-11-20-12-00-00_0.bag"),
        "--items", str(FBM1H / "fbm1h.yaml"), "--items-order", ",".join(names),
    )  # fmt: skip
    assert code == 1
    only_errors(out, err, *(f"run {i}: item '{n}'" for i, n in enumerate(names, 1)))


@pytest.mark.slow
def test_fbm1_one_run_failed_keeps_the_others(capsys: pytest.CaptureFixture[str]) -> None:
    answers = yaml.safe_load(
        (FBM1H / "log_fbm1h_2015-11-20-12-00-00_0.answers.yaml").read_text(encoding="utf-8")
    )
    # the item ids the sample presented, the first replaced by one not in the list
    order = [str(i) for i in answers["truth"]["order"]]
    assert len(order) == 10
    order[0] = "zz"
    code, out, err = run(
        capsys, "score", "fbm1h", str(FBM1H / "log_fbm1h_2015-11-20-12-00-00_0.bag"),
        "--items", str(FBM1H / "fbm1h.yaml"), "--items-order", ",".join(order),
        "--format", "json",
    )  # fmt: skip
    assert code == 1
    data = json.loads(out)
    assert data["runs"]["1"]["status"] == "failed"
    assert [r["status"] for k, r in data["runs"].items() if k != "1"].count("failed") == 0
    assert [x for x in err if x.startswith("ertools: error: ")] == [
        f"ertools: error: run 1: item 'zz' (--items-order) is not in {FBM1H / 'fbm1h.yaml'}"
    ]


def test_trajectory_nothing_compared(capsys: pytest.CaptureFixture[str]) -> None:
    # with --max-gap 1 us every robot pose falls in a "gap" between 120 Hz GT poses
    code, out, err = run(
        capsys, "score", "trajectory", str(SAMPLES / "robotlog" / "FBM2H_201511201200_homer.bag"),
        str(SAMPLES / "robotlog"), "--max-gap", "0.000001",
    )  # fmt: skip
    assert code == 1
    only_errors(out, err, "no robot pose could be compared (381 in GT gaps")
