"""Bad HPPF inputs: one ``ertools: error:`` line naming what and where, exit 1 (2 for usage)."""

from __future__ import annotations

import shutil
from dataclasses import replace
from pathlib import Path

import pytest
import yaml

from ertools.cli.main import main
from ertools.simulator.rsbb import write_rsbb_run
from tests.benchmarks.hppf.hppf_runs import build, write
from tests.helpers.stderr_text import error_messages

pytestmark = pytest.mark.slow  # writes a run bag


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    return write(tmp_path_factory.mktemp("hppf_bad"), build(["right", "wrong"], seed=4))


def _cli(capsys: pytest.CaptureFixture[str], *argv: str | Path) -> tuple[int, str, str]:
    code = main(["score", "hppf", *map(str, argv)])
    out = capsys.readouterr()
    return code, out.out, out.err


def _one_error(err: str, *needles: str) -> None:
    lines = error_messages(err)
    assert len(lines) == 1, err
    assert "Traceback" not in err
    for needle in needles:
        assert needle in lines[0], lines[0]


def test_a_config_without_the_person_shown(
    run: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    config = tmp_path / "HPPF.yaml"
    config.write_text(yaml.safe_dump({"people": ["Nobody"], "goal_timeout": 3.0}))
    code, out, err = _cli(capsys, run[0], "--config", config)
    assert (code, out) == (1, "")
    _one_error(err, "not among the config's people", "--config")


@pytest.mark.parametrize(
    ("text", "needle"), [("people: Joe", "a list of names"), ("[1, 2", "malformed")]
)
def test_malformed_config(
    run: tuple[Path, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    text: str,
    needle: str,
) -> None:
    config = tmp_path / "HPPF.yaml"
    config.write_text(text)
    code, out, err = _cli(capsys, run[0], "--config", config)
    assert (code, out) == (1, "")
    _one_error(err, needle)


def test_no_people_anywhere(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # no HPPF.yaml, no live score, no result file: nothing says who the people were
    run = build(["right"], seed=5)
    quiet = replace(run, scenario=replace(run.scenario, saves=()))
    paths = write_rsbb_run(tmp_path, quiet.scenario)
    paths.result.unlink()
    code, out, err = _cli(capsys, paths.bag)
    assert (code, out) == (1, "")
    _one_error(err, "HPPF.yaml", "--config")


def test_another_benchmarks_run(
    run: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "rsbb_logs" / "HOPF" / "teamA"
    folder.mkdir(parents=True)
    bag = folder / "run_1_2019-04-11-16-26-40.bag"
    shutil.copy(run[0], bag)
    code, out, err = _cli(capsys, bag, "--config", run[1])
    assert (code, out) == (1, "")
    _one_error(err, "HOPF run", "ertools score hopf")


def test_options_that_exclude_each_other(
    run: tuple[Path, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, err = _cli(capsys, run[0], "--rules", "2019", "--max-gap", "0.5")
    assert (code, out) == (2, "")
    _one_error(err, "--max-gap")
