"""Scoring reports its reads in bytes, then its runs one by one (sample bags, whose answers
files say how many runs the generator wrote)."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from ertools.benchmarks import registry
from ertools.benchmarks.scoring import score_execution
from ertools.progress import reporting

pytestmark = pytest.mark.slow

S = Path(__file__).resolve().parents[2] / "sample_bags"


class Recorder:
    def __init__(self) -> None:
        self.tasks: list[tuple[str, int, str, list[int]]] = []

    def task(self, label: str, total: int, unit: str) -> None:
        self.tasks.append((label, total, unit, []))

    def advance(self, n: int) -> None:
        self.tasks[-1][3].append(n)


def _check(rec: Recorder, bag: Path, runs: int, pose_topic: str) -> None:
    *reads, scoring = rec.tasks
    assert scoring == ("scoring runs", runs, "runs", [1] * runs)
    assert reads and all(unit == "B" for _l, _t, unit, _s in reads)
    for _label, total, _unit, steps in reads:
        assert 0 < total <= bag.stat().st_size  # chunks of this one file
        assert sum(steps) == total and all(n > 0 for n in steps)
    assert f"reading {pose_topic} from {bag.name}" in [label for label, *_ in reads]


def test_fbm3w_reports_reads_then_runs() -> None:
    bag = S / "fbm3w/log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
    answers = yaml.safe_load(bag.with_name(bag.stem + ".answers.yaml").read_text())
    rec = Recorder()
    with reporting(rec):
        result = score_execution(registry.get("fbm3w"), [bag], {}).result
    assert len(answers["truth"]["runs"]) == 5  # the generator's runs_specifications
    assert len(result.runs) == 5
    _check(rec, bag, 5, "/fbm3w/robot_at_work/pose2d")  # the default pose source


def test_fbm1_reports_reads_then_runs() -> None:
    bag = S / "fbm1h/log_fbm1h_2015-11-20-12-00-00_0.bag"
    answers = yaml.safe_load(bag.with_name(bag.stem + ".answers.yaml").read_text())
    runs = answers["generator"]["parameters"]["runs"]
    assert runs == 10
    rec = Recorder()
    with reporting(rec):
        score_execution(registry.get("fbm1h"), [bag], {"items": S / "fbm1h/fbm1h.yaml"})
    _check(rec, bag, runs, "/fbm1h/origin/pose")


def test_no_reporter_nothing_reported() -> None:
    # the same call outside any reporting scope: the library stays silent (and still works)
    bag = S / "fbm3w/log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
    assert len(score_execution(registry.get("fbm3w"), [bag], {}).result.runs) == 5
