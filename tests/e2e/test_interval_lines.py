"""Every ``score`` command prints its intervals on stderr in one shape (issue 28): per score
``interval: NAME VALUE [LOW, HIGH] at C% (Monte Carlo, N draws, seed S; SOURCE P%, ...)``,
then ``interval sources: ...``; each line within the CLI's 200 characters, and the numbers on
it those of the JSON printed beside it."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest

from ertools.cli.main import main
from tests.helpers.stderr_text import joined_lines

SAMPLES = Path(__file__).resolve().parents[2] / "sample_bags"
FBM2 = SAMPLES / "fbm2h"
CASES = {
    "fbm1h": (
        [
            str(SAMPLES / "fbm1h" / "log_fbm1h_2015-11-20-12-00-00_0.bag"),
            *("--items", str(SAMPLES / "fbm1h" / "fbm1h.yaml")),
        ],
        "pose_score",
        1.0,
    ),
    "fbm2h": (
        [
            str(FBM2 / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"),
            *("--goal", str(FBM2 / "fbm2h_goal.yaml")),
            *("--transform", str(FBM2 / "transform-simbot.yaml")),
        ],
        "position_accuracy",
        1000.0,
    ),
    "fbm3w": (
        [str(SAMPLES / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag")],
        "best_distance_error",
        1000.0,
    ),
    "trajectory": (
        [str(SAMPLES / "robotlog" / "FBM2H_201511201200_homer.bag"), str(SAMPLES / "robotlog")],
        "position_error",
        1000.0,
    ),
}
NUM = r"-?[0-9.]+(?:e[+-][0-9]+)?"
LINE = re.compile(
    rf"^ertools: interval: (?P<name>[a-z_ 0-9]+?) (?P<value>{NUM})(?: \w+)? "
    rf"\[(?P<low>{NUM}), (?P<high>{NUM})\](?: \w+)? at 95% "
    r"\(Monte Carlo, 50 draws, seed 3; (?P<shares>[a-z_]+ \d+%(?:, [a-z_]+ \d+%)*)\)$"
)


def _close(text: str, value: float) -> bool:
    # 4 significant digits on the line
    return abs(float(text) - value) <= 5e-4 * max(abs(value), 1e-12) + 1e-12


@pytest.mark.parametrize("name", sorted(CASES))
def test_every_benchmark_prints_its_intervals_in_one_shape(
    name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    argv, key, scale = CASES[name]
    code = main(["score", name, *argv, "--format", "json", "--draws", "50", "--seed", "3"])
    out, err = capsys.readouterr()
    assert code == 0, err
    data: dict[str, Any] = json.loads(out)
    lines = [line for line in joined_lines(err) if line.startswith("ertools: interval")]
    assert all(len(line) <= 200 for line in lines)
    # (FBM1 adds a note why its counts have no interval)
    scores = [line for line in lines if line.startswith("ertools: interval: ") and "[" in line]
    parsed = [LINE.match(line) for line in scores]
    assert parsed and all(parsed), scores
    first = {m.group("name"): m for m in parsed if m is not None}[key]
    value = data[key]
    low, high = data[f"{key}_interval"]
    assert _close(first.group("value"), value * scale)
    assert _close(first.group("low"), low * scale) and _close(first.group("high"), high * scale)
    # the shares named are the block's, largest first
    shares = data["uncertainty"]["shares"]
    block = shares[key]
    named = [s.rsplit(" ", 1)[0] for s in first.group("shares").split(", ")]
    assert named == sorted(block, key=lambda n: -block[n])[: len(named)]
    (sources,) = [line for line in lines if line.startswith("ertools: interval sources: ")]
    for s in data["uncertainty"]["sources"]:
        assert f"{s['name']} " in sources
        assert f"({'measured' if s['measured'] else 'default'})" in sources
