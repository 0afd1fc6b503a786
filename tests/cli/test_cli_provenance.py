"""Reports record the command as run, not the host process's argv."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ertools.cli.main import main

pytestmark = pytest.mark.slow

SAMPLE = Path(__file__).resolve().parents[2] / "sample_bags" / "fbm3w"


def test_report_records_the_command_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = next(SAMPLE.glob("*.bag"))
    out = tmp_path / "rep"
    assert main(["score", "fbm3w", str(bag), "--report", str(out)]) == 0
    text = (out / "index.html").read_text(encoding="utf-8")
    assert f"ertools score fbm3w {bag}" in text
    recorded = json.loads((out / "result.json").read_text(encoding="utf-8"))
    # exactly what was run, not the test runner's own argv
    assert recorded["argv"] == ["ertools", "score", "fbm3w", str(bag), "--report", str(out)]
