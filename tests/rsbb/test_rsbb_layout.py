"""ertools.rsbb.layout: a season folder's files recognised, results paired with their bags."""

from __future__ import annotations

from dataclasses import replace
from datetime import datetime
from pathlib import Path

import pytest

from ertools.errors import UsageError
from ertools.rsbb.layout import FileKind, classify, pair_runs, scan
from ertools.simulator.rsbb import write_rsbb_run
from tests.helpers.rsbb_replay.scenarios import at, hnf_scenario


def test_classify_run_bags_results_and_side_files() -> None:
    bag = classify("season/rsbb_logs/HNF/b-it-bots/run_3_2019-04-10-14-31-06.bag")
    assert bag is not None and bag.kind is FileKind.RUN_BAG
    assert (bag.code, bag.team, bag.run, bag.active) == ("HNF", "b-it-bots", 3, False)
    assert bag.local_time == datetime(2019, 4, 10, 14, 31, 6)
    active = classify("x/rsbb_logs/HPFF/homer/run_1_2019-04-10-14-31-06.bag.active")
    assert active is not None and active.active
    res = classify("season/results/HNF/b-it-bots/result_run_3_2019-04-10_14:31:05_WEST(+0100).yaml")
    assert res is not None and res.kind is FileKind.RESULT
    assert (res.code, res.team, res.run) == ("HNF", "b-it-bots", 3)
    assert res.local_time == datetime(2019, 4, 10, 14, 31, 5)
    side = {
        "rsbb_etc/transforms/transform-homer.yaml": (FileKind.TRANSFORM, None, "homer"),
        "rsbb_bmbox/scripts/benchmark_configs/HNF.yaml": (FileKind.BENCHMARK_CONFIG, "HNF", None),
        "configs/HGMF.yaml": (FileKind.BENCHMARK_CONFIG, "HGMF", None),
        "rsbb_etc/objects_informations/items_with_pose.yaml": (FileKind.ITEMS, None, None),
        "rsbb_etc/config/benchmarks_description.yaml": (FileKind.DESCRIPTION, None, None),
        "logs/log_mocap_2019-04-10-14-00-00_0.bag": (FileKind.MOCAP_LOG, None, None),
    }
    for path, (kind, code, team) in side.items():
        f = classify(path)
        assert f is not None and (f.kind, f.code, f.team) == (kind, code, team), path
    for other in (
        "rsbb_logs/XYZ/team/run_1_2019-04-10-14-31-06.bag",  # unknown code
        "somewhere/run_1_2019-04-10-14-31-06.bag",  # not in the RSBB folders
        "results/HNF/result_run_1_2019-04-10_14:31:05_WEST(+0100).yaml",  # no team folder
        "HGTKMH.yaml",  # a task benchmark has no script config
        "notes.yaml",
    ):
        assert classify(other) is None, other


def test_pairing_by_code_team_run_and_time() -> None:
    files = [
        classify(p)
        for p in (
            "s/rsbb_logs/HNF/a/run_1_2019-04-10-10-00-01.bag",
            "s/results/HNF/a/result_run_1_2019-04-10_10:00:00_WEST(+0100).yaml",
            # run 1 repeated an hour later
            "s/rsbb_logs/HNF/a/run_1_2019-04-10-11-00-02.bag",
            "s/results/HNF/a/result_run_1_2019-04-10_11:00:00_WEST(+0100).yaml",
            # a result whose bag was lost, a task benchmark's bag (no result expected)
            "s/results/HNF/b/result_run_1_2019-04-10_12:00:00_WEST(+0100).yaml",
            "s/rsbb_logs/HWV/a/run_1_2019-04-10-13-00-00.bag",
            "s/transform-a.yaml",
            "s/rsbb_bmbox/HNF.yaml",
        )
    ]
    runs, problems = pair_runs(f for f in files if f is not None)
    by = {(r.code, r.team, r.run, (r.bag or r.result).local_time.hour): r for r in runs}  # type: ignore[union-attr]
    early, late = by[("HNF", "a", 1, 10)], by[("HNF", "a", 1, 11)]
    assert early.bag is not None and early.result is not None
    assert early.bag.stamp == "2019-04-10-10-00-01" and late.bag is not None
    assert late.result is not None and late.result.stamp.startswith("2019-04-10_11")
    assert early.transform == Path("s/transform-a.yaml") and early.config == Path(
        "s/rsbb_bmbox/HNF.yaml"
    )
    lost = by[("HNF", "b", 1, 12)]
    assert lost.bag is None and lost.transform is None
    task = by[("HWV", "a", 1, 13)]
    assert task.result is None
    assert problems == (
        "s/results/HNF/b/result_run_1_2019-04-10_12:00:00_WEST(+0100).yaml: "
        "no run bag of HNF b run 1 beside it",
    )


@pytest.mark.slow  # writes two run bags (~2 s)
def test_scan_a_written_season(tmp_path: Path) -> None:
    write_rsbb_run(tmp_path, hnf_scenario())
    write_rsbb_run(tmp_path, replace(hnf_scenario(), team="teamB", t_connect_ns=at(0.7)))
    (tmp_path / "rsbb_etc" / "transforms").mkdir(parents=True)
    (tmp_path / "rsbb_etc" / "transforms" / "transform-teamA.yaml").write_text("team_name: teamA\n")
    layout = scan(tmp_path)
    assert [(r.team, r.bag is not None, r.result is not None) for r in layout.runs] == [
        ("teamA", True, True),
        ("teamB", True, True),
    ]
    assert layout.runs[0].transform is not None and layout.runs[1].transform is None
    assert layout.problems == ()
    with pytest.raises(UsageError, match="not a folder"):
        scan(tmp_path / "missing")


def test_two_configs_for_one_code_are_named() -> None:
    files = [
        classify(p)
        for p in ("a/HNF.yaml", "b/HNF.yaml", "s/rsbb_logs/HNF/t/run_1_2019-04-10-10-00-01.bag")
    ]
    runs, problems = pair_runs(f for f in files if f is not None)
    assert runs[0].config == Path("a/HNF.yaml")
    assert problems[0] == "2 files for HNF's config: a/HNF.yaml used, not b/HNF.yaml"
    assert problems[1].endswith("no result file of HNF t run 1")
