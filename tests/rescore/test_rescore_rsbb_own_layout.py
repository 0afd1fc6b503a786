"""A run in the RSBB layout takes its side files from its own layout (never a same-named file
of another folder beside it), and a run bag that cannot be read stays an execution, unscoreable
and said on stderr (issue 38 item 3)."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path
from typing import Any

import pytest
import yaml

from ertools.cli.main import main
from ertools.rsbb.layout import classify, pair_runs
from ertools.simulator.answers import read_answers

pytestmark = pytest.mark.slow  # scores whole folders (~20 s each)

SAMPLES = Path(__file__).resolve().parents[2] / "sample_bags"
HNF_RUN_1 = "run_1_2019-04-10-14-31-06"


def test_pair_runs_takes_the_transform_of_the_runs_own_layout() -> None:
    # a 2015 folder's transform-simbot.yaml sorts before the RSBB folder's: still not taken
    names = [
        "/c/fbm2h/transform-simbot.yaml",
        "/c/hnf/rsbb_etc/transforms/transform-simbot.yaml",
        "/c/hnf/rsbb_logs/HNF/simbot/run_1_2019-04-10-14-31-06.bag",
        "/c/other/rsbb_logs/HNF/simbot/run_2_2019-04-10-15-31-06.bag",
    ]
    runs, problems = pair_runs(f for f in (classify(n) for n in names) if f is not None)
    by_run = {r.run: r.transform for r in runs}
    assert by_run[1] == Path("/c/hnf/rsbb_etc/transforms/transform-simbot.yaml")
    # a layout without its own: the first of the others, and the choice said
    assert by_run[2] == Path("/c/fbm2h/transform-simbot.yaml")
    assert [p for p in problems if "no result file" not in p] == [
        "2 files for team simbot's transform: /c/fbm2h/transform-simbot.yaml used, not "
        "/c/hnf/rsbb_etc/transforms/transform-simbot.yaml",
    ]


def test_a_2015_folder_beside_rsbb_ones_gives_hnf_no_transform(tmp_path: Path) -> None:
    for name in ("season2019", "fbm2h", "hnf"):
        shutil.copytree(SAMPLES / name, tmp_path / name)
    out = tmp_path / "out"
    paths = [str(tmp_path / n) for n in ("season2019", "fbm2h", "hnf")]
    code = main(["rescore", *paths, "--out", str(out), "--no-reports", "-j", "1"])
    assert code == 0
    manifest = yaml.safe_load((out / "manifest.yaml").read_text(encoding="utf-8"))
    transform = Path(manifest["benchmarks"]["hnf"]["teams"]["simbot"]["transform"])
    assert transform == tmp_path / "hnf/rsbb_etc/transforms/transform-simbot.yaml"
    doc: dict[str, Any] = json.loads((out / "results.json").read_text(encoding="utf-8"))
    run = next(
        r for r in doc["executions"] if r["benchmark"] == "hnf" and HNF_RUN_1 in r["bags"][0]
    )
    answers = read_answers(SAMPLES / f"hnf/rsbb_logs/HNF/simbot/{HNF_RUN_1}.bag")
    # the generator's truth: stops against waypoints with the run's own marker offset; its
    # tolerance is the simulated mocap noise (0.2 mm per axis), so 1 mm
    expected = answers["expected"]["ertools"]["position_accuracy"]
    assert run["score"]["position_accuracy[m]"] == pytest.approx(
        expected, abs=answers["tolerance"]["distance"]["abs"]
    )
    places = {f["path"]: f["place"] for f in doc["files"]}
    assert places["hnf/rsbb_etc/transforms/transform-simbot.yaml"] == "input"


def test_a_truncated_run_bag_is_an_unscoreable_execution(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "season2019"
    shutil.copytree(SAMPLES / "season2019", folder)
    bag = folder / "rsbb_logs/HGMF/simbot/run_1_2019-04-13-10-00-00.bag"
    size = bag.stat().st_size // 2
    bag.write_bytes(bag.read_bytes()[:size])
    out = tmp_path / "out"
    code = main(["rescore", str(folder), "--out", str(out), "--no-reports", "-j", "1"])
    assert code == 1  # as for any execution not scored
    err = capsys.readouterr().err.splitlines()
    # its id's time is its result file's (10:00:00 WET, +0000): the bag holds none
    line = next(x for x in err if "hgmf-simbot-" in x)
    assert re.fullmatch(
        r"ertools: error: hgmf-simbot-20190413T100000: unscoreable: its run bag cannot be read "
        rf"\(truncated: the index at byte \d+ lies past the end \({size} bytes\)\)",
        line,
    ), line
    assert any(x.startswith(f"ertools: warning: {bag}: truncated: ") for x in err), err
    assert "ertools: 9 executions: 8 scored, 1 unscoreable, 0 failed (0 from the cache)" in err
    doc: dict[str, Any] = json.loads((out / "results.json").read_text(encoding="utf-8"))
    row = next(r for r in doc["executions"] if r["id"] == "hgmf-simbot-20190413T100000")
    assert row["status"] == "unscoreable" and row["team"] == "simbot"
    places = {f["path"]: f["place"] for f in doc["files"]}
    result = next(p for p in places if p.startswith("results/HGMF/simbot/"))
    assert places[result] == "input"  # its result file is the run's, not unused


def test_a_truncated_run_bag_without_its_result_has_no_1970_time(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "season2019"
    shutil.copytree(SAMPLES / "season2019", folder)
    bag = folder / "rsbb_logs/HGMF/simbot/run_1_2019-04-13-10-00-00.bag"
    bag.write_bytes(bag.read_bytes()[: bag.stat().st_size // 2])
    shutil.rmtree(folder / "results/HGMF/simbot")
    out = tmp_path / "out"
    assert main(["rescore", str(folder), "--out", str(out), "--no-reports", "-j", "1"]) == 1
    doc: dict[str, Any] = json.loads((out / "results.json").read_text(encoding="utf-8"))
    row = next(r for r in doc["executions"] if r["bags"][0].endswith(bag.name))
    # no time anywhere (its bag holds no message, no result file names one): its id is its
    # place in the list, never 1970-01-01
    assert row["status"] == "unscoreable" and row["start_ns"] is None
    assert re.fullmatch(r"hgmf-simbot-\d+", row["id"]), row["id"]
    assert f"ertools: error: {row['id']}: unscoreable: its run bag cannot be read" in (
        capsys.readouterr().err
    )
