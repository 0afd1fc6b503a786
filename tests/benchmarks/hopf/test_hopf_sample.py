"""The HOPF sample run (``sample_bags/hopf``) scores as its answers (computed by the simulator
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
from tests.helpers.rsbb_replay import hopf as replay_hopf
from tests.helpers.rsbb_replay.fromlog import timeline_from_bag
from tests.helpers.rsbb_replay.world import World, run_script

SAMPLE = Path(__file__).parents[3] / "sample_bags" / "hopf"
BAG = next(SAMPLE.glob("rsbb_logs/HOPF/*/run_*.bag"))
ANSWERS = read_answers(BAG)  # hopf.answers.yaml beside the layout folder


def _json(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[dict[str, Any], str]:
    code = main(["score", "hopf", str(BAG), "--format", "json", "--draws", "0", *argv])
    out = capsys.readouterr()
    assert code == 0, out.err
    return json.loads(out.out), out.err


@pytest.mark.parametrize("rules", ["ertools", "2019"])
def test_the_sample_scores_as_its_answers(capsys: pytest.CaptureFixture[str], rules: str) -> None:
    score, err = _json(capsys, "--rules", rules)
    expected = ANSWERS["expected"]["ertools" if rules == "ertools" else "rules_2019"]
    pose = ANSWERS["tolerance"]["pose"]["abs"]
    assert score["pose_score"] == pytest.approx(expected["pose_score"], abs=pose)
    for key in ("class_accuracy", "instance_accuracy"):
        assert score[key] == pytest.approx(expected[key], abs=1e-12)
    assert score["execution_time"] == pytest.approx(expected["execution_time"], abs=1e-9)
    for goal in ANSWERS["truth"]["goals"]:
        g = score[f"goal_{goal['goal']}"]
        if "pose_score" not in goal:
            assert "partial_score" not in g
            continue
        assert g["item_acquired"]["pose"] == pytest.approx(goal["truth"], abs=pose)
        want = goal["pose_score"] if rules == "ertools" else goal["pose_score_2019"]
        assert g["partial_score"]["pose_score"] == pytest.approx(want, abs=pose)
    if rules == "ertools":  # only goal 7 (1.08 m off) is past the clip
        assert "the translation term of goal(s) 7 clipped at 1 m;" in err
    # the side files were found in the layout and said so
    assert "items_with_pose.yaml found in the RSBB layout" in err
    assert "result file found" in err


def test_the_sample_is_the_replayed_script(capsys: pytest.CaptureFixture[str]) -> None:
    score, err = _json(capsys, "--rules", "2019")
    # the run's live score and result file are the script's on the logged mocap (the sample
    # computes them as the RSBB did): the recomputation agrees with both
    assert "live score (/rsbb/current_benchmark_result): all " in err
    assert err.count(" fields the same (numbers to 1e-06)") == 2
    root = SAMPLE
    items = yaml.safe_load(next(root.rglob("items_with_pose.yaml")).read_text())["items"]
    params = yaml.safe_load(next(root.rglob("HOPF.yaml")).read_text())
    tl = timeline_from_bag(BAG, params, {"items": items})
    oracle = run_script(World(tl), replay_hopf.execute)
    same(score, json.loads(json.dumps(oracle.score)))


def test_the_sample_has_the_paths_the_docs_promise() -> None:
    happens = [g["happens"] for g in ANSWERS["truth"]["goals"]]
    assert happens[2] == "dropout" and happens[4] == "timeout" and happens[-1] == "stop"


def _channels(path: Path) -> dict[str, int]:
    with path.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None and summary.statistics is not None
    counts = summary.statistics.channel_message_counts
    return {c.topic: counts[i] for i, c in summary.channels.items()}


@pytest.mark.slow  # a report, figures and an MCAP file with 20 draws (~8 s)
def test_report_plot_and_foxglove(tmp_path: Path) -> None:
    report, png, mcap = tmp_path / "report", tmp_path / "hopf.png", tmp_path / "hopf.mcap"
    outputs = ["--report", str(report), "--plot", str(png), "--foxglove", str(mcap)]
    ran = run(["score", "hopf", str(BAG), "--draws", "20", *outputs])
    assert ran.code == 0, ran.stderr
    assert "interval: pose_score" in ran.stderr
    with (report / "goals.csv").open() as f:
        rows = list(csv.DictReader(f))
    # one row per goal, in order, with the sample's outcomes (goal 5 timed out, 10 stopped)
    assert [r["goal"] for r in rows] == [str(k) for k in range(1, 11)]
    assert rows[4]["status"] == "timeout" and rows[9]["status"] == "stopped"
    score = yaml.safe_load((report / "score.yaml").read_text())
    assert float(rows[0]["pose_score"]) == score["goal_1"]["partial_score"]["pose_score"]
    with (report / "comparison.csv").open() as f:
        compared = list(csv.DictReader(f))
    assert compared and set(compared[0]) == {
        "key",
        "recomputed",
        "live",
        "file",
        "live_agrees",
        "file_agrees",
    }
    assert f"of {len(compared)} fields differ" in ran.stderr
    assert (report / "index.html").is_file()
    assert png.stat().st_size > 10_000
    # the ten items' ground truths and the ten goals
    channels = _channels(mcap)
    assert channels["/hopf/items"] == 10 and channels["/hopf/goals"] == 10
