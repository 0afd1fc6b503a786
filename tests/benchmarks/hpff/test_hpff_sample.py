"""``ertools score hpff`` on the committed sample (``sample_bags/hpff``, the RSBB layout): the
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

ROOT = Path(__file__).resolve().parents[3] / "sample_bags" / "hpff"
RUNS = sorted((ROOT / "rsbb_logs" / "HPFF" / "simbot").glob("run_*.bag"))
DEVIATION = "Average deviation from desired distance"
COVERED = "Distance covered while following"


def _answers(bag: Path) -> dict[str, Any]:
    return read_answers(bag)  # hpff.answers.yaml beside the layout folder


def _score(bag: Path, *extra: str) -> tuple[dict[str, Any], str]:
    ran = run(["score", "hpff", str(bag), "--format", "json", "--draws", "0", *extra])
    assert ran.code == 0, ran.stderr
    return json.loads(ran.stdout), ran.stderr


@pytest.mark.parametrize(("rules", "key"), [("ertools", "ertools"), ("2019", "2019")])
def test_run_1_against_the_truth(rules: str, key: str) -> None:
    answers = _answers(RUNS[0])
    tol = answers["tolerance"]
    expected = answers["expected"][key]
    score, err = _score(RUNS[0], "--rules", rules)
    assert "HPFF.yaml found in the RSBB layout" in err and "transform-simbot.yaml found" in err
    assert score[DEVIATION] == pytest.approx(expected[DEVIATION], abs=tol["deviation"]["abs"])
    assert score[COVERED] == pytest.approx(expected[COVERED], abs=tol["covered"]["abs"])
    assert score["Benchmark reliability"] == expected["Benchmark reliability"]
    assert f"samples: {expected['samples']}, measured {expected['measured']}" in err
    assert f"duration {expected['duration']:.3f} s" in err
    if rules == "2019":
        assert "live score (/rsbb/current_benchmark_result): all 3 fields the same" in err


def test_run_2_stopped() -> None:
    score, _ = _score(RUNS[1], "--rules", "2019")
    assert score == {}
    answers = _answers(RUNS[1])["expected"]["ertools"]
    score, err = _score(RUNS[1])
    assert score["Result"].startswith("Benchmark failed")
    assert score[DEVIATION] == pytest.approx(answers[DEVIATION], abs=1e-3)
    assert "the run was stopped" in err


def test_report_plot_and_foxglove(tmp_path: Path) -> None:
    out = tmp_path / "out"
    ran = run(
        [
            "score",
            "hpff",
            str(RUNS[0]),
            "--draws",
            "20",
            "--report",
            str(out / "report"),
            "--plot",
            str(out / "hpff.png"),
            "--foxglove",
            str(out / "hpff.mcap"),
        ]
    )
    assert ran.code == 0, ran.stderr
    assert "interval: Average deviation from desired distance" in ran.stderr
    report = out / "report"
    assert (report / "index.html").is_file() and (report / "samples.csv").is_file()
    assert "Benchmark reliability" in (report / "score.yaml").read_text()
    assert (out / "hpff.png").stat().st_size > 10_000
    assert (out / "hpff.mcap").stat().st_size > 1_000
