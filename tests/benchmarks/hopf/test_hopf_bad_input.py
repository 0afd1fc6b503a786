"""Bad HOPF inputs: one ``ertools: error:`` line naming what and where, exit 1 (2 for usage),
no traceback, no score on stdout."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
import yaml

from ertools.cli.main import main
from tests.benchmarks.hopf.hopf_runs import build, write
from tests.helpers.stderr_text import error_messages

pytestmark = pytest.mark.slow  # writes a run bag


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, Path]:
    return write(tmp_path_factory.mktemp("hopf_bad"), build(["right", "wrong"], seed=3))


def _cli(capsys: pytest.CaptureFixture[str], *argv: str | Path) -> tuple[int, str, str]:
    code = main(["score", "hopf", *map(str, argv)])
    out = capsys.readouterr()
    return code, out.out, out.err


def _one_error(err: str, *needles: str) -> None:
    lines = error_messages(err)
    assert len(lines) == 1, err
    assert "Traceback" not in err
    for needle in needles:
        assert needle in lines[0], lines[0]


def test_no_items_file(
    run: tuple[Path, Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = tmp_path / "run_1_2019-04-11-16-26-40.bag"
    shutil.copy(run[0], bag)  # alone: nothing beside it
    code, out, err = _cli(capsys, bag)
    assert (code, out) == (1, "")
    _one_error(err, "items_with_pose.yaml", "--items")


def test_items_that_lack_the_item_shown(
    run: tuple[Path, Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = yaml.safe_load(run[1].read_text())
    shown = int(data["items"][0]["id"])
    items = tmp_path / "items.yaml"
    named = [i for i in data["items"] if i["id"] != shown]
    items.write_text(yaml.safe_dump({"items": named}))
    code, out, err = _cli(capsys, run[0], "--items", items)
    if code == 0:  # the item removed was not drawn: remove every item but one
        items.write_text(yaml.safe_dump({"items": named[:1]}))
        code, out, err = _cli(capsys, run[0], "--items", items)
    assert (code, out) == (1, "")
    _one_error(err, "lacks", "--items")


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("items: [{id: 1}]", "missing class"),
        ("items: []", "non-empty list"),
        ("[1, 2", "malformed"),
        (
            "items: [{id: 1, class: a, instance: a1, description: d, trans: [0, 0], "
            "rot: [0, 0, 0, 1]}]",
            "3 finite numbers",
        ),
        (
            "items: [{id: 1, class: a, instance: a1, description: d, trans: [0, 0, 0], "
            "rot: [0, 0, 0, 0]}]",
            "zero quaternion",
        ),
    ],
)
def test_malformed_items(
    run: tuple[Path, Path, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    text: str,
    needle: str,
) -> None:
    items = tmp_path / "items.yaml"
    items.write_text(text)
    code, out, err = _cli(capsys, run[0], "--items", items)
    assert (code, out) == (1, "")
    _one_error(err, needle, "items.yaml")


def test_another_benchmarks_result_file(
    run: tuple[Path, Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    result = tmp_path / "result_run_1_x.yaml"
    result.write_text(
        yaml.safe_dump({"benchmark_info": {"benchmark_code": "HNF", "team": "t", "run": 1}})
    )
    code, out, err = _cli(capsys, run[0], "--items", run[1], "--result", result)
    assert (code, out) == (1, "")
    _one_error(err, "HNF", "not HOPF")


def test_not_an_rsbb_bag(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    sample = Path(__file__).parents[3] / "sample_bags" / "fbm2h"
    bag = next(sample.glob("*.bag"))
    items = tmp_path / "items.yaml"
    items.write_text(
        "items: [{id: 1, class: a, instance: a1, description: d, trans: [0, 0, 0], "
        "rot: [0, 0, 0, 1]}]"
    )
    code, out, err = _cli(capsys, bag, "--items", items)
    assert (code, out) == (1, "")
    _one_error(err, "not an RSBB run bag")


def test_another_benchmarks_run(
    run: tuple[Path, Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "rsbb_logs" / "HNF" / "teamA"
    folder.mkdir(parents=True)
    bag = folder / "run_1_2019-04-11-16-26-40.bag"
    shutil.copy(run[0], bag)
    code, out, err = _cli(capsys, bag, "--items", run[1])
    assert (code, out) == (1, "")
    _one_error(err, "HNF run", "ertools score hnf")


def test_options_that_exclude_each_other(
    run: tuple[Path, Path, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, err = _cli(capsys, run[0], "--rules", "2019", "--max-gap", "0.5")
    assert (code, out) == (2, "")
    _one_error(err, "--max-gap")
