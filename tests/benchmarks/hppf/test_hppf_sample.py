"""The HPPF sample run (``sample_bags/hppf``) scores as its answers (computed by the simulator
from the noiseless truth), and ``--rules 2019`` on it equals the replayed script."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

import pytest
import yaml
from mcap.reader import make_reader

from ertools.cli.main import main
from ertools.simulator.answers import read_answers
from tests.helpers.inprocess import run
from tests.helpers.rsbb_fields import same
from tests.helpers.rsbb_replay import hppf as replay_hppf
from tests.helpers.rsbb_replay.fromlog import timeline_from_bag
from tests.helpers.rsbb_replay.world import World, run_script

SAMPLE = Path(__file__).parents[3] / "sample_bags" / "hppf"
BAG = next(SAMPLE.glob("rsbb_logs/HPPF/*/run_*.bag"))
ANSWERS = read_answers(BAG)  # hppf.answers.yaml beside the layout folder


def _json(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[dict[str, Any], str]:
    code = main(["score", "hppf", str(BAG), "--format", "json", "--draws", "0", *argv])
    out = capsys.readouterr()
    assert code == 0, out.err
    return json.loads(out.out), out.err


@pytest.mark.parametrize("rules", ["ertools", "2019"])
def test_the_sample_scores_as_its_answers(capsys: pytest.CaptureFixture[str], rules: str) -> None:
    score, err = _json(capsys, "--rules", rules)
    expected = ANSWERS["expected"]["ertools" if rules == "ertools" else "rules_2019"]
    tol = ANSWERS["tolerance"]["position"]["abs"]
    assert score["Distance error"] == pytest.approx(expected["Distance error"], abs=tol)
    assert score["Recognized persons"] == expected["Recognized persons"]
    assert score["% Recognized persons"] == expected["% Recognized persons"]
    assert score["execution_time"] == pytest.approx(expected["execution_time"], abs=1e-9)
    for row in ANSWERS["truth"]["passes"]:
        if "position_error" not in row:
            continue
        g = score[f"goal_{row['goal']}"]
        assert g["position_error"] == pytest.approx(row["position_error"], abs=tol)
        key = "recognized" if rules == "ertools" else "recognized_2019"
        assert g["recognized"] is row[key]
    assert "HPPF.yaml found in the RSBB layout" in err


def test_the_sample_is_the_replayed_script(capsys: pytest.CaptureFixture[str]) -> None:
    score, err = _json(capsys, "--rules", "2019")
    # the run's live score and result file are the script's on the logged mocap (the sample
    # computes them as the RSBB did): the recomputation agrees with both
    assert "live score (/rsbb/current_benchmark_result): all " in err
    assert err.count(" fields the same (numbers to 1e-06)") == 2
    params = yaml.safe_load(next(SAMPLE.rglob("HPPF.yaml")).read_text())
    oracle = run_script(World(timeline_from_bag(BAG, params, {})), replay_hppf.execute)
    same(score, json.loads(json.dumps(oracle.score)))
    # the restart, the dropout, the timeout and the stop are all there
    happens = [row["happens"] for row in ANSWERS["truth"]["passes"]]
    assert {"restart", "dropout", "timeout", "stop"} <= set(happens)


def _channels(path: Path) -> dict[str, int]:
    with path.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None and summary.statistics is not None
    counts = summary.statistics.channel_message_counts
    return {c.topic: counts[i] for i, c in summary.channels.items()}


@pytest.mark.slow  # a report, figures and an MCAP file with 20 draws (~8 s)
def test_report_plot_and_foxglove(tmp_path: Path) -> None:
    report, png, mcap = tmp_path / "report", tmp_path / "hppf.png", tmp_path / "hppf.mcap"
    outputs = ["--report", str(report), "--plot", str(png), "--foxglove", str(mcap)]
    ran = run(["score", "hppf", str(BAG), "--draws", "20", *outputs])
    assert ran.code == 0, ran.stderr
    assert "interval: Distance error" in ran.stderr
    with (report / "goals.csv").open() as f:
        rows = list(csv.DictReader(f))
    # one row per pass of the script: goal 2 drawn twice (restarted), 3 timed out, 4 stopped
    assert [(r["goal"], r["status"]) for r in rows][2:] == [
        ("2", "restarted"),
        ("2", "detected"),
        ("3", "timeout"),
        ("4", "stopped"),
    ]
    score = yaml.safe_load((report / "score.yaml").read_text())
    assert float(rows[0]["position_error_m"]) == score["goal_0"]["position_error"]
    with (report / "comparison.csv").open() as f:
        compared = list(csv.DictReader(f))
    assert f"of {len(compared)} fields differ" in ran.stderr
    assert (report / "index.html").is_file()
    assert png.stat().st_size > 10_000
    # a goal message per pass, a scene per pass with a ground truth or an answer
    channels = _channels(mcap)
    shown = [r for r in rows if r["truth_x"] or r["answer_x"]]
    assert channels["/hppf/goals"] == len(rows) and channels["/hppf/people"] == len(shown) == 4
