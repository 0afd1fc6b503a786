"""YAML that PyYAML reads without complaint but that cannot mean what it says (issue 36,
findings 3 and 17): a key given twice (PyYAML keeps the last value silently: a second
``waypoints:`` block scored 12.197 m instead of 0.0974 m), and nesting past the depth limit by
a route the old check missed (a transform mentioning ``!!python/tuple``, even in a comment,
was read by another loader; an alias repeats a whole nested list). Every file ertools reads
is one ``ertools: error:`` line naming the file and the line, exit 1."""

from __future__ import annotations

import inspect
import logging
import shutil
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

from ertools.benchmarks.fbm2h.goal import goal_from_payload
from ertools.cli.main import main
from ertools.configs._yaml import parse_payload, parse_yaml
from ertools.configs.mocap import load_mocap_config
from ertools.errors import ConfigError
from tests.helpers.stderr_text import error_messages

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "sample_bags"
FBM2H = SAMPLES / "fbm2h"
FBM2H_BAG = FBM2H / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"
FBM2H_GOAL = FBM2H / "fbm2h_goal.yaml"
FBM2H_TIMING = FBM2H / "log_fbm2h_mocap_2015-11-20-12-00-00_0_reached_waypoint_timing.yaml"
FBM2H_TRANSFORM = FBM2H / "transform-simbot.yaml"
FBM3W = SAMPLES / "fbm3w"
FBM3W_BAG = FBM3W / "log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
FBM3W_ROSBAG2 = FBM3W / "log_fbm3w_mocap_2015-11-20-12-00-00_0_mcap"
FBM1H = SAMPLES / "fbm1h"
FBM1H_BAG = FBM1H / "log_fbm1h_2015-11-20-12-00-00_0.bag"
FBM1H_ITEMS = FBM1H / "fbm1h.yaml"

SECOND_WAYPOINTS = "\n".join(
    ["  waypoints:", *(f"  - [{k / 10}, {k / 10}, {k / 10}]" for k in range(5)), ""]
)


def _insert(text: str, before: str, new: str) -> str:
    assert before in text, before
    return text.replace(before, new + before, 1)


# kind -> (the file's name, its text with a key given twice, the line of the second, the
# command that reads it)
Case = tuple[str, Callable[[], str], int, Callable[[Path], list[str]]]
CASES: dict[str, Case] = {
    "goal": (
        "goal.yaml",
        lambda: _insert(FBM2H_GOAL.read_text(), "  num_waypoints: 5", SECOND_WAYPOINTS),
        8,
        lambda f: ["score", "fbm2h", str(FBM2H_BAG), "--goal", str(f)],
    ),
    "timing": (
        "timing.yaml",
        lambda: FBM2H_TIMING.read_text().replace("- p1: 10.1", "- p1: 10.1\n  p1: 12.0", 1),
        4,
        lambda f: [
            *("score", "fbm2h", str(FBM2H_BAG), "--goal", str(FBM2H_GOAL)),
            *("--reached", "timing", str(f)),
        ],
    ),
    "transform": (
        "transform-simbot.yaml",
        lambda: (
            FBM2H_TRANSFORM.read_text() + "marker_to_robot_transform: [[0, 0, 0], [0, 0, 0, 1]]\n"
        ),
        9,
        lambda f: ["score", "fbm2h", str(FBM2H_BAG), "--transform", str(f)],
    ),
    # the ERL RSBB layout, read by the tuple-reading loader: the same refusal
    "transform-tuple": (
        "transform-rsbb.yaml",
        lambda: (
            "team_name: simbot\n"
            "markerset_to_robot_transform: !!python/tuple [[0.12, -0.05, -0.85], [0, 0, 0, 1]]\n"
            "markerset_to_robot_transform: !!python/tuple [[0, 0, 0], [0, 0, 0, 1]]\n"
        ),
        3,
        lambda f: ["score", "fbm2h", str(FBM2H_BAG), "--transform", str(f)],
    ),
    "items": (
        "fbm1h.yaml",
        lambda: FBM1H_ITEMS.read_text().replace("  id: 1\n", "  id: 1\n  id: 7\n", 1),
        4,
        lambda f: ["score", "fbm1h", str(FBM1H_BAG), "--items", str(f)],
    ),
    "results": (
        "results.yaml",
        lambda: "1: {item_class: a, item_instance: a1, x: 0.1, y: 0.0, theta: 0, x: 0.5}\n",
        1,
        lambda f: [
            "score",
            "fbm1h",
            str(FBM1H_BAG),
            "--items",
            str(FBM1H_ITEMS),
            "--results",
            str(f),
        ],
    ),
    "fbm3w-config": (
        "fbm3w.yaml",
        lambda: (FBM3W / "fbm3w.yaml").read_text() + "d_min: 0.01\n",
        9,
        lambda f: ["score", "fbm3w", str(FBM3W_BAG), "--config", str(f)],
    ),
    "runs-file": (
        "runs.yaml",
        lambda: "- spec: line\n  reference: 1.0\n  start: 2.0\n  end: 9.0\n  start: 5.0\n",
        5,
        lambda f: ["score", "fbm3w", str(FBM3W_BAG), "--runs-file", str(f)],
    ),
    "manifest": (
        "competition.yaml",
        lambda: (
            "version: 1\n"
            "benchmarks:\n  fbm3w:\n    inputs: {d_min: 0.001}\n"
            "executions:\n"
            f"- {{benchmark: fbm3w, team: a, bags: [{FBM3W_BAG}]}}\n"
            "benchmarks:\n  fbm2h: {}\n"
        ),
        7,
        lambda f: ["rescore", "--config", str(f), "--check"],
    ),
}


