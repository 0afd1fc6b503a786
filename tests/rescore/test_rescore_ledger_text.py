"""The pure parts of issue 24: the ledger (every file in one place), the page's wording
(numbers at the data's resolution, relative paths, options as manifest keys, warnings said
once) and the per-team rule. Expected values are written down here by hand."""

from __future__ import annotations

from pathlib import Path

from ertools.benchmarks import registry
from ertools.competition.ledger import Claim, account, place_files
from ertools.competition.site_text import (
    Paths,
    deviation_terms,
    difference,
    group_warnings,
    manifest_terms,
    prose_units,
    rule_text,
    shown,
    with_unit,
)

ROOT = "/data/erl"


def test_each_file_takes_its_best_claim_once() -> None:
    files = [
        f"{ROOT}/bm/log_fbm2h_0.bag",
        f"{ROOT}/gt/log_mocap_0.bag",
        f"{ROOT}/gt/log_mocap_1.bag",
        f"{ROOT}/rosbag2/log_fbm3w/metadata.yaml",  # a rosbag2 folder's files: the folder's
        f"{ROOT}/rosbag2/log_fbm3w/log_fbm3w_0.mcap",
        f"{ROOT}/README.md",
        f"{ROOT}/fbm2h/log_x_reached_waypoint_timing.yaml",
        f"{ROOT}/old/lost.bag",
    ]
    claims = [
        Claim(f"{ROOT}/gt/log_mocap_0.bag", "problem", kind="gap", reason="gap of 6 s"),
        Claim(f"{ROOT}/gt/log_mocap_0.bag", "gt", "fbm2h-homer-1"),  # gt beats problem
        Claim(f"{ROOT}/bm/log_fbm2h_0.bag", "execution", "fbm2h-homer-1"),
        Claim(f"{ROOT}/gt/log_mocap_1.bag", "problem", kind="gt-only", reason="split file"),
        Claim(f"{ROOT}/rosbag2/log_fbm3w", "execution", "fbm3w-x-1"),
        Claim(ROOT, "problem", kind="unreadable", reason="the folder's own problem"),
    ]
    got = {e.path: (e.place, e.execution, e.kind) for e in place_files(files, claims, ROOT)}
    assert got == {
        "bm/log_fbm2h_0.bag": ("execution", "fbm2h-homer-1", None),
        "gt/log_mocap_0.bag": ("gt", "fbm2h-homer-1", None),
        "gt/log_mocap_1.bag": ("problem", None, "gt-only"),
        "rosbag2/log_fbm3w/metadata.yaml": ("execution", "fbm3w-x-1", None),
        "rosbag2/log_fbm3w/log_fbm3w_0.mcap": ("execution", "fbm3w-x-1", None),
        "README.md": ("problem", None, "unused"),  # not the folder's problem
        "fbm2h/log_x_reached_waypoint_timing.yaml": ("problem", None, "unused"),
        "old/lost.bag": ("problem", None, "unused"),
    }
    reasons = {e.path: e.reason for e in place_files(files, claims, ROOT)}
    assert reasons["README.md"] == "not a log, and no input of any execution names it"
    assert "timing file no execution uses" in str(
        reasons["fbm2h/log_x_reached_waypoint_timing.yaml"]
    )
    assert "a log no execution uses" in str(reasons["old/lost.bag"])


def test_account_adds_files_and_unused_problems() -> None:
    doc = {
        "manifest": {"path": f"{ROOT}/competition.yaml"},
        "executions": [
            {
                "id": "fbm2h-homer-1",
                "of": None,
                "bags": [f"{ROOT}/bm/a.bag", f"{ROOT}/gt/g.bag"],
                "inputs": [
                    {"name": "goal", "path": f"{ROOT}/goal.yaml", "sha256": "x"},
                    {"name": "reached", "value": ["timing", {"path": f"{ROOT}/t.yaml"}]},
                ],
            },
        ],
        "problems": [],
    }
    files = [
        f"{ROOT}/{p}" for p in ("bm/a.bag", "gt/g.bag", "goal.yaml", "t.yaml", "competition.yaml")
    ]
    files += [f"{ROOT}/robots/FBM2H_1_homer.bag", f"{ROOT}/notes.txt"]
    out = account(doc, files, [ROOT], {f"{ROOT}/robots/FBM2H_1_homer.bag": f"{ROOT}/bm/a.bag"})
    places = {e["path"]: (e["place"], e["execution"]) for e in out["files"]}
    assert places == {
        "bm/a.bag": ("execution", "fbm2h-homer-1"),
        "gt/g.bag": ("gt", "fbm2h-homer-1"),
        "goal.yaml": ("input", "fbm2h-homer-1"),
        "t.yaml": ("input", "fbm2h-homer-1"),  # inside a value: the timing file of reached
        "competition.yaml": ("input", None),
        "robots/FBM2H_1_homer.bag": ("robot-log", "fbm2h-homer-1"),
        "notes.txt": ("problem", None),
    }
    assert out["root"] == ROOT
    assert out["problems"] == [
        {
            "kind": "unused",
            "path": f"{ROOT}/notes.txt",
            "message": "not a log, and no input of any execution names it",
        }
    ]


