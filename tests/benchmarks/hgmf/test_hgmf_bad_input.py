"""Bad input to ``ertools score hgmf``: one line on stderr naming what and where, no
traceback, exit 1 (2 for usage)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from ertools.cli.main import main
from tests.helpers.stderr_text import error_messages

pytestmark = pytest.mark.slow  # copies and reads the sample bag (~1 s each)

SAMPLE = Path(__file__).resolve().parents[3] / "sample_bags" / "hgmf"


def _bag() -> Path:
    (bag,) = sorted(SAMPLE.glob("rsbb_logs/HGMF/*/run_*.bag"))
    return bag


def _error(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
    code = main(["score", "hgmf", *argv])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    (line,) = error_messages(err)
    return code, line


def test_no_config_anywhere(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    alone = tmp_path / "run_1_2019-04-12-10-00-00.bag"
    shutil.copy(_bag(), alone)
    code, line = _error(capsys, str(alone))
    assert code == 1 and "give --config HGMF.yaml" in line  # a file missing: docs/cli.md


def test_another_benchmarks_run(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    other = tmp_path / "rsbb_logs" / "HNF" / "simbot" / _bag().name
    other.parent.mkdir(parents=True)
    shutil.copy(_bag(), other)
    code, line = _error(capsys, str(other))
    # one refusal for every RSBB benchmark (ertools.rsbb.opened): a config problem, exit 1
    assert code == 1 and "this bag is a HNF run" in line and "not HGMF's: ertools score hnf" in line


def test_a_config_without_objects(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    config = tmp_path / "HGMF.yaml"
    config.write_text("objects: []\ntable_size: {x: 1.0, y: 1.5}\n", encoding="utf-8")
    code, line = _error(capsys, str(_bag()), "--config", str(config))
    assert code == 1 and str(config) in line and "no objects list" in line


def test_two_bags_and_contradicting_rules(capsys: pytest.CaptureFixture[str]) -> None:
    code, line = _error(capsys, str(_bag()), str(_bag()))
    assert code == 2 and "give one HGMF run bag" in line
    code, line = _error(capsys, str(_bag()), "--rules", "2019", "--gt-gaps", "limit")
    assert code == 2 and "--rules 2019 sets --gt-gaps" in line


def test_not_a_run_bag(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    fbm2h = next((SAMPLE.parent / "fbm2h").glob("*.bag"))
    code, line = _error(capsys, str(fbm2h), "--config", str(next(SAMPLE.rglob("HGMF.yaml"))))
    assert code == 1 and "not an RSBB run bag" in line