@pytest.mark.parametrize("kind", list(CASES))
def test_a_key_given_twice_is_refused_naming_the_file_and_line(
    kind: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    name, text, line, command = CASES[kind]
    path = tmp_path / name
    path.write_text(text())
    code = main(command(path))
    err = capsys.readouterr().err
    assert code == 1, err
    assert "Traceback" not in err and "this is a bug" not in err
    said = [m for m in error_messages(err) if "duplicate key" in m]
    assert len(said) == 1, err
    assert str(path) in said[0] and f"line {line}," in said[0], said[0]


def test_a_key_given_twice_in_a_mocap_config(tmp_path: Path) -> None:
    path = tmp_path / "mocap.yaml"
    path.write_text(
        "rigid_bodies:\n"
        "  '3':\n    pose: robot_at_home/pose\n    child_frame_id: robot_at_home\n"
        "  '3':\n    pose: robot_at_work/pose\n    child_frame_id: robot_at_work\n"
    )
    with pytest.raises(
        ConfigError, match=r"at line 5, column 3: duplicate key '3' \(first at line 2\)"
    ):
        load_mocap_config(path)


def test_a_key_given_twice_in_a_rosbag2_metadata(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = tmp_path / FBM3W_ROSBAG2.name
    shutil.copytree(FBM3W_ROSBAG2, bag)
    meta = bag / "metadata.yaml"
    text = meta.read_text()
    meta.write_text(
        text.replace(
            "  storage_identifier: mcap\n",
            "  storage_identifier: mcap\n  storage_identifier: sqlite3\n",
        )
    )
    line = text[: text.index("  storage_identifier: mcap")].count("\n") + 2
    code = main(["info", str(bag)])
    err = capsys.readouterr().err
    assert code == 1 and "Traceback" not in err
    assert f"a key given twice, at line {line}" in err, err
    assert "sqlite3" not in err  # the file's text is not quoted (it may be anything)


def test_a_key_given_twice_in_a_result_read_by_report(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    score = tmp_path / "score.json"
    score.write_text('{"benchmark": "fbm3w", "score": 0.01,\n "score": 0.5}\n')
    code = main(["report", str(score), "--report", str(tmp_path / "site")])
    err = capsys.readouterr().err
    assert code == 1, err
    lines = error_messages(err)
    assert len(lines) == 1 and str(score) in lines[0], err
    assert "duplicate key 'score' at line 2" in lines[0], lines[0]


def test_the_sample_files_have_no_key_twice() -> None:
    """The refusal costs nothing on honest files: every YAML file of the samples reads."""
    for path in sorted(SAMPLES.rglob("*.yaml")):
        parse_yaml(path.read_text(), str(path), tags="tuples")


def test_a_payload_with_a_key_twice_is_read_as_the_2015_nodes_did(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """A payload is what the live system read (PyYAML: the last value wins, and the live score
    used it): read the same way, and said, with the line."""
    payload = FBM2H_GOAL.read_text().replace("goal:\n", "", 1)
    payload = _insert(payload, "  num_waypoints: 5", SECOND_WAYPOINTS)
    with caplog.at_level(logging.WARNING):
        goal = goal_from_payload(payload, "/fbm2h/bmbox_state payload")
    assert goal.waypoints[0] == (0.0, 0.0, 0.0)  # the second block, as yaml.load gave
    warned = [r.getMessage() for r in caplog.records if "duplicate key" in r.getMessage()]
    assert warned == [
        "/fbm2h/bmbox_state payload: duplicate key 'waypoints' at line 7 (first at line 1) of "
        "the goal payload: the last value is used, as the 2015 nodes read it"
    ]
    assert parse_payload("{a: 1, b: 2}", "p") == {"a": 1, "b": 2}


# --- finding 17: the depth limit, whatever the text says ------------------------------------

DEEP = "[" * 3000 + "]" * 3000


@pytest.mark.parametrize(
    "text",
    [
        f"# written by the RSBB acquirer: !!python/tuple\nmarker_to_robot_transform: {DEEP}\n",
        f"marker_to_robot_transform: !!python/tuple {DEEP}\n",
        f"a: !!python/tuple [1]\nmarker_to_robot_transform: {DEEP}\n",
    ],
    ids=["comment", "tag", "elsewhere"],
)
def test_a_transform_naming_the_tuple_tag_keeps_the_depth_limit(
    text: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "transform-deep.yaml"
    path.write_text(text)
    code = main(["score", "fbm2h", str(FBM2H_BAG), "--transform", str(path)])
    err = capsys.readouterr().err
    assert code == 1 and "this is a bug" not in err and "RecursionError" not in err, err
    lines = error_messages(err)
    assert len(lines) == 1 and str(path) in lines[0], err
    assert "nested more than 64 levels deep" in lines[0]


def test_aliases_that_nest_past_the_limit_are_refused() -> None:
    """Each line places the previous list 20 levels down: 21, 40, 59, then 78 levels of data
    (the composer's own depth never passes 21)."""
    lines = ["a0: &a0 " + "[" * 20 + "1" + "]" * 20]
    for k in range(1, 4):
        lines.append(f"a{k}: &a{k} " + "[" * 19 + f"*a{k - 1}" + "]" * 19)
    with pytest.raises(ConfigError, match=r"line 4, column 28: nested more than 64 levels deep"):
        parse_yaml("\n".join(lines) + "\n", "aliases.yaml")
    # within the limit an alias is read as before
    assert parse_yaml("a: &a [[1]]\nb: [*a, *a]\n") == {"a": [[1]], "b": [[[1]], [[1]]]}


def test_an_alias_inside_itself_is_refused() -> None:
    with pytest.raises(ConfigError, match=r"line 1, column 11: alias \*a refers to itself"):
        parse_yaml("loop: &a [*a]\n", "loop.yaml")


def test_a_recursion_error_is_a_config_error_naming_the_file(tmp_path: Path) -> None:
    """Whatever ends in Python's recursion limit (a caller already deep in its stack) is one
    error naming the file, never "unexpected RecursionError"."""
    path = tmp_path / "goal.yaml"
    path.write_text("goal: " + "[" * 60 + "]" * 60 + "\n")
    limit = sys.getrecursionlimit()
    # room for 80 more frames than the test has: 60 levels take 3 or more each to compose
    sys.setrecursionlimit(len(inspect.stack(0)) + 80)
    try:
        with pytest.raises(ConfigError, match=r"nested too deep"):
            parse_yaml(path.read_text(), str(path), what="goal list")
    finally:
        sys.setrecursionlimit(limit)
