"""The noise measure as a registered benchmark (issue 37): ``ertools score noise`` scores
what ``ertools noise`` measures, its report draws the histogram through the registry, and its
Foxglove content is the pairs' distances over time. Numbers from the stationary sample's
answers (the simulator's truth) and from the bag read here with rosbags."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from rosbags.highlevel import AnyReader

from ertools.benchmarks import registry
from ertools.benchmarks.base import Reported, Simulated
from ertools.benchmarks.noise.foxglove import content
from ertools.benchmarks.scoring import score_execution
from ertools.cli.main import main
from ertools.report.figures import figure_specs
from ertools.views.foxglove import Collected

ROOT = Path(__file__).resolve().parents[3]
BAG = ROOT / "sample_bags" / "stationary" / "log_fbm3w_noise_2015-11-20-09-00-00_0.bag"
ANSWERS = yaml.safe_load(BAG.with_suffix(".answers.yaml").read_text(encoding="utf-8"))


def _json(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    assert main(argv) == 0
    return capsys.readouterr().out


def test_score_noise_is_the_noise_command(capsys: pytest.CaptureFixture[str]) -> None:
    """Both commands print the same JSON, and it is the sample's known noise."""
    scored = _json(["score", "noise", str(BAG), "--format", "json"], capsys)
    assert scored == _json(["noise", str(BAG), "--format", "json"], capsys)
    got: dict[str, Any] = json.loads(scored)
    exp = ANSWERS["expected"]
    assert (got["samples"], got["lost"]) == (exp["samples"], exp["lost"])
    # the 2015 tool's (x, y) distance; same samples as the bag, only summation order differs
    assert got["epsilon"] == pytest.approx(exp["epsilon_xy"], abs=1e-12)
    assert got["suggested_d_min"] == pytest.approx(3 * exp["epsilon_xy"], abs=3e-12)


def test_the_options_are_the_declared_inputs(capsys: pytest.CaptureFixture[str]) -> None:
    """--bin and --c of `ertools score noise` are those of `ertools noise`."""
    argv = [str(BAG), "--format", "json", "--bin", "0.0001", "--c", "4"]
    scored = json.loads(_json(["score", "noise", *argv], capsys))
    assert scored == json.loads(_json(["noise", *argv], capsys))
    assert scored["suggested_d_min"] == pytest.approx(4 * ANSWERS["expected"]["epsilon_xy"])


def _pose2d(bag: Path) -> tuple[np.ndarray, np.ndarray]:
    """(header-less Pose2D: record times, x y) of the sample's pose2d topic."""
    with AnyReader([bag]) as reader:
        conns = [c for c in reader.connections if c.topic == "/fbm3w/robot_at_work/pose2d"]
        rows = []
        for c, t, raw in reader.messages(connections=conns):
            msg: Any = reader.deserialize(raw, c.msgtype)
            rows.append((t, msg.x, msg.y))
    t_ns = np.array([r[0] for r in rows], dtype=np.int64)
    return t_ns, np.array([r[1:] for r in rows], dtype=np.float64)


def test_report_and_foxglove_through_the_registry() -> None:
    bench = registry.get("noise")
    assert isinstance(bench, Reported) and isinstance(bench, Simulated)
    assert bench.sample_args(ROOT / "sample_bags") == [str(BAG)]
    result: Any = score_execution(bench, [BAG], {}).result
    assert [s.name for s in figure_specs(result)] == ["noise"]
    t_ns, xy = _pose2d(BAG)
    step = np.hypot(*np.diff(xy, axis=0).T)
    moved = step != 0.0
    assert int(moved.sum()) == ANSWERS["expected"]["moving_pairs"]
    out = Collected()
    limit = 1000
    content(out, result, limit=limit)
    pairs = [m for m in out.messages if m[1] == "/noise/distances"]
    k = -(-int(moved.sum()) // limit)  # every k-th pair: at most `limit` of them
    assert len(pairs) == len(range(0, int(moved.sum()), k))
    times = t_ns[1:][moved][::k]
    assert [int(t) for t, _, _ in pairs] == times.tolist()
    first = json.loads(pairs[1][2])
    assert first["pair"] == k
    assert first["distance"] == pytest.approx(float(step[moved][k]), abs=1e-15)
    logs = [m for m in out.messages if m[1] == "/ertools/log"]
    assert len(logs) == 1 and logs[0][0] == int(t_ns[1:][moved][-1])
