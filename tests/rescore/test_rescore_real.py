"""`ertools rescore` on the real 2015 FBM2@Home bag (../shared/real_bags): the row's score is
exactly `ertools score fbm2h ... --format json` for the same inputs, and the report folder is
the score command's."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import pytest

from ertools.cli.main import main

REAL = Path(__file__).resolve().parents[2] / ".." / "shared" / "real_bags"
BAG = REAL / "log_fbm2h_mocap_2015-10-23-16-15-40_0.bag"
GOAL = REAL / "fbm2h_test_optitrackless_goal.yaml"
TIMING = REAL / "log_fbm2h_mocap_2015-10-23-16-15-40_0_reached_waypoint_timing.yaml"
IDENTITY = Path(__file__).resolve().parents[2] / "configs" / "transform-identity.yaml"

pytestmark = [pytest.mark.real, pytest.mark.slow]


def test_real_bag_scores_as_the_score_command(tmp_path: Path) -> None:
    if not BAG.exists():
        pytest.skip("../shared/real_bags not present")
    manifest = tmp_path / "competition.yaml"
    manifest.write_text(
        "benchmarks:\n  fbm2h:\n    inputs:\n"
        f"      goal: {GOAL}\n      reached: [timing, {TIMING}]\n"
        f"    teams:\n      test: {{transform: {IDENTITY}}}\n"
        f"executions:\n  - {{benchmark: fbm2h, team: test, bags: [{BAG}]}}\n"
    )
    out = tmp_path / "out"
    with contextlib.redirect_stderr(io.StringIO()):
        assert main(["rescore", "--config", str(manifest), "--out", str(out), "-j", "1"]) == 0
    (row,) = json.loads((out / "results.json").read_text())["executions"]
    printed = io.StringIO()
    argv = ["score", "fbm2h", str(BAG), "--goal", str(GOAL), "--reached", "timing", str(TIMING)]
    argv += ["--transform", str(IDENTITY), "--team", "test", "--format", "json"]
    with contextlib.redirect_stdout(printed), contextlib.redirect_stderr(io.StringIO()):
        assert main(argv) == 0
    assert row["score"] == json.loads(printed.getvalue())
    assert row["live_score"] is None  # the bag holds no state topics
    report = out / row["report"]
    assert json.loads((report.parent / "score.json").read_text()) == row["score"]
