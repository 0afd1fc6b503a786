"""``ertools score hnf`` on the committed sample (``sample_bags/hnf``, the RSBB layout): the
side files found, the numbers against the answers (noiseless truth), the script's live score
reproduced by ``--rules 2019``. tests/samples/test_samples_scenarios.py regenerates the sample
and compares it with the committed files."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from ertools.simulator.answers import read_answers
from tests.helpers.inprocess import run

pytestmark = pytest.mark.slow  # four scores of two bags

ROOT = Path(__file__).resolve().parents[3] / "sample_bags" / "hnf"
RUNS = sorted((ROOT / "rsbb_logs" / "HNF" / "simbot").glob("run_*.bag"))


def _answers(bag: Path) -> dict[str, Any]:
    return read_answers(bag)  # hnf.answers.yaml beside the layout folder


def _score(bag: Path, *extra: str) -> tuple[dict[str, Any], str]:
    ran = run(["score", "hnf", str(bag), "--format", "json", "--draws", "0", *extra])
    assert ran.code == 0, ran.stderr
    return json.loads(ran.stdout), ran.stderr


def test_two_runs_in_the_sample() -> None:
    assert [p.name[:5] for p in RUNS] == ["run_1", "run_2"]


@pytest.mark.parametrize("index", [0, 1])
def test_default_reading_against_the_truth(index: int) -> None:
    bag = RUNS[index]
    answers = _answers(bag)
    d_tol = answers["tolerance"]["distance"]["abs"]
    a_tol = answers["tolerance"]["angle"]["abs"]
    score, err = _score(bag)
    assert "HNF.yaml found in the RSBB layout" in err and "transform-simbot.yaml found" in err
    assert "the result file found in the RSBB layout" in err
    for seg in answers["expected"]["segments"]:
        mine = score[f"segment_{seg['segment']}"]
        if "distance_error" in seg:
            assert mine["distance_error"] == pytest.approx(seg["distance_error"], abs=d_tol)
            assert mine["orientation_error"] == pytest.approx(seg["orientation_error"], abs=a_tol)
            assert [mine["robot_pose"][k] for k in ("x", "y")] == pytest.approx(
                seg["robot_pose"][:2], abs=d_tol
            )
        else:
            assert "distance_error" not in mine
    ertools = answers["expected"]["ertools"]
    assert score["position_accuracy[m]"] == pytest.approx(ertools["position_accuracy"], abs=d_tol)
    assert score["orientation_accuracy[rad]"] == pytest.approx(
        ertools["orientation_accuracy"], abs=a_tol
    )


def test_2019_reproduces_the_live_score() -> None:
    bag = RUNS[0]
    expected = _answers(bag)["expected"]["2019"]
    score, err = _score(bag, "--rules", "2019")
    assert score["position_accuracy[m]"] == pytest.approx(expected["position_accuracy"], abs=1e-3)
    assert score["orientation_accuracy[rad]"] == pytest.approx(
        expected["orientation_accuracy"], abs=2e-3
    )
    assert (score["reached_waypoints"], score["timed_out_waypoints"]) == (4, 1)
    assert score["segment_4"]["robot_pose"] == "null\n...\n"  # skipped after the dropout
    assert "live score (/rsbb/current_benchmark_result): all 52 fields the same" in err
    assert "all 52 fields the same" in err.split("result file")[1]


def test_2019_stopped_run_has_no_totals() -> None:
    score, err = _score(RUNS[1], "--rules", "2019")
    assert "position_accuracy[m]" not in score and score["segment_3"]["timeout"] is None
    assert "the referee stopped the run" in err


def test_report_plot_and_foxglove(tmp_path: Path) -> None:
    out = tmp_path / "out"
    ran = run(
        [
            "score",
            "hnf",
            str(RUNS[0]),
            "--draws",
            "20",
            "--report",
            str(out / "report"),
            "--plot",
            str(out / "hnf.png"),
            "--foxglove",
            str(out / "hnf.mcap"),
        ]
    )
    assert ran.code == 0, ran.stderr
    assert "interval: position_accuracy[m]" in ran.stderr
    report = out / "report"
    assert (report / "index.html").is_file() and (report / "segments.csv").is_file()
    assert "segment_1" in (report / "score.yaml").read_text()
    comparison = (report / "comparison.csv").read_text()
    assert comparison.startswith("key,recomputed,live,file,live_agrees,file_agrees")
    assert (out / "hnf.png").stat().st_size > 10_000
    assert (out / "hnf.mcap").stat().st_size > 1_000
