"""Runs of one benchmark and team in two RSBB layouts with different side files: each run is
scored with its own layout's (the draft gives them per execution), never the first run's."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest
import yaml

from ertools.cli.main import main

pytestmark = pytest.mark.slow  # scores three folders

SAMPLES = Path(__file__).resolve().parents[2] / "sample_bags"
TRANSFORM = "rsbb_etc/transforms/transform-simbot.yaml"
# the second layout's marker set sits 0.3 m further along x: enough to move the score by cm
OTHER_TRANSFORM = """team_name: simbot
markerset_to_robot_transform: !!python/tuple
- [0.4, 0.05, -0.4]
- [0.0, 0.0, -0.14943813247359922, 0.9887710779360422]
"""


def _layout(folder: Path, run: int, transform: str | None) -> None:
    """``folder``: the sample HNF layout with only its run ``run`` (bag and result file)."""
    shutil.copytree(SAMPLES / "hnf", folder)  # its answers are beside it, not in it
    for path in [*folder.glob("rsbb_logs/HNF/simbot/*"), *folder.glob("results/HNF/simbot/*")]:
        if not path.name.startswith((f"run_{run}_", f"result_run_{run}_")):
            path.unlink()
    if transform is not None:
        (folder / TRANSFORM).write_text(transform, encoding="utf-8")


def _scores(out: Path, *paths: Path) -> dict[str, float]:
    """Each HNF run's position accuracy (by run bag name) from ``rescore PATHS --out OUT``."""
    code = main(["rescore", *map(str, paths), "--out", str(out), "--no-reports", "-j", "1"])
    assert code == 0
    doc: dict[str, Any] = json.loads((out / "results.json").read_text(encoding="utf-8"))
    return {
        Path(r["bags"][0]).name: r["score"]["position_accuracy[m]"]
        for r in doc["executions"]
        if r["benchmark"] == "hnf"
    }


def test_each_run_takes_its_own_layouts_transform(tmp_path: Path) -> None:
    one, two = tmp_path / "one", tmp_path / "two"
    _layout(one, 1, None)
    _layout(two, 2, OTHER_TRANSFORM)
    # the independent figures: each layout rescored alone has only its own transform
    alone = {**_scores(tmp_path / "out1", one), **_scores(tmp_path / "out2", two)}
    assert len(alone) == 2
    both = _scores(tmp_path / "out", one, two)
    # the same bags, inputs and code path: the same floats, to rounding only
    assert both == pytest.approx(alone, rel=1e-12, abs=0.0)
    # and the transform matters here (else the test could not fail): scored with the first
    # layout's transform, run 2 comes out elsewhere
    other = _scores(tmp_path / "out3", _moved(tmp_path, two, one))
    run_2 = next(n for n in alone if n.startswith("run_2_"))
    assert abs(other[run_2] - alone[run_2]) > 0.01
    manifest = yaml.safe_load((tmp_path / "out/manifest.yaml").read_text(encoding="utf-8"))
    given = {
        Path(e["bags"][0]).name: Path(e["inputs"]["transform"])
        for e in manifest["executions"]
        if e["benchmark"] == "hnf"
    }
    assert given == {n: (one if n.startswith("run_1_") else two) / TRANSFORM for n in alone}


def _moved(tmp_path: Path, layout: Path, transform_of: Path) -> Path:
    """A copy of ``layout`` holding ``transform_of``'s transform."""
    copy = tmp_path / "moved"
    shutil.copytree(layout, copy)
    shutil.copyfile(transform_of / TRANSFORM, copy / TRANSFORM)
    return copy


def test_a_run_whose_layout_has_none_of_several_is_not_scored(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    one, two, three = tmp_path / "one", tmp_path / "two", tmp_path / "three"
    _layout(one, 1, None)
    _layout(two, 2, None)
    (two / TRANSFORM).unlink()  # run 2's layout without its transform
    (three / TRANSFORM).parent.mkdir(parents=True)  # another folder with one
    (three / TRANSFORM).write_text(OTHER_TRANSFORM, encoding="utf-8")
    bag = next((two / "rsbb_logs/HNF/simbot").glob("run_2_*.bag"))
    out = tmp_path / "out"
    paths = [str(one), str(two), str(three)]
    code = main(["rescore", *paths, "--out", str(out), "--no-reports", "-j", "1"])
    assert code == 1
    lines = capsys.readouterr().err.splitlines()
    said = [line for line in lines if "ambiguous" in line or "no transform in its" in line]
    assert said == [
        f"ertools: warning: {bag}: HNF run 2 of team simbot: no transform in its RSBB layout "
        f"and 2 elsewhere ({one / TRANSFORM}, {three / TRANSFORM}): name the run's in the "
        "manifest (executions[].inputs.transform)"
    ]
    doc: dict[str, Any] = json.loads((out / "results.json").read_text(encoding="utf-8"))
    status = {r["bags"][0]: r["status"] for r in doc["executions"] if r["benchmark"] == "hnf"}
    assert status.pop(str(bag)) == "unscoreable"
    assert list(status.values()) == ["scored"]
