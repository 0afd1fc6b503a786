"""A new benchmark takes one package and one registry line (issue 16).

The toy benchmark of docs/writing-a-benchmark.md, ``tests/helpers/toybench/``, is registered
with one line (the registry's entries monkeypatched: ertools itself is not edited); with no
other change it gets ``ertools score toy``, ``ertools report`` and ``ertools audit``. Its
sample's answers are known by hand: 40 measured marker poses 0.1 m apart along x (mean x
1.95 m) and 2 without a position, which the toy's original node counted (live score 42).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ertools.benchmarks import registry
from ertools.cli.main import main
from tests.helpers.toybench import sample

TOY = registry.Entry("toy", "tests.helpers.toybench.declare", "Toy@Test: counts the marker poses")


@pytest.fixture
def toy(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The toy's registry line, and its sample log."""
    monkeypatch.setattr(registry, "ENTRIES", (*registry.ENTRIES, TOY))
    return sample.generate(tmp_path, seed=1)


def test_score_takes_the_declared_inputs(toy: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["score", "toy", str(toy), "--scale", "2.5", "--format", "json"]) == 0
    cap = capsys.readouterr()
    data = json.loads(cap.out)
    assert data["count"] == pytest.approx(2.5 * sample.MEASURED, abs=1e-12)
    assert data["mean_x"] == pytest.approx(sample.MEAN_X, abs=1e-12)  # 0.1 steps: float sums
    said = "2 pose(s) without a position not counted; --count-nan restores 2015 [toy.nan-poses]"
    assert cap.err == f"ertools: differs from 2015: {said}\n"
    assert main(["score", "toy", str(toy), "--count-nan", "--format", "json"]) == 0
    cap = capsys.readouterr()
    assert json.loads(cap.out)["count"] == sample.MEASURED + sample.UNMEASURED
    assert "differs from" not in cap.err
    assert main(["score", "toy", str(toy), "--scale", "0"]) == 2
    assert "--scale must be positive" in capsys.readouterr().err
    assert main(["score", "toy", str(toy), "--topic", "toy/marker"]) == 2
    assert capsys.readouterr().err.strip().endswith("a topic name starts with /")
    assert main(["score", "toy", "--help"]) == 0
    shown = capsys.readouterr().out
    assert "--scale" in shown and "--topic TOPIC" in shown and "--count-nan" in shown
    assert main(["score", "--help"]) == 0
    members = capsys.readouterr().out.split("members:")[1].split()
    assert members[-6:] == ["toy", "Toy@Test:", "counts", "the", "marker", "poses"]


@pytest.mark.slow
def test_report_folder_and_combined_page(
    toy: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "r"
    assert main(["score", "toy", str(toy), "--report", str(folder)]) == 0
    score = json.loads((folder / "score.json").read_text(encoding="utf-8"))
    assert score["count"] == pytest.approx(sample.MEASURED, abs=1e-12)
    meta = json.loads((folder / "result.json").read_text(encoding="utf-8"))
    assert meta["benchmark"] == "toy"
    assert [i["name"] for i in meta["inputs"]] == ["toy.bag"]
    combined = tmp_path / "all"
    assert main(["report", str(folder), "--out", str(combined)]) == 0
    page = (combined / "index.html").read_text(encoding="utf-8")
    assert "toy" in page and "toy.bag" in page


def test_audit_recomputes_and_compares(toy: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["audit", str(toy), "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["benchmark"] == "toy"
    # The live score counted the 42 messages; ertools' default counts the 40 measured.
    assert data["live_score"] == {"count": 42, "mean_x": sample.MEAN_X}
    assert data["recomputed"]["count"] == pytest.approx(sample.MEASURED, abs=1e-12)
    comparison = data["score_comparison"]
    assert (comparison["same"], comparison["differences"]) == (1, 1), comparison
    count, mean_x = comparison["lines"]
    assert (count["key"], count["live"], count["recomputed"]) == ("count", 42, 40)
    # The second rescore, with values_2015 (--count-nan), counts the 42 the live node did.
    assert count["explanation"].startswith("recomputed with the 2015 rules: 42, the live value")
    assert (mean_x["key"], mean_x["status"]) == ("mean_x", "same")
