"""Small faults (issue 36, finding 20): each one a wrong or misleading output, fixed where all
its variants pass (every output path, every result read, every name printed)."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

import pytest

from ertools.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "sample_bags"
FBM3W_BAG = SAMPLES / "fbm3w" / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"


def _strict_json(text: str) -> Any:
    def refuse(word: str) -> float:
        raise AssertionError(f"{word} is not JSON")

    return json.loads(text, parse_constant=refuse)


# --- report: a result holding Infinity ---------------------------------------------------------


def _result(folder: Path, team: str, best: str) -> Path:
    """A result.json as `score --report` writes it, the score spelled as given (JSON text)."""
    folder.mkdir(parents=True)
    score = f'"best_distance_error": {best}, "best_run": 0'
    (folder / "result.json").write_text(
        f'{{"benchmark": "fbm3w", "team": "{team}", "inputs": [], "headline": {{{score}}}, '
        f'"score": {{{score}, "best_distance_error_interval": [0.0004, 0.0006], '
        '"uncertainty": {"confidence": 0.95}}}'
    )
    return folder


@pytest.mark.parametrize("spelling", ["Infinity", "-Infinity", "NaN"])
def test_report_ranks_no_result_whose_score_is_not_a_number(
    spelling: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Python's json reads `Infinity`; ranked, -Infinity came first (lower is better) and
    Infinity second of two. Such a score is no score: listed unranked, with the reason."""
    folders = [
        _result(tmp_path / "a", "alpha", "0.0005"),
        _result(tmp_path / "b", "bravo", spelling),
        _result(tmp_path / "c", "charlie", "0.0009"),
    ]
    out = tmp_path / "site"
    assert main(["report", *map(str, folders), "--report", str(out)]) == 0
    rows = {r["team"]: r for r in _strict_json((out / "results.json").read_text())}
    assert rows["alpha"]["rank"] == 1 and rows["charlie"]["rank"] == 2
    assert rows["bravo"]["rank"] is None
    assert rows["bravo"]["best_distance_error"] is None
    assert "not a finite number" in rows["bravo"]["rank_note"]
    with (out / "results.csv").open() as f:
        table = {r["team"]: r for r in csv.DictReader(f)}
    assert table["bravo"]["rank"] == "" and table["bravo"]["best_distance_error"] == ""