def test_numbers_at_the_datas_resolution() -> None:
    assert shown("best_distance_error", 0.0006389302989094458) == "0.64"  # m -> mm, 0.01 mm
    assert with_unit("position_accuracy", 0.06304760469410157) == "63.05 mm"
    assert with_unit("orientation_accuracy", 0.030862283) == "1.77 deg"  # 0.030862 rad
    assert with_unit("execution_time", 44.954661) == "44.955 s"
    assert shown("pose_score", 0.7829047845808581) == "0.782905"
    assert shown("best_run", 2) == "2" and shown("x", None) == "\u2014"
    assert rule_text("position_accuracy (metres, the mean distance)") == (
        "position_accuracy (mm, the mean distance)"
    )
    assert prose_units("clipped at 1 m; 0.0900 rad; 0.05 m/s") == (
        "clipped at 1000.00 mm; 5.16 deg; 0.05 m/s"
    )


def test_a_difference_as_shown() -> None:
    d = difference(
        "position_accuracy: live 0.0095 vs recomputed 0.0081; why: robot pose interpolated "
        "[fbm2h.pose-moment]; recomputed with reached=states"
    )
    assert (d.key, d.live, d.recomputed, d.difference) == (
        "position_accuracy",
        "9.50 mm",
        "8.10 mm",
        "-1.40 mm",
    )
    assert d.rules == ("fbm2h.pose-moment",)
    assert d.why.startswith("robot pose interpolated")
    tiny = difference("execution_time: live 41.6000001 vs recomputed 41.6")
    assert tiny.difference.startswith("below the shown resolution")
    assert difference("best_run: live 3 vs recomputed 2").difference == "-1"


def test_paths_relative_and_options_as_manifest_keys() -> None:
    paths = Paths(ROOT, ["/data"])
    assert paths.path(f"{ROOT}/bm/a.bag") == "bm/a.bag"
    assert paths.path("/data/competition.yaml") == "../competition.yaml"
    text = f"{ROOT}/bm/a.bag:/fbm2h/robot_at_home/pose: no messages (see {ROOT}/gt/g.bag)"
    assert paths.text(text) == "bm/a.bag:/fbm2h/robot_at_home/pose: no messages (see gt/g.bag)"
    assert manifest_terms("give --robot-topic (found 0)", "trajectory") == (
        "give benchmarks.trajectory.inputs.robot_topic (found 0)"
    )
    # a robot log's warning in an FBM1H row names the comparison's benchmark
    assert manifest_terms("not compared by trajectory (give --gt-topic)", "fbm1h") == (
        "not compared by trajectory (give benchmarks.trajectory.inputs.gt_topic)"
    )
    # a deviation's option, by the benchmark its rule key names (fbm1: the FBM1 benchmarks)
    assert deviation_terms("--count-aborted restores 2015 [fbm1.aborted-runs]") == (
        "benchmarks.fbm1h.inputs.count_aborted restores 2015 [fbm1.aborted-runs]"
    )
    assert manifest_terms("give --transform FILE", "fbm2h") == (
        "give benchmarks.fbm2h.teams.TEAM.transform FILE"
    )


def test_a_warning_shared_by_executions_is_said_once() -> None:
    rows = [
        {
            "id": f"fbm1h-{team}-1",
            "benchmark": "fbm1h",
            "warnings": [
                f"robot log {ROOT}/robots/FBM1H_1_{team}.bag: not compared with the GT by "
                f"trajectory ({ROOT}/robots/FBM1H_1_{team}.bag: give --robot-topic)",
                *(["only mine"] if team == "homer" else []),
                "team unknown (name it in the manifest)",
            ],
        }
        for team in ("homer", "socrob", "skuba")
    ]
    grouped, own = group_warnings(
        rows, Paths(ROOT), skip=("team unknown (name it in the manifest)",)
    )
    (g,) = grouped
    assert g.text == (
        "its robot log: not compared with the GT by trajectory "
        "(its log: give benchmarks.trajectory.inputs.robot_topic)"
    )
    assert g.executions == ("fbm1h-homer-1", "fbm1h-socrob-1", "fbm1h-skuba-1") and g.of == 3
    assert own == {"fbm1h-homer-1": ["only mine"], "fbm1h-socrob-1": [], "fbm1h-skuba-1": []}


def test_the_transform_is_needed_only_where_the_scoring_path_uses_it() -> None:
    transform = registry.get("fbm2h").input("transform")
    timing = ("timing", Path("t.yaml"))
    assert transform.needed({})  # reached moments from the state topics (the default)
    assert transform.needed({"reached": ("states",)})
    assert not transform.needed({"reached": timing})
    assert not transform.needed({"reached": ("auto",)})
    assert not registry.get("fbm2h").input("goal").needed({})  # not a per-team input
