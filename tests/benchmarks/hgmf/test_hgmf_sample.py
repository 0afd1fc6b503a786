"""``ertools score hgmf`` on the simulated sample run (sample_bags/hgmf/): its answers come
from the noiseless truth (ertools/benchmarks/hgmf/sample.py), the tolerances are theirs (2 mm
of mocap noise on a distance, exact times and grasps). Side files found in the RSBB layout; the live
score and the result file agree with --rules 2019; ertools' reading differs where the sample
planted it (a restarted goal, a 0.3 s tracking loss under a lookup)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from ertools.cli.main import main
from ertools.simulator.answers import read_answers

pytestmark = pytest.mark.slow  # scores the sample twice (~3 s)

SAMPLE = Path(__file__).resolve().parents[3] / "sample_bags" / "hgmf"


@pytest.fixture(scope="module")
def answers() -> dict[str, Any]:
    return read_answers(_bag())  # hgmf.answers.yaml beside the layout folder


def _bag() -> Path:
    (bag,) = sorted(SAMPLE.glob("rsbb_logs/HGMF/*/run_*.bag"))
    return bag


def _score(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[dict[str, Any], str]:
    code = main(["score", "hgmf", str(_bag()), "--format", "json", *argv])
    out = capsys.readouterr()
    assert code == 0, out.err
    data: dict[str, Any] = json.loads(out.out)
    return data, out.err


def _goals(score: dict[str, Any], answers: dict[str, Any]) -> None:
    tol = answers["tolerance"]
    last = {g["goal"]: g for g in answers["expected"]["goals"]}  # a restart is overwritten
    for k, e in last.items():
        got = score[f"goal_{k}"]
        assert got["segment_time [s]"] == pytest.approx(
            e["segment_time"], abs=tol["segment_time"]["abs"]
        )
        assert got["completed"] is e["completed"] and got["timeout"] is e["timeout"]
        if e["completed"]:
            assert got["Object grasped"] is e["grasped"]
    assert score["goal_3"] == {}  # the referee stopped the run while it was placed


def test_rules_2019(capsys: pytest.CaptureFixture[str], answers: dict[str, Any]) -> None:
    score, err = _score(capsys, "--rules", "2019")
    _goals(score, answers)
    exp, d_tol = answers["expected"], answers["tolerance"]["distance_error"]["abs"]
    # by hand from the answers: (0.03 + 0.05) / 3 completed goals, the restarted one too
    assert exp["rules_2019"]["Avg distance error"] == pytest.approx((0.03 + 0.05) / 3)
    assert score["Avg distance error"] == pytest.approx(
        exp["rules_2019"]["Avg distance error"], abs=d_tol
    )
    assert score["Objects grasped"] == exp["rules_2019"]["Objects grasped"] == "3 out of 4"
    assert score["execution_time"] == pytest.approx(exp["rules_2019"]["execution_time"])
    assert score["goal_2"]["Distance error"] == pytest.approx(0.05, abs=d_tol)
    assert "HGMF.yaml found in the RSBB layout" in err
    assert "live score (/rsbb/current_benchmark_result): all 24 fields the same" in err
    assert "all 24 fields the same (numbers to 1e-06)" in err.split("result file")[1]


def test_ertools_reading(capsys: pytest.CaptureFixture[str], answers: dict[str, Any]) -> None:
    score, err = _score(capsys)
    _goals(score, answers)
    exp, d_tol = answers["expected"], answers["tolerance"]["distance_error"]["abs"]
    assert score["Avg distance error"] == pytest.approx(
        exp["ertools"]["Avg distance error"], abs=d_tol
    )
    assert score["Objects grasped"] == exp["ertools"]["Objects grasped"] == "1 out of 4"
    assert score["goal_2"]["Distance error"] is None  # 0.3 s between samples > 0.1 s
    for key in ("hgmf.restarted-goals", "hgmf.grasp-sampling", "hgmf.gt-gaps"):
        assert f"restores 2019 [{key}]" in err
    assert "differs from 2019:" in err
    assert "3 of 24 fields differ" in err  # the two totals and goal_2's distance


@pytest.mark.parametrize(
    ("option", "grasped", "average"),
    [
        # the restarted goal_2 counts in the divisor and the grasps: 0.03 / 2
        (["--restarted-goals", "2019"], "2 out of 4", 0.03 / 2),
        # the timer sees the same 10 cm lifts: the same counts as ertools' reading
        (["--grasp-sampling", "timer"], "1 out of 4", 0.03),
        # goal_2's position across its 0.3 s gap is measured: (0.03 + 0.05) / 2
        (["--gt-gaps", "interpolate"], "2 out of 4", (0.03 + 0.05) / 2),
    ],
    ids=["restarted-goals", "grasp-sampling", "gt-gaps"],
)
def test_each_option_restores_one_behaviour(
    capsys: pytest.CaptureFixture[str],
    answers: dict[str, Any],
    option: list[str],
    grasped: str,
    average: float,
) -> None:
    score, err = _score(capsys, *option)
    d_tol = answers["tolerance"]["distance_error"]["abs"]
    assert score["Objects grasped"] == grasped
    assert score["Avg distance error"] == pytest.approx(average, abs=d_tol)
    key = {"--restarted-goals": "restarted-goals", "--grasp-sampling": "grasp-sampling"}
    restored = key.get(option[0], "gt-gaps")
    assert f"[hgmf.{restored}]" not in err  # that rule at the script's, the others not
    assert err.count("differs from 2019:") == 2
